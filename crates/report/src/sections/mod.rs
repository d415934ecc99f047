//! The page's sections, one file each, in reading order: the header with
//! the verdict (`head`), the platform error over the workspace (`maps`),
//! the residuals against the stated noise (`residuals`), what the
//! calibration deploys (`deployed`), what was looked for and not found
//! (`looked_for`), the daily checks (`checks`), the controller files
//! (`controller`) and the sources' JSON (`blocks`). Each takes the
//! [`crate::json::Lookup`] of the sources and shows values only through
//! it.

pub mod blocks;
pub mod checks;
pub mod controller;
pub mod deployed;
pub mod head;
pub mod looked_for;
pub mod maps;
pub mod residuals;

/// The JSON pointer `/a/b/...` of keys (each escaped).
pub fn ptr(keys: &[&str]) -> String {
    keys.iter()
        .map(|k| format!("/{}", crate::json::token(k)))
        .collect()
}
