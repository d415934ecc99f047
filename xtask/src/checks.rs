//! `cargo xtask one-build` and `cargo xtask msrv`: the two build-level
//! promises of the README, checked by `.ci/run`.
//!
//! - **One build.** `cargo xtask encoder-study`, `cargo test --workspace`,
//!   `cargo run -p tricept-cli` and `cargo run -p tricept-example-downstream`
//!   compile every third-party crate once: each builds the same artifact (the
//!   same file name, which carries cargo's hash of the crate's features,
//!   profile and dependencies) for every third-party crate they share. The
//!   check builds each target with `--message-format=json` and compares the
//!   artifacts; after `cargo test --workspace` it compiles only the few
//!   workspace crates the tests did not build. The features are unified by
//!   `crates/workspace-hack`.
//! - **MSRV.** The workspace's `rust-version` is at least the
//!   `rust-version` of every locked dependency (from `cargo metadata
//!   --locked`), and the README states it.

use std::collections::BTreeMap;
use std::process::Command;

use serde_json::Value;

/// The builds of the README's commands (the `cargo run` targets are built,
/// not run).
const BUILDS: [&[&str]; 4] = [
    &["build", "-p", "xtask"],
    &["test", "--workspace", "--no-run"],
    &["build", "-p", "tricept-cli"],
    &["build", "-p", "tricept-example-downstream"],
];

/// The workspace root (xtask's parent directory).
const ROOT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/..");

/// Runs the cargo that runs this xtask, in the workspace root, with
/// `args` (and `--locked`); returns its stdout, or its stderr as the error.
fn cargo(args: &[&str]) -> Result<Vec<u8>, String> {
    let command = format!("cargo {}", args.join(" "));
    let output = Command::new(std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into()))
        .current_dir(ROOT)
        .args(args)
        .arg("--locked")
        .output()
        .map_err(|e| format!("{command}: {e}"))?;
    if !output.status.success() {
        return Err(format!(
            "{command} --locked failed:\n{}",
            String::from_utf8_lossy(&output.stderr)
        ));
    }
    Ok(output.stdout)
}

/// One compiled third-party target: its package and target, and cargo's
/// artifact files with the features it was built with.
type Unit = (String, String);
#[derive(Debug, PartialEq)]
struct Artifact {
    filenames: Vec<String>,
    features: Vec<String>,
}

/// The third-party artifacts one build produces (compiling what is stale),
/// and how many of them it had to compile.
fn artifacts(args: &[&str]) -> Result<(BTreeMap<Unit, Artifact>, usize), String> {
    let stdout = cargo(&[args, &["--message-format=json"]].concat())?;
    let mut units = BTreeMap::new();
    let mut compiled = 0;
    for line in String::from_utf8_lossy(&stdout).lines() {
        let Ok(message) = serde_json::from_str::<Value>(line) else {
            continue;
        };
        if message["reason"] != "compiler-artifact" {
            continue;
        }
        let package = message["package_id"].as_str().unwrap_or_default();
        if package.starts_with("path+") {
            continue;
        }
        let strings = |key: &str| -> Vec<String> {
            message[key]
                .as_array()
                .map(|a| {
                    a.iter()
                        .filter_map(|v| v.as_str().map(String::from))
                        .collect()
                })
                .unwrap_or_default()
        };
        let target = message["target"]["name"].as_str().unwrap_or_default();
        let name = package.rsplit('#').next().unwrap_or(package);
        if message["fresh"] == false {
            compiled += 1;
        }
        let mut filenames = strings("filenames");
        filenames.sort();
        units.insert(
            (name.to_string(), target.to_string()),
            Artifact {
                filenames,
                features: strings("features"),
            },
        );
    }
    Ok((units, compiled))
}

