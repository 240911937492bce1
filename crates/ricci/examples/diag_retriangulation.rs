//! Genus-1 moduli under re-triangulation: prints the normalized second and third lattice
//! lengths of a surface, its midpoint subdivision, random off-centre face splits, and
//! irregular tori against the closed form √(R² − r²)/r.
//!
//! `cargo run --release -p ricci --example diag_retriangulation -- [yamabe|thurston|…]`

use ricci::analysis::spectrum::lattice_spectrum;
use ricci::layout::deck_group;
use ricci::layout::pipeline::{cut_disk, uniformization_metric};
use ricci::layout::place::layout;
use ricci::mesh::generate::{irregular_torus, midpoint_subdivision, random_face_splits};
use ricci::mesh::Surface;
use ricci::metric::IntrinsicMetric;
use ricci::metric::{Euclidean, Geometry, Scheme};
use ricci::progress::NoProgress;
use std::time::Instant;

fn spectrum(s: &Surface, scheme: Scheme) -> Result<Vec<f64>, String> {
    let flow = uniformization_metric(
        &s.mesh,
        &IntrinsicMetric::euclidean(s.edge_lengths()),
        Geometry::Euclidean,
        scheme,
        1e-11,
        &mut NoProgress,
    )
    .map_err(|e| e.to_string())?;
    if !flow.converged {
        return Err(format!(
            "not converged: {:.2e}, {} degenerate",
            flow.max_curvature_error, flow.degenerate_faces
        ));
    }
    let disk = cut_disk(
        &s.mesh,
        &IntrinsicMetric::new(Geometry::Euclidean, flow.lengths.to_vec()),
        None,
        None,
        &mut NoProgress,
    )
    .map_err(|e| e.to_string())?;
    let l = layout::<Euclidean>(&disk.mesh, &disk.metric, None).map_err(|e| e.to_string())?;
    let g = deck_group::<Euclidean>(&l, &disk.polygon).map_err(|e| e.to_string())?;
    let gens = g.named_generators();
    let sp = lattice_spectrum(gens[0].1.t, gens[1].1.t, 4).map_err(|e| e.to_string())?;
    Ok(sp.iter().map(|x| x / sp[0]).collect())
}

fn main() {
    let scheme: Scheme = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "yamabe".into())
        .parse()
        .expect("scheme");
    let dir = std::env::var("RICCI_MESHES").unwrap_or_else(|_| "../shared/meshes".into());
    let mut cases: Vec<(String, Surface)> = Vec::new();
    for name in [
        "kitten.nf20k.off",
        "torus.off",
        "bob_tri.obj",
        "rocker-arm.off",
    ] {
        let p = std::path::Path::new(&dir).join(name);
        if let Ok((s, _)) = ricci::mesh::io::read_surface(&p) {
            cases.push((format!("{name} /4"), midpoint_subdivision(&s).unwrap()));
            cases.push((
                format!("{name} split"),
                random_face_splits(&s, 0.5, 11).unwrap(),
            ));
            cases.push((name.to_string(), s));
        }
    }
    for (big, small, n) in [(1.0f64, 0.25f64, 4000), (1.0, 0.5, 4000), (2.0, 1.0, 8000)] {
        let want: f64 = (big * big - small * small).sqrt() / small;
        println!("irregular torus R={big} r={small}: exact modulus {want:.5}");
        cases.push((
            format!("irregular R={big} r={small} n={n}"),
            irregular_torus(big, small, n, 5).unwrap(),
        ));
    }
    for (name, s) in &cases {
        let t = Instant::now();
        match spectrum(s, scheme) {
            Ok(sp) => println!(
                "{name:40} F={:7}  lengths {:.5} {:.5} {:.5}  {:.2} s",
                s.mesh.n_faces(),
                sp[1],
                sp[2],
                sp[3],
                t.elapsed().as_secs_f64()
            ),
            Err(e) => println!("{name:40} F={:7}  {e}", s.mesh.n_faces()),
        }
    }
}
