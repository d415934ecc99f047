//! The page in a real browser (headless Chromium through WebDriver, one
//! session for every page): it loads with no console error and fetches
//! nothing; every plot has a non-empty box and every plot's text stays in
//! its plot; no text overflows its container at 1280 and at 390 CSS
//! pixels wide; it prints to A4 with a page break before every section;
//! headings run in order, every figure has a text alternative, and the
//! verdict's colours have the contrast WCAG asks of text; and every value
//! shown equals the JSON it names, read back from the page's DOM and
//! compared with the files and the door's JSON, each obtained here on its
//! own.

use std::collections::BTreeMap;
use std::path::Path;

use serde_json::Value;
use tricept_ident::MachineInput;
use tricept_ident::advanced::TrueErrors;
use tricept_ident::compensate::{Calibrated, CompensateRequest, compensate};
use tricept_ident::diagnosis::{DiagnoseRequest, diagnose};

use crate::support::{
    Dir, campaign, check_into, export_of, fixture, page, pitch_machine, read_json, table2_machine,
};
use crate::webdriver::{Driver, Session, ensure_browser};

/// The pitch error the pitch fixture holds (docs/diagnosis.md).
pub const PITCH: &str =
    r#"{"effect":"leg-periodic","um":[4,4,4],"period_mm":10,"phase_deg":[0,120,240]}"#;

#[test]
fn the_page_in_a_real_browser() {
    ensure_browser();
    let dir = Dir::new("browser");
    // A deployed pitch error, its campaign, two checks and an export.
    let machine = pitch_machine(&dir);
    let history = dir.join("checks.jsonl");
    for day in 1..=2u64 {
        let truth = TrueErrors::Random {
            magnitude_mm: 0.25,
            seed: 4,
        };
        let data = campaign(
            &dir,
            &format!("day{day}.csv"),
            truth,
            &[PITCH],
            20 + day,
            1.0,
        );
        check_into(&machine, &data, &history);
    }
    let export = export_of(&machine, &dir, "cnc");
    let data = fixture("fixtures/data/diagnose-pitch.csv");
    let full = dir.join("pitch.html");
    let report = page(&machine, Some(&data), Some(&history), Some(&export), &full).unwrap();
    let mut expected = BTreeMap::new();
    expected.insert("machine".to_string(), read_json(&machine));
    expected.insert("history".into(), history_lines(&history));
    expected.insert("trends".into(), trends(&history));
    expected.insert("export".into(), read_json(&export.join("export.json")));
    let d =
        diagnose(DiagnoseRequest::new(data.as_path()).machine(MachineInput::default())).unwrap();
    // The page keeps the diagnosis' keys without the output's
    // `format_version`.
    let mut diagnosis = d.to_json();
    if let Some(o) = diagnosis.as_object_mut() {
        o.shift_remove("format_version");
    }
    expected.insert("diagnosis".into(), diagnosis);
    expected.insert("verdict".into(), report.verdict().to_json());
    // The Table 2 fixture identified, alone.
    let table2 = table2_machine(&dir);
    let alone = dir.join("table2.html");
    let r2 = page(&table2, None, None, None, &alone).unwrap();
    let mut expected2 = BTreeMap::new();
    expected2.insert("machine".to_string(), read_json(&table2));
    expected2.insert("verdict".into(), r2.verdict().to_json());

    let driver = Driver::start();
    let session = driver.session();
    let started = std::time::Instant::now();
    check_page(&session, &full, &machine, Some(&expected));
    check_page(&session, &alone, &table2, Some(&expected2));
    let sample = fixture("docs/report-sample.html");
    check_page(
        &session,
        &sample,
        &fixture("fixtures/report/table2.json"),
        None,
    );
    eprintln!(
        "browser checks of 3 pages: {:.1} s",
        started.elapsed().as_secs_f64()
    );
}

/// The history's lines as JSON.
fn history_lines(path: &Path) -> Value {
    Value::Array(
        std::fs::read_to_string(path)
            .unwrap()
            .lines()
            .filter(|l| !l.trim().is_empty())
            .map(|l| serde_json::from_str(l).unwrap())
            .collect(),
    )
}

