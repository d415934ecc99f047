//! Touch-offs (`q1,q2,q3,h1,h2,feature`) and the features file (JSON)
//! they refer to.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::{ExternalData, ExternalPose, ExternalRow, Row, instrument_record};
use crate::DataError;

/// One touch of a probe in the spindle on a feature of the features file.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TouchReading {
    /// Where the machine stood when the probe triggered (latched values).
    pub pose: ExternalPose,
    /// Id of the feature touched.
    pub feature: u32,
    /// Standard deviation of the touch along the surface normal, um
    /// (`None`: the default).
    pub sigma_um: Option<f64>,
    /// Structure temperature, °C.
    pub temp_c: Option<f64>,
    /// Line in the file (0 if none).
    pub line: u64,
}

/// Touches of a probe.
pub type TouchData = ExternalData<TouchReading>;

impl ExternalRow for TouchReading {
    const MEASURED: &'static [&'static str] = &["feature"];
    const OPTIONAL: &'static [&'static str] = &["sigma_um", "temp_c"];

    fn from_row(pose: ExternalPose, row: &Row<'_>) -> Result<Self, DataError> {
        let f = row.measured(0)?;
        if f < 1.0 || f.fract() != 0.0 || f > f64::from(u32::MAX) {
            return Err(row.bad(
                row.measured_column(0),
                "a feature id must be a whole number from 1",
            ));
        }
        Ok(TouchReading {
            feature: f as u32,
            ..TouchReading::with_reading(row.reading(pose)?)
        })
    }

    fn own_value(&self, column: &str) -> Option<f64> {
        (column == "feature").then_some(f64::from(self.feature))
    }
}

instrument_record!(TouchReading);

/// The probe's stylus.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Stylus {
    /// Effective radius of the stylus ball (pre-travel included), mm.
    pub radius_mm: f64,
    /// Standard deviation of that radius (calibration certificate), um.
    pub radius_sigma_um: f64,
}

/// A reference feature on the table or the part, touched by the probe.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum Feature {
    /// A reference sphere of known radius; its centre is unknown.
    Sphere {
        /// Id used by the touch file's `feature` column.
        id: u32,
        /// Radius, mm.
        radius_mm: f64,
        /// Standard deviation of the radius, um.
        #[serde(default)]
        radius_sigma_um: f64,
    },
    /// A plane; its position and orientation are unknown.
    Plane {
        /// Id used by the touch file's `feature` column.
        id: u32,
    },
}

impl Feature {
    /// The feature's id.
    pub fn id(&self) -> u32 {
        match self {
            Feature::Sphere { id, .. } | Feature::Plane { id } => *id,
        }
    }
}

/// The features file of a touch-off campaign (JSON).
///
/// # Example
/// ```
/// let json = r#"{"stylus": {"radius_mm": 1.0, "radius_sigma_um": 2.0},
///   "features": [{"id": 1, "kind": "sphere", "radius_mm": 12.7, "radius_sigma_um": 0.5},
///                {"id": 2, "kind": "plane"}]}"#;
/// let f = tricept_data::external::Features::from_json(json, "features.json").unwrap();
/// assert_eq!(f.features.len(), 2);
/// let e = tricept_data::external::Features::from_json(r#"{"stylus": {"radius_mm": 1.0, "radius_sigma_um": 2.0},
///   "features": [{"id": 1, "kind": "cube"}]}"#, "f.json").unwrap_err();
/// assert!(e.to_string().starts_with("f.json: line 2, column"), "{e}");
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Features {
    /// The stylus.
    pub stylus: Stylus,
    /// The features, with distinct ids.
    pub features: Vec<Feature>,
}

/// The largest stylus ball radius a features file may state, mm.
pub const MAX_STYLUS_RADIUS_MM: f64 = 50.0;
/// The largest sphere radius a features file may state, mm.
pub const MAX_SPHERE_RADIUS_MM: f64 = 1000.0;

impl Features {
    /// Parses and checks a features file's text; `file` names it in errors.
    pub fn from_json(text: &str, file: &str) -> Result<Features, DataError> {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let f: Features = serde_json::from_str(text).map_err(|e| DataError::Json {
            file: file.into(),
            line: e.line() as u64,
            column: e.column() as u64,
            message: strip_position(&e.to_string()),
        })?;
        let invalid = |message: String| DataError::Invalid {
            file: file.into(),
            message,
        };
        let s = f.stylus;
        if !(s.radius_mm.is_finite() && (0.0..=MAX_STYLUS_RADIUS_MM).contains(&s.radius_mm)) {
            return Err(invalid(format!(
                "stylus.radius_mm must be a number of mm from 0 to {MAX_STYLUS_RADIUS_MM}, got {}",
                s.radius_mm
            )));
        }
        if !(s.radius_sigma_um.is_finite() && s.radius_sigma_um > 0.0) {
            return Err(invalid(format!(
                "stylus.radius_sigma_um must be positive, got {}",
                s.radius_sigma_um
            )));
        }
        for (k, feature) in f.features.iter().enumerate() {
            if f.features[..k].iter().any(|g| g.id() == feature.id()) {
                return Err(invalid(format!(
                    "feature id {} appears twice",
                    feature.id()
                )));
            }
            if let Feature::Sphere {
                radius_mm,
                radius_sigma_um,
                id,
            } = feature
            {
                if !(radius_mm.is_finite()
                    && *radius_mm > 0.0
                    && *radius_mm <= MAX_SPHERE_RADIUS_MM)
                {
                    return Err(invalid(format!(
                        "feature {id}: radius_mm must be positive and at most {MAX_SPHERE_RADIUS_MM} mm, got {radius_mm}"
                    )));
                }
                if !(radius_sigma_um.is_finite() && *radius_sigma_um >= 0.0) {
                    return Err(invalid(format!(
                        "feature {id}: radius_sigma_um must be non-negative, got {radius_sigma_um}"
                    )));
                }
            }
        }
        if f.features.is_empty() {
            return Err(invalid("no features".into()));
        }
        Ok(f)
    }

    /// Reads and checks a features file.
    pub fn from_path(path: &Path) -> Result<Features, DataError> {
        let file = path.display().to_string();
        let text = crate::bounded::read_json_text(path).map_err(|source| DataError::Io {
            file: file.clone(),
            source,
        })?;
        Features::from_json(&text, &file)
    }

    /// The feature with id `id`.
    pub fn get(&self, id: u32) -> Option<&Feature> {
        self.features.iter().find(|f| f.id() == id)
    }
}

/// serde_json appends " at line L column C"; the message states it up front.
fn strip_position(s: &str) -> String {
    match s.rfind(" at line ") {
        Some(i) => s[..i].to_string(),
        None => s.to_string(),
    }
}
