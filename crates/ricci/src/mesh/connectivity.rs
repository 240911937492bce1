//! Half-edge connectivity of an oriented 2-manifold triangle mesh, possibly with boundary.
//!
//! Flat index arrays, no positions (see docs/DESIGN.md §2: connectivity, metric and embedding are
//! kept apart). Conventions:
//!
//! * Face `f` has vertices `faces[f] = [v0, v1, v2]` in counter-clockwise order.
//! * The three **interior half-edges** of face `f` are `h = 3f + i`, `i = 0, 1, 2`; half-edge
//!   `3f + i` goes from `v_i` to `v_{i+1}`. `next(3f+i) = 3f + (i+1)%3`.
//! * **Corners** share the numbering of interior half-edges: corner `c = 3f + i` is the corner
//!   of face `f` at vertex `v_i`; the edge opposite to it is half-edge `3f + (i+1)%3`.
//! * **Boundary half-edges** have indices `3F..3F+B`; they have no face (`face == NONE`) and
//!   their `next` runs along the boundary loop (with the surface on the right).
//! * Every vertex stores one outgoing interior half-edge; for a boundary vertex it is the one
//!   whose twin is a boundary half-edge, so that the counter-clockwise rotation
//!   `h ↦ twin(prev(h))` starting there sweeps the whole fan.

use crate::error::{Error, Result};

/// Marker for "no such element" in index arrays.
pub const NONE: u32 = u32::MAX;

/// Connectivity of a manifold, oriented triangle mesh. Build it with
/// [`Mesh::from_triangles`], which validates the input.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Mesh {
    pub(crate) n_vertices: usize,
    pub(crate) faces: Vec<[u32; 3]>,
    /// Twin of every half-edge (interior and boundary).
    pub(crate) twin: Vec<u32>,
    /// `next` of boundary half-edges, indexed by `h - 3F`.
    pub(crate) boundary_next: Vec<u32>,
    /// Origin vertex of boundary half-edges, indexed by `h - 3F`.
    pub(crate) boundary_origin: Vec<u32>,
    /// Undirected edge of every half-edge.
    pub(crate) he_edge: Vec<u32>,
    /// One half-edge per edge; the interior one for boundary edges.
    pub(crate) edge_he: Vec<u32>,
    /// One outgoing interior half-edge per vertex (see module docs); `NONE` for isolated vertices.
    pub(crate) vertex_he: Vec<u32>,
}

/// Directed half-edges `h = 3f + i` (from corner `i` of face `f` to corner `i + 1`) with their
/// undirected key `lo << 32 | hi`, in the order of key, then `h` — the order in which
/// [`Mesh::from_triangles`] pairs them and numbers the edges. A counting pass by `lo`, then
/// each vertex's few entries sorted: the order of one sort of all `(key, h)`, in linear time.
fn halfedges_by_pair(n_vertices: usize, faces: &[[u32; 3]]) -> Vec<(u64, u32)> {
    let nh = 3 * faces.len();
    let ends = |h: usize| {
        let (a, b) = (faces[h / 3][h % 3], faces[h / 3][(h % 3 + 1) % 3]);
        if a < b {
            (a, b)
        } else {
            (b, a)
        }
    };
    let mut start = vec![0usize; n_vertices + 1];
    for h in 0..nh {
        start[ends(h).0 as usize + 1] += 1;
    }
    for v in 0..n_vertices {
        start[v + 1] += start[v];
    }
    let mut keyed: Vec<(u64, u32)> = vec![(0, 0); nh];
    let mut fill = start.clone();
    for h in 0..nh {
        let (lo, hi) = ends(h);
        keyed[fill[lo as usize]] = (((lo as u64) << 32) | hi as u64, h as u32);
        fill[lo as usize] += 1;
    }
    for v in 0..n_vertices {
        keyed[start[v]..start[v + 1]].sort_unstable();
    }
    keyed
}