/// The history's trends as `tricept check --json` gives them.
fn trends(path: &Path) -> Value {
    let entries = tricept_check::history::read(path).unwrap();
    serde_json::to_value(tricept_check::history::trends(&entries)).unwrap()
}

/// Every check of one page; `expected` the sources to compare its values
/// with (none: its own JSON blocks).
fn check_page(
    session: &Session<'_>,
    file: &Path,
    machine: &Path,
    expected: Option<&BTreeMap<String, Value>>,
) {
    let name = file.display().to_string();
    session.window(1280, 900);
    let _ = session.console();
    session.open(file);
    let console: Vec<Value> = session
        .console()
        .into_iter()
        .filter(|e| e["level"] == "SEVERE" || e["level"] == "WARNING")
        .collect();
    assert!(console.is_empty(), "{name}: console: {console:?}");
    let fetched =
        session.script("return performance.getEntriesByType('resource').map(e => e.name)");
    assert_eq!(fetched, Value::Array(vec![]), "{name}: fetched resources");
    for width in [1280, 390] {
        session.window(width, 900);
        let layout = session.script(LAYOUT);
        let shown = layout["width"].as_f64().unwrap();
        assert!(
            (shown - f64::from(width)).abs() < 20.0,
            "{name}: a {width} px window shows {shown} px"
        );
        assert!(
            layout["scroll"].as_f64().unwrap() <= shown + 0.5,
            "{name} at {width} px: the page scrolls sideways: {layout}"
        );
        let plots = layout["plots"].as_array().unwrap();
        assert!(plots.len() >= 3, "{name}: {} plots", plots.len());
        for p in plots {
            assert!(
                p["w"].as_f64().unwrap() > 50.0 && p["h"].as_f64().unwrap() > 20.0,
                "{name} at {width} px: an empty plot: {p}"
            );
        }
        assert_eq!(
            layout["overflow"],
            Value::Array(vec![]),
            "{name} at {width} px"
        );
        assert_eq!(
            layout["svgText"],
            Value::Array(vec![]),
            "{name} at {width} px"
        );
    }
    session.window(1280, 900);
    accessibility(session, &name);
    let sections = session
        .script("return document.querySelectorAll('section').length")
        .as_u64()
        .unwrap() as usize;
    pdf(&session.print_a4(), sections, &name);
    let values = session.script(VALUES);
    let blocks = session.script(BLOCKS);
    let mut sources: BTreeMap<String, Value> = BTreeMap::new();
    for (id, text) in blocks.as_object().unwrap() {
        let id = id.strip_prefix("json-").unwrap().to_string();
        sources.insert(id, serde_json::from_str(text.as_str().unwrap()).unwrap());
    }
    if let Some(expected) = expected {
        for (id, want) in expected {
            assert_eq!(
                sources.get(id),
                Some(want),
                "{name}: the page's `{id}` block"
            );
        }
        for (id, block) in &sources {
            if id.starts_with("map-") {
                check_map(machine, block, &name);
            }
        }
    }
    let values = values.as_array().unwrap();
    assert!(values.len() > 40, "{name}: only {} values", values.len());
    let mut problems = Vec::new();
    for v in values {
        let (src, path, text) = (
            v["src"].as_str().unwrap(),
            v["path"].as_str().unwrap(),
            v["text"].as_str().unwrap(),
        );
        let source = expected
            .and_then(|e| e.get(src))
            .or_else(|| sources.get(src));
        match source.and_then(|s| s.pointer(path)) {
            None => problems.push(format!("{src} {path}: not in its JSON ({text})")),
            Some(json) => {
                if let Err(why) = equals(json, text) {
                    problems.push(format!("{src} {path}: shows {text}: {why}"));
                }
            }
        }
    }
    assert!(problems.is_empty(), "{name}: {problems:#?}");
}

