//! `ricci param` benchmark: conformal UV maps (`ricci::param::parametrize`) of the shared
//! meshes of issue 16 with the cone counts of the BFF comparison. Prints per case: faces,
//! cones, flipped input faces, qc mean / p95 (count- and area-weighted) / max, σ(log area ratio), seam length, flow
//! flips, wall seconds. Cases ending in `+c` run one round of
//! `ParamOptions::cone_corrections`; `BENCH_PARAM_CHARTS=1` also prints per chart the flow
//! runs, corrections and the flow's σ(2u). Cases ending in `w` use the wide cone search
//! (`ConeSearch::Energy`), in `f` free homology seams (`SeamMode::Free`, `--seams free`).
//! `BENCH_PARAM_CONES=N` or `auto:D` replaces
//! the case's cones by `N` greedy cones or `--cones auto --max-area-distortion D`.
//!
//! ```sh
//! RICCI_MESHES=/work/shared/meshes cargo run --release -p ricci --example bench_param
//! RICCI_MESHES=/work/shared/meshes cargo run --release -p ricci --example bench_param -- face
//! RICCI_MESHES=/work/shared/meshes cargo run --release -p ricci --example bench_param -- =camel-8
//! ```

use ricci::mesh::io::read_surface;
use ricci::param::cones::{ConeSearch, CurvatureRule};
use ricci::param::{parametrize, ConeSpec, ParamOptions, SeamMode};
use ricci::progress::NoProgress;
use std::path::PathBuf;

