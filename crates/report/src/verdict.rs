//! The page's verdict: one of three levels, in words and colour, with the
//! reasons it rests on, each naming the values (source and JSON pointer)
//! it reads. The rule, in order (docs/report.md):
//!
//! - **do not trust** (red; the door's exit code 3) when the calibration's
//!   fit did not converge, was written with `--force`, or its model did not
//!   explain its data (`calibration.converged`, `.forced`, `.adequate`), or
//!   when the last check of the history found the machine changed
//!   (`changed`, `changed-unexplained`);
//! - **use with caution** (amber) when the last check found the readings
//!   noisier than stated, the file states no accuracy promise, the
//!   campaign's diagnosis leaves a remainder or names causes a geometric
//!   file does not deploy, or a history line or the export names no
//!   calibration (written before they did);
//! - **trusted** (green) otherwise.
//!
//! The reasons of the lower levels are kept (a red page still says that
//! the fit converged), so the page shows everything the verdict read.

use serde::Serialize;
use serde_json::Value;

use crate::json::{Lookup, token};
use crate::sources::Sources;

/// How far the machine can be trusted, worst last.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Level {
    /// Green: nothing on record speaks against the calibration.
    Trusted,
    /// Amber: usable, with something to look at first.
    Caution,
    /// Red: the calibration is not to be relied on.
    DoNotTrust,
}

impl Level {
    /// The level in words, as the page's verdict says it.
    pub fn words(self) -> &'static str {
        match self {
            Level::Trusted => "TRUSTED",
            Level::Caution => "USE WITH CAUTION",
            Level::DoNotTrust => "DO NOT TRUST",
        }
    }

    /// The level's name in the page and its JSON (`trusted`, `caution`,
    /// `do-not-trust`).
    pub fn as_str(self) -> &'static str {
        match self {
            Level::Trusted => "trusted",
            Level::Caution => "caution",
            Level::DoNotTrust => "do-not-trust",
        }
    }

    /// What the level asks of the reader.
    pub fn meaning(self) -> &'static str {
        match self {
            Level::Trusted => "nothing on record speaks against this calibration",
            Level::Caution => "usable; read the notes below first",
            Level::DoNotTrust => {
                "do not rely on this calibration: find why (below) or calibrate again"
            }
        }
    }
}

/// A value a reason reads: its source and JSON pointer.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Shown {
    /// The source's id on the page.
    pub src: String,
    /// The JSON pointer of the value.
    pub path: String,
}

/// One reason of the verdict.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Reason {
    /// The level this reason calls for.
    pub level: Level,
    /// What it says, one sentence.
    pub says: String,
    /// The values it reads.
    pub shows: Vec<Shown>,
}

/// The verdict of a page.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Verdict {
    /// The worst level of the reasons.
    pub level: Level,
    /// The level in words.
    pub words: String,
    /// The digest of the calibration the page is about.
    pub calibration_digest: String,
    /// Every reason, worst first.
    pub reasons: Vec<Reason>,
}

impl Verdict {
    /// The verdict as the JSON block of the page.
    pub fn to_json(&self) -> Value {
        serde_json::to_value(self).unwrap_or(Value::Null)
    }
}

fn shown(src: &str, paths: &[String]) -> Vec<Shown> {
    paths
        .iter()
        .map(|p| Shown {
            src: src.to_string(),
            path: p.clone(),
        })
        .collect()
}

