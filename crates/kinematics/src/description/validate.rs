//! The checks of a description: finite numbers, sizes a machine can have,
//! distinct and non-collinear joints, ordered limits, a head that turns the
//! tool, plausible calibration values; each error names its key.

use super::{MAX_HEAD_ANGLE_OFFSET_RAD, MAX_LENGTH_MM, MachineDescription, Placement};
use crate::error::DescriptionError;

impl MachineDescription {
    /// Checks that the description is a possible machine, of a format
    /// version this tricept reads (its own and the machines inside its
    /// calibration record).
    pub fn validate(&self) -> Result<(), DescriptionError> {
        super::check_version(self.format_version, "machine file", super::FORMAT_VERSION)?;
        let invalid = |key: &str, reason: String| DescriptionError::Invalid {
            key: key.to_string(),
            reason,
        };
        let finite = |key: &str, values: &[f64]| -> Result<(), DescriptionError> {
            match values.iter().find(|v| !v.is_finite()) {
                Some(v) => Err(invalid(key, format!("{v} is not a finite number"))),
                None => Ok(()),
            }
        };
        let positive = |key: &str, v: f64| -> Result<(), DescriptionError> {
            finite(key, &[v])?;
            if v > 0.0 {
                Ok(())
            } else {
                Err(invalid(key, format!("must be positive, got {v}")))
            }
        };
        match &self.placement {
            Placement::Circular(c) => {
                positive("placement.circular.base_radius_mm", c.base_radius_mm)?;
                positive(
                    "placement.circular.platform_radius_mm",
                    c.platform_radius_mm,
                )?;
                finite("placement.circular.joint_angles_deg", &c.joint_angles_deg)?;
            }
            Placement::Explicit(e) => {
                finite(
                    "placement.explicit.base_joints_mm",
                    e.base_joints_mm.as_flattened(),
                )?;
                finite(
                    "placement.explicit.platform_joints_mm",
                    e.platform_joints_mm.as_flattened(),
                )?;
            }
        }
        // Finite is not enough: 1e200 mm would pass every check below and
        // overflow inside the solvers.
        let size = |key: &str, values: &[f64]| -> Result<(), DescriptionError> {
            finite(key, values)?;
            match values.iter().find(|v| v.abs() > MAX_LENGTH_MM) {
                Some(v) => Err(invalid(
                    key,
                    format!(
                        "{v} mm is not the size of a machine (lengths are limited to {MAX_LENGTH_MM} mm)"
                    ),
                )),
                None => Ok(()),
            }
        };
        match &self.placement {
            Placement::Circular(c) => size(
                "placement.circular",
                &[c.base_radius_mm, c.platform_radius_mm],
            )?,
            Placement::Explicit(e) => {
                size(
                    "placement.explicit.base_joints_mm",
                    e.base_joints_mm.as_flattened(),
                )?;
                size(
                    "placement.explicit.platform_joints_mm",
                    e.platform_joints_mm.as_flattened(),
                )?;
            }
        }
        size("leg_offsets_mm", &self.leg_offsets_mm)?;
        size(
            "up_limb",
            &[self.up_limb.axis_offset_mm, self.up_limb.twist_reference_mm],
        )?;
        size(
            "workspace",
            &[
                self.workspace.radius_mm,
                self.workspace.height_mm,
                self.workspace.distance_mm,
            ],
        )?;
        size("limits.leg_stroke_mm", &self.limits.leg_stroke_mm)?;
        size("limits.up_stroke_mm", &self.limits.up_stroke_mm)?;
        for (key, v) in [
            ("head.axis1_point_mm", self.head.axis1_point_mm),
            ("head.axis2_point_mm", self.head.axis2_point_mm),
            ("head.tool_tip_mm", self.head.tool_tip_mm),
            ("loads.head_com_mm", self.loads.head_com_mm),
        ] {
            size(key, &v)?;
        }
        let e = &self.leg_effects;
        finite("leg_effects.lead_ppm", &e.lead_ppm)?;
        finite(
            "leg_effects.compliance_um_per_kn_at_1m",
            &[e.compliance_um_per_kn_at_1m],
        )?;
        if let Some(v) = e.lead_ppm.iter().find(|v| v.abs() > 1e4) {
            return Err(invalid(
                "leg_effects.lead_ppm",
                format!("{v} ppm is not a lead error (limit 10000 ppm, 1 %)"),
            ));
        }
        if e.compliance_um_per_kn_at_1m.abs() > 1e4 {
            return Err(invalid(
                "leg_effects.compliance_um_per_kn_at_1m",
                format!(
                    "{} um/kN is not the compliance of a machine leg (limit 10000 um/kN)",
                    e.compliance_um_per_kn_at_1m
                ),
            ));
        }
        self.validate_leg_tables()?;
        if let Some(c) = &self.controller {
            finite("controller.backlash_um", &c.backlash_um)?;
            finite(
                "controller",
                &[c.thermal_expansion_ppm_per_k, c.reference_temperature_c],
            )?;
            if !(-60.0..=200.0).contains(&c.reference_temperature_c) {
                return Err(invalid(
                    "controller.reference_temperature_c",
                    format!("{} °C is outside -60..200 °C", c.reference_temperature_c),
                ));
            }
        }
        if let Some(c) = &self.calibration {
            if let Some(r) = &c.relative_to_machine {
                super::check_version(r.format_version, "machine file", super::FORMAT_VERSION)?;
            }
            c.nominal.validate().map_err(|e| match e {
                DescriptionError::Invalid { key, reason } => DescriptionError::Invalid {
                    key: format!("calibration.nominal.{key}"),
                    reason,
                },
                e => e,
            })?;
        }

        let (base, platform) = self.joints_mm();
        check_triangle("base joints B1..B3", &base, Some([0.0; 3]))
            .map_err(|r| invalid("placement", r))?;
        check_triangle("platform joints A1..A3", &platform, None)
            .map_err(|r| invalid("placement", r))?;

        let up = &self.up_limb;
        finite(
            "up_limb",
            &[
                up.axis_skew_rad,
                up.axis_offset_mm,
                up.twist_rad_per_mm,
                up.twist_reference_mm,
            ],
        )?;
        if up.axis_skew_rad.abs() > 0.1 {
            return Err(invalid(
                "up_limb.axis_skew_rad",
                format!(
                    "{} rad is not a small manufacturing error (limit 0.1 rad)",
                    up.axis_skew_rad
                ),
            ));
        }
        finite("leg_offsets_mm", &self.leg_offsets_mm)?;

        let w = &self.workspace;
        positive("workspace.radius_mm", w.radius_mm)?;
        positive("workspace.height_mm", w.height_mm)?;
        positive("workspace.distance_mm", w.distance_mm)?;

        let l = &self.limits;
        for (key, [lo, hi]) in [
            ("limits.leg_stroke_mm", l.leg_stroke_mm),
            ("limits.up_stroke_mm", l.up_stroke_mm),
        ] {
            positive(key, lo)?;
            positive(key, hi)?;
            if lo >= hi {
                return Err(invalid(key, format!("min {lo} must be below max {hi}")));
            }
        }
        positive("limits.max_tilt_deg", l.max_tilt_deg)?;
        if l.max_tilt_deg >= 90.0 {
            return Err(invalid(
                "limits.max_tilt_deg",
                format!("{} deg must be below 90", l.max_tilt_deg),
            ));
        }

        let h = &self.head;
        for (key, v) in [
            ("head.axis1_direction", h.axis1_direction),
            ("head.axis2_direction", h.axis2_direction),
            ("head.tool_direction", h.tool_direction),
        ] {
            finite(key, &v)?;
            if norm3(v) < 1e-9 {
                return Err(invalid(key, "direction must not be the zero vector".into()));
            }
        }
        for (key, v) in [
            ("head.axis1_point_mm", h.axis1_point_mm),
            ("head.axis2_point_mm", h.axis2_point_mm),
            ("head.tool_tip_mm", h.tool_tip_mm),
        ] {
            finite(key, &v)?;
        }
        let (a1, a2) = (unit3(h.axis1_direction), unit3(h.axis2_direction));
        if norm3(cross3(a1, a2)) < 1e-6 {
            return Err(invalid(
                "head.axis2_direction",
                "the two head axes are parallel: the head would have one degree of freedom".into(),
            ));
        }
        if norm3(cross3(a2, unit3(h.tool_direction))) < 1e-6 {
            return Err(invalid(
                "head.tool_direction",
                "the tool lies along the second head axis: that axis could not turn it".into(),
            ));
        }
        finite("head.angle_offsets_rad", &h.angle_offsets_rad)?;
        if let Some(v) = h
            .angle_offsets_rad
            .iter()
            .find(|v| v.abs() > MAX_HEAD_ANGLE_OFFSET_RAD)
        {
            return Err(invalid(
                "head.angle_offsets_rad",
                format!(
                    "{v} rad is not a zero offset of a head encoder (limit {MAX_HEAD_ANGLE_OFFSET_RAD} rad; degrees?)"
                ),
            ));
        }

        let s = &self.sensors;
        positive("sensors.angle_noise_arcsec", s.angle_noise_arcsec)?;
        positive("sensors.length_noise_um", s.length_noise_um)?;
        if s.readings_per_pose == 0 {
            return Err(invalid(
                "sensors.readings_per_pose",
                "must be at least 1".into(),
            ));
        }
        let loads = &self.loads;
        finite(
            "loads",
            &[
                loads.platform_mass_kg,
                loads.head_mass_kg,
                loads.leg_stiffness_n_per_um_at_1m,
            ],
        )?;
        if loads.platform_mass_kg < 0.0 || loads.head_mass_kg < 0.0 {
            return Err(invalid("loads", "masses must not be negative".into()));
        }
        positive(
            "loads.leg_stiffness_n_per_um_at_1m",
            loads.leg_stiffness_n_per_um_at_1m,
        )?;
        finite("loads.head_com_mm", &loads.head_com_mm)?;
        finite("loads.gravity_direction", &loads.gravity_direction)?;
        if norm3(loads.gravity_direction) < 1e-9 {
            return Err(invalid(
                "loads.gravity_direction",
                "direction must not be the zero vector".into(),
            ));
        }
        Ok(())
    }
}

