//! Speed and quality of the procedural surfaces.
//!
//! `cargo run --release -p ricci --example bench_generate` prints, per generator and size, the
//! wall time (best of a few runs), faces per second, and the angle range.

use ricci::mesh::generate::*;
use ricci::mesh::quality::angle_stats;
use ricci::mesh::Surface;
use std::time::Instant;

fn bench(name: &str, runs: usize, f: impl Fn() -> ricci::Result<Surface>) {
    let mut best = f64::INFINITY;
    let mut last = None;
    for _ in 0..runs {
        let t = Instant::now();
        let s = f().expect("generation failed");
        best = best.min(t.elapsed().as_secs_f64());
        last = Some(s);
    }
    let s = last.expect("at least one run");
    let q = angle_stats(&s);
    let nf = s.mesh.n_faces();
    println!(
        "{name:<28} {:>9} faces {:>9.3} s {:>11.0} faces/s   angles {:5.1}°–{:5.1}°",
        nf,
        best,
        nf as f64 / best,
        q.min_angle_deg,
        q.max_angle_deg
    );
}

fn main() {
    println!("generator                        faces     time       faces/s   angles");
    bench("icosphere(3)", 5, || icosphere(3));
    bench("icosphere(8)", 3, || icosphere(8));
    bench("torus(1, 0.5, 48)", 5, || torus(1.0, 0.5, 48));
    bench("torus(1, 0.5, 866) ~1M", 3, || torus(1.0, 0.5, 866));
    bench("disk(64)", 5, || disk(64));
    bench("disk(512)", 1, || disk(512));
    bench("annulus(0.5, 1, 64)", 5, || annulus(0.5, 1.0, 64));
    bench("pair_of_pants(64)", 5, || pair_of_pants(64));
    bench("pair_of_pants(512)", 1, || pair_of_pants(512));
    bench("genus(2, 40) [demo]", 3, || genus(2, 40));
    bench("genus(3, 40)", 3, || genus(3, 40));
    bench("genus(4, 40)", 3, || genus(4, 40));
    bench("genus(2, 120)", 1, || genus(2, 120));
    bench("genus(2, 300)", 1, || genus(2, 300));
}
