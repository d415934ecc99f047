//! Laser-tracker (or CMM) points: `y = R_T x(q, h; e, o) + t_T`, three rows
//! per point, each coordinate with its own standard deviation.
//!
//! Nuisance: the target's offset `o` from the tool tip (3, mm, spindle
//! frame at zero head angles; free, or known with a prior) and, per
//! station, the instrument's frame: a rotation (3, rad, as a small rotation
//! `exp([w]x)` applied to the current frame and re-based after each step)
//! and a translation (3, mm). The frame starts from Horn's closed-form fit
//! of the measured points to the model's predictions (at least three
//! non-collinear points per station).
//!
//! With a free target the tool tip cannot be told from the target offset:
//! their columns are identical, so the tool-tip parameters (and `h2`'s zero,
//! which moves the tip like a tip shift) are held at their prior by the
//! rank rule and named.

use nalgebra::{Matrix3, Rotation3, Vector3};
use tricept_data::{external::TrackerData, external::TrackerPoint};
use tricept_model::head_errors::Effector;

use crate::error::IdentError;
use crate::fusion::source::{
    Nuisance, PointRows, Readings, RecordList, Sink, Source, SourceKind, SourceRows, Start,
    TrackerTarget, cross_matrix, rotate_row,
};

/// How to read a tracker file.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackerOptions {
    /// Standard deviation of a coordinate for rows without `sigma_um`, um.
    pub sigma_um: f64,
    /// The target offset.
    pub target: TrackerTarget,
}

impl Default for TrackerOptions {
    /// 10 um per coordinate, free target.
    fn default() -> Self {
        TrackerOptions {
            sigma_um: 10.0,
            target: TrackerTarget::Free,
        }
    }
}

#[derive(Debug, Clone)]
struct Tracker {
    points: Readings<TrackerPoint>,
    target: TrackerTarget,
    setups: Vec<u32>,
    setup_of: Vec<usize>,
}

impl Source {
    /// Tracker / CMM points. Refused: a station with fewer than three points.
    ///
    /// # Example
    /// ```
    /// use tricept_engine::fusion::{Source, TrackerOptions};
    /// let csv = "q1,q2,q3,h1,h2,x,y,z,setup\n800,800,800,0,0,1,2,3,1\n810,800,800,0,0,1,2,3,1\n";
    /// let data = tricept_data::external::read_external_from::<tricept_data::external::TrackerPoint, _>(csv.as_bytes(), "t.csv").unwrap();
    /// let e = Source::tracker(&data, &TrackerOptions::default()).unwrap_err();
    /// assert!(e.to_string().starts_with("t.csv: station 1 has 2 points"), "{e}");
    /// assert!(e.to_string().ends_with("(lines 2, 3)"), "{e}");
    /// ```
    pub fn tracker(data: &TrackerData, options: &TrackerOptions) -> Result<Source, IdentError> {
        let points = Readings::new(data, options.sigma_um);
        let (setups, setup_of) = points.setups(3, |id, n| {
            format!("station {id} has {n} points; its frame needs at least 3 not on one line")
        })?;
        Ok(Source::new(Box::new(Tracker {
            points,
            target: options.target,
            setups,
            setup_of,
        })))
    }
}

/// Horn's closed-form rigid fit `y ~ R x + t`; `None` when the points are
/// (nearly) collinear.
fn horn(x: &[Vector3<f64>], y: &[Vector3<f64>]) -> Option<(Matrix3<f64>, Vector3<f64>)> {
    let n = x.len() as f64;
    let xc = x.iter().sum::<Vector3<f64>>() / n;
    let yc = y.iter().sum::<Vector3<f64>>() / n;
    let h: Matrix3<f64> = x
        .iter()
        .zip(y)
        .map(|(a, b)| (a - xc) * (b - yc).transpose())
        .sum();
    let spread: Matrix3<f64> = x.iter().map(|a| (a - xc) * (a - xc).transpose()).sum();
    let e = spread.symmetric_eigenvalues();
    let (lo, hi) = (
        e.iter().copied().fold(f64::INFINITY, f64::min),
        e.iter().copied().fold(0.0, f64::max),
    );
    let mid = e.sum() - lo - hi;
    if mid.is_nan() || mid <= 1e-8 * hi {
        return None;
    }
    let svd = h.svd(true, true);
    let (u, vt) = (svd.u?, svd.v_t?);
    let v = vt.transpose();
    let d = (v * u.transpose()).determinant().signum();
    let r = v * Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, d)) * u.transpose();
    Some((r, yc - r * xc))
}

impl SourceRows for Tracker {
    fn kind(&self) -> SourceKind {
        SourceKind::Tracker
    }

    fn record_list(&self) -> &dyn RecordList {
        &self.points
    }

