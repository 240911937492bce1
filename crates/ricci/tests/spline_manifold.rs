//! Manifold triangular B-splines (paper 000 §5): partition of unity on the spline domain,
//! evaluation independent of the chart and of the chart provider, C^{n−1} across every
//! interior edge (and not C^n, so the measurement can fail), fairing constraints, the G¹ fill
//! patch at the extraordinary point, and the end-to-end construction on real meshes.
//!
//! Real-mesh tests read `RICCI_MESHES` and skip with a note when it is unset.

use ricci::atlas::FlatCharts;
use ricci::mesh::io::read_surface;
use ricci::mesh::Surface;
use ricci::progress::NoProgress;
use ricci::spline::dms::{KnotOptions, Workspace};
use ricci::spline::fit::{constraint_residuals, fair, fairness_constraints};
use ricci::spline::hole::Hole;
use ricci::spline::manifold::{rotate_partials, LocalCharts, ManifoldSpace};
use ricci::spline::simplex::n_partials;
use ricci::spline::surface::{
    continuity, flat_domain, run, FlatDomain, MeshDistance, Singularity, SplineOptions,
};
use std::path::PathBuf;

fn mesh_dir() -> Option<PathBuf> {
    match ricci_meshes() {
        Some(d) => Some(d),
        None => {
            eprintln!("note: RICCI_MESHES is not set; skipping the real-mesh spline tests");
            None
        }
    }
}

fn load(name: &str) -> Option<Surface> {
    let dir = mesh_dir()?;
    Some(read_surface(&dir.join(name)).expect(name).0)
}

fn genus2() -> Surface {
    ricci::mesh::generate::genus(2, 16).unwrap()
}

const SAMPLES: [[f64; 3]; 6] = [
    [1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0],
    [0.7, 0.2, 0.1],
    [0.05, 0.15, 0.8],
    [1.0, 0.0, 0.0],
    [0.0, 0.5, 0.5],
    [0.3, 0.0, 0.7],
];

/// Σ N = 1 at sample points (vertices and edge points included) of every `stride`-th active face.
fn check_partition_of_unity<A: FlatCharts + Sync>(space: &ManifoldSpace<'_, A>, stride: usize) {
    let mut ws = Workspace::default();
    let mut worst: f64 = 0.0;
    let nf = space.charts().mesh().n_faces() as u32;
    for f in (0..nf).step_by(stride) {
        if !space.is_active(f) {
            continue;
        }
        for b in SAMPLES {
            let s = space.basis_sum(f, b, &mut ws).unwrap();
            worst = worst.max((s - 1.0).abs());
        }
    }
    assert!(worst < 1e-9, "partition of unity off by {worst:.2e}");
}

/// What [`check_chart_independence`] asserts: partials at face centroids relative to the
/// largest partial of that order there, partials anywhere relative to the size of the terms of
/// the sum (`A_k`, see below), and partials anywhere relative to the largest partial.
#[derive(Clone, Copy)]
struct ChartTolerances {
    centroid: f64,
    terms: f64,
    anywhere: f64,
}

/// The issue's 1e-10, relative to the largest partial of each order at the point, everywhere:
/// `LocalCharts` on genus2:16, eight, 3holes, genus3 and fertility (measured 1.2e-12 …
/// 6.1e-12, with the double-double recurrence; in double precision 2e-8 … 2.1e-7).
const ISSUE: ChartTolerances = ChartTolerances {
    centroid: 1e-10,
    terms: 1e-10,
    anywhere: 1e-10,
};

/// Over the paper's affine atlas (genus2:16, eight.off): its central chart holds the graded
/// cone neighbourhood's faces (down to 1e-8 of the chart) in one coordinate system, so a face's
/// corners there carry a relative error ~1e-8 (measured anywhere 2.8e-10, at centroids 4.3e-11).
const ATLAS: ChartTolerances = ChartTolerances {
    centroid: 1e-10,
    terms: 1e-10,
    anywhere: 1e-9,
};

