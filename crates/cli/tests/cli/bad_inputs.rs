//! Every input a user can get wrong: the exit code (2 for usage and input
//! errors, 1 for anything else), one clear line on stderr naming the
//! problem (file, line and column where there is one), nothing on stdout,
//! and never a panic.

use std::path::Path;

use crate::support::{fresh_workdir, ok, tricept, workdir};

/// A valid measured-data file (the paper's machine, Table 2), as text.
fn good_csv(dir: &Path) -> String {
    let path = dir.join("good.csv");
    let out = tricept()
        .args(["simulate", "--poses", "grid:1,8,3", "--out"])
        .arg(&path)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    std::fs::read_to_string(path).unwrap()
}

/// The data lines (after comments and header) of a CSV text.
fn split(csv: &str) -> (Vec<String>, String, Vec<String>) {
    let mut comments = Vec::new();
    let mut lines = csv.lines().map(str::to_string);
    let header = loop {
        let l = lines.next().unwrap();
        if l.starts_with('#') {
            comments.push(l);
        } else {
            break l;
        }
    };
    (comments, header, lines.collect())
}

struct Case {
    name: &'static str,
    args: Vec<String>,
    files: Vec<(&'static str, Vec<u8>)>,
    code: i32,
    needles: Vec<&'static str>,
}

fn case(
    name: &'static str,
    args: &[&str],
    files: Vec<(&'static str, Vec<u8>)>,
    code: i32,
    needles: &[&'static str],
) -> Case {
    Case {
        name,
        args: args.iter().map(|s| s.to_string()).collect(),
        files,
        code,
        needles: needles.to_vec(),
    }
}

fn with_rows(header: &str, rows: &[String]) -> Vec<u8> {
    let mut s = format!("{header}\n");
    for r in rows {
        s.push_str(r);
        s.push('\n');
    }
    s.into_bytes()
}

fn replace_field(row: &str, index: usize, value: &str) -> String {
    let mut f: Vec<String> = row.split(',').map(str::to_string).collect();
    f[index] = value.to_string();
    f.join(",")
}

/// The table of bad inputs: each an exit code 2 and a message naming the
/// problem (the tests are the named cases below).
fn bad_inputs_cases(dir: &Path) -> Vec<Case> {
    let csv = good_csv(dir);
    let (_, header, rows) = split(&csv);
    let base = header.clone();
    let id = |file: &'static str| {
        vec![
            "identify".to_string(),
            "--data".to_string(),
            dir.join(file).display().to_string(),
        ]
    };
    let mut cases = vec![
        // Measured-data files.
        case(
            "empty file",
            &[],
            vec![("empty.csv", Vec::new())],
            2,
            &["empty.csv", "empty file"],
        ),
        case(
            "header only",
            &[],
            vec![("header.csv", format!("{base}\n").into_bytes())],
            2,
            &["header only"],
        ),
        case(
            "missing column",
            &[],
            vec![("missing.csv", with_rows("q1,q2,q3,phi,theta,temp_c", &[]))],
            2,
            &["missing required column `s`"],
        ),
        case(
            "misspelt column",
            &[],
            vec![(
                "misspelt.csv",
                with_rows(&base.replace("theta", "theat"), &rows),
            )],
            2,
            &["missing required column `theta`", "theat"],
        ),
        case(
            "non-numeric field",
            &[],
            vec![(
                "text.csv",
                with_rows(&base, &[rows[0].clone(), replace_field(&rows[1], 3, "abc")]),
            )],
            2,
            &["text.csv: line 3, column `phi`", "not a number"],
        ),
        case(
            "NaN",
            &[],
            vec![(
                "nan.csv",
                with_rows(&base, &[replace_field(&rows[0], 5, "NaN")]),
            )],
            2,
            &["line 2, column `s`", "not a finite number"],
        ),
        case(
            "infinity",
            &[],
            vec![(
                "inf.csv",
                with_rows(&base, &[replace_field(&rows[0], 0, "inf")]),
            )],
            2,
            &["column `q1`", "not a finite number"],
        ),
        case(
            "wrong column count",
            &[],
            vec![(
                "count.csv",
                with_rows(
                    &base,
                    &[
                        rows[0].clone(),
                        rows[1].rsplit_once(',').unwrap().0.to_string(),
                    ],
                ),
            )],
            2,
            &["line 3", "fields"],
        ),
        case(
            "angles in degrees",
            &[],
            vec![(
                "degrees.csv",
                with_rows(
                    &base,
                    &rows
                        .iter()
                        .map(|r| {
                            let phi: f64 = r.split(',').nth(3).unwrap().parse().unwrap();
                            replace_field(r, 3, &(phi.to_degrees()).to_string())
                        })
                        .collect::<Vec<_>>(),
                ),
            )],
            2,
            &["column `phi`", "degrees"],
        ),
        case(
            "command beyond the stroke",
            &[],
            vec![(
                "stroke.csv",
                with_rows(&base, &[rows[0].clone(), replace_field(&rows[1], 1, "100")]),
            )],
            2,
            &["stroke.csv: line 3, column `q2`", "stroke"],
        ),
        case(
            "no assembly for the commands",
            &[],
            vec![(
                "assembly.csv",
                with_rows(&base, &{
                    let mut r = rows.clone();
                    r[4] = replace_field(&replace_field(&r[4], 0, "500"), 1, "1200");
                    r
                }),
            )],
            2,
            &["line 6", "cannot be reached"],
        ),
        case(
            "too few poses",
            &[],
            vec![("few.csv", with_rows(&base, &rows[..4]))],
            2,
            &["too few poses", "at least"],
        ),
        case(
            "duplicate row",
            &[],
            vec![(
                "dup.csv",
                with_rows(&base, &[rows[0].clone(), rows[1].clone(), rows[0].clone()]),
            )],
            2,
            &["line 4 repeats line 2"],
        ),
        case(
            "negative command",
            &[],
            vec![(
                "neg.csv",
                with_rows(&base, &[replace_field(&rows[0], 2, "-700")]),
            )],
            2,
            &["column `q3`", "positive"],
        ),
        case(
            "bad approach direction",
            &[],
            vec![(
                "dir.csv",
                with_rows(&base, &[replace_field(&rows[0], 8, "0")]),
            )],
            2,
            &["column `dir1`", "+1 or -1"],
        ),
        case(
            "partial direction columns",
            &[],
            vec![(
                "partial.csv",
                with_rows("q1,q2,q3,phi,theta,s,dir1,dir2", &[]),
            )],
            2,
            &["come as a set", "dir3"],
        ),
        case(
            "implausible temperature",
            &[],
            vec![(
                "temp.csv",
                with_rows(&base, &[replace_field(&rows[0], 6, "2000")]),
            )],
            2,
            &["column `temp_c`", "temperature"],
        ),
        case("missing data file", &[], vec![], 2, &["nothere.csv"]),
        case(
            "not text",
            &[],
            vec![("binary.csv", vec![b'q', b'1', 0xff, 0xfe, b'\n'])],
            2,
            &["binary.csv", "UTF-8"],
        ),
    ];
    // The data cases all run `identify` on their first file (or a missing one).
    for c in cases.iter_mut() {
        let file = c.files.first().map_or("nothere.csv", |f| f.0);
        c.args = id(file);
    }
    let good = dir.join("good.csv").display().to_string();
    let machine_cases = vec![
        case(
            "unknown machine key",
            &[],
            vec![("unknown.json", {
                let mut v: serde_json::Value =
                    serde_json::from_str(tricept_kinematics::description::PAPER_MACHINE_JSON)
                        .unwrap();
                v["colour"] = "red".into();
                serde_json::to_vec_pretty(&v).unwrap()
            })],
            2,
            &["unknown.json: line", "unknown field `colour`"],
        ),
        case(
            "negative radius",
            &[],
            vec![(
                "negative.json",
                tricept_kinematics::description::PAPER_MACHINE_JSON
                    .replace("288.7", "-288.7")
                    .into_bytes(),
            )],
            2,
            &["base_radius_mm", "positive"],
        ),
        case(
            "coincident joints",
            &[],
            vec![(
                "coincident.json",
                tricept_kinematics::description::PAPER_MACHINE_JSON
                    .replace("[120.0, 240.0, 0.0]", "[120.0, 120.0, 0.0]")
                    .into_bytes(),
            )],
            2,
            &["coincide"],
        ),
        case(
            "malformed JSON",
            &[],
            vec![("malformed.json", b"{ \"name\": ".to_vec())],
            2,
            &["malformed.json: line 1"],
        ),
        case(
            "inverted stroke",
            &[],
            vec![(
                "stroke.json",
                tricept_kinematics::description::PAPER_MACHINE_JSON
                    .replace("[450.0, 1250.0]", "[1250.0, 450.0]")
                    .into_bytes(),
            )],
            2,
            &["leg_stroke_mm", "below"],
        ),
        case("missing machine file", &[], vec![], 2, &["nomachine.json"]),
    ];
    for mut c in machine_cases {
        let file = c.files.first().map_or("nomachine.json", |f| f.0);
        c.args = vec![
            "identify".into(),
            "--data".into(),
            good.clone(),
            "--machine".into(),
            dir.join(file).display().to_string(),
        ];
        cases.push(c);
    }
    // Arguments.
    let args = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    let mut arg_cases = vec![
        (
            case("ik with a word", &[], vec![], 2, &["invalid value"]),
            args(&["ik", "0", "x", "750"]),
        ),
        (
            case("ik out of reach", &[], vec![], 2, &["ik:", "stroke"]),
            args(&["ik", "0", "0", "3000"]),
        ),
        (
            case("fk without assembly", &[], vec![], 2, &["fk:"]),
            args(&["fk", "500", "1200", "1200"]),
        ),
        (
            case("unknown verb", &[], vec![], 2, &["unrecognized subcommand"]),
            args(&["calibrate-everything"]),
        ),
        (
            case(
                "unknown parameter set",
                &[],
                vec![],
                2,
                &["--params", "paper99"],
            ),
            args(&["identifiability", "--params", "paper99"]),
        ),
        (
            case("bad pose set", &[], vec![], 2, &["grid:2,x,1"]),
            args(&["identifiability", "--poses", "grid:2,x,1"]),
        ),
        (
            case(
                "negative noise",
                &[],
                vec![],
                2,
                &["--angle-noise-arcsec", "positive"],
            ),
            args(&["identifiability", "--angle-noise-arcsec", "-1"]),
        ),
        (
            case("missing errors file", &[], vec![], 2, &["noerrors.json"]),
            args(&["simulate", "--errors", "noerrors.json"]),
        ),
        (
            case(
                "bad effect",
                &[],
                vec![],
                2,
                &["--truth-effect", "unknown variant"],
            ),
            args(&["simulate", "--truth-effect", r#"{"effect":"gremlins"}"#]),
        ),
        (
            case(
                "too few poses to diagnose",
                &[],
                vec![],
                2,
                &["too few poses"],
            ),
            vec![
                "diagnose".into(),
                "--data".into(),
                dir.join("few10.csv").display().to_string(),
            ],
        ),
        (
            case("unknown error parameter", &[], vec![], 2, &["dzB1"]),
            vec![
                "simulate".into(),
                "--errors".into(),
                dir.join("errors.json").display().to_string(),
            ],
        ),
    ];
    std::fs::write(dir.join("few10.csv"), with_rows(&base, &rows[..10])).unwrap();
    // Degenerate data for the diagnosis.
    let swap = |row: &String| {
        let mut f: Vec<&str> = row.split(',').collect();
        f.swap(0, 1);
        f.join(",")
    };
    let swapped: Vec<String> = rows.iter().map(swap).collect();
    std::fs::write(dir.join("swapped.csv"), with_rows(&base, &swapped)).unwrap();
    let repeated: Vec<String> = (0..25)
        .map(|k| {
            let f: Vec<&str> = rows[0].split(',').collect();
            let s: f64 = f[5].parse().unwrap();
            replace_field(&rows[0], 5, &(s + 1e-4 * k as f64).to_string())
        })
        .collect();
    std::fs::write(dir.join("repeated.csv"), with_rows(&base, &repeated)).unwrap();
    std::fs::write(dir.join("good.csv"), &csv).unwrap();
    std::fs::write(dir.join("ranges.json"), r#"{"thermal.alpha": [20, 26]}"#).unwrap();
    let diag = |file: &str, extra: &[&str]| {
        let mut v = vec![
            "diagnose".to_string(),
            "--data".to_string(),
            dir.join(file).display().to_string(),
        ];
        v.extend(extra.iter().map(|s| s.to_string()));
        v
    };
    for (name, args, needles) in [
        (
            "diagnose: every row with q1 and q2 swapped",
            diag("swapped.csv", &[]),
            &["swapped.csv", "cannot be fitted"][..],
        ),
        (
            "diagnose: one pose logged again and again",
            diag("repeated.csv", &[]),
            &["repeated.csv", "distinct pose"][..],
        ),
        (
            "diagnose: noise from data without repeated poses",
            diag("good.csv", &["--noise-from-data"]),
            &["repeated poses"][..],
        ),
        (
            "diagnose: unknown plausibility quantity",
            diag("good.csv", &["--plausibility", "ranges.json"]),
            &["ranges.json", "unknown quantity `thermal.alpha`"][..],
        ),
        (
            "diagnose: negative temperature noise",
            diag("good.csv", &["--temperature-noise", "-1"]),
            &["--temperature-noise"][..],
        ),
        (
            "diagnose: unknown deploy rule",
            diag("good.csv", &["--deploy-rule", "always"]),
            &["--deploy-rule", "confident, expected-error"][..],
        ),
    ] {
        let mut c = case(name, &[], vec![], 2, needles);
        c.args = args;
        cases.push(c);
    }
    std::fs::write(dir.join("errors.json"), r#"{"dzB1": 0.1}"#).unwrap();
    for (mut c, a) in arg_cases.drain(..) {
        c.args = a;
        cases.push(c);
    }
    assert!(cases.len() >= 25, "{} cases", cases.len());
    cases
}

/// A table of cases, built in a directory.
type Table = fn(&Path) -> Vec<Case>;

/// Runs the case `name` of `table` alone, in a directory of its own
/// (`tag` names it) holding what the whole table's run would have left
/// there before it: the table's files, and those of the cases before it.
fn run_named(table: Table, tag: &str, name: &str) {
    let dir = fresh_workdir(&format!("bad-inputs-{tag}"));
    let cases = table(&dir);
    let k = cases
        .iter()
        .position(|c| c.name == name)
        .unwrap_or_else(|| panic!("no case named `{name}`"));
    for c in &cases[..k] {
        for (file, content) in &c.files {
            std::fs::write(dir.join(file), content).unwrap();
        }
    }
    run_cases(&dir, &cases[k..=k]);
    std::fs::remove_dir_all(&dir).ok();
}

/// Every case of `table` has a test of its own: the names in `tested` are
/// the table's, each once.
fn every_case_is_tested(table: Table, tag: &str, tested: &[&str]) {
    let dir = fresh_workdir(&format!("bad-inputs-{tag}"));
    let names: Vec<&str> = table(&dir).iter().map(|c| c.name).collect();
    std::fs::remove_dir_all(&dir).ok();
    let mut unique = names.clone();
    unique.sort_unstable();
    unique.dedup();
    assert_eq!(unique.len(), names.len(), "case names repeat: {names:?}");
    let untested: Vec<String> = names
        .iter()
        .filter(|n| !tested.contains(n))
        .map(|n| format!("{} = {n:?};", slug(n)))
        .collect();
    assert!(
        untested.is_empty(),
        "cases without a test:\n{}",
        untested.join("\n")
    );
    let unknown: Vec<&&str> = tested.iter().filter(|n| !names.contains(n)).collect();
    assert!(unknown.is_empty(), "tests of no case: {unknown:?}");
}

/// A case name as a test name.
fn slug(name: &str) -> String {
    let mut s: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '_'
            }
        })
        .collect();
    while s.contains("__") {
        s = s.replace("__", "_");
    }
    s.trim_matches('_').to_string()
}

/// One test per case of a table: `module = table; test = "case name"; ...`.
/// The module also checks that every case of the table is tested.
macro_rules! named_cases {
    ($module:ident = $table:ident; $($test:ident = $name:literal;)*) => {
        mod $module {
            $(
                #[test]
                fn $test() {
                    super::run_named(
                        super::$table,
                        concat!(stringify!($module), "-", stringify!($test)),
                        $name,
                    );
                }
            )*
            #[test]
            fn every_case_is_tested() {
                super::every_case_is_tested(
                    super::$table,
                    stringify!($module),
                    &[$($name),*],
                );
            }
        }
    };
}

named_cases! {
    bad_inputs_get_exit_code_2_and_a_message_naming_the_problem = bad_inputs_cases;
    empty_file = "empty file";
    header_only = "header only";
    missing_column = "missing column";
    misspelt_column = "misspelt column";
    non_numeric_field = "non-numeric field";
    nan = "NaN";
    infinity = "infinity";
    wrong_column_count = "wrong column count";
    angles_in_degrees = "angles in degrees";
    command_beyond_the_stroke = "command beyond the stroke";
    no_assembly_for_the_commands = "no assembly for the commands";
    too_few_poses = "too few poses";
    duplicate_row = "duplicate row";
    negative_command = "negative command";
    bad_approach_direction = "bad approach direction";
    partial_direction_columns = "partial direction columns";
    implausible_temperature = "implausible temperature";
    missing_data_file = "missing data file";
    not_text = "not text";
    unknown_machine_key = "unknown machine key";
    negative_radius = "negative radius";
    coincident_joints = "coincident joints";
    malformed_json = "malformed JSON";
    inverted_stroke = "inverted stroke";
    missing_machine_file = "missing machine file";
    diagnose_every_row_with_q1_and_q2_swapped = "diagnose: every row with q1 and q2 swapped";
    diagnose_one_pose_logged_again_and_again = "diagnose: one pose logged again and again";
    diagnose_noise_from_data_without_repeated_poses = "diagnose: noise from data without repeated poses";
    diagnose_unknown_plausibility_quantity = "diagnose: unknown plausibility quantity";
    diagnose_negative_temperature_noise = "diagnose: negative temperature noise";
    diagnose_unknown_deploy_rule = "diagnose: unknown deploy rule";
    ik_with_a_word = "ik with a word";
    ik_out_of_reach = "ik out of reach";
    fk_without_assembly = "fk without assembly";
    unknown_verb = "unknown verb";
    unknown_parameter_set = "unknown parameter set";
    bad_pose_set = "bad pose set";
    negative_noise = "negative noise";
    missing_errors_file = "missing errors file";
    bad_effect = "bad effect";
    too_few_poses_to_diagnose = "too few poses to diagnose";
    unknown_error_parameter = "unknown error parameter";
}

named_cases! {
    bad_external_inputs_get_exit_code_2_and_a_message_naming_the_problem = bad_external_cases;
    tracker_missing_column = "tracker: missing column";
    tracker_not_a_number = "tracker: not a number";
    tracker_head_angles_in_degrees = "tracker: head angles in degrees";
    tracker_non_positive_sigma = "tracker: non-positive sigma";
    tracker_repeated_row = "tracker: repeated row";
    tracker_command_outside_the_stroke = "tracker: command outside the stroke";
    tracker_two_points = "tracker: two points";
    tracker_points_on_one_line = "tracker: points on one line";
    tracker_one_tool_orientation = "tracker: one tool orientation";
    ballbar_length_in_um = "ballbar: length in um";
    ballbar_ball_in_one_plane = "ballbar: ball in one plane";
    touch_unknown_feature = "touch: unknown feature";
    touch_no_features_file = "touch: no features file";
    features_not_json = "features: not JSON";
    unknown_effect = "unknown effect";
    bad_tracker_target = "bad tracker target";
    tracker_target_not_stated = "tracker target not stated";
    plan_tracker_target_not_stated = "plan: tracker target not stated";
    bad_head = "bad head";
    write_machine_with_effects = "write-machine with effects";
    plan_zero_measurements = "plan: zero measurements";
    plan_unreachable_pivot = "plan: unreachable pivot";
    simulate_tracker_output_without_poses = "simulate: tracker output without poses";
    simulate_unknown_head_parameter = "simulate: unknown head parameter";
}

named_cases! {
    values_sizes_and_files_no_verb_can_use_get_exit_code_2 = unusable_cases;
    tracker_x_of_1e300 = "tracker x of 1e300";
    features_radius_of_1e308 = "features radius of 1e308";
    truth_of_1e308 = "truth of 1e308";
    workspace_beyond_the_stroke = "workspace beyond the stroke";
    plan_output_in_a_missing_directory = "plan output in a missing directory";
    s_of_1e308_for_the_diagnosis = "s of 1e308 for the diagnosis";
    head_errors_of_1e300 = "head errors of 1e300";
    negative_stiffness = "negative stiffness";
    duplicate_key_in_a_truth_file = "duplicate key in a truth file";
    negative_accuracy_target = "negative accuracy target";
    accuracy_target_not_a_number = "accuracy target not a number";
    the_same_tracker_file_twice = "the same tracker file twice";
    header_only_batch_file = "header-only batch file";
    tolerance_of_1_mm = "tolerance of -1 mm";
    no_optimal_poses = "no optimal poses";
    huge_evaluation_grid = "huge evaluation grid";
    huge_candidate_grid = "huge candidate grid";
    ten_million_ballbar_candidates = "ten million ballbar candidates";
    a_ball_1e308_mm_from_the_tip = "a ball 1e308 mm from the tip";
    a_1_mm_table = "a 1 mm table";
    dev_zero_as_data = "/dev/zero as data";
    old_mac_line_ends = "old Mac line ends";
    tab_separated = "tab-separated";
    no_header = "no header";
    a_100_kb_field = "a 100 kB field";
    a_10_mb_line = "a 10 MB line";
    control_characters = "control characters";
    a_tracker_file_given_as_measured_data = "a tracker file given as measured data";
    leg_offset_edited = "leg offset edited";
    nominal_edited = "nominal edited";
    estimate_edited = "estimate edited";
    unknown_method = "unknown method";
    unknown_parameter_set = "unknown parameter set";
    truth_not_a_spec = "truth not a spec";
    compensate_truth_of_a_negative_size = "compensate: truth of a negative size";
    compensate_truth_effect_not_json = "compensate: truth effect not JSON";
    truth_effect_file_missing = "truth effect file missing";
    touch_sphere_of_two_numbers = "touch sphere of two numbers";
    plan_touch_sphere_not_a_number = "plan: touch sphere not a number";
    tracker_frame_of_five_numbers = "tracker frame of five numbers";
    tracker_frame_beyond_any_machine = "tracker frame beyond any machine";
}

/// Runs every case in `dir`; every broken expectation is collected, so
/// that one run shows all of them.
fn run_cases(dir: &Path, cases: &[Case]) {
    let mut failures: Vec<String> = Vec::new();
    for c in cases {
        for (name, content) in &c.files {
            std::fs::write(dir.join(name), content).unwrap();
        }
        let out = tricept().args(&c.args).current_dir(dir).output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        let mut fail = |what: String| failures.push(format!("{}: {what}\n{stderr}", c.name));
        if stderr.contains("panicked") {
            fail("panicked".into());
        }
        if out.status.code() != Some(c.code) {
            fail(format!(
                "exit code {:?}, expected {}",
                out.status.code(),
                c.code
            ));
        }
        for n in &c.needles {
            if !stderr.contains(n) {
                fail(format!("stderr lacks `{n}`"));
            }
        }
        if !out.stdout.is_empty() {
            fail("printed to stdout".into());
        }
        // clap's usage errors span a few lines; ours are exactly one.
        let from_clap = c
            .needles
            .iter()
            .any(|n| ["invalid value", "unrecognized subcommand"].contains(n));
        if !from_clap && stderr.trim_end().lines().count() != 1 {
            fail("not exactly one line on stderr".into());
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} cases failed:\n\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n")
    );
}

/// One row of a 40-pose file logged again with two commands swapped: a
/// gross inconsistency, flagged by its line; the report is finite and the
/// exit code 0.
#[test]
fn a_duplicated_row_with_swapped_commands_is_flagged_not_fatal() {
    let dir = workdir("bad-inputs").join("swapped-row");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("dup.csv");
    let out = tricept()
        .args([
            "simulate",
            "--errors",
            "random:0.25,4",
            "--poses",
            "random:40,11",
            "--effect",
            r#"{"effect":"thermal","drift_k":2,"expansion_ppm_per_k":0}"#,
            "--out",
        ])
        .arg(&path)
        .output()
        .unwrap();
    assert!(out.status.success());
    let text = std::fs::read_to_string(&path).unwrap();
    let (comments, header, rows) = split(&text);
    let mut f: Vec<&str> = rows[5].split(',').collect();
    f.swap(0, 1);
    let mut all = rows.clone();
    all.push(f.join(","));
    let mut body = comments.join("\n");
    body.push('\n');
    body.push_str(&String::from_utf8(with_rows(&header, &all)).unwrap());
    std::fs::write(&path, body).unwrap();
    let line = (comments.len() + 1 + all.len()) as u64;
    let out = tricept()
        .args(["diagnose", "--json", "--data"])
        .arg(&path)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(!text.contains("NaN") && !text.contains("inf"), "{text}");
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let outliers = v["causes"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["effect"] == "outliers")
        .expect("the swapped row is an outlier");
    assert_eq!(outliers["rows"], serde_json::json!([line]));
    for k in ["holdout_rms_geometric", "holdout_rms_extended"] {
        assert!(v["gain"][k].as_f64().is_some_and(f64::is_finite), "{k}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn results_go_to_stdout_with_exit_code_0() {
    let out = tricept()
        .args(["ik", "-120.5", "80", "700", "--json"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0));
    assert!(out.stderr.is_empty());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    for k in ["q1", "q2", "q3", "phi", "theta", "q4"] {
        assert!(v[k].is_number(), "{k}");
    }
    let q = [
        v["q1"].as_f64().unwrap(),
        v["q2"].as_f64().unwrap(),
        v["q3"].as_f64().unwrap(),
    ];
    let out = tricept()
        .args([
            "fk",
            &q[0].to_string(),
            &q[1].to_string(),
            &q[2].to_string(),
            "--json",
        ])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0));
    let f: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!((f["x"].as_f64().unwrap() + 120.5).abs() < 1e-9);
    assert!((f["y"].as_f64().unwrap() - 80.0).abs() < 1e-9);
    assert!((f["z"].as_f64().unwrap() - 700.0).abs() < 1e-9);
    let out = tricept().args(["--help"]).output().unwrap();
    assert_eq!(out.status.code(), Some(0));
    assert!(String::from_utf8_lossy(&out.stdout).contains("identify"));
}

/// A file of poses (`q1,q2,q3,h1,h2`) for the nominal machine at tool tips
/// `tips` with tool axes `axes`.
fn poses_csv(tips: &[[f64; 3]], axes: &[[f64; 3]], extension: Option<&[f64]>) -> Vec<u8> {
    let m = tricept_kinematics::Machine::paper();
    let mut s = String::from("q1,q2,q3,h1,h2");
    s.push_str(if extension.is_some() {
        ",extension_mm\n"
    } else {
        "\n"
    });
    for (j, (t, a)) in tips.iter().zip(axes).enumerate() {
        let ik = m
            .tool_inverse(
                &nalgebra::Vector3::from(*t),
                &nalgebra::Vector3::from(*a),
                tricept_kinematics::head::HeadBranch::default(),
            )
            .unwrap();
        let [q1, q2, q3] = ik.legs_mm;
        let [h1, h2] = ik.head_rad;
        s.push_str(&format!("{q1},{q2},{q3},{h1},{h2}"));
        if let Some(e) = extension {
            s.push_str(&format!(",{}", e[j]));
        }
        s.push('\n');
    }
    s.into_bytes()
}

/// 12 tool poses spread over the workspace: tips on a 250 mm circle at
/// three heights, tool axes tilted 0.4 in turn.
fn spread_tool_poses() -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
    let tips: Vec<[f64; 3]> = (0..12)
        .map(|j| {
            let a = j as f64 * std::f64::consts::FRAC_PI_6;
            [
                250.0 * a.cos(),
                250.0 * a.sin(),
                1050.0 + 10.0 * (j % 3) as f64,
            ]
        })
        .collect();
    let axes: Vec<[f64; 3]> = (0..12)
        .map(|j| {
            let a = j as f64 * 1.9;
            [0.4 * a.cos(), 0.4 * a.sin(), 1.0]
        })
        .collect();
    (tips, axes)
}

/// The table of bad external-instrument inputs (trackers, ballbars,
/// touch-offs): each an exit code 2 and a message naming the problem.
fn bad_external_cases(dir: &Path) -> Vec<Case> {
    // Good files: internal data, 12 spread tracker points, a ballbar.
    let (tips, axes) = spread_tool_poses();
    std::fs::write(dir.join("poses.csv"), poses_csv(&tips, &axes, None)).unwrap();
    ok(
        dir,
        &[
            "simulate",
            "--poses",
            "grid:1,8,3",
            "--head-errors",
            "random:1,3",
            "--out",
            "good.csv",
            "--tracker-out",
            "tracker.csv",
            "--tracker-poses",
            "poses.csv",
        ],
    );
    let tracker = std::fs::read_to_string(dir.join("tracker.csv")).unwrap();
    let (_, t_header, t_rows) = split(&tracker);
    let bar_tips: Vec<[f64; 3]> = (0..8)
        .map(|j| {
            let a = j as f64 * std::f64::consts::FRAC_PI_4;
            [100.0 * a.cos(), 100.0 * a.sin(), 1250.0 - 112.0]
        })
        .collect();
    std::fs::write(dir.join("flat.csv"), poses_csv(&bar_tips, &axes[..8], None)).unwrap();
    ok(
        dir,
        &[
            "simulate",
            "--poses",
            "grid:1,8,3",
            "--out",
            "unused.csv",
            "--ballbar-out",
            "flat-ballbar.csv",
            "--ballbar-poses",
            "flat.csv",
        ],
    );
    // One pose, three extensions along the tool: collinear points.
    let one = [tips[0]; 3];
    std::fs::write(
        dir.join("line.csv"),
        poses_csv(&one, &[axes[0]; 3], Some(&[0.0, 50.0, 100.0])),
    )
    .unwrap();
    ok(
        dir,
        &[
            "simulate",
            "--poses",
            "grid:1,8,3",
            "--out",
            "unused.csv",
            "--tracker-out",
            "line-tracker.csv",
            "--tracker-poses",
            "line.csv",
        ],
    );
    // Five tips, one tool orientation: the target's offset along the tool
    // is a translation of the tracker.
    let z = [[0.0, 0.0, 1.0]; 5];
    std::fs::write(dir.join("still.csv"), poses_csv(&tips[..5], &z, None)).unwrap();
    ok(
        dir,
        &[
            "simulate",
            "--poses",
            "grid:1,8,3",
            "--out",
            "unused.csv",
            "--tracker-out",
            "still-tracker.csv",
            "--tracker-poses",
            "still.csv",
        ],
    );
    let features = r#"{"stylus": {"radius_mm": 1.0, "radius_sigma_um": 2.0}, "features": [{"id": 1, "kind": "plane"}]}"#;
    // A tracker's target is always stated (there is no default).
    let fused = |extra: &[&str]| -> Vec<String> {
        let stated = !extra.contains(&"--tracker") || extra.contains(&"--tracker-target");
        let target: &[&str] = if stated {
            &[]
        } else {
            &["--tracker-target", "tip"]
        };
        ["identify", "--data", "good.csv"]
            .iter()
            .chain(extra)
            .chain(target)
            .map(|s| s.to_string())
            .collect()
    };
    let mut cases = vec![
        case(
            "tracker: missing column",
            &[],
            vec![("t1.csv", with_rows(&t_header.replace(",z", ""), &t_rows))],
            2,
            &["t1.csv: line 1: missing required column `z`"],
        ),
        case(
            "tracker: not a number",
            &[],
            vec![(
                "t2.csv",
                with_rows(
                    &t_header,
                    &[t_rows[0].clone(), replace_field(&t_rows[1], 6, "NaN")],
                ),
            )],
            2,
            &["t2.csv: line 3, column `y`: not a finite number"],
        ),
        case(
            "tracker: head angles in degrees",
            &[],
            vec![(
                "t3.csv",
                with_rows(&t_header, &[replace_field(&t_rows[0], 3, "90")]),
            )],
            2,
            &["t3.csv: line 2, column `h1`", "degrees"],
        ),
        case(
            "tracker: non-positive sigma",
            &[],
            vec![(
                "t4.csv",
                with_rows(&t_header, &[replace_field(&t_rows[0], 8, "0")]),
            )],
            2,
            &["t4.csv: line 2, column `sigma_um`: a standard deviation must be positive"],
        ),
        case(
            "tracker: repeated row",
            &[],
            vec![(
                "t5.csv",
                with_rows(&t_header, &[t_rows[0].clone(), t_rows[0].clone()]),
            )],
            2,
            &["t5.csv: line 3 repeats line 2"],
        ),
        case(
            "tracker: command outside the stroke",
            &[],
            vec![(
                "t6.csv",
                with_rows(&t_header, &[replace_field(&t_rows[0], 1, "100")]),
            )],
            2,
            &["t6.csv: line 2, column `q2`: command 100 mm is outside the leg stroke"],
        ),
        case(
            "tracker: two points",
            &[],
            vec![("t7.csv", with_rows(&t_header, &t_rows[..2]))],
            2,
            &["t7.csv: station 1 has 2 points"],
        ),
        case(
            "tracker: points on one line",
            &[],
            vec![],
            2,
            &["line-tracker.csv", "lie on one line"],
        ),
        case(
            "tracker: one tool orientation",
            &[],
            vec![],
            2,
            &[
                "still-tracker.csv",
                "cannot be determined",
                "vary the spindle's orientation",
            ],
        ),
        case(
            "ballbar: length in um",
            &[],
            vec![(
                "b1.csv",
                b"q1,q2,q3,h1,h2,length\n800,800,800,0,0,150000\n".to_vec(),
            )],
            2,
            &["b1.csv: line 2, column `length`: a ballbar length must be 10-2000 mm"],
        ),
        case(
            "ballbar: ball in one plane",
            &[],
            vec![],
            2,
            &["flat-ballbar.csv", "lie in one plane"],
        ),
        case(
            "touch: unknown feature",
            &[],
            vec![
                (
                    "touch.csv",
                    format!(
                        "q1,q2,q3,h1,h2,feature\n{},7\n",
                        t_rows[0].split(',').take(5).collect::<Vec<_>>().join(",")
                    )
                    .into_bytes(),
                ),
                ("features.json", features.as_bytes().to_vec()),
            ],
            2,
            &["touch.csv: line 2: column `feature`: feature 7 is not in the features file"],
        ),
        case(
            "touch: no features file",
            &[],
            vec![],
            2,
            &["--features: needed with touch-off files"],
        ),
        case(
            "features: not JSON",
            &[],
            vec![(
                "bad-features.json",
                b"{\"stylus\": {\"radius_mm\": 1.0,\n \"radius_sigma_um\": }}".to_vec(),
            )],
            2,
            &["bad-features.json: line 2, column"],
        ),
        case(
            "unknown effect",
            &[],
            vec![],
            2,
            &["--effects: unknown effect `gravity`"],
        ),
        case(
            "bad tracker target",
            &[],
            vec![],
            2,
            &["--tracker-target: expected `tip`, `free` or X,Y,Z in mm, got `1,2`"],
        ),
        case(
            "tracker target not stated",
            &[],
            vec![],
            2,
            &[
                "--tracker-target is required with a tracker",
                "`tip`",
                "`free`",
            ],
        ),
        case(
            "plan: tracker target not stated",
            &[],
            vec![],
            2,
            &["--tracker-target is required with a tracker"],
        ),
        case(
            "bad head",
            &[],
            vec![],
            2,
            &["--head: expected head13 or none"],
        ),
        case(
            "write-machine with effects",
            &[],
            vec![],
            2,
            &["--write-machine: leg-lead fitted, but the machine format cannot carry it"],
        ),
        case(
            "plan: zero measurements",
            &[],
            vec![],
            2,
            &["--k: expected positive whole numbers"],
        ),
        case(
            "plan: unreachable pivot",
            &[],
            vec![],
            2,
            &["--ballbar-pivot-mm 0,0,3000: the machine reaches only 0 positions"],
        ),
        case(
            "simulate: tracker output without poses",
            &[],
            vec![],
            2,
            &["--tracker-out and --tracker-poses go together"],
        ),
        case(
            "simulate: unknown head parameter",
            &[],
            vec![("head.json", br#"{"tool_lenght_mm": 0.3}"#.to_vec())],
            2,
            &["--head-errors: head.json: unknown parameter `tool_lenght_mm`"],
        ),
    ];
    let args: Vec<Vec<String>> = vec![
        fused(&["--tracker", "t1.csv"]),
        fused(&["--tracker", "t2.csv"]),
        fused(&["--tracker", "t3.csv"]),
        fused(&["--tracker", "t4.csv"]),
        fused(&["--tracker", "t5.csv"]),
        fused(&["--tracker", "t6.csv"]),
        fused(&["--tracker", "t7.csv"]),
        fused(&["--tracker", "line-tracker.csv"]),
        fused(&["--tracker", "still-tracker.csv", "--tracker-target", "free"]),
        fused(&["--ballbar", "b1.csv"]),
        fused(&["--ballbar", "flat-ballbar.csv"]),
        fused(&["--touch", "touch.csv", "--features", "features.json"]),
        fused(&["--touch", "touch.csv"]),
        fused(&["--touch", "touch.csv", "--features", "bad-features.json"]),
        fused(&["--effects", "gravity"]),
        fused(&["--tracker", "tracker.csv", "--tracker-target", "1,2"]),
        ["identify", "--data", "good.csv", "--tracker", "tracker.csv"]
            .map(String::from)
            .to_vec(),
        ["plan", "--instrument", "tracker", "--k", "5"]
            .map(String::from)
            .to_vec(),
        fused(&["--head", "head15"]),
        fused(&[
            "--tracker",
            "tracker.csv",
            "--effects",
            "leg-lead",
            "--write-machine",
            "m.json",
        ]),
        ["plan", "--instrument", "tracker", "--k", "0"]
            .map(String::from)
            .to_vec(),
        [
            "plan",
            "--instrument",
            "ballbar",
            "--ballbar-pivot-mm",
            "0,0,3000",
        ]
        .map(String::from)
        .to_vec(),
        ["simulate", "--tracker-out", "x.csv"]
            .map(String::from)
            .to_vec(),
        ["simulate", "--head-errors", "head.json"]
            .map(String::from)
            .to_vec(),
    ];
    assert_eq!(args.len(), cases.len());
    for (c, a) in cases.iter_mut().zip(args) {
        c.args = a;
    }
    cases
}

/// Values, sizes and files no verb can use (issue 17): numbers beyond
/// any unit of the format, plausible-looking magnitudes that would
/// overflow, sizes that would exhaust the memory or run without end, files
/// in another format, calibrated machine files edited by hand; each an
/// exit code 2 with one line naming the file, line and column or the flag.
fn unusable_cases(dir: &Path) -> Vec<Case> {
    let csv = good_csv(dir);
    std::fs::write(dir.join("good.csv"), &csv).unwrap();
    let (_, header, rows) = split(&csv);
    // A tracker file of this campaign (12 tool poses).
    let (tips, axes) = spread_tool_poses();
    std::fs::write(dir.join("poses.csv"), poses_csv(&tips, &axes, None)).unwrap();
    ok(
        dir,
        &[
            "simulate",
            "--poses",
            "grid:1,8,3",
            "--out",
            "unused.csv",
            "--tracker-out",
            "tracker.csv",
            "--tracker-poses",
            "poses.csv",
        ],
    );
    let tracker = std::fs::read_to_string(dir.join("tracker.csv")).unwrap();
    let (_, t_header, t_rows) = split(&tracker);
    let tx = t_header.split(',').position(|c| c == "x").unwrap();
    let mut big_x = t_rows.clone();
    big_x[3] = replace_field(&big_x[3], tx, "1e300");
    let s_col = header.split(',').position(|c| c == "s").unwrap();
    let mut big_s = rows.clone();
    big_s[4] = replace_field(&big_s[4], s_col, "1e308");
    let mut long_field = rows.clone();
    long_field[2] = replace_field(&long_field[2], 0, &format!("{}x", "7".repeat(100_000)));
    let mut long_line = rows.clone();
    long_line[2] = replace_field(&long_line[2], 0, &"7".repeat(10_000_000));
    let mut control = rows.clone();
    control[1] = replace_field(&control[1], 0, "7\u{1b}[2J7");
    // A calibrated machine file and hand edits of it.
    ok(
        dir,
        &[
            "identify",
            "--data",
            "good.csv",
            "--write-machine",
            "cal.json",
        ],
    );
    let cal: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("cal.json")).unwrap()).unwrap();
    let edited = |edit: &dyn Fn(&mut serde_json::Value)| {
        let mut v = cal.clone();
        edit(&mut v);
        serde_json::to_vec_pretty(&v).unwrap()
    };
    let mut unreachable: serde_json::Value =
        serde_json::from_str(tricept_kinematics::description::PAPER_MACHINE_JSON).unwrap();
    unreachable["workspace"]["radius_mm"] = 900.0.into();
    let features = br#"{"stylus": {"radius_mm": 1.0, "radius_sigma_um": 2.0},
      "features": [{"id": 1, "kind": "sphere", "radius_mm": 1e308, "radius_sigma_um": 0.5}]}"#;
    let a = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<String>>();
    let rows_of = |r: &[String]| with_rows(&header, r);
    let cases: Vec<(Case, Vec<String>)> = vec![
        // Numbers beyond any unit (exit 1 or a panic before).
        (
            case(
                "tracker x of 1e300",
                &[],
                vec![("big-x.csv", with_rows(&t_header, &big_x))],
                2,
                &["big-x.csv: line", "column `x`", "1e300", "beyond"],
            ),
            a(&[
                "identify",
                "--data",
                "good.csv",
                "--tracker",
                "big-x.csv",
                "--tracker-target",
                "tip",
            ]),
        ),
        (
            case(
                "features radius of 1e308",
                &[],
                vec![("big-f.json", features.to_vec())],
                2,
                &[
                    "big-f.json",
                    "radius_mm must be positive and at most 1000 mm",
                ],
            ),
            a(&[
                "identify",
                "--data",
                "good.csv",
                "--touch",
                "tracker.csv",
                "--features",
                "big-f.json",
            ]),
        ),
        (
            case(
                "truth of 1e308",
                &[],
                vec![("big-truth.json", br#"{"dq1": 1e308}"#.to_vec())],
                2,
                &["big-truth.json", "dq1", "beyond ±50 mm"],
            ),
            a(&[
                "compensate",
                "--data",
                "good.csv",
                "--truth",
                "big-truth.json",
            ]),
        ),
        (
            case(
                "workspace beyond the stroke",
                &[],
                vec![("far.json", serde_json::to_vec_pretty(&unreachable).unwrap())],
                2,
                &[
                    "far.json",
                    "not within the machine's reach",
                    "shrink `workspace`",
                ],
            ),
            a(&["identify", "--data", "good.csv", "--machine", "far.json"]),
        ),
        (
            case(
                "plan output in a missing directory",
                &[],
                vec![],
                2,
                &["--out", "does not exist"],
            ),
            a(&[
                "plan",
                "--instrument",
                "tracker",
                "--tracker-target",
                "tip",
                "--out",
                "/nonexistent/dir/p.csv",
            ]),
        ),
        (
            case(
                "s of 1e308 for the diagnosis",
                &[],
                vec![("big-s.csv", rows_of(&big_s))],
                2,
                &["big-s.csv: line", "column `s`", "beyond"],
            ),
            a(&["diagnose", "--data", "big-s.csv"]),
        ),
        // Bad values that used to be accepted.
        (
            case(
                "head errors of 1e300",
                &[],
                vec![("he.json", br#"{"tool_length_mm": 1e300}"#.to_vec())],
                2,
                &["--head-errors", "he.json", "tool_length_mm", "beyond"],
            ),
            a(&["simulate", "--head-errors", "he.json"]),
        ),
        (
            case(
                "negative stiffness",
                &[],
                vec![],
                2,
                &["--truth-effect", "stiffness_n_per_um_at_1m", "positive"],
            ),
            a(&[
                "simulate",
                "--truth-effect",
                r#"{"effect":"compliance","stiffness_n_per_um_at_1m":-5}"#,
            ]),
        ),
        (
            case(
                "duplicate key in a truth file",
                &[],
                vec![("dup.json", br#"{"dq1": 0.1, "dq1": 0.2}"#.to_vec())],
                2,
                &["dup.json", "the key `dq1` appears twice"],
            ),
            a(&["simulate", "--truth", "dup.json"]),
        ),
        (
            case(
                "negative accuracy target",
                &[],
                vec![],
                2,
                &["--target-um", "positive"],
            ),
            a(&[
                "plan",
                "--instrument",
                "tracker",
                "--tracker-target",
                "tip",
                "--target-um",
                "-1",
            ]),
        ),
        (
            case(
                "accuracy target not a number",
                &[],
                vec![],
                2,
                &["--target-um", "positive"],
            ),
            a(&[
                "plan",
                "--instrument",
                "tracker",
                "--tracker-target",
                "tip",
                "--target-um",
                "nan",
            ]),
        ),
        (
            case(
                "the same tracker file twice",
                &[],
                vec![],
                2,
                &["--tracker", "tracker.csv", "counts once"],
            ),
            a(&[
                "identify",
                "--data",
                "good.csv",
                "--tracker",
                "tracker.csv",
                "--tracker",
                "./tracker.csv",
                "--tracker-target",
                "tip",
            ]),
        ),
        (
            case(
                "header-only batch file",
                &[],
                vec![("points.csv", b"x,y,z\n".to_vec())],
                2,
                &["points.csv: header only"],
            ),
            a(&["ik", "--input", "points.csv"]),
        ),
        (
            case("tolerance of -1 mm", &[], vec![], 2, &["--tolerance-mm"]),
            a(&["identify", "--data", "good.csv", "--tolerance-mm", "-1"]),
        ),
        (
            case("no optimal poses", &[], vec![], 2, &["--poses `optimal:0`"]),
            a(&["simulate", "--poses", "optimal:0"]),
        ),
        // Sizes that would exhaust the memory or run without end.
        (
            case(
                "huge evaluation grid",
                &[],
                vec![],
                2,
                &["--eval-grid", "evaluation poses; at most 10000"],
            ),
            a(&[
                "plan",
                "--instrument",
                "tracker",
                "--tracker-target",
                "tip",
                "--eval-grid",
                "1000,1000,1000",
            ]),
        ),
        (
            case(
                "huge candidate grid",
                &[],
                vec![],
                2,
                &["grid:1000,1000,100", "at most 1000000"],
            ),
            a(&[
                "plan",
                "--instrument",
                "tracker",
                "--tracker-target",
                "tip",
                "--candidates",
                "grid:1000,1000,100",
            ]),
        ),
        (
            case(
                "ten million ballbar candidates",
                &[],
                vec![],
                2,
                &["--ballbar-candidates", "at most 50000"],
            ),
            a(&[
                "plan",
                "--instrument",
                "ballbar",
                "--ballbar-candidates",
                "10000000",
            ]),
        ),
        (
            case(
                "a ball 1e308 mm from the tip",
                &[],
                vec![],
                2,
                &["--ballbar-ball-mm", "beyond"],
            ),
            a(&[
                "identify",
                "--data",
                "good.csv",
                "--ballbar",
                "tracker.csv",
                "--ballbar-ball-mm",
                "1e308,0,0",
            ]),
        ),
        (
            case(
                "a 1 mm table",
                &[],
                vec![],
                2,
                &["--table-spacing 1", "coarser spacing"],
            ),
            a(&[
                "compensate",
                "--data",
                "good.csv",
                "--table",
                "out",
                "--table-spacing",
                "1",
            ]),
        ),
        (
            case(
                "/dev/zero as data",
                &[],
                vec![],
                2,
                &["/dev/zero: line 1", "longer than 1048576 bytes"],
            ),
            a(&["identify", "--data", "/dev/zero"]),
        ),
        // Files in another format; fields that would flood the terminal.
        (
            case(
                "old Mac line ends",
                &[],
                vec![("cr.csv", csv.replace('\n', "\r").into_bytes())],
                2,
                &["cr.csv: line", "carriage returns"],
            ),
            a(&["identify", "--data", "cr.csv"]),
        ),
        (
            case(
                "tab-separated",
                &[],
                vec![(
                    "tabs.csv",
                    csv.lines()
                        .filter(|l| !l.starts_with('#'))
                        .map(|l| l.replace(',', "\t") + "\n")
                        .collect::<String>()
                        .into_bytes(),
                )],
                2,
                &["tabs.csv: line 1", "separated by tabs"],
            ),
            a(&["identify", "--data", "tabs.csv"]),
        ),
        (
            case(
                "no header",
                &[],
                vec![(
                    "noheader.csv",
                    rows.iter()
                        .map(|r| r.clone() + "\n")
                        .collect::<String>()
                        .into_bytes(),
                )],
                2,
                &[
                    "noheader.csv: line 1",
                    "not column names",
                    "needs a header line",
                ],
            ),
            a(&["identify", "--data", "noheader.csv"]),
        ),
        (
            case(
                "a 100 kB field",
                &[],
                vec![("long.csv", rows_of(&long_field))],
                2,
                &[
                    "long.csv: line 4, column `q1`",
                    "… (99921 more bytes)",
                    "not a number",
                ],
            ),
            a(&["identify", "--data", "long.csv"]),
        ),
        (
            case(
                "a 10 MB line",
                &[],
                vec![("longer.csv", rows_of(&long_line))],
                2,
                &["longer.csv: line 4", "longer than 1048576 bytes"],
            ),
            a(&["identify", "--data", "longer.csv"]),
        ),
        (
            case(
                "control characters",
                &[],
                vec![("ctl.csv", rows_of(&control))],
                2,
                &["ctl.csv: line", "\\u{1b}[2J"],
            ),
            a(&["identify", "--data", "ctl.csv"]),
        ),
        (
            case(
                "a tracker file given as measured data",
                &[],
                vec![],
                2,
                &[
                    "tracker.csv: line",
                    "a laser-tracker file",
                    "give it as a tracker file (tracker)",
                ],
            ),
            a(&["identify", "--data", "tracker.csv"]),
        ),
        // Calibrated machine files that do not match their record.
        (
            case(
                "leg offset edited",
                &[],
                vec![(
                    "e1.json",
                    edited(&|v| {
                        let x = v["leg_offsets_mm"][0].as_f64().unwrap();
                        v["leg_offsets_mm"][0] = (x + 5.0).into();
                    }),
                )],
                2,
                &[
                    "e1.json",
                    "does not match its calibration record",
                    "leg_offsets_mm[0]",
                ],
            ),
            a(&["compensate", "--machine", "e1.json", "--table", "out"]),
        ),
        (
            case(
                "nominal edited",
                &[],
                vec![(
                    "e2.json",
                    edited(&|v| {
                        let p = &mut v["calibration"]["nominal"]["placement"]["circular"];
                        let r = p["base_radius_mm"].as_f64().unwrap();
                        p["base_radius_mm"] = (r + 2.0).into();
                    }),
                )],
                2,
                &[
                    "e2.json",
                    "does not match its calibration record",
                    "base joint 1",
                ],
            ),
            a(&["ik", "0", "0", "750", "--machine", "e2.json"]),
        ),
        (
            case(
                "estimate edited",
                &[],
                vec![(
                    "e3.json",
                    edited(&|v| {
                        let x = v["calibration"]["estimates_mm"]["dq2"].as_f64().unwrap();
                        v["calibration"]["estimates_mm"]["dq2"] = (x + 0.5).into();
                    }),
                )],
                2,
                &["e3.json", "leg_offsets_mm[1]", "(dq2 = "],
            ),
            a(&["ik", "0", "0", "750", "--machine", "e3.json"]),
        ),
        (
            case(
                "unknown method",
                &[],
                vec![(
                    "e4.json",
                    edited(&|v| v["calibration"]["method"] = "guess".into()),
                )],
                2,
                &["e4.json", "unknown method `guess`"],
            ),
            a(&["machine", "--machine", "e4.json"]),
        ),
        (
            case(
                "unknown parameter set",
                &[],
                vec![(
                    "e5.json",
                    edited(&|v| v["calibration"]["parameter_set"] = "paper16".into()),
                )],
                2,
                &["e5.json", "unknown parameter set `paper16`"],
            ),
            a(&["machine", "--machine", "e5.json"]),
        ),
        // Flag values parsed by the door's types (clap value parsers): one
        // line naming the flag, exit 2, before anything is read.
        (
            case(
                "truth not a spec",
                &[],
                vec![],
                2,
                &["error: --truth `random:x`: ", "MAG_MM"],
            ),
            a(&["simulate", "--truth", "random:x"]),
        ),
        (
            case(
                "compensate: truth of a negative size",
                &[],
                vec![],
                2,
                &["error: --truth `random:-1`: "],
            ),
            a(&["compensate", "--data", "good.csv", "--truth", "random:-1"]),
        ),
        (
            case(
                "compensate: truth effect not JSON",
                &[],
                vec![],
                2,
                &["error: --truth-effect: "],
            ),
            a(&[
                "compensate",
                "--data",
                "good.csv",
                "--truth",
                "table2",
                "--truth-effect",
                "{oops",
            ]),
        ),
        (
            case(
                "truth effect file missing",
                &[],
                vec![],
                2,
                &["error: --truth-effect: no-effect.json"],
            ),
            a(&["simulate", "--truth-effect", "@no-effect.json"]),
        ),
        (
            case(
                "touch sphere of two numbers",
                &[],
                vec![],
                2,
                &["error: --touch-sphere-mm: expected 3 comma-separated numbers, got `1,2`"],
            ),
            a(&["simulate", "--touch-sphere-mm", "1,2"]),
        ),
        (
            case(
                "plan: touch sphere not a number",
                &[],
                vec![],
                2,
                &["error: --touch-sphere-mm: expected 3 comma-separated numbers, got `x,0,0`"],
            ),
            a(&[
                "plan",
                "--instrument",
                "touch",
                "--touch-sphere-mm",
                "x,0,0",
            ]),
        ),
        (
            case(
                "tracker frame of five numbers",
                &[],
                vec![],
                2,
                &[
                    "error: --tracker-frame-mm-rad: expected 6 comma-separated numbers, got `1,2,3,4,5`",
                ],
            ),
            a(&["simulate", "--tracker-frame-mm-rad", "1,2,3,4,5"]),
        ),
        (
            case(
                "tracker frame beyond any machine",
                &[],
                vec![],
                2,
                &["error: --tracker-frame-mm-rad: 200000 is beyond ±100000"],
            ),
            a(&["simulate", "--tracker-frame-mm-rad", "2e5,0,0,0,0,0"]),
        ),
    ];
    cases
        .into_iter()
        .map(|(mut c, args)| {
            c.args = args;
            c
        })
        .collect()
}

/// Inputs that look odd but are fine: a machine file with a byte-order
/// mark, a noise level of a nanometre (whose detectability search used to
/// grow as 1/noise^2 and take minutes).
#[test]
fn odd_but_valid_inputs_are_accepted() {
    let dir = std::env::temp_dir().join(format!("tricept-odd-valid-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bom = dir.join("bom.json");
    let mut text = "\u{feff}".to_string();
    text.push_str(tricept_kinematics::description::PAPER_MACHINE_JSON);
    std::fs::write(&bom, text).unwrap();
    let out = tricept()
        .args(["ik", "0", "0", "750", "--machine", bom.to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = tricept()
        .args([
            "detectability",
            "--length-noise-um",
            "0.001",
            "--angle-noise-arcsec",
            "0.001",
            "--json",
        ])
        .output()
        .unwrap();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v.to_string().contains("detectable_multiple"), "{v}");
    std::fs::remove_dir_all(&dir).ok();
}