impl Mesh {
    /// Build the connectivity from triangles that are already known to be consistently oriented
    /// and manifold. Use [`crate::mesh::build`] to validate arbitrary input; this function still
    /// checks everything it relies on and returns an error (never panics) if the input is not
    /// a consistently oriented manifold.
    pub fn from_triangles(n_vertices: usize, faces: Vec<[u32; 3]>) -> Result<Mesh> {
        let nf = faces.len();
        if n_vertices >= NONE as usize || 3 * nf >= (NONE as usize) / 2 {
            return Err(Error::input("mesh too large for 32-bit indices"));
        }
        for (f, t) in faces.iter().enumerate() {
            for &v in t {
                if v as usize >= n_vertices {
                    return Err(Error::invalid_mesh(format!(
                        "face {f} refers to vertex {v}, but there are only {n_vertices} vertices"
                    )));
                }
            }
            if t[0] == t[1] || t[1] == t[2] || t[2] == t[0] {
                return Err(Error::invalid_mesh(format!(
                    "face {f} uses vertex {} twice",
                    if t[0] == t[1] || t[0] == t[2] {
                        t[0]
                    } else {
                        t[1]
                    }
                )));
            }
        }
        let nh_int = 3 * nf;
        let keyed = halfedges_by_pair(n_vertices, &faces);
        let origin = |h: u32| faces[h as usize / 3][h as usize % 3];
        let mut twin = vec![NONE; nh_int];
        let mut he_edge = vec![NONE; nh_int];
        let mut edge_he = Vec::with_capacity(nh_int / 2 + 1);
        let mut boundary_of: Vec<u32> = Vec::new(); // interior half-edges on the boundary
        let mut i = 0;
        while i < keyed.len() {
            let mut j = i + 1;
            while j < keyed.len() && keyed[j].0 == keyed[i].0 {
                j += 1;
            }
            let e = edge_he.len() as u32;
            let (lo, hi) = ((keyed[i].0 >> 32) as u32, keyed[i].0 as u32);
            match j - i {
                1 => {
                    let h = keyed[i].1;
                    he_edge[h as usize] = e;
                    edge_he.push(h);
                    boundary_of.push(h);
                }
                2 => {
                    let (h0, h1) = (keyed[i].1, keyed[i + 1].1);
                    if origin(h0) == origin(h1) {
                        return Err(Error::invalid_mesh(format!(
                            "faces {} and {} traverse edge ({lo}, {hi}) in the same direction \
                             (inconsistent orientation)",
                            h0 / 3,
                            h1 / 3
                        )));
                    }
                    twin[h0 as usize] = h1;
                    twin[h1 as usize] = h0;
                    he_edge[h0 as usize] = e;
                    he_edge[h1 as usize] = e;
                    edge_he.push(h0);
                }
                n => {
                    let fs: Vec<String> =
                        keyed[i..j].iter().map(|x| (x.1 / 3).to_string()).collect();
                    return Err(Error::invalid_mesh(format!(
                        "non-manifold edge ({lo}, {hi}) is shared by {n} faces ({})",
                        fs.join(", ")
                    )));
                }
            }
            i = j;
        }
        // Boundary half-edges.
        let nb = boundary_of.len();
        twin.resize(nh_int + nb, NONE);
        he_edge.resize(nh_int + nb, NONE);
        let mut boundary_origin = vec![NONE; nb];
        // Outgoing boundary half-edge per vertex (to link `next` along loops).
        let mut out_boundary = vec![NONE; n_vertices];
        for (k, &h) in boundary_of.iter().enumerate() {
            let b = (nh_int + k) as u32;
            twin[h as usize] = b;
            twin[b as usize] = h;
            he_edge[b as usize] = he_edge[h as usize];
            // b goes from tip(h) to origin(h).
            let tip = faces[h as usize / 3][(h as usize % 3 + 1) % 3];
            boundary_origin[k] = tip;
            if out_boundary[tip as usize] != NONE {
                return Err(Error::invalid_mesh(format!(
                    "non-manifold vertex {tip}: two boundary fans meet there"
                )));
            }
            out_boundary[tip as usize] = b;
        }
        let mut boundary_next = vec![NONE; nb];
        for k in 0..nb {
            let h = boundary_of[k];
            let dest = origin(h); // b = twin(h) ends at origin(h)
            boundary_next[k] = out_boundary[dest as usize];
        }
        // Vertex half-edges.
        let mut vertex_he = vec![NONE; n_vertices];
        for h in 0..nh_int as u32 {
            let v = origin(h) as usize;
            if vertex_he[v] == NONE {
                vertex_he[v] = h;
            }
        }
        for &h in &boundary_of {
            // h = u→w interior with boundary twin: it is the first outgoing half-edge of u.
            vertex_he[origin(h) as usize] = h;
        }
        let mesh = Mesh {
            n_vertices,
            faces,
            twin,
            boundary_next,
            boundary_origin,
            he_edge,
            edge_he,
            vertex_he,
        };
        mesh.check_vertex_fans()?;
        Ok(mesh)
    }

