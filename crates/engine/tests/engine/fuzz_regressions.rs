//! Replays the fuzz seeds and every committed fuzz-crash input through the
//! same property checks the `cargo fuzz` targets run (`fuzz/src/checks.rs`),
//! so a fixed crash stays fixed on every `cargo test`.

#[path = "../../../../fuzz/src/checks.rs"]
mod checks;

use std::path::{Path, PathBuf};

fn inputs(target: &str) -> Vec<PathBuf> {
    let fuzz = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz");
    let mut files = Vec::new();
    for kind in ["seeds", "regressions"] {
        let Ok(dir) = std::fs::read_dir(fuzz.join(kind).join(target)) else {
            continue;
        };
        for entry in dir.flatten() {
            let path = entry.path();
            if path.is_file() && path.file_name().is_some_and(|n| n != ".keep") {
                files.push(path);
            }
        }
    }
    files.sort();
    files
}

fn replay(target: &str, check: impl Fn(&[u8])) {
    let files = inputs(target);
    assert!(
        files.iter().any(|f| f.to_string_lossy().contains("seeds")),
        "no seeds for fuzz target `{target}`"
    );
    for file in files {
        let bytes = std::fs::read(&file).unwrap();
        eprintln!("replaying {}", file.display());
        check(&bytes);
    }
}

#[test]
fn csv_reader_inputs() {
    replay("csv_reader", checks::csv_reader);
}

#[test]
fn machine_description_inputs() {
    replay("machine_description", |bytes| {
        // libFuzzer feeds `&str` targets only valid UTF-8.
        if let Ok(text) = std::str::from_utf8(bytes) {
            checks::machine_description(text);
        }
    });
}

#[test]
fn identify_inputs() {
    replay("identify", checks::identify);
}
