//! The compact fundamental domain of `surface_spectrum` is centred on the vertex it reports and
//! its radius is not padded. The search keeps tiles up to distance `L + 2·radius`, so their
//! number grows like `e^{2·radius}`: seahorse2_100K's spectrum took 72 166 tiles with the
//! radius of `dffde35` (the farthest point plus the longest edge, 7.32) and 1 691 with the
//! farthest point alone (5.43, since `b7d1078`). Checked here from the developed points
//! themselves, not from the code's numbers:
//! - the centre's copy is the origin of the disk;
//! - every triangle of the development has the metric's side lengths (so the points are the
//!   domain, laid out in H²);
//! - the radius is the largest hyperbolic distance `2 atanh |p|` from the origin to a point
//!   (to 1e-9 relative);
//! - it lies between the two bounds every domain about that centre obeys: the ball holds the
//!   domain, whose area is `4π(g − 1)` (Gauss–Bonnet), so `2π(cosh R − 1) ≥ 4π(g − 1)`; and
//!   no point is farther than its shortest path along the triangles' sides.

mod ricci_meshes;

use ricci::analysis::spectrum::surface_spectrum;
use ricci::layout::pipeline::{polish_uniformization, uniformization_metric};
use ricci::metric::IntrinsicMetric;
use ricci::metric::{Geometry, Scheme};
use ricci::progress::NoProgress;

/// Hyperbolic distance of two points of the Poincaré disk.
fn disk_distance(p: [f64; 2], q: [f64; 2]) -> f64 {
    // |p − q| / |1 − p̄ q|
    let (dx, dy) = (p[0] - q[0], p[1] - q[1]);
    let (re, im) = (
        1.0 - (p[0] * q[0] + p[1] * q[1]),
        -(p[0] * q[1] - p[1] * q[0]),
    );
    2.0 * (dx.hypot(dy) / re.hypot(im)).atanh()
}

fn check(name: &str) -> bool {
    let Some(dir) = ricci_meshes::ricci_meshes().filter(|d| d.is_dir()) else {
        return false;
    };
    let (s, _) = ricci::mesh::io::read_surface(&dir.join(name)).unwrap();
    let input = IntrinsicMetric::euclidean(s.edge_lengths());
    let f = uniformization_metric(
        &s.mesh,
        &input,
        Geometry::Hyperbolic,
        Scheme::Conformal,
        1e-12,
        &mut NoProgress,
    )
    .unwrap();
    let work = f.triangulation.as_ref().unwrap().simplicial.mesh.clone();
    let p = polish_uniformization(&s.mesh, &input, &f).unwrap();
    let (_, dom) = surface_spectrum(&work, &p.metric, None, 12, 2_000_000).unwrap();
    let lengths = p.metric.lengths();
    let (pts, tri) = (&dom.points, &dom.triangles);
    assert_eq!(tri.len(), work.n_faces(), "{name}: one triangle per face");
    assert_eq!(pts.len(), dom.point_vertex.len());

    // The centre's copy at the origin.
    let at_origin: Vec<usize> = (0..pts.len())
        .filter(|&i| pts[i][0].hypot(pts[i][1]) < 1e-12)
        .collect();
    assert_eq!(
        at_origin.len(),
        1,
        "{name}: points at the origin {at_origin:?}"
    );
    let o = at_origin[0];
    assert_eq!(
        dom.point_vertex[o], dom.centre,
        "{name}: the origin's vertex"
    );

    // A development of the metric: triangle t is face t, side i from corner i to i + 1 is
    // half-edge 3t + i.
    let mut worst_side: f64 = 0.0;
    for (t, c) in tri.iter().enumerate() {
        let face = work.face(t as u32);
        for i in 0..3 {
            assert_eq!(dom.point_vertex[c[i] as usize], face[i], "{name}: face {t}");
            let e = work.he_edge(3 * t as u32 + i as u32) as usize;
            let d = disk_distance(pts[c[i] as usize], pts[c[(i + 1) % 3] as usize]);
            worst_side = worst_side.max((d - lengths[e]).abs() / lengths[e]);
        }
    }
    assert!(
        worst_side < 1e-9,
        "{name}: a developed side differs from its length by {worst_side:.2e} (relative)"
    );

    // The radius about the origin, from the points.
    let far = pts
        .iter()
        .map(|q| 2.0 * q[0].hypot(q[1]).atanh())
        .fold(0.0, f64::max);
    assert!(
        (dom.radius - far).abs() <= 1e-9 * far,
        "{name}: reported radius {} but the farthest point is at {far}",
        dom.radius
    );

    // Gauss–Bonnet: the ball of radius R holds the domain of area 4π(g − 1).
    let chi = work.n_vertices() as f64 - work.n_edges() as f64 + work.n_faces() as f64;
    let genus = (2.0 - chi) / 2.0;
    let r_min = (2.0 * genus - 1.0).acosh();
    assert!(
        dom.radius >= r_min,
        "{name}: radius {} below the area bound {r_min}",
        dom.radius
    );
    // Shortest paths along the domain's triangle sides from the origin (Dijkstra).
    let mut adj: Vec<Vec<(usize, f64)>> = vec![Vec::new(); pts.len()];
    for (t, c) in tri.iter().enumerate() {
        for i in 0..3 {
            let e = work.he_edge(3 * t as u32 + i as u32) as usize;
            let (a, b) = (c[i] as usize, c[(i + 1) % 3] as usize);
            adj[a].push((b, lengths[e]));
            adj[b].push((a, lengths[e]));
        }
    }
    let mut dist = vec![f64::INFINITY; pts.len()];
    let mut heap = std::collections::BinaryHeap::new();
    dist[o] = 0.0;
    heap.push((std::cmp::Reverse(0u64), o));
    while let Some((std::cmp::Reverse(k), v)) = heap.pop() {
        if f64::from_bits(k) > dist[v] {
            continue;
        }
        for &(w, l) in &adj[v] {
            let d = dist[v] + l;
            if d < dist[w] {
                dist[w] = d;
                heap.push((std::cmp::Reverse(d.to_bits()), w));
            }
        }
    }
    let r_max = dist.iter().copied().fold(0.0, f64::max);
    assert!(
        dom.radius <= r_max * (1.0 + 1e-12),
        "{name}: radius {} beyond the longest shortest path {r_max}",
        dom.radius
    );
    eprintln!(
        "{name}: genus {genus}, radius {:.4} (area bound {r_min:.4}, path bound {r_max:.4}), \
         sides to {worst_side:.1e}",
        dom.radius
    );
    true
}

#[test]
fn the_domain_is_centred_and_its_radius_is_its_farthest_point() {
    for name in ["eight.off", "fertility.off"] {
        if !check(name) {
            eprintln!("RICCI_MESHES not set; skipped");
            return;
        }
    }
}
