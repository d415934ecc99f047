//! Volumetric error maps: where the platform really goes when commanded by
//! one model's IK and driven by another (the actual) machine's exact FK.
//!
//! Before compensation the commands come from the nominal IK; after
//! compensation from the identified machine's IK. The paper's Fig. 3 plots
//! `dV = |dr|` over the workspace's middle plane.

use nalgebra::Vector3;
use serde::Serialize;
use tricept_kinematics::Machine;

use crate::error::ModelError;

/// Platform position errors `dr = r_reached - r_target` at a set of targets.
#[derive(Debug, Clone, PartialEq)]
pub struct ErrorMap {
    /// Target points, mm.
    pub targets_mm: Vec<Vector3<f64>>,
    /// Error vectors at each target, mm.
    pub errors_mm: Vec<Vector3<f64>>,
}

/// Max, min, mean and RMS of `|dr|` over a map, mm.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MapStats {
    /// Largest `|dr|`, mm.
    pub max_mm: f64,
    /// Smallest `|dr|`, mm.
    pub min_mm: f64,
    /// Mean `|dr|`, mm.
    pub mean_mm: f64,
    /// Root mean square of `|dr|`, mm.
    pub rms_mm: f64,
}

impl ErrorMap {
    /// `|dr|` at each target, mm.
    pub fn magnitudes_mm(&self) -> Vec<f64> {
        self.errors_mm.iter().map(|e| e.norm()).collect()
    }

    /// Summary statistics of `|dr|`.
    pub fn stats(&self) -> MapStats {
        let m = self.magnitudes_mm();
        let n = m.len().max(1) as f64;
        MapStats {
            max_mm: m.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            min_mm: m.iter().copied().fold(f64::INFINITY, f64::min),
            mean_mm: m.iter().sum::<f64>() / n,
            rms_mm: (m.iter().map(|x| x * x).sum::<f64>() / n).sqrt(),
        }
    }

    /// The mean error vector: the best-fit rigid translation in the
    /// least-squares sense (what touching off on a work piece removes), mm.
    pub fn mean_translation_mm(&self) -> Vector3<f64> {
        let n = self.errors_mm.len().max(1) as f64;
        self.errors_mm.iter().sum::<Vector3<f64>>() / n
    }

    /// The map with the best-fit rigid translation removed.
    pub fn without_mean_translation(&self) -> ErrorMap {
        let t = self.mean_translation_mm();
        ErrorMap {
            targets_mm: self.targets_mm.clone(),
            errors_mm: self.errors_mm.iter().map(|e| e - t).collect(),
        }
    }
}

/// Commands each target with `commanding`'s IK and drives `actual` with
/// them (exact FK, seeded at the commanded configuration).
///
/// # Example
/// ```
/// use tricept_kinematics::Machine;
/// use tricept_model::volumetric::volumetric_errors;
/// let m = Machine::paper();
/// let targets = m.workspace.disc_grid(m.workspace.mid_plane_z_mm(), 100.0);
/// // A machine commanded by its own model has no error.
/// let map = volumetric_errors(&m, &m, &targets).unwrap();
/// assert!(map.stats().max_mm < 1e-9);
/// ```
pub fn volumetric_errors(
    commanding: &Machine,
    actual: &Machine,
    targets_mm: &[Vector3<f64>],
) -> Result<ErrorMap, ModelError> {
    let mut errors_mm = Vec::with_capacity(targets_mm.len());
    for r in targets_mm {
        let ik = commanding.inverse(r)?;
        let fk = actual.forward_from(&ik.legs_mm, &ik.up)?;
        errors_mm.push(fk.position_mm - r);
    }
    Ok(ErrorMap {
        targets_mm: targets_mm.to_vec(),
        errors_mm,
    })
}
