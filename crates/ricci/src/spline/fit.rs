//! Fairing and fitting of DMS splines (paper 000 §5), generic over [`SplineSpace`]: the planar
//! [`DmsSpace`] and the manifold space of [`crate::spline::manifold`].
//!
//! **Fairing** (paper 000 eq. 14, Fig. 13). Given control points `c`, find `c̃` minimising
//! `Σ ‖c̃_{I,β} − c_{I,β}‖²` subject to, for every interior edge shared by triangles `I` and
//! `J` and every `β` of `I` with `β_o ≤ r` (`o` = the vertex of `I` opposite the edge),
//! `c̃_{I,β} = f^J(t^I_{0,0..β_0−1}, t^I_{1,0..β_1−1}, t^I_{2,0..β_2−1})`: the control point of `I`
//! equals the blossom of `J`'s B-patch polynomial (built from `c̃_J`) at `I`'s arguments. Both
//! orientations of every edge are imposed. `r = 0` makes the control points along each edge
//! shared (the arguments then only involve knots of the edge's vertices); larger `r` ties
//! more rows of control points to the neighbour's polynomial, `r = n` would make the whole
//! spline one polynomial. The constraints are homogeneous, `A c̃ = 0`, so `c̃ = c − Aᵀ y` with
//! `A Aᵀ y = A c`; `A Aᵀ` can be singular (constraints around a vertex are dependent), so it is
//! factored with a tiny diagonal shift (faer sparse Cholesky) and used as the preconditioner
//! of conjugate gradients on the consistent system until `‖A c̃‖` reaches the tolerance.
//!
//! **Fitting.** Given data `(face, parameter point) → target`, minimise
//! `(1/K) Σ_k ‖F(u_k) − p_k‖² + λ (h̄² / |D|) E(F) + γ ‖c − c₀‖²`, where `E` is the thin-plate
//! energy `∫_D |F_xx|² + 2|F_xy|² + |F_yy|²` (quadrature: every domain triangle split into nine,
//! the three corner pieces split again twice, three points of degree 2 in each piece — see
//! [`super::quadrature::QUADRATURE_SUBDIVISION`] for why so many), `h̄` the mean domain edge length and `|D|` the domain area
//! (so `λ` is scale-free), and `γ` a tiny ridge towards `c₀` that keeps control points that
//! neither term determines where they were. The normal equations are solved by sparse
//! Cholesky (faer).
//!
//! **Precision.** The quadrature and the data rows evaluate the basis with the double-precision
//! recurrence ([`Precision::Double`], ~8× faster than the default double-double): the Gram
//! matrix needs the basis to ~1e-10 of its terms, not the 1e-12 chart independence of a
//! single partial that the extended recurrence gives.

use std::collections::BTreeMap;

use faer::linalg::matmul::triangular::BlockStructure;
use faer::sparse::{SparseColMat, Triplet};
use faer::Mat;

use crate::error::{Error, Result};
use crate::numeric::sparse::Cholesky;
use crate::progress::{NoProgress, Progress};

use super::dms::{Precision, Workspace};
use super::simplex::{n_partials, Point};

// The spline-space interface and the quadrature rules live in their own modules (so that
// [`super::dms`] and this one do not import each other).
use super::quadrature::quadrature_barycentric;
use super::space::{evaluate, SplineSpace};

mod fairing;
pub use fairing::{constraint_residuals, fair, fairness_constraints, Constraint, FairingReport};

/// One data point for [`fit`]: a parameter point in a domain face and its target.
#[derive(Debug, Clone)]
pub struct DataPoint {
    pub face: u32,
    pub param: Point,
    /// `dim` coordinates.
    pub target: Vec<f64>,
}

/// Options of [`fit`].
#[derive(Debug, Clone, Copy)]
pub struct FitOptions {
    /// Weight `λ` of the (scale-free) thin-plate energy.
    pub smoothing: f64,
    /// Weight `γ` of the ridge towards the initial control points, relative to the data term.
    pub ridge: f64,
}

