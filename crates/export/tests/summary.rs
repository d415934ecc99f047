//! What an export's summary states, against the documented rules
//! (docs/controllers.md): where a Fanuc axis' points lie (parameters 3620
//! to 3624), the remedy a format error past the tolerance names, the size
//! of a thermal growth a control cannot carry, the options refused, and
//! the files written. Expected values come from the parameters the
//! summary states and from the fixtures' controller block, not from the
//! writers' code.

use std::path::{Path, PathBuf};

use tricept_export::{ExportError, ExportOptions, ExportPlan, control::Controller, plan};
use tricept_kinematics::MachineDescription;

fn fixture(name: &str) -> MachineDescription {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(format!("{name}.json"));
    MachineDescription::from_file(&path).unwrap()
}

/// The number after `key` in `text` (up to the next space, `;` or `)`).
fn number_after(text: &str, key: &str) -> f64 {
    let at = text
        .find(key)
        .unwrap_or_else(|| panic!("no {key:?} in {text}"))
        + key.len();
    let word = text[at..].split([' ', ';', ')', ',']).next().unwrap_or("");
    word.parse()
        .unwrap_or_else(|_| panic!("{word:?} after {key:?} in {text}"))
}

fn fanuc(max_points: usize, detection_unit_um: f64, tolerance_um: f64) -> ExportOptions {
    let mut o = ExportOptions::new(Controller::Fanuc);
    o.max_points = Some(max_points);
    o.detection_unit_um = Some(detection_unit_um);
    o.tolerance_um = tolerance_um;
    o
}

#[test]
fn a_fanuc_axis_s_points_lie_where_its_parameters_put_them() {
    // Parameter 3620 is the reference point's number, 3621 and 3622 the
    // first and last point's, 3624 the interval: point n compensates the
    // section ending at P_ref + (n - n_ref) h.
    let p = plan(&fixture("lead"), &fanuc(128, 0.1, 5.0)).unwrap();
    for (axis, line) in p.summary.axes.iter().zip(&p.summary.parameters) {
        let n_ref = number_after(line, "3620 = ");
        let first = number_after(line, "3621 = ");
        let last = number_after(line, "3622 = ");
        let h = axis.step_mm;
        assert!(
            (h - number_after(line, "3624 = ") * 1e-4).abs() < 1e-12,
            "{line}"
        );
        assert_eq!(axis.points as f64, last - first + 1.0, "{line}");
        let at = |n: f64| axis.reference_mm + (n - n_ref) * h;
        assert!((axis.min_mm - at(first)).abs() < 1e-9, "{axis:?} {line}");
        assert!((axis.max_mm - at(last)).abs() < 1e-9, "{axis:?} {line}");
        // The points cover the reference point, below and above.
        assert!(axis.min_mm < axis.reference_mm && axis.reference_mm < axis.max_mm);
    }
    // The three axes are numbered one after the other, from 0.
    let numbers: Vec<(f64, f64)> = p
        .summary
        .parameters
        .iter()
        .map(|l| (number_after(l, "3621 = "), number_after(l, "3622 = ")))
        .collect();
    assert_eq!(numbers[0].0, 0.0);
    for pair in numbers.windows(2) {
        assert_eq!(pair[1].0, pair[0].1 + 1.0, "{numbers:?}");
    }
}

#[test]
fn each_linear_format_rounds_to_its_own_resolution() {
    // The lead fixture's legs: a lead error (linear, so interpolation is
    // exact) and no table. What is left is the rounding of the values:
    // half of 1e-6 mm in a Sinumerik program, half of 1e-4 mm in a
    // Heidenhain table (docs/controllers.md).
    let d = fixture("lead");
    assert!(d.leg_effects.tables.is_empty());
    for (c, half_um) in [
        (Controller::Sinumerik, 0.5e-3),
        (Controller::Heidenhain, 0.05),
    ] {
        let p = plan(&d, &ExportOptions::new(c)).unwrap();
        for axis in &p.summary.axes {
            assert!(
                axis.format_error_um <= half_um * (1.0 + 1e-6),
                "{c}: {axis:?}"
            );
        }
        // Heidenhain's rounding is seen (a lead of some ppm over 2 mm spans
        // many 0.1 um steps).
        if c == Controller::Heidenhain {
            let largest = p
                .summary
                .axes
                .iter()
                .map(|a| a.format_error_um)
                .fold(0.0, f64::max);
            assert!(largest > 0.01, "{largest}");
        }
    }
}

