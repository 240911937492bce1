//! Mesh file formats: OBJ, OFF, PLY (ascii, binary little/big endian), STL (ascii, binary).
//!
//! Readers are hand-written so that every error names the line (text) or byte offset
//! (binary) at fault; they never panic, whatever the bytes. Each produces a
//! [`PolygonSoup`] with 1-based source lines for vertices and polygons; [`read_surface`]
//! then validates it with [`build_surface`] into a [`Surface`] and a [`BuildReport`].
//! The readers' errors are [`ReadError`]s: the sentence the user sees, the place (file, line,
//! byte) and the record at fault (vertex, face, …) as data; they convert into
//! [`Error::Parse`] with the same sentence.
//! The byte-slice entry points ([`parse_obj`], [`parse_off`], [`parse_ply`], [`parse_stl`])
//! serve tests and fuzzing.
//!
//! Writers take any [`std::io::Write`]; ascii numbers use Rust's shortest round-trip
//! formatting, so a written file reads back to the same `f64` bit patterns.
//! [`write_surface`] picks the format by extension and writes atomically.

mod error;
mod obj;
mod off;
mod ply;
pub mod scalars;
mod stl;
pub(crate) mod text;
pub mod uv_match;

pub use error::{ReadError, ReadResult, Record};
pub use obj::{parse_obj, write_obj};
pub use off::{parse_off, write_off};
pub use ply::{parse_ply, write_ply};
pub use stl::{parse_stl, write_stl};

use super::{build_surface, BuildReport, PolygonSoup, Surface};
use crate::error::{Error, Result};
use std::path::Path;

/// A mesh file format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Format {
    Obj,
    Off,
    Ply,
    Stl,
}

/// How numbers are stored, for formats that have both flavours (PLY, STL).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Encoding {
    Ascii,
    /// Binary little endian (the default: compact and exact for `f64` in PLY).
    #[default]
    Binary,
}

impl Format {
    /// The format of a file name's extension (case-insensitive), if it is one we know.
    pub fn from_extension(ext: &str) -> Option<Format> {
        match ext.to_ascii_lowercase().as_str() {
            "obj" => Some(Format::Obj),
            "off" => Some(Format::Off),
            "ply" => Some(Format::Ply),
            "stl" => Some(Format::Stl),
            _ => None,
        }
    }

    /// The format of a path, or an error naming the path and the formats we know.
    pub fn from_path(path: &Path) -> Result<Format> {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_string())
            .unwrap_or_default();
        Format::from_extension(&ext).ok_or_else(|| {
            Error::input(format!(
                "{}: unknown mesh format {}; expected a file ending in .obj, .off, .ply or .stl",
                path.display(),
                if ext.is_empty() {
                    "(no extension)".to_string()
                } else {
                    format!("'.{ext}'")
                }
            ))
        })
    }

    /// Lower-case name, as in the file extension.
    pub fn name(self) -> &'static str {
        match self {
            Format::Obj => "obj",
            Format::Off => "off",
            Format::Ply => "ply",
            Format::Stl => "stl",
        }
    }
}

/// Parse a file held in memory into a polygon soup (no validation beyond the syntax).
pub fn parse(data: &[u8], format: Format) -> Result<PolygonSoup> {
    Ok(parse_soup(data, format)?)
}

/// Like [`parse`], with the reader's own error ([`ReadError`]: place and record as data).
pub fn parse_soup(data: &[u8], format: Format) -> ReadResult<PolygonSoup> {
    match format {
        Format::Obj => parse_obj(data),
        Format::Off => parse_off(data),
        Format::Ply => parse_ply(data),
        Format::Stl => parse_stl(data),
    }
}

/// Read a mesh file into a polygon soup; the format is chosen by extension. Errors carry
/// the file name.
pub fn read_soup(path: &Path) -> Result<PolygonSoup> {
    let name = path.display().to_string();
    let format = Format::from_path(path)?;
    let data = std::fs::read(path).map_err(|e| Error::io(&name, e))?;
    parse(&data, format).map_err(|e| e.in_file(&name))
}

/// Read and validate a mesh file; the format is chosen by extension (case-insensitive).
pub fn read_surface(path: &Path) -> Result<(Surface, BuildReport)> {
    let name = path.display().to_string();
    let soup = read_soup(path)?;
    build_surface(soup).map_err(|e| e.in_file(&name))
}

/// Write a surface in the given format to any writer.
pub fn write_to<W: std::io::Write>(
    w: W,
    s: &Surface,
    format: Format,
    encoding: Encoding,
) -> Result<()> {
    let binary = encoding == Encoding::Binary;
    match format {
        Format::Obj => write_obj(w, s),
        Format::Off => write_off(w, s),
        Format::Ply => write_ply(w, s, binary),
        Format::Stl => write_stl(w, s, binary),
    }
}

/// Write a surface to a file; the format is chosen by extension (PLY and STL are written
/// binary). The file is written atomically: to a temporary file in the same directory, then
/// renamed, so nothing half-written is left behind on error.
pub fn write_surface(path: &Path, s: &Surface) -> Result<()> {
    write_surface_as(path, s, Format::from_path(path)?, Encoding::default())
}

/// Like [`write_surface`] with an explicit format and encoding.
pub fn write_surface_as(
    path: &Path,
    s: &Surface,
    format: Format,
    encoding: Encoding,
) -> Result<()> {
    let name = path.display().to_string();
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let file_name = path
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_else(|| "mesh".into());
    let tmp = dir.join(format!(".{file_name}.{}.tmp", std::process::id()));
    let result = (|| -> Result<()> {
        let f = std::fs::File::create(&tmp).map_err(|e| Error::io(tmp.display().to_string(), e))?;
        let mut w = std::io::BufWriter::new(f);
        write_to(&mut w, s, format, encoding).map_err(|e| match e {
            Error::Io { source, .. } => Error::io(&name, source),
            other => other,
        })?;
        let f = w
            .into_inner()
            .map_err(|e| Error::io(&name, e.into_error()))?;
        f.sync_all().map_err(|e| Error::io(&name, e))?;
        std::fs::rename(&tmp, path).map_err(|e| Error::io(&name, e))
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Writers refuse coordinates that no reader would accept back.
pub(crate) fn check_finite(s: &Surface) -> Result<()> {
    if let Some(i) = s
        .positions
        .iter()
        .position(|p| p.iter().any(|x| !x.is_finite()))
    {
        return Err(Error::input(format!(
            "vertex {i} has a non-finite coordinate; refusing to write it"
        )));
    }
    if let Some(uv) = &s.uvs {
        if let Some(i) = uv.iter().position(|p| p.iter().any(|x| !x.is_finite())) {
            return Err(Error::input(format!(
                "vertex {i} has a non-finite texture coordinate; refusing to write it"
            )));
        }
    }
    Ok(())
}