impl Default for FitOptions {
    fn default() -> Self {
        FitOptions {
            smoothing: 1e-3,
            ridge: 1e-9,
        }
    }
}

/// What [`fit`] reached.
#[derive(Debug, Clone, serde::Serialize)]
pub struct FitReport {
    pub data_points: usize,
    /// Root mean square and maximum of `‖F(u_k) − p_k‖`.
    pub rms_error: f64,
    pub max_error: f64,
    /// Thin-plate energy `E(F)` before (initial control points) and after.
    pub energy_before: f64,
    pub energy_after: f64,
    /// The full objective before and after.
    pub objective_before: f64,
    pub objective_after: f64,
    /// `‖H c − b‖ / ‖b‖` of the normal equations after the solve.
    pub relative_residual: f64,
}

/// Dense `nb × nb` blocks of a symmetric matrix over triangle pairs `(I ≥ J)`, indexed in
/// the order of the pairs (a `BTreeMap`: every sum over the blocks runs in the same order from
/// call to call, so the fit is reproducible to the last bit).
struct Blocks {
    nb: usize,
    index: BTreeMap<(u32, u32), usize>,
    data: Vec<f64>,
}

impl Blocks {
    fn new(nb: usize) -> Blocks {
        Blocks {
            nb,
            index: BTreeMap::new(),
            data: Vec::new(),
        }
    }
    /// Add `w Σ_k a_k ⊗ b_k` for the functions found at one point: `vals[i * stride + k]`
    /// for function `i` (triangle groups of `nb` consecutive functions) and components `comps`
    /// (with weights `cw`).
    fn add_point(&mut self, idx: &[u32], vals: &[f64], stride: usize, comps: &[(usize, f64)]) {
        let nb = self.nb;
        let groups = idx.len() / nb;
        for gi in 0..groups {
            let ti = idx[gi * nb] / nb as u32;
            for gj in 0..=gi {
                let tj = idx[gj * nb] / nb as u32;
                let (a, b, ga, gb) = if ti >= tj {
                    (ti, tj, gi, gj)
                } else {
                    (tj, ti, gj, gi)
                };
                let next = self.data.len();
                let off = *self.index.entry((a, b)).or_insert(next);
                if off == next {
                    self.data.resize(next + nb * nb, 0.0);
                }
                let blk = &mut self.data[off..off + nb * nb];
                for p in 0..nb {
                    let rp = (ga * nb + p) * stride;
                    for q in 0..nb {
                        let rq = (gb * nb + q) * stride;
                        let mut s = 0.0;
                        for &(k, w) in comps {
                            s += w * vals[rp + k] * vals[rq + k];
                        }
                        blk[p * nb + q] += s;
                    }
                }
            }
        }
    }
    /// The block `(a, b)` (`a ≥ b`), created as zeros when missing.
    fn block_mut(&mut self, a: u32, b: u32) -> &mut [f64] {
        let nb = self.nb;
        let next = self.data.len();
        let off = *self.index.entry((a, b)).or_insert(next);
        if off == next {
            self.data.resize(next + nb * nb, 0.0);
        }
        &mut self.data[off..off + nb * nb]
    }
    /// `y += M x` (`dim` columns).
    fn apply(&self, x: &[f64], dim: usize, y: &mut [f64]) {
        let nb = self.nb;
        for (&(a, b), &off) in &self.index {
            let blk = &self.data[off..off + nb * nb];
            for p in 0..nb {
                for q in 0..nb {
                    let v = blk[p * nb + q];
                    let (i, j) = (a as usize * nb + p, b as usize * nb + q);
                    for d in 0..dim {
                        y[i * dim + d] += v * x[j * dim + d];
                        if a != b {
                            y[j * dim + d] += v * x[i * dim + d];
                        }
                    }
                }
            }
        }
    }
}

/// Thin-plate energy of a spline (the quadrature of [`fit`]).
pub fn thin_plate_energy<S: SplineSpace + ?Sized>(
    space: &S,
    control: &[f64],
    dim: usize,
) -> Result<f64> {
    thin_plate_energy_with(space, control, dim, &quadrature_barycentric())
}

