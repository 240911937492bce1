//! The hot loop of Ricci flow: from variables `u` to edge lengths, corner angles, curvature and
//! the sparse Hessian `H = ∂K/∂u`, generic over the background geometry and the length law
//! (paper 001 §V Step 3, Appendix D; docs/DESIGN.md §3).
//!
//! Angles use the half-angle form of the cosine law, `tan²(θ_i/2) = s(σ−l_j)s(σ−l_k) /
//! (s(σ)s(σ−l_i))`, from which `sin θ = 2t/(1+t²)` and `cos θ = (1−t²)/(1+t²)` follow without
//! further trigonometry. The Hessian is assembled per face by the chain rule
//! `∂θ/∂u = (∂θ/∂l)(∂l/∂u)` with the derivative cosine law
//! `∂θ_i/∂l_i = s(l_i)/(s(l_j)s(l_k) sin θ_i)`, `∂θ_i/∂l_j = −(∂θ_i/∂l_i) cos θ_k`, and
//! `∂K_i/∂u_j = −Σ_faces ∂θ_i/∂u_j`. Degenerate faces (a triangle inequality violated; the
//! angles take the continuous extension 0, 0, π) contribute nothing to the Hessian.

#![allow(clippy::needless_range_loop)]

use super::geometry::Background;
use super::scheme::Law;
use crate::mesh::{Mesh, NONE};
use std::f64::consts::PI;

/// Flat copies of the connectivity the kernel needs.
#[derive(Debug, Clone)]
pub struct MeshData {
    pub faces: Vec<[u32; 3]>,
    /// Edge opposite each corner of each face.
    pub face_edges: Vec<[u32; 3]>,
    /// For the edge opposite corner m: `true` when `edges[e][0]` is the face's vertex m+2
    /// (so the derivative pair is swapped relative to the face's order m+1, m+2).
    pub face_edge_flip: Vec<[bool; 3]>,
    pub edges: Vec<[u32; 2]>,
    pub boundary_vertex: Vec<bool>,
    pub isolated_vertex: Vec<bool>,
}

impl MeshData {
    pub fn new(mesh: &Mesh) -> MeshData {
        let nf = mesh.n_faces();
        let edges: Vec<[u32; 2]> = (0..mesh.n_edges() as u32)
            .map(|e| mesh.edge_vertices(e))
            .collect();
        let mut face_edges = Vec::with_capacity(nf);
        let mut face_edge_flip = Vec::with_capacity(nf);
        for f in 0..nf as u32 {
            let t = mesh.face(f);
            let fe = mesh.face_edges_opposite(f);
            let mut flip = [false; 3];
            for m in 0..3 {
                flip[m] = edges[fe[m] as usize][0] != t[(m + 1) % 3];
            }
            face_edges.push(fe);
            face_edge_flip.push(flip);
        }
        MeshData {
            faces: mesh.faces().to_vec(),
            face_edges,
            face_edge_flip,
            edges,
            boundary_vertex: (0..mesh.n_vertices() as u32)
                .map(|v| mesh.is_boundary_vertex(v))
                .collect(),
            isolated_vertex: (0..mesh.n_vertices() as u32)
                .map(|v| mesh.is_isolated(v))
                .collect(),
        }
    }
    pub fn n_vertices(&self) -> usize {
        self.boundary_vertex.len()
    }
    pub fn n_edges(&self) -> usize {
        self.edges.len()
    }
    pub fn n_faces(&self) -> usize {
        self.faces.len()
    }
    /// `2π` inside, `π` on the boundary, 0 for isolated vertices: `K_i = base_i − Σθ`.
    pub fn curvature_base(&self, v: usize) -> f64 {
        if self.isolated_vertex[v] {
            0.0
        } else if self.boundary_vertex[v] {
            PI
        } else {
            2.0 * PI
        }
    }
}

/// Lengths and `∂l/∂u` of every edge; returns false if some length does not exist.
pub fn edge_pass<B: Background, L: Law>(
    eta: &[f64],
    edges: &[[u32; 2]],
    u: &[f64],
    vertex_data: &mut [[f64; 3]],
    lengths: &mut [f64],
    derivatives: &mut [[f64; 2]],
) -> bool {
    for (d, &x) in vertex_data.iter_mut().zip(u) {
        *d = L::vertex::<B>(x);
    }
    let mut ok = true;
    for (e, &[a, b]) in edges.iter().enumerate() {
        let (l, da, db) = L::edge::<B>(eta[e], vertex_data[a as usize], vertex_data[b as usize]);
        ok &= l.is_finite() && l > 0.0 && da.is_finite() && db.is_finite();
        lengths[e] = l;
        derivatives[e] = [da, db];
    }
    ok
}

