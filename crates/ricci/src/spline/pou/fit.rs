//! Least-squares fit of the control points of a partition-of-unity surface to the mesh
//! (the construction of paper 004 §4 with the fitting of paper 003 §5 / paper 000 §5):
//!
//! `min (1/K) Σ_k ‖F(p_k) − x_k‖² + λ (h̄²/|D|) Σ_f A_f (|F_xx|² + 2|F_xy|² + |F_yy|²)(q_f)
//!       + γ ‖P − P⁰‖²`
//!
//! over the control points `P`. Data: every vertex of the domain (target: its position) and
//! the centre `λ = (⅓, ⅓, ⅓)` of every face (target: the centroid of the input triangle). The
//! fairness term is the thin-plate energy in the chart of the face's first vertex at the face
//! centre `q_f`, weighted by the face's area `A_f` in that chart; `h̄` (mean chart edge length)
//! and `|D|` (total chart area) make `λ` scale-free. `γ` is a tiny ridge (relative to the mean
//! diagonal of the data term) towards `P⁰` = the vertex positions. The normal equations are
//! assembled column by column from the sparse rows and solved by faer's sparse Cholesky.

use std::time::Instant;

use faer::linalg::solvers::Solve;
use faer::sparse::{SparseColMat, Triplet};
use faer::{Mat, Side};
use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::layout::isometry::Complex;

use super::atlas::point_in_face;
use super::local::LocalPolynomial;
use super::surface::{PouBasis, PouSurface};

/// Options of [`fit`].
#[derive(Debug, Clone, Copy)]
pub struct PouFitOptions {
    /// Weight `λ` of the scale-free thin-plate term.
    pub smoothing: f64,
    /// Ridge `γ` towards the vertex positions, relative to the data term's mean diagonal.
    pub ridge: f64,
}

impl Default for PouFitOptions {
    fn default() -> Self {
        PouFitOptions {
            smoothing: 1e-4,
            ridge: 1e-9,
        }
    }
}

/// What [`fit`] reached.
#[derive(Debug, Clone, serde::Serialize)]
pub struct PouFitReport {
    pub data_points: usize,
    pub fairness_points: usize,
    /// Non-zeros of the normal matrix (lower triangle).
    pub normal_nonzeros: usize,
    /// Mean number of bases at a data point.
    pub mean_bases_per_point: f64,
    /// RMS and max of `‖F(p_k) − x_k‖` over the data.
    pub rms_error: f64,
    pub max_error: f64,
    /// `‖H P − b‖ / ‖b‖` after the solve.
    pub relative_residual: f64,
    pub seconds: f64,
}

/// One sparse row: `(column, value)`, columns merged.
type Row = Vec<(u32, f64)>;

/// Three fairness rows of a face, their targets, its chart area and edge-length sum.
type Fair = ([Row; 3], [[f64; 3]; 3], f64, f64);

fn merge(mut r: Row) -> Row {
    r.sort_unstable_by_key(|e| e.0);
    let mut out: Row = Vec::with_capacity(r.len());
    for (c, v) in r {
        match out.last_mut() {
            Some(l) if l.0 == c => l.1 += v,
            _ => out.push((c, v)),
        }
    }
    out
}