/// A compensation map block against the door's compensation at its plane:
/// the same statistics, and its points the columns of map.csv.
fn check_map(machine: &Path, block: &Value, name: &str) {
    let z = block["plane_z_mm"].as_f64().unwrap();
    let mut r = CompensateRequest::new(Calibrated::MachineFile(machine.into()));
    r.force = true;
    r.plane_z_mm = Some(z);
    r.spacing_mm = block["spacing_mm"].as_f64().unwrap();
    let c = compensate(r).unwrap();
    let json = c.to_json();
    for key in ["plane_z_mm", "grid_points", "predicted_correction"] {
        assert_eq!(block[key], json[key], "{name}: map at z = {z}: {key}");
    }
    let csv = c.map_csv();
    let mut lines = csv.lines().filter(|l| !l.starts_with('#'));
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    for column in ["x", "y", "correction_mm"] {
        let k = header.iter().position(|h| *h == column).unwrap();
        let want: Vec<f64> = rows.iter().map(|r| r[k]).collect();
        let got: Vec<f64> = block["points"][column]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        assert_eq!(got, want, "{name}: map at z = {z}: column {column}");
    }
}

/// Whether the text shown is the JSON value: a string as it is, a flag as
/// yes/no, an integer exactly, any other number within half a unit of the
/// shown text's last digit.
fn equals(json: &Value, text: &str) -> Result<(), String> {
    match json {
        Value::String(s) if s == text => Ok(()),
        Value::Bool(b) if text == if *b { "yes" } else { "no" } => Ok(()),
        Value::Number(n) if n.is_i64() || n.is_u64() => {
            if n.to_string() == text {
                Ok(())
            } else {
                Err(format!("the integer {n}"))
            }
        }
        Value::Number(n) => {
            let v = n.as_f64().unwrap();
            let shown: f64 = text.parse().map_err(|_| "not a number".to_string())?;
            let unit = last_digit(text);
            if (shown - v).abs() <= 0.5 * unit * (1.0 + 1e-9) {
                Ok(())
            } else {
                Err(format!("{v} is not {shown} to its last digit ({unit})"))
            }
        }
        other => Err(format!("the JSON holds {other}")),
    }
}

/// The value of one unit in the last digit of a decimal text
/// (`0.0579` -> 1e-4, `3.21e-172` -> 1e-174, `208` -> 1).
fn last_digit(text: &str) -> f64 {
    let (mantissa, exponent) = match text.split_once(['e', 'E']) {
        Some((m, e)) => (m, e.parse::<i32>().unwrap_or(0)),
        None => (text, 0),
    };
    let decimals = mantissa.split_once('.').map_or(0, |(_, d)| d.len()) as i32;
    10f64.powi(exponent - decimals)
}

#[test]
fn the_rounding_reader_reads_its_documented_cases() {
    assert_eq!(last_digit("0.0579"), 1e-4);
    assert!((last_digit("3.21e-172") / 1e-174 - 1.0).abs() < 1e-12);
    assert_eq!(last_digit("208"), 1.0);
    assert!(equals(&serde_json::json!(0.057945682797896365), "0.0579").is_ok());
    assert!(equals(&serde_json::json!(0.057945682797896365), "0.0580").is_err());
    assert!(equals(&serde_json::json!(75), "75.0").is_err());
    assert!(equals(&serde_json::json!(true), "yes").is_ok());
}