    /// Every vertex must have a single fan of faces (a disk or a half-disk).
    fn check_vertex_fans(&self) -> Result<()> {
        let mut count = vec![0u32; self.n_vertices];
        for t in &self.faces {
            for &v in t {
                count[v as usize] += 1;
            }
        }
        for (v, &n) in count.iter().enumerate() {
            if self.vertex_he[v] == NONE {
                continue;
            }
            let fan = self.vertex_faces(v as u32).take(n as usize + 1).count();
            if fan != n as usize {
                return Err(Error::invalid_mesh(format!(
                    "non-manifold vertex {v}: its {} faces form more than one fan (the surface is pinched there)",
                    n
                )));
            }
        }
        Ok(())
    }

    // ----- sizes -----
    pub fn n_vertices(&self) -> usize {
        self.n_vertices
    }
    pub fn n_faces(&self) -> usize {
        self.faces.len()
    }
    pub fn n_edges(&self) -> usize {
        self.edge_he.len()
    }
    pub fn n_halfedges(&self) -> usize {
        self.twin.len()
    }
    /// Number of interior half-edges (= number of corners) = 3F.
    pub fn n_corners(&self) -> usize {
        3 * self.faces.len()
    }
    pub fn n_boundary_halfedges(&self) -> usize {
        self.twin.len() - 3 * self.faces.len()
    }

    // ----- faces -----
    pub fn faces(&self) -> &[[u32; 3]] {
        &self.faces
    }
    pub fn face(&self, f: u32) -> [u32; 3] {
        self.faces[f as usize]
    }
    /// The three interior half-edges of face `f`.
    pub fn face_halfedges(&self, f: u32) -> [u32; 3] {
        [3 * f, 3 * f + 1, 3 * f + 2]
    }
    /// The three edges of face `f`, edge `i` opposite to vertex `i`.
    pub fn face_edges_opposite(&self, f: u32) -> [u32; 3] {
        [
            self.he_edge[(3 * f + 1) as usize],
            self.he_edge[(3 * f + 2) as usize],
            self.he_edge[(3 * f) as usize],
        ]
    }

    // ----- half-edges -----
    #[inline]
    pub fn is_boundary_halfedge(&self, h: u32) -> bool {
        h as usize >= 3 * self.faces.len()
    }
    #[inline]
    pub fn he_face(&self, h: u32) -> u32 {
        if self.is_boundary_halfedge(h) {
            NONE
        } else {
            h / 3
        }
    }
    #[inline]
    pub fn he_origin(&self, h: u32) -> u32 {
        let nh = 3 * self.faces.len();
        if (h as usize) < nh {
            self.faces[h as usize / 3][h as usize % 3]
        } else {
            self.boundary_origin[h as usize - nh]
        }
    }
    #[inline]
    pub fn he_tip(&self, h: u32) -> u32 {
        self.he_origin(self.twin[h as usize])
    }
    #[inline]
    pub fn he_twin(&self, h: u32) -> u32 {
        self.twin[h as usize]
    }
    #[inline]
    pub fn he_next(&self, h: u32) -> u32 {
        let nh = 3 * self.faces.len();
        if (h as usize) < nh {
            3 * (h / 3) + (h % 3 + 1) % 3
        } else {
            self.boundary_next[h as usize - nh]
        }
    }
    /// Previous half-edge in the same face (interior half-edges only; for boundary half-edges
    /// the previous one along the boundary loop, found by rotation).
    #[inline]
    pub fn he_prev(&self, h: u32) -> u32 {
        if !self.is_boundary_halfedge(h) {
            3 * (h / 3) + (h % 3 + 2) % 3
        } else {
            // The boundary half-edge arriving at origin(h): rotate clockwise around origin(h).
            let mut g = self.twin[h as usize]; // interior, arrives at origin(h)
            loop {
                let t = self.he_next(g); // leaves origin(h)
                let tw = self.twin[t as usize];
                if self.is_boundary_halfedge(tw) {
                    return tw;
                }
                g = tw;
            }
        }
    }
    #[inline]
    pub fn he_edge(&self, h: u32) -> u32 {
        self.he_edge[h as usize]
    }
    /// The corner opposite to interior half-edge `h` (at the vertex not on `h`).
    #[inline]
    pub fn opposite_corner(&self, h: u32) -> u32 {
        3 * (h / 3) + (h % 3 + 2) % 3
    }
    /// The interior half-edge opposite to corner `c`.
    #[inline]
    pub fn corner_opposite_halfedge(&self, c: u32) -> u32 {
        3 * (c / 3) + (c % 3 + 1) % 3
    }
    /// The vertex of corner `c`.
    #[inline]
    pub fn corner_vertex(&self, c: u32) -> u32 {
        self.faces[c as usize / 3][c as usize % 3]
    }

