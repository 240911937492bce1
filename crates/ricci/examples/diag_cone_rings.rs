//! Diagnosis of a single-cone flow (paper 000 §4 Step 3) at the best-ranked candidates of the
//! automatic placement: per edge-ring around the cone, the range of the flow variable `u`
//! reached, the largest jump of `u` along an edge leaving the ring outwards, and the faces
//! with a violated triangle inequality — on the candidate mesh with only the cone's valence
//! raised, or graded around the cone (`atlas::placement::candidate_mesh`).
//!
//! `cargo run --release -p ricci --example diag_cone_rings -- MESH [CANDIDATES] [SCHEMES]
//! [MAX_ITERATIONS] [graded]` (defaults: 1, thurston, 400, ungraded; SCHEMES comma-separated).
//! Near a cone of angle `2π(1 + m)` the flat metric's log conformal factor grows like
//! `m log r`; jumps of several units per edge within the first rings mean the triangulation
//! does not resolve it.

use ricci::atlas::placement::{candidate_mesh, estimate, PlacementOptions};
use ricci::flow::{ricci_flow, FlowOptions, TargetSpec};
use ricci::mesh::io::read_surface;
use ricci::metric::IntrinsicMetric;
use ricci::metric::{euler_characteristic, Geometry, Scheme};
use ricci::progress::NoProgress;
use std::collections::VecDeque;
use std::f64::consts::PI;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(file) = args.first() else {
        eprintln!("usage: diag_cone_rings MESH [CANDIDATES] [SCHEMES] [MAX_ITERATIONS] [graded]");
        return;
    };
    let (s, _) = match read_surface(std::path::Path::new(file)) {
        Ok(x) => x,
        Err(e) => {
            eprintln!("{file}: {e}");
            return;
        }
    };
    let count: usize = args.get(1).and_then(|x| x.parse().ok()).unwrap_or(1);
    let schemes: Vec<Scheme> = args
        .get(2)
        .map(|x| x.split(',').filter_map(|s| s.parse().ok()).collect())
        .unwrap_or_else(|| vec![Scheme::Thurston]);
    let max_it: usize = args.get(3).and_then(|x| x.parse().ok()).unwrap_or(400);
    let graded = args.get(4).is_some_and(|x| x == "graded");
    let mesh = &s.mesh;
    let lengths = s.edge_lengths();
    let kappa = 2.0 * PI * euler_characteristic(mesh) as f64;
    let t = Instant::now();
    let (est, method) = match estimate(
        mesh,
        &IntrinsicMetric::euclidean(lengths.to_vec()),
        Scheme::Thurston,
        &PlacementOptions::default(),
    ) {
        Ok(x) => x,
        Err(e) => {
            eprintln!("{file}: {e}");
            return;
        }
    };
    println!("estimate ({method}): {:.2} s", t.elapsed().as_secs_f64());
    let mut order: Vec<u32> = (0..mesh.n_vertices() as u32)
        .filter(|&v| est[v as usize].is_finite())
        .collect();
    order.sort_by(|&a, &b| est[a as usize].total_cmp(&est[b as usize]).then(a.cmp(&b)));
    for &v in order.iter().take(count) {
        let refined = match candidate_mesh(
            mesh,
            &IntrinsicMetric::euclidean(lengths.to_vec()),
            v,
            kappa,
            graded,
        ) {
            Ok(r) => r,
            Err(e) => {
                println!("vertex {v}: {e}");
                continue;
            }
        };
        let m = &refined.mesh;
        let nv = m.n_vertices();
        let mut hop = vec![usize::MAX; nv];
        hop[v as usize] = 0;
        let mut q = VecDeque::from([v]);
        while let Some(x) = q.pop_front() {
            for w in m.vertex_neighbors(x) {
                if hop[w as usize] == usize::MAX {
                    hop[w as usize] = hop[x as usize] + 1;
                    q.push_back(w);
                }
            }
        }
        println!(
            "vertex {v} (estimate {:.3}, {}): valence {} → {}, {} → {} vertices",
            est[v as usize],
            if graded { "graded" } else { "ungraded" },
            mesh.valence(v),
            m.valence(v),
            mesh.n_vertices(),
            nv
        );
        for &scheme in &schemes {
            let t = Instant::now();
            let run = ricci_flow(
                m,
                &refined.lengths,
                &FlowOptions {
                    geometry: Geometry::Euclidean,
                    scheme,
                    target: TargetSpec::Cones(vec![(v, kappa)]),
                    tolerance: 1e-9,
                    max_iterations: Some(max_it),
                    ..FlowOptions::default()
                },
                &mut NoProgress,
            );
            let f = match run {
                Ok(f) => f,
                Err(e) => {
                    println!("  {scheme}: {e}");
                    continue;
                }
            };
            let hist: Vec<String> = f
                .history
                .iter()
                .take(12)
                .map(|h| format!("{:.3e}", h.max_curvature_error))
                .collect();
            println!(
                "  {scheme}: converged {}, max |K − K̄| {:.3e} after {} iterations, {} faces violate a triangle inequality, {:.2} s; history {}",
                f.converged,
                f.max_curvature_error,
                f.iterations,
                f.degenerate_faces,
                t.elapsed().as_secs_f64(),
                hist.join(" ")
            );
            for n in &f.notes {
                println!("    note: {n}");
            }
            // u is shifted by one constant (the area normalization), so jumps are exact; if
            // the shift overflowed, say so.
            if !f.u.iter().all(|x| x.is_finite()) {
                println!(
                    "    (u not finite after the area normalization: rerun with fewer iterations)"
                );
                continue;
            }
            for d in 0..10 {
                let ring: Vec<usize> = (0..nv).filter(|&i| hop[i] == d).collect();
                if ring.is_empty() {
                    break;
                }
                let lo = ring.iter().map(|&i| f.u[i]).fold(f64::INFINITY, f64::min);
                let hi = ring
                    .iter()
                    .map(|&i| f.u[i])
                    .fold(f64::NEG_INFINITY, f64::max);
                let mut jump: f64 = 0.0;
                for &i in &ring {
                    for w in m.vertex_neighbors(i as u32) {
                        if hop[w as usize] > d {
                            jump = jump.max((f.u[w as usize] - f.u[i]).abs());
                        }
                    }
                }
                let bad = (0..m.n_faces() as u32)
                    .filter(|&g| {
                        let t = m.face(g);
                        t.iter().map(|&x| hop[x as usize]).min() == Some(d) && {
                            let l = m.face_edges_opposite(g).map(|e| f.lengths[e as usize]);
                            (0..3).any(|i| l[i] >= l[(i + 1) % 3] + l[(i + 2) % 3])
                        }
                    })
                    .count();
                println!(
                    "    ring {d}: {} vertices, u in [{lo:.2}, {hi:.2}], largest outward jump {jump:.2}, {bad} faces violate a triangle inequality",
                    ring.len()
                );
            }
        }
    }
}
