//! Benchmark: manifold splines with a single extraordinary point, in the form of paper 000
//! Table 1 (g, N_f, N_c, T_ricci, T_spline, n, continuity) plus errors and the seam's normal
//! jump.
//!
//! `RICCI_MESHES=/work/shared/meshes cargo run --release -p ricci --example bench_spline [-- [--degree N] [--fairness R] [--fit] [--atlas] files…]`
//! (`--atlas`: charts of `ricci::atlas::AffineAtlas` instead of `LocalCharts`; the row names
//! the atlas's charts and how many of them are local charts of the cone's graded
//! neighbourhood)
//! (default: eight.off 3holes.off fertility.off kitten.nf20k.off face.off; `genus2:RES` is
//! a generated genus-2 surface).

use ricci::atlas::FlatCharts;
use ricci::mesh::io::read_surface;
use ricci::progress::NoProgress;
use ricci::spline::surface::{flat_domain, run, MeshDistance, Singularity, SplineOptions};
use std::path::PathBuf;
use std::time::Instant;

fn main() {
    let dir = PathBuf::from(
        std::env::var("RICCI_MESHES").unwrap_or_else(|_| "/work/shared/meshes".into()),
    );
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let mut opts = SplineOptions::default();
    let take = |name: &str, args: &mut Vec<String>| -> Option<usize> {
        let i = args.iter().position(|a| a == name)?;
        let v = args.get(i + 1)?.parse().ok();
        args.drain(i..i + 2);
        v
    };
    if let Some(n) = take("--degree", &mut args) {
        opts.degree = n;
    }
    if let Some(r) = take("--fairness", &mut args) {
        opts.fairness = r;
    }
    let mut use_atlas = false;
    if let Some(i) = args.iter().position(|a| a == "--atlas") {
        use_atlas = true;
        args.remove(i);
    }
    if let Some(i) = args.iter().position(|a| a == "--fit") {
        opts.fit_smoothing = Some(1e-3);
        args.remove(i);
    }
    if args.is_empty() {
        args = [
            "eight.off",
            "3holes.off",
            "fertility.off",
            "kitten.nf20k.off",
            "face.off",
        ]
        .map(String::from)
        .to_vec();
    }
    println!("| mesh | g | N_f | N_c | T_ricci s | T_spline s | n | r | continuity | max jump order n−1 | seam jump ° | rms % | max % | knots s | fairing s | fit s | fill s |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for f in args {
        let surface = if let Some(res) = f.strip_prefix("genus2:") {
            match ricci::mesh::generate::genus(2, res.parse().unwrap_or(16)) {
                Ok(s) => s,
                Err(e) => {
                    eprintln!("{f}: {e}");
                    continue;
                }
            }
        } else {
            match read_surface(&dir.join(&f)) {
                Ok((s, _)) => s,
                Err(e) => {
                    eprintln!("{f}: {e}");
                    continue;
                }
            }
        };
        let t = Instant::now();
        if use_atlas {
            let atlas = match ricci::atlas::AffineAtlas::build(
                &surface,
                &ricci::atlas::AtlasOptions::default(),
                &mut NoProgress,
            ) {
                Ok(a) => a,
                Err(e) => {
                    eprintln!("{f}: {e}");
                    continue;
                }
            };
            let t_ricci = t.elapsed().as_secs_f64();
            let dist = MeshDistance::new(&surface.positions, surface.mesh.faces());
            match run(&atlas, &dist, &opts, 4, &mut NoProgress) {
                Ok((rep, _, _)) => {
                    let n = rep.degree;
                    println!(
                        "| {f} (atlas, {} charts, {} local in {:.3} s) | {} | {} | {} | {:.2} | {:.3} | {} | {} | {} | {:.1e} | {} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} |",
                        atlas.n_charts(),
                        atlas.report.local_charts,
                        atlas.report.seconds_local_charts,
                        atlas.report.genus,
                        rep.domain_faces,
                        rep.control_points,
                        t_ricci,
                        rep.seconds,
                        n,
                        rep.fairness,
                        rep.continuity.class,
                        rep.continuity.relative_jumps[n - 1],
                        if rep.continuity.seams.is_empty() {
                            "–".to_string()
                        } else {
                            format!("{:.2e}", rep.continuity.max_seam_normal_jump_deg)
                        },
                        rep.rms_error_percent,
                        rep.max_error_percent,
                        rep.seconds_knots,
                        rep.seconds_fairing,
                        rep.seconds_fit,
                        rep.seconds_fill
                    );
                }
                Err(e) => eprintln!("{f} (atlas): {e}"),
            }
            continue;
        }
        let dom = match flat_domain(&surface, Singularity::Auto, &mut NoProgress) {
            Ok(d) => d,
            Err(e) => {
                eprintln!("{f}: {e}");
                continue;
            }
        };
        let t_ricci = t.elapsed().as_secs_f64();
        let dist = MeshDistance::new(&surface.positions, surface.mesh.faces());
        match run(&dom.charts, &dist, &opts, 4, &mut NoProgress) {
            Ok((rep, tess, _)) => {
                if std::env::var("SPLINE_DEBUG").is_ok() {
                    let bad: Vec<usize> = tess
                        .positions
                        .iter()
                        .enumerate()
                        .filter(|(_, p)| p.iter().any(|x| !x.is_finite()))
                        .map(|(i, _)| i)
                        .collect();
                    let infs: Vec<usize> = tess
                        .positions
                        .iter()
                        .enumerate()
                        .filter(|(_, p)| !dist.distance(**p).is_finite())
                        .map(|(i, _)| i)
                        .collect();
                    eprintln!(
                        "inf distance: {} e.g. {:?}",
                        infs.len(),
                        infs.first().map(|&i| tess.positions[i])
                    );
                    eprintln!(
                        "mesh verts 0 {:?} bbox {:?}",
                        surface.positions[0],
                        surface.bounding_box()
                    );
                    eprintln!(
                        "non-finite: {} of {}; first faces {:?}",
                        bad.len(),
                        tess.positions.len(),
                        bad.iter()
                            .take(5)
                            .map(|&i| tess.vertex_face[i])
                            .collect::<Vec<_>>()
                    );
                }
                let n = rep.degree;
                println!(
                    "| {f} | {} | {} | {} | {:.2} | {:.3} | {} | {} | {} | {:.1e} | {} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} |",
                    dom.genus,
                    rep.domain_faces,
                    rep.control_points,
                    t_ricci,
                    rep.seconds,
                    n,
                    rep.fairness,
                    rep.continuity.class,
                    rep.continuity.relative_jumps[n - 1],
                    if rep.continuity.seams.is_empty() {
                        "–".to_string()
                    } else {
                        format!("{:.2e}", rep.continuity.max_seam_normal_jump_deg)
                    },
                    rep.rms_error_percent,
                    rep.max_error_percent,
                    rep.seconds_knots,
                    rep.seconds_fairing,
                    rep.seconds_fit,
                    rep.seconds_fill
                );
            }
            Err(e) => eprintln!("{f}: {e}"),
        }
    }
}
