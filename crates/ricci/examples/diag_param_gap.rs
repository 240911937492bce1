//! Where does `ricci param`'s gap to BFF at equal cone count come from (issue 16)? For one
//! closed mesh and a cone choice, prints the map's distortion three ways:
//!
//! * `written`: what `ricci param` reports (the common subdivision when the map lives there),
//!   count-weighted qc mean / p95 (every triangle counts once, slivers too) and area-weighted
//!   (`qc_mean_area`, `qc_p95_area`);
//! * `by input face`: per input face the pieces of the subdivision lumped together — log area
//!   ratio `log(Σ A_uv / A_face)` (exact, whatever the pieces) and the area-weighted mean qc
//!   of its pieces — then σ and count/area p95 over input faces (as a tool that writes UVs on
//!   the input's faces would be measured);
//! * the linearised `σ(2u)` of the cone set (the placement's energy).
//!
//! Cone choices: `N` (our greedy), `lsq:V,V,…` (positions given, least-squares curvatures),
//! `dir:V,V,…` (positions given, Dirichlet curvatures: BFF's rule), `V=K,…` (given).
//!
//! ```sh
//! cargo run --release -p ricci --example diag_param_gap -- ../shared/meshes/camel.off 8
//! cargo run --release -p ricci --example diag_param_gap -- camel.off dir:12,345,…
//! ```

use ricci::analysis::distortion::face_distortions;
use ricci::metric::IntrinsicMetric;
use ricci::param::cones::{cone_curvatures_at, greedy_cones, ConeBudget, CurvatureRule};
use ricci::param::{parametrize, ConeSpec, ParamOptions};
use ricci::progress::NoProgress;

fn p95(v: &mut [(f64, f64)]) -> (f64, f64) {
    v.sort_by(|a, b| a.0.total_cmp(&b.0));
    let n = v.len();
    let count = v[((0.95 * (n - 1) as f64).round() as usize).min(n - 1)].0;
    let total: f64 = v.iter().map(|x| x.1).sum();
    let mut acc = 0.0;
    let mut area = v[n - 1].0;
    for &(q, a) in v.iter() {
        acc += a;
        if acc >= 0.95 * total {
            area = q;
            break;
        }
    }
    (count, area)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 2 {
        return Err("usage: diag_param_gap MESH (N | lsq:V,… | dir:V,… | V=K,…)".into());
    }
    let (s, _) = ricci::mesh::io::read_surface(std::path::Path::new(&args[0]))?;
    let metric = IntrinsicMetric::euclidean(s.edge_lengths());
    let spec = &args[1];
    let ids = |t: &str| -> Vec<u32> { t.split(',').filter_map(|x| x.parse().ok()).collect() };
    let cones: Vec<(u32, f64)> = if let Some(t) = spec.strip_prefix("lsq:") {
        cone_curvatures_at(&s.mesh, &metric, &ids(t), CurvatureRule::LeastSquares)?.0
    } else if let Some(t) = spec.strip_prefix("dir:") {
        cone_curvatures_at(&s.mesh, &metric, &ids(t), CurvatureRule::Dirichlet)?.0
    } else if spec.contains('=') {
        spec.split(',')
            .filter_map(|x| x.split_once('='))
            .filter_map(|(v, k)| Some((v.parse().ok()?, k.parse().ok()?)))
            .collect()
    } else {
        greedy_cones(&s.mesh, &metric, ConeBudget::Count(spec.parse()?))?.cones
    };
    let verts: Vec<u32> = cones.iter().map(|c| c.0).collect();
    let (_, lin_lsq) = cone_curvatures_at(&s.mesh, &metric, &verts, CurvatureRule::LeastSquares)?;
    let (_, lin_dir) = cone_curvatures_at(&s.mesh, &metric, &verts, CurvatureRule::Dirichlet)?;
    let k: Vec<String> = cones
        .iter()
        .map(|c| format!("{}={:.3}", c.0, c.1))
        .collect();
    println!("cones {}", k.join(","));
    println!(
        "linearised σ(2u) at these positions: least-squares {lin_lsq:.4}, Dirichlet {lin_dir:.4}"
    );
    let opts = ParamOptions {
        cones: ConeSpec::Given(cones),
        ..ParamOptions::default()
    };
    let p = parametrize(&s, &opts, &mut NoProgress)?;
    let w = &p.stats;
    println!(
        "written ({}): {} triangles, flips {}, qc mean {:.4} / p95 {:.4} (count), mean {:.4} / p95 {:.4} (area), σ_logA {:.4}, {:.2} s",
        p.uv_on(), w.faces, w.flipped_faces, w.qc_mean, w.qc_p95, w.qc_mean_area, w.qc_p95_area, w.log_area_sigma, p.seconds
    );
    let nf = s.mesh.n_faces();
    // Per input face: (Σ A_uv, Σ A_3d, Σ qc·A_3d) over its pieces.
    let mut acc = vec![(0.0f64, 0.0f64, 0.0f64); nf];
    match &p.subdivision {
        Some(sub) => {
            let tris: Vec<[u32; 3]> = (0..sub.mesh.n_faces() as u32)
                .map(|t| sub.mesh.face(t))
                .collect();
            let d = face_distortions(&sub.positions, &tris, &sub.corner_uv);
            for (t, x) in d.iter().enumerate() {
                if x.area_3d > 0.0 && x.area_ratio.is_finite() {
                    let a = &mut acc[sub.input_face[t] as usize];
                    a.0 += x.area_ratio * x.area_3d;
                    a.1 += x.area_3d;
                    if !x.flipped() {
                        a.2 += x.qc() * x.area_3d;
                    }
                }
            }
            let i = &sub.input_stats;
            println!(
                "input faces' own UV triangles: flips {}, qc mean {:.4} / p95 {:.4} (count), p95 {:.4} (area), σ_logA {:.4}",
                i.flipped_faces, i.qc_mean, i.qc_p95, i.qc_p95_area, i.log_area_sigma
            );
        }
        None => {
            let tris: Vec<[u32; 3]> = (0..nf as u32).map(|f| s.mesh.face(f)).collect();
            for (f, x) in face_distortions(&s.positions, &tris, &p.corner_uv)
                .iter()
                .enumerate()
            {
                acc[f] = (x.area_ratio * x.area_3d, x.area_3d, x.qc() * x.area_3d);
            }
        }
    }
    let (mut w1, mut s1) = (0.0, 0.0);
    let mut qcs = Vec::with_capacity(nf);
    for a in &acc {
        if a.1 > 0.0 && a.0 > 0.0 {
            w1 += a.1;
            s1 += a.1 * (a.0 / a.1).ln();
            qcs.push((a.2 / a.1, a.1));
        }
    }
    let m = s1 / w1;
    let s2: f64 = acc
        .iter()
        .filter(|a| a.1 > 0.0 && a.0 > 0.0)
        .map(|a| a.1 * ((a.0 / a.1).ln() - m).powi(2))
        .sum();
    let mean_c = qcs.iter().map(|x| x.0).sum::<f64>() / qcs.len() as f64;
    let mean_a = qcs.iter().map(|x| x.0 * x.1).sum::<f64>() / w1;
    let (pc, pa) = p95(&mut qcs);
    println!(
        "by input face ({} faces): qc mean {mean_c:.4} / p95 {pc:.4} (count), mean {mean_a:.4} / p95 {pa:.4} (area), σ_logA {:.4}",
        qcs.len(),
        (s2 / w1).sqrt()
    );

    Ok(())
}