/// Headings in order, one `h1` first; every figure a captioned plot whose
/// `svg` is an image with a title and a description; the verdict's
/// colours (every level, shown in its legend) at WCAG's contrast for text.
fn accessibility(session: &Session<'_>, name: &str) {
    let headings = session.script(
        "return [...document.querySelectorAll('h1,h2,h3,h4,h5,h6')].map(h => Number(h.tagName[1]))",
    );
    let levels: Vec<u64> = headings
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_u64().unwrap())
        .collect();
    assert_eq!(levels.first(), Some(&1), "{name}: the first heading");
    assert_eq!(
        levels.iter().filter(|l| **l == 1).count(),
        1,
        "{name}: one h1"
    );
    for w in levels.windows(2) {
        assert!(
            w[1] <= w[0] + 1,
            "{name}: a heading skips a level: {levels:?}"
        );
    }
    let figures = session.script(FIGURES);
    for f in figures.as_array().unwrap() {
        assert!(
            f["plots"].as_u64().unwrap() >= 1,
            "{name}: a figure without a plot: {f}"
        );
        assert!(
            f["caption"].as_str().unwrap().len() > 20,
            "{name}: a figure without a caption: {f}"
        );
    }
    let plots = session.script(PLOTS);
    for p in plots.as_array().unwrap() {
        assert_eq!(p["role"], "img", "{name}: {p}");
        assert!(p["title"].as_str().unwrap().len() > 5, "{name}: {p}");
        assert!(p["desc"].as_str().unwrap().len() > 20, "{name}: {p}");
    }
    let colours = session.script(
        "return [...document.querySelectorAll('[data-level]')].map(e => { const s = getComputedStyle(e); return {level: e.dataset.level, color: s.color, background: s.backgroundColor}; })",
    );
    let mut seen = Vec::new();
    for c in colours.as_array().unwrap() {
        let fg = rgb(c["color"].as_str().unwrap());
        let bg = rgb(c["background"].as_str().unwrap());
        let ratio = contrast(fg, bg);
        assert!(
            ratio >= 4.5,
            "{name}: the {} colours {fg:?} on {bg:?} have contrast {ratio:.2}, below WCAG's 4.5:1 for text",
            c["level"]
        );
        seen.push(c["level"].as_str().unwrap().to_string());
    }
    for level in ["trusted", "caution", "do-not-trust"] {
        assert!(
            seen.iter().any(|s| s == level),
            "{name}: no {level} colours shown"
        );
    }
}

/// `rgb(r, g, b)` or `rgba(r, g, b, a)` as CSS computed styles write them.
fn rgb(css: &str) -> [f64; 3] {
    let inner = css
        .trim_start_matches("rgba(")
        .trim_start_matches("rgb(")
        .trim_end_matches(')');
    let parts: Vec<f64> = inner
        .split(',')
        .map(|p| p.trim().parse().unwrap())
        .collect();
    [parts[0], parts[1], parts[2]]
}

/// The contrast ratio of two colours by WCAG 2.2's definitions: "relative
/// luminance [...] L = 0.2126 * R + 0.7152 * G + 0.0722 * B where [...] if
/// RsRGB <= 0.04045 then R = RsRGB/12.92 else R = ((RsRGB+0.055)/1.055) ^
/// 2.4", and "contrast ratio (L1 + 0.05) / (L2 + 0.05), where L1 is the
/// relative luminance of the lighter of the colors". Success criterion
/// 1.4.3 asks 4.5:1 of text.
fn contrast(a: [f64; 3], b: [f64; 3]) -> f64 {
    let channel = |c: f64| {
        let s = c / 255.0;
        if s <= 0.04045 {
            s / 12.92
        } else {
            ((s + 0.055) / 1.055).powf(2.4)
        }
    };
    let luminance =
        |c: [f64; 3]| 0.2126 * channel(c[0]) + 0.7152 * channel(c[1]) + 0.0722 * channel(c[2]);
    let (la, lb) = (luminance(a), luminance(b));
    (la.max(lb) + 0.05) / (la.min(lb) + 0.05)
}

#[test]
fn the_contrast_formula_gives_wcag_s_extremes() {
    assert!((contrast([0.0; 3], [255.0; 3]) - 21.0).abs() < 1e-9);
    assert!((contrast([119.0; 3], [255.0; 3]) - 4.48).abs() < 0.01);
}

