//! Holomorphic 1-forms, the Riemann period matrix, zeros and the conformal net of a closed
//! surface of genus `g ≥ 1` (paper 002 §4.2 "global conformal parameterization", §6.3 period
//! matrices; paper 003 §2; Gu–Yau, "Global conformal surface parameterization", 2003).
//!
//! The chain:
//! 1. [`working`]: the triangulation and Euclidean metric (default: intrinsic Delaunay
//!    triangulation of the input metric, non-negative cotangent weights).
//! 2. [`crate::cut::canonical_cut`]: loops `a₁, b₁, …, a_g, b_g` through a base vertex.
//! 3. [`cochain`]: the closed 1-form dual to each loop; their periods on the loops form an
//!    integer matrix `P` (± the intersection form), and `P⁻¹` gives closed forms `ζ_k` with
//!    `∫_{γ_l} ζ_k = δ_kl` (the cohomology basis dual to the homology basis).
//! 4. [`harmonic`]: their harmonic representatives (one cotangent Laplacian factorization).
//! 5. [`hodge`]: the Hodge star on the cohomology and the complex structure `J`.
//! 6. [`period`]: the holomorphic basis `ω_i = α_i + i *α_i` normalized on the a-cycles and the
//!    period matrix `Ω_ij = ∫_{b_j} ω_i` (genus 1: `τ = Ω`).
//! 7. [`zeros`]: the `2g − 2` zeros of a holomorphic form; [`net`]: its integral on the cut
//!    mesh (the conformal net); [`placement`]: forms with zeros at chosen vertices;
//!    [`uniform`]: the combination of least area distortion (§4.2.1).

pub mod cochain;
pub mod corners;
pub mod double;
pub(crate) mod harmonic;
pub(crate) mod hodge;
pub(crate) mod net;
pub(crate) mod period;
pub mod placement;
pub(crate) mod small;
pub(crate) mod symmetric;
pub mod trajectories;
pub mod uniform;
pub(crate) mod working;
pub(crate) mod zeros;

use crate::analysis::spectrum::torus_modulus;
use crate::cut::{canonical_cut, CanonicalCut, CutOptions};
use crate::error::{Error, Result};
use crate::layout::isometry::Complex;
use crate::mesh::Mesh;
use crate::metric::IntrinsicMetric;
use crate::progress::Progress;
use serde::Serialize;
use small::Matrix;

pub use double::{double_forms, DoubleForms, Reflection};
pub use net::{ConformalNet, NetQuality};
pub use period::{lattice_energies, PeriodMatrix};
pub use working::{working_surface, FormsTriangulation, WorkingSurface};
pub use zeros::{Zero, ZeroSet};

/// Options of [`holomorphic_forms`].
#[derive(Debug, Clone, Default)]
pub struct FormsOptions {
    pub triangulation: FormsTriangulation,
    pub cut: CutOptions,
    /// Surfaces with boundary: do not widen boundary corners sharper than π/2 before doubling
    /// ([`corners`]; for comparisons — their zeros are then not faithful).
    pub keep_sharp_corners: bool,
}

/// A holomorphic 1-form `re + i·im` (1-forms per edge of the refined mesh of the cut).
#[derive(Debug, Clone)]
pub struct HolomorphicForm {
    pub re: Vec<f64>,
    pub im: Vec<f64>,
}

/// What was measured on the way (all should be small; see [`hodge`] for `star_defect`).
#[derive(Debug, Clone, Serialize)]
pub struct FormsReport {
    pub triangulation: FormsTriangulation,
    pub vertices: usize,
    pub faces: usize,
    /// Intrinsic flips from the input triangulation to the working one.
    pub flips: usize,
    /// Edges with a negative cotangent weight (0 on a Delaunay triangulation, up to ties).
    pub negative_weights: usize,
    /// `max_f |∮_{∂f} ζ_k|` over the harmonic basis.
    pub closedness: f64,
    /// Relative codifferential residual of the harmonic basis.
    pub harmonic_residual: f64,
    /// `max |W − Pᵀ J₀ P|`-type check: distance of the wedge matrix from an integer matrix.
    pub wedge_integrality: f64,
    /// `max |S² + 1|` of the least-squares Hodge star (discretization error).
    pub star_defect: f64,
    /// `max |Ω − Ωᵀ|` of the period matrix built from `S` instead of `J`.
    pub raw_asymmetry: f64,
    /// Newton steps of the complex structure.
    pub complex_structure_iterations: usize,
    pub seconds: f64,
}

