//! Why does the common subdivision of an E² free-boundary layout of a surface with several
//! boundary loops (bunny: 5 holes) have flipped triangles? Runs the pipeline of
//! `ricci layout MESH --geometry euclidean --target free-boundary` (flow, cut, layout, deck
//! group, common subdivision) and prints the faces of `T` that are flipped in the layout, the
//! deck maps their corners took, and the flipped pieces.
//!
//! `RICCI_MESHES=/work/shared/meshes cargo run --release -p ricci --example diag_free_boundary [MESH]`

use ricci::flow::{ricci_flow, FlowOptions, TargetSpec};
use ricci::layout::deck::deck_group;
use ricci::layout::pipeline::cut_disk;
use ricci::layout::place::layout;
use ricci::layout::subdivision_uv::common_subdivision_uvs;
use ricci::metric::IntrinsicMetric;
use ricci::metric::{Euclidean, Geometry, Scheme};
use ricci::progress::NoProgress;

fn main() {
    let dir = std::path::PathBuf::from(std::env::var("RICCI_MESHES").expect("RICCI_MESHES"));
    let name = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "bunny.off".into());
    let s = ricci::mesh::io::read_surface(&dir.join(&name)).unwrap().0;
    let l = s.edge_lengths();
    let o = FlowOptions {
        geometry: Geometry::Euclidean,
        scheme: Scheme::Conformal,
        target: TargetSpec::FreeBoundary,
        tolerance: 1e-10,
        ..FlowOptions::default()
    };
    let r = ricci_flow(&s.mesh, &l, &o, &mut NoProgress).unwrap();
    println!(
        "flow: converged {}, error {:.2e}",
        r.converged, r.max_curvature_error
    );
    let it = r.triangulation.as_ref().unwrap();
    let work = &it.simplicial.mesh;
    let d = cut_disk(
        work,
        &IntrinsicMetric::new(Geometry::Euclidean, r.lengths.to_vec()),
        None,
        None,
        &mut NoProgress,
    )
    .unwrap();
    println!("polygon: {}", d.polygon.word());
    let lay = layout::<Euclidean>(&d.mesh, &d.metric, None).unwrap();
    println!(
        "layout: {} faces, {} flipped, {} degenerate",
        d.mesh.n_faces(),
        lay.flipped_faces.len(),
        lay.degenerate_faces.len()
    );
    let group = deck_group::<Euclidean>(&lay, &d.polygon).unwrap();
    println!(
        "deck group: {} pairings, relation error {:?}",
        group.pairings.len(),
        group.relation_error
    );
    let tri = &it.triangulation;
    let faces: Vec<[u32; 3]> = (0..tri.n_faces() as u32).map(|f| tri.face(f)).collect();
    let used = vec![true; tri.n_vertices];
    let c = ricci::layout::input_uv::face_uvs::<Euclidean>(
        &used,
        &faces,
        &lay.positions,
        &d.vertex_origin,
        Some(&group),
    )
    .unwrap();
    println!(
        "T: {} faces, {} flipped in the layout, {} seam faces",
        faces.len(),
        c.flipped_faces.len(),
        c.seam_faces
    );
    for &f in c.flipped_faces.iter().take(20) {
        let f = f as usize;
        let src = [0, 1, 2].map(|i| c.source[3 * f + i]);
        let z = [0, 1, 2].map(|i| c.corner[3 * f + i]);
        let bnd = faces[f].map(|v| work.is_boundary_vertex(v));
        println!(
            "  T face {f} {:?} flipped: sources {src:?}, boundary {bnd:?}, corners {:?}",
            faces[f],
            z.map(|z| (z.re, z.im))
        );
    }
    let sub = common_subdivision_uvs::<Euclidean>(
        &s.mesh,
        &s.positions,
        &IntrinsicMetric::euclidean(l.to_vec()),
        tri,
        &r.u,
        &lay.positions,
        &d.vertex_origin,
        Some(&group),
    )
    .unwrap();
    println!(
        "subdivision: {} triangles, {} flipped, {} faces of T flipped",
        sub.triangles.len(),
        sub.flipped_faces,
        sub.t_flipped_faces
    );
}
