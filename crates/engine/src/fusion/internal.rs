//! The internal source: the UP limb's own readings, three rows per pose
//! with the three sensor zero offsets as a linear nuisance, re-solved at
//! every evaluation exactly as [`crate::identify`] does.

use tricept_data::{Dataset, MeasuredPose, external::ExternalPose};
use tricept_kinematics::up_limb::UpJoints;

use crate::error::IdentError;
use crate::fusion::model::{FusedAt, LegContext};
use crate::fusion::source::{Nuisance, RecordList, Sink, Source, SourceKind, SourceRows};

impl Source {
    /// The UP limb's readings, with the standard deviation of one logged
    /// reading `[phi, theta, s]` (rad, rad, mm).
    pub fn internal(data: &Dataset, sigma: [f64; 3]) -> Source {
        Source::new(Box::new(Internal {
            poses: data.poses.clone(),
            sigma,
            file: data.source.clone(),
        }))
    }
}

/// The UP limb's readings.
#[derive(Debug, Clone)]
struct Internal {
    poses: Vec<MeasuredPose>,
    sigma: [f64; 3],
    file: String,
}

impl RecordList for Internal {
    fn file(&self) -> &str {
        &self.file
    }

    fn len(&self) -> usize {
        self.poses.len()
    }

    fn pose(&self, record: usize) -> ExternalPose {
        ExternalPose {
            commands_mm: self.poses[record].commands_mm,
            head_rad: [0.0, 0.0],
        }
    }

    fn line(&self, record: usize) -> u64 {
        self.poses[record].line
    }
}

impl SourceRows for Internal {
    fn kind(&self) -> SourceKind {
        SourceKind::Internal
    }

    fn record_list(&self) -> &dyn RecordList {
        self
    }

    fn nuisance_names(&self) -> Vec<String> {
        vec![
            "phi_offset_rad".into(),
            "theta_offset_rad".into(),
            "s_offset_mm".into(),
        ]
    }

    fn rows_each(&self) -> usize {
        3
    }

    fn min_redundancy(&self) -> f64 {
        6.0
    }

    fn residual_unit_um(&self) -> Option<f64> {
        None
    }

    fn linear_nuisance(&self) -> bool {
        true
    }

    fn initial(
        &self,
        _at: &FusedAt<'_>,
        _contexts: &[LegContext],
        _seeds: &mut [Option<UpJoints>],
        _active: &[bool],
    ) -> Result<Nuisance, IdentError> {
        Ok(Nuisance {
            values: vec![0.0; 3],
            ..Nuisance::default()
        })
    }

    fn evaluate(
        &self,
        at: &FusedAt<'_>,
        contexts: &[LegContext],
        _nu: &Nuisance,
        seeds: &mut [Option<UpJoints>],
        sink: &mut Sink,
    ) -> Result<(), IdentError> {
        let k = at.len();
        let mut jac = vec![0.0; 3 * k];
        let mut unit = [0.0; 3];
        for (j, ((pose, seed), ctx)) in self.poses.iter().zip(seeds).zip(contexts).enumerate() {
            let g = at
                .readings(&pose.commands_mm, ctx, seed, &mut jac)
                .map_err(|source| IdentError::Kinematics {
                    pose: j,
                    line: pose.line,
                    source,
                })?;
            let y = pose.readings.to_array();
            for c in 0..3 {
                unit.iter_mut().for_each(|v| *v = 0.0);
                unit[c] = 1.0;
                sink.data(
                    j,
                    1.0 / self.sigma[c],
                    &unit,
                    &jac[c * k..(c + 1) * k],
                    y[c] - g[c],
                );
            }
        }
        Ok(())
    }

    fn retract(&self, _nu: &mut Nuisance, _step: &[f64]) {}

    fn take_off_linear_nuisance(&self, rows: &mut [(usize, f64, f64)], offsets: &[f64]) {
        for (i, (_, z, raw)) in rows.iter_mut().enumerate() {
            let c = i % 3;
            *raw -= offsets[c];
            *z = *raw / self.sigma[c];
        }
    }

    fn nuisance_hint(&self) -> &'static str {
        "the poses do not move the UP limb's joints"
    }
}