/// The holomorphic structure of a closed surface (module docs).
#[derive(Debug, Clone)]
pub struct HolomorphicForms {
    pub genus: usize,
    pub working: WorkingSurface,
    /// The canonical cut of the working surface; the forms live on `cut.refined.mesh`.
    pub cut: CanonicalCut,
    /// Cotangent weights of the refined mesh.
    pub weights: Vec<f64>,
    /// Harmonic 1-forms `ζ_k` dual to the loops `a₁, b₁, …` (`∫_{γ_l} ζ_k = δ_kl`).
    pub harmonic: Vec<Vec<f64>>,
    /// `G_kl = ∫⟨ζ_k, ζ_l⟩`.
    pub gram: Matrix,
    /// `W_kl = ∫ ζ_k ∧ ζ_l`.
    pub wedge: Matrix,
    /// Least-squares Hodge star `S` and complex structure `J` on the `ζ` coordinates.
    pub star: Matrix,
    pub complex_structure: Matrix,
    /// `ω_1 … ω_g`, `∫_{a_j} ω_i = δ_ij`.
    pub basis: Vec<HolomorphicForm>,
    /// Coordinates of `Re ω_i` in the `ζ` basis (its periods on `a₁, b₁, …`).
    pub basis_coordinates: Vec<Vec<f64>>,
    pub period_matrix: PeriodMatrix,
    pub report: FormsReport,
}

/// Compute the holomorphic structure of a closed surface given by a mesh and its Euclidean
/// edge lengths (positions optional, carried to the outputs).
pub fn holomorphic_forms(
    mesh: &Mesh,
    metric: &IntrinsicMetric,
    positions: Option<&[[f64; 3]]>,
    options: &FormsOptions,
    progress: &mut dyn Progress,
) -> Result<HolomorphicForms> {
    let working = working_surface(mesh, metric, positions, options.triangulation, progress)?;
    holomorphic_forms_on(working, &options.cut, progress)
}

/// [`holomorphic_forms`] on a prepared working surface.
pub fn holomorphic_forms_on(
    working: WorkingSurface,
    cut_options: &CutOptions,
    progress: &mut dyn Progress,
) -> Result<HolomorphicForms> {
    let t0 = std::time::Instant::now();
    progress.report("forms", Some(0.0), "canonical cut");
    let cut = canonical_cut(
        &working.mesh,
        &IntrinsicMetric::euclidean(working.lengths.clone()),
        working.positions.as_deref(),
        cut_options,
        progress,
    )?;
    let g = cut.genus;
    if g == 0 || cut.boundary_loops > 0 {
        return Err(Error::topology(
            "holomorphic 1-forms are computed for closed surfaces of genus ≥ 1",
        ));
    }
    let loops: Vec<(&str, &[u32])> = cut
        .loops
        .iter()
        .take(2 * g)
        .map(|lp| (lp.label.as_str(), lp.halfedges.as_slice()))
        .collect();
    let lf = forms_of_loops(&cut.refined.mesh, &cut.refined.lengths, &loops, progress)?;
    let report = FormsReport {
        triangulation: working.kind,
        vertices: cut.refined.mesh.n_vertices(),
        faces: cut.refined.mesh.n_faces(),
        flips: working.flips,
        negative_weights: lf.negative_weights,
        closedness: lf.closedness,
        harmonic_residual: lf.harmonic_residual,
        wedge_integrality: lf.wedge_integrality,
        star_defect: hodge::star_defect(&lf.star),
        raw_asymmetry: lf.raw_asymmetry,
        complex_structure_iterations: lf.iterations,
        seconds: t0.elapsed().as_secs_f64(),
    };
    progress.report("forms", Some(1.0), "done");
    Ok(HolomorphicForms {
        genus: g,
        working,
        weights: lf.weights,
        harmonic: lf.harmonic,
        gram: lf.gram,
        wedge: lf.wedge,
        star: lf.star,
        complex_structure: lf.complex_structure,
        basis: lf.basis,
        basis_coordinates: lf.basis_coordinates,
        period_matrix: lf.period_matrix,
        report,
        cut,
    })
}

