//! T-splines over the flat torus (issue 18): blending functions against an independent de Boor
//! evaluation of periodic tensor-product B-splines, partition of unity and linear independence
//! on analysis-suitable T-meshes (with a sheared lattice), derivatives against finite
//! differences, Bézier extraction, continuity across patch sides.

// Index loops mirror the formulas.
#![allow(clippy::needless_range_loop)]

use ricci::spline::tspline::{continuity, extract, Lattice, TBasis, TMesh, TSpline};

struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// De Boor's algorithm for a periodic cubic B-spline curve with columns `c` (period `w`) and
/// control values `p[i]` attached to the function centred at column `i`.
fn de_boor_periodic(c: &[f64], w: f64, p: &[f64], x: f64) -> f64 {
    let n = c.len() as i64;
    let t = |k: i64| -> f64 {
        let q = k.div_euclid(n);
        c[k.rem_euclid(n) as usize] + q as f64 * w
    };
    let x = x - (x / w).floor() * w;
    // span k: t_k ≤ x < t_{k+1}
    let mut k = 0i64;
    while !(t(k) <= x && x < t(k + 1)) {
        k += 1;
    }
    // functions j = k-3..=k have support [t_j, t_{j+4}] ∋ x; function j is centred at t_{j+2}
    let mut d: Vec<f64> = (0..4)
        .map(|r| {
            let j = k - 3 + r;
            p[(j + 2).rem_euclid(n) as usize]
        })
        .collect();
    for r in 1..=3 {
        for jj in (r..=3).rev() {
            let i = k - 3 + jj as i64;
            let a = (x - t(i)) / (t(i + 4 - r as i64) - t(i));
            d[jj] = (1.0 - a) * d[jj - 1] + a * d[jj];
        }
    }
    d[3]
}

fn random_as_mesh(shift_frac: f64, seed: u64, refinements: usize) -> TMesh {
    let lat = Lattice {
        width: 3.0,
        height: 2.0,
        shift: shift_frac * 3.0,
    };
    let mut m = TMesh::uniform(lat, 6, 5).unwrap();
    let mut rng = Lcg(seed);
    for _ in 0..refinements {
        let f = (rng.next() * m.faces().len() as f64) as usize;
        let quad = rng.next() < 0.5;
        m.refine_face(f.min(m.faces().len() - 1), quad);
        m.make_analysis_suitable(2000).unwrap();
    }
    m
}

#[test]
fn regular_t_mesh_equals_periodic_tensor_product_bsplines() {
    let lat = Lattice {
        width: 4.0,
        height: 3.0,
        shift: 0.0,
    };
    let us = [0.0, 0.5, 1.4, 1.9, 2.7, 3.3];
    let vs = [0.0, 0.8, 1.1, 2.0, 2.4];
    let mesh = TMesh::grid(lat, &us, &vs).unwrap();
    assert!(mesh.t_junctions().is_empty());
    let basis = TBasis::new(mesh).unwrap();
    assert_eq!(basis.len(), us.len() * vs.len());
    let mut rng = Lcg(7);
    let net: Vec<Vec<f64>> = (0..us.len())
        .map(|_| (0..vs.len()).map(|_| rng.next()).collect())
        .collect();
    let control: Vec<[f64; 3]> = basis
        .anchors
        .iter()
        .map(|a| {
            let i = us.iter().position(|&x| (x - a.u).abs() < 1e-12).unwrap();
            let j = vs.iter().position(|&y| (y - a.v).abs() < 1e-12).unwrap();
            [net[i][j], 0.0, 0.0]
        })
        .collect();
    let ts = TSpline { basis, control };
    for _ in 0..400 {
        let (u, v) = (rng.next() * 4.0, rng.next() * 3.0);
        // tensor product: de Boor in v for every column, then in u
        let col: Vec<f64> = (0..us.len())
            .map(|i| de_boor_periodic(&vs, 3.0, &net[i], v))
            .collect();
        let want = de_boor_periodic(&us, 4.0, &col, u);
        let got = ts.point(u, v)[0];
        assert!((got - want).abs() < 1e-13, "({u}, {v}): {got} vs {want}");
    }
}

