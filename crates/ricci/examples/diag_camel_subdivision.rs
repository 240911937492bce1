//! Why does the common subdivision of camel.off's E² layout (genus 1, uniform target) have
//! flipped pieces inside faces of `T` that are not flipped? Runs the pipeline of
//! `ricci layout MESH` (flow with the layout options, cut, layout, deck group, common
//! subdivision) and prints, for every flipped piece: its face of `T`, the corners' projective
//! weights, the sign of `det β` (the piece's orientation in exact arithmetic on the face of
//! `T`, up to the face's own orientation), its UVs and signed area, the crossings involved.
//!
//! `RICCI_MESHES=/work/shared/meshes cargo run --release -p ricci --example diag_camel_subdivision [MESH]`

use ricci::flow::uniformize::layout_tolerance;
use ricci::flow::{default_scheme, ricci_flow, UniformizationOptions};
use ricci::layout::deck::deck_group_ext;
use ricci::layout::pipeline::cut_disk;
use ricci::layout::place::layout_dd;
use ricci::layout::subdivision_uv::{common_subdivision_uvs_ext, LaidOut};
use ricci::metric::common_subdivision::CommonSubdivision;
use ricci::metric::IntrinsicMetric;
use ricci::metric::{Euclidean, Geometry};
use ricci::progress::NoProgress;

fn det3(w: [[f64; 3]; 3]) -> f64 {
    let n = w.map(|r| {
        let s = r[0] + r[1] + r[2];
        r.map(|x| x / s)
    });
    n[0][0] * (n[1][1] * n[2][2] - n[1][2] * n[2][1])
        - n[0][1] * (n[1][0] * n[2][2] - n[1][2] * n[2][0])
        + n[0][2] * (n[1][0] * n[2][1] - n[1][1] * n[2][0])
}

fn main() {
    let dir = std::path::PathBuf::from(std::env::var("RICCI_MESHES").expect("RICCI_MESHES"));
    let name = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "camel.off".into());
    let s = ricci::mesh::io::read_surface(&dir.join(&name)).unwrap().0;
    let l = s.edge_lengths();
    let g = Geometry::Euclidean;
    let scheme = default_scheme(g);
    let uo = UniformizationOptions::single(Some(g), scheme, layout_tolerance(g));
    let o = uo.flow_options(&s.mesh, scheme, None).unwrap();
    let r = ricci_flow(&s.mesh, &l, &o, &mut NoProgress).unwrap();
    println!(
        "flow: converged {}, error {:.2e}",
        r.converged, r.max_curvature_error
    );
    let it = r.triangulation.as_ref().unwrap();
    let work = &it.simplicial.mesh;
    let d = cut_disk(
        work,
        &IntrinsicMetric::new(g, r.lengths.to_vec()),
        None,
        None,
        &mut NoProgress,
    )
    .unwrap();
    let lay = layout_dd::<Euclidean>(&d.mesh, &d.metric, None).unwrap();
    println!(
        "layout: {} faces, {} flipped, {} degenerate",
        d.mesh.n_faces(),
        lay.flipped_faces.len(),
        lay.degenerate_faces.len()
    );
    let (group, frames) = deck_group_ext::<Euclidean>(&lay, &d.polygon).unwrap();
    let laid = LaidOut {
        positions: &lay.positions,
        positions_lo: &lay.positions_lo,
        origin: &d.vertex_origin,
    };
    let tri = &it.triangulation;
    let sub = common_subdivision_uvs_ext::<Euclidean>(
        &s.mesh,
        &s.positions,
        &IntrinsicMetric::euclidean(l.to_vec()),
        tri,
        &r.u,
        &laid,
        Some(&group),
        Some(&frames),
    )
    .unwrap();
    println!(
        "subdivision: {} triangles, {} flipped, {} faces of T flipped, {} seam faces, {} UVs \
         nudged",
        sub.triangles.len(),
        sub.flipped_faces,
        sub.t_flipped_faces,
        sub.seam_faces,
        sub.nudged_uvs
    );
    let cs = CommonSubdivision::from_triangulation(&s.mesh, g, &l, tri, &r.u).unwrap();
    println!("report: {:?}", cs.report);
    assert_eq!(cs.triangles, sub.triangles);
    let uv = &sub.corner_uv;
    for t in 0..cs.triangles.len() {
        let q = [0, 1, 2].map(|i| uv[3 * t + i]);
        let a =
            (q[1][0] - q[0][0]) * (q[2][1] - q[0][1]) - (q[1][1] - q[0][1]) * (q[2][0] - q[0][0]);
        if a.is_nan() || a <= 0.0 {
            let f = cs.t_face[t];
            let w = [0, 1, 2].map(|i| cs.t_weights[3 * t + i]);
            println!(
                "piece {t}: area {a:.3e}, T face {f} {:?}, input face {}, vertices {:?}",
                cs.triangulation.face(f),
                cs.input_face[t],
                cs.triangles[t]
            );
            println!("  weights {w:?}");
            println!("  det(normalised weights) {:.3e}", det3(w));
            println!("  uv {q:?}");
            println!(
                "  input bary {:?}",
                [0, 1, 2].map(|i| cs.input_barycentric[3 * t + i])
            );
            for &v in &cs.triangles[t] {
                if (v as usize) >= cs.n_input_vertices {
                    let c = &cs.crossings[v as usize - cs.n_input_vertices];
                    println!("  crossing {}: {c:?}", v as usize - cs.n_input_vertices);
                }
            }
            let pieces: Vec<usize> = (0..cs.triangles.len())
                .filter(|&k| cs.t_face[k] == f)
                .collect();
            println!("  T face {f} has {} pieces", pieces.len());
        }
    }
}
