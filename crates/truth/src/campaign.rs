//! A campaign written as the documented data CSV (`docs/data-format.md`):
//! columns `q1,q2,q3,phi,theta,s`, then `temp_c` and `dir1,dir2,dir3` when
//! the rows carry them, every value with full precision.

/// One logged pose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Row {
    /// Leg lengths commanded to the drives, mm.
    pub commands_mm: [f64; 3],
    /// Readings `[phi rad, theta rad, s mm]`.
    pub readings: [f64; 3],
    /// Structure temperature, deg C.
    pub temp_c: Option<f64>,
    /// Sign of each leg's last motion before the pose.
    pub directions: Option<[i8; 3]>,
}

/// The rows as the documented CSV text, header first; the optional columns
/// appear when the first row has them (every row must then have them).
pub fn to_csv(rows: &[Row]) -> String {
    let temp = rows.first().is_some_and(|r| r.temp_c.is_some());
    let dirs = rows.first().is_some_and(|r| r.directions.is_some());
    let mut out = String::from("q1,q2,q3,phi,theta,s");
    if temp {
        out.push_str(",temp_c");
    }
    if dirs {
        out.push_str(",dir1,dir2,dir3");
    }
    out.push('\n');
    for r in rows {
        let mut fields: Vec<String> = r
            .commands_mm
            .iter()
            .chain(r.readings.iter())
            .map(|v| format!("{v:?}"))
            .collect();
        if temp {
            fields.push(format!("{:?}", r.temp_c.expect("every row has temp_c")));
        }
        if dirs {
            let d = r.directions.expect("every row has directions");
            fields.extend(d.iter().map(|s| s.to_string()));
        }
        out.push_str(&fields.join(","));
        out.push('\n');
    }
    out
}
