//! Issue 15 item 3 diagnostic: the E² free-boundary conformal flow on a bumpy disk whose faces
//! (boundary faces too) were split off-centre — once on the surface itself (boundary edges
//! never flip) and once on its double (`mesh::double_cover`, boundary vertices held at
//! `u = 0`, `K̄ = 0` elsewhere), where the boundary edges are ordinary edges.
//!
//! `cargo run --release -p ricci --example diag_double_flow [splits] [seed]`, or
//! `… diag_double_flow MESH [euclidean|hyperbolic]`: a mesh file with boundary, free boundary in
//! E², geodesic boundary in H², on the surface and on its double.

use ricci::flow::double::flow_on_double;
use ricci::flow::target::resolve;
use ricci::flow::{ricci_flow, FlowOptions, TargetSpec};
use ricci::mesh::generate;
use ricci::metric::intrinsic::{length_of_lambda, IntrinsicTriangulation};
use ricci::metric::IntrinsicMetric;
use ricci::metric::{Geometry, Scheme};
use ricci::progress::NoProgress;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if let Some(path) = args.get(1).filter(|a| a.contains('.')) {
        let geometry = match args.get(2).map(String::as_str) {
            Some("hyperbolic") => Geometry::Hyperbolic,
            _ => Geometry::Euclidean,
        };
        return mesh_file(path, geometry);
    }
    let count: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(120);
    let seed: u64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(7);
    let s = generate::bumpy_split_disk(count, seed, 0.75, true).unwrap();
    let m = &s.mesh;
    println!(
        "surface: {} vertices, {} faces, {} boundary edges",
        m.n_vertices(),
        m.n_faces(),
        (0..m.n_edges() as u32)
            .filter(|&e| m.is_boundary_edge(e))
            .count()
    );
    // 1. The flow on the surface itself.
    let o = FlowOptions {
        geometry: Geometry::Euclidean,
        scheme: Scheme::Conformal,
        target: TargetSpec::FreeBoundary,
        tolerance: 1e-10,
        ..FlowOptions::default()
    };
    let t = std::time::Instant::now();
    match ricci_flow(m, &s.edge_lengths(), &o, &mut NoProgress) {
        Ok(r) => {
            println!(
                "surface flow: converged {} in {} iterations, max |K − K̄| {:.3e}, {} degenerate \
                 faces, {:.2} s",
                r.converged,
                r.iterations,
                r.max_curvature_error,
                r.degenerate_faces,
                t.elapsed().as_secs_f64()
            );
            for h in r.history.iter().rev().take(4).rev() {
                println!(
                    "  it {}: err {:.3e} step {:.3e}",
                    h.iteration, h.max_curvature_error, h.step
                );
            }
            for n in &r.notes {
                println!("  note: {n}");
            }
            // Where it stopped: the slack of the triangle inequality of the faces on a
            // boundary edge ab (opposite vertex p), (l_ap + l_bp − l_ab) / l_ab.
            if let Some(it) = &r.triangulation {
                let t = &it.triangulation;
                let mut slack: Vec<(f64, u32)> = Vec::new();
                for e in 0..t.n_edges() as u32 {
                    if !t.is_boundary_edge(e) {
                        continue;
                    }
                    let h = t.edge_he[e as usize];
                    let len = |x: u32| {
                        length_of_lambda(Geometry::Euclidean, t.lambda[t.edge[x as usize] as usize])
                    };
                    let (ab, bp, pa) = (
                        len(h),
                        len(IntrinsicTriangulation::next(h)),
                        len(IntrinsicTriangulation::prev(h)),
                    );
                    slack.push((
                        (bp + pa - ab) / ab,
                        t.origin[IntrinsicTriangulation::prev(h) as usize],
                    ));
                }
                slack.sort_by(|a, b| a.0.total_cmp(&b.0));
                let bad = slack.iter().filter(|s| s.0 <= 1e-9).count();
                println!(
                    "  boundary triangles at the last iterate: {bad} with slack ≤ 1e-9 (of {}); \
                     smallest {:?}",
                    slack.len(),
                    &slack[..slack.len().min(4)]
                );
                let interior_bad = r.degenerate_faces.saturating_sub(bad);
                println!("  degenerate faces not on the boundary: {interior_bad}");
            }
        }
        Err(e) => println!("surface flow: error {e}"),
    }
    // Boundary edges that are not Delaunay in the double at the input metric: the angle
    // opposite them exceeds π/2.
    let l = s.edge_lengths();
    let mut obtuse = 0;
    for e in 0..m.n_edges() as u32 {
        if !m.is_boundary_edge(e) {
            continue;
        }
        let h = m.edge_halfedge(e);
        let (a, b) = (m.he_origin(h), m.he_tip(h));
        let c = m.he_tip(m.he_next(h));
        let len = |x: u32, y: u32| l[m.he_edge(m.halfedge_between(x, y).unwrap()) as usize];
        let (ab, bc, ca) = (len(a, b), len(b, c), len(c, a));
        if bc * bc + ca * ca < ab * ab {
            obtuse += 1;
        }
    }
    println!("boundary edges with an obtuse opposite angle (not Delaunay in the double): {obtuse}");
    // 2. The flow on the double.
    let target = resolve(m, Geometry::Euclidean, &TargetSpec::FreeBoundary).unwrap();
    let t = std::time::Instant::now();
    let r = flow_on_double(m, &l, Geometry::Euclidean, &target, 1e-10, &mut NoProgress).unwrap();
    println!(
        "double: {} vertices, {} faces; {} isometric flips",
        r.sigma.len(),
        2 * m.n_faces(),
        r.initial_flips
    );
    println!(
        "double flow: converged {} in {} iterations, max |K − K̄| {:.3e}, {} degenerate faces, \
         {} Ptolemy flips, max |u − u∘σ| {:.2e}, {:.2} s; boundary edges not in the final \
         triangulation: {}",
        r.converged,
        r.iterations,
        r.max_error,
        r.degenerate_faces,
        r.flips,
        r.asymmetry,
        t.elapsed().as_secs_f64(),
        r.boundary_edges_flipped
    );
    for h in &r.history {
        println!(
            "  it {}: err {:.3e} step {:.3e}",
            h.iteration, h.max_curvature_error, h.step
        );
    }
    for n in &r.notes {
        println!("  note: {n}");
    }
    half_region(m, &r);
}

