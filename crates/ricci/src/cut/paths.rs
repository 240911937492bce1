//! Closed edge paths: conversion from vertex sequences, right push-off, algebraic intersection
//! numbers (they work when the paths share edges).
//!
//! **Push-off.** A closed path `P = h₀ h₁ … h_{n−1}` (half-edges) is pushed off to its right into
//! a dual path `P'`: at every vertex `v` between `h_j` and `h_{j+1}`, `P'` turns through the
//! faces on the right of `P`, i.e. counter-clockwise around `v` from `twin(h_j)` to `h_{j+1}`,
//! crossing every edge strictly between them (from the face on its right to the face on its
//! left). `P'` is homotopic to `P` and never runs along an edge, so
//!
//! **Intersection.** `P·Q` = signed number of crossings of `P'` with `Q`: a crossing of the edge
//! `e` (outgoing from `v`) counts `−1` for every traversal of `e` by `Q` away from `v` and `+1`
//! for every traversal towards `v`. This is the standard convention: `P·Q = +1` when `(P', Q)`
//! is a positively oriented frame; on a torus cut along `a b a⁻¹ b⁻¹` (disk on the left),
//! `a·b = +1`.

use super::CutError;
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use std::collections::HashMap;

/// The half-edges of a vertex path `v₀ v₁ … v_k` (consecutive vertices must be adjacent).
pub fn halfedge_path(mesh: &Mesh, vertices: &[u32]) -> Result<Vec<u32>> {
    let mut out = Vec::with_capacity(vertices.len().saturating_sub(1));
    for w in vertices.windows(2) {
        for &v in w {
            if v as usize >= mesh.n_vertices() {
                return Err(CutError::PathVertexMissing {
                    vertex: v,
                    n_vertices: mesh.n_vertices(),
                }
                .into());
            }
        }
        let h = mesh
            .halfedge_between(w[0], w[1])
            .ok_or(CutError::PathNotAnEdge {
                from: w[0],
                to: w[1],
            })?;
        out.push(h);
    }
    Ok(out)
}

/// Check that the half-edges form a closed path.
pub fn check_closed(mesh: &Mesh, p: &[u32]) -> Result<()> {
    if p.is_empty() {
        return Err(Error::input("the path is empty"));
    }
    for (j, &h) in p.iter().enumerate() {
        if h as usize >= mesh.n_halfedges() {
            return Err(Error::input(format!("half-edge {h} does not exist")));
        }
        let n = p[(j + 1) % p.len()];
        if n as usize >= mesh.n_halfedges() || mesh.he_tip(h) != mesh.he_origin(n) {
            return Err(Error::input(format!(
                "the path is not closed: half-edge {h} ends at vertex {} but the next one starts at vertex {}",
                mesh.he_tip(h),
                mesh.he_origin(n.min(mesh.n_halfedges() as u32 - 1))
            )));
        }
    }
    Ok(())
}

/// Counter-clockwise successor of the outgoing half-edge `h` around its origin, if any.
#[inline]
fn ccw(mesh: &Mesh, h: u32) -> Option<u32> {
    if mesh.is_boundary_halfedge(h) {
        None
    } else {
        Some(mesh.he_twin(mesh.he_prev(h)))
    }
}

/// The edges crossed by the right push-off of the closed path `p`, in order, each given as the
/// half-edge `e` leaving the path vertex: the push-off crosses from `face(twin(e))` into
/// `face(e)`. Fails if the path runs along the boundary with the surface on its left (the
/// right side is then outside the surface).
pub fn right_pushoff_crossings(mesh: &Mesh, p: &[u32]) -> Result<Vec<u32>> {
    check_closed(mesh, p)?;
    let mut out = Vec::new();
    for j in 0..p.len() {
        let h_in = p[j];
        let h_out = p[(j + 1) % p.len()];
        let v = mesh.he_tip(h_in);
        let stop = mesh.he_twin(h_in);
        let mut e = stop;
        let mut guard = 0usize;
        loop {
            e = ccw(mesh, e).ok_or_else(|| {
                Error::input(format!(
                    "the path runs along the boundary at vertex {v} with the surface on its left; \
                     it cannot be pushed off to the right"
                ))
            })?;
            if e == h_out {
                break;
            }
            if e == stop {
                return Err(CutError::PathNotSimple { vertex: v }.into());
            }
            out.push(e);
            guard += 1;
            if guard > mesh.n_halfedges() {
                return Err(Error::input("corrupt rotation around a path vertex"));
            }
        }
    }
    Ok(out)
}

