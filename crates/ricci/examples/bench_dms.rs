//! Benchmark of planar DMS splines: knot placement and basis construction, evaluation of
//! values / gradient+Hessian, fairing (paper 000 eq. 14) and least-squares fitting, on a
//! jittered grid of ~1k domain triangles, degrees 3 and 5.
//!
//! `cargo run --release --example bench_dms`

use std::time::Instant;

use ricci::spline::dms::{DmsSpace, Domain, KnotClouds, KnotOptions, Workspace};
use ricci::spline::fit::{fair, fit, DataPoint, FitOptions};
use ricci::spline::simplex::n_partials;

fn grid(m: usize) -> Domain {
    let mut s = 0x1234_5678u64;
    let mut rnd = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut pts = Vec::new();
    for j in 0..=m {
        for i in 0..=m {
            let (mut x, mut y) = (i as f64 / m as f64, j as f64 / m as f64);
            if i > 0 && i < m && j > 0 && j < m {
                x += 0.4 / m as f64 * (rnd() - 0.5);
                y += 0.4 / m as f64 * (rnd() - 0.5);
            }
            pts.push([x, y]);
        }
    }
    let id = |i: usize, j: usize| (j * (m + 1) + i) as u32;
    let mut t = Vec::new();
    for j in 0..m {
        for i in 0..m {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            t.push([a, b, c]);
            t.push([a, c, d]);
        }
    }
    Domain::new(pts, t).unwrap()
}

fn main() {
    let dom = grid(22); // 968 triangles
    println!(
        "domain: {} triangles, {} vertices",
        dom.n_faces(),
        dom.points().len()
    );
    for n in [3usize, 5] {
        let t0 = Instant::now();
        let clouds = KnotClouds::place(&dom, n, &KnotOptions::default()).unwrap();
        let t_place = t0.elapsed().as_secs_f64();
        let t0 = Instant::now();
        let space = DmsSpace::new(dom.clone(), clouds).unwrap();
        let t_build = t0.elapsed().as_secs_f64();
        let rep = space.report();
        let nc = space.n_control_points();
        // Height field positions → subdivision control points (dim 3).
        let pos: Vec<f64> = dom
            .points()
            .iter()
            .flat_map(|p| [p[0], p[1], 0.1 * (6.0 * p[0]).sin() * (4.0 * p[1]).cos()])
            .collect();
        let c = space.subdivision_control_points(&pos, 3).unwrap();
        // Evaluation at 20 points per triangle.
        let mut pts = Vec::new();
        for f in 0..dom.n_faces() as u32 {
            for k in 0..20 {
                let a = ((k * 7) % 20) as f64 / 20.0 * 0.9 + 0.03;
                let b = ((k * 13) % 20) as f64 / 20.0 * (0.95 - a) + 0.02;
                pts.push((f, dom.point_in_face(f, [1.0 - a - b, a, b])));
            }
        }
        let mut ws = Workspace::default();
        let mut out = vec![0.0; n_partials(2) * 3];
        let mut acc = 0.0;
        let t0 = Instant::now();
        for &(f, u) in &pts {
            space.evaluate(&c, 3, f, u, 0, &mut ws, &mut out).unwrap();
            acc += out[2];
        }
        let t_val = t0.elapsed().as_secs_f64() / pts.len() as f64;
        let t0 = Instant::now();
        for &(f, u) in &pts {
            space.evaluate(&c, 3, f, u, 2, &mut ws, &mut out).unwrap();
            acc += out[5 * 3 + 2];
        }
        let t_d2 = t0.elapsed().as_secs_f64() / pts.len() as f64;
        let r = if n == 3 { 1 } else { 2 };
        let t0 = Instant::now();
        let (_, frep) = fair(&space, &c, 3, r).unwrap();
        let t_fair = t0.elapsed().as_secs_f64();
        // Fit to 8 samples per triangle of the height field.
        let data: Vec<DataPoint> = pts
            .iter()
            .step_by(20 / 8)
            .map(|&(f, u)| DataPoint {
                face: f,
                param: u,
                target: vec![u[0], u[1], 0.1 * (6.0 * u[0]).sin() * (4.0 * u[1]).cos()],
            })
            .collect();
        let t0 = Instant::now();
        let (_, fr) = fit(&space, &data, &c, 3, &FitOptions::default()).unwrap();
        let t_fit = t0.elapsed().as_secs_f64();
        println!(
            "n={n}: {nc} control points, knot placement {:.3} s, basis build {:.3} s (max {} simplex nodes/triangle, general position {:.1e}); \
             eval {:.2} µs/point (value), {:.2} µs/point (≤ 2nd derivatives); \
             fairing r={r}: {:.3} s ({} constraints, residual {:.1e}, {} CG steps); \
             fit: {:.3} s ({} points, rms {:.2e}, max {:.2e}) [checksum {acc:.3}]",
            t_place,
            t_build,
            rep.max_nodes,
            rep.min_general_position,
            t_val * 1e6,
            t_d2 * 1e6,
            t_fair,
            frep.constraints,
            frep.max_constraint_residual,
            frep.refinement_steps,
            t_fit,
            fr.data_points,
            fr.rms_error,
            fr.max_error
        );
    }
}