/// Evaluate at the same surface point in every chart containing the face: values agree to
/// 1e-10 of the bounding-box diagonal; partials up to `n − 1`, rotated by the transition into
/// the canonical chart, agree to `tol` ([`ChartTolerances`]):
/// - at face centroids, relative to the largest partial of that order at the point;
/// - everywhere (edge midpoints and points near vertices included) relative to the size of
///   the terms of the sum, `A_k = max_d Σ_β |c_{β,d} − F_d| max_{|α|=k} |∂^α N_β|`
///   (`Σ_β ∂^α N_β = 0` lets `F` be subtracted), and relative to the largest partial.
///
/// What it takes (module docs of `spline::manifold`, *Conditioning*): at edge midpoints and
/// near vertices the thin basis functions (knot sets from one or two clouds) have order-2
/// partials up to 10³ × and order-3 partials up to 10⁸ × those of `F` (relative to the face);
/// their sum cancels. In double precision the recurrence's rounding, each basis's own rounding
/// of the point's offset, and the rounding of `Σ c N` with `|c|` the distance from the origin
/// each moved `∂²F` by 1e-9 … 2e-7 — as much as moving the point by one ulp in the same chart.
fn check_chart_independence<A: FlatCharts + Sync>(
    space: &ManifoldSpace<'_, A>,
    control: &[f64],
    stride: usize,
    tol: ChartTolerances,
) -> usize {
    let charts = space.charts();
    let n = space.degree();
    let order = n - 1;
    let np = n_partials(order);
    let diag = Surface {
        mesh: charts.mesh().clone(),
        positions: charts.positions().to_vec(),
        uvs: None,
    }
    .diagonal();
    let mut ws = Workspace::default();
    let mut compared = 0;
    let (mut worst_v, mut worst_d): (f64, f64) = (0.0, 0.0);
    let (mut worst_terms, mut worst_centroid): (f64, f64) = (0.0, 0.0);
    let nf = charts.mesh().n_faces() as u32;
    for f in (0..nf).step_by(stride) {
        if !space.is_active(f) {
            continue;
        }
        let c0 = space.canonical_chart(f);
        for (si, b) in [SAMPLES[0], SAMPLES[2], SAMPLES[4]].into_iter().enumerate() {
            let mut base = vec![0.0; np * 3];
            space
                .evaluate(control, 3, f, b, order, &mut ws, &mut base)
                .unwrap();
            // A_k (see the doc comment) from the basis at the point.
            let m = space
                .basis_at_point(f, space.face_point(f, b), order, &mut ws)
                .unwrap();
            let terms: Vec<f64> = (0..=order)
                .map(|k| {
                    (0..3)
                        .map(|d| {
                            (0..m)
                                .map(|j| {
                                    let g = ws.indices[j] as usize;
                                    let dn = (n_partials(k) - k - 1..n_partials(k))
                                        .map(|i| ws.values[j * np + i].abs())
                                        .fold(0.0, f64::max);
                                    (control[g * 3 + d] - base[d]).abs() * dn
                                })
                                .sum::<f64>()
                        })
                        .fold(1e-300, f64::max)
                })
                .collect();
            let scale: Vec<f64> = (0..=order)
                .map(|k| {
                    (n_partials(k) - k - 1..n_partials(k))
                        .flat_map(|i| (0..3).map(move |d| (i, d)))
                        .map(|(i, d)| base[i * 3 + d].abs())
                        .fold(1e-300, f64::max)
                })
                .collect();
            for c in charts.charts_of_face(f) {
                let x = charts.face_coords(c, f).unwrap();
                let u = [
                    b[0] * x[0][0] + b[1] * x[1][0] + b[2] * x[2][0],
                    b[0] * x[0][1] + b[1] * x[1][1] + b[2] * x[2][1],
                ];
                let mut out = vec![0.0; np * 3];
                space
                    .evaluate_in_chart(control, 3, c, f, u, order, &mut ws, &mut out)
                    .unwrap();
                // Partials in chart c → canonical chart: u_c = m(u_0) with m: canon → c.
                let (m, _) = charts.transition(c0, c, f).unwrap();
                for d in 0..3 {
                    let mut col: Vec<f64> = (0..np).map(|k| out[k * 3 + d]).collect();
                    rotate_partials(order, m.rot, &mut col);
                    for k in 0..np {
                        out[k * 3 + d] = col[k];
                    }
                }
                for d in 0..3 {
                    worst_v = worst_v.max((out[d] - base[d]).abs() / diag);
                }
                for (k, sk) in scale.iter().enumerate().skip(1) {
                    for i in n_partials(k) - k - 1..n_partials(k) {
                        for d in 0..3 {
                            let e = (out[i * 3 + d] - base[i * 3 + d]).abs();
                            worst_d = worst_d.max(e / sk);
                            worst_terms = worst_terms.max(e / terms[k]);
                            if si == 0 {
                                worst_centroid = worst_centroid.max(e / sk);
                            }
                        }
                    }
                }
                compared += 1;
            }
        }
    }
    assert!(
        worst_v <= 1e-10,
        "values differ between charts by {worst_v:.2e}"
    );
    eprintln!(
        "chart independence ({compared} comparisons): values {worst_v:.1e} of the diagonal; partials {worst_d:.1e} of the partial, {worst_centroid:.1e} at centroids, {worst_terms:.1e} of the terms"
    );
    assert!(
        worst_centroid <= tol.centroid,
        "partials at centroids differ between charts by {worst_centroid:.2e}"
    );
    assert!(
        worst_terms <= tol.terms,
        "partials differ between charts by {worst_terms:.2e} of the size of the terms"
    );
    assert!(
        worst_d <= tol.anywhere,
        "partials differ between charts by {worst_d:.2e}"
    );
    compared
}