/// Thin-plate energy of a spline with the quadrature rule `rule` on every triangle (e.g. a
/// finer [`super::quadrature::quadrature_barycentric_subdivided`] to check the fit's rule).
pub fn thin_plate_energy_with<S: SplineSpace + ?Sized>(
    space: &S,
    control: &[f64],
    dim: usize,
    rule: &[([f64; 3], f64)],
) -> Result<f64> {
    // Quadrature and data rows: double precision suffices (module docs, *Precision*).
    let mut ws = Workspace::with_precision(Precision::Double);
    let mut out = vec![0.0; n_partials(2) * dim];
    let mut e = 0.0;
    for (f, u, w) in space.quadrature_with(rule) {
        evaluate(space, control, dim, f, u, 2, &mut ws, &mut out)?;
        for d in 0..dim {
            let (xx, xy, yy) = (out[3 * dim + d], out[4 * dim + d], out[5 * dim + d]);
            e += w * (xx * xx + 2.0 * xy * xy + yy * yy);
        }
    }
    Ok(e)
}

/// Add the thin-plate energy's Gram matrix `Σ_k w_k (∂²_xx N ⊗ ∂²_xx N + 2 ∂²_xy N ⊗ ∂²_xy N +
/// ∂²_yy N ⊗ ∂²_yy N)(u_k)` over the quadrature to `blocks`. Per triangle, in parallel
/// ([`face_gram`]): the basis functions met at its points get local columns and their Gram
/// matrix is summed from small dense products, scattered into the blocks once per triangle
/// instead of once per point.
///
/// The faces are processed in [`GRAM_CHUNKS`] consecutive chunks (each in parallel), with a
/// progress report on the calling thread after each: the fraction of the quadrature done. The
/// per-face Gram matrices of a chunk are scattered in face order, so the result does not depend
/// on the threads.
fn energy_gram<S: SplineSpace + ?Sized>(
    space: &S,
    blocks: &mut Blocks,
    progress: &mut dyn Progress,
) -> Result<()> {
    use rayon::prelude::*;
    let nb = blocks.nb;
    let quad = space.quadrature();
    // Runs of consecutive points of one triangle.
    let mut runs = Vec::new();
    let mut start = 0;
    for k in 1..=quad.len() {
        if k == quad.len() || quad[k].0 != quad[start].0 {
            runs.push((start, k));
            start = k;
        }
    }
    let chunk = runs.len().div_ceil(GRAM_CHUNKS).max(1);
    for (ci, part) in runs.chunks(chunk).enumerate() {
        let done: Vec<FaceGram> = part
            .par_iter()
            .map_init(GramScratch::new, |scratch, &(a, b)| {
                face_gram(space, nb, &quad[a..b], scratch)
            })
            .collect::<Result<_>>()?;
        // Scatter this chunk's faces in face order (and drop them: the per-face matrices of
        // all faces at once were most of the fit's memory).
        for (groups, g) in done {
            for (la, &ta) in groups.iter().enumerate() {
                for (lb, &tb) in groups.iter().enumerate() {
                    if ta < tb {
                        continue;
                    }
                    let blk = blocks.block_mut(ta, tb);
                    for p in 0..nb {
                        for q in 0..nb {
                            let (i, j) = (la * nb + p, lb * nb + q);
                            blk[p * nb + q] += if i >= j { g[(i, j)] } else { g[(j, i)] };
                        }
                    }
                }
            }
        }
        let finished = ((ci + 1) * chunk).min(runs.len());
        progress.report(
            "fit",
            Some(finished as f64 / runs.len().max(1) as f64),
            &format!(
                "thin-plate quadrature: {finished} of {} faces ({} points each)",
                runs.len(),
                quadrature_barycentric().len()
            ),
        );
    }
    // Clean every thread of the pool once after the phase (as the other faer phases do).
    crate::numeric::simd::clear_upper_state();
    Ok(())
}

/// The triangles whose basis functions one face's quadrature meets, and the lower triangle of
/// their Gram matrix (local columns `position in the list × nb + β`).
type FaceGram = (Vec<u32>, Mat<f64>);

