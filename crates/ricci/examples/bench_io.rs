//! Benchmark: read + validate + topology of mesh files (issue 2: aim ≥ 2M faces/s).
//!
//! `cargo run --release -p ricci --example bench_io [FILES...]`
//! Without arguments: horse.ply from `$RICCI_MESHES` and a generated ≈1M-face torus written
//! by the writers to a temporary directory in every format. Prints one line per file and stage.

use ricci::mesh::generate::torus;
use ricci::mesh::io::{self, Encoding, Format};
use ricci::mesh::{build_surface, topology};
use std::path::{Path, PathBuf};
use std::time::Instant;

fn bench(path: &Path) {
    let best = |f: &mut dyn FnMut() -> f64| (0..3).map(|_| f()).fold(f64::INFINITY, f64::min);
    let data = std::fs::read(path).expect("readable file");
    let format = Format::from_path(path).expect("known extension");
    let soup = io::parse(&data, format).expect("parses");
    let nf: usize = soup
        .polygons
        .iter()
        .map(|p| p.len().saturating_sub(2))
        .sum();
    let t_parse = best(&mut || {
        let t = Instant::now();
        let s = io::parse(&data, format).expect("parses");
        std::hint::black_box(s);
        t.elapsed().as_secs_f64()
    });
    let t_build = best(&mut || {
        let s = soup.clone();
        let t = Instant::now();
        let r = build_surface(s).expect("valid");
        std::hint::black_box(r);
        t.elapsed().as_secs_f64()
    });
    let (surface, _) = build_surface(soup.clone()).expect("valid");
    let t_topo = best(&mut || {
        let t = Instant::now();
        std::hint::black_box(topology(&surface.mesh));
        t.elapsed().as_secs_f64()
    });
    let t_total = best(&mut || {
        let t = Instant::now();
        let (s, _) = io::read_surface(path).expect("reads");
        std::hint::black_box(topology(&s.mesh));
        t.elapsed().as_secs_f64()
    });
    println!(
        "{:<28} {:>9} faces  parse {:>7.1} ms  build {:>7.1} ms  topology {:>6.1} ms  total (incl. file read) {:>7.1} ms = {:>5.2} M faces/s",
        path.file_name().unwrap_or_default().to_string_lossy(),
        nf,
        t_parse * 1e3,
        t_build * 1e3,
        t_topo * 1e3,
        t_total * 1e3,
        nf as f64 / t_total / 1e6
    );
}

fn main() {
    let args: Vec<PathBuf> = std::env::args().skip(1).map(PathBuf::from).collect();
    if !args.is_empty() {
        for a in &args {
            bench(a);
        }
        return;
    }
    if let Some(dir) = std::env::var_os("RICCI_MESHES") {
        let horse = Path::new(&dir).join("horse.ply");
        if horse.exists() {
            bench(&horse);
        }
    } else {
        eprintln!("RICCI_MESHES is not set: skipping horse.ply");
    }
    let dir = std::env::temp_dir().join(format!("ricci-bench-io-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    // The project's torus generator (R = 1, r = 0.4): 1000 columns give ≈ 1M faces.
    let t = torus(1.0, 0.4, 1000).expect("torus");
    println!("generated torus: {} faces", t.mesh.n_faces());
    for (name, format, enc) in [
        ("torus1M.ply", Format::Ply, Encoding::Binary),
        ("torus1M_ascii.ply", Format::Ply, Encoding::Ascii),
        ("torus1M.off", Format::Off, Encoding::Ascii),
        ("torus1M.obj", Format::Obj, Encoding::Ascii),
        ("torus1M.stl", Format::Stl, Encoding::Binary),
    ] {
        let p = dir.join(name);
        let t0 = Instant::now();
        io::write_surface_as(&p, &t, format, enc).expect("writes");
        let tw = t0.elapsed().as_secs_f64();
        bench(&p);
        println!("{:<28} written in {:.1} ms", name, tw * 1e3);
    }
    let _ = std::fs::remove_dir_all(&dir);
}
