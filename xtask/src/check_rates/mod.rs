//! `cargo xtask check-rates`: the false-alarm rate and the power of
//! `tricept check` on machines and data the project did not generate
//! (issue 31, item 6; the table of docs/check.md, "Measured rates").
//!
//! True machines come from `tricept-truth` (written from the documented
//! conventions alone); each is calibrated by the door's `identify` from 80
//! random poses and its check planned by the door's `plan --instrument
//! check` at 10 and 20 poses. Each scenario (`SCENARIOS`) hides a change,
//! more sensor noise, a jittery temperature log or a bad reading in check
//! campaigns at the planned poses, and the door's `check` judges them. Per
//! scenario and pose count the table gives the exit codes and how often
//! the named change is the hidden one. The campaigns run in parallel
//! (rayon), each seeded by its own indices: the same table at any thread
//! count.
//!
//! The check's result is read through its JSON (`to_json`): `changes[]`
//! when the check gives a set of changes, else the `most_likely`
//! candidate, so the harness reads a richer result unchanged.

#[cfg(test)]
mod tests;
mod truth_side;

use std::collections::BTreeMap;
use std::io::Cursor;
use std::path::{Path, PathBuf};

use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;
use rayon::prelude::*;
use serde_json::Value;
use tricept_ident::advanced::read_data_from;
use tricept_ident::check::{CheckRequest, check};
use tricept_ident::{DataInput, EXIT_INADEQUATE, EXIT_OK};
use tricept_truth::to_csv;

pub use truth_side::{BadReading, Calibrated, Change, Hidden, Scenario};

/// Options of `cargo xtask check-rates`.
#[derive(Debug, clap::Args)]
pub struct CheckRatesArgs {
    /// Check campaigns per scenario and pose count.
    #[arg(long, default_value_t = 50)]
    campaigns: usize,
    /// True machines, each calibrated once (campaign `c` checks machine
    /// `c mod machines`).
    #[arg(long, default_value_t = 10)]
    machines: usize,
    /// Pose counts of the check, each planned by `plan --instrument check
    /// --k N` (comma separated).
    #[arg(long, value_delimiter = ',', default_values_t = vec![10, 20])]
    poses: Vec<usize>,
    /// Seed of the machines and the campaigns.
    #[arg(long, default_value_t = 31)]
    seed: u64,
    /// Print every campaign's hidden change, exit code and named change.
    #[arg(long)]
    verbose: bool,
}

/// One bad reading: the scale off by 25 um.
const BAD_SCALE: Option<BadReading> = Some(BadReading::ScaleUm(25.0));
/// One bad reading: `phi` off by 40 arcsec.
const BAD_PHI: Option<BadReading> = Some(BadReading::PhiArcsec(40.0));
/// The logged temperature's jitter, K per pose.
const JITTER_K: f64 = 0.3;

/// The scenarios of the table, in its order.
pub const SCENARIOS: [Scenario; 14] = [
    Scenario::unchanged("nothing changed"),
    Scenario {
        noise_factor: 1.5,
        ..Scenario::unchanged("nothing changed, 1.5x noise")
    },
    Scenario {
        temp_jitter_k: JITTER_K,
        ..Scenario::unchanged("nothing changed, temperature log 0.3 K jitter")
    },
    Scenario {
        bad: BAD_SCALE,
        ..Scenario::unchanged("nothing changed, one bad reading (s +25 um)")
    },
    Scenario {
        bad: BAD_PHI,
        ..Scenario::unchanged("nothing changed, one bad reading (phi +40 arcsec)")
    },
    Scenario::changed("a leg slipped 20-25 um", Change::LegSlip),
    Scenario::changed("a joint moved 50-60 um", Change::JointMoved),
    Scenario::changed("two legs slipped +25, -25 um", Change::TwoLegs),
    Scenario::changed("legs 4 K warmer, precise log", Change::WarmLegs(4.0)),
    Scenario {
        temp_jitter_k: JITTER_K,
        ..Scenario::changed("legs 4 K warmer, log 0.3 K jitter", Change::WarmLegs(4.0))
    },
    Scenario::changed(
        "structure 4 K warmer, precise log",
        Change::WarmStructure(4.0),
    ),
    Scenario {
        temp_jitter_k: JITTER_K,
        ..Scenario::changed(
            "structure 4 K warmer, log 0.3 K jitter",
            Change::WarmStructure(4.0),
        )
    },
    Scenario {
        bad: BAD_SCALE,
        ..Scenario::changed("a leg slipped + one bad reading (s)", Change::LegSlip)
    },
    Scenario {
        noise_factor: 1.5,
        ..Scenario::changed("a leg slipped + 1.5x noise", Change::LegSlip)
    },
];

