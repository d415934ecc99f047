//! The header: the machine, the verdict in words and colour with the
//! reasons it rests on, and the numbers behind it (the accuracy promise,
//! when and from what the machine was calibrated, the last check, the
//! controller files), then what the verdict's colours mean.

use crate::json::{Digits, Lookup, escape};
use crate::sources::Sources;
use crate::verdict::{Level, Verdict};

/// The `<header>` of the page.
pub fn header(l: &Lookup<'_>, sources: &Sources, verdict: &Verdict) -> String {
    let m = "machine";
    let mut s = String::from("<header>\n<p class=\"muted\">tricept calibration report</p>\n");
    s.push_str(&format!("<h1>{}</h1>\n", l.text(m, "/name")));
    s.push_str(&format!(
        "<div class=\"verdict\" id=\"verdict\" data-level=\"{}\">\n<p class=\"words\">{}</p>\n<p>{}</p>\n<ul>",
        verdict.level.as_str(),
        l.text("verdict", "/words"),
        escape(verdict.level.meaning())
    ));
    for (k, r) in verdict.reasons.iter().enumerate() {
        let values: Vec<String> = r
            .shows
            .iter()
            .map(|v| {
                let key = v.path.rsplit('/').next().unwrap_or_default();
                let key = key.replace("~1", "/").replace("~0", "~");
                format!(
                    "{} {}",
                    escape(&key),
                    l.show(&v.src, &v.path, Digits::Sig(4))
                )
            })
            .collect();
        let values = if values.is_empty() {
            String::new()
        } else {
            format!(": {}", values.join(", "))
        };
        s.push_str(&format!(
            "<li data-level-of=\"{}\">{}{values}</li>",
            r.level.as_str(),
            l.text("verdict", &format!("/reasons/{k}/says"))
        ));
    }
    s.push_str("</ul>\n</div>\n<dl class=\"facts\">\n");
    let a = "/calibration/accuracy";
    let promise = if l.get(m, a).is_some() {
        format!(
            "rms {} mm, 95 % upper bound {} mm, at the {} (what a file commanded in the state of its campaign delivers over the workspace)",
            l.num(m, &format!("{a}/rms_mm")),
            l.num(m, &format!("{a}/upper_mm")),
            l.text(m, &format!("{a}/point"))
        )
    } else {
        "none stated (a file written before files carried one)".into()
    };
    fact(&mut s, "Accuracy promise", &promise);
    let c = |k: &str| format!("/calibration/{k}");
    fact(
        &mut s,
        "Calibrated",
        &format!(
            "{} by <code>tricept {}</code> (version {}) from {}: {} poses, chi-square per degree of freedom {} on {} degrees of freedom",
            l.text(m, &c("date")),
            l.text(m, &c("method")),
            l.text(m, &c("tool_version")),
            l.text(m, &c("data_file")),
            l.num(m, &c("poses_used")),
            l.num(m, &c("chi2_per_dof")),
            l.num(m, &c("dof"))
        ),
    );
    fact(
        &mut s,
        "Campaign's SHA-256",
        &format!("<code>{}</code>", l.text(m, &c("data_sha256"))),
    );
    fact(&mut s, "Last check", &last_check(l, sources));
    let export = if sources.export.is_some() {
        format!(
            "{} files for the {}; format errors within {} um: {} (section 6)",
            l.text("export", "/controller"),
            l.text("export", "/control"),
            l.num("export", "/tolerance_um"),
            l.text("export", "/within_tolerance")
        )
    } else {
        "none given (export)".into()
    };
    fact(&mut s, "Controller files", &export);
    fact(
        &mut s,
        "Calibration digest",
        &format!("<code>{}</code>", l.text("verdict", "/calibration_digest")),
    );
    s.push_str("</dl>\n<ul class=\"levels\" aria-label=\"What the verdict's colours mean\">");
    for level in [Level::Trusted, Level::Caution, Level::DoNotTrust] {
        s.push_str(&format!(
            "<li data-level=\"{}\">{}: {}</li>",
            level.as_str(),
            level.words(),
            escape(level.meaning())
        ));
    }
    s.push_str("</ul>\n</header>\n");
    s
}

fn fact(s: &mut String, term: &str, html: &str) {
    s.push_str(&format!("<dt>{}</dt><dd>{html}</dd>\n", escape(term)));
}

/// The last check of the history: its verdict, when, what changed.
fn last_check(l: &Lookup<'_>, sources: &Sources) -> String {
    let n = sources
        .history
        .as_ref()
        .and_then(|h| h.json.as_array())
        .map_or(0, Vec::len);
    if n == 0 {
        return "none on record (history)".into();
    }
    let p = |k: &str| format!("/{}/{k}", n - 1);
    let mut s = format!(
        "{} on {} (campaign {})",
        l.text("history", &p("verdict")),
        l.text("history", &p("time")),
        l.text("history", &p("data_file"))
    );
    if l.str("history", &p("most_likely")).is_some() {
        s.push_str(&format!(
            "; most likely {}",
            l.text("history", &p("most_likely"))
        ));
    }
    s.push_str(" (section 5)");
    s
}