fn subdivided_and_faired<A: FlatCharts + Sync>(space: &ManifoldSpace<'_, A>, r: usize) -> Vec<f64> {
    let c0 = space.subdivision_control_points();
    fair(space, &c0, 3, r).unwrap().0
}

#[test]
fn rotation_of_partials_matches_a_rotated_polynomial() {
    // G(w) = w_x³ w_y − 2 w_x w_y² + w_y (degree 4), F(u) = G(rot u + t): compare all partials up
    // to order 4 with finite-difference-free closed forms via polynomial evaluation.
    use num_complex::Complex64 as C;
    let rot = C::from_polar(1.0, 0.83);
    let t = C::new(0.3, -1.2);
    let g = |x: f64, y: f64| x.powi(3) * y - 2.0 * x * y * y + y;
    let f = |x: f64, y: f64| {
        let w = rot * C::new(x, y) + t;
        g(w.re, w.im)
    };
    // Partials of G at w0 by exact formulas.
    let u0 = [0.4, 0.7];
    let w = rot * C::new(u0[0], u0[1]) + t;
    let (x, y) = (w.re, w.im);
    let gp = [
        g(x, y),
        3.0 * x * x * y - 2.0 * y * y,
        x.powi(3) - 4.0 * x * y + 1.0,
        6.0 * x * y,
        3.0 * x * x - 4.0 * y,
        -4.0 * x,
    ];
    let mut v = gp.to_vec();
    rotate_partials(2, rot, &mut v);
    // Partials of F by central differences (step 1e-4; error ~1e-7).
    let h = 1e-4;
    let fx = (f(u0[0] + h, u0[1]) - f(u0[0] - h, u0[1])) / (2.0 * h);
    let fy = (f(u0[0], u0[1] + h) - f(u0[0], u0[1] - h)) / (2.0 * h);
    let fxx = (f(u0[0] + h, u0[1]) - 2.0 * f(u0[0], u0[1]) + f(u0[0] - h, u0[1])) / (h * h);
    let fyy = (f(u0[0], u0[1] + h) - 2.0 * f(u0[0], u0[1]) + f(u0[0], u0[1] - h)) / (h * h);
    let fxy = (f(u0[0] + h, u0[1] + h) - f(u0[0] + h, u0[1] - h) - f(u0[0] - h, u0[1] + h)
        + f(u0[0] - h, u0[1] - h))
        / (4.0 * h * h);
    let want = [f(u0[0], u0[1]), fx, fy, fxx, fxy, fyy];
    for k in 0..6 {
        assert!(
            (v[k] - want[k]).abs() < 1e-5 * (1.0 + want[k].abs()),
            "partial {k}: {} vs {}",
            v[k],
            want[k]
        );
    }
}

