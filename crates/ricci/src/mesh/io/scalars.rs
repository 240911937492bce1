//! Scalar values per vertex or per face read from a file: whitespace- or comma-separated
//! numbers (`#` starts a comment), or an array in a JSON file (a METRIC.json's `u` or `K`, or
//! any key). Used by `ricci render --scalar FILE[.json:KEY]`; the caller decides whether the
//! count is the mesh's vertices or faces.

use crate::error::{Error, Result};
use std::path::Path;

/// Numbers read from a scalar file, and the name they go by (the JSON key, or the file's stem).
#[derive(Clone, Debug, PartialEq)]
pub struct ScalarFile {
    /// The values in file order; a JSON `null` is NaN (a missing value).
    pub values: Vec<f64>,
    /// The JSON key the values came from, or the file name without its extension.
    pub name: String,
}

/// Reads the scalar file at `path`. A `.json` file gives the array under `key`, or without a
/// key the first of `u` and `K` present; any other file is read as text numbers.
pub fn read_scalar_file(path: &Path, key: Option<&str>) -> Result<ScalarFile> {
    let text =
        std::fs::read_to_string(path).map_err(|e| Error::io(path.display().to_string(), e))?;
    let is_json = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"));
    if is_json {
        json_values(path, &text, key)
    } else {
        text_values(path, &text)
    }
}

fn json_values(path: &Path, text: &str, key: Option<&str>) -> Result<ScalarFile> {
    let v: serde_json::Value = serde_json::from_str(text)
        .map_err(|e| Error::input(format!("{}: not valid JSON: {e}", path.display())))?;
    let keys: Vec<&str> = match key {
        Some(k) => vec![k],
        None => vec!["u", "K"],
    };
    let (k, arr) = keys
        .iter()
        .find_map(|k| v.get(*k).and_then(|a| a.as_array()).map(|a| (*k, a)))
        .ok_or_else(|| {
            Error::input(format!(
                "{}: no array under the key {}",
                path.display(),
                keys.join(" or ")
            ))
        })?;
    let values = arr
        .iter()
        .enumerate()
        .map(|(i, x)| {
            x.as_f64()
                .or(if x.is_null() { Some(f64::NAN) } else { None })
                .ok_or_else(|| {
                    Error::input(format!(
                        "{}: entry {i} of \"{k}\" is not a number",
                        path.display()
                    ))
                })
        })
        .collect::<Result<Vec<f64>>>()?;
    Ok(ScalarFile {
        values,
        name: k.to_string(),
    })
}

fn text_values(path: &Path, text: &str) -> Result<ScalarFile> {
    let mut values = Vec::new();
    for (ln, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("");
        for tok in line
            .split(|c: char| c.is_whitespace() || c == ',')
            .filter(|t| !t.is_empty())
        {
            let x: f64 = tok.parse().map_err(|_| {
                Error::input(format!(
                    "{}, line {}: '{tok}' is not a number",
                    path.display(),
                    ln + 1
                ))
            })?;
            values.push(x);
        }
    }
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_default();
    Ok(ScalarFile { values, name })
}
