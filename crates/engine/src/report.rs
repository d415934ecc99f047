//! The identifiability report: what a pose set and the UP limb's sensors
//! can and cannot tell about the parameters.
//!
//! Everything is computed on the identification matrix after weighting by
//! the sensor noise (`1/sigma` per reading), projecting out the three sensor
//! zero offsets, and scaling every parameter column to unit norm, so that
//! the numbers do not depend on units. With `s_1 >= ... >= s_L` the singular
//! values of the identifiable columns and `m` the number of rows:
//!
//! | index | definition | reference |
//! |---|---|---|
//! | `O1` | `(s_1 s_2 ... s_L)^(1/L) / sqrt(m)` | Borm & Menq (D-optimality) |
//! | `O2` | `s_L / s_1` (inverse condition number) | Driels & Pathre |
//! | `O3` | `s_L` (minimum singular value) | Nahvi et al. (E-optimality) |
//! | `O4` | `s_L^2 / s_1` (noise amplification index) | Nahvi & Hollerbach |
//! | `O5` | `1 / (1/s_1 + ... + 1/s_L)` | Sun & Hollerbach |
//!
//! `a_optimality = 1 / sum(1/s_i^2)` is reported beside them.

use serde::Serialize;
use serde_json::{Map, Value};

use tricept_numerics::lsq::{RankDecision, Solution};

/// Observability indices (see the module docs).
///
#[cfg_attr(
    any(doc, doctest),
    doc = r#"
# Example
```
let o = tricept_engine::report::Observability::from_singular_values(&[4.0, 1.0], 16);
assert_eq!(o.o1, 0.5); // sqrt(4 * 1) / sqrt(16)
assert_eq!(o.o2, 0.25);
assert_eq!(o.o3, 1.0);
assert_eq!(o.o4, 0.25);
assert_eq!(o.o5, 0.8);
```
"#
)]
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Observability {
    /// Borm-Menq: geometric mean of the singular values over sqrt(m).
    #[serde(rename = "O1")]
    pub o1: f64,
    /// Driels-Pathre: inverse condition number.
    #[serde(rename = "O2")]
    pub o2: f64,
    /// Nahvi: minimum singular value.
    #[serde(rename = "O3")]
    pub o3: f64,
    /// Nahvi-Hollerbach: noise amplification index.
    #[serde(rename = "O4")]
    pub o4: f64,
    /// Sun-Hollerbach.
    #[serde(rename = "O5")]
    pub o5: f64,
    /// `1 / sum(1 / s_i^2)`.
    pub a_optimality: f64,
}

