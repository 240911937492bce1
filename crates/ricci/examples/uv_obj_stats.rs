//! Distortion of a UV map read from an OBJ file (`v`, `vt`, `f v/vt …`, triangles; e.g. the
//! output of Boundary First Flattening's `bff-command-line` or of `ricci param --out`), with
//! the measure `ricci param` reports ([`ricci::analysis::distortion::uv_stats`]): flipped
//! faces, qc = σmax/σmin mean / p95 / max, and the area-weighted σ of log(A_uv/A_3d). Also
//! prints the same σ without area weights and σ(log area)/2 = σ(log scale factor u), so that
//! tables from elsewhere can be matched to the definition they used.
//!
//! Second line per file: where the flat metric of the UVs has its curvature. Per `v` not on
//! the mesh's boundary, `K = 2π − Σ` of its UV corner angles over all faces (seams included:
//! both sides' angles add up), then how many vertices have `|K| > 0.01` rad, the curvature
//! they carry, and the 8 largest `|K|`. A map with `N` cones has exactly `N` such vertices
//! (rigid transitions across the seams); a map whose seams bend has curvature spread along
//! them.
//!
//! `qcA_mean`, `qcA_p95`: the same qc weighted by 3D face area (slivers of a common
//! subdivision count by their area). With `UV_CONES=T` also the list `V=K,…` of the vertices
//! with `|K| > T` (e.g. another tool's cones, to be imposed with `ricci param --cones`).
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

/// `2π − Σθ` (UV corner angles) per position index; `NaN` on the boundary (edges with one
/// face) and at unused positions.
fn uv_angle_defects(n: usize, faces: &[[u32; 3]], corner: &[[f64; 2]]) -> Vec<f64> {
    let mut k = vec![f64::NAN; n];
    let mut edges: std::collections::HashMap<(u32, u32), u32> = std::collections::HashMap::new();
    for t in faces {
        for i in 0..3 {
            k[t[i] as usize] = 2.0 * std::f64::consts::PI;
            let (a, b) = (t[i], t[(i + 1) % 3]);
            *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    for (f, t) in faces.iter().enumerate() {
        for i in 0..3 {
            let p = corner[3 * f + i];
            let (q, r) = (corner[3 * f + (i + 1) % 3], corner[3 * f + (i + 2) % 3]);
            let (a, b) = ([q[0] - p[0], q[1] - p[1]], [r[0] - p[0], r[1] - p[1]]);
            let ang = (a[0] * b[1] - a[1] * b[0])
                .abs()
                .atan2(a[0] * b[0] + a[1] * b[1]);
            k[t[i] as usize] -= ang;
        }
    }
    for (&(a, b), &c) in &edges {
        if c == 1 {
            k[a as usize] = f64::NAN;
            k[b as usize] = f64::NAN;
        }
    }
    k
}

fn main() {
    let files: Vec<String> = std::env::args().skip(1).collect();
    if files.is_empty() {
        eprintln!("usage: uv_obj_stats UV.obj [more.obj …]");
        std::process::exit(1);
    }
    println!(
        "{:<32} {:>7} {:>6} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8}",
        "file",
        "faces",
        "flips",
        "qc_mean",
        "qc_p95",
        "qcA_mean",
        "qcA_p95",
        "qc_max",
        "σ_logA",
        "σ_unw",
        "σ_logA/2"
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
            "{:<32} {:>7} {:>6} {:>8.4} {:>8.4} {:>8.4} {:>8.4} {:>8.3} {:>8.3} {:>8.3} {:>8.3}",
            f.rsplit('/').next().unwrap_or(&f),
            s.faces,
            s.flipped_faces,
            s.qc_mean,
            s.qc_p95,
            s.qc_mean_area,
            s.qc_p95_area,
            s.qc_max,
            s.log_area_sigma,
            unw,
            s.log_area_sigma / 2.0
        );
        let k = uv_angle_defects(v.len(), &faces, &corner);
        let mut big: Vec<f64> = k.iter().copied().filter(|x| x.abs() > 0.01).collect();
        let total: f64 = big.iter().sum();
        big.sort_by(|a, b| b.abs().total_cmp(&a.abs()));
        let all: f64 = k.iter().filter(|x| x.is_finite()).sum();
        println!(
            "    UV curvature: {} vertices with |K| > 0.01 carry {:.3} of Σ K = {:.3} (interior); largest {:?}",
            big.len(),
            total,
            all,
            big.iter().take(8).map(|x| (x * 1000.0).round() / 1000.0).collect::<Vec<_>>()
        );
        if let Some(t) = std::env::var("UV_CONES")
            .ok()
            .and_then(|x| x.parse::<f64>().ok())
        {
            // The vertices carrying |K| > t, as `--cones V=K,…` (0-based position indices).
            let mut c: Vec<(usize, f64)> = k
                .iter()
                .enumerate()
                .filter(|x| x.1.abs() > t)
                .map(|(v, &x)| (v, x))
                .collect();
            c.sort_by(|a, b| b.1.abs().total_cmp(&a.1.abs()));
            let list: Vec<String> = c.iter().map(|(v, x)| format!("{v}={x:.4}")).collect();
            println!("    cones (|K| > {t}): {}", list.join(","));
        }
    }
}