#[test]
fn analysis_suitable_t_meshes_give_partition_of_unity_and_independent_functions() {
    for (shift, seed) in [(0.0, 3u64), (0.37, 11), (0.5, 5)] {
        let mesh = random_as_mesh(shift, seed, 12);
        assert!(mesh.is_analysis_suitable());
        let tj = mesh.t_junctions().len();
        assert!(tj > 0 || shift != 0.0, "refinement made no T-junctions");
        let basis = TBasis::new(mesh).unwrap();
        let n = basis.len();
        let mut rng = Lcg(seed + 100);
        let mut buf = Vec::new();
        let m = 6 * n;
        let mut rows = faer::Mat::<f64>::zeros(m, n);
        for r in 0..m {
            let (u, v) = (rng.next() * 3.0, rng.next() * 2.0);
            basis.eval(u, v, &mut buf);
            let mut s = [0.0; 6];
            for (i, j) in &buf {
                for k in 0..6 {
                    s[k] += j[k];
                }
                assert!(j[0] >= -1e-15);
                rows[(r, *i)] = j[0];
            }
            assert!(
                (s[0] - 1.0).abs() < 1e-12,
                "shift {shift}: Σ B = {} at ({u}, {v})",
                s[0]
            );
            for k in 1..6 {
                assert!(
                    s[k].abs() < 1e-9,
                    "shift {shift}: Σ ∂B = {} at ({u}, {v})",
                    s[k]
                );
            }
        }
        let gram = rows.transpose() * &rows;
        let ev = gram.self_adjoint_eigenvalues(faer::Side::Lower).unwrap();
        let (lo, hi) = (ev[0], ev[ev.len() - 1]);
        assert!(
            lo / hi > 1e-10,
            "shift {shift}: Gram eigenvalues {lo} .. {hi}: dependent blending functions"
        );
    }
}

#[test]
fn non_suitable_meshes_are_detected_and_closed() {
    // two neighbouring 1-to-4 splits leave T-junction extensions that cross
    let lat = Lattice {
        width: 8.0,
        height: 8.0,
        shift: 0.0,
    };
    let mut m = TMesh::uniform(lat, 8, 8).unwrap();
    let f = m.locate(3.5, 3.5).unwrap();
    m.refine_face(f, true);
    let g = m.locate(4.5, 4.5).unwrap();
    m.refine_face(g, true);
    assert!(!m.intersecting_extensions().is_empty());
    let splits = m.make_analysis_suitable(1000).unwrap();
    assert!(splits > 0);
    assert!(m.is_analysis_suitable());
    let basis = TBasis::new(m).unwrap();
    let mut buf = Vec::new();
    let mut rng = Lcg(9);
    for _ in 0..2000 {
        let (u, v) = (rng.next() * 8.0, rng.next() * 8.0);
        basis.eval(u, v, &mut buf);
        let s: f64 = buf.iter().map(|(_, j)| j[0]).sum();
        assert!((s - 1.0).abs() < 1e-12);
    }
}

fn random_surface(shift: f64, seed: u64) -> TSpline {
    let basis = TBasis::new(random_as_mesh(shift, seed, 10)).unwrap();
    let mut rng = Lcg(seed ^ 77);
    let control = basis
        .anchors
        .iter()
        .map(|a| {
            let (t, p) = (
                a.u / 3.0 * std::f64::consts::TAU,
                a.v / 2.0 * std::f64::consts::TAU,
            );
            let r = 2.0 + 0.7 * p.cos() + 0.05 * rng.next();
            [r * t.cos(), r * t.sin(), 0.7 * p.sin() + 0.05 * rng.next()]
        })
        .collect();
    TSpline { basis, control }
}

