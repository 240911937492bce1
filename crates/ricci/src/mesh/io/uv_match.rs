//! Texture coordinates of a mesh read from a UV file (an OBJ with `vt`, or a planar layout)
//! whose faces match the mesh's face by face — what `ricci layout` and `ricci param` write
//! (the input's faces with seams as extra `vt`), or a file with the mesh's own per-corner `vt`.
//! Used by `ricci render --uv` and by anyone who wants a map back on the mesh it was made for.

use super::read_soup;
use crate::error::{Error, Result};
use crate::mesh::{build_surface, Surface};
use std::path::Path;

/// Texture coordinates found for a mesh: one per vertex when every vertex has a single UV,
/// else one per face corner (`3 f + i`), as a map with seams needs.
#[derive(Clone, Debug, PartialEq)]
pub enum MatchedUvs {
    /// One UV per vertex of the mesh.
    PerVertex(Vec<[f64; 2]>),
    /// One UV per face corner, `3 f + i`.
    PerCorner(Vec<[f64; 2]>),
}

/// Whether `path` is an OBJ file whose every face corner has a `vt`.
pub fn has_corner_uvs(path: &Path) -> bool {
    let is_obj = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("obj"));
    is_obj
        && read_soup(path)
            .map(|s| s.corner_uvs.is_some())
            .unwrap_or(false)
}

/// Texture coordinates for `mesh` from a UV file whose faces match it face by face: its `vt`
/// (or, for a planar mesh without `vt`, its x and y) at the corner with the same position,
/// or at the same corner when positions differ (a layout written with planar positions).
/// The surface of a UV file whose faces differ from the mesh's but which carries 3D
/// positions of its own (not a flat layout) and texture coordinates: `ricci layout` writes
/// the UVs on the triangulation it laid out (refined near the cut), with that triangulation's
/// positions on the input surface. `None` when the file has the mesh's face count (the
/// usual case) or is flat.
pub fn uv_file_surface(path: &Path, mesh: &Surface) -> Result<Option<Surface>> {
    let soup = read_soup(path)?;
    let has_uv = soup.corner_uvs.is_some() || soup.uvs.is_some();
    let (u, _) = build_surface(soup)?;
    if u.mesh.n_faces() == mesh.mesh.n_faces() || !has_uv {
        return Ok(None);
    }
    let d = u.diagonal().max(f64::MIN_POSITIVE);
    let flat = u.positions.iter().all(|p| p[2].abs() <= 1e-9 * d);
    // The same surface: the same area (a refinement or common subdivision has the input's
    // area exactly; a piece of the surface or another surface does not).
    let (a0, a1) = (mesh.area(), u.area());
    let same = (a1 - a0).abs() <= 1e-6 * a0.max(f64::MIN_POSITIVE);
    Ok((!flat && same).then_some(u))
}

/// Texture coordinates for `mesh` read from the UV file at `path`, whose faces must be the
/// mesh's faces in the same order (a layout's or `ricci param`'s uv.obj): per vertex when every
/// vertex of `mesh` gets one UV, else per corner (a map with seams). The UV file's `vt` are
/// taken per vertex, else per corner, else a planar file's x and y; a corner of the UV file
/// is matched to the mesh's corner with the same position (to 1e-9 of the diagonal), or to the
/// same corner when no position matches (a layout written with planar positions).
pub fn uvs_from_file(path: &Path, mesh: &Surface) -> Result<MatchedUvs> {
    let soup = read_soup(path)?;
    let (in_polygons, in_corner_uvs) = (soup.polygons.clone(), soup.corner_uvs.clone());
    let (u, report) = build_surface(soup)?;
    let (nf, unf) = (mesh.mesh.n_faces(), u.mesh.n_faces());
    if nf != unf {
        return Err(Error::input(format!(
            "{}: {unf} faces, but the mesh has {nf}; the UV file must have the same faces in the same order",
            path.display()
        )));
    }
    let planar = {
        let d = u.diagonal().max(f64::MIN_POSITIVE);
        u.positions.iter().all(|p| p[2].abs() <= 1e-9 * d)
    };
    // One UV per corner of the UV file's faces: its per-vertex `vt`, else its per-corner `vt`
    // (a layout of a cut surface has seams: `f v/vt` with several `vt` per vertex), else x, y.
    let per_vertex = |coords: &[[f64; 2]]| -> Vec<[f64; 2]> {
        u.mesh
            .faces()
            .iter()
            .flat_map(|t| t.map(|v| coords[v as usize]))
            .collect()
    };
    let ucorner: Vec<[f64; 2]> = match (&u.uvs, &in_corner_uvs, planar) {
        (Some(uv), _, _) => per_vertex(uv),
        (None, Some(cuv), _) => {
            let mut start = Vec::with_capacity(in_polygons.len());
            let mut acc = 0usize;
            for p in &in_polygons {
                start.push(acc);
                acc += p.len();
            }
            let mut out = Vec::with_capacity(3 * unf);
            for (f, t) in u.mesh.faces().iter().enumerate() {
                let p = report.face_origin[f] as usize;
                for &v in t {
                    let vin = report.vertex_origin[v as usize];
                    let k = in_polygons[p]
                        .iter()
                        .position(|&w| w == vin)
                        .ok_or_else(|| {
                            Error::input(format!(
                                "{}: face {f} lost track of its corners",
                                path.display()
                            ))
                        })?;
                    out.push(cuv[start[p] + k]);
                }
            }
            out
        }
        (None, None, true) => {
            let xy: Vec<[f64; 2]> = u.positions.iter().map(|p| [p[0], p[1]]).collect();
            per_vertex(&xy)
        }
        (None, None, false) => {
            return Err(Error::input(format!(
                "{}: no texture coordinates (vt lines) and not a planar layout",
                path.display()
            )))
        }
    };
    let tol = 1e-9 * mesh.diagonal().max(f64::MIN_POSITIVE);
    let same = |a: [f64; 3], b: [f64; 3]| (0..3).all(|k| (a[k] - b[k]).abs() <= tol);
    let mf = mesh.mesh.faces();
    let uf = u.mesh.faces();
    let mut corner = Vec::with_capacity(3 * nf);
    let mut matched_positions = 0usize;
    for f in 0..nf {
        let (mt, ut) = (mf[f], uf[f]);
        for i in 0..3 {
            let p = mesh.positions[mt[i] as usize];
            let j = (0..3).find(|&j| same(u.positions[ut[j] as usize], p));
            if j.is_some() {
                matched_positions += 1;
            }
            corner.push(ucorner[3 * f + j.unwrap_or(i)]);
        }
    }
    if matched_positions != 0 && matched_positions != 3 * nf {
        return Err(Error::input(format!(
            "{}: only {matched_positions} of {} corners have the position of the mesh's corner; the faces do not match",
            path.display(),
            3 * nf
        )));
    }
    // Per vertex when every vertex has one UV.
    let mut per_vertex: Vec<Option<[f64; 2]>> = vec![None; mesh.positions.len()];
    let mut consistent = true;
    for (c, uv) in corner.iter().enumerate() {
        let v = mf[c / 3][c % 3] as usize;
        match per_vertex[v] {
            None => per_vertex[v] = Some(*uv),
            Some(old) if old != *uv => {
                consistent = false;
                break;
            }
            _ => {}
        }
    }
    Ok(if consistent {
        MatchedUvs::PerVertex(
            per_vertex
                .into_iter()
                .map(|x| x.unwrap_or([0.0; 2]))
                .collect(),
        )
    } else {
        MatchedUvs::PerCorner(corner)
    })
}