/// What one check campaign hid and what the check said.
#[derive(Debug, Clone, PartialEq)]
pub struct Outcome {
    /// Index into [`SCENARIOS`].
    pub scenario: usize,
    /// Poses of the check.
    pub poses: usize,
    /// The campaign's index within its scenario and pose count.
    pub campaign: usize,
    /// The seed of the machine checked.
    pub machine: u64,
    /// What was hidden.
    pub hidden: Hidden,
    /// The check's exit code (of its error when it refused the data).
    pub exit: u8,
    /// The verdict (`unchanged`, `changed`, ...) or `error: ...`.
    pub verdict: String,
    /// The changes the check names: `changes[].name`, else the most likely
    /// candidate.
    pub named: Vec<String>,
    /// The changes the check cannot tell apart from those it names: its
    /// shortlist and the named changes' aliases.
    pub shortlist: Vec<String>,
    /// The line of the bad reading in the campaign's data, if any.
    pub bad_line: Option<u64>,
    /// The lines the check set aside as gross readings (`set_aside[].line`).
    pub set_aside: Vec<u64>,
}

impl Outcome {
    /// Whether the check said what was hidden: exit 0 when nothing changed;
    /// else exit 3 with the hidden changes named (a thermal growth, of the
    /// legs or of the structure, among the named ones; any other change
    /// named exactly, no more and no fewer).
    pub fn right(&self) -> bool {
        let wanted = &self.hidden.names;
        if wanted.is_empty() {
            return self.exit == EXIT_OK;
        }
        if self.exit != EXIT_INADEQUATE {
            return false;
        }
        if wanted.iter().any(|n| is_thermal(n)) {
            return self.named.iter().any(|n| is_thermal(n));
        }
        let mut named = self.named.clone();
        let mut wanted = wanted.clone();
        named.sort();
        wanted.sort();
        named == wanted
    }

    /// Whether the bad reading (if one was hidden) is among the lines the
    /// check set aside.
    pub fn bad_set_aside(&self) -> bool {
        self.bad_line.is_some_and(|l| self.set_aside.contains(&l))
    }

    /// Whether a change was found (exit 3) and every hidden change is
    /// named or on the shortlist of changes the check cannot tell apart.
    pub fn listed(&self) -> bool {
        self.exit == EXIT_INADEQUATE
            && !self.hidden.names.is_empty()
            && self.hidden.names.iter().all(|h| {
                let said = |n: &String| n == h || (is_thermal(h) && is_thermal(n));
                self.named.iter().chain(&self.shortlist).any(said)
            })
    }
}

/// Whether a candidate is a thermal growth: `thermal growth` (of the legs)
/// or `thermal growth of the structure`.
fn is_thermal(name: &str) -> bool {
    name.starts_with("thermal growth")
}

/// The changes a check's JSON names: every `changes[].name`, else the
/// `most_likely` candidate's name (none when unchanged).
pub fn named(v: &Value) -> Vec<String> {
    if let Some(changes) = v["changes"].as_array() {
        return changes
            .iter()
            .filter_map(|c| c["name"].as_str().map(String::from))
            .collect();
    }
    v["most_likely"]
        .as_u64()
        .and_then(|i| v["candidates"][i as usize]["name"].as_str())
        .map(|s| vec![s.to_string()])
        .unwrap_or_default()
}

/// The lines a check's JSON sets aside as gross readings: `rejected[].line`
/// (the key `identify` uses) or `set_aside[].line` (or plain numbers),
/// none when it has neither.
pub fn set_aside_lines(v: &Value) -> Vec<u64> {
    ["rejected", "set_aside"]
        .iter()
        .filter_map(|key| v[*key].as_array())
        .flatten()
        .filter_map(|x| x["line"].as_u64().or_else(|| x.as_u64()))
        .collect()
}

/// The candidates a check's JSON says it cannot tell apart from what it
/// names: the `shortlist` and every `changes[].aliases`.
pub fn alike(v: &Value) -> Vec<String> {
    let strings = |a: &Value| -> Vec<String> {
        a.as_array()
            .map(|l| {
                l.iter()
                    .filter_map(|n| n.as_str().map(String::from))
                    .collect()
            })
            .unwrap_or_default()
    };
    let mut out = strings(&v["shortlist"]);
    for c in v["changes"].as_array().into_iter().flatten() {
        for alias in strings(&c["aliases"]) {
            if !out.contains(&alias) {
                out.push(alias);
            }
        }
    }
    out
}

