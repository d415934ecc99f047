//! The settings of a diagnosis ([`DiagnoseOptions`]) and of its generic
//! dictionary ([`DictionaryOptions`]).

use tricept_kinematics::Machine;

use crate::plausibility::Plausibility;

/// Options of [`crate::diagnose`].
#[derive(Debug, Clone, PartialEq)]
pub struct DiagnoseOptions {
    /// Standard deviation of one logged reading `[phi, theta, s]` (rad, rad, mm).
    pub sigma: [f64; 3],
    /// Family-wise significance level of the tests.
    pub alpha: f64,
    /// Folds of the cross-validation.
    pub folds: usize,
    /// Largest number of causes named.
    pub max_causes: usize,
    /// Lattice of the middle-plane comparison, mm.
    pub plane_spacing_mm: f64,
    /// Largest share of poses that may be called outliers.
    pub max_outlier_share: f64,
    /// The generic dictionary.
    pub dictionary: DictionaryOptions,
    /// Physical ranges of the effects.
    pub plausibility: Plausibility,
    /// Estimate the noise from repeated poses and use it in every test.
    pub noise_from_data: bool,
    /// Poses whose commands agree within this are repeats, mm.
    pub repeat_tolerance_mm: f64,
    /// Standard deviation of the logged temperature, K.
    pub temperature_sigma_k: f64,
    /// A fit needing a geometric error larger than this has failed, mm.
    pub max_error_mm: f64,
    /// The machine whose rank decision the fits use (the nominal machine
    /// of a calibrated one: docs/identifiability.md); `None`: the machine
    /// diagnosed.
    pub rank_reference: Option<Machine>,
}

/// Smallest degrees of freedom of pure error per channel for
/// `noise_from_data`.
pub const MIN_PURE_ERROR_DOF: usize = 10;

impl DiagnoseOptions {
    /// Defaults with the logged noise of `machine`'s sensors.
    pub fn for_machine(machine: &Machine) -> DiagnoseOptions {
        DiagnoseOptions {
            sigma: machine.sensors.logged_sigma(),
            alpha: 1e-3,
            folds: 5,
            max_causes: 4,
            plane_spacing_mm: 50.0,
            max_outlier_share: 0.1,
            dictionary: DictionaryOptions::default(),
            plausibility: Plausibility::default(),
            noise_from_data: false,
            repeat_tolerance_mm: 1e-3,
            temperature_sigma_k: 0.02,
            max_error_mm: 20.0,
            rank_reference: None,
        }
    }
}

/// Settings of the generic dictionary.
#[derive(Debug, Clone, PartialEq)]
pub struct DictionaryOptions {
    /// Search the dictionary at all (off: the vocabulary only).
    pub enabled: bool,
    /// Shortest and longest period of the ball-screw scan, mm.
    pub period_range_mm: (f64, f64),
    /// Grid points per independent frequency of the scan.
    pub oversampling: f64,
    /// Cells of the step scan's grid over each leg's stroke (its
    /// `K (K + 1) / 2 - 1` pairs of edges each count in the multiplicity;
    /// 0: no step scan).
    pub step_cells: usize,
    /// Best-ranked groups refitted exactly at each selection step.
    pub refit_top: usize,
}

impl Default for DictionaryOptions {
    fn default() -> DictionaryOptions {
        DictionaryOptions {
            enabled: true,
            period_range_mm: (4.0, 50.0),
            oversampling: 4.0,
            step_cells: 16,
            refit_top: 3,
        }
    }
}
