//! Diagnostic for the genus ≥ 2 domain-mesh spline between the input vertices (issue 18): the
//! two fits of `ricci tspline` (vertices only; with points on the triangles), and for each the
//! cells where the spline is farthest from the input triangles — strip, cylinder, row and
//! column, cell size, how far from the strip's ends (a zero sits at a corner), how many data
//! vertices and triangle points the cell holds, and the largest vertex error in it
//! (`DIAG_STEPS=1`: the refinements; `DIAG_VERTICES=1`: the worst vertices and their cells).
//!
//! `cargo run --release -p ricci --example diag_between_vertices -- MESH [TOL] [SMOOTHING] [TOP] [THIN_PLATE]`
use ricci::analysis::forms::{holomorphic_forms, FormsOptions};
use ricci::metric::IntrinsicMetric;
use ricci::progress::NoProgress;
use ricci::spline::tspline::domain_fit::{
    deviation_between_vertices, deviation_per_cell, fit_domain_mesh_on_triangles, locate,
    triangle_points, DomainFitOptions,
};
use ricci::spline::tspline::genus_domain::best_genus_domain;
use ricci::spline::tspline::glue::gluing;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let Some(path) = args.get(1) else {
        eprintln!("usage: diag_between_vertices MESH [TOL] [SMOOTHING] [TOP] [THIN_PLATE]");
        std::process::exit(2);
    };
    let tol: f64 = args.get(2).and_then(|x| x.parse().ok()).unwrap_or(0.005);
    let smoothing: f64 = args.get(3).and_then(|x| x.parse().ok()).unwrap_or(1e-4);
    let top: usize = args.get(4).and_then(|x| x.parse().ok()).unwrap_or(8);
    let thin_plate: f64 = args.get(5).and_then(|x| x.parse().ok()).unwrap_or(0.0);
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
            "cylinder {c}: circumference {:.4}, height {:.4}, {} data points",
            ch.circumference, ch.height, ch.data_points
        );
    }
    let tris = s.mesh.faces();
    for w in [0.0, DomainFitOptions::default().between_vertices] {
        let opts = DomainFitOptions {
            tolerance: tol,
            smoothing,
            between_vertices: w,
            thin_plate,
            // as `ricci tspline`'s default --max-iterations
            max_iterations: 30,
            ..DomainFitOptions::default()
        };
        let t = std::time::Instant::now();
        let f = fit_domain_mesh_on_triangles(&d, &g, &s.positions, tris, &opts)?;
        let secs = t.elapsed().as_secs_f64();
        let m = &f.mesh;
        let (rms, linf) = f.errors_percent();
        let (bmax, brms) = deviation_between_vertices(&f, &s.positions, tris, 4);
        println!(
            "\nbetween_vertices {w}: {} cp, L∞ {linf:.3} % rms {rms:.3} %, between {bmax:.2} / {brms:.3} %, {} levels, {} blocks, {secs:.1} s",
            m.n_control_points(),
            f.levels,
            m.blocks.len()
        );
        if std::env::var("DIAG_STEPS").is_ok() {
            for r in &f.refinements {
                println!("  {r}");
            }
        }
        let mut verts = vec![0usize; m.n_cells()];
        let mut worst = vec![0.0f64; m.n_cells()];
        for (&(c, _, _), &e) in f.located.iter().zip(&f.errors) {
            verts[c as usize] += 1;
            worst[c as usize] = worst[c as usize].max(e);
        }
        let mut tri = vec![0usize; m.n_cells()];
        for e in triangle_points(&d, &s.positions, tris, 0.1) {
            if let Some((c, _, _)) = locate(m, &g, &d, e.0, e.1, e.2) {
                tri[c as usize] += 1;
            }
        }
        if std::env::var("DIAG_VERTICES").is_ok() {
            let mut by: Vec<usize> = (0..f.errors.len()).collect();
            by.sort_by(|&a, &b| f.errors[b].total_cmp(&f.errors[a]));
            for &k in by.iter().take(top) {
                let (c, ls, lt) = f.located[k];
                let (r, i, j) = m.cell_at[c as usize];
                let rc = &m.rects[r as usize];
                let (i, j) = (i as usize, j as usize);
                let (du, dv) = m.size(c);
                let (x, y) = (rc.x(i) + ls * du, rc.y(j) + lt * dv);
                println!(
                    "  vertex err {:.3} % cyl {} strip {} cell ({i},{j}) size {:.5}×{:.5}; from the ends {:.4}×{:.5}; near_zero {}",
                    f.errors[k] * 100.0 / f.scale,
                    rc.cylinder,
                    rc.strip,
                    du,
                    dv,
                    x.min(rc.length - x),
                    y.min(rc.height - y),
                    m.near_zero(c)
                );
            }
        }
        let per = deviation_per_cell(&f, &s.positions, tris, 4);
        let empty = (0..m.n_cells()).filter(|&c| verts[c] == 0).count();
        println!("  {} cells, {empty} without a vertex", m.n_cells());
        let mut order: Vec<usize> = (0..m.n_cells()).collect();
        order.sort_by(|&a, &b| per[b].0.total_cmp(&per[a].0));
        let pc = 100.0 / f.scale;
        for &c in order.iter().take(top) {
            let (r, i, j) = m.cell_at[c];
            let rc = &m.rects[r as usize];
            let (i, j) = (i as usize, j as usize);
            let (du, dv) = m.size(c as u32);
            let (x, y) = (rc.x(i) + per[c].1 * du, rc.y(j) + per[c].2 * dv);
            let (bu, bv) = (x.min(rc.length - x), y.min(rc.height - y));
            println!(
                "  {:.2} % cell {c} cyl {} strip {} ({i},{j}) of {}×{} size {:.4}×{:.4} (aspect {:.1}); from the ends {:.3}×{:.4} = {:.1}×{:.1} E; {} vertices (worst {:.3} %), {} tri pts; near_zero {}",
                per[c].0 * pc,
                rc.cylinder,
                rc.strip,
                rc.m,
                rc.n,
                du,
                dv,
                du.max(dv) / du.min(dv),
                bu,
                bv,
                bu / rc.edge_u,
                bv / rc.edge_v,
                verts[c],
                worst[c] * pc,
                tri[c],
                m.near_zero(c as u32)
            );
        }
    }
    Ok(())
}
