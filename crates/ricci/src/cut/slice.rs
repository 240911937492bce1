//! Slicing a mesh open along a set of edges, and reading the boundary of the result.
//!
//! Every vertex is split into one copy per wedge between consecutive cut edges around it (an
//! interior vertex with `k ≥ 1` cut edges gets `k` copies, a boundary vertex `k + 1`); faces keep
//! their ids and their interior half-edge numbering `3f + i`, so a half-edge of the cut mesh is
//! the same half-edge of the input on the same face.

use crate::error::{Error, Result};
use crate::mesh::{Mesh, NONE};

/// Slice `mesh` open along the edges with `cut[e]`; returns the cut mesh and, for each of its
/// vertices, the vertex of `mesh` it is a copy of.
pub fn slice(mesh: &Mesh, cut: &[bool]) -> Result<(Mesh, Vec<u32>)> {
    if cut.len() != mesh.n_edges() {
        return Err(Error::input(format!(
            "{} cut flags given for {} edges",
            cut.len(),
            mesh.n_edges()
        )));
    }
    let nc = mesh.n_corners();
    let mut corner_vertex = vec![NONE; nc];
    let mut origin: Vec<u32> = Vec::with_capacity(mesh.n_vertices() + 64);
    let mut hs: Vec<u32> = Vec::new();
    for v in 0..mesh.n_vertices() as u32 {
        hs.clear();
        hs.extend(mesh.outgoing(v));
        if hs.is_empty() {
            origin.push(v);
            continue;
        }
        let is_cut = |h: u32| cut[mesh.he_edge(h) as usize];
        let boundary = mesh.is_boundary_vertex(v);
        if !boundary {
            if let Some(k) = hs.iter().position(|&h| is_cut(h)) {
                hs.rotate_left(k);
            }
        }
        let base = origin.len() as u32;
        let mut copy: u32 = 0;
        let mut first = true;
        for &h in hs.iter() {
            if mesh.is_boundary_halfedge(h) {
                continue;
            }
            // The first wedge of an interior vertex starts at its first cut edge; boundary
            // edges of a boundary vertex are never cut.
            let starts_wedge = if boundary {
                !mesh.is_boundary_edge(mesh.he_edge(h))
            } else {
                !first
            };
            if is_cut(h) && starts_wedge {
                copy += 1;
            }
            first = false;
            corner_vertex[h as usize] = base + copy;
        }
        for _ in 0..=copy {
            origin.push(v);
        }
    }
    let faces: Vec<[u32; 3]> = (0..mesh.n_faces())
        .map(|f| {
            [
                corner_vertex[3 * f],
                corner_vertex[3 * f + 1],
                corner_vertex[3 * f + 2],
            ]
        })
        .collect();
    let cut_mesh = Mesh::from_triangles(origin.len(), faces)?;
    Ok((cut_mesh, origin))
}

/// A maximal piece of the cut-mesh boundary between two polygon corners.
#[derive(Debug, Clone)]
pub(crate) struct RawSide {
    /// Interior half-edges of the cut mesh along the side (disk on the left), in order.
    pub halfedges: Vec<u32>,
    /// Vertices of the input mesh along the side, from corner to corner.
    pub vertices: Vec<u32>,
    /// The path (or boundary loop, as `n_paths + k`) whose edges the side runs along.
    pub source: u32,
}

/// Read the single boundary loop of the cut mesh and split it at the vertices that are copies
/// of a polygon corner (`corner[v]` for input vertex `v`). `edge_source[e]` says which path (or
/// boundary loop) input edge `e` belongs to; a side must run along one source only.
pub(crate) fn read_sides(
    mesh: &Mesh,
    cut_mesh: &Mesh,
    origin: &[u32],
    corner: &[bool],
    edge_source: &[u32],
) -> Result<Vec<RawSide>> {
    let loops = cut_mesh.boundary_loop_halfedges();
    if loops.len() != 1 {
        return Err(Error::topology(format!(
            "the cut mesh has {} boundary loops instead of one",
            loops.len()
        )));
    }
    let mut lp = loops.into_iter().next().unwrap_or_default();
    let is_corner = |h: u32| corner[origin[cut_mesh.he_origin(h) as usize] as usize];
    if let Some(k) = lp.iter().position(|&h| is_corner(h)) {
        lp.rotate_left(k);
    }
    let mut sides: Vec<RawSide> = Vec::new();
    for (i, &h) in lp.iter().enumerate() {
        let start_new = i == 0 || is_corner(h);
        let e = mesh.he_edge(h);
        let src = edge_source[e as usize];
        if src == NONE {
            return Err(Error::topology(format!(
                "the cut mesh boundary runs along edge {e}, which is neither cut nor on the boundary"
            )));
        }
        if start_new {
            sides.push(RawSide {
                halfedges: Vec::new(),
                vertices: vec![origin[cut_mesh.he_origin(h) as usize]],
                source: src,
            });
        }
        let s = sides.last_mut().expect("a side was started");
        if s.source != src {
            return Err(Error::topology(format!(
                "a side of the cut polygon runs along two different cut paths (at edge {e})"
            )));
        }
        s.halfedges.push(h);
        s.vertices.push(origin[cut_mesh.he_tip(h) as usize]);
    }
    Ok(sides)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slicing_a_torus_along_meridian_and_longitude_gives_a_square() {
        let (n, m) = (6u32, 5u32);
        let id = |i: u32, j: u32| (i % n) * m + (j % m);
        let mut f = Vec::new();
        for i in 0..n {
            for j in 0..m {
                f.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                f.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        let mesh = Mesh::from_triangles((n * m) as usize, f).unwrap();
        let mut cut = vec![false; mesh.n_edges()];
        for i in 0..n {
            cut[mesh.he_edge(mesh.halfedge_between(id(i, 0), id(i + 1, 0)).unwrap()) as usize] =
                true;
        }
        for j in 0..m {
            cut[mesh.he_edge(mesh.halfedge_between(id(0, j), id(0, j + 1)).unwrap()) as usize] =
                true;
        }
        let (cm, origin) = slice(&mesh, &cut).unwrap();
        // (n+1)(m+1) grid vertices, one boundary loop of 2(n+m) edges, χ = 1.
        assert_eq!(cm.n_vertices(), ((n + 1) * (m + 1)) as usize);
        assert_eq!(origin.len(), cm.n_vertices());
        let t = crate::mesh::topology(&cm);
        assert_eq!(t.euler_characteristic(), 1);
        let loops = cm.boundary_loops();
        assert_eq!(loops.len(), 1);
        assert_eq!(loops[0].len(), (2 * (n + m)) as usize);
        // The base vertex (0,0) has 4 copies.
        assert_eq!(origin.iter().filter(|&&v| v == 0).count(), 4);
    }
}
