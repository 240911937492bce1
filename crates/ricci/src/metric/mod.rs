//! Background geometries, discrete conformal schemes, curvature, Ricci energy and its Hessian
//! (paper 001 §IV–V and Appendix D, paper 002 ch. 3; docs/DESIGN.md §3).
//!
//! * [`geometry`] — the backgrounds E², H², S² and their stable cosine laws;
//! * [`scheme`] — Thurston / tangential / inversive distance circle packings and vertex scaling;
//! * [`conformal`] — the initial conformal structure built from a mesh's edge lengths;
//! * [`kernel`] — the allocation-free evaluation of lengths, angles, curvature and Hessian;
//! * [`lengths`] — [`IntrinsicMetric`]: geometry + edge lengths (+ their double-double tail),
//!   the metric the flow produces and the cut, layout, atlas and spline consume;
//! * [`file`] — the metric file (`METRIC.json`): one reader and writer for every command;
//! * [`intrinsic`] — intrinsic (Δ-complex) triangulations with log Penner coordinates, Ptolemy
//!   flips and the Penner Delaunay criterion (discrete conformal equivalence);
//! * [`refine`] — intrinsic refinement: metric-preserving edge splits and flips in E², H², S²
//!   (paper 000 Step 2), moved here from `mesh` because it needs the background geometries;
//! * [`common_subdivision`] — normal coordinates of the input edges through the flips, the
//!   overlay of the input and the intrinsic triangulation, UVs by projective interpolation.
//!
//! **Energy and signs.** We use the convex Ricci energy `E(u) = ∫ Σ (K_i − K̄_i) du_i`, whose
//! gradient is `K − K̄` and whose Hessian is `H = ∂K/∂u` (positive semidefinite in E², with the
//! constants as kernel; positive definite in H²; indefinite in S²). The papers' energy
//! (paper 001 eq. 11) is `f = −E`: the discrete Ricci flow `du/dt = K̄ − K` descends `E`.
//! `E` is path independent because `H` is symmetric; [`Evaluator::energy`] integrates it along
//! the straight segment from `u⁰` with Gauss–Legendre quadrature.

#![allow(clippy::needless_range_loop)]

pub mod common_subdivision;
pub(crate) mod conformal;
pub(crate) mod error;
pub mod file;
pub mod geometry;
pub mod intrinsic;
pub mod kernel;
pub(crate) mod lengths;
pub mod refine;
pub(crate) mod scheme;

pub use conformal::ConformalStructure;
pub use error::MetricError;
pub use geometry::{Background, Euclidean, Geometry, Hyperbolic, Spherical};
pub use kernel::{HessianPattern, MeshData, Workspace};
pub use lengths::IntrinsicMetric;
pub use scheme::{CirclePacking, Law, Scheme, VertexScaling};

use crate::mesh::Mesh;
use std::f64::consts::PI;

/// The monomorphized evaluation function of one (geometry, law) pair.
pub type EvalFn =
    fn(&MeshData, &[f64], &[f64], &mut Workspace, Option<(&HessianPattern, &mut [f64])>) -> bool;

/// Pick the evaluation kernel once for a runtime (geometry, scheme) pair.
pub fn eval_fn(geometry: Geometry, scheme: Scheme) -> EvalFn {
    use kernel::evaluate;
    match (geometry, scheme.is_circle_packing()) {
        (Geometry::Euclidean, true) => evaluate::<Euclidean, CirclePacking>,
        (Geometry::Hyperbolic, true) => evaluate::<Hyperbolic, CirclePacking>,
        (Geometry::Spherical, true) => evaluate::<Spherical, CirclePacking>,
        (Geometry::Euclidean, false) => evaluate::<Euclidean, VertexScaling>,
        (Geometry::Hyperbolic, false) => evaluate::<Hyperbolic, VertexScaling>,
        (Geometry::Spherical, false) => evaluate::<Spherical, VertexScaling>,
    }
}