/// Calibrates `count` true machines (seeds from `seed`) in parallel, their
/// files in `dir`, each with its check planned at every pose count.
pub fn calibrate_machines(
    seed: u64,
    count: usize,
    pose_counts: &[usize],
    dir: &Path,
) -> Result<Vec<Calibrated>, String> {
    (0..count as u64)
        .into_par_iter()
        .map(|i| {
            let s = seed.wrapping_mul(1000).wrapping_add(i);
            Calibrated::new(s, &dir.join(format!("machine-{s}")), pose_counts)
        })
        .collect()
}

/// The seed of campaign `campaign` of scenario `scenario` at `poses`.
fn campaign_seed(seed: u64, scenario: usize, poses: usize, campaign: usize) -> u64 {
    seed.wrapping_mul(0x9e37_79b9_7f4a_7c15)
        ^ ((scenario as u64) << 48)
        ^ ((poses as u64) << 32)
        ^ campaign as u64
}

/// Runs `campaigns` check campaigns of every scenario in `scenarios`
/// (indices into [`SCENARIOS`]) at every pose count, in parallel, in a
/// fixed order.
pub fn outcomes(
    machines: &[Calibrated],
    scenarios: &[usize],
    pose_counts: &[usize],
    campaigns: usize,
    seed: u64,
) -> Result<Vec<Outcome>, String> {
    if machines.is_empty() {
        return Err("no machines to check".into());
    }
    let jobs: Vec<(usize, usize, usize)> = scenarios
        .iter()
        .flat_map(|&s| {
            pose_counts
                .iter()
                .flat_map(move |&k| (0..campaigns).map(move |c| (s, k, c)))
        })
        .collect();
    jobs.into_par_iter()
        .map(|(s, k, c)| {
            let scenario = SCENARIOS.get(s).ok_or_else(|| format!("no scenario {s}"))?;
            let machine = &machines[c % machines.len()];
            let commands = machine
                .commands(k)
                .ok_or_else(|| format!("machine {}: no {k}-pose plan", machine.seed))?;
            let mut rng = Pcg64Mcg::seed_from_u64(campaign_seed(seed, s, k, c));
            let (rows, hidden) = machine.campaign(scenario, commands, c, &mut rng);
            let name = format!("check-{s}-{k}-{c}.csv");
            let data = read_data_from(Cursor::new(to_csv(&rows)), &name, machine.loaded.geometry())
                .map_err(|e| e.to_string())?;
            let bad_line = hidden
                .bad_row
                .and_then(|i| data.poses.get(i))
                .map(|p| p.line);
            let request = CheckRequest::new(machine.loaded.clone(), DataInput::Memory(data));
            let (exit, verdict, named, shortlist, set_aside) = match check(request) {
                Ok(r) => {
                    let v: Value = r.to_json();
                    let verdict = v["verdict"].as_str().unwrap_or("?").to_string();
                    let shortlist = alike(&v);
                    (
                        r.exit_code(),
                        verdict,
                        named(&v),
                        shortlist,
                        set_aside_lines(&v),
                    )
                }
                Err(e) => (
                    e.exit_code(),
                    format!("error: {}", e.message()),
                    Vec::new(),
                    Vec::new(),
                    Vec::new(),
                ),
            };
            Ok(Outcome {
                scenario: s,
                poses: k,
                campaign: c,
                machine: machine.seed,
                hidden,
                exit,
                verdict,
                named,
                shortlist,
                bad_line,
                set_aside,
            })
        })
        .collect()
}

/// The outcomes of one scenario at one pose count, counted.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Tally {
    /// Index into [`SCENARIOS`].
    pub scenario: usize,
    /// Poses of the check.
    pub poses: usize,
    /// Campaigns.
    pub campaigns: usize,
    /// Campaigns that exited 0.
    pub exit_ok: usize,
    /// Campaigns that exited 3 (a change found).
    pub exit_changed: usize,
    /// Campaigns where the check said what was hidden ([`Outcome::right`]).
    pub right: usize,
    /// Campaigns of a hidden change where it was found and is named or on
    /// the shortlist ([`Outcome::listed`]).
    pub listed: usize,
    /// Campaigns whose bad reading the check set aside
    /// ([`Outcome::bad_set_aside`]).
    pub bad_set_aside: usize,
    /// Campaigns per verdict.
    pub verdicts: BTreeMap<String, usize>,
}

