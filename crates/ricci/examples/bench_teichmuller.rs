//! Benchmark and comparison: Teichmüller coordinates (`ricci::analysis::teichmuller`) of
//! closed genus ≥ 2 meshes, with their midpoint subdivision and random off-centre face splits.
//!
//! `RICCI_MESHES=/work/shared/meshes cargo run --release -p ricci --example bench_teichmuller
//! [-- files…]` (default: eight.off cup_input_simple_10000.off). `FILE@V` cuts through base
//! vertex `V`; `FILE+` also runs the two re-triangulations.

use ricci::analysis::teichmuller::{surface_teichmuller, TeichmullerOptions};
use ricci::mesh::generate::{midpoint_subdivision, random_face_splits};
use ricci::mesh::io::read_surface;
use ricci::mesh::Surface;
use ricci::metric::IntrinsicMetric;
use ricci::progress::NoProgress;
use std::path::PathBuf;

fn run(name: &str, s: &Surface, base: Option<u32>) {
    let opts = TeichmullerOptions {
        base,
        ..Default::default()
    };
    match surface_teichmuller(
        &s.mesh,
        &IntrinsicMetric::euclidean(s.edge_lengths()),
        &opts,
        &mut NoProgress,
    ) {
        Ok(r) => {
            let c = &r.coordinates;
            let fmt = |v: &[f64]| {
                v.iter()
                    .map(|x| format!("{x:.5}"))
                    .collect::<Vec<_>>()
                    .join(" ")
            };
            println!(
                "{name} | faces {} | base {} | {:.2} s | relation {:.1e} | misplaced {} | FN [{}] | L [{}]",
                s.mesh.n_faces(),
                r.base,
                r.seconds,
                r.deck_relation_error,
                c.misplaced_seams,
                fmt(&c.fenchel_nielsen),
                fmt(&c.length_coordinates)
            );
        }
        Err(e) => println!("{name}: {e}"),
    }
}

fn main() {
    let dir =
        PathBuf::from(std::env::var("RICCI_MESHES").unwrap_or_else(|_| "../shared/meshes".into()));
    let mut files: Vec<String> = std::env::args().skip(1).collect();
    if files.is_empty() {
        files = vec!["eight.off".into(), "cup_input_simple_10000.off".into()];
    }
    for arg in files {
        let (arg, retri) = match arg.strip_suffix('+') {
            Some(a) => (a.to_string(), true),
            None => (arg, false),
        };
        let (f, base) = match arg.split_once('@') {
            Some((f, b)) => (f.to_string(), b.parse::<u32>().ok()),
            None => (arg.clone(), None),
        };
        let s = match read_surface(&dir.join(&f)) {
            Ok((s, _)) => s,
            Err(e) => {
                eprintln!("{f}: {e}");
                continue;
            }
        };
        run(&arg, &s, base);
        if retri {
            run(
                &format!("{arg} midpoint"),
                &midpoint_subdivision(&s).unwrap(),
                base,
            );
            run(
                &format!("{arg} splits"),
                &random_face_splits(&s, 0.5, 7).unwrap(),
                base,
            );
        }
    }
}