/// The Riemann period matrix of the closed surface `mesh` (Euclidean `lengths`, cotangent
/// weights of this very triangulation) for the homology basis `a₁, b₁, …, a_g, b_g` given as
/// simple closed edge loops (half-edge cycles) — the computation of [`holomorphic_forms_on`]
/// with any loops in place of a canonical cut's. Two canonical bases on one triangulation
/// give period matrices related exactly (up to rounding) by the action of `Sp(2g, Z)`, with
/// no discretization difference between them.
pub fn period_matrix_of_loops(
    mesh: &Mesh,
    metric: &IntrinsicMetric,
    loops: &[Vec<u32>],
) -> Result<PeriodMatrix> {
    let lengths = metric.lengths();
    if loops.is_empty() || !loops.len().is_multiple_of(2) {
        return Err(Error::input(format!(
            "{} loops given; a homology basis a1, b1, …, ag, bg has an even, positive number",
            loops.len()
        )));
    }
    let labelled: Vec<(String, &[u32])> = loops
        .iter()
        .enumerate()
        .map(|(k, l)| (format!("{}{}", ["a", "b"][k % 2], k / 2 + 1), l.as_slice()))
        .collect();
    let refs: Vec<(&str, &[u32])> = labelled.iter().map(|(s, l)| (s.as_str(), *l)).collect();
    let lf = forms_of_loops(mesh, lengths, &refs, &mut crate::progress::NoProgress)?;
    Ok(lf.period_matrix)
}

/// What [`forms_of_loops`] computes.
struct LoopForms {
    weights: Vec<f64>,
    negative_weights: usize,
    harmonic: Vec<Vec<f64>>,
    closedness: f64,
    harmonic_residual: f64,
    gram: Matrix,
    wedge: Matrix,
    wedge_integrality: f64,
    star: Matrix,
    complex_structure: Matrix,
    iterations: usize,
    raw_asymmetry: f64,
    basis: Vec<HolomorphicForm>,
    basis_coordinates: Vec<Vec<f64>>,
    period_matrix: PeriodMatrix,
}

/// Steps 3–6 of the module docs for the labelled loops `a₁, b₁, …` (simple edge loops).
fn forms_of_loops(
    mesh: &Mesh,
    lengths: &[f64],
    loops: &[(&str, &[u32])],
    progress: &mut dyn Progress,
) -> Result<LoopForms> {
    let n = loops.len();
    progress.report("forms", Some(0.3), "dual 1-forms of the loops");
    let mut duals = Vec::with_capacity(n);
    for (label, hs) in loops {
        duals.push(
            cochain::loop_dual(mesh, hs)
                .map_err(|e| Error::numerical(format!("loop {label}: {e}")))?,
        );
    }
    let p: Matrix = duals
        .iter()
        .map(|w| {
            loops
                .iter()
                .map(|(_, hs)| cochain::period(mesh, w, hs))
                .collect()
        })
        .collect();
    let c = small::inverse(&p, "loop crossing")?;
    let zeta0: Vec<Vec<f64>> = (0..n)
        .map(|m| {
            let mut z = vec![0.0; mesh.n_edges()];
            for (k, w) in duals.iter().enumerate() {
                let ck = c[m][k];
                if ck != 0.0 {
                    for (a, b) in z.iter_mut().zip(w) {
                        *a += ck * b;
                    }
                }
            }
            z
        })
        .collect();
    forms_of_closed(mesh, lengths, &zeta0, progress)
}

