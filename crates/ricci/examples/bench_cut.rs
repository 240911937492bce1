//! Benchmark of `ricci::cut::canonical_cut` (refinement around the base vertex, tree–cotree,
//! the canonical loops — cut-and-paste on closed surfaces, the greedy with boundary —, slicing
//! and the checks), on the shared meshes.
//!
//! ```sh
//! cargo run --release -p ricci --example bench_cut [-- MESH...]
//! ```
//!
//! Without arguments it runs botijo (82k faces, genus 5) and seahorse2_100K (100k faces,
//! genus 8) from `$RICCI_MESHES` (default `../shared/meshes`). Reading the file is not timed.
//! Environment: `BENCH_RUNS` (default 5), `BENCH_BASE` (base vertex), `BENCH_ATTEMPTS`
//! (attempts per round), `BENCH_VALENCE` (minimum valence at the base vertex). Failed attempts
//! are printed above each result line.

use ricci::cut::{canonical_cut, Construction, CutOptions};
use ricci::mesh::io::read_surface;
use ricci::metric::Geometry;
use ricci::metric::IntrinsicMetric;
use ricci::progress::NoProgress;
use std::path::PathBuf;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let files: Vec<PathBuf> = if args.is_empty() {
        let dir = std::env::var("RICCI_MESHES").unwrap_or_else(|_| "../shared/meshes".into());
        ["botijo.off", "seahorse2_100K.off"]
            .iter()
            .map(|f| PathBuf::from(&dir).join(f))
            .collect()
    } else {
        args.iter().map(PathBuf::from).collect()
    };
    let runs: usize = std::env::var("BENCH_RUNS")
        .ok()
        .and_then(|r| r.parse().ok())
        .unwrap_or(5);
    let base: Option<u32> = std::env::var("BENCH_BASE")
        .ok()
        .and_then(|r| r.parse().ok());
    // BENCH_CONSTRUCTION: cut-and-paste (default), greedy, greedy-then-cut-and-paste.
    let construction = match std::env::var("BENCH_CONSTRUCTION").as_deref() {
        Ok("greedy") => Construction::Greedy,
        Ok("greedy-then-cut-and-paste") => Construction::GreedyThenCutAndPaste,
        _ => Construction::CutAndPaste,
    };
    for f in files {
        let (s, _) = match read_surface(&f) {
            Ok(x) => x,
            Err(e) => {
                eprintln!("{}: {e}", f.display());
                continue;
            }
        };
        let lengths = s.edge_lengths();
        let mut times = Vec::new();
        let mut last = None;
        for _ in 0..runs {
            let t = Instant::now();
            let c = canonical_cut(
                &s.mesh,
                &IntrinsicMetric::new(Geometry::Euclidean, lengths.to_vec()),
                Some(&s.positions),
                &CutOptions {
                    base,
                    max_attempts: std::env::var("BENCH_ATTEMPTS")
                        .ok()
                        .and_then(|r| r.parse().ok()),
                    min_valence: std::env::var("BENCH_VALENCE")
                        .ok()
                        .and_then(|r| r.parse().ok()),
                    construction,
                },
                &mut NoProgress,
            );
            times.push(t.elapsed().as_secs_f64());
            last = Some(c);
        }
        times.sort_by(|a, b| a.total_cmp(b));
        let name = f
            .file_name()
            .map(|n| n.to_string_lossy().to_string())
            .unwrap_or_default();
        match last {
            Some(Ok(c)) => {
                for f in &c.report.failed_attempts {
                    println!("  {f}");
                }
                let total: f64 = c.loops.iter().map(|l| l.length).sum();
                println!(
                    "{name}: F={} genus={} base={} valence {}→{} splits={} attempts={} searches={} moves={} rejected={:?} sides={} \
                     loops total length {:.4} (bbox diag {:.4}) | median {:.3} s, min {:.3} s over {runs} runs",
                    s.mesh.n_faces(),
                    c.genus,
                    c.base,
                    c.report.valence_before,
                    c.report.valence_after,
                    c.report.refinement_splits,
                    c.report.attempts,
                    c.report.search.searches,
                    c.report.search.moves,
                    c.report.search.rejected,
                    c.polygon.len(),
                    total,
                    s.diagonal(),
                    times[runs / 2],
                    times[0]
                );
            }
            Some(Err(e)) => println!("{name}: error: {e}"),
            None => {}
        }
    }
}
