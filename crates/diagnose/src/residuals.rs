//! The structure left in residuals: correlations of each reading channel
//! with every regressor the data offer (platform position, joints, leg
//! commands, pose order, time, temperature, approach directions), and the
//! residual plots that show a cause before and after it is modelled.

use tricept_data::Dataset;
use tricept_kinematics::units::RAD_PER_ARCSEC;
use tricept_kinematics::{Machine, UpJoints};
use tricept_model::effects::{CauseName, EffectName, GenericFamily};
use tricept_numerics::stats::chi2_sf;

use crate::report::{Cause, ResidualPlot, Structure};
use crate::select::{Fit, residuals_of};

/// Regressors of every pose (name, value per pose).
fn regressors(nominal: &Machine, data: &Dataset) -> Vec<(String, Vec<f64>)> {
    let n = data.poses.len();
    let mut out: Vec<(String, Vec<f64>)> = Vec::new();
    let fk: Vec<Option<(UpJoints, nalgebra::Vector3<f64>)>> = data
        .poses
        .iter()
        .map(|p| {
            nominal
                .forward(&p.commands_mm)
                .ok()
                .map(|f| (f.up, f.position_mm))
        })
        .collect();
    type Solved = (UpJoints, nalgebra::Vector3<f64>);
    let get = |f: &dyn Fn(&Solved) -> f64| -> Vec<f64> {
        fk.iter().map(|v| v.as_ref().map_or(f64::NAN, f)).collect()
    };
    out.push(("x_mm".into(), get(&|v| v.1.x)));
    out.push(("y_mm".into(), get(&|v| v.1.y)));
    out.push(("z_mm".into(), get(&|v| v.1.z)));
    out.push(("phi_rad".into(), get(&|v| v.0.phi_rad)));
    out.push(("theta_rad".into(), get(&|v| v.0.theta_rad)));
    out.push(("q4_mm".into(), get(&|v| v.0.q4_mm)));
    for i in 0..3 {
        out.push((
            format!("q{}_mm", i + 1),
            data.poses.iter().map(|p| p.commands_mm[i]).collect(),
        ));
    }
    out.push(("pose_index".into(), (0..n).map(|j| j as f64).collect()));
    if data.poses.iter().all(|p| p.time_s.is_some()) {
        out.push((
            "time_s".into(),
            data.poses.iter().map(|p| p.time_s.unwrap_or(0.0)).collect(),
        ));
    }
    if data.poses.iter().all(|p| p.temp_c.is_some()) {
        out.push((
            "temp_c".into(),
            data.poses.iter().map(|p| p.temp_c.unwrap_or(0.0)).collect(),
        ));
    }
    if data.poses.iter().all(|p| p.approach.is_some()) {
        for i in 0..3 {
            out.push((
                format!("dir{}", i + 1),
                data.poses
                    .iter()
                    .map(|p| f64::from(p.approach.map_or(0, |a| a[i])))
                    .collect(),
            ));
        }
    }
    out
}

fn correlation(x: &[f64], y: &[f64]) -> Option<f64> {
    let pairs: Vec<(f64, f64)> = x
        .iter()
        .zip(y)
        .filter(|(a, b)| a.is_finite() && b.is_finite())
        .map(|(a, b)| (*a, *b))
        .collect();
    let n = pairs.len() as f64;
    if n < 4.0 {
        return None;
    }
    let (mx, my) = pairs
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for (x, y) in &pairs {
        sxy += (x - mx) * (y - my);
        sxx += (x - mx) * (x - mx);
        syy += (y - my) * (y - my);
    }
    (sxx > 0.0 && syy > 0.0).then(|| sxy / (sxx * syy).sqrt())
}