#[test]
fn a_fanuc_format_error_past_the_tolerance_names_its_remedy() {
    // Few points (large sections) and a tolerance below the staircase's
    // miss: the summary says so, and names the points that would do
    // (the miss less half a unit shrinks with the points) or, when half a
    // unit alone is past the tolerance, a finer unit.
    let d = fixture("lead");
    let mut small_increments = fanuc(12, 0.1, 1.0);
    // At most 7 units a point: the magnification grows past 1.
    small_increments.max_increment = Some(7);
    let mut magnified = false;
    for o in [fanuc(12, 0.1, 1.0), small_increments] {
        magnified |= assert_remedies(&plan(&d, &o).unwrap());
    }
    assert!(magnified);
    // Within the tolerance: no limit.
    let loose = plan(&d, &fanuc(12, 0.1, 1000.0)).unwrap();
    assert!(loose.summary.within_tolerance && loose.summary.limits.is_empty());
    // Half a unit of 10 um alone is past a 1 um tolerance: a finer unit.
    let coarse = plan(&d, &fanuc(128, 10.0, 1.0)).unwrap();
    for limit in &coarse.summary.limits {
        assert!(
            limit.contains(": lower detection_unit_um (10 um"),
            "{limit}"
        );
        assert!(!limit.contains("max_points"), "{limit}");
    }
    assert!(!coarse.summary.limits.is_empty());
}

/// Asserts the remedy each axis past the tolerance of 1 um names: the
/// points that would do, or a finer unit; whether an axis is magnified.
fn assert_remedies(p: &ExportPlan) -> bool {
    assert!(!p.summary.within_tolerance);
    assert!(!p.summary.limits.is_empty());
    let mut magnified = false;
    for (axis, line) in p.summary.axes.iter().zip(&p.summary.parameters) {
        let named = format!("axis {}: ", axis.axis);
        let limit = p.summary.limits.iter().find(|l| l.starts_with(&named));
        let Some(limit) = limit else {
            assert!(axis.format_error_um <= 1.0, "{axis:?}");
            continue;
        };
        assert!(axis.format_error_um > 1.0, "{axis:?}");
        assert!(
            limit.contains(&format!(
                "format error {:.3} um past tolerance_um 1:",
                axis.format_error_um
            )),
            "{limit}"
        );
        let magnification = number_after(line, "3623 = ");
        magnified |= magnification > 1.0;
        let half_unit = 0.5 * 0.1 * magnification;
        assert!(
            limit.contains(&format!("half a unit is {half_unit:.3} um")),
            "{limit}"
        );
        let points = number_after(limit, "to more than ");
        let needed = axis.points as f64 * (axis.format_error_um - half_unit) / (1.0 - half_unit);
        assert_eq!(points, needed.ceil(), "{limit}");
        assert!(points > axis.points as f64, "{limit}");
    }
    magnified
}

#[test]
fn a_thermal_growth_a_control_cannot_carry_is_listed_with_its_size() {
    // The lead fixture's legs grow 11.5 ppm/K (its controller block); a
    // Fanuc export carries no thermal parameter: the growth per K of the
    // longest leg command is listed, um.
    let d = fixture("lead");
    let alpha = d.controller.unwrap().thermal_expansion_ppm_per_k;
    // The diagnosis' estimate of the plant's 11.5 ppm/K (+- 0.02).
    assert!((alpha - 11.5).abs() < 0.1, "{alpha}");
    let p = plan(&d, &fanuc(128, 0.1, 5.0)).unwrap();
    let thermal = p
        .summary
        .not_exported
        .iter()
        .find(|n| n.what == "thermal growth, per K")
        .unwrap();
    // The longest command lies in the last point's section.
    let (last, h) = p
        .summary
        .axes
        .iter()
        .map(|a| (a.max_mm, a.step_mm))
        .fold((0.0, 0.0), |a, b| if b.0 > a.0 { b } else { a });
    let per_k_um = |q_mm: f64| alpha * 1e-6 * q_mm * 1e3;
    assert!(
        thermal.size_um <= per_k_um(last) && thermal.size_um >= per_k_um(last - h),
        "{} um, {} to {} um",
        thermal.size_um,
        per_k_um(last - h),
        per_k_um(last)
    );
    // Sinumerik carries it.
    let s = plan(&d, &ExportOptions::new(Controller::Sinumerik)).unwrap();
    assert!(
        s.summary
            .not_exported
            .iter()
            .all(|n| !n.what.contains("thermal"))
    );
}

