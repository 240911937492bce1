//! Diagnostic for the genus ≥ 2 domain-mesh fit's refinement (issue 18): per step of
//! [`fit_domain_mesh_on_triangles`] (the fit rerun with `max_iterations = k`), the control
//! points, and where the input vertices beyond the tolerance lie — per strip, next to a zero,
//! past a T-junction, in a block, or elsewhere — with the strip's graded cells.
//!
//! `cargo run --release -p ricci --example diag_domain_refinement -- MESH [TOL] [STEPS] [blocks]`
use ricci::analysis::forms::{holomorphic_forms, FormsOptions};
use ricci::metric::IntrinsicMetric;
use ricci::progress::NoProgress;
use ricci::spline::tspline::domain_fit::{fit_domain_mesh_on_triangles, DomainFitOptions};
use ricci::spline::tspline::genus_domain::best_genus_domain;
use ricci::spline::tspline::glue::gluing;
use std::collections::BTreeMap;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let Some(path) = args.get(1) else {
        eprintln!("usage: diag_domain_refinement MESH [TOL] [STEPS] [blocks]");
        std::process::exit(2);
    };
    let tol: f64 = args.get(2).and_then(|x| x.parse().ok()).unwrap_or(0.005);
    let steps: usize = args.get(3).and_then(|x| x.parse().ok()).unwrap_or(10);
    let blocks = args.get(4).is_none_or(|x| x != "noblocks");
    let (s, _) = ricci::mesh::io::read_surface(std::path::Path::new(path))?;
    let h = holomorphic_forms(
        &s.mesh,
        &IntrinsicMetric::euclidean(s.edge_lengths()),
        Some(&s.positions),
        &FormsOptions::default(),
        &mut NoProgress,
    )?;
    let d = best_genus_domain(&h, s.positions.len())?;
    let g = gluing(&d)?;
    for (c, ch) in d.cylinders.iter().enumerate() {
        println!(
            "cylinder {c}: circumference {:.4}, height {:.4}, {} data points, {} strips",
            ch.circumference,
            ch.height,
            ch.data_points,
            g.layouts[c].strips()
        );
    }
    for k in 1..=steps {
        let opts = DomainFitOptions {
            tolerance: tol,
            max_iterations: k,
            blocks,
            ..DomainFitOptions::default()
        };
        let f = fit_domain_mesh_on_triangles(&d, &g, &s.positions, s.mesh.faces(), &opts)?;
        let m = &f.mesh;
        let lim = tol * f.scale;
        // per strip: (near zero, past T-junction, elsewhere), worst error
        let mut per: BTreeMap<usize, ([usize; 3], f64)> = BTreeMap::new();
        for (&(c, ls, lt), &e) in f.located.iter().zip(&f.errors) {
            if e <= lim {
                continue;
            }
            let (r, _, _) = m.base_cell(c);
            let kind = if m.near_zero(c) {
                0
            } else if m.past_t_junction(c) {
                1
            } else {
                2
            };
            if kind == 0 && std::env::var("DIAG_NEAR").is_ok() {
                let (_, i, j) = m.cell_at[c as usize];
                let rc = &m.rects[r];
                let (i, j) = (i as usize, j as usize);
                let x = rc.x(i) + ls * (rc.x(i + 1) - rc.x(i));
                let y = rc.y(j) + lt * (rc.y(j + 1) - rc.y(j));
                println!(
                    "    near: cyl {} strip {} du/E {:.3} dv/E {:.3} (E {:.4} × {:.4}) err {:.3} %",
                    rc.cylinder,
                    rc.strip,
                    x.min(rc.length - x) / rc.edge_u / (1u64 << rc.levels) as f64,
                    y.min(rc.height - y) / rc.edge_v / (1u64 << rc.levels) as f64,
                    rc.edge_u * (1u64 << rc.levels) as f64,
                    rc.edge_v * (1u64 << rc.levels) as f64,
                    100.0 * e / f.scale
                );
            }
            let x = per.entry(r).or_default();
            x.0[kind] += 1;
            x.1 = x.1.max(100.0 * e / f.scale);
        }
        let st = f.steps.last().unwrap();
        println!(
            "step {k}: {} cp, L∞ {:.3} %, levels {}, {} blocks{}",
            st.control_points,
            st.max_error_percent,
            f.levels,
            m.blocks.len(),
            if f.converged { ", converged" } else { "" }
        );
        for (r, (n, w)) in &per {
            let rc = &m.rects[*r];
            println!(
                "  strip {} of cylinder {} ({} × {} graded, {} × {} cells): {} near a zero, {} past a T-junction, {} elsewhere; worst {w:.3} %",
                rc.strip, rc.cylinder, rc.base_m, rc.base_n, rc.m, rc.n, n[0], n[1], n[2]
            );
        }
        if let Some(r) = f.refinements.last() {
            println!("  {r}");
        }
        if f.converged || f.steps.len() < k {
            break;
        }
    }
    Ok(())
}
