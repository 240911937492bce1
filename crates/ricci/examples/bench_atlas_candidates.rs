//! Benchmark: the candidate flows of the automatic singularity placement (paper 000 §4
//! Step 1) — which candidates converge, with which scheme, on which mesh (graded or not),
//! in how many Newton iterations and how much CPU time; and the whole atlas build.
//!
//! `RICCI_MESHES=/work/shared/meshes cargo run --release -p ricci --example
//! bench_atlas_candidates -- [--iterations N] [--budget N] [--no-grade] [--no-atlas] FILE …`
//! (`--iterations` / `--budget`: `PlacementOptions::candidate_iterations` /
//! `confirm_budget`, `--budget 0` means unlimited; `--no-grade`: `grade = false`). CPU seconds are this process's user +
//! system time (`/proc/self/stat`), so they do not count other engineers' load.

use ricci::atlas::placement::place;
use ricci::atlas::{AffineAtlas, AtlasOptions, FlatCharts, Singularity};
use ricci::mesh::io::read_surface;
use ricci::metric::IntrinsicMetric;
use ricci::progress::NoProgress;
use std::path::PathBuf;
use std::time::Instant;

fn cpu_seconds() -> f64 {
    let s = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    // Fields after the command name (which is in parentheses): utime is field 14, stime 15.
    let rest = s.rsplit(')').next().unwrap_or("");
    let f: Vec<&str> = rest.split_whitespace().collect();
    let t = |i: usize| f.get(i).and_then(|x| x.parse::<f64>().ok()).unwrap_or(0.0);
    (t(11) + t(12)) / 100.0
}

fn main() {
    let dir =
        PathBuf::from(std::env::var("RICCI_MESHES").unwrap_or_else(|_| "../shared/meshes".into()));
    let mut opts = AtlasOptions::default();
    let mut files = Vec::new();
    let mut atlas = true;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--iterations" => {
                opts.placement.candidate_iterations =
                    args.next().and_then(|x| x.parse().ok()).unwrap_or(40)
            }
            "--budget" => {
                let b: usize = args.next().and_then(|x| x.parse().ok()).unwrap_or(300);
                opts.placement.confirm_budget = if b == 0 { usize::MAX } else { b };
            }
            "--no-atlas" => atlas = false,
            "--no-grade" => opts.placement.grade = false,
            _ => files.push(a),
        }
    }
    println!(
        "| mesh | vertices | genus | chosen | confirmed: vertex D scheme graded iterations | rejected: vertex best max|K−K̄| iterations | flow iterations | placement CPU s | atlas CPU s | atlas |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for f in files {
        let (s, _) = match read_surface(&dir.join(&f)) {
            Ok(x) => x,
            Err(e) => {
                eprintln!("{f}: {e}");
                continue;
            }
        };
        let genus = ricci::mesh::topology(&s.mesh).genus();
        let lengths = s.edge_lengths();
        let c0 = cpu_seconds();
        let t = Instant::now();
        let p = place(
            &s,
            &IntrinsicMetric::euclidean(lengths.to_vec()),
            &opts,
            &mut NoProgress,
        );
        let c_place = cpu_seconds() - c0;
        let w_place = t.elapsed().as_secs_f64();
        let p = match p {
            Ok(p) => p,
            Err(e) => {
                println!(
                    "| {f} | {} | {genus} | — | failed: {e} | | | {c_place:.1} (wall {w_place:.1}) | | |",
                    s.mesh.n_vertices()
                );
                continue;
            }
        };
        let conf: Vec<String> = p
            .confirmed
            .iter()
            .map(|c| {
                format!(
                    "{} {:.4} {} {} {}",
                    c.vertex,
                    c.measured,
                    c.scheme,
                    if c.graded { "graded" } else { "-" },
                    c.iterations
                )
            })
            .collect();
        let rej: Vec<String> = p
            .rejected
            .iter()
            .map(|r| {
                format!(
                    "{} {} {}",
                    r.vertex,
                    r.best_error.map_or("—".into(), |e| format!("{e:.2e}")),
                    r.iterations
                )
            })
            .collect();
        let (c_atlas, outcome) = if atlas {
            let c1 = cpu_seconds();
            let a = AffineAtlas::build(
                &s,
                &AtlasOptions {
                    singularity: Singularity::Vertex(p.chosen),
                    ..opts.clone()
                },
                &mut NoProgress,
            );
            let out = match a {
                Ok(a) => format!(
                    "{} charts, flow {} {:.1e}, D {:.3}, transitions {:.1e}",
                    a.n_charts(),
                    a.report.scheme,
                    a.report.max_curvature_error,
                    a.report.area_distortion,
                    a.report.max_transition_error
                ),
                Err(e) => format!("failed: {e}"),
            };
            (format!("{:.1}", cpu_seconds() - c1), out)
        } else {
            (String::new(), String::new())
        };
        println!(
            "| {f} | {} | {genus} | {} | {} | {} | {} | {c_place:.1} (wall {w_place:.1}) | {c_atlas} | {outcome} |",
            s.mesh.n_vertices(),
            p.chosen,
            conf.join("; "),
            rej.join("; "),
            p.flow_iterations
        );
    }
}
