//! Ricci flow benchmark: time, Newton steps and peak memory per mesh.
//!
//! ```sh
//! RICCI_MESHES=/work/shared/meshes cargo run --release -p ricci --example bench_flow
//! cargo run --release -p ricci --example bench_flow -- kitten     # cases whose name contains "kitten"
//! ```
//!
//! Every case runs in a child process (this executable with `--case NAME`) so that the peak
//! resident memory (VmHWM) belongs to that case alone. Times: `flow` is the wall time of
//! `ricci_flow` (building the conformal structure, checking the target, solving), `cpu` the CPU
//! time of the process during it (the machine is shared, so wall time can exceed it), `read`
//! the time to read and validate the mesh file.

use ricci::flow::{ricci_flow, separated_vertices, FlowOptions, Solver, TargetSpec};
use ricci::mesh::{generate, io::read_surface, Surface};
use ricci::metric::{euler_characteristic, Geometry, Scheme};
use ricci::progress::NoProgress;
use std::f64::consts::PI;
use std::path::PathBuf;
use std::time::Instant;

struct Case {
    name: &'static str,
    mesh: &'static str,
    geometry: Geometry,
    scheme: Scheme,
    target: &'static str,
    solver: Solver,
}

const fn case(
    name: &'static str,
    mesh: &'static str,
    geometry: Geometry,
    target: &'static str,
) -> Case {
    Case {
        name,
        mesh,
        geometry,
        scheme: Scheme::Thurston,
        target,
        solver: Solver::Newton,
    }
}

fn cases() -> Vec<Case> {
    use Geometry::*;
    let mut v = vec![
        case("kitten E2", "kitten.nf20k.off", Euclidean, "uniform"),
        case("eight H2", "eight.off", Hyperbolic, "uniform"),
        case("3holes H2", "3holes.off", Hyperbolic, "uniform"),
        case("botijo H2", "botijo.off", Hyperbolic, "uniform"),
        case("botijo E2 8 cones", "botijo.off", Euclidean, "cones"),
        case("seahorse H2", "seahorse2_100K.off", Hyperbolic, "uniform"),
        case(
            "camelhead E2 round",
            "camelhead.off",
            Euclidean,
            "round-boundary",
        ),
        case("maxplanck S2", "maxplanck.nf25k.off", Spherical, "uniform"),
        case("horse S2", "horse.ply", Spherical, "uniform"),
        case("torus 1M E2", "gen:torus", Euclidean, "uniform"),
    ];
    for (name, mesh, g, scheme) in [
        (
            "kitten E2 yamabe",
            "kitten.nf20k.off",
            Euclidean,
            Scheme::Yamabe,
        ),
        (
            "kitten E2 inversive",
            "kitten.nf20k.off",
            Euclidean,
            Scheme::Inversive,
        ),
        (
            "seahorse H2 tangential",
            "seahorse2_100K.off",
            Hyperbolic,
            Scheme::Tangential,
        ),
        ("horse S2 yamabe", "horse.ply", Spherical, Scheme::Yamabe),
    ] {
        v.push(Case {
            scheme,
            ..case(name, mesh, g, "uniform")
        });
    }
    for (name, mesh, g) in [
        ("torus.off E2 gradient", "torus.off", Euclidean),
        ("torus.off E2 newton", "torus.off", Euclidean),
        ("eight H2 gradient", "eight.off", Hyperbolic),
    ] {
        v.push(Case {
            solver: if name.ends_with("gradient") {
                Solver::Gradient
            } else {
                Solver::Newton
            },
            ..case(name, mesh, g, "uniform")
        });
    }
    v
}

fn cpu_seconds() -> f64 {
    // /proc/self/schedstat: time spent on the CPU in nanoseconds.
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

fn peak_mib() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines().find(|l| l.starts_with("VmHWM:")).and_then(|l| {
                l.split_whitespace()
                    .nth(1)
                    .and_then(|x| x.parse::<f64>().ok())
            })
        })
        .map(|kb| kb / 1024.0)
        .unwrap_or(f64::NAN)
}

fn run_case(c: &Case, dir: Option<&PathBuf>) -> Option<String> {
    let t0 = Instant::now();
    let s: Surface = if c.mesh == "gen:torus" {
        generate::torus(1.0, 0.5, 866).ok()?
    } else {
        let dir = dir?;
        let p = dir.join(c.mesh);
        if !p.exists() {
            return None;
        }
        read_surface(&p).ok()?.0
    };
    let read = t0.elapsed().as_secs_f64();
    let target = if c.target == "cones" {
        let chi = euler_characteristic(&s.mesh);
        let v = separated_vertices(&s.mesh, (-chi) as usize, 6);
        TargetSpec::Cones(v.iter().map(|&v| (v, -2.0 * PI)).collect())
    } else {
        c.target.parse().ok()?
    };
    let o = FlowOptions {
        geometry: c.geometry,
        scheme: c.scheme,
        target,
        solver: c.solver,
        gradient_step: 0.1,
        ..FlowOptions::default()
    };
    let lengths = s.edge_lengths();
    let cpu0 = cpu_seconds();
    let t1 = Instant::now();
    let r = ricci_flow(&s.mesh, &lengths, &o, &mut NoProgress);
    let wall = t1.elapsed().as_secs_f64();
    let cpu = cpu_seconds() - cpu0;
    Some(match r {
        Ok(r) => format!(
            "{:22} {:>8} {:10} {:10} {:>6} {:>9.2e} {:>8.3} {:>8.3} {:>7.2} {:>8.0} {}{}",
            c.name,
            s.mesh.n_faces(),
            c.scheme.name(),
            c.solver.name(),
            r.iterations,
            r.max_curvature_error,
            wall,
            cpu,
            read,
            peak_mib(),
            r.route,
            if r.converged { "" } else { " NOT CONVERGED" }
        ),
        Err(e) => format!("{:22} {:>8} refused: {e}", c.name, s.mesh.n_faces()),
    })
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let dir = std::env::var("RICCI_MESHES").ok().map(PathBuf::from);
    if args.len() == 3 && args[1] == "--case" {
        let all = cases();
        let c = all.iter().find(|c| c.name == args[2]).expect("known case");
        if let Some(line) = run_case(c, dir.as_ref()) {
            println!("{line}");
        }
        return;
    }
    let filter = args.get(1).cloned().unwrap_or_default();
    if dir.is_none() {
        eprintln!("note: RICCI_MESHES is not set; only generated meshes are benchmarked");
    }
    println!(
        "{:22} {:>8} {:10} {:10} {:>6} {:>9} {:>8} {:>8} {:>7} {:>8} route",
        "case",
        "faces",
        "scheme",
        "solver",
        "steps",
        "max|K-K̄|",
        "flow s",
        "cpu s",
        "read s",
        "peak MiB"
    );
    let exe = std::env::current_exe().expect("own executable");
    for c in cases().iter().filter(|c| c.name.contains(&filter)) {
        let out = std::process::Command::new(&exe)
            .args(["--case", c.name])
            .output()
            .expect("run case");
        print!("{}", String::from_utf8_lossy(&out.stdout));
        if !out.status.success() {
            println!(
                "{:22} failed: {}",
                c.name,
                String::from_utf8_lossy(&out.stderr).trim()
            );
        }
    }
}
