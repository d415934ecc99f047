//! What the extended model changes where it matters: the platform's
//! displacement on the middle plane between the geometric-only
//! calibration and the final one.

use tricept_data::MeasuredPose;
use tricept_ident::ReadingModel;
use tricept_kinematics::Machine;

use crate::fit::Fit;
use crate::options::DiagnoseOptions;

/// Mean, max and touched-off mean displacement of the platform on the
/// middle plane between the geometric-only calibration and the final one
/// (targets commanded through the geometric fit's IK, positions predicted
/// by the final model with the leg effects at the campaign's mean context),
/// and a note when targets could not be reached.
pub(crate) fn volumetric_difference(
    nominal: &Machine,
    geo: &Fit,
    fin: &Fit,
    options: &DiagnoseOptions,
) -> (Option<(f64, f64, f64)>, Option<String>) {
    let targets = nominal
        .workspace
        .disc_grid(nominal.workspace.mid_plane_z_mm(), options.plane_spacing_mm);
    let m_geo = geo.model.machine_at(&geo.id.estimate);
    let m_fin = fin.model.machine_at(&fin.id.estimate);
    let predictor = fin.model.at(&fin.id.estimate);
    let k = fin.model.names().len();
    let mut jac = vec![0.0; 3 * k];
    let mut map = tricept_model::ErrorMap {
        targets_mm: Vec::new(),
        errors_mm: Vec::new(),
    };
    for r in &targets {
        let Ok(ik) = m_geo.inverse(r) else { continue };
        let pose = MeasuredPose {
            commands_mm: ik.legs_mm,
            approach: None,
            ..Default::default()
        };
        let mut seed = Some(ik.up);
        // The final model's reading prediction solves its UP joints (the
        // reading effects are sensor-side and do not move the platform).
        if predictor.predict(&pose, &mut seed, &mut jac).is_err() {
            continue;
        }
        let Some(up) = seed else { continue };
        map.targets_mm.push(*r);
        map.errors_mm.push(m_fin.up_limb.pose(&up).position_mm - r);
    }
    let reached = map.targets_mm.len();
    if reached == 0 {
        return (
            None,
            Some(format!(
                "the calibrations cannot reach the middle plane (0 of {} targets)",
                targets.len()
            )),
        );
    }
    let raw = map.stats();
    let touched = map.without_mean_translation().stats();
    let note = (reached < targets.len()).then(|| {
        format!(
            "{reached} of {} middle-plane targets reached",
            targets.len()
        )
    });
    (Some((raw.mean_mm, raw.max_mm, touched.mean_mm)), note)
}
