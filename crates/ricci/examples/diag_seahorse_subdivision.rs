//! Why does the common subdivision of a hyperbolic layout have flipped triangles? Runs the
//! pipeline of `ricci layout MESH` (H²: conformal flow, polish, cut, double-double layout,
//! deck group, common subdivision) and prints, for the flipped triangles, how far out in the
//! Poincaré disk they are (hyperbolic distance from 0, `1 − |z|`) and how large they are
//! (hyperbolic size from the flow's metric vs. Euclidean size in the disk).
//!
//! `RICCI_MESHES=/work/shared/meshes cargo run --release -p ricci --example diag_seahorse_subdivision [MESH]`

use ricci::flow::{ricci_flow, FlowOptions, TargetSpec};
use ricci::layout::deck::deck_group_ext;
use ricci::layout::isometry::Complex;
use ricci::layout::pipeline::{cut_disk_polished, polish_uniformization};
use ricci::layout::place::layout_dd;
use ricci::layout::subdivision_uv::{common_subdivision_uvs, common_subdivision_uvs_ext, LaidOut};
use ricci::metric::common_subdivision::disk_orientation;
use ricci::metric::IntrinsicMetric;
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
    let p = polish_uniformization(&s.mesh, &IntrinsicMetric::euclidean(l.to_vec()), &r).unwrap();
    let work = &it.simplicial.mesh;
    let d = cut_disk_polished(work, &p.metric, None, None, &mut NoProgress).unwrap();
    let lay = layout_dd::<Hyperbolic>(&d.mesh, &d.metric, None).unwrap();
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
            "  degenerate cut face {f}: distance {:.2}, 1-|z| {:.2e}, lengths {:?}, area {:.3e}",
            dist(z[0]),
            1.0 - z[0].norm(),
            [0, 1, 2].map(|k| d.metric[d.mesh.he_edge(3 * f + k) as usize]),
            {
                let q = [0, 1, 2].map(|k| d.metric[d.mesh.he_edge(3 * f + k) as usize]);
                Geometry::Hyperbolic.area(q[0], q[1], q[2])
            }
        );
    }
    let (group, frames) = deck_group_ext::<Hyperbolic>(&lay, &d.polygon).unwrap();
    let f64_only = common_subdivision_uvs::<Hyperbolic>(
        &s.mesh,
        &s.positions,
        &IntrinsicMetric::euclidean(l.to_vec()),
        &it.triangulation,
        &r.u,
        &lay.positions,
        &d.vertex_origin,
        Some(&group),
    )
    .unwrap();
    println!(
        "subdivision from the f64 layout: {} triangles, {} flipped, {} faces of T flipped, {} seam faces",
        f64_only.triangles.len(),
        f64_only.flipped_faces,
        f64_only.t_flipped_faces,
        f64_only.seam_faces
    );
    {
        // Which faces of T are flipped in the f64 layout, and are they seam faces?
        let tri = &it.triangulation;
        let faces: Vec<[u32; 3]> = (0..tri.n_faces() as u32).map(|f| tri.face(f)).collect();
        let used = vec![true; tri.n_vertices];
        let c = ricci::layout::input_uv::face_uvs::<Hyperbolic>(
            &used,
            &faces,
            &lay.positions,
            &d.vertex_origin,
            Some(&group),
        )
        .unwrap();
        for &f in c.flipped_faces.iter().take(30) {
            let f = f as usize;
            let src = [0, 1, 2].map(|i| c.source[3 * f + i]);
            let z = c.corner[3 * f];
            let lens = [0, 1, 2].map(|i| {
                let e = tri.edge[3 * f + i] as usize;
                ricci::metric::intrinsic::length_of_lambda(Geometry::Hyperbolic, tri.lambda[e])
            });
            println!(
                "  T face {f} flipped (f64): maps {:?}, distance {:.2}, lengths {:?}",
                src.map(|s| s.1),
                dist(z),
                lens
            );
        }
    }
    let laid = LaidOut {
        positions: &lay.positions,
        positions_lo: &lay.positions_lo,
        origin: &d.vertex_origin,
    };
    let sub = common_subdivision_uvs_ext::<Hyperbolic>(
        &s.mesh,
        &s.positions,
        &IntrinsicMetric::euclidean(l.to_vec()),
        &it.triangulation,
        &r.u,
        &laid,
        Some(&group),
        Some(&frames),
    )
    .unwrap();
    println!(
        "subdivision from the double-double layout: {} triangles, {} flipped, {} faces of T flipped, {} seam faces, {} recentred",
        sub.triangles.len(),
        sub.flipped_faces,
        sub.t_flipped_faces,
        sub.seam_faces,
        sub.recentred_faces
    );
    let mut hist = [0usize; 8];
    for t in 0..sub.triangles.len() {
        let z = [0, 1, 2].map(|i| {
            let w = sub.corner_uv[3 * t + i];
            Complex::new(w[0], w[1])
        });
        let a = disk_orientation(
            sub.corner_uv[3 * t],
            sub.corner_uv[3 * t + 1],
            sub.corner_uv[3 * t + 2],
        );
        if a.is_nan() || a <= 0.0 {
            let r = dist(z[0]);
            hist[((r / 5.0) as usize).min(7)] += 1;
            if hist.iter().sum::<usize>() <= 8 {
                let size = (z[1] - z[0]).norm().max((z[2] - z[0]).norm());
                println!(
                    "  flipped {t} (input face {}): distance {r:.2}, 1-|z| {:.2e}, euclidean size {size:.2e}, orientation {a:.2e}",
                    sub.input_face[t],
                    1.0 - z[0].norm()
                );
            }
        }
    }
    println!("flipped by distance (bins of 5): {hist:?}");
}
