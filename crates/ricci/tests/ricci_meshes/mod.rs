//! `$RICCI_MESHES`, shared by the test files of both crates (`mod ricci_meshes;`, with a
//! `#[path]` from outside this folder).

/// `$RICCI_MESHES` as a folder. Cargo runs test binaries in the crate's folder, so a relative
/// path (the README's `../shared/meshes`) is taken from the workspace root when it does not
/// exist from the current directory.
pub fn ricci_meshes() -> Option<std::path::PathBuf> {
    let d = std::path::PathBuf::from(std::env::var_os("RICCI_MESHES")?);
    if d.is_relative() && !d.is_dir() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
        return Some(root.join(d));
    }
    Some(d)
}