/// The verdict of `sources`; `unnamed` are the history's checks (0-based)
/// that name no calibration, `export_named` whether the export names one.
pub fn verdict(sources: &Sources, unnamed: &[usize], export_named: bool) -> Verdict {
    let list = sources.lookup_list();
    let l = Lookup::new(&list);
    let mut reasons = Vec::new();
    let mut reason = |level: Level, says: &str, src: &str, paths: &[&str]| {
        let paths: Vec<String> = paths.iter().map(|p| p.to_string()).collect();
        reasons.push(Reason {
            level,
            says: says.to_string(),
            shows: shown(src, &paths),
        });
    };
    let flag = |p: &str| l.get("machine", p).and_then(Value::as_bool);
    let c = "/calibration";
    if flag("/calibration/converged") == Some(false) {
        reason(
            Level::DoNotTrust,
            "the calibration's fit did not converge: its estimates are not a calibration",
            "machine",
            &["/calibration/converged"],
        );
    }
    if flag("/calibration/forced") == Some(true) {
        reason(
            Level::DoNotTrust,
            "the file was written although its fit is not to be trusted (forced)",
            "machine",
            &["/calibration/forced", "/calibration/warnings/0"],
        );
    }
    if flag("/calibration/adequate") == Some(false) {
        reason(
            Level::DoNotTrust,
            "the calibration's model did not explain its data (chi-square per degree of freedom)",
            "machine",
            &["/calibration/adequate", "/calibration/chi2_per_dof"],
        );
    }
    if flag("/calibration/converged") == Some(true) && flag("/calibration/adequate") == Some(true) {
        reason(
            Level::Trusted,
            "the calibration's fit converged and its model explains its data to the stated noise",
            "machine",
            &["/calibration/converged", "/calibration/adequate"],
        );
    }
    if l.get("machine", &format!("{c}/accuracy")).is_none() {
        reason(
            Level::Caution,
            "the file states no accuracy promise (written before files carried one): calibrate again for one",
            "machine",
            &["/calibration/date"],
        );
    }
    let checks = sources
        .history
        .as_ref()
        .and_then(|h| h.json.as_array())
        .map_or(0, Vec::len);
    if checks == 0 {
        reason(
            Level::Trusted,
            "no daily check on record (give the check history, CHECKS.jsonl, that a check with a history writes)",
            "machine",
            &[],
        );
    } else {
        let last = format!("/{}", checks - 1);
        let p = |key: &str| format!("{last}/{key}");
        let verdict = l.str("history", &p("verdict")).unwrap_or_default();
        let (level, says) = match verdict {
            "changed" | "changed-unexplained" => (
                Level::DoNotTrust,
                "the last check found the machine changed since its calibration",
            ),
            "noisier-than-stated" => (
                Level::Caution,
                "the last check found the readings noisier than stated (not a change of the machine): state the noise or service the sensors",
            ),
            "unchanged" => (Level::Trusted, "the last check found the machine unchanged"),
            _ => (
                Level::Caution,
                "the last check's verdict is not one tricept writes",
            ),
        };
        let mut paths = vec![p("verdict"), p("time")];
        if l.get("history", &p("most_likely"))
            .is_some_and(|v| !v.is_null())
        {
            paths.push(p("most_likely"));
        }
        let refs: Vec<&str> = paths.iter().map(String::as_str).collect();
        reason(level, says, "history", &refs);
    }
    if let Some(&k) = unnamed.first() {
        reason(
            Level::Caution,
            "the history's checks from this one on name no calibration (written before checks named it): the page cannot tell whether they are checks of this calibration",
            "history",
            &[&format!("/{k}/time")],
        );
    }
    if sources.export.is_some() && !export_named {
        reason(
            Level::Caution,
            "the export names no calibration (written before exports named it): the page cannot tell whether it is an export of this calibration; export again",
            "export",
            &["/control"],
        );
    }
    if sources.diagnosis.is_some() {
        diagnosis_reasons(&l, &mut reason);
    }
    reasons.sort_by_key(|r| std::cmp::Reverse(r.level));
    let level = reasons.first().map_or(Level::Trusted, |r| r.level);
    Verdict {
        level,
        words: level.words().to_string(),
        calibration_digest: sources.calibration_digest.clone(),
        reasons,
    }
}

/// What the campaign's diagnosis adds: a remainder, or causes a geometric
/// file does not deploy.
fn diagnosis_reasons(l: &Lookup<'_>, reason: &mut impl FnMut(Level, &str, &str, &[&str])) {
    if l.get("diagnosis", "/final_adequate")
        .and_then(Value::as_bool)
        == Some(false)
    {
        reason(
            Level::Caution,
            "the campaign's diagnosis leaves a misfit no named cause explains (its verdict and remainder below)",
            "diagnosis",
            &["/verdict"],
        );
    }
    let geometric = l.str("machine", "/calibration/method") == Some("identify");
    let causes = l.array("diagnosis", "/causes");
    if geometric && !causes.is_empty() {
        let paths: Vec<String> = (0..causes.len())
            .map(|k| format!("/causes/{k}/{}", token("effect")))
            .collect();
        let refs: Vec<&str> = paths.iter().map(String::as_str).collect();
        reason(
            Level::Caution,
            "the campaign's diagnosis names causes this geometric-only file does not deploy (a machine file a diagnosis writes deploys them)",
            "diagnosis",
            &refs,
        );
    }
}