#[test]
fn generated_genus2_partition_of_unity_charts_and_providers() {
    let s = genus2();
    let dom = flat_domain(&s, largest_valence(&s), &mut NoProgress).unwrap();
    let space = ManifoldSpace::new(&dom.charts, 3, &KnotOptions::default()).unwrap();
    let rep = space.report();
    assert!(rep.max_chart_residual < 1e-10, "{rep:?}");
    check_partition_of_unity(&space, 1);
    let control = subdivided_and_faired(&space, 1);
    let compared = check_chart_independence(&space, &control, 3, ISSUE);
    assert!(compared > 1000, "only {compared} chart comparisons");

    // A second, independently placed provider (every chart moved by a random rigid motion):
    // the same spline, values equal and partials related by the rotation between the two
    // providers' canonical charts.
    let charts = &dom.charts;
    let other = LocalCharts::new(
        charts.mesh().clone(),
        ricci::metric::IntrinsicMetric::euclidean(charts.lengths().to_vec()),
        charts.positions().to_vec(),
        charts.singular_vertices().to_vec(),
        Some(77),
    )
    .unwrap();
    let space2 = ManifoldSpace::new(&other, 3, &KnotOptions::default()).unwrap();
    let mut ws = Workspace::default();
    let np = n_partials(2);
    let mut worst: f64 = 0.0;
    let mut worst_d: f64 = 0.0;
    for f in 0..charts.mesh().n_faces() as u32 {
        if !space.is_active(f) {
            continue;
        }
        let a = space.canonical_coords(f);
        let b = space2.canonical_coords(f);
        let (m, _) = ricci::atlas::fit_rigid(&a, &b);
        for bary in [SAMPLES[0], SAMPLES[1], SAMPLES[4]] {
            let mut x = vec![0.0; np * 3];
            let mut y = vec![0.0; np * 3];
            space
                .evaluate(&control, 3, f, bary, 2, &mut ws, &mut x)
                .unwrap();
            space2
                .evaluate(&control, 3, f, bary, 2, &mut ws, &mut y)
                .unwrap();
            for d in 0..3 {
                let mut col: Vec<f64> = (0..np).map(|k| y[k * 3 + d]).collect();
                rotate_partials(2, m.rot, &mut col);
                for k in 0..np {
                    y[k * 3 + d] = col[k];
                }
            }
            for d in 0..3 {
                worst = worst.max((x[d] - y[d]).abs());
            }
            let s1 = (3..9).map(|i| x[i].abs()).fold(1e-300, f64::max);
            worst_d = worst_d.max((3..9).map(|i| (x[i] - y[i]).abs()).fold(0.0, f64::max) / s1);
        }
    }
    assert!(
        worst < 1e-10 * s.diagonal(),
        "providers differ by {worst:.2e}"
    );
    assert!(
        worst_d < 1e-6,
        "first partials differ between providers by {worst_d:.2e}"
    );
}

#[test]
fn continuity_is_c_n_minus_1_and_not_c_n() {
    let s = genus2();
    let dom = flat_domain(&s, largest_valence(&s), &mut NoProgress).unwrap();
    for n in [2usize, 3, 4] {
        let space = ManifoldSpace::new(&dom.charts, n, &KnotOptions::default()).unwrap();
        let control = subdivided_and_faired(&space, 1.min(n - 1));
        let rep = continuity(&space, &control, &[], 1e-8).unwrap();
        eprintln!("degree {n}: relative jumps {:?}", rep.relative_jumps);
        assert!(rep.chart_boundary_edges > 100, "{rep:?}");
        // Every order < n to 1e-8 (before the double-double recurrence and the partition-of-
        // unity form of `Σ c N`, order n − 1 reached only 4.5e-8 for n = 4).
        for k in 0..n {
            let tol = 1e-8;
            assert!(
                rep.relative_jumps[k] <= tol,
                "degree {n}: order {k} jumps by {:.2e}",
                rep.relative_jumps[k]
            );
        }
        // Order-n partials are piecewise constant and jump across knot lines: the
        // measurement sees it.
        assert!(
            rep.relative_jumps[n] > 1e-4,
            "degree {n}: order-{n} jump only {:.2e}",
            rep.relative_jumps[n]
        );
    }
}

#[test]
fn fairing_constraints_hold_on_the_manifold() {
    let s = genus2();
    let dom = flat_domain(&s, largest_valence(&s), &mut NoProgress).unwrap();
    let space = ManifoldSpace::new(&dom.charts, 3, &KnotOptions::default()).unwrap();
    let c0 = space.subdivision_control_points();
    let mut changes = Vec::new();
    for r in 0..3 {
        let (c, rep) = fair(&space, &c0, 3, r).unwrap();
        assert!(rep.converged, "{rep:?}");
        let cons = fairness_constraints(&space, r).unwrap();
        let res = constraint_residuals(&space, &cons, &c, 3);
        let scale = c.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        let worst = res.iter().fold(0.0f64, |a, b| a.max(b.abs())) / scale;
        assert!(worst < 1e-8, "r = {r}: residual {worst:.2e}");
        // For r ≥ 1 the initial control points violate them (otherwise the test says nothing;
        // r = 0 only asks for shared edge control points, which the subdivision already has).
        let res0 = constraint_residuals(&space, &cons, &c0, 3);
        let worst0 = res0.iter().fold(0.0f64, |a, b| a.max(b.abs())) / scale;
        if r == 0 {
            assert!(worst0 < 1e-12, "{worst0:.2e}");
        } else {
            assert!(worst0 > 1e-4, "{worst0:.2e}");
        }
        changes.push(rep.rms_change);
    }
    // More constraints, more change (paper 000 Fig. 13).
    assert!(
        changes[0] < changes[1] && changes[1] < changes[2],
        "{changes:?}"
    );
}

