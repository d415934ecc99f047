//! The structure left in residuals: correlations of each reading channel
//! with every regressor the data offer (platform position, joints, leg
//! commands, pose order, time, temperature, approach directions), and the
//! residual plots that show a cause before and after it is modelled.

use tricept_data::Dataset;
use tricept_kinematics::units::RAD_PER_ARCSEC;
use tricept_kinematics::{Machine, up_limb::UpJoints};
use tricept_model::effects::{CauseName, PlotAxes, XAxis, YAxis};
use tricept_numerics::stats::chi2_sf;

use crate::fit::{Fit, residuals_of};
use crate::report::{Cause, ResidualPlot, Structure};

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

impl PlotOf {
    /// The axes of the plot, from the registry.
    fn axes(&self) -> PlotAxes {
        match self.effect {
            CauseName::Catalogue(e) => e.spec().plot,
            CauseName::Generic(g) => g.plot(self.leg, self.channel),
        }
    }
}

/// What the residual plot of a pose can show.
struct Point<'a> {
    pose: &'a tricept_data::MeasuredPose,
    /// The pose's position in the file.
    index: usize,
    /// The nominal UP joints at the commands.
    up: UpJoints,
    /// Weighted residuals (noise units).
    weighted: [f64; 3],
    /// Joint residuals (rad, rad, mm).
    joint: [f64; 3],
    /// Leg-length residuals (`J1` times the joint residuals), mm.
    legs: nalgebra::Vector3<f64>,
}

impl Point<'_> {
    fn x(&self, axis: XAxis, period_mm: Option<f64>) -> Option<f64> {
        let (p, up) = (self.pose, &self.up);
        Some(match axis {
            XAxis::LegCommand(i) => p.commands_mm[i],
            XAxis::LegCommandModuloPeriod(i) => {
                p.commands_mm[i].rem_euclid(period_mm.unwrap_or(f64::INFINITY))
            }
            XAxis::LegApproach(i) => f64::from(p.approach?[i]) + 0.02 * (p.line % 7) as f64,
            XAxis::Temperature => p.temp_c?,
            XAxis::Tilt => up.theta_rad.hypot(up.phi_rad).to_degrees(),
            XAxis::Extension => up.q4_mm,
            XAxis::Angle(c) => if c == 0 { up.phi_rad } else { up.theta_rad }.to_degrees(),
            XAxis::Line => p.line as f64,
            XAxis::Order => p.time_s.unwrap_or(self.index as f64),
        })
    }

    fn y(&self, axis: YAxis) -> f64 {
        match axis {
            YAxis::LegResidual(i) => self.legs[i] * 1e3,
            YAxis::MeanLegResidual => self.legs.sum() / 3.0 * 1e3,
            YAxis::ScaleResidual => self.joint[2] * 1e3,
            YAxis::Reading(2) => self.joint[2] * 1e3,
            YAxis::Reading(c) => self.joint[c] / RAD_PER_ARCSEC,
            YAxis::LargestResidualSigma => self.weighted.iter().fold(0.0f64, |a, v| a.max(v.abs())),
        }
    }
}

/// Residual plot of a cause (its axes from the registry): leg-length
/// residuals (`J1` times the joint residuals, um) against the leg's
/// regressor for leg effects; reading residuals against the exposing joint
/// value or time otherwise.
pub(crate) fn residual_plot(
    of: &PlotOf,
    nominal: &Machine,
    data: &Dataset,
    geo: &Fit,
    fin: &Fit,
    sigma: &[f64; 3],
) -> Option<ResidualPlot> {
    let axes = of.axes();
    let series = |f: &Fit| -> Vec<(f64, f64)> {
        let res = residuals_of(f, &data.poses, sigma);
        data.poses
            .iter()
            .enumerate()
            .zip(res)
            .filter_map(|((index, pose), r)| {
                let weighted = r?;
                let joint = [0, 1, 2].map(|c| weighted[c] * sigma[c]);
                let up = nominal.forward(&pose.commands_mm).ok()?.up;
                let legs = nominal.legs_at(&up).j1() * nalgebra::Vector3::from(joint);
                let point = Point {
                    pose,
                    index,
                    up,
                    weighted,
                    joint,
                    legs,
                };
                Some((point.x(axes.x, of.period_mm)?, point.y(axes.y)))
            })
            .collect()
    };
    Some(ResidualPlot {
        effect: of.effect,
        x_label: axes.x.label(),
        y_label: axes.y.label(),
        before: series(geo),
        after: series(fin),
    })
}
