//! The one conversion between the angle units the project quotes
//! (arcseconds, for encoder grades and small angular errors) and the unit
//! it computes in (radians).

/// One arcsecond in radians.
pub const RAD_PER_ARCSEC: f64 = std::f64::consts::PI / (180.0 * 3600.0);

/// Arcseconds to radians.
///
/// # Example
/// ```
/// use tricept_kinematics::units::arcsec_to_rad;
/// assert!((arcsec_to_rad(3600.0) - 1f64.to_radians()).abs() < 1e-18);
/// ```
pub fn arcsec_to_rad(arcsec: f64) -> f64 {
    arcsec * RAD_PER_ARCSEC
}

/// Radians to arcseconds.
///
/// # Example
/// ```
/// use tricept_kinematics::units::{arcsec_to_rad, rad_to_arcsec};
/// assert!((rad_to_arcsec(arcsec_to_rad(0.8)) - 0.8).abs() < 1e-15);
/// ```
pub fn rad_to_arcsec(rad: f64) -> f64 {
    rad / RAD_PER_ARCSEC
}