#[test]
fn fill_patch_meets_the_spline_g1() {
    let s = genus2();
    let dom = flat_domain(&s, largest_valence(&s), &mut NoProgress).unwrap();
    let sv = dom.singular.unwrap();
    let space = ManifoldSpace::new(&dom.charts, 3, &KnotOptions::default()).unwrap();
    let control = subdivided_and_faired(&space, 1);
    let hole = Hole::new(&space, &control, sv).unwrap();
    // Cone angle of 2πχ of curvature: Θ = 2π − 2πχ = 6π for genus 2.
    assert!(
        (hole.cone_angle - 6.0 * std::f64::consts::PI).abs() < 1e-8,
        "{}",
        hole.cone_angle
    );
    assert!(hole.min_clearance > 0.0);
    let rep = hole.seam_normal_jump(&space, &control, 720).unwrap();
    assert!(rep.max_normal_jump_deg <= 0.5, "{rep:?}");
    assert!(rep.max_position_gap < 1e-12, "{rep:?}");
    // The seam is outside the one-ring (inside active faces) and its data is the spline's.
    let mut ws = Workspace::default();
    for j in 0..50 {
        let psi = 2.0 * std::f64::consts::PI * j as f64 / 50.0;
        let phi = hole.cone_angle * psi / (2.0 * std::f64::consts::PI);
        assert!(hole.radius(psi) > hole.r_link(phi));
        let loc = hole.locate(hole.radius(psi), phi).unwrap();
        assert!(space.is_active(loc.face));
        let (c, _, _) = hole.seam_data(&space, &control, psi, &mut ws).unwrap();
        let mut out = [0.0; 3];
        space
            .evaluate(&control, 3, loc.face, loc.bary, 0, &mut ws, &mut out)
            .unwrap();
        for k in 0..3 {
            assert!((c[k] - out[k]).abs() < 1e-9 * s.diagonal());
        }
    }
}

/// The fill is C² at its centre: near `t = 0` it agrees with its quadratic Taylor polynomial in
/// the disk's coordinates `(x, y) = t (cos ψ, sin ψ)` up to `O(t³)`. Measured as the residual
/// of the best quadratic fit to samples on the circle of radius `ε`: it must fall like `ε³`
/// (ratio ≥ 6 per halving; ~8 for a C³ patch, 4 for a patch whose second-order term depends on
/// ψ other than through a quadratic form — the radial Hermite fill had that, and its zebra
/// stripes showed a starburst at the centre).
#[test]
fn fill_patch_is_c2_at_its_centre() {
    let s = genus2();
    let dom = flat_domain(&s, largest_valence(&s), &mut NoProgress).unwrap();
    let space = ManifoldSpace::new(&dom.charts, 3, &KnotOptions::default()).unwrap();
    let control = subdivided_and_faired(&space, 1);
    let hole = Hole::new(&space, &control, dom.singular.unwrap()).unwrap();
    let mut ws = Workspace::default();
    let residual = |eps: f64, ws: &mut Workspace| -> f64 {
        // Least squares over the monomials 1, x, y, x², xy, y² (normal equations, 6×6).
        let k = 48;
        let mut ata = [[0.0f64; 6]; 6];
        let mut atb = [[0.0f64; 3]; 6];
        let mut rows = Vec::new();
        for j in 0..k {
            let psi = 2.0 * std::f64::consts::PI * (j as f64 + 0.25) / k as f64;
            let (x, y) = (psi.cos(), psi.sin()); // in units of eps
            let m = [1.0, x, y, x * x, x * y, y * y];
            let f = hole.fill_point(&space, &control, eps, psi, ws).unwrap();
            for a in 0..6 {
                for b in 0..6 {
                    ata[a][b] += m[a] * m[b];
                }
                for d in 0..3 {
                    atb[a][d] += m[a] * f[d];
                }
            }
            rows.push((m, f));
        }
        // Gaussian elimination with partial pivoting.
        let mut a = ata;
        let mut b = atb;
        for c in 0..6 {
            let p = (c..6)
                .max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))
                .unwrap();
            a.swap(c, p);
            b.swap(c, p);
            let (pa, pb) = (a[c], b[c]);
            for r in 0..6 {
                if r != c {
                    let f = a[r][c] / pa[c];
                    for (x, y) in a[r].iter_mut().zip(&pa) {
                        *x -= f * y;
                    }
                    for (x, y) in b[r].iter_mut().zip(&pb) {
                        *x -= f * y;
                    }
                }
            }
        }
        let coef: Vec<[f64; 3]> = (0..6)
            .map(|r| std::array::from_fn(|d| b[r][d] / a[r][r]))
            .collect();
        rows.iter()
            .map(|(m, f)| {
                (0..3)
                    .map(|d| {
                        let g: f64 = (0..6).map(|i| m[i] * coef[i][d]).sum();
                        (g - f[d]).powi(2)
                    })
                    .sum::<f64>()
            })
            .sum::<f64>()
            .sqrt()
    };
    let (r1, r2, r3) = (
        residual(0.04, &mut ws),
        residual(0.02, &mut ws),
        residual(0.01, &mut ws),
    );
    eprintln!("fill centre: quadratic-fit residuals {r1:.3e} {r2:.3e} {r3:.3e}");
    assert!(
        r1 / r2 >= 6.0 && r2 / r3 >= 6.0,
        "{r1:.3e} {r2:.3e} {r3:.3e}"
    );
}

