//! The control models an export is written for: each model's family (the
//! file formats) and its limits: compensation points per axis, the range
//! of one value, the compensation point numbers the axes share, each with
//! its source (docs/controllers.md quotes them).
//!
//! A limit is *hard* when a source states that the control takes no more:
//! an option past it is refused. Where the sources the project could read
//! give no limit, the model takes the narrowest value they document the
//! control (or its smaller sibling) to take, says so, and lets the user
//! raise it with a warning: a narrow limit costs format error, never a
//! file the control refuses.

use serde::Serialize;

/// A CNC control.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Controller {
    /// Siemens Sinumerik (840D, 828D, 808D).
    Sinumerik,
    /// Fanuc (Series 0i, 16i/18i/21i, 30i).
    Fanuc,
    /// Heidenhain (TNC, iTNC, MANUALplus).
    Heidenhain,
}

impl Controller {
    /// Every control, in the order `--controller` lists them.
    pub const ALL: [Controller; 3] = [
        Controller::Sinumerik,
        Controller::Fanuc,
        Controller::Heidenhain,
    ];

    /// The name on the command line.
    pub fn as_str(self) -> &'static str {
        match self {
            Controller::Sinumerik => "sinumerik",
            Controller::Fanuc => "fanuc",
            Controller::Heidenhain => "heidenhain",
        }
    }

    /// The axis names used without `--axis-names`.
    pub fn default_axis_names(self) -> [&'static str; 3] {
        match self {
            Controller::Sinumerik => ["X1", "Y1", "Z1"],
            Controller::Fanuc | Controller::Heidenhain => ["U", "V", "W"],
        }
    }

    /// Whether `name` is an axis name the control accepts, else what it
    /// accepts.
    pub(crate) fn check_axis_name(self, name: &str) -> Result<(), &'static str> {
        let b = name.as_bytes();
        let ok = match self {
            Controller::Sinumerik => {
                (1..=8).contains(&b.len())
                    && b[0].is_ascii_uppercase()
                    && b.iter()
                        .all(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || *c == b'_')
            }
            Controller::Fanuc => b.len() == 1 && b"XYZABCUVW".contains(&b[0]),
            Controller::Heidenhain => {
                (1..=2).contains(&b.len())
                    && b"XYZABCUVW".contains(&b[0])
                    && b[1..].iter().all(u8::is_ascii_digit)
            }
        };
        ok.then_some(()).ok_or(match self {
            Controller::Sinumerik => {
                "a machine axis name: 1 to 8 upper-case letters, digits or `_`, starting with a letter"
            }
            Controller::Fanuc => "one of the letters X Y Z A B C U V W (parameter 1020)",
            Controller::Heidenhain => "an axis key: X Y Z A B C U V or W, optionally one digit",
        })
    }
}

impl std::str::FromStr for Controller {
    type Err = String;
    fn from_str(s: &str) -> Result<Controller, String> {
        Controller::ALL
            .into_iter()
            .find(|c| c.as_str() == s.to_ascii_lowercase())
            .ok_or_else(|| {
                format!("unknown controller `{s}`: expected sinumerik, fanuc or heidenhain")
            })
    }
}

impl std::fmt::Display for Controller {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// One limit of a control model, with where it comes from.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Limit {
    /// The value.
    pub value: u64,
    /// Whether a source states that the control takes no more (else the
    /// value is the most the sources show it to take, and may be raised
    /// with a warning).
    pub hard: bool,
    /// The source, or why the value is a stand-in.
    pub source: &'static str,
}

/// A control model's limits (JSON `control_limits` of the summary).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ControlLimits {
    /// The most compensation points one axis' table takes.
    pub points_per_axis: Limit,
    /// Fanuc: the compensation point numbers the axes share (0 to this
    /// less one).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub point_numbers: Option<Limit>,
    /// Fanuc: the largest value of one point, in detection units times
    /// the magnification (the range is minus to plus it).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub value_range: Option<Limit>,
    /// Fanuc: the largest magnification (parameter 3623).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_magnification: Option<Limit>,
}

/// A CNC control model (`--control`).
///
#[cfg_attr(
    any(doc, doctest),
    doc = r#"