impl Observability {
    /// Indices from singular values (any order) and the number of rows.
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_engine::report::Observability;
// Condition number 100: O2 = 0.01 whatever the scale.
let a = Observability::from_singular_values(&[10.0, 0.1], 10);
let b = Observability::from_singular_values(&[1.0, 0.01], 10);
assert!((a.o2 - b.o2).abs() < 1e-15 && (a.o2 - 0.01).abs() < 1e-15);
```
"#
    )]
    pub fn from_singular_values(s: &[f64], rows: usize) -> Observability {
        let l = s.len().max(1) as f64;
        let max = s.iter().copied().fold(0.0, f64::max);
        let min = s.iter().copied().fold(f64::INFINITY, f64::min);
        let min = if min.is_finite() { min } else { 0.0 };
        let log_mean = s.iter().map(|x| x.ln()).sum::<f64>() / l;
        Observability {
            o1: log_mean.exp() / (rows.max(1) as f64).sqrt(),
            o2: if max > 0.0 { min / max } else { 0.0 },
            o3: min,
            o4: if max > 0.0 { min * min / max } else { 0.0 },
            o5: 1.0 / s.iter().map(|x| 1.0 / x).sum::<f64>(),
            a_optimality: 1.0 / s.iter().map(|x| 1.0 / (x * x)).sum::<f64>(),
        }
    }
}

/// A linear combination of parameters, by name (coefficients scaled so the
/// largest is 1).
///
#[cfg_attr(
    any(doc, doctest),
    doc = r#"
# Example
```
use tricept_engine::{model::GeometricModel, IdentifyOptions};
use tricept_kinematics::Machine;
use tricept_model::ParameterSet;
let m = Machine::paper();
let model = GeometricModel::new(m.clone(), ParameterSet::paper15());
let poses: Vec<tricept_data::MeasuredPose> = m
    .workspace
    .polar_grid(3, 8, 3)
    .iter()
    .map(|r| tricept_data::MeasuredPose {
        commands_mm: m.inverse(r).unwrap().legs_mm,
        ..Default::default()
    })
    .collect();
let report = tricept_engine::identify::identifiability(&model, &[0.0; 15], &poses, &IdentifyOptions::for_machine(&m)).unwrap();
let weak = &report.weak[0];
assert!(weak.to_text().contains("dq1"));
assert!(weak.std_dev_mm.unwrap() > 0.1);
```
"#
)]
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Combination {
    /// `(name, coefficient)` pairs, largest coefficient first (in JSON: the
    /// map `combination`).
    #[serde(rename = "combination", serialize_with = "terms_as_map")]
    pub terms: Vec<(String, f64)>,
    /// Singular value of the direction (scaled units).
    pub singular_value: f64,
    /// Standard deviation of `sum(coefficient * parameter)` under the
    /// sensor noise, mm (absent for unidentifiable combinations).
    pub std_dev_mm: Option<f64>,
}

fn terms_as_map<S: serde::Serializer>(terms: &[(String, f64)], s: S) -> Result<S::Ok, S::Error> {
    s.collect_map(terms.iter().map(|(n, c)| (n, c)))
}

impl Combination {
    /// The combination as a JSON map `name -> coefficient`.
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
let c = tricept_engine::report::Combination {
    terms: vec![("dq1".into(), 1.0), ("dq2".into(), -0.5)],
    singular_value: 0.0,
    std_dev_mm: None,
};
assert_eq!(c.to_map()["dq2"], -0.5);
```
"#
    )]
    pub fn to_map(&self) -> Map<String, Value> {
        self.terms
            .iter()
            .map(|(n, c)| (n.clone(), Value::from(*c)))
            .collect()
    }

    /// `1.000 dyA3 - 0.250 dq1 ...`
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
let c = tricept_engine::report::Combination {
    terms: vec![("dyA3".into(), 1.0), ("dq1".into(), -0.25)],
    singular_value: 0.0,
    std_dev_mm: None,
};
assert_eq!(c.to_text(), "1.000 dyA3 - 0.250 dq1");
```
"#
    )]
    pub fn to_text(&self) -> String {
        let mut s = String::new();
        for (i, (n, c)) in self.terms.iter().enumerate() {
            let sign = if *c < 0.0 { "-" } else { "+" };
            if i == 0 {
                s.push_str(&format!(
                    "{}{:.3} {n}",
                    if *c < 0.0 { "-" } else { "" },
                    c.abs()
                ));
            } else {
                s.push_str(&format!(" {sign} {:.3} {n}", c.abs()));
            }
        }
        s
    }
}

/// What a pose set and the sensors can tell about the parameters.
///
#[cfg_attr(
    any(doc, doctest),
    doc = r#"
# Example
```
use tricept_engine::{model::GeometricModel, IdentifyOptions};
use tricept_kinematics::Machine;
use tricept_model::ParameterSet;
let m = Machine::paper();
let model = GeometricModel::new(m.clone(), ParameterSet::paper15());
let poses: Vec<tricept_data::MeasuredPose> = m
    .workspace
    .polar_grid(3, 8, 3)
    .iter()
    .map(|r| tricept_data::MeasuredPose {
        commands_mm: m.inverse(r).unwrap().legs_mm,
        ..Default::default()
    })
    .collect();
