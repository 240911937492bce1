//! Benchmark: the affine atlas (paper 000 §4) — the automatic singularity placement against
//! the paper's brute force (one full flow per vertex, on every `STEP`-th vertex), and the
//! whole atlas build.
//!
//! `RICCI_MESHES=../shared/meshes cargo run --release -p ricci --example bench_atlas [FILE:STEP …]`
//! (default: eight.off:1 3holes.off:12 fertility.off:24).

use ricci::atlas::placement::{brute_force, place};
use ricci::atlas::{AffineAtlas, AtlasOptions, FlatCharts};
use ricci::mesh::io::read_surface;
use ricci::metric::IntrinsicMetric;
use ricci::metric::Scheme;
use ricci::progress::NoProgress;
use std::path::PathBuf;
use std::time::Instant;

fn main() {
    let dir =
        PathBuf::from(std::env::var("RICCI_MESHES").unwrap_or_else(|_| "../shared/meshes".into()));
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    if args.is_empty() {
        args = vec![
            "eight.off:1".into(),
            "3holes.off:12".into(),
            "fertility.off:24".into(),
        ];
    }
    println!("| mesh | vertices | genus | auto vertex | D(auto) | best D (brute) | median D | worst D | rank of auto | brute-force vertices | auto s | brute force s | atlas s | charts | max transition error |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for a in args {
        let (f, step) = match a.split_once(':') {
            Some((f, s)) => (f.to_string(), s.parse::<usize>().unwrap_or(1).max(1)),
            None => (a.clone(), 1),
        };
        let (s, _) = match read_surface(&dir.join(&f)) {
            Ok(x) => x,
            Err(e) => {
                eprintln!("{f}: {e}");
                continue;
            }
        };
        let genus = ricci::mesh::topology(&s.mesh).genus();
        let lengths = s.edge_lengths();
        let opts = AtlasOptions::default();
        let t = Instant::now();
        let p = match place(
            &s,
            &IntrinsicMetric::euclidean(lengths.to_vec()),
            &opts,
            &mut NoProgress,
        ) {
            Ok(p) => p,
            Err(e) => {
                eprintln!("{f}: {e}");
                continue;
            }
        };
        let t_auto = t.elapsed().as_secs_f64();
        let d_auto = p
            .confirmed
            .iter()
            .find(|c| c.vertex == p.chosen)
            .map(|c| c.measured)
            .unwrap_or(f64::NAN);
        let mut cand: Vec<u32> = (0..s.mesh.n_vertices() as u32).step_by(step).collect();
        if !cand.contains(&p.chosen) {
            cand.push(p.chosen);
        }
        let t = Instant::now();
        let bf = brute_force(
            &s.mesh,
            &IntrinsicMetric::euclidean(lengths.to_vec()),
            &cand,
            Scheme::Thurston,
            &mut NoProgress,
        );
        let t_bf = t.elapsed().as_secs_f64();
        let mut d: Vec<f64> = bf.iter().filter_map(|x| x.1).collect();
        d.sort_by(|a, b| a.total_cmp(b));
        let rank = d.iter().filter(|&&x| x < d_auto).count();
        let t = Instant::now();
        let atlas = AffineAtlas::build(
            &s,
            &AtlasOptions {
                singularity: ricci::atlas::Singularity::Vertex(p.chosen),
                ..AtlasOptions::default()
            },
            &mut NoProgress,
        );
        let t_atlas = t.elapsed().as_secs_f64();
        let (charts, trans) = atlas
            .as_ref()
            .map(|a| (a.n_charts(), a.report.max_transition_error))
            .unwrap_or((0, f64::NAN));
        println!(
            "| {f} | {} | {genus} | {} | {d_auto:.4} | {:.4} | {:.4} | {:.4} | {rank} of {} | every {step}th + auto ({} failed) | {t_auto:.2} | {t_bf:.1} | {t_atlas:.2} | {charts} | {trans:.1e} |",
            s.mesh.n_vertices(),
            p.chosen,
            d.first().copied().unwrap_or(f64::NAN),
            d.get(d.len() / 2).copied().unwrap_or(f64::NAN),
            d.last().copied().unwrap_or(f64::NAN),
            d.len(),
            bf.len() - d.len(),
        );
    }
}