/// Evaluates a conformal structure at variables `u`: lengths, angles, curvature, Hessian.
#[derive(Debug, Clone)]
pub struct Evaluator {
    pub data: MeshData,
    pub structure: ConformalStructure,
    pub ws: Workspace,
    f: EvalFn,
}

impl Evaluator {
    pub fn new(mesh: &Mesh, structure: ConformalStructure) -> Evaluator {
        let data = MeshData::new(mesh);
        let ws = Workspace::new(&data);
        let f = eval_fn(structure.geometry, structure.scheme);
        Evaluator {
            data,
            structure,
            ws,
            f,
        }
    }
    /// Lengths, angles, curvature and area at `u`; false if some edge length does not exist.
    pub fn evaluate(&mut self, u: &[f64]) -> bool {
        (self.f)(&self.data, &self.structure.eta, u, &mut self.ws, None)
    }
    /// As [`Evaluator::evaluate`], also filling the Hessian values of `pattern`.
    pub fn evaluate_with_hessian(
        &mut self,
        u: &[f64],
        pattern: &HessianPattern,
        values: &mut [f64],
    ) -> bool {
        (self.f)(
            &self.data,
            &self.structure.eta,
            u,
            &mut self.ws,
            Some((pattern, values)),
        )
    }
    /// The full symmetric Hessian `∂K_i/∂u_j` over all vertices as `(i, j, value)` triplets
    /// (both triangles), or `None` outside the domain.
    pub fn hessian_triplets(&mut self, u: &[f64]) -> Option<Vec<(u32, u32, f64)>> {
        let fixed = vec![false; self.data.n_vertices()];
        let p = HessianPattern::new(&self.data, &fixed);
        let mut vals = vec![0.0; p.nnz()];
        if !self.evaluate_with_hessian(u, &p, &mut vals) {
            return None;
        }
        let mut out = Vec::with_capacity(2 * vals.len());
        for c in 0..p.n() {
            for s in p.col_ptr[c] as usize..p.col_ptr[c + 1] as usize {
                let r = p.row_idx[s] as usize;
                let (i, j) = (p.free_vertex[r], p.free_vertex[c]);
                out.push((i, j, vals[s]));
                if i != j {
                    out.push((j, i, vals[s]));
                }
            }
        }
        Some(out)
    }
    /// Per-face Jacobian `∂θ/∂u` (local indices) at the state of the last evaluation.
    pub fn face_jacobian(&self, f: usize) -> [[f64; 3]; 3] {
        match self.structure.geometry {
            Geometry::Euclidean => kernel::face_jacobian::<Euclidean>(&self.data, &self.ws, f),
            Geometry::Hyperbolic => kernel::face_jacobian::<Hyperbolic>(&self.data, &self.ws, f),
            Geometry::Spherical => kernel::face_jacobian::<Spherical>(&self.data, &self.ws, f),
        }
    }
    /// Energy difference `E(b) − E(a) = ∫₀¹ (K(a + t(b−a)) − K̄)·(b − a) dt`, by composite
    /// Gauss–Legendre quadrature (`panels` × 8 nodes). `None` if the segment leaves the domain.
    pub fn energy_difference(
        &mut self,
        a: &[f64],
        b: &[f64],
        target: &[f64],
        panels: usize,
    ) -> Option<f64> {
        let (x, w) = gauss_legendre_8();
        let n = a.len();
        let mut p = vec![0.0; n];
        let mut total = 0.0;
        let h = 1.0 / panels as f64;
        for k in 0..panels {
            for q in 0..8 {
                let t = h * (k as f64 + 0.5 * (x[q] + 1.0));
                for i in 0..n {
                    p[i] = a[i] + t * (b[i] - a[i]);
                }
                if !self.evaluate(&p) {
                    return None;
                }
                let mut g = 0.0;
                for i in 0..n {
                    g += (self.ws.curvature[i] - target[i]) * (b[i] - a[i]);
                }
                total += 0.5 * h * w[q] * g;
            }
        }
        Some(total)
    }
    /// The convex Ricci energy `E(u) = ∫_{u⁰}^{u} Σ(K_i − K̄_i) du_i` (see the module docs).
    pub fn energy(&mut self, u: &[f64], target: &[f64]) -> Option<f64> {
        let u0 = self.structure.u0.clone();
        self.energy_difference(&u0, u, target, 8)
    }
}