/// Net number of traversals of each edge by `q`, counted along the edge's own half-edge
/// (`Mesh::edge_halfedge`).
fn edge_flow(mesh: &Mesh, q: &[u32]) -> HashMap<u32, i64> {
    let mut flow = HashMap::new();
    for &h in q {
        let e = mesh.he_edge(h);
        let s = if mesh.edge_halfedge(e) == h { 1 } else { -1 };
        *flow.entry(e).or_insert(0) += s;
    }
    flow
}

/// Algebraic intersection number `p·q` of two closed edge paths (see the module docs). The
/// paths may share vertices and edges; `p·q = −q·p`.
pub fn intersection_number(mesh: &Mesh, p: &[u32], q: &[u32]) -> Result<i64> {
    check_closed(mesh, q)?;
    let crossings = right_pushoff_crossings(mesh, p)?;
    let flow = edge_flow(mesh, q);
    let mut s = 0i64;
    for e in crossings {
        let edge = mesh.he_edge(e);
        if let Some(&f) = flow.get(&edge) {
            let dir = if mesh.edge_halfedge(edge) == e { 1 } else { -1 };
            s -= f * dir;
        }
    }
    Ok(s)
}

/// The matrix of intersection numbers `loops[i]·loops[j]`.
pub fn intersection_matrix(mesh: &Mesh, loops: &[Vec<u32>]) -> Result<Vec<Vec<i64>>> {
    let mut m = vec![vec![0i64; loops.len()]; loops.len()];
    for i in 0..loops.len() {
        for j in 0..loops.len() {
            if i != j {
                m[i][j] = intersection_number(mesh, &loops[i], &loops[j])?;
            }
        }
    }
    Ok(m)
}

/// The standard symplectic matrix of `g` handles in the basis `a₁, b₁, …, a_g, b_g`:
/// `a_i·b_i = 1`, `b_i·a_i = −1`, all other entries 0.
pub fn standard_symplectic(g: usize) -> Vec<Vec<i64>> {
    let mut m = vec![vec![0i64; 2 * g]; 2 * g];
    for i in 0..g {
        m[2 * i][2 * i + 1] = 1;
        m[2 * i + 1][2 * i] = -1;
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    fn torus(n: u32, m: u32) -> (Mesh, impl Fn(u32, u32) -> u32) {
        let id = move |i: u32, j: u32| (i % n) * m + (j % m);
        let mut f = Vec::new();
        for i in 0..n {
            for j in 0..m {
                f.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                f.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        (Mesh::from_triangles((n * m) as usize, f).unwrap(), id)
    }

    #[test]
    fn torus_cycles_intersect_once_and_antisymmetrically() {
        let (mesh, id) = torus(7, 6);
        let vs = |f: &dyn Fn(u32) -> u32, k: u32| -> Vec<u32> { (0..=k).map(f).collect() };
        let a = halfedge_path(&mesh, &vs(&|i| id(i, 0), 7)).unwrap();
        let b = halfedge_path(&mesh, &vs(&|j| id(0, j), 6)).unwrap();
        let ab = intersection_number(&mesh, &a, &b).unwrap();
        let ba = intersection_number(&mesh, &b, &a).unwrap();
        assert_eq!(ab.abs(), 1);
        assert_eq!(ab, -ba);
        // Self-intersection of a simple closed curve is 0; parallel copies don't meet.
        assert_eq!(intersection_number(&mesh, &a, &a).unwrap(), 0);
        let a2 = halfedge_path(&mesh, &vs(&|i| id(i, 3), 7)).unwrap();
        assert_eq!(intersection_number(&mesh, &a, &a2).unwrap(), 0);
        // A diagonal (1,1) curve meets a once and b once, with the signs of a and b.
        let d = halfedge_path(&mesh, &vs(&|i| id(i, i), 42)).unwrap();
        let da = intersection_number(&mesh, &d, &a).unwrap();
        let db = intersection_number(&mesh, &d, &b).unwrap();
        // d ~ 6a + 7b in homology: d·a = 7 b·a, d·b = 6 a·b.
        assert_eq!(da, 7 * ba);
        assert_eq!(db, 6 * ab);
        // Homology invariance: twice around a is homologous to 2a.
        let aa: Vec<u32> = a.iter().chain(a.iter()).copied().collect();
        assert_eq!(intersection_number(&mesh, &aa, &b).unwrap(), 2 * ab);
        // A contractible loop (boundary of a face) meets nothing algebraically.
        let f = mesh.face_halfedges(10).to_vec();
        assert_eq!(intersection_number(&mesh, &f, &a).unwrap(), 0);
        assert_eq!(intersection_number(&mesh, &a, &f).unwrap(), 0);
    }
}
