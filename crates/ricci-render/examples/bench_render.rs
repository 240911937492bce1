//! Benchmark: render a 100k-face mesh at 1024² (supersampling 2 and 3) with several paints,
//! and encode the PNG. Prints the median of 5 runs per case.
//!
//! `cargo run --release -p ricci-render --example bench_render`
//! With `RICCI_MESHES` set, also renders `seahorse2_100K.off` (100 000 faces, genus 8).

use ricci_render::render::Uvs;
use ricci_render::*;
use std::time::Instant;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// CPU time (user + system, all threads) of this process in seconds, from /proc (Linux);
/// unlike wall time it does not grow when other processes share the cores.
fn cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return f64::NAN;
    };
    // Fields after the parenthesised command name; utime and stime are fields 14 and 15.
    let rest = stat.rsplit_once(')').map_or("", |r| r.1);
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| {
        f.get(i)
            .and_then(|s| s.parse::<f64>().ok())
            .unwrap_or(f64::NAN)
    };
    (ticks(11) + ticks(12)) / 100.0
}

/// Median wall time, mean CPU time per run, and the last result.
fn time<T>(runs: usize, mut f: impl FnMut() -> T) -> (f64, f64, T) {
    let mut ts = Vec::new();
    let mut last = None;
    let c0 = cpu_seconds();
    for _ in 0..runs {
        let t = Instant::now();
        last = Some(f());
        ts.push(t.elapsed().as_secs_f64());
    }
    let cpu = (cpu_seconds() - c0) / runs as f64;
    (median(ts), cpu, last.unwrap())
}

/// Minimal OFF reader for the optional real-mesh case (triangles only).
fn read_off(path: &std::path::Path) -> Option<shapes::Shape> {
    let text = std::fs::read_to_string(path).ok()?;
    let mut tok = text
        .lines()
        .map(|l| l.split('#').next().unwrap_or(""))
        .flat_map(|l| l.split_whitespace())
        .skip(1);
    let nv: usize = tok.next()?.parse().ok()?;
    let nf: usize = tok.next()?.parse().ok()?;
    tok.next()?;
    let mut p = Vec::with_capacity(nv);
    for _ in 0..nv {
        p.push([
            tok.next()?.parse().ok()?,
            tok.next()?.parse().ok()?,
            tok.next()?.parse().ok()?,
        ]);
    }
    let mut f = Vec::with_capacity(nf);
    for _ in 0..nf {
        let k: usize = tok.next()?.parse().ok()?;
        let idx: Vec<u32> = (0..k).filter_map(|_| tok.next()?.parse().ok()).collect();
        for j in 1..k.saturating_sub(1) {
            f.push([idx[0], idx[j], idx[j + 1]]);
        }
    }
    Some(shapes::Shape {
        positions: p,
        triangles: f,
    })
}

fn bench_mesh(name: &str, p: &[[f64; 3]], t: &[[u32; 3]], uv: Option<&[[f64; 2]]>) {
    println!("mesh {name}: {} vertices, {} faces", p.len(), t.len());
    let scalar: Vec<f64> = p.iter().map(|q| q[2]).collect();
    for ss in [2u32, 3] {
        let opts = RenderOptions {
            width: 1024,
            height: 1024,
            supersample: ss,
            ..Default::default()
        };
        let mut cases: Vec<(&str, Style)> = vec![
            ("solid", Style::default()),
            (
                "scalar+legend+isolines",
                Style {
                    paint: Paint::Scalar(Scalar {
                        isolines: 12,
                        label: "z".into(),
                        ..Scalar::per_vertex(&scalar, Colormap::Viridis)
                    }),
                    legend: true,
                    ..Default::default()
                },
            ),
            (
                "zebra+wireframe",
                Style {
                    paint: Paint::Zebra(Zebra::default()),
                    wireframe: Some(Wireframe::default()),
                    ..Default::default()
                },
            ),
        ];
        if let Some(uv) = uv {
            cases.push((
                "checker",
                Style {
                    paint: Paint::Checker(Checker::new(Uvs::PerVertex(uv), 16.0)),
                    ..Default::default()
                },
            ));
        }
        for (label, style) in &cases {
            let (secs, cpu, r) = time(5, || render(p, t, style, &opts).expect("render"));
            let (enc, _, png) = time(3, || r.png().expect("png"));
            println!(
                "  1024² ss={ss} {label:<24} render {:6.1} ms wall {:6.1} ms cpu   png {:5.1} ms ({} KiB)   coverage {:.0}%",
                secs * 1e3,
                cpu * 1e3,
                enc * 1e3,
                png.len() / 1024,
                r.coverage * 100.0
            );
        }
    }
}

fn main() {
    println!(
        "threads: {}   (cpu = user+system time of all threads; wall time grows with machine load)",
        rayon::current_num_threads()
    );
    let tor = shapes::torus(2.0, 0.8, 250, 200);
    let uv: Vec<[f64; 2]> = (0..tor.positions.len())
        .map(|k| [(k / 200) as f64 / 250.0 * 4.0, (k % 200) as f64 / 200.0])
        .collect();
    bench_mesh("torus 250x200", &tor.positions, &tor.triangles, Some(&uv));
    if let Some(dir) = std::env::var_os("RICCI_MESHES") {
        let path = std::path::Path::new(&dir).join("seahorse2_100K.off");
        match read_off(&path) {
            Some(s) => bench_mesh("seahorse2_100K.off", &s.positions, &s.triangles, None),
            None => eprintln!("note: could not read {}", path.display()),
        }
    }
}
