//! Why does the common subdivision of a hyperbolic layout have flipped triangles? Runs the
//! pipeline of `ricci layout MESH` (H²: conformal flow, polish, cut, double-double layout,
//! deck group, common subdivision) and prints, for the flipped triangles, how far out in the
//! Poincaré disk they are (hyperbolic distance from 0, `1 − |z|`) and how large they are
//! (hyperbolic size from the flow's metric vs. Euclidean size in the disk).
//!
//! `RICCI_MESHES=/work/shared/meshes cargo run --release -p ricci --example diag_seahorse_subdivision [MESH]`

use ricci::flow::{ricci_flow, FlowOptions, TargetSpec};
use ricci::layout::deck::deck_group;
use ricci::layout::isometry::Complex;
use ricci::layout::pipeline::{cut_disk_polished, polish_uniformization};
use ricci::layout::place::layout_dd;
use ricci::layout::subdivision_uv::common_subdivision_uvs;
use ricci::metric::{Geometry, Hyperbolic, Scheme};
use ricci::progress::NoProgress;

fn main() {
    let dir = std::path::PathBuf::from(std::env::var("RICCI_MESHES").expect("RICCI_MESHES"));
    let name = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "seahorse2_100K.off".into());
    let s = ricci::mesh::io::read_surface(&dir.join(&name)).unwrap().0;
    let l = s.edge_lengths();
    let o = FlowOptions {
        geometry: Geometry::Hyperbolic,
        scheme: Scheme::Conformal,
        target: if s.mesh.has_boundary() {
            TargetSpec::GeodesicBoundary
        } else {
            TargetSpec::Uniform
        },
        tolerance: 1e-12,
        ..FlowOptions::default()
    };
    let r = ricci_flow(&s.mesh, &l, &o, &mut NoProgress).unwrap();
    let it = r.triangulation.as_ref().unwrap();
    let p = polish_uniformization(&s.mesh, &l, &r).unwrap();
    let work = &it.simplicial.mesh;
    let d =
        cut_disk_polished(work, &p.lengths, &p.lengths_lo, None, None, &mut NoProgress).unwrap();
    let lay = layout_dd::<Hyperbolic>(&d.mesh, &d.lengths, Some(&d.lengths_lo), None).unwrap();
    println!(
        "layout: {} faces, {} flipped, {} degenerate, depth {}",
        d.mesh.n_faces(),
        lay.flipped_faces.len(),
        lay.degenerate_faces.len(),
        lay.depth
    );
    let dist = |z: Complex| 2.0 * z.norm().atanh();
    let far = lay.positions.iter().map(|&z| dist(z)).fold(0.0, f64::max);
    println!("layout: largest hyperbolic distance from 0: {far:.2}");
    for f in lay.degenerate_faces.iter().take(5) {
        let v = d.mesh.face(*f);
        let z = v.map(|i| lay.positions[i as usize]);
        println!(
            "  degenerate cut face {f}: distance {:.2}, 1-|z| {:.2e}, lengths {:?}",
            dist(z[0]),
            1.0 - z[0].norm(),
            [0, 1, 2].map(|k| d.lengths[d.mesh.he_edge(3 * f + k) as usize])
        );
    }
    let group = deck_group::<Hyperbolic>(&lay, &d.polygon).unwrap();
    let sub = common_subdivision_uvs::<Hyperbolic>(
        &s.mesh,
        &s.positions,
        &l,
        &it.triangulation,
        &r.u,
        &lay.positions,
        &d.vertex_origin,
        Some(&group),
    )
    .unwrap();
    println!(
        "subdivision: {} triangles, {} flipped, {} faces of T flipped, {} seam faces",
        sub.triangles.len(),
        sub.flipped_faces,
        sub.t_flipped_faces,
        sub.seam_faces
    );
    let mut hist = [0usize; 8];
    for t in 0..sub.triangles.len() {
        let z = [0, 1, 2].map(|i| {
            let w = sub.corner_uv[3 * t + i];
            Complex::new(w[0], w[1])
        });
        let q = z.map(|z| {
            let k = 2.0 / (1.0 + z.norm_sqr());
            [k * z.re, k * z.im]
        });
        let a =
            (q[1][0] - q[0][0]) * (q[2][1] - q[0][1]) - (q[1][1] - q[0][1]) * (q[2][0] - q[0][0]);
        if a.is_nan() || a <= 0.0 {
            let r = dist(z[0]);
            hist[((r / 5.0) as usize).min(7)] += 1;
            if hist.iter().sum::<usize>() <= 8 {
                let size = (z[1] - z[0]).norm().max((z[2] - z[0]).norm());
                println!(
                    "  flipped {t} (input face {}): distance {r:.2}, 1-|z| {:.2e}, euclidean size {size:.2e}, klein area {a:.2e}",
                    sub.input_face[t],
                    1.0 - z[0].norm()
                );
            }
        }
    }
    println!("flipped by distance (bins of 5): {hist:?}");
}
