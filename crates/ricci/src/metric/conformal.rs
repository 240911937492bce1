//! The initial discrete conformal structure of a mesh (paper 001 §V Step 2, paper 002 §4.3.1):
//! per-edge coefficients `η` and per-vertex initial variables `u⁰` such that the scheme's
//! lengths at `u⁰` reproduce the input metric (exactly for inversive distance and vertex
//! scaling, approximately for Thurston and tangential packings).
//!
//! **Input metric in H² and S².** The input lengths are Euclidean; they are first multiplied by
//! `input_scale` (the flow chooses it so the scaled Euclidean area equals the area the target
//! curvature asks for, which keeps triangles small relative to 1 and the initial metric close to
//! the final one) and then read as chords: `s(l⁰/2) = scale·l/2`, i.e. `l⁰ = 2 asinh(scale·l/2)`
//! in H² and `l⁰ = 2 asin(scale·l/2)` in S². For small triangles this is the identity up to
//! `O(l³)`; for a mesh inscribed in a sphere of radius `1/scale` it gives the exact spherical
//! geodesic lengths.
//!
//! **Radii.** Thurston's rule (paper 001 §V Step 2): `γ_i` = mean over the faces at `i` of
//! `(l_ij + l_ik − l_jk)/2`, with background lengths `l⁰`; then `η = cos φ` from the cosine
//! law, clamped to `[0, 1]` (φ ∈ [0, π/2]) for Thurston, `η = 1` for tangential packings.
//! Inversive distance packings use `γ_i = min(Thurston radius, ½ shortest edge at i)`, which
//! makes every inversive distance `I_ij ≥ 0` (the regime where Guo and Luo proved rigidity),
//! and `η = I_ij` exactly reproduces `l⁰`.

#![allow(clippy::needless_range_loop)]

use super::error::MetricError;
use super::geometry::{Background, Euclidean, Geometry, Hyperbolic, Spherical};
use super::scheme::Scheme;
use crate::error::{Error, Result};
use crate::mesh::Mesh;

/// Per-edge coefficients and per-vertex initial variables of a discrete conformal structure.
#[derive(Debug, Clone)]
pub struct ConformalStructure {
    pub geometry: Geometry,
    pub scheme: Scheme,
    /// Per edge: `cos φ` (Thurston, tangential), inversive distance `I` (inversive),
    /// `s(l⁰/2)` (Yamabe).
    pub eta: Vec<f64>,
    /// Initial variables: `u` of the initial radii for circle packings, 0 for vertex scaling.
    pub u0: Vec<f64>,
    /// Factor applied to the input lengths before reading them in the background geometry.
    pub input_scale: f64,
    /// Thurston only: edges whose intersection angle had to be clamped into [0, π/2].
    pub clamped_edges: usize,
    /// Largest relative difference between the initial scheme lengths and the (scaled) input
    /// lengths (0 up to rounding for inversive distance and Yamabe).
    pub initial_length_error: f64,
}

/// Lengths of the input read in the background geometry (see the module docs).
pub fn background_lengths(geometry: Geometry, lengths: &[f64], scale: f64) -> Result<Vec<f64>> {
    let mut out = Vec::with_capacity(lengths.len());
    for (e, &l) in lengths.iter().enumerate() {
        if !(l.is_finite() && l > 0.0) {
            return Err(Error::input(format!(
                "edge {e} has length {l}; every edge length must be positive and finite"
            )));
        }
        let x = 0.5 * scale * l;
        let l0 = match geometry {
            Geometry::Euclidean => 2.0 * x,
            Geometry::Hyperbolic => Hyperbolic::length_of_half_sine(x),
            Geometry::Spherical => {
                if x >= 1.0 {
                    return Err(Error::input(format!(
                        "edge {e} is longer than the diameter of the sphere the mesh is scaled to \
                         (scaled length {:.4} ≥ 2); the mesh is too coarse for a spherical metric",
                        2.0 * x
                    )));
                }
                Spherical::length_of_half_sine(x)
            }
        };
        out.push(l0);
    }
    Ok(out)
}