/// Corner angles of a triangle with sides `l` (side i opposite corner i) and `tan(θ_i/2)`.
/// Returns `degenerate = true` when a triangle inequality fails (continuous extension).
#[inline]
pub fn triangle_angles<B: Background>(l: [f64; 3]) -> ([f64; 3], [f64; 3], bool) {
    let sig = 0.5 * (l[0] + l[1] + l[2]);
    let d = [sig - l[0], sig - l[1], sig - l[2]];
    if d[0] <= 0.0 || d[1] <= 0.0 || d[2] <= 0.0 {
        let mut th = [0.0; 3];
        // The side that is at least the sum of the others gets π.
        let i = if d[0] <= 0.0 {
            0
        } else if d[1] <= 0.0 {
            1
        } else {
            2
        };
        th[i] = PI;
        return (th, [0.0; 3], true);
    }
    let s0 = B::s(sig);
    let sd = [B::s(d[0]), B::s(d[1]), B::s(d[2])];
    let mut th = [0.0; 3];
    let mut t = [0.0; 3];
    if s0 > 0.0 && sd.iter().all(|&x| x > 0.0) {
        for i in 0..3 {
            let (j, k) = ((i + 1) % 3, (i + 2) % 3);
            t[i] = (sd[j] * sd[k] / (s0 * sd[i])).sqrt();
            th[i] = 2.0 * t[i].atan();
        }
    } else {
        // Spherical triangles with perimeter ≥ 2π.
        for i in 0..3 {
            let (j, k) = ((i + 1) % 3, (i + 2) % 3);
            th[i] = B::angle_cosine_law(l[i], l[j], l[k]);
            t[i] = (0.5 * th[i]).tan();
        }
    }
    (th, t, false)
}

/// Corner angles of a triangle and their derivatives `d[i][j] = ∂θ_i/∂l_j` (zero for
/// degenerate triangles).
#[inline]
pub fn angle_derivatives<B: Background>(l: [f64; 3]) -> ([f64; 3], [[f64; 3]; 3], bool) {
    let (th, t, deg) = triangle_angles::<B>(l);
    let mut d = [[0.0; 3]; 3];
    if deg {
        return (th, d, true);
    }
    let sl = [B::s(l[0]), B::s(l[1]), B::s(l[2])];
    let mut cos = [0.0; 3];
    let mut sin = [0.0; 3];
    for i in 0..3 {
        let t2 = t[i] * t[i];
        sin[i] = 2.0 * t[i] / (1.0 + t2);
        cos[i] = (1.0 - t2) / (1.0 + t2);
    }
    for i in 0..3 {
        let (j, k) = ((i + 1) % 3, (i + 2) % 3);
        let a = sl[i] / (sl[j] * sl[k] * sin[i]);
        d[i][i] = a;
        d[i][j] = -a * cos[k];
        d[i][k] = -a * cos[j];
    }
    (th, d, false)
}

/// Scratch buffers of one evaluation.
#[derive(Debug, Clone, Default)]
pub struct Workspace {
    pub vertex_data: Vec<[f64; 3]>,
    pub lengths: Vec<f64>,
    pub dlengths: Vec<[f64; 2]>,
    pub angles: Vec<f64>,
    pub curvature: Vec<f64>,
    /// Faces with a violated triangle inequality at the last evaluation.
    pub degenerate_faces: usize,
    /// Background area of the metric at the last evaluation.
    pub area: f64,
}

impl Workspace {
    pub fn new(md: &MeshData) -> Workspace {
        Workspace {
            vertex_data: vec![[0.0; 3]; md.n_vertices()],
            lengths: vec![0.0; md.n_edges()],
            dlengths: vec![[0.0; 2]; md.n_edges()],
            angles: vec![0.0; 3 * md.n_faces()],
            curvature: vec![0.0; md.n_vertices()],
            degenerate_faces: 0,
            area: 0.0,
        }
    }
}