fn end_to_end(name: &str, s: &Surface, dom: &FlatDomain, degree: usize, max_error_percent: f64) {
    let dist = MeshDistance::new(&s.positions, s.mesh.faces());
    let opts = SplineOptions {
        degree,
        ..SplineOptions::default()
    };
    let (rep, tess, _) = run(&dom.charts, &dist, &opts, 3, &mut NoProgress).unwrap();
    let n = degree;
    eprintln!(
        "{name}: N_f {} N_c {} {} jumps {:?} seam {:.2e}° rms {:.3}% max {:.3}% ({:.2} s)",
        rep.domain_faces,
        rep.control_points,
        rep.continuity.class,
        rep.continuity.relative_jumps,
        rep.continuity.max_seam_normal_jump_deg,
        rep.rms_error_percent,
        rep.max_error_percent,
        rep.seconds
    );
    assert!(rep.fairing.converged);
    assert!(rep.max_error_percent < max_error_percent, "{name}: {rep:?}");
    assert!(tess
        .positions
        .iter()
        .all(|p| p.iter().all(|x| x.is_finite())));
    // Every order < n to 1e-8 (face.off: 3.7e-10 now, 4.4e-8 with the double recurrence);
    // order n jumps by O(1).
    for k in 0..n {
        let tol = 1e-8;
        assert!(
            rep.continuity.relative_jumps[k] <= tol,
            "{name}: order {k} jumps by {:.2e}",
            rep.continuity.relative_jumps[k]
        );
    }
    assert!(rep.continuity.relative_jumps[n] > 1e-3, "{name}");
    assert!(rep.continuity.max_seam_normal_jump_deg <= 0.5, "{name}");
    assert_eq!(rep.continuity.seams.len(), dom.singular.iter().count());
}

#[test]
fn eight_single_extraordinary_point() {
    let Some(s) = load("eight.off") else { return };
    let dom = flat_domain(&s, largest_valence(&s), &mut NoProgress).unwrap();
    assert_eq!(dom.genus, 2);
    let space = ManifoldSpace::new(&dom.charts, 3, &KnotOptions::default()).unwrap();
    check_partition_of_unity(&space, 1);
    let control = subdivided_and_faired(&space, 1);
    check_chart_independence(&space, &control, 7, ISSUE);
    end_to_end("eight", &s, &dom, 3, 1.0);
}

#[test]
fn open_and_genus_one_surfaces_have_no_extraordinary_point() {
    for name in ["face.off", "eight.open.off"] {
        let Some(s) = load(name) else { return };
        let dom = flat_domain(&s, largest_valence(&s), &mut NoProgress).unwrap();
        assert!(dom.singular.is_none());
        let space = ManifoldSpace::new(&dom.charts, 3, &KnotOptions::default()).unwrap();
        assert_eq!(space.report().active_faces, s.mesh.n_faces());
        check_partition_of_unity(&space, 3);
        end_to_end(name, &s, &dom, 3, 1.0);
    }
}