# Example
```
use tricept_export::{control::ControlModel, control::Controller};
let m: ControlModel = "fanuc-0i".parse().unwrap();
assert_eq!(m.family(), Controller::Fanuc);
assert_eq!(m.limits().value_range.unwrap().value, 7);
assert_eq!(ControlModel::default().as_str(), "sinumerik-840d-sl");
```
"#
)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
pub enum ControlModel {
    /// Siemens SINUMERIK 840D sl: the Tricept's own control (the default).
    #[default]
    #[serde(rename = "sinumerik-840d-sl")]
    Sinumerik840dSl,
    /// Siemens SINUMERIK 828D.
    #[serde(rename = "sinumerik-828d")]
    Sinumerik828d,
    /// Siemens SINUMERIK 808D.
    #[serde(rename = "sinumerik-808d")]
    Sinumerik808d,
    /// FANUC Series 0i (and 16i/18i/21i).
    #[serde(rename = "fanuc-0i")]
    Fanuc0i,
    /// FANUC Series 30i/31i/32i.
    #[serde(rename = "fanuc-30i")]
    Fanuc30i,
    /// HEIDENHAIN TNC 640.
    #[serde(rename = "heidenhain-tnc640")]
    HeidenhainTnc640,
    /// HEIDENHAIN iTNC 530.
    #[serde(rename = "heidenhain-itnc530")]
    HeidenhainItnc530,
    /// HEIDENHAIN TNC 407 (and 415/425).
    #[serde(rename = "heidenhain-tnc407")]
    HeidenhainTnc407,
}

/// The Sinumerik 808D's table ([S1]).
const SINUMERIK_808D_POINTS: Limit = Limit {
    value: 200,
    hard: true,
    source: "SINUMERIK 808D function manual 01/2017 p. 106: \"Up to 200 interpolation points (N = 0...199) are possible.\"",
};

/// A TNC 407's `*.COM` table ([H4]).
const TNC407_POINTS: Limit = Limit {
    value: 256,
    hard: true,
    source: "HEIDENHAIN TNC 407 technical manual, module 9095, error 3: \"Compensation value table (.COM) has more than 256 entries\"",
};

/// FANUC's range of one point ([F6]).
const FANUC_VALUE_RANGE: Limit = Limit {
    value: 7,
    hard: true,
    source: "FANUC Series 0i/16i/18i pitch error compensation data: -7 to +7 a point, times the magnification (parameter 3623), as read from the parameter manuals by the outside review of tricept's issue 43 (the stored copies the project can read do not hold that page); taken for every FANUC model",
};

/// FANUC's parameter 3623 ([F1]).
const FANUC_MAGNIFICATION: Limit = Limit {
    value: 100,
    hard: false,
    source: "parameter 3623, pitch error compensation magnification: its range is not in the sources found; at most 100 is written",
};

/// FANUC's compensation point numbers: what the sources found show.
const FANUC_POINT_NUMBERS: Limit = Limit {
    value: 1024,
    hard: false,
    source: "the range of parameters 3620-3622 is not in the sources found; 0 to 1023 (the numbers of the Series 0i and 16i/18i, the smallest FANUC range commonly stated) is taken; raise max_points only as far as the control's parameter manual allows",
};

impl ControlModel {
    /// Every model, in the order `--control` lists them.
    pub const ALL: [ControlModel; 8] = [
        ControlModel::Sinumerik840dSl,
        ControlModel::Sinumerik828d,
        ControlModel::Sinumerik808d,
        ControlModel::Fanuc0i,
        ControlModel::Fanuc30i,
        ControlModel::HeidenhainTnc640,
        ControlModel::HeidenhainItnc530,
        ControlModel::HeidenhainTnc407,
    ];

