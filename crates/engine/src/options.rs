//! [`IdentifyOptions`]: the settings of [`crate::identify()`], the noise
//! model and the solver's tolerances.

use tricept_kinematics::Machine;
use tricept_numerics::lsq::DEFAULT_RANK_TOLERANCE;

/// Settings of [`identify`](crate::identify()): the noise model and the solver's tolerances,
/// the same for every data set they are used on.
///
/// # Example
/// ```
/// use tricept_engine::IdentifyOptions;
/// use tricept_kinematics::{Machine, units::arcsec_to_rad};
/// let mut o = IdentifyOptions::for_machine(&Machine::paper());
/// // The paper's sensors: 0.8 arcsec and 0.5 um per reading, mean of 3.
/// assert!((o.sigma[0] - arcsec_to_rad(0.8) / 3f64.sqrt()).abs() < 1e-15);
/// o.sigma[0] = arcsec_to_rad(2.0); // a 2 arcsec encoder, one reading
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct IdentifyOptions {
    /// Standard deviation of one *logged* reading `[phi, theta, s]`
    /// (rad, rad, mm).
    pub sigma: [f64; 3],
    /// Relative singular-value tolerance of the rank decision.
    pub rank_tolerance: f64,
    /// `s_i / s_1` below which an identifiable direction is reported weak.
    pub weak_threshold: f64,
    /// Gauss-Newton iteration limit. With 0 the estimate is the one linear
    /// solve at the starting point (the linearised estimator) and the
    /// residual statistics are those of the starting point; otherwise they
    /// are those of the estimate.
    pub max_iterations: u32,
}

impl IdentifyOptions {
    /// Defaults with the logged noise of `machine`'s sensors.
    ///
    /// # Example
    /// ```
    /// use tricept_engine::IdentifyOptions;
    /// let m = tricept_kinematics::Machine::paper();
    /// let o = IdentifyOptions::for_machine(&m);
    /// assert_eq!(o.sigma, m.sensors.logged_sigma());
    /// ```
    pub fn for_machine(machine: &Machine) -> IdentifyOptions {
        IdentifyOptions::with_sigma(machine.sensors.logged_sigma())
    }

    /// Defaults with the given standard deviations of one logged reading
    /// (`phi` rad, `theta` rad, `s` mm): the stated rank tolerance, weak
    /// threshold 1e-2, at most 30 iterations.
    ///
    /// # Example
    /// ```
    /// use tricept_engine::IdentifyOptions;
    /// use tricept_kinematics::units::arcsec_to_rad;
    /// // A 2 arcsec encoder and a 0.5 um scale, one reading per pose.
    /// let o = IdentifyOptions::with_sigma([arcsec_to_rad(2.0), arcsec_to_rad(2.0), 0.5e-3]);
    /// assert_eq!(o.max_iterations, 30);
    /// ```
    pub fn with_sigma(sigma: [f64; 3]) -> IdentifyOptions {
        IdentifyOptions {
            sigma,
            rank_tolerance: DEFAULT_RANK_TOLERANCE,
            weak_threshold: 1e-2,
            max_iterations: 30,
        }
    }
}