/// Per worker thread scratch of [`face_gram`] (reused from face to face).
struct GramScratch {
    ws: Workspace,
    /// Per point: the local triangle ids met there (in the order the space lists them),
    /// flattened, with `point_groups[r]..point_groups[r + 1]` the range of point `r`.
    keys: Vec<u32>,
    point_groups: Vec<usize>,
    /// Per point and function met: √w·(∂xx, √2 ∂xy, ∂yy), in the order of the point's keys.
    vals: Vec<[f64; 3]>,
    point_vals: Vec<usize>,
    /// The distinct key lists (as ranges of a point's keys) and their points.
    sets: Vec<(usize, Vec<usize>)>,
    /// The dense matrix `V` of one key list's points (three rows per point).
    v: Mat<f64>,
}

impl GramScratch {
    fn new() -> GramScratch {
        GramScratch {
            // Quadrature and data rows: double precision suffices (module docs, *Precision*).
            ws: Workspace::with_precision(Precision::Double),
            keys: Vec::new(),
            point_groups: Vec::new(),
            vals: Vec::new(),
            point_vals: Vec::new(),
            sets: Vec::new(),
            v: Mat::zeros(0, 0),
        }
    }
}

/// The thin-plate Gram matrix of one face's quadrature points `quad` ([`energy_gram`]).
///
/// Each point meets the basis functions of a few triangles only (those whose support contains
/// it), and points near the same corner meet the same triangles. So the points are grouped by
/// the list of triangles they meet (in order of first appearance); each group's scaled second
/// partials form a dense matrix `V` with no zero columns, and the lower triangle of `VᵀV`
/// (faer, sequential: the faces are the parallelism) is added into the face's Gram matrix. A
/// dense `V` over all of the face's points and triangles was mostly zeros: the same products
/// cost several times the flops, and zeroing it was a visible part of the profile.
fn face_gram<S: SplineSpace + ?Sized>(
    space: &S,
    nb: usize,
    quad: &[(u32, Point, f64)],
    sc: &mut GramScratch,
) -> Result<FaceGram> {
    let np2 = n_partials(2);
    let mut groups: Vec<u32> = Vec::new();
    sc.keys.clear();
    sc.vals.clear();
    sc.point_groups.clear();
    sc.point_vals.clear();
    sc.point_groups.push(0);
    sc.point_vals.push(0);
    for &(f, u, w) in quad {
        let m = space.basis_at(f, u, 2, &mut sc.ws)?;
        // Scaled second partials √w·(∂xx, √2 ∂xy, ∂yy): VᵀV sums w(∂xx² + 2∂xy² + ∂yy²).
        let sw = [w.sqrt(), (2.0 * w).sqrt(), w.sqrt()];
        for (gi, g) in sc.ws.indices[..m].chunks(nb).enumerate() {
            let t = g[0] / nb as u32;
            let lg = match groups.iter().position(|&x| x == t) {
                Some(i) => i,
                None => {
                    groups.push(t);
                    groups.len() - 1
                }
            };
            sc.keys.push(lg as u32);
            for p in 0..g.len() {
                let v = &sc.ws.values[(gi * nb + p) * np2..];
                sc.vals.push([sw[0] * v[3], sw[1] * v[4], sw[2] * v[5]]);
            }
        }
        sc.point_groups.push(sc.keys.len());
        sc.point_vals.push(sc.vals.len());
    }
    // Group the points by their key lists (first appearance order: deterministic).
    sc.sets.clear();
    let n_points = quad.len();
    for r in 0..n_points {
        let key = &sc.keys[sc.point_groups[r]..sc.point_groups[r + 1]];
        let found = sc
            .sets
            .iter()
            .position(|(r0, _)| &sc.keys[sc.point_groups[*r0]..sc.point_groups[*r0 + 1]] == key);
        match found {
            Some(i) => sc.sets[i].1.push(r),
            None => sc.sets.push((r, vec![r])),
        }
    }
    let cols = groups.len() * nb;
    let mut g = Mat::<f64>::zeros(cols, cols);
    for (r0, points) in &sc.sets {
        let key = &sc.keys[sc.point_groups[*r0]..sc.point_groups[*r0 + 1]];
        let (rows, m) = (
            3 * points.len(),
            sc.point_vals[*r0 + 1] - sc.point_vals[*r0],
        );
        if m == 0 {
            continue;
        }
        if sc.v.nrows() < rows || sc.v.ncols() < m {
            sc.v = Mat::zeros(rows.max(sc.v.nrows()), m.max(sc.v.ncols()));
        }
        // Every entry of this V is written: each of its points meets exactly these functions.
        let mut v = sc.v.as_mut().submatrix_mut(0, 0, rows, m);
        for (i, &r) in points.iter().enumerate() {
            let vals = &sc.vals[sc.point_vals[r]..sc.point_vals[r + 1]];
            for (j, d) in vals.iter().enumerate() {
                for (c, dc) in d.iter().enumerate() {
                    v[(3 * i + c, j)] = *dc;
                }
            }
        }
        let v = v.as_ref();
        let mut gs = Mat::<f64>::zeros(m, m);
        faer::linalg::matmul::triangular::matmul(
            gs.as_mut(),
            BlockStructure::TriangularLower,
            faer::Accum::Replace,
            v.transpose(),
            BlockStructure::Rectangular,
            v,
            BlockStructure::Rectangular,
            1.0,
            faer::Par::Seq,
        );
        // Local column of the set's column j: its triangle's local id × nb + β.
        let col = |j: usize| key[j / nb] as usize * nb + j % nb;
        for j2 in 0..m {
            for j1 in j2..m {
                let (c1, c2) = (col(j1), col(j2));
                let x = gs[(j1, j2)];
                if c1 == c2 && j1 != j2 {
                    // One triangle listed twice at a point: both cross terms land here.
                    g[(c1, c1)] += 2.0 * x;
                } else {
                    g[(c1.max(c2), c1.min(c2))] += x;
                }
            }
        }
    }
    // Leave this thread's vector registers clean for the next triangle's basis evaluations
    // (`crate::numeric::simd`).
    crate::numeric::simd::clear_upper_state_here();
    Ok((groups, g))
}