/// A PDF printed on A4, a page for the header and one at least for every
/// section (each starts a page).
fn pdf(bytes: &[u8], sections: usize, name: &str) {
    assert!(bytes.starts_with(b"%PDF-"), "{name}: not a PDF");
    let text = String::from_utf8_lossy(bytes);
    let pages = text
        .match_indices("/Type /Page")
        .filter(|(i, _)| !text[i + "/Type /Page".len()..].starts_with('s'))
        .count();
    assert!(
        pages > sections,
        "{name}: {pages} pages for {sections} sections"
    );
    let boxes: Vec<&str> = text
        .match_indices("/MediaBox [")
        .map(|(i, _)| &text[i..])
        .collect();
    assert!(!boxes.is_empty(), "{name}: no page size");
    for b in boxes {
        let inner = &b["/MediaBox [".len()..b.find(']').unwrap()];
        let v: Vec<f64> = inner
            .split_whitespace()
            .map(|x| x.parse().unwrap())
            .collect();
        // A4 is 210 x 297 mm: 595.3 x 841.9 points of 1/72 in.
        let (w, h) = (v[2] - v[0], v[3] - v[1]);
        assert!(
            (w - 595.3).abs() < 2.9 && (h - 841.9).abs() < 2.9,
            "{name}: a page of {w} x {h} pt, not A4"
        );
    }
}

/// The layout at the window's width: the viewport, the page's width, each
/// plot's box, elements past the viewport or wider than their box, and
/// plot texts outside their plot.
const LAYOUT: &str = r#"
const vw = document.documentElement.clientWidth;
const out = {width: vw, scroll: document.documentElement.scrollWidth, plots: [], overflow: [], svgText: []};
const describe = e => e.tagName.toLowerCase() + (e.id ? '#' + e.id : '') + ' "' + (e.textContent || '').trim().slice(0, 60) + '"';
for (const svg of document.querySelectorAll('svg.plot')) {
  const r = svg.getBoundingClientRect();
  out.plots.push({id: svg.id, w: r.width, h: r.height});
  const vb = svg.viewBox.baseVal;
  for (const t of svg.querySelectorAll('text')) {
    const b = t.getBBox();
    if (b.x < vb.x - 0.5 || b.y < vb.y - 0.5 || b.x + b.width > vb.x + vb.width + 0.5 || b.y + b.height > vb.y + vb.height + 0.5)
      out.svgText.push(svg.id + ': ' + t.textContent);
  }
}
for (const e of document.body.querySelectorAll('*')) {
  if (e.closest('svg') || e.tagName === 'SCRIPT') continue;
  const r = e.getBoundingClientRect();
  if (r.width === 0 && r.height === 0) continue;
  if (r.left < -0.5 || r.right > vw + 0.5) { out.overflow.push(describe(e) + ' reaches past the viewport'); continue; }
  if (e.clientWidth > 0 && e.scrollWidth > e.clientWidth + 1) out.overflow.push(describe(e) + ' holds ' + e.scrollWidth + ' px in ' + e.clientWidth);
}
return out;
"#;

/// Every figure: its plots and its caption.
const FIGURES: &str = r#"
return [...document.querySelectorAll('figure')].map(f => ({
  plots: f.querySelectorAll('svg.plot').length,
  caption: (f.querySelector('figcaption') || {textContent: ''}).textContent.trim()
}));
"#;

/// Every plot's role and accessible name and description, from the
/// elements its aria-labelledby and aria-describedby name.
const PLOTS: &str = r#"
const text = id => ((id && document.getElementById(id)) || {textContent: ''}).textContent.trim();
return [...document.querySelectorAll('svg.plot')].map(s => ({
  id: s.id, role: s.getAttribute('role'),
  title: text(s.getAttribute('aria-labelledby')), desc: text(s.getAttribute('aria-describedby'))
}));
"#;

/// Every shown value: its source, its pointer and its text.
const VALUES: &str = r#"
return [...document.querySelectorAll('[data-path]')].map(e => ({src: e.dataset.src, path: e.dataset.path, text: e.textContent}));
"#;

/// The JSON blocks, by id.
const BLOCKS: &str = r#"
return Object.fromEntries([...document.querySelectorAll('script[type="application/json"]')].map(s => [s.id, s.textContent]));
"#;
