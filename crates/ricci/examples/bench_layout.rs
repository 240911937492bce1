//! Benchmark: layout and deck group of large meshes with their hyperbolic uniformization
//! metric (flow and cut timed separately, as context).
//!
//! `RICCI_MESHES=../shared/meshes cargo run --release --example bench_layout [files…]`
//! (default: botijo.off seahorse2_100K.off). `FILE@V` cuts through base vertex `V` instead of
//! the cut's automatic choice. Flow tolerance 1e-12 (as `tests/layout_meshes.rs`), then the
//! metric polished to double-double (`ricci::flow::polish`, as `ricci layout` does by
//! default; `RICCI_NO_POLISH=1` skips it), cut with the double-double lengths
//! (`cut_disk_polished`) and `layout_dd`.

use ricci::layout::deck_group;
use ricci::layout::pipeline::{
    cut_disk, cut_disk_polished, polish_uniformization, uniformization_metric,
};
use ricci::layout::place::layout_dd;
use ricci::mesh::io::read_surface;
use ricci::metric::IntrinsicMetric;
use ricci::metric::{Geometry, Hyperbolic, Scheme};
use ricci::progress::NoProgress;
use std::path::PathBuf;
use std::time::Instant;

fn main() {
    let dir =
        PathBuf::from(std::env::var("RICCI_MESHES").unwrap_or_else(|_| "../shared/meshes".into()));
    let mut files: Vec<String> = std::env::args().skip(1).collect();
    if files.is_empty() {
        files = vec!["botijo.off".into(), "seahorse2_100K.off".into()];
    }
    let no_polish = std::env::var_os("RICCI_NO_POLISH").is_some();
    println!("| mesh | faces | genus | scheme | max abs(K − K̄) | flow s | polish (steps, dd residual, refined) | polish s | cut s | layout s | deck s | flipped | max radius | relation error | edge spread (matrices) | edge spread (points) | max length error |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for arg in files {
        let (f, base) = match arg.split_once('@') {
            Some((f, b)) => (f.to_string(), b.parse::<u32>().ok()),
            None => (arg.clone(), None),
        };
        let (s, _) = match read_surface(&dir.join(&f)) {
            Ok(x) => x,
            Err(e) => {
                eprintln!("{f}: {e}");
                continue;
            }
        };
        let genus = ricci::mesh::topology(&s.mesh).genus();
        let t = Instant::now();
        // Thurston circle packing (the papers'); vertex scaling if it is refused.
        let run = |scheme| {
            uniformization_metric(
                &s.mesh,
                &IntrinsicMetric::euclidean(s.edge_lengths()),
                Geometry::Hyperbolic,
                scheme,
                1e-12,
                &mut NoProgress,
            )
        };
        let mut scheme = Scheme::Thurston;
        let flow = match run(scheme) {
            Ok(r) => r,
            Err(e) => {
                eprintln!("{f}: Thurston flow refused ({e}); trying vertex scaling");
                scheme = Scheme::Yamabe;
                match run(scheme) {
                    Ok(r) => r,
                    Err(e) => {
                        eprintln!("{f}: flow: {e}");
                        continue;
                    }
                }
            }
        };
        let t_flow = t.elapsed().as_secs_f64();
        if !flow.converged {
            eprintln!(
                "{f}: the flow did not converge (max |K − K̄| = {:.1e} after {} iterations)",
                flow.max_curvature_error, flow.iterations
            );
        }
        let t = Instant::now();
        let polished = if no_polish {
            None
        } else {
            match polish_uniformization(
                &s.mesh,
                &IntrinsicMetric::euclidean(s.edge_lengths()),
                &flow,
            ) {
                Ok(p) => Some(p),
                Err(e) => {
                    eprintln!("{f}: polish: {e}");
                    None
                }
            }
        };
        let t_polish = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let disk = match &polished {
            Some(p) => cut_disk_polished(&s.mesh, &p.metric, None, base, &mut NoProgress),
            None => cut_disk(
                &s.mesh,
                &IntrinsicMetric::new(Geometry::Hyperbolic, flow.lengths.to_vec()),
                None,
                base,
                &mut NoProgress,
            ),
        };
        let disk = match disk {
            Ok(d) => d,
            Err(e) => {
                eprintln!("{f}: cut: {e}");
                continue;
            }
        };
        // The cut's time includes the polish of the refined metric.
        let t_cut = t.elapsed().as_secs_f64();
        let polish_cell = match (&polished, &disk.refined_polish) {
            (Some(p), r) => format!(
                "{}, {:.1e}{}",
                p.steps,
                p.residual_dd,
                r.map_or(String::new(), |r| format!(
                    "; {}, {:.1e}",
                    r.steps, r.residual_dd
                ))
            ),
            (None, _) => "off".to_string(),
        };
        let t = Instant::now();
        let l = layout_dd::<Hyperbolic>(&disk.mesh, &disk.metric, None).expect("layout");
        let t_layout = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let g = deck_group::<Hyperbolic>(&l, &disk.polygon).expect("deck group");
        let t_deck = t.elapsed().as_secs_f64();
        println!(
            "| {arg} | {} | {genus} | {} | {:.1e} | {t_flow:.2} | {polish_cell} | {t_polish:.2} | {t_cut:.2} | {t_layout:.3} | {t_deck:.3} | {} | {:.1} | {:.1e} | {:.1e} | {:.1e} | {:.1e} |",
            s.mesh.n_faces(),
            scheme.name(),
            flow.max_curvature_error,
            l.flipped_faces.len(),
            l.max_radius,
            g.relation_error.unwrap_or(f64::NAN),
            g.max_edge_spread_matrix,
            g.max_edge_spread,
            l.max_length_error
        );
    }
}
