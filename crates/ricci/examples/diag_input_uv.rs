//! Which input faces get a flipped UV triangle from `layout::input_uv` (diagnostics).
use ricci::layout::input_uv::input_face_uvs;
use ricci::layout::pipeline::{cut_disk, uniformization_metric};
use ricci::layout::{deck_group, layout_dd};
use ricci::metric::IntrinsicMetric;
use ricci::metric::{Geometry, Hyperbolic, Scheme};
use ricci::progress::NoProgress;

fn main() {
    let path = std::env::args().nth(1).expect("mesh");
    let (s, _) = ricci::mesh::io::read_surface(std::path::Path::new(&path)).unwrap();
    let f = uniformization_metric(
        &s.mesh,
        &IntrinsicMetric::euclidean(s.edge_lengths()),
        Geometry::Hyperbolic,
        Scheme::Conformal,
        1e-12,
        &mut NoProgress,
    )
    .unwrap();
    let work = &f.triangulation.as_ref().unwrap().simplicial.mesh;
    let d = cut_disk(
        work,
        &IntrinsicMetric::new(Geometry::Hyperbolic, f.lengths.to_vec()),
        None,
        None,
        &mut NoProgress,
    )
    .unwrap();
    let l = layout_dd::<Hyperbolic>(&d.mesh, &d.metric, None).unwrap();
    let g = deck_group::<Hyperbolic>(&l, &d.polygon).unwrap();
    let u =
        input_face_uvs::<Hyperbolic>(&s.mesh, &l.positions, &d.vertex_origin, Some(&g)).unwrap();
    let base = d.cut.base;
    println!(
        "base {base}, refined vertices {}, cut vertices {}",
        d.cut.refined.mesh.n_vertices(),
        d.mesh.n_vertices()
    );
    for &f in &u.flipped_faces {
        let t = s.mesh.face(f);
        let copies: Vec<usize> = t
            .iter()
            .map(|&v| d.vertex_origin.iter().filter(|&&o| o == v).count())
            .collect();
        let c = &u.corner[3 * f as usize..3 * f as usize + 3];
        let dist = |a: ricci::layout::isometry::Complex, b: ricci::layout::isometry::Complex| {
            <Hyperbolic as ricci::layout::Space>::distance(a, b)
        };
        println!(
            "face {f} {t:?} copies {copies:?} d01 {:.3} d12 {:.3} d20 {:.3} |z| {:.3} {:.3} {:.3}",
            dist(c[0], c[1]),
            dist(c[1], c[2]),
            dist(c[2], c[0]),
            c[0].norm(),
            c[1].norm(),
            c[2].norm()
        );
    }
}