/// The same spline over the affine atlas and over `LocalCharts` built on the atlas's own
/// metric: knots depend only on the metric, so the two spaces must agree (values to 1e-10 of
/// the diagonal, first partials after the rotation between the canonical charts to 1e-8).
fn atlas_vs_local(s: &Surface, name: &str, stride: usize) {
    use ricci::atlas::{AffineAtlas, AtlasOptions};
    let atlas = AffineAtlas::build(s, &AtlasOptions::default(), &mut NoProgress).unwrap();
    let space = ManifoldSpace::new(&atlas, 3, &KnotOptions::default()).unwrap();
    check_partition_of_unity(&space, stride);
    // The fairing reaches its tolerance over the atlas's charts as over `LocalCharts` (its
    // constraints are formed in vertex frames; from the home charts, eight.off stalled at a
    // residual of 1.3e-4 after 21 s).
    let (control, fairing) = fair(&space, &space.subdivision_control_points(), 3, 1).unwrap();
    assert!(fairing.converged, "{name}: {fairing:?}");
    let compared = check_chart_independence(&space, &control, stride, ATLAS);
    assert!(compared > 0);
    let local = LocalCharts::new(
        atlas.mesh().clone(),
        ricci::metric::IntrinsicMetric::euclidean(atlas.lengths().to_vec()),
        atlas.positions().to_vec(),
        atlas.singular_vertices().to_vec(),
        None,
    )
    .unwrap();
    let space2 = ManifoldSpace::new(&local, 3, &KnotOptions::default()).unwrap();
    // Same metric, same knots, same constraints: the same faired control points.
    let (control2, _) = fair(&space2, &space2.subdivision_control_points(), 3, 1).unwrap();
    let diag = s.diagonal();
    let moved = control
        .iter()
        .zip(&control2)
        .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()))
        / diag;
    assert!(
        moved < 1e-9,
        "{name}: faired control points differ by {moved:.2e}"
    );
    let mut ws = Workspace::default();
    let np = n_partials(1);
    let (mut worst, mut worst_d): (f64, f64) = (0.0, 0.0);
    for f in (0..atlas.mesh().n_faces() as u32).step_by(stride) {
        if !space.is_active(f) {
            continue;
        }
        let (m, _) =
            ricci::atlas::fit_rigid(&space.canonical_coords(f), &space2.canonical_coords(f));
        for bary in [SAMPLES[0], SAMPLES[3], SAMPLES[4]] {
            let mut x = vec![0.0; np * 3];
            let mut y = vec![0.0; np * 3];
            space
                .evaluate(&control, 3, f, bary, 1, &mut ws, &mut x)
                .unwrap();
            space2
                .evaluate(&control, 3, f, bary, 1, &mut ws, &mut y)
                .unwrap();
            for d in 0..3 {
                let mut col: Vec<f64> = (0..np).map(|k| y[k * 3 + d]).collect();
                rotate_partials(1, m.rot, &mut col);
                for k in 0..np {
                    y[k * 3 + d] = col[k];
                }
                worst = worst.max((x[d] - y[d]).abs());
            }
            let s1 = (3..9).map(|i| x[i].abs()).fold(1e-300, f64::max);
            worst_d = worst_d.max((3..9).map(|i| (x[i] - y[i]).abs()).fold(0.0, f64::max) / s1);
        }
    }
    eprintln!("{name}: atlas vs local: values {worst:.2e}, partials {worst_d:.2e}");
    assert!(
        worst < 1e-10 * s.diagonal(),
        "{name}: providers differ by {worst:.2e}"
    );
    assert!(worst_d < 1e-6, "{name}: partials differ by {worst_d:.2e}");
    let holes: Vec<Hole> = atlas
        .singular_vertices()
        .iter()
        .map(|&v| Hole::new(&space, &control, v).unwrap())
        .collect();
    let rep = continuity(&space, &control, &holes, 1e-8).unwrap();
    eprintln!(
        "{name}: atlas jumps {:?} seam {:.2e}°",
        rep.relative_jumps, rep.max_seam_normal_jump_deg
    );
    assert_eq!(rep.smoothness, Some(2), "{name}: {rep:?}");
    assert!(rep.max_seam_normal_jump_deg <= 0.5, "{name}: {rep:?}");
}

#[test]
fn affine_atlas_generated_genus2() {
    atlas_vs_local(&genus2(), "genus2", 1);
}

#[test]
fn affine_atlas_real_meshes() {
    // 3holes.off and kitten over the atlas are left to the benchmark (the atlas itself takes
    // seconds to build there).
    let Some(s) = load("eight.off") else { return };
    atlas_vs_local(&s, "eight.off", 11);
}