/// Check the triangle inequality (strictly) on every face.
pub fn check_triangles(mesh: &Mesh, lengths: &[f64], geometry: Geometry) -> Result<()> {
    for f in 0..mesh.n_faces() as u32 {
        let e = mesh.face_edges_opposite(f);
        let l = e.map(|e| lengths[e as usize]);
        let sum = l[0] + l[1] + l[2];
        for i in 0..3 {
            if l[i] >= sum - l[i] {
                return Err(MetricError::DegenerateFace {
                    face: f,
                    vertices: mesh.face(f),
                    lengths: l,
                }
                .into());
            }
        }
        if geometry == Geometry::Spherical && sum >= 2.0 * std::f64::consts::PI {
            return Err(MetricError::SphericalFaceTooLarge {
                face: f,
                perimeter: sum,
            }
            .into());
        }
    }
    Ok(())
}

impl ConformalStructure {
    /// Build the structure of `scheme` in `geometry` from Euclidean input lengths (indexed by
    /// edge id) scaled by `input_scale`. Errors name the edge, face or vertex at fault.
    pub fn new(
        mesh: &Mesh,
        lengths: &[f64],
        geometry: Geometry,
        scheme: Scheme,
        input_scale: f64,
    ) -> Result<ConformalStructure> {
        if lengths.len() != mesh.n_edges() {
            return Err(Error::input(format!(
                "{} edge lengths given for a mesh with {} edges",
                lengths.len(),
                mesh.n_edges()
            )));
        }
        if !(input_scale.is_finite() && input_scale > 0.0) {
            return Err(Error::input(format!(
                "input scale {input_scale} must be positive"
            )));
        }
        let l0 = background_lengths(geometry, lengths, input_scale)?;
        check_triangles(mesh, &l0, geometry)?;
        match geometry {
            Geometry::Euclidean => Self::build::<Euclidean>(mesh, &l0, scheme, input_scale),
            Geometry::Hyperbolic => Self::build::<Hyperbolic>(mesh, &l0, scheme, input_scale),
            Geometry::Spherical => Self::build::<Spherical>(mesh, &l0, scheme, input_scale),
        }
    }

    fn build<B: Background>(
        mesh: &Mesh,
        l0: &[f64],
        scheme: Scheme,
        input_scale: f64,
    ) -> Result<ConformalStructure> {
        let nv = mesh.n_vertices();
        let ne = mesh.n_edges();
        let mut s = ConformalStructure {
            geometry: B::KIND,
            scheme,
            eta: vec![0.0; ne],
            u0: vec![0.0; nv],
            input_scale,
            clamped_edges: 0,
            initial_length_error: 0.0,
        };
        if !scheme.is_circle_packing() {
            for e in 0..ne {
                s.eta[e] = B::half_sine(l0[e]);
            }
            return Ok(s);
        }
        let gamma = thurston_radii(mesh, l0)?;
        let gamma = if scheme == Scheme::Inversive {
            let mut g = gamma;
            for (e, &l) in l0.iter().enumerate() {
                let [a, b] = mesh.edge_vertices(e as u32);
                g[a as usize] = g[a as usize].min(0.5 * l);
                g[b as usize] = g[b as usize].min(0.5 * l);
            }
            g
        } else {
            gamma
        };
        for v in 0..nv {
            if mesh.is_isolated(v as u32) {
                continue;
            }
            let g = gamma[v];
            if B::KIND == Geometry::Spherical && g >= std::f64::consts::PI {
                return Err(Error::input(format!(
                    "vertex {v}: initial circle radius {g:.4} is not below π"
                )));
            }
            s.u0[v] = B::variable_of_radius(g);
        }
        let mut max_err = 0.0f64;
        for e in 0..ne {
            let [a, b] = mesh.edge_vertices(e as u32);
            let (ga, gb) = (gamma[a as usize], gamma[b as usize]);
            let eta = B::circle_packing_coefficient(ga, gb, l0[e]);
            let eta = match scheme {
                Scheme::Thurston => {
                    if !(0.0..=1.0).contains(&eta) {
                        s.clamped_edges += 1;
                    }
                    eta.clamp(0.0, 1.0)
                }
                Scheme::Tangential => 1.0,
                Scheme::Inversive => {
                    if !(eta > -1.0 && eta.is_finite()) {
                        return Err(Error::input(format!(
                            "edge {e} ({a}, {b}): no inversive distance reproduces its length \
                             (I = {eta:.4})"
                        )));
                    }
                    eta
                }
                Scheme::Yamabe | Scheme::Conformal => unreachable!(),
            };
            s.eta[e] = eta;
            let l = B::circle_packing_length(ga, gb, eta);
            max_err = max_err.max((l - l0[e]).abs() / l0[e]);
        }
        s.initial_length_error = max_err;
        Ok(s)
    }