fn norm3(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

fn unit3(v: [f64; 3]) -> [f64; 3] {
    let n = norm3(v);
    [v[0] / n, v[1] / n, v[2] / n]
}

fn cross3(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn sub3(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// Joints must be distinct (1 mm apart) and not collinear; base joints must
/// also stay clear of the UP limb's joint B4 at the origin.
fn check_triangle(
    what: &str,
    p: &[[f64; 3]; 3],
    also_distinct_from: Option<[f64; 3]>,
) -> Result<(), String> {
    const MIN_SEPARATION_MM: f64 = 1.0;
    for i in 0..3 {
        for j in i + 1..3 {
            let d = norm3(sub3(p[i], p[j]));
            if d < MIN_SEPARATION_MM {
                return Err(format!(
                    "{what}: joints {} and {} coincide ({d:.3} mm apart)",
                    i + 1,
                    j + 1
                ));
            }
        }
        if let Some(q) = also_distinct_from {
            let d = norm3(sub3(p[i], q));
            if d < MIN_SEPARATION_MM {
                return Err(format!(
                    "{what}: joint {} coincides with the UP limb's joint B4 at the origin",
                    i + 1
                ));
            }
        }
    }
    let area2 = norm3(cross3(sub3(p[1], p[0]), sub3(p[2], p[0])));
    let longest = (0..3)
        .map(|i| norm3(sub3(p[i], p[(i + 1) % 3])))
        .fold(0.0, f64::max);
    if area2 < 1e-3 * longest * longest {
        return Err(format!("{what} are collinear"));
    }
    Ok(())
}

/// The most points a compensation table may hold per leg.
pub const MAX_TABLE_POINTS: usize = 100_000;

/// The largest extra length a compensation table may hold, um: 1 mm, far
/// beyond any screw error (a larger value is a unit mistake).
pub const MAX_TABLE_EXTRA_UM: f64 = 1000.0;

/// The steepest a compensation table may be between neighbouring points,
/// um of extra length per mm of command: 200 um/mm (20 %) holds the
/// steepest pitch error a diagnosis finds plausible (25 um at a 1 mm
/// period, 157 um/mm) and keeps the corrected command unique (IK's passes
/// contract by the slope).
pub const MAX_TABLE_SLOPE_UM_PER_MM: f64 = 200.0;

impl MachineDescription {
    /// The checks of the per-leg compensation tables: a leg 1-3 at most
    /// once, 2 to [`MAX_TABLE_POINTS`] points, a positive finite spacing
    /// (the commands increase), a start and end within the legs' stroke,
    /// finite values within [`MAX_TABLE_EXTRA_UM`] and slopes within
    /// [`MAX_TABLE_SLOPE_UM_PER_MM`].
    fn validate_leg_tables(&self) -> Result<(), DescriptionError> {
        let mut seen = [false; 3];
        for (k, t) in self.leg_effects.tables.iter().enumerate() {
            let key = |field: &str| format!("leg_effects.tables[{k}].{field}");
            let invalid = |field: &str, reason: String| DescriptionError::Invalid {
                key: key(field),
                reason,
            };
            let Some(i) = t.leg_index() else {
                return Err(invalid("leg", format!("must be 1, 2 or 3, got {}", t.leg)));
            };
            if std::mem::replace(&mut seen[i], true) {
                return Err(invalid(
                    "leg",
                    format!("leg {} has a second table (one per leg)", t.leg),
                ));
            }
            let n = t.extra_length_um.len();
            if !(2..=MAX_TABLE_POINTS).contains(&n) {
                return Err(invalid(
                    "extra_length_um",
                    format!("must hold 2 to {MAX_TABLE_POINTS} points, got {n}"),
                ));
            }
            if !(t.step_mm.is_finite() && t.step_mm > 0.0) {
                return Err(invalid(
                    "step_mm",
                    format!(
                        "must be a positive number of mm (the commands increase along the table), got {}",
                        t.step_mm
                    ),
                ));
            }
            let [lo, hi] = self.limits.leg_stroke_mm;
            if !(t.start_mm.is_finite() && t.start_mm >= lo && t.end_mm() <= hi) {
                return Err(invalid(
                    "start_mm",
                    format!(
                        "the table covers {} to {} mm, outside the legs' stroke {lo} to {hi} mm (limits.leg_stroke_mm)",
                        t.start_mm,
                        t.end_mm()
                    ),
                ));
            }
            if let Some((j, v)) = t
                .extra_length_um
                .iter()
                .enumerate()
                .find(|(_, v)| !(v.is_finite() && v.abs() <= MAX_TABLE_EXTRA_UM))
            {
                return Err(invalid(
                    &format!("extra_length_um[{j}]"),
                    format!("{v} um is not a leg error (finite, within {MAX_TABLE_EXTRA_UM} um)"),
                ));
            }
            if let Some(j) = (1..n).find(|&j| {
                (t.extra_length_um[j] - t.extra_length_um[j - 1]).abs() / t.step_mm
                    > MAX_TABLE_SLOPE_UM_PER_MM
            }) {
                return Err(invalid(
                    &format!("extra_length_um[{j}]"),
                    format!(
                        "changes by {} um over {} mm from the point before: steeper than {MAX_TABLE_SLOPE_UM_PER_MM} um/mm",
                        t.extra_length_um[j] - t.extra_length_um[j - 1],
                        t.step_mm
                    ),
                ));
            }
        }
        Ok(())
    }
}