#[test]
fn options_no_control_can_use_are_refused() {
    let d = fixture("lead");
    let refused = |o: ExportOptions, name: &str| match plan(&d, &o) {
        Err(ExportError::Setting { setting, why }) => assert_eq!(setting, name, "{why}"),
        other => panic!("{name}: {other:?}"),
    };
    for tolerance in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let mut o = ExportOptions::new(Controller::Sinumerik);
        o.tolerance_um = tolerance;
        refused(o, "tolerance_um");
    }
    for points in [2, 100_001] {
        let mut o = ExportOptions::new(Controller::Heidenhain);
        o.max_points = Some(points);
        refused(o, "max_points");
    }
    for c in [Controller::Sinumerik, Controller::Heidenhain] {
        let mut o = ExportOptions::new(c);
        o.detection_unit_um = Some(1.0);
        refused(o, "detection_unit_um");
        let mut o = ExportOptions::new(c);
        o.max_increment = Some(7);
        refused(o, "max_increment");
    }
    for du in [0.0, -0.1, 100.5, f64::NAN] {
        refused(fanuc(128, du, 5.0), "detection_unit_um");
    }
    let mut o = fanuc(128, 1.0, 5.0);
    o.max_increment = Some(0);
    refused(o, "max_increment");
    // At the ends of their ranges the options are taken.
    let mut o = fanuc(3, 100.0, 5.0);
    o.max_increment = Some(1);
    assert!(plan(&d, &o).is_ok());
    assert!(plan(&d, &fanuc(128, 0.001, 5.0)).is_ok());
    let mut o = ExportOptions::new(Controller::Sinumerik);
    o.max_points = Some(100_000);
    assert!(plan(&d, &o).is_ok());
}

