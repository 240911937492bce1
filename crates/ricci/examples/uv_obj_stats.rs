//! Distortion of a UV map read from an OBJ file (`v`, `vt`, `f v/vt …`, triangles; e.g. the
//! output of Boundary First Flattening's `bff-command-line` or of `ricci param --out`), with
//! the measure `ricci param` reports ([`ricci::analysis::distortion::uv_stats`]): flipped
//! faces, qc = σmax/σmin mean / p95 / max, and the area-weighted σ of log(A_uv/A_3d). Also
//! prints the same σ without area weights and σ(log area)/2 = σ(log scale factor u), so that
//! tables from elsewhere can be matched to the definition they used.
//!
//! ```sh
//! cargo run --release -p ricci --example uv_obj_stats -- uv.obj [more.obj …]
//! ```

use ricci::analysis::distortion::{face_distortions, stats};

/// Positions, triangles (by position index) and the UV of every corner.
type UvMesh = (Vec<[f64; 3]>, Vec<[u32; 3]>, Vec<[f64; 2]>);

fn parse(text: &str) -> Result<UvMesh, String> {
    let (mut v, mut vt, mut faces, mut corner) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for (ln, line) in text.lines().enumerate() {
        let mut it = line.split_whitespace();
        let num = |s: Option<&str>| -> Result<f64, String> {
            s.and_then(|x| x.parse().ok())
                .ok_or_else(|| format!("line {}: bad number", ln + 1))
        };
        match it.next() {
            Some("v") => v.push([num(it.next())?, num(it.next())?, num(it.next())?]),
            Some("vt") => vt.push([num(it.next())?, num(it.next())?]),
            Some("f") => {
                let c: Vec<&str> = it.collect();
                if c.len() != 3 {
                    return Err(format!("line {}: only triangles are read", ln + 1));
                }
                let mut t = [0u32; 3];
                for (i, s) in c.iter().enumerate() {
                    let mut p = s.split('/');
                    let a: usize = p.next().and_then(|x| x.parse().ok()).unwrap_or(0);
                    let b: usize = p.next().and_then(|x| x.parse().ok()).unwrap_or(0);
                    if a == 0 || b == 0 || a > v.len() || b > vt.len() {
                        return Err(format!("line {}: corner '{s}' needs v/vt", ln + 1));
                    }
                    t[i] = (a - 1) as u32;
                    corner.push(vt[b - 1]);
                }
                faces.push(t);
            }
            _ => {}
        }
    }
    Ok((v, faces, corner))
}

fn main() {
    let files: Vec<String> = std::env::args().skip(1).collect();
    if files.is_empty() {
        eprintln!("usage: uv_obj_stats UV.obj [more.obj …]");
        std::process::exit(1);
    }
    println!(
        "{:<32} {:>7} {:>6} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8}",
        "file", "faces", "flips", "qc_mean", "qc_p95", "qc_max", "σ_logA", "σ_unw", "σ_logA/2"
    );
    for f in files {
        let text = match std::fs::read_to_string(&f) {
            Ok(t) => t,
            Err(e) => {
                println!("{f}: {e}");
                continue;
            }
        };
        let (v, faces, corner) = match parse(&text) {
            Ok(x) => x,
            Err(e) => {
                println!("{f}: {e}");
                continue;
            }
        };
        let d = face_distortions(&v, &faces, &corner);
        let s = stats(&d);
        // Unweighted σ of log area ratio over the faces stats() measured.
        let logs: Vec<f64> = d
            .iter()
            .filter(|x| x.area_3d > 0.0 && !x.flipped())
            .map(|x| x.area_ratio.ln())
            .collect();
        let m = logs.iter().sum::<f64>() / logs.len().max(1) as f64;
        let unw =
            (logs.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / logs.len().max(1) as f64).sqrt();
        println!(
            "{:<32} {:>7} {:>6} {:>8.4} {:>8.4} {:>8.3} {:>8.3} {:>8.3} {:>8.3}",
            f.rsplit('/').next().unwrap_or(&f),
            s.faces,
            s.flipped_faces,
            s.qc_mean,
            s.qc_p95,
            s.qc_max,
            s.log_area_sigma,
            unw,
            s.log_area_sigma / 2.0
        );
    }
}