    // ----- edges -----
    pub fn edge_halfedge(&self, e: u32) -> u32 {
        self.edge_he[e as usize]
    }
    pub fn edge_vertices(&self, e: u32) -> [u32; 2] {
        let h = self.edge_he[e as usize];
        [self.he_origin(h), self.he_tip(h)]
    }
    pub fn is_boundary_edge(&self, e: u32) -> bool {
        self.is_boundary_halfedge(self.twin[self.edge_he[e as usize] as usize])
    }
    /// Half-edge from `a` to `b`, if the edge exists.
    pub fn halfedge_between(&self, a: u32, b: u32) -> Option<u32> {
        self.outgoing(a).find(|&h| self.he_tip(h) == b)
    }

    // ----- vertices -----
    pub fn vertex_halfedge(&self, v: u32) -> u32 {
        self.vertex_he[v as usize]
    }
    pub fn is_isolated(&self, v: u32) -> bool {
        self.vertex_he[v as usize] == NONE
    }
    pub fn is_boundary_vertex(&self, v: u32) -> bool {
        let h = self.vertex_he[v as usize];
        h != NONE && self.is_boundary_halfedge(self.twin[h as usize])
    }
    /// Outgoing half-edges of `v` in counter-clockwise order. For a boundary vertex the first is
    /// the interior half-edge along the incoming boundary and the last is the outgoing boundary
    /// half-edge, so the tips enumerate all neighbours exactly once.
    pub fn outgoing(&self, v: u32) -> Outgoing<'_> {
        let start = self.vertex_he[v as usize];
        Outgoing {
            mesh: self,
            start,
            cur: start,
            done: start == NONE,
        }
    }
    /// Neighbouring vertices in counter-clockwise order.
    pub fn vertex_neighbors(&self, v: u32) -> impl Iterator<Item = u32> + '_ {
        self.outgoing(v).map(move |h| self.he_tip(h))
    }
    /// Faces around `v` in counter-clockwise order.
    pub fn vertex_faces(&self, v: u32) -> impl Iterator<Item = u32> + '_ {
        self.outgoing(v)
            .filter(move |&h| !self.is_boundary_halfedge(h))
            .map(|h| h / 3)
    }
    /// Corners at `v` (interior outgoing half-edges = corners at their origin), counter-clockwise.
    pub fn vertex_corners(&self, v: u32) -> impl Iterator<Item = u32> + '_ {
        self.outgoing(v)
            .filter(move |&h| !self.is_boundary_halfedge(h))
    }
    /// Number of edges at `v`.
    pub fn valence(&self, v: u32) -> usize {
        self.outgoing(v).count()
    }

    // ----- boundary -----
    /// Boundary loops as vertex cycles, each oriented with the surface on its left (the
    /// direction of the faces' own half-edges). Loops are ordered by their smallest vertex.
    pub fn boundary_loops(&self) -> Vec<Vec<u32>> {
        self.boundary_loop_halfedges()
            .into_iter()
            .map(|l| l.into_iter().map(|h| self.he_origin(h)).collect())
            .collect()
    }
    /// Boundary loops as sequences of interior half-edges (surface on the left).
    pub fn boundary_loop_halfedges(&self) -> Vec<Vec<u32>> {
        let nh = 3 * self.faces.len();
        let nb = self.twin.len() - nh;
        let mut seen = vec![false; nb];
        let mut loops = Vec::new();
        for k in 0..nb {
            if seen[k] {
                continue;
            }
            // Walk the boundary half-edges backwards so the interior twins come out in order.
            let mut lp = Vec::new();
            let mut b = (nh + k) as u32;
            while !seen[b as usize - nh] {
                seen[b as usize - nh] = true;
                lp.push(self.twin[b as usize]);
                b = self.he_prev(b);
            }
            // Rotate so the loop starts at its smallest vertex.
            let (imin, _) = lp
                .iter()
                .enumerate()
                .min_by_key(|(_, &h)| self.he_origin(h))
                .unwrap_or((0, &0));
            lp.rotate_left(imin);
            loops.push(lp);
        }
        loops.sort_by_key(|l| l.first().map(|&h| self.he_origin(h)).unwrap_or(NONE));
        loops
    }
    pub fn has_boundary(&self) -> bool {
        self.twin.len() > 3 * self.faces.len()
    }
}

