//! Plausibility of a fused fit's estimates: every module, effect and head
//! parameter and every instrument nuisance with a size of its own (a
//! target offset's change from its stated value, a bar's length error, a
//! stylus' radius change) against one table of plausible ranges.
//!
//! The head's and the tool's ranges are ten times their typical sizes
//! ([`tricept_model::head_errors::TYPICAL_HEAD_ERRORS`]): a head built to a drawing is
//! off by its typical size, a 5-sigma outlier of a machine twice as bad
//! stays inside, and a tool length change of millimetres (a target that
//! is not where `--tracker-target` says, a tracker file of another tool)
//! does not. The module's range is the 10 mm beyond which `identify`
//! warns ([`crate::verdict::LARGE_ESTIMATE_MM`]); the effects' are the
//! diagnosis' (`docs/diagnosis.md`). An estimate is implausible when its
//! 3-sigma interval misses its range ([`Range::admits`]); the table is
//! overridden from a JSON object (`identify --plausibility FILE.json`,
//! [`FusionPlausibility::with_overrides`]).

use std::collections::BTreeMap;

use serde::Serialize;
use tricept_model::effects::Measure;
use tricept_model::plausibility::{
    PlausibilityError, Range, insert_range, override_ranges, round3,
};
use tricept_model::{head_errors::HEAD13_NAMES, head_errors::TYPICAL_HEAD_ERRORS};

use crate::fusion::model::{FusedModel, fusable_effects};

/// The plausibility table of a fused fit: quantity key to range.
///
/// # Example
/// ```
/// use tricept_engine::fusion::FusionPlausibility;
/// let p = FusionPlausibility::default();
/// assert_eq!(p.ranges["tool_length_mm"].max, 3.0);
/// let q = FusionPlausibility::with_overrides(r#"{"tool_length_mm": [-30, 30]}"#).unwrap();
/// assert_eq!(q.ranges["tool_length_mm"].max, 30.0);
/// assert!(FusionPlausibility::with_overrides(r#"{"tool_mm": [-1, 1]}"#).is_err());
/// ```
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FusionPlausibility {
    /// The ranges: a head parameter's name, `module_mm`, an effect's
    /// `effect.quantity`, or an instrument's `kind.quantity`.
    pub ranges: BTreeMap<String, Range>,
}

/// How many typical sizes a head or tool estimate may reach.
pub const HEAD_RANGE_TYPICAL_SIZES: f64 = 10.0;

impl Default for FusionPlausibility {
    fn default() -> FusionPlausibility {
        let mut ranges = BTreeMap::new();
        let mut add = |key: &str, min: f64, max: f64, unit: &'static str, why: String| {
            insert_range(&mut ranges, key, min, max, unit, why)
        };
        let limit = crate::verdict::LARGE_ESTIMATE_MM;
        add(
            "module_mm",
            -limit,
            limit,
            "mm",
            "machines are built to drawings to better than this".into(),
        );
        for (name, typical) in HEAD13_NAMES.iter().zip(TYPICAL_HEAD_ERRORS) {
            let (unit, shown, shown_unit) = if name.ends_with("_rad") {
                ("rad", typical * 1e3, "mrad")
            } else {
                ("mm", typical, "mm")
            };
            let r = HEAD_RANGE_TYPICAL_SIZES * typical;
            add(
                name,
                -r,
                r,
                unit,
                format!(
                    "{HEAD_RANGE_TYPICAL_SIZES} times the typical error of a head as built ({shown} {shown_unit})"
                ),
            );
        }
        for e in fusable_effects() {
            for j in e.spec().plausible {
                let r = &j.range;
                add(
                    &format!("{e}.{}", r.quantity),
                    r.min,
                    r.max,
                    r.unit,
                    r.why.into(),
                );
            }
        }
        add(
            "tracker.target_change_mm",
            -0.5,
            0.5,
            "mm",
            "a target stated with tracker_target sits where it is stated to a few um".into(),
        );
        add(
            "tracker.target_free_mm",
            -300.0,
            300.0,
            "mm",
            "a target in the spindle, on an extension at most".into(),
        );
        add(
            "ballbar.length_error_mm",
            -0.05,
            0.05,
            "mm",
            "a bar calibrated to a few um; beyond: another bar, or its nominal length misread"
                .into(),
        );
        add(
            "touch.stylus_radius_change_mm",
            -0.05,
            0.05,
            "mm",
            "a calibrated stylus; beyond: another stylus, or its radius misread".into(),
        );
        FusionPlausibility { ranges }
    }
}

impl FusionPlausibility {
    /// The default table with overrides from a JSON object of
    /// `key: [min, max]` (every key must be in the table).
    pub fn with_overrides(json: &str) -> Result<FusionPlausibility, PlausibilityError> {
        let mut p = FusionPlausibility::default();
        override_ranges(&mut p.ranges, json)?;
        Ok(p)
    }

    /// The key of a global parameter of `model` at column `j`.
    pub(crate) fn key_of(model: &FusedModel, j: usize) -> String {
        let name = &model.names()[j];
        if model.module_range().contains(&j) {
            "module_mm".into()
        } else if let Some((e, i)) = model.effect_parameter(j) {
            // The range that judges the parameter itself (lead1_ppm,
            // lead2_ppm and lead3_ppm share one).
            e.spec()
                .plausible
                .iter()
                .find(|r| r.of.iter().any(|(m, _)| *m == Measure::Parameter(i)))
                .map_or_else(|| name.clone(), |r| format!("{e}.{}", r.range.quantity))
        } else {
            name.clone()
        }
    }
}

/// An estimate outside its plausible range.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Implausible {
    /// The parameter's or nuisance's name.
    pub name: String,
    /// The table key it was judged by.
    pub key: String,
    /// The value judged (a change from a stated value for some nuisance).
    pub value: f64,
    /// Its standard deviation.
    pub std_dev: f64,
    /// The range it misses.
    pub range: Range,
}

impl Implausible {
    /// One sentence.
    pub fn to_text(&self) -> String {
        format!(
            "{} = {} +- {} {} is far outside its plausible range {} to {} {} ({})",
            self.name,
            round3(self.value),
            round3(self.std_dev),
            self.range.unit,
            round3(self.range.min),
            round3(self.range.max),
            self.range.unit,
            self.range.why
        )
    }
}
