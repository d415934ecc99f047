//! The functional forms of the generic families and of the simulator's
//! effects outside the vocabulary: periodic and Legendre shapes over a
//! normalised stroke, a worn segment of the stroke, encoder gains, linear
//! drifts.

/// Extra leg length (mm) of a periodic error of period `period_mm` in the
/// leg length `command_mm`, with sine and cosine amplitudes in um (a
/// ball-screw pitch error: `A sin(2 pi q / P + psi)` has sine amplitude
/// `A cos psi` and cosine amplitude `A sin psi`).
///
/// # Example
/// ```
/// use tricept_model::effects::periodic_extra_mm;
/// // 4 um sine amplitude, a quarter period in: the full 4 um.
/// assert!((periodic_extra_mm(4.0, 0.0, 10.0, 802.5) - 0.004).abs() < 1e-12);
/// ```
pub fn periodic_extra_mm(sin_um: f64, cos_um: f64, period_mm: f64, command_mm: f64) -> f64 {
    let (s, c) = (std::f64::consts::TAU * command_mm / period_mm).sin_cos();
    (sin_um * s + cos_um * c) * 1e-3
}

/// Extra leg length (mm) of a worn segment: `um` inside the commands
/// `from_mm` to `to_mm` (both included), nothing outside (a step in and a
/// step out of the segment).
///
/// # Example
/// ```
/// use tricept_model::effects::segment_extra_mm;
/// assert_eq!(segment_extra_mm(3.0, 720.0, 960.0, 800.0), 0.003);
/// assert_eq!(segment_extra_mm(3.0, 720.0, 960.0, 960.0), 0.003);
/// assert_eq!(segment_extra_mm(3.0, 720.0, 960.0, 961.0), 0.0);
/// ```
pub fn segment_extra_mm(um: f64, from_mm: f64, to_mm: f64, command_mm: f64) -> f64 {
    if (from_mm..=to_mm).contains(&command_mm) {
        um * 1e-3
    } else {
        0.0
    }
}

/// `x` in `[lo, hi]` mapped linearly onto `[-1, 1]` (`0` when the range is
/// empty).
///
/// # Example
/// ```
/// assert_eq!(tricept_model::effects::normalised_coordinate(750.0, 600.0, 900.0), 0.0);
/// assert_eq!(tricept_model::effects::normalised_coordinate(900.0, 600.0, 900.0), 1.0);
/// ```
pub fn normalised_coordinate(x: f64, lo: f64, hi: f64) -> f64 {
    if hi > lo {
        (2.0 * x - lo - hi) / (hi - lo)
    } else {
        0.0
    }
}

/// Legendre polynomial `P2(x) = (3 x^2 - 1) / 2`: the quadratic shape with
/// no constant or linear part over `[-1, 1]` (those are absorbed by a leg
/// offset and a lead).
pub fn legendre_p2(x: f64) -> f64 {
    0.5 * (3.0 * x * x - 1.0)
}

/// Legendre polynomial `P3(x) = (5 x^3 - 3 x) / 2`.
pub fn legendre_p3(x: f64) -> f64 {
    0.5 * (5.0 * x * x * x - 3.0 * x)
}

/// Legendre polynomial `P4(x) = (35 x^4 - 30 x^2 + 3) / 8`.
pub fn legendre_p4(x: f64) -> f64 {
    let x2 = x * x;
    (35.0 * x2 * x2 - 30.0 * x2 + 3.0) / 8.0
}

/// Reading error of an encoder with gain error `ppm` at `angle_rad`, rad.
///
/// # Example
/// ```
/// // 200 ppm at 0.3 rad: 60 urad, 12.4 arcsec.
/// assert!((tricept_model::effects::encoder_gain_error_rad(200.0, 0.3) - 6e-5).abs() < 1e-18);
/// ```
pub fn encoder_gain_error_rad(ppm: f64, angle_rad: f64) -> f64 {
    ppm * 1e-6 * angle_rad
}

/// A quantity drifting linearly by `amount` over the campaign, at
/// `fraction` of it (any unit: the result has `amount`'s).
pub fn linear_drift(amount: f64, fraction: f64) -> f64 {
    amount * fraction
}
