//! Discrete conformal schemes: how per-vertex variables `u` and per-edge coefficients give edge
//! lengths (paper 001 §IV "Discrete Conformal Deformation", eq. 9 and 12; the unified framework
//! of Zhang–Guo–Zeng–Luo–Yau–Gu 2014; docs/DESIGN.md §3).
//!
//! Two length laws cover the four schemes:
//!
//! * **circle packing** ([`CirclePacking`]): a radius `γ_i` per vertex and a coefficient `η_ij`
//!   per edge, `s(l/2)² = s((γi−γj)/2)² + ½ s(γi)s(γj)(1 + η)` — Thurston's packing with
//!   `η = cos φ ∈ [0, 1]`, the tangential packing `η = 1`, the inversive distance packing
//!   `η = I` (any value > −1). The variable is `u = log γ` (E²), `log tanh(γ/2)` (H²),
//!   `log tan(γ/2)` (S²), so that `dγ/du = s(γ)`, and
//!   `∂l_ij/∂u_i = s(γi) τ_ij / s(l_ij)` with `τ_ij = s(γi)c(γj) + c(γi)s(γj)η_ij`;
//! * **vertex scaling** ([`VertexScaling`], Yamabe / Luo's combinatorial Yamabe flow):
//!   `s(l/2) = e^{(u_i+u_j)/2} s(l⁰/2)`, stored as `η_ij = s(l⁰_ij/2)`, with
//!   `∂l_ij/∂u_i = s(l/2)/c(l/2)`.

use super::geometry::Background;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// The discrete conformal scheme chosen at run time.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Scheme {
    /// Thurston's circle packing with intersection angles φ ∈ [0, π/2] (the papers' default).
    Thurston,
    /// Tangential circle packing (φ = 0 on every edge).
    Tangential,
    /// Inversive distance circle packing (reproduces the input lengths exactly).
    Inversive,
    /// Vertex scaling (discrete Yamabe flow; reproduces the input lengths exactly).
    Yamabe,
    /// Discrete conformal equivalence: vertex scaling on the intrinsic Delaunay triangulation
    /// of the current metric, with Ptolemy flips ([`crate::flow::conformal`]); the result
    /// lives on an intrinsic triangulation.
    Conformal,
}

impl Scheme {
    pub fn name(self) -> &'static str {
        match self {
            Scheme::Thurston => "thurston",
            Scheme::Tangential => "tangential",
            Scheme::Inversive => "inversive",
            Scheme::Yamabe => "yamabe",
            Scheme::Conformal => "conformal",
        }
    }
    /// True for the three circle-packing schemes.
    pub fn is_circle_packing(self) -> bool {
        !matches!(self, Scheme::Yamabe | Scheme::Conformal)
    }
}

impl fmt::Display for Scheme {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Scheme {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.to_ascii_lowercase().as_str() {
            "thurston" | "circle-packing" => Ok(Scheme::Thurston),
            "tangential" | "tangent" => Ok(Scheme::Tangential),
            "inversive" | "inversive-distance" => Ok(Scheme::Inversive),
            "yamabe" | "vertex-scaling" => Ok(Scheme::Yamabe),
            "conformal" | "dce" | "delaunay" => Ok(Scheme::Conformal),
            _ => Err(format!(
                "unknown scheme '{s}' (expected thurston, tangential, inversive, yamabe or \
                 conformal)"
            )),
        }
    }
}

/// A length law at compile time: what is precomputed per vertex and how an edge length and its
/// two derivatives follow.
pub trait Law: Copy + Send + Sync + 'static {
    /// Per-vertex quantities computed once per evaluation from `u` (circle packing:
    /// `[s(γ), c(γ), γ]`; vertex scaling: `[e^{u/2}, 0, 0]`). NaN entries mark an invalid `u`.
    fn vertex<B: Background>(u: f64) -> [f64; 3];
    /// Length of the edge with coefficient `eta` between vertices with data `a` and `b`, and
    /// `(∂l/∂u_a, ∂l/∂u_b)`. NaN length when no such edge exists.
    fn edge<B: Background>(eta: f64, a: [f64; 3], b: [f64; 3]) -> (f64, f64, f64);
}

/// Circle packing law (Thurston, tangential, inversive distance).
#[derive(Debug, Clone, Copy, Default)]
pub struct CirclePacking;

/// Vertex scaling law (Yamabe).
#[derive(Debug, Clone, Copy, Default)]
pub struct VertexScaling;

impl Law for CirclePacking {
    #[inline]
    fn vertex<B: Background>(u: f64) -> [f64; 3] {
        let g = B::radius_of_variable(u);
        [B::s(g), B::c(g), g]
    }
    #[inline]
    fn edge<B: Background>(eta: f64, a: [f64; 3], b: [f64; 3]) -> (f64, f64, f64) {
        let l = B::circle_packing_length(a[2], b[2], eta);
        let sl = B::s(l);
        // τ_ab = s(γa)c(γb) + c(γa)s(γb)η ; ∂l/∂u_a = s(γa) τ_ab / s(l).
        let tab = a[0] * b[1] + a[1] * b[0] * eta;
        let tba = b[0] * a[1] + b[1] * a[0] * eta;
        (l, a[0] * tab / sl, b[0] * tba / sl)
    }
}

impl Law for VertexScaling {
    #[inline]
    fn vertex<B: Background>(u: f64) -> [f64; 3] {
        [(0.5 * u).exp(), 0.0, 0.0]
    }
    #[inline]
    fn edge<B: Background>(eta: f64, a: [f64; 3], b: [f64; 3]) -> (f64, f64, f64) {
        let l = B::length_of_half_sine(a[0] * b[0] * eta);
        let d = B::half_tangent(l);
        (l, d, d)
    }
}