let report = tricept_engine::identify::identifiability(&model, &[0.0; 15], &poses, &IdentifyOptions::for_machine(&m)).unwrap();
let json = report.to_json();
assert_eq!(json["n_params"], 15);
assert_eq!(json["unidentifiable"][0]["dyA3"], 1.0);
assert!(report.condition_number > 100.0);
```
"#
)]
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct IdentifiabilityReport {
    /// Parameter names.
    #[serde(skip)]
    pub names: Vec<String>,
    /// Number of parameters.
    pub n_params: usize,
    /// Number of poses.
    pub n_poses: usize,
    /// Numerical rank of the offset-projected, weighted, column-scaled matrix.
    pub rank: usize,
    /// Relative singular-value tolerance of the rank decision.
    pub rank_tolerance: f64,
    /// All singular values, descending (scaled units).
    pub singular_values: Vec<f64>,
    /// `s_max / s_min` over the identifiable parameters (`null` in JSON
    /// when infinite).
    #[serde(serialize_with = "finite_or_null")]
    pub condition_number: f64,
    /// Observability indices over the identifiable parameters.
    pub observability: Observability,
    /// Combinations the data cannot see (first order), one per fixed
    /// parameter (in JSON: `name -> coefficient` maps).
    #[serde(serialize_with = "terms_only")]
    pub unidentifiable: Vec<Combination>,
    /// Parameters held at their prior by the pivoting rule.
    pub fixed: Vec<String>,
    /// Identifiable but weakly determined combinations (`s_i / s_1` below
    /// the weak threshold), with their standard deviation.
    pub weak: Vec<Combination>,
    /// Threshold on `s_i / s_1` for `weak`.
    pub weak_threshold: f64,
    /// Pairs of identifiable parameters with `|correlation| >= 0.9`,
    /// strongest first.
    pub correlated_pairs: Vec<CorrelatedPair>,
    /// Predicted standard deviation of each parameter under the sensor
    /// noise, mm (`None` for fixed parameters).
    pub std_dev_mm: NamedValues,
}

/// Two strongly correlated parameters.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CorrelatedPair {
    /// One parameter.
    pub a: String,
    /// The other.
    pub b: String,
    /// Their correlation.
    pub correlation: f64,
}

/// Optional values by parameter name, in parameter order; a JSON object
/// `name -> value` (`null` where there is none).
///
#[cfg_attr(
    any(doc, doctest),
    doc = r##"
# Example
```
let v = tricept_engine::report::NamedValues(vec![("dq1".into(), Some(0.5)), ("dyA3".into(), None)]);
assert_eq!(serde_json::to_string(&v).unwrap(), r#"{"dq1":0.5,"dyA3":null}"#);
assert_eq!(v.get("dq1"), Some(0.5));
```
"##
)]
#[derive(Debug, Clone, PartialEq, Default)]
pub struct NamedValues(pub Vec<(String, Option<f64>)>);

impl NamedValues {
    /// Pairs `names` with `values`.
    pub fn new(names: &[String], values: &[Option<f64>]) -> NamedValues {
        NamedValues(names.iter().cloned().zip(values.iter().copied()).collect())
    }

    /// The value of `name`, if it has one.
    pub fn get(&self, name: &str) -> Option<f64> {
        self.0.iter().find(|(n, _)| n == name).and_then(|(_, v)| *v)
    }
}

impl Serialize for NamedValues {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_map(self.0.iter().map(|(n, v)| (n, v)))
    }
}

/// Combinations as `name -> coefficient` maps.
fn terms_only<S: serde::Serializer>(v: &[Combination], s: S) -> Result<S::Ok, S::Error> {
    s.collect_seq(v.iter().map(|c| c.to_map()))
}

/// `null` for a non-finite number (JSON has no infinity).
fn finite_or_null<S: serde::Serializer>(x: &f64, s: S) -> Result<S::Ok, S::Error> {
    if x.is_finite() {
        s.serialize_f64(*x)
    } else {
        s.serialize_none()
    }
}

/// Coefficients below this fraction of the largest are dropped from a
/// printed combination.
const COEFFICIENT_CUTOFF: f64 = 1e-4;

pub(crate) fn combination(
    names: &[String],
    v: &[f64],
    singular_value: f64,
    std_dev_mm: Option<f64>,
) -> Combination {
    let largest = v.iter().copied().fold(0.0f64, |a, b| a.max(b.abs()));
    let pivot = v
        .iter()
        .copied()
        .max_by(|a, b| a.abs().total_cmp(&b.abs()))
        .unwrap_or(1.0);
    let sign = if pivot < 0.0 { -1.0 } else { 1.0 };
    let mut terms: Vec<(String, f64)> = names
        .iter()
        .zip(v)
        .filter(|(_, c)| c.abs() > COEFFICIENT_CUTOFF * largest)
        .map(|(n, c)| (n.clone(), sign * c / largest))
        .collect();
    terms.sort_by(|a, b| b.1.abs().total_cmp(&a.1.abs()));
    Combination {
        terms,
        singular_value,
        std_dev_mm,
    }
}

impl IdentifiabilityReport {
    /// Builds the report from a rank decision, the solution's covariance
    /// (nuisance first, `n_nuisance` of them) and the problem size.
    pub(crate) fn new(
        names: &[String],
        decision: &RankDecision,
        solution: &Solution,
        n_nuisance: usize,
        rows: usize,
        n_poses: usize,
        weak_threshold: f64,
    ) -> IdentifiabilityReport {
        let k = names.len();
        let cov = |a: usize, b: usize| solution.covariance[(n_nuisance + a, n_nuisance + b)];
        let identifiable = &decision.identifiable;
        // Singular values of the identifiable columns only.
        let sub_values = identifiable_singular_values(decision);
        let observability = Observability::from_singular_values(&sub_values, rows);
        let max = sub_values.iter().copied().fold(0.0, f64::max);
        let min = sub_values.iter().copied().fold(f64::INFINITY, f64::min);

        let unidentifiable = decision
            .null_space_basis()
            .iter()
            .zip(decision.singular_values[decision.rank..].iter())
            .map(|(v, s)| combination(names, v, *s, None))
            .collect();

        let top = decision.singular_values.first().copied().unwrap_or(0.0);
        let weak = (0..decision.rank)
            .filter(|&i| decision.singular_values[i] < weak_threshold * top)
            .map(|i| {
                let v = decision.direction(i);
                let largest = v.iter().copied().fold(0.0f64, |a, b| a.max(b.abs()));
                let c: Vec<f64> = v.iter().map(|x| x / largest).collect();
                let var: f64 = (0..k)
                    .flat_map(|a| (0..k).map(move |b| (a, b)))
                    .map(|(a, b)| c[a] * c[b] * cov(a, b))
                    .sum();
                combination(
                    names,
                    &v,
                    decision.singular_values[i],
                    Some(var.max(0.0).sqrt()),
                )
            })
            .collect();

        let mut correlated_pairs = Vec::new();
        for (ia, &a) in identifiable.iter().enumerate() {
            for &b in &identifiable[ia + 1..] {
                let r = cov(a, b) / (cov(a, a) * cov(b, b)).sqrt();
                if r.abs() >= 0.9 {
                    correlated_pairs.push(CorrelatedPair {
                        a: names[a].clone(),
                        b: names[b].clone(),
                        correlation: r,
                    });
                }
            }
        }
        correlated_pairs.sort_by(|x, y| y.correlation.abs().total_cmp(&x.correlation.abs()));

        let std_dev_mm: Vec<Option<f64>> = (0..k)
            .map(|j| {
                if decision.fixed.contains(&j) {
                    None
                } else {
                    Some(cov(j, j).max(0.0).sqrt())
                }
            })
            .collect();
        IdentifiabilityReport {
            names: names.to_vec(),
            n_params: k,
            n_poses,
            rank: decision.rank,
            rank_tolerance: decision.tolerance,
            singular_values: decision.singular_values.clone(),
            condition_number: if min > 0.0 { max / min } else { f64::INFINITY },
            observability,
            unidentifiable,
            fixed: decision.fixed.iter().map(|&j| names[j].clone()).collect(),
            weak,
            weak_threshold,
            correlated_pairs,
            std_dev_mm: NamedValues::new(names, &std_dev_mm),
        }
    }

    /// The report as JSON with the contract keys (`rank`, `n_params`,
    /// `unidentifiable` as a list of name -> coefficient maps,
    /// `singular_values`, `condition_number`, `observability`) and more.
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_engine::{model::GeometricModel, IdentifyOptions};
use tricept_kinematics::Machine;
use tricept_model::ParameterSet;
let m = Machine::paper();
let model = GeometricModel::new(m.clone(), ParameterSet::paper15());
let poses: Vec<tricept_data::MeasuredPose> = m
    .workspace
    .polar_grid(3, 8, 3)
    .iter()
    .map(|r| tricept_data::MeasuredPose { commands_mm: m.inverse(r).unwrap().legs_mm, ..Default::default() })
    .collect();
let r = tricept_engine::identify::identifiability(&model, &[0.0; 15], &poses, &IdentifyOptions::for_machine(&m)).unwrap();
let j = r.to_json();
assert_eq!(j["rank"], 14);
assert_eq!(j["unidentifiable"][0]["dyA3"], 1.0);
```
"#
    )]
    pub fn to_json(&self) -> Value {
        serde_json::to_value(self).unwrap_or(Value::Null)
    }

    /// A human-readable summary.
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_engine::{model::GeometricModel, IdentifyOptions};
use tricept_kinematics::Machine;
use tricept_model::ParameterSet;
let m = Machine::paper();
let model = GeometricModel::new(m.clone(), ParameterSet::paper15());
let poses: Vec<tricept_data::MeasuredPose> = m
    .workspace
    .polar_grid(3, 8, 3)
    .iter()
    .map(|r| tricept_data::MeasuredPose { commands_mm: m.inverse(r).unwrap().legs_mm, ..Default::default() })
    .collect();
