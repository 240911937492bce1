//! The conformal sphere (`flow::sphere::conformal_sphere`) on closed genus-0 meshes: rounds,
//! Newton steps, flips, link size, chords-vs-metric residual and time.
//!
//! `RICCI_MESHES=/work/shared/meshes cargo run --release -p ricci --example bench_sphere [-- NAME... [--verbose]]`

use ricci::flow::sphere::conformal_sphere;
use ricci::progress::Progress;
use std::time::Instant;

struct Print(bool);
impl Progress for Print {
    fn report(&mut self, stage: &str, _f: Option<f64>, m: &str) {
        if self.0 {
            eprintln!("  {stage}: {m}");
        }
    }
}

fn main() {
    let dir = std::path::PathBuf::from(std::env::var("RICCI_MESHES").expect("RICCI_MESHES"));
    let args: Vec<String> = std::env::args().skip(1).collect();
    let verbose = args.iter().any(|a| a == "--verbose");
    let mut names: Vec<String> = args.into_iter().filter(|a| !a.starts_with("--")).collect();
    if names.is_empty() {
        names = ["sphere.off", "spot.obj", "maxplanck.nf25k.off", "horse.ply"]
            .map(String::from)
            .to_vec();
    }
    println!(
        "mesh | V | F | rounds | Newton | initial flips | flips | link | chords vs metric | s"
    );
    for name in names {
        let s = ricci::mesh::io::read_surface(&dir.join(&name)).unwrap().0;
        let l = s.edge_lengths();
        let t0 = Instant::now();
        let c0 = cpu_seconds();
        match conformal_sphere(&s.mesh, &l, 1e-11, 50, &mut Print(verbose)) {
            Ok(c) => {
                println!(
                    "| {name} | {} | {} | {} | {} | {} | {} | {} | {:.1e} | {:.0} | {:.3} | {:.3} |",
                    s.mesh.n_vertices(),
                    s.mesh.n_faces(),
                    c.rounds,
                    c.iterations,
                    c.initial_flips,
                    c.flips,
                    c.link_vertices,
                    c.conformal_residual,
                    peak_rss_mb(),
                    t0.elapsed().as_secs_f64(),
                    cpu_seconds() - c0
                );
                for n in &c.notes {
                    println!("  note: {n}");
                }
            }
            Err(e) => println!("{name}: error {e}"),
        }
    }
}

/// CPU time of this thread (`/proc/self/schedstat`): the machine is shared.
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

/// Peak resident set size of the process so far (`VmHWM` of `/proc/self/status`), MB.
fn peak_rss_mb() -> f64 {
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