#[test]
fn the_files_are_written_as_planned() {
    let p: ExportPlan = plan(
        &fixture("lead"),
        &ExportOptions::new(Controller::Heidenhain),
    )
    .unwrap();
    let dir: PathBuf =
        std::env::temp_dir().join(format!("tricept-export-summary-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    // Written into a directory made for it.
    p.write(&dir.join("out")).unwrap();
    for (name, text) in &p.files {
        let written = std::fs::read_to_string(dir.join("out").join(name)).unwrap();
        assert_eq!(&written, text, "{name}");
    }
    assert_eq!(
        std::fs::read_dir(dir.join("out")).unwrap().count(),
        p.files.len()
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_linear_table_past_the_tolerance_names_the_points_its_own_spacing_needs() {
    // The pitch fixture's deployed table (every 10/24 mm) on 20 points:
    // each axis misses the sine by far more than 1 um, and the summary
    // names the control's point limit and the points the deployed
    // table's own spacing needs over the written stroke.
    let d = fixture("pitch");
    let step_mm = d.leg_effects.tables[0].step_mm;
    for (c, limit_name) in [
        (Controller::Sinumerik, "MD38000 MM_ENC_COMP_MAX_POINTS"),
        (Controller::Heidenhain, "the points a *.COM table takes"),
    ] {
        let mut o = ExportOptions::new(c);
        o.max_points = Some(20);
        o.tolerance_um = 1.0;
        let p = plan(&d, &o).unwrap();
        assert_eq!(p.summary.limits.len(), 3, "{:#?}", p.summary.limits);
        for (axis, limit) in p.summary.axes.iter().zip(&p.summary.limits) {
            assert!(axis.format_error_um > 1.0, "{axis:?}");
            assert!(
                limit.starts_with(&format!(
                    "axis {}: format error {:.3} um past tolerance_um 1: raise max_points ({limit_name}) to ",
                    axis.axis, axis.format_error_um
                )),
                "{limit}"
            );
            let needed = number_after(limit, ") to ");
            let stroke = axis.max_mm - axis.min_mm;
            assert!(
                needed >= stroke / step_mm + 1.0 && needed <= stroke / step_mm + 3.0,
                "{limit}: {stroke} mm every {step_mm} mm"
            );
        }
        // Enough points: within the tolerance, no limit.
        let mut o = ExportOptions::new(c);
        o.max_points = Some(10_000);
        o.tolerance_um = 1.0;
        assert!(plan(&d, &o).unwrap().summary.limits.is_empty());
    }
}

#[test]
fn sinumerik_carries_a_thermal_growth_in_its_temperature_compensation() {
    // The lead fixture's 11.5 ppm/K: a position-dependent temperature
    // compensation per axis whose slope (SD43910) is "the gradient of the
    // approximated error line" (SINUMERIK K3, [S5]): the legs grow, the
    // error line rises, +alpha 1e-6 per K; a machine without thermal
    // growth (the pitch fixture) has none.
    let d = fixture("lead");
    let alpha = d.controller.unwrap().thermal_expansion_ppm_per_k;
    let p = plan(&d, &ExportOptions::new(Controller::Sinumerik)).unwrap();
    let lines: Vec<&String> = p
        .summary
        .parameters
        .iter()
        .filter(|l| l.contains("TEMP_COMP_SLOPE"))
        .collect();
    assert_eq!(lines.len(), 3, "{:#?}", p.summary.parameters);
    for (line, axis) in lines.iter().zip(["X1", "Y1", "Z1"]) {
        assert!(
            line.starts_with(&format!("{axis}: MD32750 TEMP_COMP_TYPE = 2")),
            "{line}"
        );
        let slope = number_after(line, "SD43910 TEMP_COMP_SLOPE = ");
        assert!((slope - alpha * 1e-6).abs() < 1e-11, "{line}");
        assert!(line.contains("(T - 20 degC)"), "{line}");
    }
    let pitch = fixture("pitch");
    assert_eq!(
        pitch
            .controller
            .unwrap_or_default()
            .thermal_expansion_ppm_per_k,
        0.0
    );
    let p = plan(&pitch, &ExportOptions::new(Controller::Sinumerik)).unwrap();
    assert!(
        p.summary
            .parameters
            .iter()
            .all(|l| !l.contains("TEMP_COMP"))
    );
}

/// The case: a pitch error on a FANUC Series 0i at 0.1 um with
/// 1000 points an axis. Every value the tape holds lies within the
/// control's -7 to +7 (the magnification grows instead), and three axes
/// of 1000 points need more compensation point numbers than the 1024
/// (0 to 1023) the Series 0i is known to have: nothing is written and the
/// limit is named; with the default points (a third of them) it fits.
#[test]
fn a_fanuc_tape_keeps_the_range_of_a_point_and_of_the_point_numbers() {
    let d = fixture("pitch");
    // `N<10000 + number>P<value>` lines of the pitch tape.
    let tape = |p: &ExportPlan| -> Vec<(u64, i64)> {
        p.files
            .iter()
            .find(|(n, _)| n == "PITCH.TXT")
            .unwrap()
            .1
            .lines()
            .filter_map(|l| l.strip_prefix('N'))
            .map(|l| {
                let (n, v) = l.split_once('P').unwrap();
                (n.parse::<u64>().unwrap() - 10000, v.parse().unwrap())
            })
            .collect()
    };
    let values = |p: &ExportPlan| tape(p).into_iter().map(|(_, v)| v).collect::<Vec<_>>();
    let numbers = |p: &ExportPlan| tape(p).into_iter().map(|(n, _)| n).collect::<Vec<_>>();
    let many = plan(&d, &fanuc(1000, 0.1, 1.0)).unwrap();
    assert!(values(&many).iter().all(|v| v.abs() <= 7));
    assert!(!many.summary.within_tolerance);
    let limit = many
        .summary
        .limits
        .iter()
        .find(|l| l.starts_with("the three axes need compensation point numbers 0 to "))
        .unwrap();
    assert!(limit.contains("the fanuc-0i has 0 to 1023"), "{limit}");
    assert!(limit.ends_with("lower max_points to 341"), "{limit}");
    // --max-points' largest value: past the axis' stand-in limit (a
    // warning) and past the numbers (a limit).
    let huge = plan(&d, &fanuc(100_000, 0.1, 1.0)).unwrap();
    assert!(!huge.summary.within_tolerance);
    assert!(
        huge.summary.warnings[0].starts_with("max_points: 100000 is past the fanuc-0i's 1018"),
        "{:?}",
        huge.summary.warnings
    );
    // The defaults: three axes of 341 points, numbered 0 to 1022, every
    // value within +-7.
    let o = ExportOptions::new(Controller::Fanuc);
    let p = plan(&d, &o).unwrap();
    assert!(values(&p).iter().all(|v| v.abs() <= 7));
    assert!(numbers(&p).iter().all(|n| *n < 1024));
    // (An axis may take one point fewer: see the next test.)
    assert!((3 * 340..=3 * 341).contains(&numbers(&p).len()));
    // A range wider than the control's is refused: the Series 0i's -7 to
    // +7 is a hard limit.
    let mut wide = fanuc(128, 1.0, 1.0);
    wide.max_increment = Some(127);
    match plan(&d, &wide) {
        Err(e @ ExportError::Setting { setting, .. }) => {
            assert_eq!(setting, "max_increment");
            assert!(
                e.to_string()
                    .starts_with("max_increment: 127 is past the fanuc-0i's 7"),
                "{e}"
            )
        }
        other => panic!("{other:?}"),
    }
}

/// An axis takes as many points as `--max-points` allows (the smallest
/// interval whose points cover the stroke): never fewer than one short
/// (when no interval gives exactly the number, one more point on either
/// side of the reference would need two).
#[test]
fn a_fanuc_axis_takes_the_points_it_is_given() {
    let d = fixture("lead");
    for n in [12, 13, 128, 341] {
        let p = plan(&d, &fanuc(n, 0.1, 1000.0)).unwrap();
        for a in &p.summary.axes {
            assert!(a.points == n || a.points + 1 == n, "{n}: {a:?}");
        }
    }
}

/// The span an export states covers every leg command of the workspace
/// (the calibrated machine's own IK over its boundary, sampled here
/// independently), for every control, with few points and many.
#[test]
fn the_stated_span_covers_every_command_of_the_workspace() {
    let d = fixture("bowed");
    let machine = tricept_model::ExtendedMachine::new(d.build().unwrap());
    let w = &machine.machine().workspace;
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for k in 0..=20 {
        for a in 0..90 {
            for ring in [0.0, 0.25, 0.5, 0.75, 1.0] {
                let phi = std::f64::consts::TAU * f64::from(a) / 90.0;
                let z = w.z_min_mm + (w.z_max_mm - w.z_min_mm) * f64::from(k) / 20.0;
                let r = nalgebra::Vector3::new(
                    ring * w.radius_mm * phi.cos(),
                    ring * w.radius_mm * phi.sin(),
                    z,
                );
                let q = machine.inverse(&r).unwrap().legs_mm;
                for i in 0..3 {
                    lo[i] = lo[i].min(q[i]);
                    hi[i] = hi[i].max(q[i]);
                }
            }
        }
    }
    for c in Controller::ALL {
        for points in [5, 40, 300] {
            let mut o = ExportOptions::new(c);
            o.max_points = Some(points);
            o.tolerance_um = 1e6;
            let p = plan(&d, &o).unwrap();
            for (i, a) in p.summary.axes.iter().enumerate() {
                assert!(
                    a.min_mm <= lo[i] && a.max_mm >= hi[i],
                    "{c} {points}: {a:?}"
                );
                assert!(a.points <= points, "{c} {points}: {a:?}");
            }
        }
    }
}

/// The default control is a Tricept's, the SINUMERIK 840D sl; the summary
/// names the model and its limits with their sources.
#[test]
fn the_summary_names_the_control_model_and_its_limits() {
    let p = plan(
        &fixture("lead"),
        &ExportOptions::for_model(Default::default()),
    )
    .unwrap();
    let v = serde_json::to_value(&p.summary).unwrap();
    assert_eq!(v["controller"], "sinumerik");
    assert_eq!(v["control"], "sinumerik-840d-sl");
    let points = &v["control_limits"]["points_per_axis"];
    assert_eq!(points["value"], 801);
    assert_eq!(points["hard"], false);
    assert!(points["source"].as_str().unwrap().contains("MD38000"));
    let p = plan(
        &fixture("lead"),
        &ExportOptions::for_model("fanuc-30i".parse().unwrap()),
    )
    .unwrap();
    let v = serde_json::to_value(&p.summary).unwrap();
    assert_eq!(v["controller"], "fanuc");
    assert_eq!(v["control"], "fanuc-30i");
    assert_eq!(v["control_limits"]["value_range"]["value"], 7);
    assert_eq!(v["control_limits"]["point_numbers"]["value"], 1024);
}
