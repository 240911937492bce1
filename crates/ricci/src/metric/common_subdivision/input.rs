//! The input triangulation of an overlay: a simplicial [`Mesh`], or a Δ-complex given as an
//! [`IntrinsicTriangulation`] ([`DeltaInput`]: two edges between the same vertices allowed, the
//! input metric's Delaunay triangulation `T_iso` of the three-way overlay on camelhead's double).
//!
//! The overlay identifies a traced input edge by its two end vertices; in a Δ-complex that is
//! not enough: [`InputComplex::halfedges_between`] then gives all the candidates, and the
//! tracer tells them apart by their **side** — where the traced edge leaves its first vertex,
//! in the cyclic order of the input edges there ([`super::sides`]) — and checks that the edge
//! found has the log Penner coordinate the strip's Ptolemy development recomputes (the flips
//! keep the hyperbolic structure, so it is the input edge's own `λ` up to rounding; two σ-mirror
//! edges of a double have the same `λ`, so `λ` alone cannot choose). Loops (an edge from a
//! vertex to itself, a face with a repeated vertex) are refused: a corner is found by its
//! vertex.
use super::Tri;
use crate::error::{Error, Result};
use crate::mesh::{Mesh, NONE};
use std::collections::HashMap;

/// The edge chosen by side among several between the same vertices must have a log Penner
/// coordinate within this of the nearest one to the traced `λ` (else refused: side and `λ`
/// disagree).
pub(super) const LAMBDA_TIE: f64 = 1e-6;

/// The input half-edges from one vertex to another.
pub(super) enum Between<'a> {
    /// Not adjacent.
    None,
    One(u32),
    /// Several (a Δ-complex): told apart by side.
    Many(&'a [u32]),
}

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
    /// The half-edges from `a` to `b` (module docs).
    fn halfedges_between(&self, a: u32, b: u32) -> Between<'_>;
    /// The log Penner coordinate of edge `e` (NaN where the input has none: a [`Mesh`]).
    fn edge_lambda(&self, e: u32) -> f64;
    /// The half-edges leaving vertex `a`, `h, twin(prev(h)), …` (the rotation the overlay's
    /// faces turn in); an error at a boundary vertex or where the input has no rotation.
    fn rotation(&self, a: u32) -> Result<Vec<u32>>;
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
    fn halfedges_between(&self, a: u32, b: u32) -> Between<'_> {
        match self.halfedge_between(a, b) {
            Some(h) => Between::One(h),
            None => Between::None,
        }
    }
    fn edge_lambda(&self, _e: u32) -> f64 {
        f64::NAN
    }
    fn rotation(&self, a: u32) -> Result<Vec<u32>> {
        // A simplicial mesh never has two edges between the same vertices: not needed.
        Err(Error::numerical(format!(
            "no rotation at vertex {a} of a simplicial input"
        )))
    }
}

/// A Δ-complex input: an intrinsic triangulation (its half-edges, edge ids and `λ`) with an
/// index of its half-edges by end vertices.
pub(super) struct DeltaInput<'a> {
    tri: &'a Tri,
    by_ends: HashMap<(u32, u32), Vec<u32>>,
    /// A half-edge leaving every vertex (`NONE` for a vertex without one).
    out: Vec<u32>,
}

impl<'a> DeltaInput<'a> {
    /// `tri` as an overlay's input; loops are refused (module docs).
    pub(super) fn new(tri: &'a Tri) -> Result<DeltaInput<'a>> {
        let mut by_ends: HashMap<(u32, u32), Vec<u32>> = HashMap::new();
        let mut out = vec![NONE; tri.n_vertices];
        for h in 0..tri.n_halfedges() as u32 {
            let (a, b) = (tri.origin[h as usize], tri.tip(h));
            if a == b {
                return Err(Error::numerical(format!(
                    "edge {} of the triangulation is a loop at vertex {a}",
                    tri.edge[h as usize]
                )));
            }
            by_ends.entry((a, b)).or_default().push(h);
            out[a as usize] = h;
        }
        Ok(DeltaInput { tri, by_ends, out })
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
    fn halfedges_between(&self, a: u32, b: u32) -> Between<'_> {
        match self.by_ends.get(&(a, b)).map(|hs| &hs[..]) {
            None | Some([]) => Between::None,
            Some([h]) => Between::One(*h),
            Some(hs) => Between::Many(hs),
        }
    }
    fn edge_lambda(&self, e: u32) -> f64 {
        self.tri.lambda[e as usize]
    }
    fn rotation(&self, a: u32) -> Result<Vec<u32>> {
        let tri = self.tri;
        let h0 = self.out[a as usize];
        if h0 == NONE {
            return Err(Error::numerical(format!("vertex {a} has no edge")));
        }
        let mut hs = vec![h0];
        let mut h = h0;
        for _ in 0..tri.n_halfedges() {
            h = tri.twin[Tri::prev(h) as usize];
            if h == NONE {
                return Err(Error::numerical(format!(
                    "vertex {a} is on the boundary of the input"
                )));
            }
            if h == h0 {
                return Ok(hs);
            }
            hs.push(h);
        }
        Err(Error::numerical(format!(
            "the half-edges around vertex {a} do not close up"
        )))
    }
}