/// Steps 4–6 of the module docs for closed 1-forms `zeta0` (their classes dual to a
/// canonical basis `a₁, b₁, …`).
fn forms_of_closed(
    mesh: &Mesh,
    lengths: &[f64],
    zeta0: &[Vec<f64>],
    progress: &mut dyn Progress,
) -> Result<LoopForms> {
    progress.report("forms", Some(0.5), "harmonic projection");
    let weights = harmonic::cotan_weights(mesh, lengths)?;
    let negative_weights = weights.iter().filter(|&&w| w < -1e-12).count();
    let projector = harmonic::HarmonicProjector::new(mesh, &weights)?;
    let zeta = projector.project(mesh, zeta0);
    let closedness = zeta
        .iter()
        .map(|z| cochain::closedness_defect(mesh, z))
        .fold(0.0, f64::max);
    let harmonic_residual = zeta
        .iter()
        .map(|z| harmonic::harmonic_residual(mesh, &weights, z))
        .fold(0.0, f64::max);
    progress.report("forms", Some(0.8), "Hodge star and period matrix");
    let gram = hodge::energy_gram(&weights, &zeta);
    let wedge = hodge::wedge_matrix(mesh, &zeta);
    let wedge_integrality = wedge
        .iter()
        .flatten()
        .map(|x| (x - x.round()).abs())
        .fold(0.0, f64::max);
    let star = hodge::star_matrix(&gram, &wedge)?;
    let (j, iterations) = hodge::complex_structure(&star)?;
    let raw_asymmetry = period::normalized_basis(&star)
        .map(|(_, _, om)| om.asymmetry())
        .unwrap_or(f64::NAN);
    let (re_coords, im_coords, period_matrix) = period::normalized_basis(&j)?;
    let combine = |coords: &[f64]| -> Vec<f64> {
        let mut z = vec![0.0; mesh.n_edges()];
        for (k, zk) in zeta.iter().enumerate() {
            for (a, b) in z.iter_mut().zip(zk) {
                *a += coords[k] * b;
            }
        }
        z
    };
    let basis = re_coords
        .iter()
        .zip(&im_coords)
        .map(|(x, jx)| HolomorphicForm {
            re: combine(x),
            im: combine(jx),
        })
        .collect();
    Ok(LoopForms {
        weights,
        negative_weights,
        harmonic: zeta,
        closedness,
        harmonic_residual,
        gram,
        wedge,
        wedge_integrality,
        star,
        complex_structure: j,
        iterations,
        raw_asymmetry,
        basis,
        basis_coordinates: re_coords,
        period_matrix,
    })
}

impl HolomorphicForms {
    /// The mesh the forms live on (the working surface refined by the cut).
    pub fn mesh(&self) -> &Mesh {
        &self.cut.refined.mesh
    }

    /// Its edge lengths.
    pub fn lengths(&self) -> &[f64] {
        &self.cut.refined.lengths
    }

    /// Its metric (Euclidean, the edge lengths of [`HolomorphicForms::lengths`]).
    pub fn metric(&self) -> IntrinsicMetric {
        IntrinsicMetric::euclidean(self.lengths().to_vec())
    }

    /// `Σ c_i ω_i`.
    pub fn combination(&self, c: &[Complex]) -> HolomorphicForm {
        let ne = self.mesh().n_edges();
        let (mut re, mut im) = (vec![0.0; ne], vec![0.0; ne]);
        for (ci, w) in c.iter().zip(&self.basis) {
            for e in 0..ne {
                re[e] += ci.re * w.re[e] - ci.im * w.im[e];
                im[e] += ci.re * w.im[e] + ci.im * w.re[e];
            }
        }
        HolomorphicForm { re, im }
    }

    /// The zeros of a holomorphic form (its real part's Poincaré–Hopf indices).
    pub fn zeros(&self, form: &HolomorphicForm) -> Result<ZeroSet> {
        zeros::zeros(self.mesh(), self.lengths(), &form.re)
    }

    /// The conformal net of a holomorphic form on the cut mesh.
    pub fn net(&self, form: &HolomorphicForm) -> Result<ConformalNet> {
        net::integrate(
            self.mesh(),
            self.lengths(),
            &self.cut.cut_mesh,
            &form.re,
            &form.im,
        )
    }

    /// Genus 1: the modulus `τ` reduced to the fundamental domain of SL(2, Z), `(Re τ, Im τ)`.
    pub fn modulus(&self) -> Option<(f64, f64)> {
        if self.genus != 1 {
            return None;
        }
        let t = Complex::new(self.period_matrix.re[0][0], self.period_matrix.im[0][0]);
        torus_modulus(Complex::new(1.0, 0.0), t).ok()
    }

    /// The Dirichlet energies of the harmonic forms with integer periods, smallest first: the
    /// same for every canonical basis ([`period`]).
    pub fn lattice_energies(&self, count: usize) -> Result<Vec<f64>> {
        lattice_energies(&self.period_matrix.energy_form()?, count)
    }
}
