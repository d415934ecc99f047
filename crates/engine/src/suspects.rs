//! Why data cannot come from the described machine: each usual mistake is
//! undone in turn and the data identified again; a mistake whose undoing
//! makes the data fit is named, with the fit it gives.
//!
//! The mistakes tried: the encoder columns `phi` and `theta` exchanged; two
//! leg columns exchanged or the three rotated; the scale logged in m or um
//! instead of mm; an encoder or the scale counting the other way; and the
//! machine file's U-joint axis order (`x-first`/`y-first`) not the
//! machine's. Each is a plain identification (no outlier screen) on at most
//! [`MAX_POSES`] poses spread over the file, so the search costs a few
//! milliseconds.

use serde::Serialize;
use tricept_data::{Dataset, Readings};
use tricept_kinematics::{Machine, description::AxisOrder};
use tricept_model::ParameterSet;

use crate::identify::identify;
use crate::model::GeometricModel;
use crate::options::IdentifyOptions;
use crate::verdict::INCONSISTENT_CHI2_PER_DOF;

/// Largest number of poses each trial identification uses.
pub const MAX_POSES: usize = 150;

/// A mistake that, undone, makes the data fit the machine.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LikelyCause {
    /// What the mistake is, in words.
    pub description: String,
    /// Chi-square per degree of freedom with the mistake undone.
    pub chi2_per_dof: f64,
}

/// A candidate mistake: how to undo it on the data or on the machine.
struct Trial {
    description: String,
    readings: Option<fn(Readings) -> Readings>,
    commands: Option<[usize; 3]>,
    axis_order: Option<AxisOrder>,
}

fn trials(machine: &Machine) -> Vec<Trial> {
    let data = |description: &str, f: fn(Readings) -> Readings| Trial {
        description: description.to_string(),
        readings: Some(f),
        commands: None,
        axis_order: None,
    };
    let legs = |description: &str, order: [usize; 3]| Trial {
        description: description.to_string(),
        readings: None,
        commands: Some(order),
        axis_order: None,
    };
    let other = match machine.up_limb.axis_order {
        AxisOrder::XFirst => AxisOrder::YFirst,
        AxisOrder::YFirst => AxisOrder::XFirst,
    };
    vec![
        data("the columns phi and theta are exchanged", |r| Readings {
            phi_rad: r.theta_rad,
            theta_rad: r.phi_rad,
            s_mm: r.s_mm,
        }),
        legs("the columns q1 and q2 are exchanged", [1, 0, 2]),
        legs("the columns q1 and q3 are exchanged", [2, 1, 0]),
        legs("the columns q2 and q3 are exchanged", [0, 2, 1]),
        legs(
            "the leg columns are rotated (q1,q2,q3 hold legs 2,3,1)",
            [2, 0, 1],
        ),
        legs(
            "the leg columns are rotated (q1,q2,q3 hold legs 3,1,2)",
            [1, 2, 0],
        ),
        data("the scale `s` is logged in m, not mm", |r| Readings {
            s_mm: r.s_mm * 1e3,
            ..r
        }),
        data("the scale `s` is logged in um, not mm", |r| Readings {
            s_mm: r.s_mm * 1e-3,
            ..r
        }),
        data("the phi encoder counts the other way", |r| Readings {
            phi_rad: -r.phi_rad,
            ..r
        }),
        data("the theta encoder counts the other way", |r| Readings {
            theta_rad: -r.theta_rad,
            ..r
        }),
        data("the scale counts the other way", |r| Readings {
            s_mm: -r.s_mm,
            ..r
        }),
        Trial {
            description: format!(
                "the machine file is wrong: its U joint is {}, and the data fit the same machine with the {other} axis order",
                machine.up_limb.axis_order
            ),
            readings: None,
            commands: None,
            axis_order: Some(other),
        },
    ]
}

/// The mistakes whose undoing makes `data` fit `machine` (chi-square per
/// degree of freedom below [`INCONSISTENT_CHI2_PER_DOF`] and a hundred
/// times below `given_chi2_per_dof`, the fit as given), best first.
///
/// # Example
/// ```
/// use tricept_engine::{model::GeometricModel, IdentifyOptions, identify, suspects::likely_causes};
/// use tricept_kinematics::Machine;
/// use tricept_model::ParameterSet;
/// use tricept_plant::{Campaign, Plant};
/// let m = Machine::paper();
/// let set = ParameterSet::paper15();
/// let mut data = Plant::geometric(m.clone(), set.to_errors(&set.table2()))
///     .simulate(&Campaign::grid(&m, 1))
///     .unwrap();
/// for p in &mut data.poses {
///     std::mem::swap(&mut p.readings.phi_rad, &mut p.readings.theta_rad);
/// }
/// let options = IdentifyOptions::for_machine(&m);
/// let id = identify(&GeometricModel::new(m.clone(), set.clone()), &data, &options).unwrap();
/// let causes = likely_causes(&m, &set, &data, &options, id.stats.reduced_chi_square);
/// assert_eq!(causes[0].description, "the columns phi and theta are exchanged");
/// assert!(causes[0].chi2_per_dof < 2.0);
/// ```
pub fn likely_causes(
    machine: &Machine,
    set: &ParameterSet,
    data: &Dataset,
    options: &IdentifyOptions,
    given_chi2_per_dof: f64,
) -> Vec<LikelyCause> {
    let step = data.poses.len().div_ceil(MAX_POSES).max(1);
    let sample = data.subset(|j| j % step == 0);
    let mut found: Vec<LikelyCause> = trials(machine)
        .into_iter()
        .filter_map(|t| {
            let mut d = sample.clone();
            for p in &mut d.poses {
                if let Some(f) = t.readings {
                    p.readings = f(p.readings);
                }
                if let Some(order) = t.commands {
                    let q = p.commands_mm;
                    p.commands_mm = order.map(|i| q[i]);
                }
            }
            let m = match t.axis_order {
                Some(order) => machine.clone().with_axis_order(order),
                None => machine.clone(),
            };
            let id = identify(&GeometricModel::new(m, set.clone()), &d, options).ok()?;
            let chi2 = id.stats.reduced_chi_square;
            (id.converged && chi2 < INCONSISTENT_CHI2_PER_DOF && chi2 * 100.0 < given_chi2_per_dof)
                .then_some(LikelyCause {
                    description: t.description,
                    chi2_per_dof: chi2,
                })
        })
        .collect();
    found.sort_by(|a, b| a.chi2_per_dof.total_cmp(&b.chi2_per_dof));
    found
}