#[test]
fn derivatives_match_finite_differences() {
    let ts = random_surface(0.29, 21);
    let mut rng = Lcg(5);
    let h = 1e-5;
    for _ in 0..300 {
        let (u, v) = (rng.next() * 3.0, rng.next() * 2.0);
        let j = ts.jet(u, v);
        let fd = |k: usize, du: f64, dv: f64| -> [f64; 3] {
            let a = ts.jet(u + du, v + dv)[k];
            let b = ts.jet(u - du, v - dv)[k];
            [
                (a[0] - b[0]) / (2.0 * h),
                (a[1] - b[1]) / (2.0 * h),
                (a[2] - b[2]) / (2.0 * h),
            ]
        };
        // (derivative index, base index, direction): S_u, S_v from S; S_uu, S_uv from S_u; S_vv from S_v
        for (k, base, du, dv) in [
            (1, 0, h, 0.0),
            (2, 0, 0.0, h),
            (3, 1, h, 0.0),
            (4, 1, 0.0, h),
            (5, 2, 0.0, h),
        ] {
            let f = fd(base, du, dv);
            for d in 0..3 {
                let scale = 1.0 + j[k][d].abs();
                assert!(
                    (j[k][d] - f[d]).abs() < 1e-4 * scale,
                    "partial {k} at ({u}, {v}): {} vs {}",
                    j[k][d],
                    f[d]
                );
            }
        }
    }
}

#[test]
fn bezier_patches_reproduce_the_t_spline_and_it_is_c2() {
    for (shift, seed) in [(0.0, 4u64), (0.41, 8)] {
        let ts = random_surface(shift, seed);
        let patches = extract(&ts);
        assert!(patches.len() >= ts.basis.mesh.faces().len());
        let mut rng = Lcg(seed + 1);
        let mut worst = 0.0f64;
        for p in &patches {
            for _ in 0..4 {
                let (u, v) = (
                    p.u0 + rng.next() * (p.u1 - p.u0),
                    p.v0 + rng.next() * (p.v1 - p.v0),
                );
                let a = p.point(u, v);
                let b = ts.point(u, v);
                for d in 0..3 {
                    worst = worst.max((a[d] - b[d]).abs());
                }
            }
        }
        assert!(
            worst < 1e-12,
            "shift {shift}: Bézier patches differ from the T-spline by {worst}"
        );
        let c = continuity(&patches, ts.basis.mesh.lattice, 3);
        let jumps = c.relative();
        assert!(
            jumps[0] < 1e-13 && jumps[1] < 1e-11 && jumps[2] < 1e-9,
            "shift {shift}: jumps {jumps:?}"
        );
        // third derivatives do jump (cubic pieces): the measurement sees a real discontinuity
        assert!(
            jumps[3] > 1e-3,
            "shift {shift}: third derivatives do not jump: {jumps:?}"
        );
        assert_eq!(c.class(1e-8), Some(2));
    }
}

/// A torus of revolution sampled on a jittered grid, parameterised over a sheared lattice.
fn torus_samples(nu: usize, nv: usize, lat: Lattice) -> (Vec<[f64; 3]>, Vec<[f64; 2]>) {
    let mut rng = Lcg(42);
    let mut pts = Vec::new();
    let mut uv = Vec::new();
    for j in 0..nv {
        for i in 0..nu {
            let a = (i as f64 + 0.3 * rng.next()) / nu as f64;
            let b = (j as f64 + 0.3 * rng.next()) / nv as f64;
            let (t, p) = (a * std::f64::consts::TAU, b * std::f64::consts::TAU);
            let r = 2.0 + 0.7 * p.cos() + 0.1 * (3.0 * t).sin() * p.sin();
            pts.push([r * t.cos(), r * t.sin(), 0.7 * p.sin()]);
            uv.push([a * lat.width + b * lat.shift, b * lat.height]);
        }
    }
    (pts, uv)
}