    /// Lengths (by edge id) of the metric with variables `u` (NaN where no edge exists).
    pub fn lengths(&self, mesh: &Mesh, u: &[f64]) -> Vec<f64> {
        let mut l = vec![0.0; mesh.n_edges()];
        let mut d = vec![[0.0; 2]; mesh.n_edges()];
        self.lengths_and_derivatives(mesh, u, &mut l, &mut d);
        l
    }

    /// Lengths and their derivatives `[∂l_e/∂u_a, ∂l_e/∂u_b]` for `[a, b] = edge_vertices(e)`.
    pub fn lengths_and_derivatives(
        &self,
        mesh: &Mesh,
        u: &[f64],
        lengths: &mut [f64],
        derivatives: &mut [[f64; 2]],
    ) {
        let edges: Vec<[u32; 2]> = (0..mesh.n_edges() as u32)
            .map(|e| mesh.edge_vertices(e))
            .collect();
        self.lengths_of_edges(&edges, u, lengths, derivatives);
    }

    /// As [`ConformalStructure::lengths_and_derivatives`], with the connectivity cache.
    pub fn lengths_from_data(
        &self,
        data: &super::MeshData,
        u: &[f64],
        lengths: &mut [f64],
        derivatives: &mut [[f64; 2]],
    ) {
        self.lengths_of_edges(&data.edges, u, lengths, derivatives);
    }

    fn lengths_of_edges(
        &self,
        edges: &[[u32; 2]],
        u: &[f64],
        lengths: &mut [f64],
        derivatives: &mut [[f64; 2]],
    ) {
        use super::scheme::{CirclePacking, VertexScaling};
        let mut vd = vec![[0.0; 3]; u.len()];
        macro_rules! go {
            ($b:ty, $l:ty) => {
                super::kernel::edge_pass::<$b, $l>(
                    &self.eta,
                    &edges,
                    u,
                    &mut vd,
                    lengths,
                    derivatives,
                )
            };
        }
        let cp = self.scheme.is_circle_packing();
        match (self.geometry, cp) {
            (Geometry::Euclidean, true) => go!(Euclidean, CirclePacking),
            (Geometry::Hyperbolic, true) => go!(Hyperbolic, CirclePacking),
            (Geometry::Spherical, true) => go!(Spherical, CirclePacking),
            (Geometry::Euclidean, false) => go!(Euclidean, VertexScaling),
            (Geometry::Hyperbolic, false) => go!(Hyperbolic, VertexScaling),
            (Geometry::Spherical, false) => go!(Spherical, VertexScaling),
        };
    }

    /// Intersection angle φ of every edge (Thurston and tangential packings), or `None`.
    pub fn intersection_angles(&self) -> Option<Vec<f64>> {
        match self.scheme {
            Scheme::Thurston | Scheme::Tangential => Some(
                self.eta
                    .iter()
                    .map(|&c| c.clamp(-1.0, 1.0).acos())
                    .collect(),
            ),
            _ => None,
        }
    }
}

/// Thurston's initial radii (paper 001 §V Step 2): per vertex, the mean over its faces of
/// `(l_ij + l_ik − l_jk)/2`.
pub fn thurston_radii(mesh: &Mesh, l0: &[f64]) -> Result<Vec<f64>> {
    let nv = mesh.n_vertices();
    let mut sum = vec![0.0; nv];
    let mut cnt = vec![0u32; nv];
    for f in 0..mesh.n_faces() as u32 {
        let t = mesh.face(f);
        let e = mesh.face_edges_opposite(f);
        let l = e.map(|e| l0[e as usize]);
        for i in 0..3 {
            let (j, k) = ((i + 1) % 3, (i + 2) % 3);
            sum[t[i] as usize] += 0.5 * (l[j] + l[k] - l[i]);
            cnt[t[i] as usize] += 1;
        }
    }
    let mut g = vec![0.0; nv];
    for v in 0..nv {
        if cnt[v] == 0 {
            continue;
        }
        g[v] = sum[v] / cnt[v] as f64;
        if !(g[v] > 0.0 && g[v].is_finite()) {
            return Err(Error::input(format!(
                "vertex {v}: Thurston's initial radius is {:.4e} (degenerate faces around it)",
                g[v]
            )));
        }
    }
    Ok(g)
}