/// Nodes and weights of the 8-point Gauss–Legendre rule on [−1, 1].
pub fn gauss_legendre_8() -> ([f64; 8], [f64; 8]) {
    let xp = [
        0.183_434_642_495_649_8,
        0.525_532_409_916_329,
        0.796_666_477_413_626_7,
        0.960_289_856_497_536_3,
    ];
    let wp = [
        0.362_683_783_378_362,
        0.313_706_645_877_887_3,
        0.222_381_034_453_374_5,
        0.101_228_536_290_376_3,
    ];
    let mut x = [0.0; 8];
    let mut w = [0.0; 8];
    for i in 0..4 {
        x[2 * i] = -xp[i];
        x[2 * i + 1] = xp[i];
        w[2 * i] = wp[i];
        w[2 * i + 1] = wp[i];
    }
    (x, w)
}

/// Corner angles (indexed by corner `3f + i`) of the metric `lengths` in `geometry`.
pub fn corner_angles(mesh: &Mesh, geometry: Geometry, lengths: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; mesh.n_corners()];
    for f in 0..mesh.n_faces() as u32 {
        let e = mesh.face_edges_opposite(f);
        let l = e.map(|e| lengths[e as usize]);
        let th = match geometry {
            Geometry::Euclidean => kernel::triangle_angles::<Euclidean>(l).0,
            Geometry::Hyperbolic => kernel::triangle_angles::<Hyperbolic>(l).0,
            Geometry::Spherical => kernel::triangle_angles::<Spherical>(l).0,
        };
        out[3 * f as usize..3 * f as usize + 3].copy_from_slice(&th);
    }
    out
}

/// Vertex curvature `K_i = 2π − Σθ` inside, `π − Σθ` on the boundary (paper 001 eq. 7).
pub fn curvature(mesh: &Mesh, geometry: Geometry, lengths: &[f64]) -> Vec<f64> {
    let th = corner_angles(mesh, geometry, lengths);
    let mut k: Vec<f64> = (0..mesh.n_vertices() as u32)
        .map(|v| {
            if mesh.is_isolated(v) {
                0.0
            } else if mesh.is_boundary_vertex(v) {
                PI
            } else {
                2.0 * PI
            }
        })
        .collect();
    for (c, t) in th.iter().enumerate() {
        k[mesh.corner_vertex(c as u32) as usize] -= t;
    }
    k
}

/// Total background area of the metric `lengths`.
pub fn total_area(mesh: &Mesh, geometry: Geometry, lengths: &[f64]) -> f64 {
    (0..mesh.n_faces() as u32)
        .map(|f| {
            let l = mesh.face_edges_opposite(f).map(|e| lengths[e as usize]);
            geometry.area(l[0], l[1], l[2])
        })
        .sum()
}

/// Euler characteristic `V − E + F` (isolated vertices excluded).
pub fn euler_characteristic(mesh: &Mesh) -> i64 {
    let v = (0..mesh.n_vertices() as u32)
        .filter(|&v| !mesh.is_isolated(v))
        .count() as i64;
    v - mesh.n_edges() as i64 + mesh.n_faces() as i64
}

/// Gauss–Bonnet residual `|Σ K_i + λ·Area − 2πχ|` (paper 001 eq. 8).
pub fn gauss_bonnet_residual(mesh: &Mesh, geometry: Geometry, lengths: &[f64]) -> f64 {
    let k: f64 = curvature(mesh, geometry, lengths).iter().sum();
    let a = total_area(mesh, geometry, lengths);
    (k + geometry.curvature() * a - 2.0 * PI * euler_characteristic(mesh) as f64).abs()
}