/// Lower-triangular CSC pattern of the Hessian restricted to the free vertices.
#[derive(Debug, Clone)]
pub struct HessianPattern {
    /// Free index of every vertex (NONE if the vertex is fixed).
    pub free_index: Vec<u32>,
    /// Vertex of every free index.
    pub free_vertex: Vec<u32>,
    pub col_ptr: Vec<u32>,
    pub row_idx: Vec<u32>,
    /// Slot of the diagonal entry of each vertex (NONE if fixed).
    pub diag_slot: Vec<u32>,
    /// Slot of the off-diagonal entry of each edge (NONE if an end is fixed).
    pub edge_slot: Vec<u32>,
}

/// The pattern as the lower triangle of a symmetric matrix in CSC, for
/// [`crate::numeric::sparse::SymmetricSolver::new`].
impl<'a> From<&'a HessianPattern> for crate::numeric::sparse::LowerCsc<'a> {
    fn from(p: &'a HessianPattern) -> Self {
        crate::numeric::sparse::LowerCsc {
            n: p.n(),
            col_ptr: &p.col_ptr,
            row_idx: &p.row_idx,
        }
    }
}

impl HessianPattern {
    /// Pattern over the vertices with `fixed[v] == false`.
    pub fn new(md: &MeshData, fixed: &[bool]) -> HessianPattern {
        let nv = md.n_vertices();
        let mut free_index = vec![NONE; nv];
        let mut free_vertex = Vec::new();
        for v in 0..nv {
            if !fixed[v] {
                free_index[v] = free_vertex.len() as u32;
                free_vertex.push(v as u32);
            }
        }
        let n = free_vertex.len();
        // Column c holds rows r ≥ c: the diagonal and the edges to higher free indices.
        let mut count = vec![1u32; n];
        for &[a, b] in &md.edges {
            let (ia, ib) = (free_index[a as usize], free_index[b as usize]);
            if ia != NONE && ib != NONE {
                count[ia.min(ib) as usize] += 1;
            }
        }
        let mut col_ptr = vec![0u32; n + 1];
        for c in 0..n {
            col_ptr[c + 1] = col_ptr[c] + count[c];
        }
        let nnz = col_ptr[n] as usize;
        let mut row_idx = vec![0u32; nnz];
        let mut fill = col_ptr[..n].to_vec();
        let mut diag_slot = vec![NONE; nv];
        for c in 0..n {
            row_idx[fill[c] as usize] = c as u32;
            diag_slot[free_vertex[c] as usize] = fill[c];
            fill[c] += 1;
        }
        let mut edge_slot = vec![NONE; md.n_edges()];
        for (e, &[a, b]) in md.edges.iter().enumerate() {
            let (ia, ib) = (free_index[a as usize], free_index[b as usize]);
            if ia != NONE && ib != NONE {
                let (c, r) = (ia.min(ib), ia.max(ib));
                row_idx[fill[c as usize] as usize] = r;
                edge_slot[e] = fill[c as usize];
                fill[c as usize] += 1;
            }
        }
        // Sort rows inside each column (keeping the slot maps consistent).
        let mut perm_slot = vec![0u32; nnz];
        for c in 0..n {
            let (s, t) = (col_ptr[c] as usize, col_ptr[c + 1] as usize);
            let mut idx: Vec<u32> = (s as u32..t as u32).collect();
            idx.sort_by_key(|&k| row_idx[k as usize]);
            let rows: Vec<u32> = idx.iter().map(|&k| row_idx[k as usize]).collect();
            for (off, &k) in idx.iter().enumerate() {
                perm_slot[k as usize] = (s + off) as u32;
            }
            row_idx[s..t].copy_from_slice(&rows);
        }
        for d in diag_slot.iter_mut().filter(|d| **d != NONE) {
            *d = perm_slot[*d as usize];
        }
        for d in edge_slot.iter_mut().filter(|d| **d != NONE) {
            *d = perm_slot[*d as usize];
        }
        HessianPattern {
            free_index,
            free_vertex,
            col_ptr,
            row_idx,
            diag_slot,
            edge_slot,
        }
    }
    pub fn n(&self) -> usize {
        self.free_vertex.len()
    }
    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }
}

