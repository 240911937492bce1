//! The common subdivision of the input and the final intrinsic triangulation of the default
//! (conformal) flow, as `ricci layout --out` builds it when the input's own faces would have
//! flipped UV triangles: seahorse2_100K in H² (`layout::subdivision_uv::common_subdivision_uvs`
//! needs a layout; timed here is the subdivision itself, `CommonSubdivision::from_triangulation`,
//! i.e. replay, tracing, crossings and polygons) and horse on S² (the whole
//! `sphere_common_subdivision`, points on the sphere included). Prints the flow's and the
//! subdivision's wall and CPU seconds.
//!
//! `RICCI_MESHES=/work/shared/meshes cargo run --release -p ricci --example bench_subdivision_uv`

use ricci::flow::{ricci_flow, FlowOptions, TargetSpec};
use ricci::layout::subdivision_uv::sphere_common_subdivision;
use ricci::metric::common_subdivision::CommonSubdivision;
use ricci::metric::{Geometry, IntrinsicMetric, Scheme};
use ricci::progress::NoProgress;
use std::time::Instant;

fn main() {
    let dir = std::path::PathBuf::from(std::env::var("RICCI_MESHES").expect("RICCI_MESHES"));
    println!(
        "| mesh | geometry | V | F | flips | flow s (cpu) | subdivision s (cpu) | sub V | sub F | flipped |"
    );
    for (name, g, tol) in [
        ("seahorse2_100K.off", Geometry::Hyperbolic, 1e-12),
        ("horse.ply", Geometry::Spherical, 1e-10),
    ] {
        let s = ricci::mesh::io::read_surface(&dir.join(name)).unwrap().0;
        let l = s.edge_lengths();
        let o = FlowOptions {
            geometry: g,
            scheme: Scheme::Conformal,
            target: TargetSpec::Uniform,
            tolerance: tol,
            ..FlowOptions::default()
        };
        let (t0, c0) = (Instant::now(), cpu_seconds());
        let r = ricci_flow(&s.mesh, &l, &o, &mut NoProgress).unwrap();
        let (flow_s, flow_c) = (t0.elapsed().as_secs_f64(), cpu_seconds() - c0);
        let it = r.triangulation.as_ref().unwrap();
        let (t1, c1) = (Instant::now(), cpu_seconds());
        let (nv, nf, flipped) = if g == Geometry::Spherical {
            let sub = sphere_common_subdivision(
                &s.mesh,
                &s.positions,
                &IntrinsicMetric::euclidean(l.to_vec()),
                &it.triangulation,
                &r.u,
                &it.points,
            )
            .unwrap();
            (
                sub.n_vertices(),
                sub.triangles.len(),
                sub.flipped_faces.to_string(),
            )
        } else {
            let sub =
                CommonSubdivision::from_triangulation(&s.mesh, g, &l, &it.triangulation, &r.u)
                    .unwrap();
            let _ = sub.positions(&s.mesh, &s.positions).unwrap();
            (
                sub.n_vertices(),
                sub.triangles.len(),
                "(needs the layout)".into(),
            )
        };
        let (sub_s, sub_c) = (t1.elapsed().as_secs_f64(), cpu_seconds() - c1);
        println!(
            "| {name} | {} | {} | {} | {} | {flow_s:.2} ({flow_c:.2}) | {sub_s:.3} ({sub_c:.3}) | {nv} | {nf} | {flipped} |",
            g.name(),
            s.mesh.n_vertices(),
            s.mesh.n_faces(),
            it.initial_flips + it.flips,
        );
    }
}

/// CPU time of this thread (`/proc/self/schedstat`): the machine is shared.
fn cpu_seconds() -> f64 {
    std::fs::read_to_string("/proc/self/schedstat")
        .ok()
        .and_then(|s| {
            s.split_whitespace()
                .next()
                .and_then(|x| x.parse::<f64>().ok())
        })
        .map(|ns| ns * 1e-9)
        .unwrap_or(f64::NAN)
}