#[test]
fn local_charts_genus3_and_4_meshes() {
    for name in ["3holes.off", "genus3.off", "fertility.off"] {
        let Some(s) = load(name) else { return };
        let dom = flat_domain(&s, largest_valence(&s), &mut NoProgress).unwrap();
        let space = ManifoldSpace::new(&dom.charts, 3, &KnotOptions::default()).unwrap();
        check_partition_of_unity(&space, 13);
        let control = subdivided_and_faired(&space, 1);
        check_chart_independence(&space, &control, 29, ISSUE);
        let hole = Hole::new(&space, &control, dom.singular.unwrap()).unwrap();
        let rep = hole.seam_normal_jump(&space, &control, 360).unwrap();
        eprintln!("{name}: seam {rep:?}");
        assert!(rep.max_normal_jump_deg <= 0.5, "{name}: {rep:?}");
        // C² across every interior edge of the spline's domain (chart boundaries included),
        // and not C³ (so the measurement can fail).
        let cont = continuity(&space, &control, &[], 1e-8).unwrap();
        eprintln!(
            "{name}: relative jumps {:?} over {} samples, {} chart-boundary edges",
            cont.relative_jumps, cont.samples, cont.chart_boundary_edges
        );
        for k in 0..3 {
            assert!(
                cont.relative_jumps[k] <= 1e-8,
                "{name}: order {k} jumps by {:.2e}",
                cont.relative_jumps[k]
            );
        }
        assert!(cont.relative_jumps[3] > 1e-3, "{name}: {cont:?}");
    }
}

mod ricci_meshes;
use ricci_meshes::ricci_meshes;

/// The cone at the interior vertex of largest valence (smallest id among ties): a fixed,
/// placement-independent choice for these tests (`Singularity::Auto`, least area distortion,
/// is exercised by the CLI tests).
fn largest_valence(s: &Surface) -> Singularity {
    let m = &s.mesh;
    let v = (0..m.n_vertices() as u32)
        .filter(|&v| !m.is_isolated(v))
        .max_by(|&a, &b| m.valence(a).cmp(&m.valence(b)).then(b.cmp(&a)))
        .unwrap();
    Singularity::Vertex(v)
}

/// rocker-arm.off (genus 1, a flat torus: no extraordinary point) has 176° cap triangles in
/// its flat metric. Their vertices' knot clouds used to be shrunk in every placement round (a
/// fixed relative-area floor that the triangle itself fails), to 10⁻⁴ of the face size, and
/// the spline measured only C⁰ (order-1 / order-2 jumps 1.2e-5 / 6.0e-3). Now C² with order-2
/// jumps at kitten's level (≤ 1e-8), and no cloud at a cap triangle is below 1e-3 of the
/// triangle's longest side.
#[test]
fn rocker_arm_flat_torus_is_c2() {
    let Some(s) = load("rocker-arm.off") else {
        return;
    };
    let dom = flat_domain(&s, Singularity::Auto, &mut NoProgress).unwrap();
    assert_eq!(dom.genus, 1);
    assert!(dom.singular.is_none());
    let charts = &dom.charts;
    let space = ManifoldSpace::new(charts, 3, &KnotOptions::default()).unwrap();
    // The caps are there (largest flat angle > 170°) and their clouds are not collapsed.
    let mesh = charts.mesh();
    let mut caps = 0;
    let mut worst_cloud = f64::INFINITY;
    for f in 0..mesh.n_faces() as u32 {
        let l = ricci::spline::manifold::face_side_lengths(mesh, charts.lengths(), f);
        let longest = l[0].max(l[1]).max(l[2]);
        let (i, _) = l
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(b.1))
            .unwrap();
        let (b, c) = (l[(i + 1) % 3], l[(i + 2) % 3]);
        let cos = (b * b + c * c - longest * longest) / (2.0 * b * c);
        if cos.clamp(-1.0, 1.0).acos().to_degrees() > 170.0 {
            caps += 1;
            for v in mesh.face(f) {
                let r = space
                    .cloud(v)
                    .iter()
                    .map(|p| p[0].hypot(p[1]))
                    .fold(0.0, f64::max);
                worst_cloud = worst_cloud.min(r / longest);
            }
        }
    }
    assert!(caps > 0, "no cap triangle in the flat metric");
    assert!(
        worst_cloud > 1e-3,
        "a cap's cloud is {worst_cloud:.1e} of its side"
    );
    let (control, fairing) = fair(&space, &space.subdivision_control_points(), 3, 1).unwrap();
    assert!(fairing.converged, "{fairing:?}");
    let rep = continuity(&space, &control, &[], 1e-8).unwrap();
    eprintln!(
        "rocker-arm: {caps} caps, smallest cap cloud {worst_cloud:.1e} of the side; jumps {:?}",
        rep.relative_jumps
    );
    let j = &rep.relative_jumps;
    assert!(j[0] <= 1e-8 && j[1] <= 1e-8 && j[2] <= 1e-8, "{j:?}");
    assert!(j[3] > 1e-3, "{j:?}");
    assert_eq!(rep.smoothness, Some(2));
}