    fn nuisance_names(&self) -> Vec<String> {
        let mut names: Vec<String> = ["target_x_mm", "target_y_mm", "target_z_mm"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        for id in &self.setups {
            for n in ["rx_rad", "ry_rad", "rz_rad", "tx_mm", "ty_mm", "tz_mm"] {
                names.push(format!("s{id}.{n}"));
            }
        }
        names
    }

    fn rows_each(&self) -> usize {
        3
    }

    fn prior_rows(&self) -> usize {
        match self.target {
            TrackerTarget::Free => 0,
            TrackerTarget::Known { .. } => 3,
        }
    }

    fn min_redundancy(&self) -> f64 {
        6.0 * self.setups.len() as f64
    }

    fn judged_nuisance(&self, values: &[f64]) -> Vec<(&'static str, usize, f64)> {
        (0..3)
            .map(|c| match self.target {
                TrackerTarget::Free => ("tracker.target_free_mm", c, values[c]),
                TrackerTarget::Known { offset_mm, .. } => {
                    ("tracker.target_change_mm", c, values[c] - offset_mm[c])
                }
            })
            .collect()
    }

    fn tracker_target(&self) -> Option<TrackerTarget> {
        Some(self.target)
    }

    fn stated_offset_mm(&self) -> Option<Vector3<f64>> {
        match self.target {
            TrackerTarget::Known { offset_mm, .. } => {
                Some(Vector3::from(offset_mm)).filter(|o| o.norm() > 0.0)
            }
            TrackerTarget::Free => None,
        }
    }

    fn with_tracker_target(&self, target: TrackerTarget) -> Option<Box<dyn SourceRows>> {
        Some(Box::new(Tracker {
            target,
            ..self.clone()
        }))
    }

    fn effector(&self, record: usize, nu: &Nuisance) -> Effector {
        Effector {
            extension_mm: self.points.records[record].extension_mm,
            offset_mm: Vector3::new(nu.values[0], nu.values[1], nu.values[2]),
        }
    }

    fn start(&self) -> Nuisance {
        let mut nu = Nuisance {
            values: vec![0.0; 3 + 6 * self.setups.len()],
            rotations: vec![Matrix3::identity(); self.setups.len()],
            normals: Vec::new(),
        };
        if let TrackerTarget::Known { offset_mm, .. } = self.target {
            nu.values[..3].copy_from_slice(&offset_mm);
        }
        nu
    }

    fn fit_start(&self, start: Start<'_>) -> Result<Nuisance, IdentError> {
        let (mut nu, active) = (start.nu, start.active);
        let points = &self.points.records;
        let predicted: Vec<Vector3<f64>> = start.points.iter().map(|x| x.position_mm).collect();
        for (s, id) in self.setups.iter().enumerate() {
            let in_station = |j: usize| self.setup_of[j] == s && active[j];
            let (x, y): (Vec<Vector3<f64>>, Vec<Vector3<f64>>) = (0..points.len())
                .filter(|&j| in_station(j))
                .map(|j| (predicted[j], Vector3::from(points[j].position_mm)))
                .unzip();
            let (r, t) = horn(&x, &y).ok_or_else(|| {
                self.points.degenerate(in_station, |lines| {
                    format!("the points of station {id} ({lines}) lie on one line: the tracker's frame cannot be found")
                })
            })?;
            nu.rotations[s] = r;
            nu.values[3 + 6 * s + 3..3 + 6 * s + 6].copy_from_slice(t.as_slice());
        }
        Ok(nu)
    }

    fn point_rows(&self, rows: PointRows<'_>, sink: &mut Sink) {
        let (j, x, k, nu) = (rows.record, rows.point, rows.k, rows.nu);
        let (jac, dnu, theta) = (rows.jac, rows.dnu, rows.theta);
        let p = &self.points.records[j];
        let s = self.setup_of[j];
        let r = nu.rotations[s];
        let base = 3 + 6 * s;
        let t = Vector3::new(
            nu.values[base + 3],
            nu.values[base + 4],
            nu.values[base + 5],
        );
        let predicted = r * x.position_mm + t;
        let d_offset = r * x.rotation;
        let d_rotation = -cross_matrix(&predicted);
        for c in 0..3 {
            dnu.iter_mut().for_each(|v| *v = 0.0);
            for m in 0..3 {
                dnu[m] = d_offset[(c, m)];
                dnu[base + m] = d_rotation[(c, m)];
            }
            dnu[base + 3 + c] = 1.0;
            rotate_row(&r, jac, k, c, theta);
            sink.data(
                j,
                1.0 / self.points.sigma_mm[j],
                dnu,
                theta,
                p.position_mm[c] - predicted[c],
            );
        }
    }

    fn priors(&self, nu: &Nuisance, sink: &mut Sink) {
        if let TrackerTarget::Known {
            offset_mm,
            sigma_um,
        } = self.target
        {
            for c in 0..3 {
                sink.prior(c, 1e-3 * sigma_um, offset_mm[c] - nu.values[c]);
            }
        }
    }

    fn retract(&self, nu: &mut Nuisance, step: &[f64]) {
        for c in 0..3 {
            nu.values[c] += step[c];
        }
        for s in 0..self.setups.len() {
            let base = 3 + 6 * s;
            let w = Vector3::new(step[base], step[base + 1], step[base + 2]);
            let turn = Rotation3::new(w).into_inner();
            nu.rotations[s] = turn * nu.rotations[s];
            let t = Vector3::new(
                nu.values[base + 3],
                nu.values[base + 4],
                nu.values[base + 5],
            );
            let moved = turn * t + Vector3::new(step[base + 3], step[base + 4], step[base + 5]);
            nu.values[base + 3..base + 6].copy_from_slice(moved.as_slice());
        }
    }

    fn report_values(&self, nu: &Nuisance) -> Vec<f64> {
        let mut v = nu.values.clone();
        for (s, r) in nu.rotations.iter().enumerate() {
            let w = Rotation3::from_matrix_unchecked(*r).scaled_axis();
            v[3 + 6 * s..3 + 6 * s + 3].copy_from_slice(w.as_slice());
        }
        v
    }

    fn nuisance_hint(&self) -> &'static str {
        "the target offset and the tracker frame cannot be separated: vary the spindle's orientation (h1, h2 and the platform tilt) between the points"
    }
}