/// Fit the control points (module docs). Returns the control points and the report.
///
/// With local polynomials `Qᵢ` ([`super::local`]; empty for none) the unknowns are still the
/// constants `Pᵢ`: `G = Σ wᵢ Qᵢ` is fixed, so the data targets become `x_k − G(p_k)` and the
/// thin-plate rows get the right-hand side `−∂²G` (the fairness acts on the whole `F`).
pub fn fit(
    basis: &PouBasis,
    local: &[LocalPolynomial],
    opts: &PouFitOptions,
) -> Result<(Vec<[f64; 3]>, PouFitReport)> {
    let t0 = Instant::now();
    let atlas = basis.atlas;
    let m = &atlas.mesh;
    let (nv, nf) = (m.n_vertices(), m.n_faces());
    if !(opts.smoothing >= 0.0 && opts.ridge > 0.0) {
        return Err(Error::input("pou fit: smoothing must be ≥ 0 and ridge > 0"));
    }
    let pos = &atlas.positions;
    if !local.is_empty() && local.len() != nv {
        return Err(Error::input(format!(
            "pou fit: {} local polynomials for {nv} vertices",
            local.len()
        )));
    }
    // G = Σ wᵢ Qᵢ: the surface with zero constants.
    let g = PouSurface {
        basis: PouBasis::new(atlas, basis.radii.clone()),
        control: vec![[0.0; 3]; nv],
        local: local.to_vec(),
    };
    let data = data_rows(basis, &g)?;
    let fair = fairness_rows(basis, &g)?;
    let area: f64 = fair.iter().map(|f| f.2).sum();
    let hbar = fair.iter().map(|f| f.3).sum::<f64>() / (3 * nf).max(1) as f64;
    let kdata = data.len() as f64;
    let lam = opts.smoothing * hbar * hbar / area.max(1e-300);
    // Weighted rows of the stacked system.
    let mut rows: Vec<Row> = Vec::with_capacity(data.len() + 3 * nf);
    let sd = 1.0 / kdata.sqrt();
    let mut rhs = vec![[0.0; 3]; nv];
    for (r, x) in &data {
        for &(c, v) in r {
            for d in 0..3 {
                rhs[c as usize][d] += v * x[d] / kdata;
            }
        }
        rows.push(r.iter().map(|&(c, v)| (c, v * sd)).collect());
    }
    let n_data_rows = rows.len();
    for (rs, ts, a, _) in &fair {
        let s = (lam * a).sqrt();
        for (r, t) in rs.iter().zip(ts) {
            for &(c, v) in r {
                for d in 0..3 {
                    rhs[c as usize][d] += v * t[d] * lam * a;
                }
            }
            rows.push(r.iter().map(|&(c, v)| (c, v * s)).collect());
        }
    }
    let mean_bases = data.iter().map(|d| d.0.len()).sum::<usize>() as f64 / kdata;
    // Data-term diagonal for the ridge.
    let mut diag_data = 0.0;
    for r in &rows[..n_data_rows] {
        for &(_, v) in r {
            diag_data += v * v;
        }
    }
    let gamma = opts.ridge * (diag_data / nv as f64).max(1e-300);
    let (trip, nnz) = normal_triplets(&rows, nv, gamma);
    for (k, x) in rhs.iter_mut().enumerate() {
        for d in 0..3 {
            x[d] += gamma * pos[k][d];
        }
    }
    let control = solve_normal(&trip, &rhs)?;
    let relative_residual = normal_residual(&rows, &control, gamma, &rhs);
    let errs: Vec<f64> = data
        .iter()
        .map(|(r, x)| {
            let mut p = [0.0; 3];
            for &(c, v) in r {
                for d in 0..3 {
                    p[d] += v * control[c as usize][d];
                }
            }
            ((p[0] - x[0]).powi(2) + (p[1] - x[1]).powi(2) + (p[2] - x[2]).powi(2)).sqrt()
        })
        .collect();
    let rms = (errs.iter().map(|e| e * e).sum::<f64>() / kdata).sqrt();
    let max = errs.iter().fold(0.0f64, |a, &b| a.max(b));
    Ok((
        control,
        PouFitReport {
            data_points: data.len(),
            fairness_points: nf,
            normal_nonzeros: nnz,
            mean_bases_per_point: mean_bases,
            rms_error: rms,
            max_error: max,
            relative_residual,
            seconds: t0.elapsed().as_secs_f64(),
        },
    ))
}