/// Chunks of faces between two progress reports of the fit's quadrature ([`fit_with_progress`]).
pub const GRAM_CHUNKS: usize = 20;

/// The input checks of [`fit`]: sizes of `initial` and of every target, faces in range, finite
/// parameters, admissible weights.
fn check_fit_inputs<S: SplineSpace + ?Sized>(
    space: &S,
    data: &[DataPoint],
    initial: &[f64],
    dim: usize,
    opts: &FitOptions,
) -> Result<()> {
    let nc = space.n_control_points();
    if initial.len() != nc * dim {
        return Err(Error::input(format!(
            "fit: {} initial numbers for {nc} control points of dimension {dim}",
            initial.len()
        )));
    }
    if data.is_empty() {
        return Err(Error::input("fit: no data points"));
    }
    let nf = space.n_triangles() as u32;
    for (k, p) in data.iter().enumerate() {
        if p.face >= nf
            || p.target.len() != dim
            || !p.param[0].is_finite()
            || !p.param[1].is_finite()
        {
            return Err(Error::input(format!(
                "fit: data point {k} has face {} (of {nf}) or {} target coordinates (need {dim})",
                p.face,
                p.target.len()
            )));
        }
    }
    if !(opts.smoothing >= 0.0 && opts.ridge > 0.0) {
        return Err(Error::input("fit: smoothing must be ≥ 0 and ridge > 0"));
    }
    Ok(())
}