#[test]
fn adaptive_fit_reaches_the_tolerance_with_t_junctions() {
    use ricci::spline::tspline::fit::{fit, FitOptions};
    let lat = Lattice {
        width: 4.0,
        height: 1.5,
        shift: 0.9,
    };
    let (pts, uv) = torus_samples(90, 40, lat);
    let opts = FitOptions {
        tolerance: 0.002,
        initial_faces: 24,
        // uniform start: this test is about the error-driven refinement
        max_points_per_face: 0,
        ..Default::default()
    };
    let r = fit(&pts, &uv, lat, &opts, &mut ricci::progress::NoProgress).unwrap();
    let last = r.steps.last().unwrap();
    assert!(r.converged, "not converged: {:?}", r.steps);
    assert!(last.max_error_percent <= 0.2 + 1e-12);
    assert!(r.steps.len() >= 2, "no refinement happened: {:?}", r.steps);
    assert!(r.steps[0].max_error_percent > last.max_error_percent);
    // the errors are measured independently of the fit's bookkeeping
    let scale = ricci::spline::tspline::fit::bbox_scale(&pts);
    let worst = pts
        .iter()
        .zip(&uv)
        .map(|(p, q)| {
            let s = r.spline.point(q[0], q[1]);
            ((s[0] - p[0]).powi(2) + (s[1] - p[1]).powi(2) + (s[2] - p[2]).powi(2)).sqrt()
        })
        .fold(0.0, f64::max);
    assert!((100.0 * worst / scale - last.max_error_percent).abs() < 1e-9);
    assert!(r.spline.basis.mesh.is_analysis_suitable());
    // the refined surface keeps the partition of unity
    let mut buf = Vec::new();
    let mut rng = Lcg(3);
    for _ in 0..500 {
        r.spline
            .basis
            .eval(rng.next() * 4.0, rng.next() * 1.5, &mut buf);
        let s: f64 = buf.iter().map(|(_, j)| j[0]).sum();
        assert!((s - 1.0).abs() < 1e-12);
    }
}

/// Data weights: a point of weight 0 is no data (the fit equals the fit of the other points
/// alone), and a common factor changes nothing (the fairness weight follows `tr(AᵀA)`).
#[test]
fn data_weights_zero_drop_points_and_a_common_factor_changes_nothing() {
    use ricci::spline::tspline::fit::fit_fixed;
    let lat = Lattice {
        width: 4.0,
        height: 1.5,
        shift: 0.9,
    };
    let (pts, uv) = torus_samples(60, 24, lat);
    let basis = || TBasis::new(TMesh::uniform(lat, 10, 5).unwrap()).unwrap();
    let solve = |p: &[[f64; 3]], q: &[[f64; 2]], w: &[f64]| {
        fit_fixed(basis(), p, q, w, 1e-4, None, 1e-13, 20_000)
            .unwrap()
            .0
            .control
    };
    let half: Vec<f64> = (0..pts.len()).map(|k| (k % 2) as f64).collect();
    let odd_p: Vec<[f64; 3]> = pts.iter().skip(1).step_by(2).cloned().collect();
    let odd_q: Vec<[f64; 2]> = uv.iter().skip(1).step_by(2).cloned().collect();
    let a = solve(&pts, &uv, &half);
    let b = solve(&odd_p, &odd_q, &[]);
    let full = solve(&pts, &uv, &[]);
    let twice = solve(&pts, &uv, &vec![2.0; pts.len()]);
    let diff = |x: &[[f64; 3]], y: &[[f64; 3]]| {
        x.iter()
            .zip(y)
            .flat_map(|(p, q)| (0..3).map(move |d| (p[d] - q[d]).abs()))
            .fold(0.0, f64::max)
    };
    assert!(diff(&a, &b) < 1e-8, "weight 0 ≠ dropped: {}", diff(&a, &b));
    assert!(
        diff(&full, &twice) < 1e-8,
        "factor 2: {}",
        diff(&full, &twice)
    );
    // and the weights do act: the half-weighted fit is not the full one
    assert!(
        diff(&a, &full) > 1e-6,
        "weights ignored: {}",
        diff(&a, &full)
    );
}