pub(crate) fn structure(
    nominal: &Machine,
    data: &Dataset,
    residuals: &[Option<[f64; 3]>],
) -> Vec<Structure> {
    let regs = regressors(nominal, data);
    let n = data.poses.len() as f64;
    let mut out = Vec::new();
    for (c, channel) in ["phi", "theta", "s"].iter().enumerate() {
        let y: Vec<f64> = residuals
            .iter()
            .map(|r| r.map_or(f64::NAN, |r| r[c]))
            .collect();
        for (name, x) in &regs {
            if let Some(r) = correlation(x, &y) {
                let z = r.clamp(-0.999_999, 0.999_999).atanh() * (n - 3.0).max(1.0).sqrt();
                out.push(Structure {
                    regressor: name.clone(),
                    channel,
                    correlation: r,
                    p_value: chi2_sf(z * z, 1.0),
                });
            }
        }
    }
    out.sort_by(|a, b| a.p_value.total_cmp(&b.p_value));
    out.truncate(6);
    out
}

/// What a residual plot shows: the effect, its first leg (0-2), its
/// channel (0-2) and, for a periodic term, its period (mm).
pub(crate) struct PlotOf {
    pub(crate) effect: CauseName,
    pub(crate) leg: usize,
    pub(crate) channel: usize,
    pub(crate) period_mm: Option<f64>,
}

impl PlotOf {
    /// The plot of a named cause.
    pub(crate) fn cause(cause: &Cause) -> PlotOf {
        PlotOf {
            effect: cause.effect,
            leg: cause
                .legs
                .first()
                .map_or(0, |l| usize::from(*l).saturating_sub(1)),
            channel: match cause.channel {
                Some("phi") => 0,
                Some("theta") => 1,
                _ => 2,
            },
            period_mm: cause
                .parameters
                .iter()
                .find(|p| p.name.ends_with("period_mm"))
                .map(|p| p.value),
        }
    }
}

