//! Geometric error parameters: the full 21-parameter vector, the paper's
//! 15-parameter set, and the linear map between them.
//!
//! The full vector stacks, limb by limb, `deps_i = [db_i; da_0i; dq_i]`
//! (eq. 9): the error of the base joint `B_i` in Oxyz, of the platform joint
//! `A_i` in O'x'y'z', and of the leg length (actual = command + `dq_i`), all
//! in mm. Its names are `dxB1 dyB1 dzB1 dxA1 dyA1 dzA1 dq1 dxB2 ... dq3`.
//!
//! A [`ParameterSet`] is a named linear subspace of that space: `k` names and
//! a `21 x k` embedding matrix `E`, so that `deps = E p`. The paper's frame
//! conventions (Oxy through B1, B2, B4 with y parallel to B1B2; O'x'y'
//! through A1, A2, A3) set `dzB1 = dzB2 = dzA1 = dzA2 = dzA3 = 0` and
//! `dxB2 = dxB1`, which leaves [`ParameterSet::paper15`]:
//! `dxB1 dyB1 dyB2 dxB3 dyB3 dzB3 dxA1 dyA1 dxA2 dyA2 dxA3 dyA3 dq1 dq2 dq3`,
//! where `dxB1` moves both B1 and B2 along x.

use nalgebra::Vector3;
use serde_json::{Map, Value};

use crate::error::ModelError;

/// Number of parameters in the full error vector.
pub const N_FULL: usize = 21;

/// Names of the full 21-parameter vector, in storage order.
pub const FULL21_NAMES: [&str; N_FULL] = [
    "dxB1", "dyB1", "dzB1", "dxA1", "dyA1", "dzA1", "dq1", //
    "dxB2", "dyB2", "dzB2", "dxA2", "dyA2", "dzA2", "dq2", //
    "dxB3", "dyB3", "dzB3", "dxA3", "dyA3", "dzA3", "dq3",
];

/// Names of the paper's 15-parameter set, in the paper's (Table 2) order.
pub const PAPER15_NAMES: [&str; 15] = [
    "dxB1", "dyB1", "dyB2", "dxB3", "dyB3", "dzB3", "dxA1", "dyA1", "dxA2", "dyA2", "dxA3", "dyA3",
    "dq1", "dq2", "dq3",
];

/// The JSON text of Table 2 (`fixtures/errors/table2.json`), embedded.
pub const TABLE2_JSON: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../fixtures/errors/table2.json"
));

/// The full geometric error vector of the parallel module, mm.
///
#[cfg_attr(
    any(doc, doctest),
    doc = r#"
# Example
```
use tricept_model::{GeometricErrors, ParameterSet};
let set = ParameterSet::paper15();
let e = set.to_errors(&set.table2());
// dxB1 = 0.2 mm moves B1 and B2 alike (the paper's convention dxB1 = dxB2).
assert_eq!(e.db_mm[0].x, 0.2);
assert_eq!(e.db_mm[1].x, 0.2);
assert_eq!(e.dq_mm, [0.45, 0.7, 0.5]);
```
"#
)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct GeometricErrors {
    /// Errors of the base joints `B_1..B_3` in Oxyz, mm.
    pub db_mm: [Vector3<f64>; 3],
    /// Errors of the platform joints `A_1..A_3` in O'x'y'z', mm.
    pub da_mm: [Vector3<f64>; 3],
    /// Leg length errors: actual length = command + `dq_i`, mm.
    pub dq_mm: [f64; 3],
}

impl GeometricErrors {
    /// The 21 values in storage order ([`FULL21_NAMES`]).
    pub fn to_array(&self) -> [f64; N_FULL] {
        let mut out = [0.0; N_FULL];
        for i in 0..3 {
            let block = &mut out[7 * i..7 * i + 7];
            block[..3].copy_from_slice(self.db_mm[i].as_slice());
            block[3..6].copy_from_slice(self.da_mm[i].as_slice());
            block[6] = self.dq_mm[i];
        }
        out
    }

    /// Builds from 21 values in storage order.
    pub fn from_array(v: &[f64; N_FULL]) -> GeometricErrors {
        let mut e = GeometricErrors::default();
        for i in 0..3 {
            let b = &v[7 * i..7 * i + 7];
            e.db_mm[i] = Vector3::new(b[0], b[1], b[2]);
            e.da_mm[i] = Vector3::new(b[3], b[4], b[5]);
            e.dq_mm[i] = b[6];
        }
        e
    }
}