/// The control-point budget is never exceeded by a refinement (the marks are halved until the
/// refined, analysis-suitable T-mesh fits), and greedy rms marking spends it.
#[test]
fn rms_refinement_stays_within_the_control_point_budget() {
    use ricci::spline::tspline::fit::{fit, FitOptions};
    let lat = Lattice {
        width: 4.0,
        height: 1.5,
        shift: 0.9,
    };
    let (pts, uv) = torus_samples(90, 40, lat);
    for (budget, rms_marks) in [(150, 0), (150, 3), (233, 5)] {
        let opts = FitOptions {
            tolerance: 0.01,
            rms_tolerance: 1e-7,
            max_control_points: budget,
            rms_marks,
            initial_faces: 24,
            max_points_per_face: 0,
            max_iterations: 200,
            ..Default::default()
        };
        let r = fit(&pts, &uv, lat, &opts, &mut ricci::progress::NoProgress).unwrap();
        assert!(!r.converged);
        let n = r.spline.control.len();
        assert!(n <= budget, "{n} control points > {budget}: {:?}", r.steps);
        assert!(r.steps.iter().all(|s| s.control_points <= budget));
        // the rms phase refined (L∞ ≤ 1 % is reached first) and the rms went down
        let first = r
            .steps
            .iter()
            .position(|s| s.max_error_percent <= 1.0)
            .unwrap();
        assert!(r.steps.len() > first + 1, "{:?}", r.steps);
        assert!(r.steps.last().unwrap().rms_error_percent < r.steps[first].rms_error_percent);
        if rms_marks > 0 {
            // greedy steps of at most `rms_marks` 1-to-2 splits (plus closure) stop close to
            // the budget
            assert!(n + 12 >= budget, "{n} of {budget}: {:?}", r.steps);
        }
    }
}

#[test]
fn density_adaptive_start_bounds_the_points_per_face() {
    // The start splits faces 1-to-4 until none holds more than `max_points_per_face` samples;
    // counted here from the faces' rectangles, independently of the fit's bookkeeping.
    use ricci::spline::tspline::fit::{fit, FitOptions};
    let lat = Lattice {
        width: 4.0,
        height: 1.5,
        shift: 0.9,
    };
    let (pts, uv) = torus_samples(90, 40, lat);
    let opts = FitOptions {
        tolerance: 0.002,
        initial_faces: 24,
        max_points_per_face: 40,
        max_iterations: 1,
        ..Default::default()
    };
    let r = fit(&pts, &uv, lat, &opts, &mut ricci::progress::NoProgress).unwrap();
    let faces = r.spline.basis.mesh.faces();
    assert!(faces.len() > 24, "no split: {} faces", faces.len());
    let mut count = vec![0usize; faces.len()];
    for q in &uv {
        let (u, v) = lat.canonical(q[0], q[1]);
        let f = faces.iter().position(|f| f.contains(u, v)).unwrap();
        count[f] += 1;
    }
    assert!(count.iter().all(|&c| c <= 40), "{count:?}");
    assert_eq!(count.iter().sum::<usize>(), uv.len());
    assert!(r.spline.basis.mesh.is_analysis_suitable());
}