/// Evaluate lengths, angles, curvature and (optionally) the Hessian values at `u`.
/// Returns false when some edge length does not exist for this `u` (outside the domain).
pub fn evaluate<B: Background, L: Law>(
    md: &MeshData,
    eta: &[f64],
    u: &[f64],
    ws: &mut Workspace,
    hessian: Option<(&HessianPattern, &mut [f64])>,
) -> bool {
    let ok = edge_pass::<B, L>(
        eta,
        &md.edges,
        u,
        &mut ws.vertex_data,
        &mut ws.lengths,
        &mut ws.dlengths,
    );
    if !ok {
        return false;
    }
    for (v, k) in ws.curvature.iter_mut().enumerate() {
        *k = md.curvature_base(v);
    }
    let mut deg = 0usize;
    let mut area = 0.0;
    let (pattern, values) = match hessian {
        Some((p, v)) => {
            v.fill(0.0);
            (Some(p), Some(v))
        }
        None => (None, None),
    };
    let mut values = values;
    for (f, t) in md.faces.iter().enumerate() {
        let fe = md.face_edges[f];
        let l = [
            ws.lengths[fe[0] as usize],
            ws.lengths[fe[1] as usize],
            ws.lengths[fe[2] as usize],
        ];
        let (th, dth, degenerate) = if pattern.is_some() {
            angle_derivatives::<B>(l)
        } else {
            let (th, _, d) = triangle_angles::<B>(l);
            (th, [[0.0; 3]; 3], d)
        };
        deg += degenerate as usize;
        area += match B::KIND {
            super::Geometry::Euclidean => B::area(l[0], l[1], l[2]),
            super::Geometry::Hyperbolic => (PI - th[0] - th[1] - th[2]).max(0.0),
            super::Geometry::Spherical => (th[0] + th[1] + th[2] - PI).max(0.0),
        };
        for m in 0..3 {
            ws.angles[3 * f + m] = th[m];
            ws.curvature[t[m] as usize] -= th[m];
        }
        if let (Some(p), Some(vals)) = (pattern, values.as_deref_mut()) {
            if degenerate {
                continue;
            }
            // g[n][q] = ∂l_n/∂u_q (local indices; zero for q == n).
            let mut g = [[0.0; 3]; 3];
            for n in 0..3 {
                let d = ws.dlengths[fe[n] as usize];
                let (d1, d2) = if md.face_edge_flip[f][n] {
                    (d[1], d[0])
                } else {
                    (d[0], d[1])
                };
                g[n][(n + 1) % 3] = d1;
                g[n][(n + 2) % 3] = d2;
            }
            // D[m][q] = ∂θ_m/∂u_q.
            let mut dm = [[0.0; 3]; 3];
            for m in 0..3 {
                for q in 0..3 {
                    dm[m][q] = dth[m][0] * g[0][q] + dth[m][1] * g[1][q] + dth[m][2] * g[2][q];
                }
            }
            for m in 0..3 {
                let s = p.diag_slot[t[m] as usize];
                if s != NONE {
                    vals[s as usize] -= dm[m][m];
                }
                // Edge opposite m joins m+1 and m+2.
                let s = p.edge_slot[fe[m] as usize];
                if s != NONE {
                    let (a, b) = ((m + 1) % 3, (m + 2) % 3);
                    vals[s as usize] -= 0.5 * (dm[a][b] + dm[b][a]);
                }
            }
        }
    }
    ws.degenerate_faces = deg;
    ws.area = area;
    true
}

/// Per-face Jacobian `∂θ_m/∂u_q` (local indices) of face `f` at the current workspace state
/// (after [`evaluate`]); used by tests to check the symmetry of each face block.
pub fn face_jacobian<B: Background>(md: &MeshData, ws: &Workspace, f: usize) -> [[f64; 3]; 3] {
    let fe = md.face_edges[f];
    let l = [
        ws.lengths[fe[0] as usize],
        ws.lengths[fe[1] as usize],
        ws.lengths[fe[2] as usize],
    ];
    let (_, dth, _) = angle_derivatives::<B>(l);
    let mut g = [[0.0; 3]; 3];
    for n in 0..3 {
        let d = ws.dlengths[fe[n] as usize];
        let (d1, d2) = if md.face_edge_flip[f][n] {
            (d[1], d[0])
        } else {
            (d[0], d[1])
        };
        g[n][(n + 1) % 3] = d1;
        g[n][(n + 2) % 3] = d2;
    }
    let mut dm = [[0.0; 3]; 3];
    for m in 0..3 {
        for q in 0..3 {
            dm[m][q] = dth[m][0] * g[0][q] + dth[m][1] * g[1][q] + dth[m][2] * g[2][q];
        }
    }
    dm
}