/// A named linear subspace of the 21 error parameters: `deps = E p`.
#[derive(Debug, Clone, PartialEq)]
pub struct ParameterSet {
    label: String,
    names: Vec<String>,
    /// Column `j` is the 21-vector moved by one mm of parameter `j`.
    columns: Vec<[f64; N_FULL]>,
    /// The non-zero entries of every column (the cheap form of `E`).
    sparse: Vec<Vec<(usize, f64)>>,
}

fn full_index(name: &str) -> Option<usize> {
    FULL21_NAMES.iter().position(|n| *n == name)
}

impl ParameterSet {
    fn new(label: &str, names: Vec<String>, columns: Vec<[f64; N_FULL]>) -> ParameterSet {
        let sparse = columns
            .iter()
            .map(|c| {
                c.iter()
                    .enumerate()
                    .filter(|(_, v)| **v != 0.0)
                    .map(|(i, v)| (i, *v))
                    .collect()
            })
            .collect();
        ParameterSet {
            label: label.into(),
            names,
            columns,
            sparse,
        }
    }

    /// All 21 parameters (includes the two rigid-body "gauge" motions that
    /// internal sensors cannot see; identification reports them).
    pub fn full21() -> ParameterSet {
        let columns = (0..N_FULL)
            .map(|j| {
                let mut c = [0.0; N_FULL];
                c[j] = 1.0;
                c
            })
            .collect();
        ParameterSet::new(
            "full21",
            FULL21_NAMES.iter().map(|s| s.to_string()).collect(),
            columns,
        )
    }

    /// The paper's 15 parameters under its frame conventions.
    pub fn paper15() -> ParameterSet {
        let columns = PAPER15_NAMES
            .iter()
            .map(|name| {
                let mut c = [0.0; N_FULL];
                if let Some(j) = full_index(name) {
                    c[j] = 1.0;
                }
                if *name == "dxB1" {
                    // The convention dxB1 = dxB2: one parameter moves both.
                    if let Some(j) = full_index("dxB2") {
                        c[j] = 1.0;
                    }
                }
                c
            })
            .collect();
        ParameterSet::new(
            "paper15",
            PAPER15_NAMES.iter().map(|s| s.to_string()).collect(),
            columns,
        )
    }

    /// Looks a set up by its label (`paper15` or `full21`).
    pub fn by_label(label: &str) -> Result<ParameterSet, ModelError> {
        match label {
            "paper15" => Ok(Self::paper15()),
            "full21" => Ok(Self::full21()),
            other => Err(ModelError::UnknownParameterSet(other.to_string())),
        }
    }

    /// Short label (`paper15`, `full21`).
    pub fn label(&self) -> &str {
        &self.label
    }

    /// Number of parameters `k`.
    pub fn len(&self) -> usize {
        self.names.len()
    }

    /// True for an empty set.
    pub fn is_empty(&self) -> bool {
        self.names.is_empty()
    }

