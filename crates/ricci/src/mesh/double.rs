//! The double of a surface with boundary: the mesh glued to its mirror copy along the boundary
//! (docs/notes/wave2-s6-spec6.md, "Design: boundaries through the double cover").
//!
//! For a mesh `M` with `V` vertices (`V_∂` of them on the boundary), `E` edges and `F` faces,
//! the double `D` has the `V` vertices of `M` (same ids), then one mirror vertex per interior
//! vertex (ids `V..2V − V_∂`, in increasing order of the vertex they mirror); faces `0..F` are
//! `M`'s faces, face `F + f` is the mirror of face `f` with its orientation reversed
//! (`[σa, σc, σb]` for `f = [a, b, c]`), so that `D` is closed and consistently oriented.
//! `σ` (the involution on `D`'s vertices) fixes exactly the boundary vertices of `M`; the
//! reflection of `D` it induces is orientation-reversing. `χ(D) = 2χ(M)`: every boundary loop
//! has as many vertices as edges. `D` is a closed surface of genus `2g + b − 1` when `M` is
//! connected with genus `g` and `b` boundary loops.
//!
//! A [`Mesh`] has at most one edge between two vertices, so an interior edge of `M` whose two
//! ends are on the boundary (it would appear twice in `D`) is refused with an error naming it.

use super::{Mesh, NONE};
use crate::error::{Error, Result};

/// The double of `mesh` (module docs): the closed mesh and the involution `σ` on its vertices.
/// Errors when `mesh` has no boundary, or when an interior edge joins two boundary vertices.
pub fn double_cover(mesh: &Mesh) -> Result<(Mesh, Vec<u32>)> {
    if !mesh.has_boundary() {
        return Err(Error::input(
            "the mesh has no boundary: its double would be two disjoint copies",
        ));
    }
    for e in 0..mesh.n_edges() as u32 {
        let [a, b] = mesh.edge_vertices(e);
        let (a, b) = (a.min(b), a.max(b));
        if !mesh.is_boundary_edge(e) && mesh.is_boundary_vertex(a) && mesh.is_boundary_vertex(b) {
            return Err(Error::invalid_mesh(format!(
                "edge {e} joins the boundary vertices {a} and {b} through the interior; the \
                 double would have two edges between them (split the edge or its faces first)"
            )));
        }
    }
    let sigma = double_vertices(mesh)?;
    let nd = sigma.len();
    let mut faces = mesh.faces().to_vec();
    faces.extend(
        mesh.faces()
            .iter()
            .map(|&[a, b, c]| [sigma[a as usize], sigma[c as usize], sigma[b as usize]]),
    );
    let double = Mesh::from_triangles(nd, faces)?;
    Ok((double, sigma))
}

/// The involution `σ` on the double's vertices (numbered as in the module docs), without
/// building the double (whose connectivity may then be a Δ-complex: an interior edge of `M`
/// between two boundary vertices appears twice). Errors when `mesh` has no boundary.
pub fn double_vertices(mesh: &Mesh) -> Result<Vec<u32>> {
    if !mesh.has_boundary() {
        return Err(Error::input(
            "the mesh has no boundary: its double would be two disjoint copies",
        ));
    }
    let nv = mesh.n_vertices();
    let mut sigma: Vec<u32> = (0..nv as u32).collect();
    let mut next = nv as u32;
    for v in 0..nv as u32 {
        if !mesh.is_isolated(v) && !mesh.is_boundary_vertex(v) {
            sigma[v as usize] = next;
            next += 1;
        }
    }
    sigma.resize(next as usize, NONE);
    for v in 0..nv {
        let s = sigma[v] as usize;
        if s >= nv {
            sigma[s] = v as u32;
        }
    }
    Ok(sigma)
}

/// The vertex of `M` that vertex `v` of the double is a copy of (`v` itself or `σ(v)`).
pub fn double_vertex_origin(sigma: &[u32], v: u32) -> u32 {
    v.min(sigma[v as usize])
}

/// For every edge of the double (built by [`double_cover`] from `mesh`), the edge of `mesh`
/// it is a copy of.
pub fn double_edge_origin(mesh: &Mesh, double: &Mesh, sigma: &[u32]) -> Result<Vec<u32>> {
    (0..double.n_edges() as u32)
        .map(|e| {
            let [a, b] = double
                .edge_vertices(e)
                .map(|v| double_vertex_origin(sigma, v));
            mesh.halfedge_between(a, b)
                .map(|h| mesh.he_edge(h))
                .ok_or_else(|| {
                    Error::input(format!(
                        "edge {e} of the double joins {a} and {b}, which no edge of the mesh joins"
                    ))
                })
        })
        .collect()
}