#[test]
fn step_and_iges_files_are_well_formed() {
    use ricci::spline::tspline::export::{iges, obj, step, torus_obj};
    let ts = random_surface(0.3, 2);
    let patches = extract(&ts);
    let s = step(&patches, "t");
    assert_eq!(s.matches("ADVANCED_FACE(").count(), patches.len());
    assert_eq!(
        s.matches("B_SPLINE_SURFACE_WITH_KNOTS(").count(),
        patches.len()
    );
    assert!(s.starts_with("ISO-10303-21;") && s.trim_end().ends_with("END-ISO-10303-21;"));
    let g = iges(&patches, "t");
    let lines: Vec<&str> = g.lines().collect();
    assert!(
        lines.iter().all(|l| l.len() == 80),
        "IGES lines must have 80 columns"
    );
    let count = |c: char| lines.iter().filter(|l| l.as_bytes()[72] == c as u8).count();
    assert_eq!(count('D'), 2 * patches.len());
    let t = lines.last().unwrap();
    assert!(
        t.contains(&format!("D{:>7}", count('D'))) && t.contains(&format!("P{:>7}", count('P')))
    );
    // parameter data: 128 entity header then 8 + 8 knots, 16 weights, 48 coordinates, 4 bounds
    let first: String = lines
        .iter()
        .filter(|l| l.as_bytes()[72] == b'P' && l[64..72].trim() == "1")
        .map(|l| l[..64].trim_end())
        .collect();
    let toks: Vec<&str> = first.trim_end_matches(';').split(',').collect();
    assert_eq!(toks.len(), 10 + 16 + 16 + 48 + 4);
    let x: f64 = toks[10 + 16 + 16].parse().unwrap();
    assert_eq!(x, patches[0].control[0][0][0]);
    let o = obj(&patches, 4);
    assert_eq!(
        o.lines().filter(|l| l.starts_with("v ")).count(),
        25 * patches.len()
    );
    // the lattice-grid tessellation is a closed torus: V − E + F = 0, every edge in two faces
    let t = torus_obj(&ts, 12, 9);
    let faces: Vec<[usize; 3]> = t
        .lines()
        .filter(|l| l.starts_with("f "))
        .map(|l| {
            let v: Vec<usize> = l[2..].split(' ').map(|x| x.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect();
    let nv = t.lines().filter(|l| l.starts_with("v ")).count();
    assert_eq!(nv, 12 * 9);
    let mut edges = std::collections::HashMap::new();
    for f in &faces {
        for k in 0..3 {
            let (a, b) = (f[k].min(f[(k + 1) % 3]), f[k].max(f[(k + 1) % 3]));
            *edges.entry((a, b)).or_insert(0) += 1;
        }
    }
    assert!(edges.values().all(|&c| c == 2));
    assert_eq!(nv as i64 - edges.len() as i64 + faces.len() as i64, 0);
}

#[test]
fn torus_of_revolution_domain_has_the_closed_form_modulus_and_fits_c2() {
    use ricci::spline::tspline::fit::{fit, flat_torus_domain, FitOptions};
    let (big, small) = (1.0, 0.5);
    let s = ricci::mesh::generate::torus(big, small, 48).unwrap();
    let (uv, lat) = flat_torus_domain(&s, &mut ricci::progress::NoProgress).unwrap();
    // conformal to a rectangle with side ratio r / √(R² − r²) (docs/DESIGN.md §5)
    let want = small / (big * big - small * small).sqrt();
    let ratio = lat.width.min(lat.height) / lat.width.max(lat.height);
    assert!(
        (ratio / want - 1.0).abs() < 3e-3,
        "side ratio {ratio} vs {want}"
    );
    assert_eq!(
        lat.shift, 0.0,
        "a torus of revolution has a rectangular lattice"
    );
    let opts = FitOptions {
        tolerance: 0.005,
        ..Default::default()
    };
    let r = fit(
        &s.positions,
        &uv,
        lat,
        &opts,
        &mut ricci::progress::NoProgress,
    )
    .unwrap();
    assert!(r.converged && r.steps.last().unwrap().max_error_percent <= 0.5);
    let patches = extract(&r.spline);
    let c = continuity(&patches, lat, 3);
    assert_eq!(c.class(1e-8), Some(2), "{c:?}");
}

#[test]
fn chart_independence_holds_for_the_lattice_and_sees_a_wrong_transition() {
    use ricci::spline::tspline::chart_independence;
    for (shift, seed) in [(0.0, 21u64), (0.37, 22)] {
        let ts = random_surface(shift, seed);
        let lat = ts.basis.mesh.lattice;
        let c = chart_independence(&ts, lat, 12);
        assert!(
            c.max_relative() <= 1e-10,
            "shift {shift}: charts differ by {:?}",
            c.relative()
        );
        assert_eq!(c.comparisons, (12 * 12 + 4 * 12) * 6);
        // the same comparison through a wrong transition (shift off by a tenth of the width)
        let wrong = Lattice {
            shift: lat.shift + 0.1 * lat.width,
            ..lat
        };
        let bad = chart_independence(&ts, wrong, 12);
        assert!(
            bad.relative()[0] > 1e-3,
            "shift {shift}: a wrong transition went unseen: {:?}",
            bad.relative()
        );
    }
}

/// Must-show of issue 18 on kitten (genus 1, paper 003 Table 1 tolerance 0.44 %): C² across
/// every side shared by two Bézier patches (relative jumps of orders 0..=2 at rounding level,
/// order 3 a real jump), and the spline the same in every chart to 1e-10.
#[test]
fn kitten_fit_is_c2_across_every_patch_side_and_chart_independent() {
    use ricci::spline::tspline::chart_independence;
    use ricci::spline::tspline::fit::{fit, flat_torus_domain, FitOptions};
    let Some(dir) = ricci_meshes() else {
        eprintln!("RICCI_MESHES is not set: skipping kitten_fit_is_c2_across_every_patch_side_and_chart_independent");
        return;
    };
    let path = std::path::Path::new(&dir).join("kitten.nf20k.off");
    let (s, _) = ricci::mesh::io::read_surface(&path).unwrap();
    let mut quiet = ricci::progress::NoProgress;
    let (uv, lat) = flat_torus_domain(&s, &mut quiet).unwrap();
    let opts = FitOptions {
        tolerance: 0.0044,
        ..Default::default()
    };
    let r = fit(&s.positions, &uv, lat, &opts, &mut quiet).unwrap();
    assert!(r.converged, "kitten did not reach 0.44 %");
    let patches = extract(&r.spline);
    let c = continuity(&patches, lat, 3);
    // every patch's right and top side (3 points each) found the neighbour across it
    assert_eq!(c.comparisons, 6 * patches.len(), "{c:?}");
    let jumps = c.relative();
    assert!(
        jumps[0] < 1e-12 && jumps[1] < 1e-10 && jumps[2] < 1e-8,
        "kitten: jumps {jumps:?}"
    );
    assert!(
        jumps[3] > 1e-4,
        "kitten: third derivatives do not jump: {jumps:?}"
    );
    let charts = chart_independence(&r.spline, lat, 24);
    assert!(
        charts.max_relative() <= 1e-10,
        "kitten: charts differ by {:?}",
        charts.relative()
    );
}

/// Paper 003 Table 1, kitten (models scaled to the unit cube: errors in % of the longest
/// bounding-box side): 765 control points, rms 0.05 %, L∞ 0.44 %. With two rounds of
/// parameter correction per fit, ours must use at most the paper's control points and reach
/// at most its L∞. The paper's rms is **not met** (session 6: 0.067 % over the vertices,
/// 0.061 % area-weighted, at 660 control points); the test holds the rms to within 1.5× the
/// paper's, so that a regression of the fit fails here. The errors are recomputed from the
/// spline and the returned parameters: `|S(u_k) − p_k|` bounds the distance of `p_k` to the
/// surface from above.
#[test]
fn kitten_with_parameter_correction_meets_paper_003_count_and_max_error() {
    use ricci::spline::tspline::fit::{area_weighted_rms, fit, flat_torus_domain, FitOptions};
    let Some(dir) = ricci_meshes() else {
        eprintln!("RICCI_MESHES is not set: skipping kitten_with_parameter_correction_meets_paper_003_count_and_max_error");
        return;
    };
    let (paper_points, paper_rms, paper_max) = (765, 0.05, 0.44);
    let path = std::path::Path::new(&dir).join("kitten.nf20k.off");
    let (s, _) = ricci::mesh::io::read_surface(&path).unwrap();
    let mut quiet = ricci::progress::NoProgress;
    let (uv, lat) = flat_torus_domain(&s, &mut quiet).unwrap();
    let opts = FitOptions {
        tolerance: paper_max / 100.0,
        parameter_correction: 2,
        ..Default::default()
    };
    let r = fit(&s.positions, &uv, lat, &opts, &mut quiet).unwrap();
    // the scale: the longest side of the bounding box, from the mesh
    let (lo, hi) = s.bounding_box();
    let scale = (0..3).map(|d| hi[d] - lo[d]).fold(0.0, f64::max);
    let errors: Vec<f64> = s
        .positions
        .iter()
        .zip(&r.params)
        .map(|(p, q)| {
            let x = r.spline.point(q[0], q[1]);
            ((x[0] - p[0]).powi(2) + (x[1] - p[1]).powi(2) + (x[2] - p[2]).powi(2)).sqrt()
        })
        .collect();
    let max = 100.0 * errors.iter().cloned().fold(0.0, f64::max) / scale;
    let rms =
        100.0 * (errors.iter().map(|e| e * e).sum::<f64>() / errors.len() as f64).sqrt() / scale;
    let rms_area = 100.0 * area_weighted_rms(&s, &errors).unwrap() / scale;
    eprintln!(
        "kitten: {} control points, rms {rms:.4} % (area-weighted {rms_area:.4} %), L∞ {max:.4} %",
        r.spline.control.len()
    );
    assert!(r.converged);
    assert!(
        r.spline.control.len() <= paper_points,
        "{} control points",
        r.spline.control.len()
    );
    assert!(max <= paper_max, "L∞ {max} %");
    assert!(rms <= 1.5 * paper_rms, "rms {rms} %");
}

/// Paper 003 Table 1, kitten, all three numbers: at most 765 control points, rms ≤ 0.05 % and
/// L∞ ≤ 0.44 % of the longest bounding-box side (the paper's unit cube), no slack factor. The
/// rms is over the mesh vertices (the paper: distances at the mesh points), recomputed here from
/// the spline at the returned parameters. The fit: eight rounds of parameter correction (Newton
/// closest points) per refit, then rms-driven 1-to-2 splits of the faces with the largest sums
/// of squared errors, never past the 765 control points. Issue 18 also asks for ≤ 30 s: ~15
/// CPU-s since session 9 (the fairness matrix once per T-mesh, the data term refilled on its
/// pattern; BENCHMARKS.md "Session 9 (tfit9)"), so it runs in CI; the time is a benchmark, not
/// asserted here.
#[test]
fn kitten_meets_paper_003_table_1_count_rms_and_max_error() {
    use ricci::spline::tspline::fit::{area_weighted_rms, fit, flat_torus_domain, FitOptions};
    let Some(dir) = ricci_meshes() else {
        eprintln!("RICCI_MESHES is not set: skipping kitten_meets_paper_003_table_1_count_rms_and_max_error");
        return;
    };
    let (paper_points, paper_rms, paper_max) = (765, 0.05, 0.44);
    let path = std::path::Path::new(&dir).join("kitten.nf20k.off");
    let (s, _) = ricci::mesh::io::read_surface(&path).unwrap();
    let mut quiet = ricci::progress::NoProgress;
    let (uv, lat) = flat_torus_domain(&s, &mut quiet).unwrap();
    let opts = FitOptions {
        tolerance: paper_max / 100.0,
        rms_tolerance: paper_rms / 100.0,
        max_control_points: paper_points,
        parameter_correction: 8,
        ..Default::default()
    };
    let r = fit(&s.positions, &uv, lat, &opts, &mut quiet).unwrap();
    let (lo, hi) = s.bounding_box();
    let scale = (0..3).map(|d| hi[d] - lo[d]).fold(0.0, f64::max);
    let errors: Vec<f64> = s
        .positions
        .iter()
        .zip(&r.params)
        .map(|(p, q)| {
            let x = r.spline.point(q[0], q[1]);
            ((x[0] - p[0]).powi(2) + (x[1] - p[1]).powi(2) + (x[2] - p[2]).powi(2)).sqrt()
        })
        .collect();
    let max = 100.0 * errors.iter().cloned().fold(0.0, f64::max) / scale;
    let rms =
        100.0 * (errors.iter().map(|e| e * e).sum::<f64>() / errors.len() as f64).sqrt() / scale;
    let rms_area = 100.0 * area_weighted_rms(&s, &errors).unwrap() / scale;
    eprintln!(
        "kitten: {} control points, rms {rms:.4} % (area-weighted {rms_area:.4} %), L∞ {max:.4} %",
        r.spline.control.len()
    );
    assert!(r.converged, "{:?}", r.steps);
    assert!(r.spline.control.len() <= paper_points);
    assert!(max <= paper_max, "L∞ {max} %");
    assert!(rms <= paper_rms, "rms {rms} %");
}

mod ricci_meshes;
use ricci_meshes::ricci_meshes;