    /// Parameter names in order.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// Index of a parameter by name.
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }

    /// Column `j` of the embedding `E` (21 values).
    pub fn column(&self, j: usize) -> &[f64; N_FULL] {
        &self.columns[j]
    }

    /// Projects a Jacobian with respect to the 21 errors onto this set:
    /// writes `J E` (`rows x k`, row-major) into `out`, where `J` is given
    /// row by row through `full(row, f)` (`f` in `0..21`). One sparse
    /// product serves every Jacobian of the project: the readings' eq. 9
    /// `J` (3 x 21), the platform position's, any subset of rows.
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_kinematics::Machine;
use tricept_model::{jacobian::error_jacobian, ParameterSet};
let m = Machine::paper();
let up = m.inverse(&nalgebra::Vector3::new(0.0, 0.0, 750.0)).unwrap().up;
let j21 = error_jacobian(&m, &up).unwrap();
let set = ParameterSet::paper15();
let mut out = vec![0.0; 3 * 15];
set.project(3, |row, f| j21[(row, f)], &mut out);
// dxB1 moves B1 and B2: its column is the sum of theirs.
assert!((out[0] - (j21[(0, 0)] + j21[(0, 7)])).abs() < 1e-15);
```
"#
    )]
    pub fn project(&self, rows: usize, full: impl Fn(usize, usize) -> f64, out: &mut [f64]) {
        let k = self.sparse.len();
        for (c, col) in self.sparse.iter().enumerate() {
            for row in 0..rows {
                out[row * k + c] = col.iter().map(|&(f, e)| full(row, f) * e).sum();
            }
        }
    }

    /// The full error vector `E p` for parameter values `p` (mm).
    pub fn to_errors(&self, p: &[f64]) -> GeometricErrors {
        let mut full = [0.0; N_FULL];
        for (col, value) in self.columns.iter().zip(p) {
            for (f, c) in full.iter_mut().zip(col) {
                *f += c * value;
            }
        }
        GeometricErrors::from_array(&full)
    }

    /// The parameter values `p` with `E p = e`, when `e` lies in the set's
    /// subspace (to 1e-12 mm); otherwise an error naming the component the
    /// set cannot represent.
    pub fn from_errors(&self, e: &GeometricErrors) -> Result<Vec<f64>, ModelError> {
        let full = e.to_array();
        // Every column of a set built here is a 0/1 vector with disjoint
        // supports, so E^T E is diagonal and the least-squares coefficient is
        // a mean over the support.
        let p: Vec<f64> = self
            .columns
            .iter()
            .map(|c| {
                let (num, den) = c
                    .iter()
                    .zip(&full)
                    .fold((0.0, 0.0), |(n, d), (ci, fi)| (n + ci * fi, d + ci * ci));
                num / den
            })
            .collect();
        let back = self.to_errors(&p).to_array();
        for (j, (a, b)) in back.iter().zip(&full).enumerate() {
            if (a - b).abs() > 1e-12 {
                return Err(ModelError::NotRepresentable {
                    set: self.label.clone(),
                    component: FULL21_NAMES[j].to_string(),
                    value: *b,
                });
            }
        }
        Ok(p)
    }

    /// Table 2 of the paper as values of this set.
    pub fn table2(&self) -> Vec<f64> {
        // The embedded fixture is covered by a unit test.
        self.parse_values(TABLE2_JSON).unwrap_or_default()
    }

    /// Parses a JSON object `{name: value_mm}`. Names must belong to the
    /// set; missing names are zero.
    pub fn parse_values(&self, json: &str) -> Result<Vec<f64>, ModelError> {
        let map = parse_object(
            json,
            "expected a JSON object of parameter name -> value in mm",
        )?;
        self.values_from_map(&map)
    }

    /// Values from a JSON map `{name: value_mm}` (missing names are zero).
    pub fn values_from_map(&self, map: &Map<String, Value>) -> Result<Vec<f64>, ModelError> {
        values_from_named_map(&self.names, &self.label, map)
    }

    /// Values as a JSON map in the set's order.
    pub fn values_to_map(&self, p: &[f64]) -> Map<String, Value> {
        values_to_named_map(&self.names, p)
    }
}

/// The largest error a parameter may be given, mm (or rad for a name
/// ending in `_rad`): beyond it a machine is not the one described, and a
/// simulation of it means nothing.
pub const MAX_PARAMETER_ERROR: (f64, f64) = (50.0, 0.5);

/// A JSON object `{name: value}` (a byte-order mark allowed before it),
/// refusing a key that appears twice (`serde_json` would keep the last).
pub(crate) fn parse_object(json: &str, expected: &str) -> Result<Map<String, Value>, ModelError> {
    struct Entries(Vec<(String, Value)>);
    impl<'de> serde::Deserialize<'de> for Entries {
        fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
            struct V;
            impl<'de> serde::de::Visitor<'de> for V {
                type Value = Entries;
                fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                    f.write_str("a JSON object")
                }
                fn visit_map<A: serde::de::MapAccess<'de>>(
                    self,
                    mut a: A,
                ) -> Result<Entries, A::Error> {
                    let mut v: Vec<(String, Value)> = Vec::new();
                    while let Some((k, x)) = a.next_entry::<String, Value>()? {
                        if v.iter().any(|(e, _)| *e == k) {
                            return Err(serde::de::Error::custom(format!(
                                "the key `{k}` appears twice"
                            )));
                        }
                        v.push((k, x));
                    }
                    Ok(Entries(v))
                }
            }
            d.deserialize_any(V)
        }
    }
    let json = json.strip_prefix('\u{feff}').unwrap_or(json);
    if !json.trim_start().starts_with('{') {
        return Err(ModelError::Values(expected.into()));
    }
    let Entries(v) = serde_json::from_str(json)?;
    Ok(v.into_iter().collect())
}

/// Values of the parameters `names` of set `label` from a JSON map
/// `{name: value}` (missing names are zero; an unknown name, a value that
/// is not a finite number, or one beyond [`MAX_PARAMETER_ERROR`] is an
/// error).
pub(crate) fn values_from_named_map(
    names: &[String],
    label: &str,
    map: &Map<String, Value>,
) -> Result<Vec<f64>, ModelError> {
    let mut p = vec![0.0; names.len()];
    for (k, v) in map {
        let Some(j) = names.iter().position(|n| n == k) else {
            return Err(ModelError::UnknownParameter {
                name: k.clone(),
                set: label.to_string(),
                known: names.join(" "),
            });
        };
        let x = v.as_f64().filter(|x| x.is_finite()).ok_or_else(|| {
            ModelError::Values(format!(
                "{k}: expected a finite number (in the unit its name carries), got {v}"
            ))
        })?;
        let (limit, unit) = if k.ends_with("_rad") {
            (MAX_PARAMETER_ERROR.1, "rad")
        } else {
            (MAX_PARAMETER_ERROR.0, "mm")
        };
        if x.abs() > limit {
            return Err(ModelError::Values(format!(
                "{k}: {x} is beyond ±{limit} {unit}: not an error of the machine described"
            )));
        }
        p[j] = x;
    }
    Ok(p)
}

/// Values `p` of the parameters `names` as a JSON map, in order.
pub(crate) fn values_to_named_map(names: &[String], p: &[f64]) -> Map<String, Value> {
    names
        .iter()
        .zip(p)
        .map(|(n, v)| (n.clone(), Value::from(*v)))
        .collect()
}

/// The paper's residual error `mu = ||deps - deps_e||_1 / n_eps` (mm).
///
/// # Example
/// ```
/// use tricept_model::{params::residual_mu, ParameterSet};
/// let t2 = ParameterSet::paper15().table2();
/// // No calibration (deps_e = 0): the paper's mu_0 = 0.285 mm.
/// let mu0 = residual_mu(&t2, &vec![0.0; 15]);
/// assert!((mu0 - 0.285).abs() < 5e-4);
/// ```
pub fn residual_mu(truth: &[f64], estimate: &[f64]) -> f64 {
    let n = truth.len().max(1) as f64;
    truth
        .iter()
        .zip(estimate)
        .map(|(a, b)| (a - b).abs())
        .sum::<f64>()
        / n
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table2_has_all_fifteen_values() {
        let set = ParameterSet::paper15();
        let t2 = set.table2();
        assert_eq!(
            t2,
            vec![
                0.2, 0.1, 0.2, 0.2, 0.27, 0.2, 0.25, -0.2, -0.25, 0.25, -0.31, 0.2, 0.45, 0.7, 0.5
            ]
        );
    }

    #[test]
    fn embedding_and_its_inverse() {
        let set = ParameterSet::paper15();
        let p: Vec<f64> = (0..15).map(|k| 0.01 * (k as f64 + 1.0)).collect();
        let e = set.to_errors(&p);
        assert_eq!(e.db_mm[0].x, e.db_mm[1].x);
        assert_eq!(e.db_mm[0].z, 0.0);
        assert_eq!(e.da_mm[2].z, 0.0);
        let back = set.from_errors(&e).unwrap();
        assert_eq!(back, p);
        // A component outside the paper's conventions is refused by name.
        let mut off = e;
        off.db_mm[1].z = 0.1;
        let err = set.from_errors(&off).unwrap_err();
        assert!(err.to_string().contains("dzB2"), "{err}");
        // The full set represents everything.
        let full = ParameterSet::full21();
        assert_eq!(full.to_errors(&full.from_errors(&off).unwrap()), off);
    }

    #[test]
    fn unknown_names_are_refused() {
        let err = ParameterSet::paper15()
            .parse_values(r#"{"dzB1": 0.1}"#)
            .unwrap_err();
        assert!(err.to_string().contains("dzB1"), "{err}");
    }
}