let r = tricept_engine::identify::identifiability(&model, &[0.0; 15], &poses, &IdentifyOptions::for_machine(&m)).unwrap();
assert!(r.to_text().starts_with("rank 14 of 15 parameters (75 poses"));
```
"#
    )]
    pub fn to_text(&self) -> String {
        let mut s = String::new();
        s.push_str(&format!(
            "rank {} of {} parameters ({} poses; tolerance {:.0e} on s_i/s_1)\n",
            self.rank, self.n_params, self.n_poses, self.rank_tolerance
        ));
        s.push_str(&format!(
            "condition number {:.1} over the identifiable parameters\n",
            self.condition_number
        ));
        let o = &self.observability;
        s.push_str(&format!(
            "observability O1 {:.4e}  O2 {:.4e}  O3 {:.4e}  O4 {:.4e}  O5 {:.4e}\n",
            o.o1, o.o2, o.o3, o.o4, o.o5
        ));
        if self.unidentifiable.is_empty() {
            s.push_str("every parameter is identifiable\n");
        } else {
            s.push_str("unidentifiable (held at the prior; the data cannot see these):\n");
            for c in &self.unidentifiable {
                s.push_str(&format!("  {}\n", c.to_text()));
            }
        }
        if !self.weak.is_empty() {
            s.push_str(&format!(
                "weakly identifiable (s_i/s_1 < {:.0e}):\n",
                self.weak_threshold
            ));
            for c in &self.weak {
                s.push_str(&format!(
                    "  {}   (s = {:.3e}, sd {:.4} mm)\n",
                    c.to_text(),
                    c.singular_value,
                    c.std_dev_mm.unwrap_or(f64::NAN)
                ));
            }
        }
        if !self.correlated_pairs.is_empty() {
            s.push_str("strongly correlated pairs (|r| >= 0.9):\n");
            for p in &self.correlated_pairs {
                s.push_str(&format!("  {} / {}: {:+.3}\n", p.a, p.b, p.correlation));
            }
        }
        s.push_str("predicted standard deviations (mm):\n");
        for (n, sd) in &self.std_dev_mm.0 {
            match sd {
                Some(v) => s.push_str(&format!("  {n:>6} {v:.5}\n")),
                None => s.push_str(&format!("  {n:>6} fixed\n")),
            }
        }
        s
    }
}

/// Singular values of the scaled parameter block restricted to the
/// identifiable columns, computed from the full SVD: the restricted matrix
/// is `U S V^T` with the fixed rows of `V^T` removed.
fn identifiable_singular_values(d: &RankDecision) -> Vec<f64> {
    let k = d.column_scale.len();
    let cols = &d.identifiable;
    // B = S V^T restricted to the identifiable columns: its singular values
    // equal those of the restricted scaled block (U is orthogonal).
    let b = faer::Mat::from_fn(k, cols.len(), |i, j| {
        d.singular_values[i] * d.right_vectors[(cols[j], i)]
    });
    match tricept_numerics::linalg::svd_values_and_vectors(b.as_ref()) {
        Some((s, _)) => s.into_iter().filter(|x| *x > 0.0).collect(),
        None => Vec::new(),
    }
}