    /// The name on the command line.
    pub fn as_str(self) -> &'static str {
        match self {
            ControlModel::Sinumerik840dSl => "sinumerik-840d-sl",
            ControlModel::Sinumerik828d => "sinumerik-828d",
            ControlModel::Sinumerik808d => "sinumerik-808d",
            ControlModel::Fanuc0i => "fanuc-0i",
            ControlModel::Fanuc30i => "fanuc-30i",
            ControlModel::HeidenhainTnc640 => "heidenhain-tnc640",
            ControlModel::HeidenhainItnc530 => "heidenhain-itnc530",
            ControlModel::HeidenhainTnc407 => "heidenhain-tnc407",
        }
    }

    /// The family: which files are written.
    pub fn family(self) -> Controller {
        match self {
            ControlModel::Sinumerik840dSl
            | ControlModel::Sinumerik828d
            | ControlModel::Sinumerik808d => Controller::Sinumerik,
            ControlModel::Fanuc0i | ControlModel::Fanuc30i => Controller::Fanuc,
            ControlModel::HeidenhainTnc640
            | ControlModel::HeidenhainItnc530
            | ControlModel::HeidenhainTnc407 => Controller::Heidenhain,
        }
    }

    /// The model `--controller FAMILY` alone stands for: the 840D sl (a
    /// Tricept's control), the Series 0i, the TNC 640.
    pub fn of_family(family: Controller) -> ControlModel {
        match family {
            Controller::Sinumerik => ControlModel::Sinumerik840dSl,
            Controller::Fanuc => ControlModel::Fanuc0i,
            Controller::Heidenhain => ControlModel::HeidenhainTnc640,
        }
    }

    /// The model's limits, with their sources.
    pub fn limits(self) -> ControlLimits {
        let linear = |points_per_axis| ControlLimits {
            points_per_axis,
            point_numbers: None,
            value_range: None,
            max_magnification: None,
        };
        match self {
            ControlModel::Sinumerik840dSl => linear(Limit {
                value: 801,
                hard: false,
                source: "SINUMERIK 840D sl function manual 09/2009 p. 364 configures \"MD38000 $MM_ENC_COMP_MAX_POINTS >= 801\" (8 bytes of static user memory a value); the upper limit of MD38000 is not in the sources found",
            }),
            ControlModel::Sinumerik828d => linear(Limit {
                hard: false,
                source: "the 828D's MD38000 limit is not in the sources found: the 808D's documented 200 points are taken",
                ..SINUMERIK_808D_POINTS
            }),
            ControlModel::Sinumerik808d => linear(SINUMERIK_808D_POINTS),
            ControlModel::Fanuc0i | ControlModel::Fanuc30i => ControlLimits {
                // The axes share the numbers: one axis may take them all
                // but the three points each other axis needs at the least.
                points_per_axis: Limit {
                    value: FANUC_POINT_NUMBERS.value - 6,
                    hard: false,
                    source: "the compensation point numbers less three for each other axis",
                },
                point_numbers: Some(FANUC_POINT_NUMBERS),
                value_range: Some(FANUC_VALUE_RANGE),
                max_magnification: Some(FANUC_MAGNIFICATION),
            },
            ControlModel::HeidenhainTnc407 => linear(TNC407_POINTS),
            ControlModel::HeidenhainTnc640 | ControlModel::HeidenhainItnc530 => linear(Limit {
                hard: false,
                source: "the entries a *.COM table takes on this control are not in the sources found: the TNC 407's documented 256 are taken",
                ..TNC407_POINTS
            }),
        }
    }

    /// The points per axis without `--max-points`: the model's limit;
    /// for Fanuc a third of the point numbers (three axes share them).
    pub fn default_max_points(self) -> usize {
        let l = self.limits();
        match l.point_numbers {
            Some(n) => (n.value / 3) as usize,
            None => l.points_per_axis.value as usize,
        }
    }
}

impl std::str::FromStr for ControlModel {
    type Err = String;
    fn from_str(s: &str) -> Result<ControlModel, String> {
        let lower = s.to_ascii_lowercase();
        ControlModel::ALL
            .into_iter()
            .find(|m| m.as_str() == lower)
            .ok_or_else(|| {
                format!(
                    "unknown control model `{s}`: expected one of {}",
                    ControlModel::ALL.map(ControlModel::as_str).join(", ")
                )
            })
    }
}