/// Residual plot of a cause: leg-length residuals (`J1` times the joint
/// residuals, um) against the leg's regressor for leg effects; reading
/// residuals against the exposing joint value or time otherwise.
pub(crate) fn residual_plot(
    of: &PlotOf,
    nominal: &Machine,
    data: &Dataset,
    geo: &Fit,
    fin: &Fit,
    sigma: &[f64; 3],
) -> Option<ResidualPlot> {
    use CauseName::{Catalogue as C, Generic as G};
    let (effect, leg, channel, period) = (of.effect, of.leg, of.channel, of.period_mm);
    let unit = |c: usize| if c == 2 { 1e3 } else { 1.0 / RAD_PER_ARCSEC };
    let series = |f: &Fit| -> Vec<(f64, f64)> {
        let res = residuals_of(f, &data.poses, sigma);
        data.poses
            .iter()
            .enumerate()
            .zip(res)
            .filter_map(|((j, p), r)| {
                let r = r?;
                let joint = [0, 1, 2].map(|c| r[c] * sigma[c]);
                let fk = nominal.forward(&p.commands_mm).ok()?;
                let legs = nominal.legs_at(&fk.up).j1() * nalgebra::Vector3::from(joint);
                let order = p.time_s.unwrap_or(j as f64);
                let x_y = match effect {
                    C(EffectName::LegLead) => (p.commands_mm[0], legs[0] * 1e3),
                    C(EffectName::Backlash) => (
                        f64::from(p.approach?[0]) + 0.02 * (p.line % 7) as f64,
                        legs[0] * 1e3,
                    ),
                    C(EffectName::Thermal) => (p.temp_c?, legs.sum() / 3.0 * 1e3),
                    C(EffectName::Compliance) => (
                        fk.up.theta_rad.hypot(fk.up.phi_rad).to_degrees(),
                        legs.sum() / 3.0 * 1e3,
                    ),
                    C(EffectName::ScaleGain) => (fk.up.q4_mm, joint[2] * 1e3),
                    C(EffectName::EncoderEccentricity) => {
                        (fk.up.phi_rad.to_degrees(), joint[0] / RAD_PER_ARCSEC)
                    }
                    C(EffectName::UjointAxes) => {
                        (fk.up.theta_rad.to_degrees(), joint[0] / RAD_PER_ARCSEC)
                    }
                    C(EffectName::TubeTwist) => (fk.up.q4_mm, legs[0] * 1e3),
                    C(EffectName::Outliers) => {
                        (p.line as f64, r.iter().fold(0.0f64, |a, v| a.max(v.abs())))
                    }
                    G(GenericFamily::LegPeriodic) => (
                        p.commands_mm[leg].rem_euclid(period.unwrap_or(f64::INFINITY)),
                        legs[leg] * 1e3,
                    ),
                    G(GenericFamily::LegPolynomial) => (p.commands_mm[leg], legs[leg] * 1e3),
                    G(GenericFamily::LegDrift) => (order, legs[leg] * 1e3),
                    G(GenericFamily::ReadingTemperature) => {
                        (p.temp_c?, joint[channel] * unit(channel))
                    }
                    G(GenericFamily::EncoderGain) => {
                        let angle = if channel == 0 {
                            fk.up.phi_rad
                        } else {
                            fk.up.theta_rad
                        };
                        (angle.to_degrees(), joint[channel] * unit(channel))
                    }
                    G(GenericFamily::ScalePolynomial) => (fk.up.q4_mm, joint[2] * 1e3),
                    G(GenericFamily::ReadingDrift) | G(GenericFamily::ReadingHysteresis) => {
                        (order, joint[channel] * unit(channel))
                    }
                };
                Some(x_y)
            })
            .collect()
    };
    let reading = |c: usize| {
        format!(
            "{} residual ({})",
            ["phi", "theta", "s"][c],
            if c == 2 { "um" } else { "arcsec" }
        )
    };
    let (x_label, y_label): (String, String) = match effect {
        C(EffectName::LegLead) => (
            "leg 1 command (mm)".into(),
            "leg 1 length residual (um)".into(),
        ),
        C(EffectName::Backlash) => (
            "leg 1 approach direction".into(),
            "leg 1 length residual (um)".into(),
        ),
        C(EffectName::Thermal) => (
            "temperature (°C)".into(),
            "mean leg length residual (um)".into(),
        ),
        C(EffectName::Compliance) => (
            "tilt of the UP limb (deg)".into(),
            "mean leg length residual (um)".into(),
        ),
        C(EffectName::ScaleGain) => ("q4 (mm)".into(), "scale residual (um)".into()),
        C(EffectName::EncoderEccentricity) => ("phi (deg)".into(), "phi residual (arcsec)".into()),
        C(EffectName::UjointAxes) => ("theta (deg)".into(), "phi residual (arcsec)".into()),
        C(EffectName::TubeTwist) => ("q4 (mm)".into(), "leg 1 length residual (um)".into()),
        C(EffectName::Outliers) => (
            "line of the data file".into(),
            "largest |residual| (sigma)".into(),
        ),
        G(GenericFamily::LegPeriodic) => (
            format!("leg {} command modulo the period (mm)", leg + 1),
            format!("leg {} length residual (um)", leg + 1),
        ),
        G(GenericFamily::LegPolynomial) => (
            format!("leg {} command (mm)", leg + 1),
            format!("leg {} length residual (um)", leg + 1),
        ),
        G(GenericFamily::LegDrift) => (
            "time (s) or pose".into(),
            format!("leg {} length residual (um)", leg + 1),
        ),
        G(GenericFamily::ReadingTemperature) => ("temperature (°C)".into(), reading(channel)),
        G(GenericFamily::EncoderGain) => (
            format!("{} (deg)", ["phi", "theta", "s"][channel]),
            reading(channel),
        ),
        G(GenericFamily::ScalePolynomial) => ("q4 (mm)".into(), reading(2)),
        G(GenericFamily::ReadingDrift) | G(GenericFamily::ReadingHysteresis) => {
            ("time (s) or pose".into(), reading(channel))
        }
    };
    Some(ResidualPlot {
        effect,
        x_label,
        y_label,
        before: series(geo),
        after: series(fin),
    })
}