/// The outcomes counted per scenario and pose count, in their order.
pub fn tallies(outcomes: &[Outcome]) -> Vec<Tally> {
    let mut out: Vec<Tally> = Vec::new();
    for o in outcomes {
        let t = match out
            .iter_mut()
            .find(|t| t.scenario == o.scenario && t.poses == o.poses)
        {
            Some(t) => t,
            None => {
                out.push(Tally {
                    scenario: o.scenario,
                    poses: o.poses,
                    campaigns: 0,
                    exit_ok: 0,
                    exit_changed: 0,
                    right: 0,
                    listed: 0,
                    bad_set_aside: 0,
                    verdicts: BTreeMap::new(),
                });
                let last = out.len() - 1;
                &mut out[last]
            }
        };
        t.campaigns += 1;
        t.exit_ok += usize::from(o.exit == EXIT_OK);
        t.exit_changed += usize::from(o.exit == EXIT_INADEQUATE);
        t.right += usize::from(o.right());
        t.listed += usize::from(o.listed());
        t.bad_set_aside += usize::from(o.bad_set_aside());
        let verdict = match o.verdict.strip_prefix("error: ") {
            Some(_) => format!("exit {}", o.exit),
            None => o.verdict.clone(),
        };
        *t.verdicts.entry(verdict).or_default() += 1;
    }
    out
}

/// The tallies as the Markdown table of docs/check.md.
pub fn table(tallies: &[Tally]) -> String {
    let mut s = String::from(
        "| scenario | poses | exit 0 | exit 3 | said what was hidden | hidden change on the shortlist | bad reading set aside | verdicts |\n|---|---|---|---|---|---|---|---|\n",
    );
    for t in tallies {
        let name = SCENARIOS.get(t.scenario).map_or("?", |s| s.name);
        let verdicts: Vec<String> = t.verdicts.iter().map(|(v, n)| format!("{v} {n}")).collect();
        let n = t.campaigns;
        let listed = match SCENARIOS.get(t.scenario).map(|s| s.change) {
            Some(Change::None) | None => String::new(),
            Some(_) => format!("{}/{n}", t.listed),
        };
        let set_aside = match SCENARIOS.get(t.scenario).and_then(|s| s.bad) {
            Some(_) => format!("{}/{n}", t.bad_set_aside),
            None => String::new(),
        };
        s.push_str(&format!(
            "| {name} | {} | {}/{n} | {}/{n} | {}/{n} | {listed} | {set_aside} | {} |\n",
            t.poses,
            t.exit_ok,
            t.exit_changed,
            t.right,
            verdicts.join(", ")
        ));
    }
    s
}

/// A scratch directory for the machine files, removed when dropped.
struct Scratch(PathBuf);

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// `cargo xtask check-rates`: calibrates the machines, runs every
/// scenario's campaigns and prints the table.
pub fn run(a: CheckRatesArgs) -> Result<(), String> {
    if a.campaigns == 0 || a.machines == 0 || a.poses.is_empty() || a.poses.contains(&0) {
        return Err("--campaigns, --machines and --poses must be positive".into());
    }
    let started = std::time::Instant::now();
    let scratch =
        Scratch(std::env::temp_dir().join(format!("tricept-check-rates-{}", std::process::id())));
    let machines = calibrate_machines(a.seed, a.machines, &a.poses, &scratch.0)?;
    eprintln!(
        "{} machines calibrated from {} poses and their checks planned in {:.1} s",
        machines.len(),
        truth_side::CALIBRATION_POSES,
        started.elapsed().as_secs_f64()
    );
    let all: Vec<usize> = (0..SCENARIOS.len()).collect();
    let outcomes = outcomes(&machines, &all, &a.poses, a.campaigns, a.seed)?;
    if a.verbose {
        for o in &outcomes {
            println!(
                "{} | {} poses | #{} machine {} | hidden {} | exit {} {} | named {:?} | shortlist {:?} | bad line {:?} set aside {:?} | {}",
                SCENARIOS[o.scenario].name,
                o.poses,
                o.campaign,
                o.machine,
                o.hidden.text,
                o.exit,
                o.verdict,
                o.named,
                o.shortlist,
                o.bad_line,
                o.set_aside,
                if o.right() { "right" } else { "WRONG" }
            );
        }
    }
    println!(
        "`cargo xtask check-rates --campaigns {} --machines {} --seed {}`: {} campaigns in {:.1} s\n",
        a.campaigns,
        a.machines,
        a.seed,
        outcomes.len(),
        started.elapsed().as_secs_f64()
    );
    print!("{}", table(&tallies(&outcomes)));
    Ok(())
}