impl std::fmt::Display for ControlModel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn models_are_named_as_on_the_command_line_and_read_back() {
        for m in ControlModel::ALL {
            assert_eq!(m.as_str().parse::<ControlModel>(), Ok(m));
            assert_eq!(m.as_str().to_uppercase().parse::<ControlModel>(), Ok(m));
            assert!(m.as_str().starts_with(m.family().as_str()), "{m}");
            assert_eq!(
                serde_json::to_value(m).unwrap(),
                serde_json::Value::from(m.as_str())
            );
        }
        let e = "fanuc-31x".parse::<ControlModel>().unwrap_err();
        assert!(e.contains("sinumerik-840d-sl"), "{e}");
    }

    /// The models' table of docs/controllers.md states what the code
    /// holds: each model's points per axis, whether that is a hard limit
    /// or a stand-in, its value range and point numbers.
    #[test]
    fn the_docs_table_of_models_is_the_code_s() {
        let docs = include_str!("../../../docs/controllers.md");
        let table = &docs[docs.find("| `--control` |").unwrap()..];
        let rows: Vec<&str> = table
            .lines()
            .skip(2)
            .take_while(|l| l.starts_with('|'))
            .collect();
        assert_eq!(rows.len(), ControlModel::ALL.len());
        for row in rows {
            let cells: Vec<&str> = row.split('|').map(str::trim).collect();
            let name = cells[1].split('`').nth(1).unwrap();
            let m: ControlModel = name.parse().unwrap();
            let l = m.limits();
            let points = cells[2];
            assert!(
                points.contains(&m.default_max_points().to_string()),
                "{name}: {points}"
            );
            let stand_in = points.contains("stand-in");
            assert_eq!(l.points_per_axis.hard, points.contains("hard"), "{name}");
            if m.family() != Controller::Fanuc {
                assert_eq!(stand_in, !l.points_per_axis.hard, "{name}");
                assert!(points.contains(&l.points_per_axis.value.to_string()));
            }
            if let Some(r) = l.value_range {
                assert!(
                    cells[3].contains(&format!("-{} to +{}", r.value, r.value)),
                    "{name}"
                );
                assert_eq!(cells[3].contains("hard"), r.hard, "{name}");
            }
            if let Some(n) = l.point_numbers {
                assert!(
                    cells[4].contains(&format!("0 to {}", n.value - 1)),
                    "{name}"
                );
                assert_eq!(cells[4].contains("stand-in"), !n.hard, "{name}");
            }
        }
    }

    /// A stand-in says so in its source: the summary never presents a
    /// guess as a vendor's number.
    #[test]
    fn every_stand_in_says_it_is_not_in_the_sources() {
        for m in ControlModel::ALL {
            let l = m.limits();
            let all = [
                Some(l.points_per_axis),
                l.point_numbers,
                l.value_range,
                l.max_magnification,
            ];
            for limit in all.into_iter().flatten() {
                assert!(!limit.source.is_empty(), "{m}");
                if !limit.hard
                    && limit.source
                        != "the compensation point numbers less three for each other axis"
                {
                    assert!(
                        limit.source.contains("not in the sources found")
                            || limit.source.contains("upper limit"),
                        "{m}: {}",
                        limit.source
                    );
                }
            }
        }
    }

    #[test]
    fn each_family_stands_for_one_of_its_models() {
        for c in Controller::ALL {
            assert_eq!(ControlModel::of_family(c).family(), c);
        }
    }

    #[test]
    fn only_fanuc_models_have_shared_numbers_and_a_value_range() {
        for m in ControlModel::ALL {
            let l = m.limits();
            let fanuc = m.family() == Controller::Fanuc;
            assert_eq!(l.point_numbers.is_some(), fanuc, "{m}");
            assert_eq!(l.value_range.is_some(), fanuc, "{m}");
            if let Some(n) = l.point_numbers {
                // Three axes of at least three points each fit, and
                // three of the default.
                assert!(l.points_per_axis.value + 6 <= n.value, "{m}");
                assert!(3 * m.default_max_points() as u64 <= n.value, "{m}");
            }
            assert!(m.default_max_points() as u64 <= l.points_per_axis.value);
        }
    }

    #[test]
    fn controllers_are_named_as_on_the_command_line() {
        let names = Controller::ALL.map(Controller::as_str);
        assert_eq!(names, ["sinumerik", "fanuc", "heidenhain"]);
        // Read back, in any case; an unknown name is refused.
        for (c, name) in Controller::ALL.into_iter().zip(names) {
            assert_eq!(name.parse::<Controller>(), Ok(c));
            assert_eq!(name.to_uppercase().parse::<Controller>(), Ok(c));
            assert_eq!(c.to_string(), name);
        }
        let e = "siemens".parse::<Controller>().unwrap_err();
        assert!(e.starts_with("unknown controller `siemens`"), "{e}");
    }

    #[test]
    fn axis_names_follow_each_control_s_rule() {
        let ok = |c: Controller, n: &str| c.check_axis_name(n).is_ok();
        // Sinumerik: 1 to 8 upper-case letters, digits or `_`, a letter first.
        for n in ["X1", "AX_3", "ABCDEFGH"] {
            assert!(ok(Controller::Sinumerik, n), "{n}");
        }
        for n in ["", "1X", "x1", "ABCDEFGHI", "A-1"] {
            assert!(!ok(Controller::Sinumerik, n), "{n}");
        }
        // Fanuc: one of X Y Z A B C U V W.
        assert!(ok(Controller::Fanuc, "U") && ok(Controller::Fanuc, "W"));
        for n in ["", "UV", "Q", "U1"] {
            assert!(!ok(Controller::Fanuc, n), "{n}");
        }
        // Heidenhain: such a letter and at most one digit.
        assert!(ok(Controller::Heidenhain, "U") && ok(Controller::Heidenhain, "V2"));
        for n in ["", "UA", "Q1", "U12", "2"] {
            assert!(!ok(Controller::Heidenhain, n), "{n}");
        }
    }
}