/// Data rows (vertices, then face centres) with their targets minus `G` (the surface `g` with
/// zero constants; nothing is subtracted without local polynomials).
fn data_rows(basis: &PouBasis, g: &PouSurface) -> Result<Vec<(Row, [f64; 3])>> {
    let atlas = basis.atlas;
    let m = &atlas.mesh;
    let (nv, nf) = (m.n_vertices(), m.n_faces());
    let pos = &atlas.positions;
    let has_local = !g.local.is_empty();
    (0..nv + nf)
        .into_par_iter()
        .map(|k| -> Result<(Row, [f64; 3])> {
            let mut w = Vec::new();
            let minus_g = |v: u32, z: Complex, x: [f64; 3]| -> Result<[f64; 3]> {
                if !has_local {
                    return Ok(x);
                }
                let gv = g.value(v, z, &mut Vec::new())?;
                Ok([x[0] - gv[0], x[1] - gv[1], x[2] - gv[2]])
            };
            if k < nv {
                let z = Complex::new(0.0, 0.0);
                basis.weights(k as u32, z, &mut w)?;
                Ok((merge(w), minus_g(k as u32, z, pos[k])?))
            } else {
                let f = (k - nv) as u32;
                let vs = m.face(f);
                let z = atlas
                    .chart_point(vs[0], f, [1.0 / 3.0; 3])
                    .ok_or_else(|| Error::input(format!("face {f} is missing from its chart")))?;
                basis.weights(vs[0], z, &mut w)?;
                let mut x = [0.0; 3];
                for v in vs {
                    for d in 0..3 {
                        x[d] += pos[v as usize][d] / 3.0;
                    }
                }
                Ok((merge(w), minus_g(vs[0], z, x)?))
            }
        })
        .collect::<Result<_>>()
}

/// Fairness rows: three per face (the scaled second partials of the weights at the face
/// centre in the chart of its first vertex), their targets (`−∂²G`), the face's chart area
/// and the sum of its chart edge lengths.
fn fairness_rows(basis: &PouBasis, g: &PouSurface) -> Result<Vec<Fair>> {
    let atlas = basis.atlas;
    let m = &atlas.mesh;
    let nf = m.n_faces();
    let has_local = !g.local.is_empty();
    (0..nf as u32)
        .into_par_iter()
        .map(|f| -> Result<Fair> {
            let v = m.face(f)[0];
            let i = atlas
                .star_index(v, f)
                .ok_or_else(|| Error::input(format!("face {f} is missing from its chart")))?;
            let z3 = atlas.charts[v as usize].star[i].z;
            let area = 0.5
                * ((z3[1] - z3[0]).re * (z3[2] - z3[0]).im
                    - (z3[1] - z3[0]).im * (z3[2] - z3[0]).re)
                    .abs();
            let edges = (0..3)
                .map(|k| (z3[(k + 1) % 3] - z3[k]).norm())
                .sum::<f64>();
            let z = point_in_face(&z3, [1.0 / 3.0; 3]);
            let mut w = Vec::new();
            basis.weight_jets(v, z, 2, &mut w)?;
            let s2 = std::f64::consts::SQRT_2;
            let terms = [(2, 0, 1.0), (1, 1, s2), (0, 2, 1.0)];
            let rows = terms
                .map(|(a, b, s)| merge(w.iter().map(|(c, j)| (*c, s * j.partial(a, b))).collect()));
            let mut targets = [[0.0; 3]; 3];
            if has_local {
                let gj = g.jets(v, z, 2)?;
                for (t, (a, b, s)) in targets.iter_mut().zip(terms) {
                    for d in 0..3 {
                        t[d] = -s * gj[d].partial(a, b);
                    }
                }
            }
            Ok((rows, targets, area, edges))
        })
        .collect::<Result<_>>()
}

