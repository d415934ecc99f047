//! The page's building blocks: its style sheet (screen, narrow screens and
//! A4 print, a page break before every section), sections, figures,
//! tables and lists. Every text goes through [`escape`]; every value
//! through [`crate::json::Lookup`].

use std::fmt::Write as _;

use crate::json::escape;

/// The page's style sheet: no web font, no image, nothing fetched.
pub const STYLE: &str = r#"
:root{--fg:#1b1b1b;--muted:#555;--line:#cfcfcf;--s1:#0072b2;--s2:#d55e00;--s3:#009e73;--s4:#cc79a7;--s5:#e69f00;--bad:#b3171d}
*{box-sizing:border-box}
html{font:16px/1.45 system-ui,-apple-system,"Segoe UI",Roboto,"Noto Sans","DejaVu Sans",sans-serif;color:var(--fg);background:#fff}
body{margin:0 auto;max-width:62rem;padding:1rem}
h1{font-size:1.55rem;line-height:1.25;margin:.2rem 0 .5rem}
h2{font-size:1.3rem;border-bottom:2px solid var(--line);padding-bottom:.2rem;margin:2.2rem 0 .6rem}
h3{font-size:1.05rem;margin:1.3rem 0 .4rem}
body,p,li,dt,dd,td,th,h1,h2,h3,figcaption,code{overflow-wrap:anywhere}
code{font-size:.9em}
.muted{color:var(--muted)}
.verdict{border:2px solid;border-radius:.4rem;padding:.7rem 1rem;margin:.8rem 0}
.verdict .words{font-size:1.5rem;font-weight:700;margin:0 0 .2rem}
.verdict ul{margin:.4rem 0 0;padding-left:1.2rem}
[data-level=trusted]{color:#0b5a29;background:#e4f3e8;border-color:#0b5a29}
[data-level=caution]{color:#6a3d00;background:#fff0d4;border-color:#6a3d00}
[data-level=do-not-trust]{color:#971016;background:#fde7e7;border-color:#971016}
.levels{display:flex;flex-wrap:wrap;gap:.4rem;padding:0;list-style:none;font-size:.85rem}
.levels li{border:1px solid;border-radius:.3rem;padding:.1rem .4rem}
dl.facts{display:grid;grid-template-columns:minmax(7rem,13rem) 1fr;gap:.25rem 1rem;margin:.6rem 0}
dl.facts dt{font-weight:600}
dl.facts dd{margin:0}
table{border-collapse:collapse;width:100%;table-layout:fixed;font-size:.88rem;margin:.4rem 0 .8rem}
th,td{border-bottom:1px solid var(--line);padding:.2rem .3rem;text-align:left;vertical-align:top}
th{font-weight:600}
.num{text-align:right;font-variant-numeric:tabular-nums}
figure{margin:1rem 0;break-inside:avoid}
figcaption{font-size:.88rem;color:var(--muted);margin-top:.3rem}
svg.plot{display:block;width:100%;height:auto;max-width:40rem}
.row{display:flex;flex-wrap:wrap;gap:.6rem}
.row svg.plot{flex:1 1 15rem;max-width:20rem;min-width:0}
svg text{font-family:inherit;font-size:12px;fill:var(--fg)}
svg .tick{font-size:11px;fill:var(--muted)}
svg .axis{font-size:12px;fill:var(--muted)}
svg .frame{fill:none;stroke:#8a8a8a}
svg .grid{stroke:#e6e6e6}
svg .s1{stroke:var(--s1);fill:var(--s1)}
svg .s2{stroke:var(--s2);fill:var(--s2)}
svg .s3{stroke:var(--s3);fill:var(--s3)}
svg .s4{stroke:var(--s4);fill:var(--s4)}
svg .s5{stroke:var(--s5);fill:var(--s5)}
svg polyline{fill:none;stroke-width:1.6}
svg .open{fill:#fff;stroke-width:1.5}
svg .bad{stroke:var(--bad);fill:var(--bad)}
svg .ok{stroke:#0b5a29;fill:#0b5a29}
svg .warn{stroke:#a86400;fill:#a86400}
svg .ref{stroke:#333;stroke-dasharray:4 3;fill:none}
svg .band{fill:#0072b2;fill-opacity:.13;stroke:none}
svg .whisker{stroke-width:1.4}
svg .cell{stroke:none}
.legend{display:flex;flex-wrap:wrap;gap:.2rem 1rem;font-size:.85rem;padding:0;margin:.2rem 0;list-style:none}
.key{display:inline-block;width:.9rem;height:.5rem;margin-right:.3rem;vertical-align:middle}
.key.s1{background:var(--s1)}.key.s2{background:var(--s2)}.key.s3{background:var(--s3)}.key.s4{background:var(--s4)}.key.s5{background:var(--s5)}.key.bad{background:var(--bad)}
@media (max-width:40rem){body{padding:.6rem}dl.facts{grid-template-columns:1fr}dl.facts dd{margin-bottom:.3rem}table{font-size:.8rem}}
@page{size:A4;margin:14mm 12mm}
@media print{html{font-size:10pt}body{max-width:none;padding:0}section{break-before:page}h2{margin-top:0}.verdict,[data-level],svg{print-color-adjust:exact;-webkit-print-color-adjust:exact}figure,table,tr{break-inside:avoid}}
"#;

/// A `<section>` with its heading (`h2`), labelled by it.
pub fn section(id: &str, title: &str, body: &str) -> String {
    format!(
        "<section id=\"{id}\" aria-labelledby=\"{id}-h\">\n<h2 id=\"{id}-h\">{}</h2>\n{body}</section>\n",
        escape(title)
    )
}

/// A figure: one or more plots (in a row when several) and its caption.
pub fn figure(plots: &[String], caption: &str) -> String {
    let inner = if plots.len() > 1 {
        format!("<div class=\"row\">{}</div>", plots.concat())
    } else {
        plots.concat()
    };
    format!("<figure>{inner}<figcaption>{caption}</figcaption></figure>\n")
}

/// A table with a caption-less header row; `numeric` right-aligns the
/// columns that hold numbers. Cells are HTML already.
pub fn table(head: &[&str], numeric: &[bool], rows: &[Vec<String>]) -> String {
    let mut s = String::from("<table><thead><tr>");
    let class = |k: usize| {
        if numeric.get(k).copied().unwrap_or(false) {
            " class=\"num\""
        } else {
            ""
        }
    };
    for (k, h) in head.iter().enumerate() {
        let _ = write!(s, "<th scope=\"col\"{}>{}</th>", class(k), escape(h));
    }
    s.push_str("</tr></thead><tbody>");
    for row in rows {
        s.push_str("<tr>");
        for (k, cell) in row.iter().enumerate() {
            let _ = write!(s, "<td{}>{cell}</td>", class(k));
        }
        s.push_str("</tr>");
    }
    s.push_str("</tbody></table>\n");
    s
}

/// A bulleted list of HTML items (nothing when there are none).
pub fn list(items: &[String]) -> String {
    if items.is_empty() {
        return String::new();
    }
    let mut s = String::from("<ul>");
    for i in items {
        let _ = write!(s, "<li>{i}</li>");
    }
    s.push_str("</ul>\n");
    s
}

/// A paragraph of HTML.
pub fn p(html: &str) -> String {
    format!("<p>{html}</p>\n")
}

/// A legend: each series' colour class and its name.
pub fn legend(entries: &[(&str, String)]) -> String {
    let mut s = String::from("<ul class=\"legend\">");
    for (class, name) in entries {
        let _ = write!(
            s,
            "<li><span class=\"key {class}\" aria-hidden=\"true\"></span>{}</li>",
            escape(name)
        );
    }
    s.push_str("</ul>");
    s
}

/// The colour class of the `k`-th series (0-based).
pub fn series(k: usize) -> &'static str {
    ["s1", "s2", "s3", "s4", "s5"][k % 5]
}
