//! Time the hyperbolic length spectrum on a mesh: flow + double-double polish, then
//! `surface_spectrum` (compact fundamental domain and tile search).
//!
//! `cargo run --release -p ricci --example bench_spectrum -- MESH [COUNT] [MAX_TILES]`
use ricci::analysis::spectrum::surface_spectrum;
use ricci::layout::pipeline::{polish_uniformization, uniformization_metric};
use ricci::metric::IntrinsicMetric;
use ricci::metric::{Geometry, Scheme};
use ricci::progress::NoProgress;
use std::time::Instant;

fn main() {
    let path = std::env::args().nth(1).expect("mesh");
    let count: usize = std::env::args()
        .nth(2)
        .map(|x| x.parse().unwrap())
        .unwrap_or(12);
    let maxt: usize = std::env::args()
        .nth(3)
        .map(|x| x.parse().unwrap())
        .unwrap_or(2_000_000);
    let (s, _) = ricci::mesh::io::read_surface(std::path::Path::new(&path)).unwrap();
    let t = Instant::now();
    let f = uniformization_metric(
        &s.mesh,
        &IntrinsicMetric::euclidean(s.edge_lengths()),
        Geometry::Hyperbolic,
        Scheme::Conformal,
        1e-12,
        &mut NoProgress,
    )
    .unwrap();
    let work = f.triangulation.as_ref().unwrap().simplicial.mesh.clone();
    let p =
        polish_uniformization(&s.mesh, &IntrinsicMetric::euclidean(s.edge_lengths()), &f).unwrap();
    println!("flow+polish {:.2} s", t.elapsed().as_secs_f64());
    let t = Instant::now();
    let sp = surface_spectrum(&work, &p.metric, None, count, maxt);
    println!("spectrum {:.2} s", t.elapsed().as_secs_f64());
    match sp {
        Ok((sp, d)) => println!(
            "{:?}\n tiles {} complete {} unmatched {} domain {d:?}",
            sp.lengths(),
            sp.tiles,
            sp.complete_up_to,
            sp.unmatched_links
        ),
        Err(e) => println!("error {e}"),
    }
}