/// The lower triangle of the normal matrix `H = D + λ T + γ I` of [`fit`] (data Gram `D`,
/// thin-plate Gram `T`), with the ridge diagonal also on control points no block touches.
fn normal_matrix(
    data_blocks: &Blocks,
    energy_blocks: &Blocks,
    nc: usize,
    nb: usize,
    lam: f64,
    gamma: f64,
) -> Result<SparseColMat<usize, f64>> {
    // Assemble H = D + λ T + γ I (lower triangle).
    let mut trip: Vec<Triplet<usize, usize, f64>> = Vec::new();
    let mut merged: BTreeMap<(u32, u32), usize> = data_blocks.index.clone();
    for k in energy_blocks.index.keys() {
        merged.entry(*k).or_insert(usize::MAX);
    }
    for &(a, b) in merged.keys() {
        let db = data_blocks
            .index
            .get(&(a, b))
            .map(|&o| &data_blocks.data[o..o + nb * nb]);
        let eb = energy_blocks
            .index
            .get(&(a, b))
            .map(|&o| &energy_blocks.data[o..o + nb * nb]);
        for p in 0..nb {
            for q in 0..nb {
                let (i, j) = (a as usize * nb + p, b as usize * nb + q);
                if i < j {
                    continue;
                }
                let mut v =
                    db.map_or(0.0, |x| x[p * nb + q]) + lam * eb.map_or(0.0, |x| x[p * nb + q]);
                if i == j {
                    v += gamma;
                }
                if v != 0.0 || i == j {
                    trip.push(Triplet::new(i, j, v));
                }
            }
        }
    }
    // Control points touched by nothing still need their ridge diagonal.
    let mut touched = vec![false; nc / nb];
    for &(a, b) in merged.keys() {
        if a == b {
            touched[a as usize] = true;
        }
    }
    for (t, &tt) in touched.iter().enumerate() {
        if !tt {
            for p in 0..nb {
                trip.push(Triplet::new(t * nb + p, t * nb + p, gamma));
            }
        }
    }
    SparseColMat::<usize, f64>::try_new_from_triplets(nc, nc, &trip)
        .map_err(|e| Error::numerical(format!("fit: could not assemble the normal matrix ({e:?})")))
}

/// Least-squares fit of the control points to data with a thin-plate fairness term (module
/// docs). `initial` (`dim` per control point) is the ridge's anchor.
pub fn fit<S: SplineSpace + ?Sized>(
    space: &S,
    data: &[DataPoint],
    initial: &[f64],
    dim: usize,
    opts: &FitOptions,
) -> Result<(Vec<f64>, FitReport)> {
    fit_with_progress(space, data, initial, dim, opts, &mut NoProgress)
}

