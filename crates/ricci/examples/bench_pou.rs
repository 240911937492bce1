//! Benchmark: the partition-of-unity surface over the hyperbolic structure (paper 004,
//! `ricci::spline::pou`), phase by phase, with wall and CPU seconds (the machine is shared:
//! CPU seconds of the process are the stable number), the errors, and the derivative jumps
//! of orders 0–3 across chart boundaries.
//!
//! `RICCI_MESHES=/work/shared/meshes cargo run --release -p ricci --example bench_pou [-- [--local D] [--radius R] [--edges N] files…]`
//! (default: eight.off genus3.off 3holes.off fertility.off botijo.off; `--edges N`: the
//! continuity check samples about N edges, 0 for all; `genus2:RES` is a generated genus-2
//! surface).

use ricci::mesh::io::read_surface;
use ricci::progress::NoProgress;
use ricci::spline::pou::fit::fit;
use ricci::spline::pou::local::local_fits;
use ricci::spline::pou::measure::{
    chart_independence, continuity, tessellate, NearestTriangle, PouOptions,
};
use ricci::spline::pou::surface::{two_ring_radii, PouBasis, PouSurface};
use ricci::spline::pou::HyperbolicAtlas;
use std::path::PathBuf;
use std::time::Instant;

/// CPU seconds (user + system) of this process so far, from `/proc/self/stat`.
fn cpu_seconds() -> f64 {
    let s = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = s.rsplit(')').next().unwrap_or("");
    let f: Vec<&str> = after.split_whitespace().collect();
    let tick = |i: usize| f.get(i).and_then(|x| x.parse::<f64>().ok()).unwrap_or(0.0);
    // Fields 14 and 15 (utime, stime) are at 11 and 12 after the command name.
    (tick(11) + tick(12)) / 100.0
}

struct Clock(Instant, f64);
impl Clock {
    fn start() -> Clock {
        Clock(Instant::now(), cpu_seconds())
    }
    fn lap(&mut self) -> (f64, f64) {
        let r = (self.0.elapsed().as_secs_f64(), cpu_seconds() - self.1);
        *self = Clock::start();
        r
    }
}

fn main() {
    let dir = PathBuf::from(
        std::env::var("RICCI_MESHES").unwrap_or_else(|_| "/work/shared/meshes".into()),
    );
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let take = |name: &str, args: &mut Vec<String>| -> Option<f64> {
        let i = args.iter().position(|a| a == name)?;
        let v = args.get(i + 1)?.parse().ok();
        args.drain(i..i + 2);
        v
    };
    let mut opts = PouOptions::default();
    if let Some(d) = take("--local", &mut args) {
        opts.local_degree = d as usize;
    }
    if let Some(r) = take("--radius", &mut args) {
        opts.radius = r;
    }
    let edges = take("--edges", &mut args).map_or(opts.continuity_edges, |e| e as usize);
    if args.is_empty() {
        args = [
            "eight.off",
            "genus3.off",
            "3holes.off",
            "fertility.off",
            "botijo.off",
        ]
        .map(String::from)
        .to_vec();
    }
    println!(
        "| mesh | faces | local degree | atlas | charts | fit | tessellation | error | checks | total (wall / CPU s) | rms / max % | controls per chart | chart independence 0/1/2 | jumps 0/1/2/3 (samples) |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for name in &args {
        let surface = if let Some(res) = name.strip_prefix("genus2:") {
            ricci::mesh::generate::genus(2, res.parse().unwrap_or(12)).unwrap()
        } else {
            match read_surface(&dir.join(name)) {
                Ok(s) => s.0,
                Err(e) => {
                    eprintln!("{name}: {e}");
                    continue;
                }
            }
        };
        let total = Clock::start();
        let mut c = Clock::start();
        let mut atlas = match HyperbolicAtlas::build(&surface, &mut NoProgress) {
            Ok(a) => a,
            Err(e) => {
                eprintln!("{name}: {e}");
                continue;
            }
        };
        let t_atlas = c.lap();
        let radii = two_ring_radii(&atlas, opts.radius).unwrap();
        atlas.develop_charts(&radii, &mut NoProgress).unwrap();
        let t_charts = c.lap();
        let basis = PouBasis::new(&atlas, radii.clone());
        let local = local_fits(&basis, opts.local_degree).unwrap();
        let (control, _) = fit(&basis, &local, &opts.fit).unwrap();
        let t_fit = c.lap();
        let s = PouSurface {
            basis,
            control,
            local,
        };
        let faces: Vec<u32> = (0..atlas.mesh.n_faces() as u32).collect();
        let tess = tessellate(&s, &faces, opts.tessellation).unwrap();
        let t_tess = c.lap();
        let dist = NearestTriangle::new(&surface.positions, surface.mesh.faces());
        let (rms, max) = dist.error_percent(&tess.positions);
        let t_err = c.lap();
        let ci = chart_independence(&s, opts.independence_samples, 0x9e3779b97f4a7c15).unwrap();
        let ne = atlas.mesh.n_edges();
        let stride = if edges == 0 {
            1
        } else {
            ne.div_ceil(edges).max(1)
        };
        let cont = continuity(&s, stride).unwrap();
        let t_checks = c.lap();
        let mut tot = total;
        let t_total = tot.lap();
        let per_chart = atlas.charts.iter().map(|x| x.controls.len()).sum::<usize>() as f64
            / atlas.charts.len().max(1) as f64;
        let f = |t: (f64, f64)| format!("{:.2} / {:.2}", t.0, t.1);
        let e = |v: &[f64]| {
            v.iter()
                .map(|x| format!("{x:.0e}"))
                .collect::<Vec<_>>()
                .join(" / ")
        };
        println!(
            "| {name} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {rms:.3} / {max:.3} | {per_chart:.0} | {} | {} ({}) |",
            surface.mesh.n_faces(),
            opts.local_degree,
            f(t_atlas),
            f(t_charts),
            f(t_fit),
            f(t_tess),
            f(t_err),
            f(t_checks),
            f(t_total),
            e(&ci.relative),
            e(&cont.relative),
            cont.samples
        );
    }
}