/// Iterator over the outgoing half-edges of a vertex, counter-clockwise.
pub struct Outgoing<'a> {
    mesh: &'a Mesh,
    start: u32,
    cur: u32,
    done: bool,
}

impl Iterator for Outgoing<'_> {
    type Item = u32;
    fn next(&mut self) -> Option<u32> {
        if self.done {
            return None;
        }
        let h = self.cur;
        let m = self.mesh;
        if m.is_boundary_halfedge(h) {
            self.done = true;
        } else {
            let n = m.twin[m.he_prev(h) as usize];
            if n == self.start {
                self.done = true;
            }
            self.cur = n;
        }
        Some(h)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tetra() -> Mesh {
        Mesh::from_triangles(4, vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]]).unwrap()
    }

    #[test]
    fn closed_tetrahedron() {
        let m = tetra();
        assert_eq!((m.n_vertices(), m.n_edges(), m.n_faces()), (4, 6, 4));
        assert!(!m.has_boundary());
        for v in 0..4 {
            assert_eq!(m.valence(v), 3);
            assert_eq!(m.vertex_faces(v).count(), 3);
        }
        for h in 0..m.n_halfedges() as u32 {
            assert_eq!(m.he_twin(m.he_twin(h)), h);
            assert_eq!(m.he_origin(m.he_twin(h)), m.he_tip(h));
            assert_eq!(m.he_prev(m.he_next(h)), h);
        }
    }

    #[test]
    fn open_fan_and_boundary_loop() {
        // A hexagon fan around vertex 0 with one wedge missing: 5 faces.
        let faces = (1..6).map(|i| [0, i, i + 1]).collect();
        let m = Mesh::from_triangles(7, faces).unwrap();
        assert_eq!(m.n_edges(), 11);
        assert!(m.is_boundary_vertex(0));
        let nb: Vec<u32> = m.vertex_neighbors(0).collect();
        assert_eq!(nb, vec![1, 2, 3, 4, 5, 6]);
        let loops = m.boundary_loops();
        assert_eq!(loops, vec![vec![0, 1, 2, 3, 4, 5, 6]]);
        for h in 0..m.n_halfedges() as u32 {
            assert_eq!(m.he_twin(m.he_twin(h)), h);
            assert_eq!(m.he_prev(m.he_next(h)), h);
            assert_eq!(m.he_tip(h), m.he_origin(m.he_next(h)));
        }
    }

    #[test]
    fn refuses_pinched_vertex_and_non_manifold_edge() {
        // Two triangles touching at vertex 0 only.
        let e = Mesh::from_triangles(5, vec![[0, 1, 2], [0, 3, 4]]).unwrap_err();
        assert!(e.to_string().contains("non-manifold vertex 0"), "{e}");
        let e = Mesh::from_triangles(5, vec![[0, 1, 2], [1, 0, 3], [0, 1, 4]]).unwrap_err();
        assert!(e.to_string().contains("non-manifold edge (0, 1)"), "{e}");
    }
}
