//! Ballbar lengths: `length = |x(q, h; ball) - c| + b`, one row per
//! reading, where `x` is the ball in the spindle, `c` the pivot on the
//! table and `b` the bar's length error (reading minus true distance).
//!
//! Nuisance per setup: the pivot (3, mm; started from a linear sphere fit
//! with the readings as radii, at least four tips not in one plane) and the
//! length error (1, mm). The length error has a prior (the bar's
//! calibration certificate, 1 um by default): a similarity about any point
//! scales every distance, so with the length free a machine scale is
//! absorbed by `b` and no ballbar sees it.

use nalgebra::Vector3;
use tricept_data::{external::BallbarData, external::BallbarReading};
use tricept_model::head_errors::Effector;

use crate::error::IdentError;
use crate::fusion::source::{
    Nuisance, PointRows, Readings, RecordList, Sink, Source, SourceKind, SourceRows, Start,
    project_rows, sphere_centre,
};

/// How to read a ballbar file.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BallbarOptions {
    /// Standard deviation of a reading for rows without `sigma_um`, um.
    pub sigma_um: f64,
    /// Standard deviation of the bar's length error, um (`None`: free).
    pub length_sigma_um: Option<f64>,
    /// Offset of the spindle ball from the tool tip, mm (spindle frame at
    /// zero head angles).
    pub ball_offset_mm: [f64; 3],
}

impl Default for BallbarOptions {
    /// 1 um readings, 1 um length certificate, ball at the tool tip.
    fn default() -> Self {
        BallbarOptions {
            sigma_um: 1.0,
            length_sigma_um: Some(1.0),
            ball_offset_mm: [0.0; 3],
        }
    }
}

#[derive(Debug, Clone)]
struct Ballbar {
    readings: Readings<BallbarReading>,
    length_sigma_mm: Option<f64>,
    effector: Effector,
    setups: Vec<u32>,
    setup_of: Vec<usize>,
}

impl Source {
    /// Ballbar readings. Refused: a setup with fewer than four readings.
    ///
    /// # Example
    /// ```
    /// use tricept_engine::fusion::{BallbarOptions, Source};
    /// let csv = "q1,q2,q3,h1,h2,length\n800,800,800,0,0.3,150\n810,800,800,0,0.3,150\n";
    /// let data = tricept_data::external::read_external_from(csv.as_bytes(), "b.csv").unwrap();
    /// let e = Source::ballbar(&data, &BallbarOptions::default()).unwrap_err();
    /// assert!(e.to_string().starts_with("b.csv: setup 1 has 2 readings"), "{e}");
    /// ```
    pub fn ballbar(data: &BallbarData, options: &BallbarOptions) -> Result<Source, IdentError> {
        let readings = Readings::new(data, options.sigma_um);
        let (setups, setup_of) = readings.setups(4, |id, n| {
            format!(
                "setup {id} has {n} readings; its pivot needs at least 4 with the ball not in one plane"
            )
        })?;
        Ok(Source::new(Box::new(Ballbar {
            readings,
            length_sigma_mm: options.length_sigma_um.map(|s| 1e-3 * s),
            effector: Effector {
                extension_mm: 0.0,
                offset_mm: Vector3::from(options.ball_offset_mm),
            },
            setups,
            setup_of,
        })))
    }
}

impl SourceRows for Ballbar {
    fn kind(&self) -> SourceKind {
        SourceKind::Ballbar
    }

    fn stated_offset_mm(&self) -> Option<Vector3<f64>> {
        Some(self.effector.offset_mm).filter(|o| o.norm() > 0.0)
    }

    fn record_list(&self) -> &dyn RecordList {
        &self.readings
    }

    fn nuisance_names(&self) -> Vec<String> {
        let mut names = Vec::new();
        for id in &self.setups {
            for n in ["pivot_x_mm", "pivot_y_mm", "pivot_z_mm", "length_error_mm"] {
                names.push(format!("s{id}.{n}"));
            }
        }
        names
    }

    fn rows_each(&self) -> usize {
        1
    }

    fn prior_rows(&self) -> usize {
        if self.length_sigma_mm.is_some() {
            self.setups.len()
        } else {
            0
        }
    }

    fn min_redundancy(&self) -> f64 {
        4.0 * self.setups.len() as f64
    }

    fn judged_nuisance(&self, values: &[f64]) -> Vec<(&'static str, usize, f64)> {
        (0..self.setups.len())
            .map(|s| ("ballbar.length_error_mm", 4 * s + 3, values[4 * s + 3]))
            .collect()
    }

    fn effector(&self, _record: usize, _nu: &Nuisance) -> Effector {
        self.effector
    }

    fn start(&self) -> Nuisance {
        Nuisance {
            values: vec![0.0; 4 * self.setups.len()],
            ..Nuisance::default()
        }
    }

    fn fit_start(&self, start: Start<'_>) -> Result<Nuisance, IdentError> {
        let (mut nu, active) = (start.nu, start.active);
        let readings = &self.readings.records;
        let tips: Vec<Vector3<f64>> = start.points.iter().map(|x| x.position_mm).collect();
        for (s, id) in self.setups.iter().enumerate() {
            let in_setup = |j: usize| self.setup_of[j] == s && active[j];
            let (x, radii): (Vec<Vector3<f64>>, Vec<f64>) = (0..readings.len())
                .filter(|&j| in_setup(j))
                .map(|j| (tips[j], readings[j].length_mm))
                .unzip();
            let c = sphere_centre(&x, &radii).ok_or_else(|| {
                self.readings.degenerate(in_setup, |lines| {
                    format!("the ball positions of setup {id} ({lines}) lie in one plane: the pivot cannot be found")
                })
            })?;
            nu.values[4 * s..4 * s + 3].copy_from_slice(c.as_slice());
        }
        Ok(nu)
    }

    fn point_rows(&self, rows: PointRows<'_>, sink: &mut Sink) {
        let (j, x, k, nu) = (rows.record, rows.point, rows.k, rows.nu);
        let (jac, dnu, theta) = (rows.jac, rows.dnu, rows.theta);
        let base = 4 * self.setup_of[j];
        let c = Vector3::new(nu.values[base], nu.values[base + 1], nu.values[base + 2]);
        let d = x.position_mm - c;
        let rho = d.norm();
        let u = d / rho;
        for m in 0..3 {
            dnu[base + m] = -u[m];
        }
        dnu[base + 3] = 1.0;
        project_rows(&u, jac, k, theta);
        sink.data(
            j,
            1.0 / self.readings.sigma_mm[j],
            dnu,
            theta,
            self.readings.records[j].length_mm - (rho + nu.values[base + 3]),
        );
    }

    fn priors(&self, nu: &Nuisance, sink: &mut Sink) {
        if let Some(sigma) = self.length_sigma_mm {
            for s in 0..self.setups.len() {
                sink.prior(4 * s + 3, sigma, -nu.values[4 * s + 3]);
            }
        }
    }

    fn nuisance_hint(&self) -> &'static str {
        "spread the ball over the sphere around the pivot (different directions, not one plane)"
    }
}