/// The lower triangle of `H = Aᵀ A + γ I` (rows `rows` of the stacked matrix `A`, `nv`
/// columns) as triplets, column by column, and their number.
fn normal_triplets(
    rows: &[Row],
    nv: usize,
    gamma: f64,
) -> (Vec<Triplet<usize, usize, f64>>, usize) {
    // Columns of the stacked matrix.
    let mut col_rows: Vec<Vec<(u32, f64)>> = vec![Vec::new(); nv];
    for (ri, r) in rows.iter().enumerate() {
        for &(c, v) in r {
            col_rows[c as usize].push((ri as u32, v));
        }
    }
    // H = Aᵀ A + γ I, lower triangle, column by column.
    let cols: Vec<Vec<(u32, f64)>> = (0..nv)
        .into_par_iter()
        .map_init(
            || (vec![0.0f64; nv], vec![false; nv], Vec::<u32>::new()),
            |(acc, mark, touched), i| {
                for &(r, a) in &col_rows[i] {
                    for &(j, b) in &rows[r as usize] {
                        if (j as usize) < i {
                            continue;
                        }
                        if !mark[j as usize] {
                            mark[j as usize] = true;
                            touched.push(j);
                        }
                        acc[j as usize] += a * b;
                    }
                }
                acc[i] += gamma;
                if !mark[i] {
                    mark[i] = true;
                    touched.push(i as u32);
                }
                let out: Vec<(u32, f64)> = touched.iter().map(|&j| (j, acc[j as usize])).collect();
                for &j in touched.iter() {
                    acc[j as usize] = 0.0;
                    mark[j as usize] = false;
                }
                touched.clear();
                out
            },
        )
        .collect();
    let mut trip = Vec::new();
    for (i, c) in cols.iter().enumerate() {
        for &(j, v) in c {
            trip.push(Triplet::new(j as usize, i, v));
        }
    }
    let nnz = trip.len();
    (trip, nnz)
}

/// Solve `H P = b` (lower triangle of `H` as triplets) by faer's sparse Cholesky.
fn solve_normal(trip: &[Triplet<usize, usize, f64>], rhs: &[[f64; 3]]) -> Result<Vec<[f64; 3]>> {
    let nv = rhs.len();
    let h = SparseColMat::<usize, f64>::try_new_from_triplets(nv, nv, trip).map_err(|e| {
        Error::numerical(format!(
            "pou fit: could not assemble the normal matrix ({e:?})"
        ))
    })?;
    let llt = h.sp_cholesky(Side::Lower).map_err(|e| {
        Error::numerical(format!(
            "pou fit: Cholesky of the normal matrix failed ({e:?})"
        ))
    })?;
    let mut sol = Mat::<f64>::zeros(nv, 3);
    for k in 0..nv {
        for d in 0..3 {
            sol[(k, d)] = rhs[k][d];
        }
    }
    llt.solve_in_place(sol.as_mut());
    drop(llt);
    crate::numeric::simd::clear_upper_state();
    let control: Vec<[f64; 3]> = (0..nv)
        .map(|k| [sol[(k, 0)], sol[(k, 1)], sol[(k, 2)]])
        .collect();
    if control.iter().flatten().any(|x| !x.is_finite()) {
        return Err(Error::numerical(
            "pou fit: the normal equations produced non-finite control points",
        ));
    }
    Ok(control)
}

/// `‖H P − b‖ / ‖b‖` with `H P = Aᵀ(A P) + γ P`.
fn normal_residual(rows: &[Row], control: &[[f64; 3]], gamma: f64, rhs: &[[f64; 3]]) -> f64 {
    let nv = rhs.len();
    let mut hp = vec![[0.0; 3]; nv];
    for r in rows {
        let mut ap = [0.0; 3];
        for &(c, v) in r {
            for d in 0..3 {
                ap[d] += v * control[c as usize][d];
            }
        }
        for &(c, v) in r {
            for d in 0..3 {
                hp[c as usize][d] += v * ap[d];
            }
        }
    }
    let (mut res2, mut b2) = (0.0, 0.0);
    for k in 0..nv {
        for d in 0..3 {
            let r = hp[k][d] + gamma * control[k][d] - rhs[k][d];
            res2 += r * r;
            b2 += rhs[k][d] * rhs[k][d];
        }
    }
    (res2 / b2.max(1e-300)).sqrt()
}
