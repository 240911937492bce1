//! Time the parts of `ricci layout` on a mesh (flow, polish, cut, layout, deck group, input UVs).
use ricci::layout::input_uv::input_face_uvs;
use ricci::layout::pipeline::{cut_disk_polished, polish_uniformization, uniformization_metric};
use ricci::layout::{deck_group, layout_dd};
use ricci::metric::{Geometry, Hyperbolic, Scheme};
use ricci::progress::NoProgress;
use std::time::Instant;

fn main() {
    let path = std::env::args().nth(1).expect("mesh");
    let scheme: Scheme = std::env::args()
        .nth(2)
        .unwrap_or("conformal".into())
        .parse()
        .unwrap();
    let (s, _) = ricci::mesh::io::read_surface(std::path::Path::new(&path)).unwrap();
    let t = Instant::now();
    let f = uniformization_metric(
        &s.mesh,
        &s.edge_lengths(),
        Geometry::Hyperbolic,
        scheme,
        1e-12,
        &mut NoProgress,
    )
    .unwrap();
    println!(
        "flow {:.2} s ({} it)",
        t.elapsed().as_secs_f64(),
        f.iterations
    );
    let work = f
        .triangulation
        .as_ref()
        .map(|t| t.simplicial.mesh.clone())
        .unwrap_or(s.mesh.clone());
    let t = Instant::now();
    let p = polish_uniformization(&s.mesh, &s.edge_lengths(), &f).unwrap();
    println!("polish {:.2} s", t.elapsed().as_secs_f64());
    let t = Instant::now();
    let pos = f.triangulation.is_none().then_some(&s.positions[..]);
    let d =
        cut_disk_polished(&work, &p.lengths, &p.lengths_lo, pos, None, &mut NoProgress).unwrap();
    println!(
        "cut {:.2} s (refined {} vertices)",
        t.elapsed().as_secs_f64(),
        d.cut.refined.mesh.n_vertices()
    );
    let t = Instant::now();
    let l = layout_dd::<Hyperbolic>(&d.mesh, &d.lengths, Some(&d.lengths_lo), None).unwrap();
    println!("layout {:.2} s", t.elapsed().as_secs_f64());
    let t = Instant::now();
    let g = deck_group::<Hyperbolic>(&l, &d.polygon).unwrap();
    println!("deck {:.2} s", t.elapsed().as_secs_f64());
    let t = Instant::now();
    let u =
        input_face_uvs::<Hyperbolic>(&s.mesh, &l.positions, &d.vertex_origin, Some(&g)).unwrap();
    println!(
        "input uv {:.2} s, flipped {}, seam {}",
        t.elapsed().as_secs_f64(),
        u.flipped_faces.len(),
        u.seam_faces
    );
}
