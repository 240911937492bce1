//! The integration tests of a crate are one binary (`tests/all.rs`, `autotests = false` in its
//! `Cargo.toml`): one compile and link of the library's generic code instead of one per file
//! (docs/notes/wave2-s12-ci12.md: the per-file binaries were 58 % of the CI build). A new
//! `tests/*.rs` is then compiled only once `all.rs` names it; this check says when it does not.
//! Shared by both crates' `all.rs` (`#[path]` from `ricci-cli`).

use std::path::Path;

/// The two lines that make `tests/{stem}.rs` a module of `all.rs`. `#[path]` (rather than a
/// bare `mod`) keeps the file's own `mod ricci_meshes;` resolving beside it in `tests/`.
fn declaration(stem: &str) -> String {
    format!("#[path = \"{stem}.rs\"]\nmod {stem};")
}

/// Panics, naming every `tests/*.rs` of the crate at `manifest_dir` that `all_rs` (the text of
/// its `tests/all.rs`) does not declare, with the lines to add.
pub fn assert_all_rs_declares_every_test_file(manifest_dir: &str, all_rs: &str) {
    let tests = Path::new(manifest_dir).join("tests");
    let mut stems: Vec<String> = std::fs::read_dir(&tests)
        .unwrap_or_else(|e| panic!("cannot list {}: {e}", tests.display()))
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "rs"))
        .filter_map(|p| Some(p.file_stem()?.to_str()?.to_string()))
        .filter(|s| s != "all")
        .collect();
    stems.sort();
    assert!(
        stems.len() > 1,
        "only {stems:?} found in {}",
        tests.display()
    );
    let missing: Vec<String> = stems
        .iter()
        .filter(|s| !all_rs.contains(&declaration(s)))
        .map(|s| {
            format!(
                "{}/{s}.rs is not compiled (autotests = false): add these two lines to {}/all.rs:\n{}",
                tests.display(),
                tests.display(),
                declaration(s)
            )
        })
        .collect();
    assert!(missing.is_empty(), "{}", missing.join("\n"));
}