fn main() {
    let dir = match std::env::var_os("RICCI_MESHES") {
        Some(d) => PathBuf::from(d),
        None => {
            eprintln!("set RICCI_MESHES to the shared mesh folder");
            return;
        }
    };
    let filter: Vec<String> = std::env::args().skip(1).collect();
    let cases: Vec<(&str, &str, ConeSpec)> = vec![
        ("face", "face.off", ConeSpec::Default),
        ("camelhead", "camelhead.off", ConeSpec::Default),
        ("bunny", "bunny.off", ConeSpec::Default),
        ("beetle", "beetle.off", ConeSpec::Default),
        ("kitten", "kitten.nf20k.off", ConeSpec::Default),
        ("rocker-arm", "rocker-arm.off", ConeSpec::Default),
        ("botijo-8", "botijo.off", ConeSpec::Count(8)),
        ("botijo-8+c", "botijo.off", ConeSpec::Count(8)),
        ("botijo-12", "botijo.off", ConeSpec::Count(12)),
        ("botijo-16", "botijo.off", ConeSpec::Count(16)),
        (
            "botijo-auto-4",
            "botijo.off",
            ConeSpec::Auto {
                max_area_distortion: 4.0,
            },
        ),
        ("seahorse-8", "seahorse2_100K.off", ConeSpec::Count(8)),
        ("horse-8", "horse.ply", ConeSpec::Count(8)),
        ("horse-8+c", "horse.ply", ConeSpec::Count(8)),
        ("maxplanck-8", "maxplanck.nf25k.off", ConeSpec::Count(8)),
        ("maxplanck-8+c", "maxplanck.nf25k.off", ConeSpec::Count(8)),
        ("camel-8", "camel.off", ConeSpec::Count(8)),
        ("botijo-8w", "botijo.off", ConeSpec::Count(8)),
        ("seahorse-8w", "seahorse2_100K.off", ConeSpec::Count(8)),
        ("horse-8w", "horse.ply", ConeSpec::Count(8)),
        ("maxplanck-8w", "maxplanck.nf25k.off", ConeSpec::Count(8)),
        ("camel-8w", "camel.off", ConeSpec::Count(8)),
        ("botijo-8f", "botijo.off", ConeSpec::Count(8)),
        ("seahorse-8f", "seahorse2_100K.off", ConeSpec::Count(8)),
        ("camel-8f", "camel.off", ConeSpec::Count(8)),
        ("kitten-8f", "kitten.nf20k.off", ConeSpec::Count(8)),
        ("eight-8f", "eight.off", ConeSpec::Count(8)),
        ("eight-8", "eight.off", ConeSpec::Count(8)),
        ("botijo-8fd", "botijo.off", ConeSpec::Count(8)),
        ("seahorse-8fd", "seahorse2_100K.off", ConeSpec::Count(8)),
        ("camel-8fd", "camel.off", ConeSpec::Count(8)),
        ("eight-auto", "eight.off", ConeSpec::Default),
        ("eight-auto+c", "eight.off", ConeSpec::Default),
    ];
    println!(
        "{:<14} {:>7} {:>5} {:>6} {:>7} {:>7} {:>8} {:>8} {:>8} {:>7} {:>9} {:>7} {:>8}",
        "case",
        "faces",
        "cones",
        "flips",
        "qc_mean",
        "qc_p95",
        "qcA_mean",
        "qcA_p95",
        "qc_max",
        "σ_logA",
        "seam_len",
        "iflips",
        "seconds"
    );
    for (name, file, cones) in cases {
        // A filter with '=' in front matches the case name exactly (`=camel-8`).
        let matches = |f: &String| match f.strip_prefix('=') {
            Some(exact) => name == exact,
            None => name.contains(f.as_str()),
        };
        if !filter.is_empty() && !filter.iter().any(matches) {
            continue;
        }
        let (s, _) = match read_surface(&dir.join(file)) {
            Ok(x) => x,
            Err(e) => {
                println!("{name:<14} read error: {e}");
                continue;
            }
        };
        let cones = match std::env::var("BENCH_PARAM_CONES") {
            Ok(c) => match c.strip_prefix("auto:") {
                Some(d) => ConeSpec::Auto {
                    max_area_distortion: d.parse().unwrap_or(1.0),
                },
                None => ConeSpec::Count(c.parse().unwrap_or(8)),
            },
            Err(_) => cones,
        };
        let opts = ParamOptions {
            cones,
            // `+c`: one round of cone-curvature correction on the nonlinear flow.
            cone_corrections: usize::from(name.ends_with("+c")),
            // `w`: the wide cone search (`ConeSearch::Energy`).
            cone_search: if name.ends_with('w') {
                ConeSearch::Energy
            } else {
                ConeSearch::Greedy
            },
            // `f`: free homology seams (`SeamMode::Free`).
            // `fd`: free seams with the Dirichlet rule for the cone curvatures (BFF's).
            free_cone_rule: if name.ends_with("fd") {
                CurvatureRule::Dirichlet
            } else {
                CurvatureRule::LeastSquares
            },
            seams: if name.ends_with('f') || name.ends_with("fd") {
                SeamMode::Free
            } else {
                SeamMode::Rigid
            },
            ..ParamOptions::default()
        };
        match parametrize(&s, &opts, &mut NoProgress) {
            Ok(p) => {
                let cones: usize = p.charts.iter().map(|c| c.cones.len()).sum();
                let flips: usize = p.charts.iter().map(|c| c.flips).sum();
                let seam: f64 = p.charts.iter().map(|c| c.seam_length).sum();
                println!(
                    "{:<14} {:>7} {:>5} {:>6} {:>7.4} {:>7.4} {:>8.4} {:>8.4} {:>8.3} {:>7.4} {:>9.3} {:>7} {:>8.3}",
                    name,
                    s.mesh.n_faces(),
                    cones,
                    p.stats.flipped_faces,
                    p.stats.qc_mean,
                    p.stats.qc_p95,
                    p.stats.qc_mean_area,
                    p.stats.qc_p95_area,
                    p.stats.qc_max,
                    p.stats.log_area_sigma,
                    seam,
                    flips,
                    p.seconds
                );
            }
            Err(e) => println!("{name:<14} error: {e}"),
        }
        if std::env::var_os("BENCH_PARAM_CHARTS").is_some() {
            if let Ok(p) = parametrize(&s, &opts, &mut NoProgress) {
                for c in &p.charts {
                    println!(
                        "  chart {}: flow runs {}, cone corrections {}, σ(2u) {:.4}, moved cones {}, flow {:.2} s, chart {:.2} s, uv on {}, input faces folded {}",
                        c.component, c.flow_runs, c.cone_corrections, c.log_scale_sigma, c.moved_cones, c.flow_seconds, c.seconds, c.uv_faces, c.input_flipped_faces
                    );
                    let k: Vec<String> = c
                        .cones
                        .iter()
                        .map(|x| format!("{}:{:.2}", x.vertex, x.curvature))
                        .collect();
                    println!("  cones {}", k.join(" "));
                }
            }
        }
    }
}
