//! Discrete conformal equivalence benchmark (`--scheme conformal`: vertex scaling with
//! intrinsic Delaunay / Ptolemy flips, `ricci::flow::conformal`): per mesh V, F, geometry,
//! Newton iterations, flips (isometric initial + Ptolemy), splits of `to_simplicial`,
//! max |K − K̄|, wall and CPU seconds of `ricci_flow`.
//!
//! ```sh
//! RICCI_MESHES=/work/shared/meshes cargo run --release -p ricci --example bench_conformal
//! RICCI_MESHES=/work/shared/meshes cargo run --release -p ricci --example bench_conformal -- kitten
//! RICCI_MESHES=/work/shared/meshes cargo run --release -p ricci --example bench_conformal -- torus1M
//! ```
//!
//! `torus1M` (only when named) is the generated torus of revolution R = 1, r = 0.3 with 1174
//! columns (1 000 248 faces), flattened in E². The last column is the peak resident memory
//! of the process so far (`VmHWM`): run one case per process to read it per case.

use ricci::flow::{ricci_flow, FlowOptions, TargetSpec};
use ricci::mesh::io::read_surface;
use ricci::metric::{Geometry, Scheme};
use ricci::progress::NoProgress;
use std::path::PathBuf;
use std::time::Instant;

fn main() {
    let dir = match std::env::var_os("RICCI_MESHES") {
        Some(d) => PathBuf::from(d),
        None => {
            eprintln!("set RICCI_MESHES to the shared mesh folder");
            return;
        }
    };
    let filter: Vec<String> = std::env::args().skip(1).collect();
    use Geometry::*;
    let cases: [(&str, &str, Geometry, TargetSpec); 12] = [
        (
            "kitten E2",
            "kitten.nf20k.off",
            Euclidean,
            TargetSpec::Uniform,
        ),
        ("torus E2", "torus.off", Euclidean, TargetSpec::Uniform),
        (
            "rocker-arm E2",
            "rocker-arm.off",
            Euclidean,
            TargetSpec::Uniform,
        ),
        ("eight H2", "eight.off", Hyperbolic, TargetSpec::Uniform),
        ("3holes H2", "3holes.off", Hyperbolic, TargetSpec::Uniform),
        ("botijo H2", "botijo.off", Hyperbolic, TargetSpec::Uniform),
        (
            "seahorse H2",
            "seahorse2_100K.off",
            Hyperbolic,
            TargetSpec::Uniform,
        ),
        (
            "camelhead E2 free",
            "camelhead.off",
            Euclidean,
            TargetSpec::FreeBoundary,
        ),
        (
            "camelhead E2 round",
            "camelhead.off",
            Euclidean,
            TargetSpec::RoundBoundary,
        ),
        (
            "face E2 round",
            "face.off",
            Euclidean,
            TargetSpec::RoundBoundary,
        ),
        (
            "beetle H2 geodesic",
            "beetle.off",
            Hyperbolic,
            TargetSpec::GeodesicBoundary,
        ),
        (
            "bunny E2 free",
            "bunny.off",
            Euclidean,
            TargetSpec::FreeBoundary,
        ),
    ];
    println!(
        "{:<20} {:>7} {:>7} {:>4} {:>5} {:>8} {:>8} {:>6} {:>10} {:>5} {:>8} {:>8} {:>7}",
        "case",
        "V",
        "F",
        "geom",
        "iters",
        "init",
        "flips",
        "splits",
        "max|K-K̄|",
        "conv",
        "seconds",
        "cpu",
        "peak MB"
    );
    let generated = filter.iter().any(|f| f == "torus1M");
    let cases = cases
        .into_iter()
        .filter(|c| filter.is_empty() || filter.iter().any(|f| c.0.contains(f.as_str())))
        .map(|(n, f, g, t)| (n, Some(f), g, t))
        .chain(generated.then_some(("torus1M E2", None, Euclidean, TargetSpec::Uniform)));
    for (name, file, geometry, target) in cases {
        let read = match file {
            Some(file) => read_surface(&dir.join(file)).map(|x| x.0),
            None => ricci::mesh::generate::torus(1.0, 0.3, 1174),
        };
        let s = match read {
            Ok(x) => x,
            Err(e) => {
                println!("{name}: {e}");
                continue;
            }
        };
        let o = FlowOptions {
            geometry,
            scheme: Scheme::Conformal,
            target,
            ..FlowOptions::default()
        };
        let t = Instant::now();
        let c0 = cpu_seconds();
        let r = ricci_flow(&s.mesh, &s.edge_lengths(), &o, &mut NoProgress);
        let secs = t.elapsed().as_secs_f64();
        let cpu = cpu_seconds() - c0;
        match r {
            Ok(r) => {
                let tri = r.triangulation.as_ref().unwrap();
                println!(
                    "{:<20} {:>7} {:>7} {:>4} {:>5} {:>8} {:>8} {:>6} {:>10.2e} {:>5} {:>8.3} {:>8.3} {:>7.0}",
                    name,
                    s.mesh.n_vertices(),
                    s.mesh.n_faces(),
                    if geometry == Euclidean { "E2" } else { "H2" },
                    r.iterations,
                    tri.initial_flips,
                    tri.flips,
                    tri.splits,
                    r.max_curvature_error,
                    r.converged,
                    secs,
                    cpu,
                    peak_rss_mb()
                );
                if !r.notes.is_empty() {
                    println!("    notes: {:?}", r.notes);
                }
            }
            Err(e) => println!("{name}: error: {e}"),
        }
    }
}

/// CPU time of this thread (`/proc/self/schedstat`, nanoseconds on the CPU): the machine is
/// shared, so wall time can exceed it.
fn cpu_seconds() -> f64 {
    std::fs::read_to_string("/proc/self/schedstat")
        .ok()
        .and_then(|s| {
            s.split_whitespace()
                .next()
                .and_then(|x| x.parse::<f64>().ok())
        })
        .map(|ns| ns * 1e-9)
        .unwrap_or(f64::NAN)
}

/// Peak resident memory of this process so far in MB (`VmHWM` of `/proc/self/status`).
fn peak_rss_mb() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1))
                .and_then(|x| x.parse::<f64>().ok())
        })
        .map(|kb| kb / 1024.0)
        .unwrap_or(f64::NAN)
}
