//! Mesh file formats: OBJ, OFF, PLY (ascii, binary little/big endian), STL (ascii, binary).
//!
//! Readers produce a [`PolygonSoup`](super::PolygonSoup) with source lines for messages;
//! [`read_surface`] validates it into a [`Surface`](super::Surface).

use super::{build_surface, BuildReport, Surface};
use crate::error::{Error, Result};
use std::path::Path;

/// Read and validate a mesh file; the format is chosen by extension.
pub fn read_surface(path: &Path) -> Result<(Surface, BuildReport)> {
    let name = path.display().to_string();
    Err(Error::input(format!(
        "{name}: no mesh readers are implemented yet"
    )))
    .and_then(|s| build_surface(s).map_err(|e: Error| e.in_file(&name)))
}
