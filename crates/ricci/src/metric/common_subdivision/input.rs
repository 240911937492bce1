//! The input triangulation of an overlay: a simplicial [`Mesh`], or a Δ-complex given as an
//! [`IntrinsicTriangulation`] ([`DeltaInput`]: two edges between the same vertices allowed, the
//! input metric's Delaunay triangulation `T_iso` of the three-way overlay on camelhead's double).
//!
//! The overlay identifies a traced input edge by its two end vertices; in a Δ-complex that is
//! not enough, so [`InputComplex::halfedge_between_near`] also takes the edge's log Penner
//! coordinate in the input decoration, which the strip's Ptolemy development computes for the
//! traced edge (the flips keep the hyperbolic structure, so it is the input edge's own `λ` up
//! to rounding): among several input edges between the same two vertices the one with the
//! nearest `λ` is taken, and a tie (two of them within [`LAMBDA_TIE`]) is refused. Loops (an
//! edge from a vertex to itself, a face with a repeated vertex) are refused: a corner is found
//! by its vertex.

use super::Tri;
use crate::error::{Error, Result};
use crate::mesh::{Mesh, NONE};
use std::collections::HashMap;

/// Two input edges between the same vertices whose log Penner coordinates differ by less than
/// this are not told apart by their `λ` (refused).
pub(super) const LAMBDA_TIE: f64 = 1e-6;

/// What the overlay needs of its input triangulation (half-edges `3f + i` of face `f`).
pub(super) trait InputComplex {
    fn n_vertices(&self) -> usize;
    fn n_edges(&self) -> usize;
    fn n_corners(&self) -> usize;
    fn face(&self, f: u32) -> [u32; 3];
    /// The face of half-edge `h`, `NONE` on the boundary (or for `h = NONE`).
    fn he_face(&self, h: u32) -> u32;
    fn he_twin(&self, h: u32) -> u32;
    fn he_edge(&self, h: u32) -> u32;
    fn edge_halfedge(&self, e: u32) -> u32;
    fn edge_vertices(&self, e: u32) -> [u32; 2];
    /// The half-edge from `a` to `b`; among several (a Δ-complex), the one whose edge's log
    /// Penner coordinate is nearest `lambda` (module docs).
    fn halfedge_between_near(&self, a: u32, b: u32, lambda: f64) -> Result<Option<u32>>;
}

impl InputComplex for Mesh {
    fn n_vertices(&self) -> usize {
        Mesh::n_vertices(self)
    }
    fn n_edges(&self) -> usize {
        Mesh::n_edges(self)
    }
    fn n_corners(&self) -> usize {
        Mesh::n_corners(self)
    }
    fn face(&self, f: u32) -> [u32; 3] {
        Mesh::face(self, f)
    }
    fn he_face(&self, h: u32) -> u32 {
        Mesh::he_face(self, h)
    }
    fn he_twin(&self, h: u32) -> u32 {
        Mesh::he_twin(self, h)
    }
    fn he_edge(&self, h: u32) -> u32 {
        Mesh::he_edge(self, h)
    }
    fn edge_halfedge(&self, e: u32) -> u32 {
        Mesh::edge_halfedge(self, e)
    }
    fn edge_vertices(&self, e: u32) -> [u32; 2] {
        Mesh::edge_vertices(self, e)
    }
    fn halfedge_between_near(&self, a: u32, b: u32, _lambda: f64) -> Result<Option<u32>> {
        Ok(self.halfedge_between(a, b))
    }
}

/// A Δ-complex input: an intrinsic triangulation (its half-edges, edge ids and `λ`) with an
/// index of its half-edges by end vertices.
pub(super) struct DeltaInput<'a> {
    tri: &'a Tri,
    by_ends: HashMap<(u32, u32), Vec<u32>>,
}

impl<'a> DeltaInput<'a> {
    /// `tri` as an overlay's input; loops are refused (module docs).
    pub(super) fn new(tri: &'a Tri) -> Result<DeltaInput<'a>> {
        let mut by_ends: HashMap<(u32, u32), Vec<u32>> = HashMap::new();
        for h in 0..tri.n_halfedges() as u32 {
            let (a, b) = (tri.origin[h as usize], tri.tip(h));
            if a == b {
                return Err(Error::numerical(format!(
                    "edge {} of the triangulation is a loop at vertex {a}",
                    tri.edge[h as usize]
                )));
            }
            by_ends.entry((a, b)).or_default().push(h);
        }
        Ok(DeltaInput { tri, by_ends })
    }

    /// Pairs of vertices joined by more than one edge.
    pub(super) fn multi_edges(&self) -> usize {
        self.by_ends
            .iter()
            .filter(|((a, b), hs)| a < b && hs.len() > 1)
            .count()
    }
}

impl InputComplex for DeltaInput<'_> {
    fn n_vertices(&self) -> usize {
        self.tri.n_vertices
    }
    fn n_edges(&self) -> usize {
        self.tri.n_edges()
    }
    fn n_corners(&self) -> usize {
        self.tri.n_halfedges()
    }
    fn face(&self, f: u32) -> [u32; 3] {
        self.tri.face(f)
    }
    fn he_face(&self, h: u32) -> u32 {
        if h == NONE {
            NONE
        } else {
            h / 3
        }
    }
    fn he_twin(&self, h: u32) -> u32 {
        self.tri.twin[h as usize]
    }
    fn he_edge(&self, h: u32) -> u32 {
        self.tri.edge[h as usize]
    }
    fn edge_halfedge(&self, e: u32) -> u32 {
        self.tri.edge_he[e as usize]
    }
    fn edge_vertices(&self, e: u32) -> [u32; 2] {
        self.tri.edge_vertices(e)
    }
    fn halfedge_between_near(&self, a: u32, b: u32, lambda: f64) -> Result<Option<u32>> {
        let Some(hs) = self.by_ends.get(&(a, b)) else {
            return Ok(None);
        };
        if hs.len() == 1 {
            return Ok(Some(hs[0]));
        }
        let dist = |h: u32| (self.tri.lambda[self.tri.edge[h as usize] as usize] - lambda).abs();
        let mut sorted = hs.clone();
        sorted.sort_by(|&x, &y| dist(x).total_cmp(&dist(y)));
        if !(dist(sorted[1]) - dist(sorted[0]) > LAMBDA_TIE) {
            return Err(Error::numerical(format!(
                "{} input edges join vertices {a} and {b} with log Penner coordinates within \
                 {LAMBDA_TIE:e} of the traced one ({lambda}); they are not told apart",
                hs.len()
            )));
        }
        Ok(Some(sorted[0]))
    }
}