/// The next step's claim, measured: the faces of the double's final triangulation that meet
/// the surface (a vertex in its interior; rung faces x, σx, y included) form a flat disk that
/// lays out in the plane with no flipped face.
fn half_region(m: &ricci::mesh::Mesh, r: &ricci::flow::double::DoubleFlow) {
    let nv = m.n_vertices();
    let s = r
        .triangulation
        .to_simplicial(Geometry::Euclidean, &r.u_double)
        .unwrap();
    let inside = |v: u32| (v as usize) < nv && r.sigma[v as usize] != v;
    let mut id = vec![u32::MAX; s.mesh.n_vertices()];
    let mut faces = Vec::new();
    let mut all_fixed = 0;
    let mut n = 0u32;
    for f in 0..s.mesh.n_faces() as u32 {
        let t = s.mesh.face(f);
        let o = t.map(|v| s.vertex_origin[v as usize]);
        if o.iter().all(|&v| v != u32::MAX && r.sigma[v as usize] == v) {
            all_fixed += 1;
        }
        if !o.iter().any(|&v| v != u32::MAX && inside(v)) {
            continue;
        }
        let mut nt = [0u32; 3];
        for k in 0..3 {
            let v = t[k] as usize;
            if id[v] == u32::MAX {
                id[v] = n;
                n += 1;
            }
            nt[k] = id[v];
        }
        faces.push((f, nt));
    }
    let n = n as usize;
    let region = ricci::mesh::Mesh::from_triangles(n, faces.iter().map(|x| x.1).collect()).unwrap();
    let mut back = vec![0u32; n];
    for (v, &i) in id.iter().enumerate() {
        if i != u32::MAX {
            back[i as usize] = v as u32;
        }
    }
    let lengths: Vec<f64> = (0..region.n_edges() as u32)
        .map(|e| {
            let [a, b] = region.edge_vertices(e).map(|v| back[v as usize]);
            let h = s.mesh.halfedge_between(a, b).unwrap();
            s.lengths[s.mesh.he_edge(h) as usize]
        })
        .collect();
    let t = ricci::mesh::topology(&region);
    println!(
        "half region: {} of {} faces, χ = {}, {} boundary loop(s), {} faces of the double with \
         only boundary vertices (left out)",
        region.n_faces(),
        s.mesh.n_faces(),
        t.euler_characteristic(),
        t.boundary_loops(),
        all_fixed
    );
    match ricci::layout::place::layout::<ricci::metric::Euclidean>(
        &region,
        &IntrinsicMetric::new(ricci::metric::Geometry::Euclidean, lengths.to_vec()),
        None,
    ) {
        Ok(l) => println!(
            "  layout: {} flipped, {} degenerate, max length error {:.2e}",
            l.flipped_faces.len(),
            l.degenerate_faces.len(),
            l.max_length_error
        ),
        Err(e) => println!("  layout: {e}"),
    }
}

/// A mesh file: free boundary (E²) or geodesic boundary (H²), on the surface and the double.
fn mesh_file(path: &str, geometry: Geometry) {
    let (s, _) = ricci::mesh::io::read_surface(std::path::Path::new(path)).unwrap();
    let spec = match geometry {
        Geometry::Hyperbolic => TargetSpec::GeodesicBoundary,
        _ => TargetSpec::FreeBoundary,
    };
    let o = FlowOptions {
        geometry,
        scheme: Scheme::Conformal,
        target: spec.clone(),
        tolerance: 1e-10,
        ..FlowOptions::default()
    };
    let l = s.edge_lengths();
    let t = std::time::Instant::now();
    let f = ricci_flow(&s.mesh, &l, &o, &mut NoProgress).unwrap();
    println!(
        "{path} {geometry:?}: {} vertices; surface flow converged {} ({} iterations, {} \
         isometric flips, max |K − K̄| {:.2e}), {:.2} s",
        s.mesh.n_vertices(),
        f.converged,
        f.iterations,
        f.triangulation.as_ref().map_or(0, |t| t.initial_flips),
        f.max_curvature_error,
        t.elapsed().as_secs_f64()
    );
    // H² reads the lengths scaled as the surface flow did.
    let scaled: Vec<f64> = l.iter().map(|x| x * f.input_scale).collect();
    let target = resolve(&s.mesh, geometry, &spec).unwrap();
    let t = std::time::Instant::now();
    match flow_on_double(&s.mesh, &scaled, geometry, &target, 1e-10, &mut NoProgress) {
        Ok(r) => {
            let du =
                r.u.iter()
                    .zip(&f.u)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0f64, f64::max);
            println!(
                "double: {} vertices; converged {} ({} iterations, {} isometric + {} Ptolemy \
                 flips, {} boundary edges flipped, max |K − K̄| {:.2e}, asymmetry {:.1e}), \
                 {:.2} s; max |u_double − u_surface| on the surface {du:.2e}",
                r.sigma.len(),
                r.converged,
                r.iterations,
                r.initial_flips,
                r.flips,
                r.boundary_edges_flipped,
                r.max_error,
                r.asymmetry,
                t.elapsed().as_secs_f64()
            );
        }
        Err(e) => println!("double: {e}"),
    }
}