/// `cargo xtask one-build`.
pub fn one_build() -> Result<(), String> {
    let mut seen: BTreeMap<Unit, (Artifact, String)> = BTreeMap::new();
    let mut differ = Vec::new();
    for args in BUILDS {
        let command = format!("cargo {}", args.join(" "));
        let (units, compiled) = artifacts(args)?;
        println!(
            "{command}: {} third-party artifacts, {compiled} compiled now",
            units.len()
        );
        for (unit, artifact) in units {
            match seen.get(&unit) {
                Some((first, by)) if *first != artifact => differ.push(format!(
                    "{} ({}): `{by}` builds it with features [{}], `{command}` with [{}]",
                    unit.0,
                    unit.1,
                    first.features.join(", "),
                    artifact.features.join(", ")
                )),
                Some(_) => {}
                None => {
                    seen.insert(unit, (artifact, command.clone()));
                }
            }
        }
    }
    if differ.is_empty() {
        println!(
            "one build: the {} third-party artifacts are the same in every build",
            seen.len()
        );
        return Ok(());
    }
    Err(format!(
        "{} third-party crates are compiled more than once (a crate above them with \
         different features, or its dependencies', is rebuilt too); add the union of \
         their features to crates/workspace-hack/Cargo.toml:\n  {}",
        differ.len(),
        differ.join("\n  ")
    ))
}

/// A `rust-version` as comparable numbers (`1.89` and `1.89.0` are equal).
fn version(text: &str) -> Result<Vec<u64>, String> {
    let mut parts = text
        .split('.')
        .map(|p| {
            p.parse::<u64>()
                .map_err(|_| format!("rust-version `{text}` is not a version"))
        })
        .collect::<Result<Vec<_>, _>>()?;
    parts.resize(3, 0);
    Ok(parts)
}

/// `cargo xtask msrv`.
pub fn msrv() -> Result<(), String> {
    let stdout = cargo(&["metadata", "--format-version", "1"])?;
    let metadata: Value =
        serde_json::from_slice(&stdout).map_err(|e| format!("cargo metadata: not JSON: {e}"))?;
    let members: Vec<&str> = metadata["workspace_members"]
        .as_array()
        .map(|a| a.iter().filter_map(Value::as_str).collect())
        .unwrap_or_default();
    let packages = metadata["packages"].as_array().cloned().unwrap_or_default();
    let mut workspace: Option<(Vec<u64>, String)> = None;
    let mut needed: Option<(Vec<u64>, String, String)> = None;
    let mut undeclared = 0;
    for package in &packages {
        let id = package["id"].as_str().unwrap_or_default();
        let name = package["name"].as_str().unwrap_or_default();
        let declared = package["rust_version"].as_str();
        if members.contains(&id) {
            let Some(text) = declared else {
                return Err(format!("workspace member {name} declares no rust-version"));
            };
            let v = version(text)?;
            match &workspace {
                Some((w, first)) if *w != v => {
                    return Err(format!(
                        "workspace members disagree on rust-version: {first} and {text} ({name})"
                    ));
                }
                Some(_) => {}
                None => workspace = Some((v, text.to_string())),
            }
            continue;
        }
        let Some(text) = declared else {
            undeclared += 1;
            continue;
        };
        let v = version(text)?;
        if needed.as_ref().is_none_or(|(n, _, _)| v > *n) {
            let label = format!("{name} {}", package["version"].as_str().unwrap_or("?"));
            needed = Some((v, text.to_string(), label));
        }
    }
    let (workspace, stated) = workspace.ok_or("no workspace member in cargo metadata")?;
    let locked = packages.len() - members.len();
    if let Some((n, text, by)) = &needed {
        if workspace < *n {
            return Err(format!(
                "Cargo.toml says rust-version = \"{stated}\", but the locked {by} needs {text}"
            ));
        }
        println!(
            "msrv: rust-version {stated} >= {text}, the highest of the {} locked dependencies \
             that declare one ({by}); {undeclared} declare none",
            locked - undeclared
        );
    }
    let readme = std::fs::read_to_string(format!("{ROOT}/README.md"))
        .map_err(|e| format!("README.md: {e}"))?;
    if !readme.contains(&format!("Rust {stated} or newer")) {
        return Err(format!(
            "README.md does not say \"Rust {stated} or newer\" (Cargo.toml's rust-version)"
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::version;

    #[test]
    fn versions_compare_by_number() {
        assert_eq!(version("1.89").unwrap(), version("1.89.0").unwrap());
        assert!(version("1.100").unwrap() > version("1.89.1").unwrap());
        assert!(version("1.x").is_err());
    }
}
