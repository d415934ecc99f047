//! The page's inputs: [`Sources`], each JSON [`Source`] with its id on the
//! page, what it is, and the file it was read from.

use serde_json::Value;

/// One JSON source of the page.
#[derive(Debug, Clone, PartialEq)]
pub struct Source {
    /// Its id on the page (`data-src` of the values it gives, and
    /// `json-<id>` of its block): `machine`, `map-1`.., `diagnosis`,
    /// `history`, `trends`, `export`.
    pub id: String,
    /// What it is and the command that gives it, one line.
    pub what: String,
    /// The file it was read from, as given (none: computed by the door).
    pub file: Option<String>,
    /// Its JSON.
    pub json: Value,
}

impl Source {
    /// A source.
    pub fn new(id: &str, what: &str, file: Option<String>, json: Value) -> Source {
        Source {
            id: id.to_string(),
            what: what.to_string(),
            file,
            json,
        }
    }
}

/// Everything a page shows.
#[derive(Debug, Clone, PartialEq)]
pub struct Sources {
    /// The calibrated machine file, as loaded (`machine`).
    pub machine: Source,
    /// Its calibration's digest (`MachineDescription::calibration_digest`).
    pub calibration_digest: String,
    /// The compensation map at a few heights, bottom to top (`map-1`..):
    /// `tricept compensate --machine CAL.json --plane-z Z --json` with
    /// `spacing_mm` and the map's columns as `points` (`x`, `y`,
    /// `correction_mm`, as `--map`'s map.csv).
    pub maps: Vec<Source>,
    /// `tricept diagnose --data CAMPAIGN.csv --json` of the calibration's
    /// campaign (`diagnosis`).
    pub diagnosis: Option<Source>,
    /// The check history's lines, in file order (`history`).
    pub history: Option<Source>,
    /// Their trends, as `tricept check --json` gives them (`trends`).
    pub trends: Option<Source>,
    /// The export's summary, `DIR/export.json` (`export`).
    pub export: Option<Source>,
}

impl Sources {
    /// Every source, in page order.
    pub fn all(&self) -> Vec<&Source> {
        let mut out = vec![&self.machine];
        out.extend(&self.maps);
        for s in [&self.diagnosis, &self.history, &self.trends, &self.export] {
            out.extend(s.as_ref());
        }
        out
    }

    /// The sources by id, for [`crate::json::Lookup`].
    pub fn lookup_list(&self) -> Vec<(&str, &Value)> {
        self.all()
            .into_iter()
            .map(|s| (s.id.as_str(), &s.json))
            .collect()
    }
}
