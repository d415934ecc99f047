//! JSON inputs read with a size bound: [`read_json_text`].
//!
//! Machine files, histories, features, true errors, plausibility tables
//! and effect files are small (a calibrated machine file is tens of
//! kilobytes, a history of ten years of daily checks a few megabytes). A
//! path to a device or a runaway file (`--machine /dev/zero`) must not
//! make a verb read until the memory is exhausted: past
//! [`MAX_JSON_BYTES`] the read stops with an error that says so.

use std::io::Read;
use std::path::Path;

/// The largest JSON input any verb reads, bytes (64 MiB).
pub const MAX_JSON_BYTES: u64 = 64 << 20;

/// The text of a JSON input file, at most [`MAX_JSON_BYTES`] long: a
/// longer file (or an endless device) is an `InvalidData` error that names
/// the bound, after reading one byte past it.
///
/// # Example
/// ```
/// let e = tricept_data::bounded::read_json_text(std::path::Path::new("/dev/zero")).unwrap_err();
/// assert!(e.to_string().contains("64 MiB"), "{e}");
/// ```
pub fn read_json_text(path: &Path) -> std::io::Result<String> {
    let mut text = String::new();
    std::fs::File::open(path)?
        .take(MAX_JSON_BYTES + 1)
        .read_to_string(&mut text)?;
    if text.len() as u64 > MAX_JSON_BYTES {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!(
                "larger than {} MiB: not a JSON input of tricept (a machine file, a history, features, errors or effects)",
                MAX_JSON_BYTES >> 20
            ),
        ));
    }
    Ok(text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_at_the_bound_is_read_and_one_byte_more_is_refused() {
        let dir = std::env::temp_dir().join(format!("tricept-bounded-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("big.json");
        let mut bytes = vec![b' '; MAX_JSON_BYTES as usize];
        std::fs::write(&path, &bytes).unwrap();
        assert_eq!(read_json_text(&path).unwrap().len() as u64, MAX_JSON_BYTES);
        bytes.push(b' ');
        std::fs::write(&path, &bytes).unwrap();
        let e = read_json_text(&path).unwrap_err();
        assert_eq!(e.kind(), std::io::ErrorKind::InvalidData);
        std::fs::remove_dir_all(&dir).ok();
    }
}