/// [`fit`], reporting the fraction of its thin-plate quadrature done (stage `"fit"`, after each
/// of [`GRAM_CHUNKS`] chunks of faces) and the solve.
pub fn fit_with_progress<S: SplineSpace + ?Sized>(
    space: &S,
    data: &[DataPoint],
    initial: &[f64],
    dim: usize,
    opts: &FitOptions,
    progress: &mut dyn Progress,
) -> Result<(Vec<f64>, FitReport)> {
    check_fit_inputs(space, data, initial, dim, opts)?;
    let nc = space.n_control_points();
    let nb = space.per_triangle();
    // Scale of the energy term.
    let (hbar, area) = space.domain_scale();
    let kdata = data.len() as f64;
    let lam = opts.smoothing * hbar * hbar / area;

    let mut data_blocks = Blocks::new(nb);
    let mut energy_blocks = Blocks::new(nb);
    let mut rhs = vec![0.0; nc * dim];
    // Quadrature and data rows: double precision suffices (module docs, *Precision*).
    let mut ws = Workspace::with_precision(Precision::Double);
    for p in data {
        let m = space.basis_at(p.face, p.param, 0, &mut ws)?;
        data_blocks.add_point(&ws.indices[..m], &ws.values, 1, &[(0, 1.0 / kdata)]);
        for i in 0..m {
            let g = ws.indices[i] as usize;
            for d in 0..dim {
                rhs[g * dim + d] += ws.values[i] * p.target[d] / kdata;
            }
        }
    }
    energy_gram(space, &mut energy_blocks, progress)?;
    // Ridge relative to the data term's diagonal.
    let mut diag_mean = 0.0;
    for (&(a, b), &off) in &data_blocks.index {
        if a == b {
            for p in 0..nb {
                diag_mean += data_blocks.data[off + p * nb + p];
            }
        }
    }
    diag_mean = (diag_mean / nc as f64).max(1e-300);
    let gamma = opts.ridge * diag_mean;
    for k in 0..nc * dim {
        rhs[k] += gamma * initial[k];
    }
    let h = normal_matrix(&data_blocks, &energy_blocks, nc, nb, lam, gamma)?;
    progress.report(
        "fit",
        Some(1.0),
        &format!("sparse Cholesky of the {nc} × {nc} normal matrix"),
    );
    let llt = Cholesky::factor(h.as_ref()).map_err(|e| {
        Error::numerical(format!("fit: Cholesky of the normal matrix failed ({e:?})"))
    })?;
    let mut sol = Mat::<f64>::zeros(nc, dim);
    for k in 0..nc {
        for d in 0..dim {
            sol[(k, d)] = rhs[k * dim + d];
        }
    }
    llt.solve_in_place(sol.as_mut());
    drop(llt);
    let mut x = vec![0.0; nc * dim];
    for k in 0..nc {
        for d in 0..dim {
            x[k * dim + d] = sol[(k, d)];
        }
    }
    if x.iter().any(|v| !v.is_finite()) {
        return Err(Error::numerical(
            "fit: the normal equations produced non-finite control points",
        ));
    }
    // Objective pieces and the residual of the normal equations (the products are independent
    // of each other: run side by side, each with its own operations in its own order).
    let hx = |c: &[f64]| {
        rayon::join(
            || {
                let mut y = vec![0.0; nc * dim];
                data_blocks.apply(c, dim, &mut y);
                y
            },
            || {
                let mut t = vec![0.0; nc * dim];
                energy_blocks.apply(c, dim, &mut t);
                t
            },
        )
    };
    let ((dx, tx), (_, t0)) = rayon::join(|| hx(&x), || hx(initial));
    let mut res2 = 0.0;
    let mut b2 = 0.0;
    for k in 0..nc * dim {
        let r = dx[k] + lam * tx[k] + gamma * x[k] - rhs[k];
        res2 += r * r;
        b2 += rhs[k] * rhs[k];
    }
    let energy = |c: &[f64], t: &[f64]| c.iter().zip(t).map(|(a, b)| a * b).sum::<f64>();
    let mut errs = Vec::with_capacity(data.len());
    let mut out = vec![0.0; dim];
    let objective = |c: &[f64],
                     e: f64,
                     errs: &mut Vec<f64>,
                     ws: &mut Workspace,
                     out: &mut [f64]|
     -> Result<f64> {
        errs.clear();
        let mut s = 0.0;
        for p in data {
            evaluate(space, c, dim, p.face, p.param, 0, ws, out)?;
            let d2: f64 = (0..dim).map(|d| (out[d] - p.target[d]).powi(2)).sum();
            errs.push(d2.sqrt());
            s += d2;
        }
        let ridge: f64 = c.iter().zip(initial).map(|(a, b)| (a - b) * (a - b)).sum();
        Ok(s / kdata + lam * e + gamma * ridge)
    };
    let e0 = energy(initial, &t0);
    let e1 = energy(&x, &tx);
    let (obj0, obj1) = rayon::join(
        || {
            let mut ws0 = Workspace::with_precision(Precision::Double);
            objective(initial, e0, &mut Vec::new(), &mut ws0, &mut vec![0.0; dim])
        },
        || objective(&x, e1, &mut errs, &mut ws, &mut out),
    );
    let (obj0, obj1) = (obj0?, obj1?);
    let rms = (errs.iter().map(|e| e * e).sum::<f64>() / kdata).sqrt();
    let max = errs.iter().fold(0.0f64, |a, &b| a.max(b));
    Ok((
        x,
        FitReport {
            data_points: data.len(),
            rms_error: rms,
            max_error: max,
            energy_before: e0,
            energy_after: e1,
            objective_before: obj0,
            objective_after: obj1,
            relative_residual: (res2 / b2.max(1e-300)).sqrt(),
        },
    ))
}
