//! Size and time of the common subdivision (input mesh ∩ final intrinsic triangulation of the
//! conformal flow), its UV map by projective interpolation, and the flipped-triangle count.
//!
//! `RICCI_MESHES=/work/shared/meshes cargo run --release -p ricci --example bench_overlay [FILTER…]`
//!
//! Per case: the flow (not timed here, see `bench_conformal`), then the replay of the flip log
//! with normal coordinates + tracing + polygons (`overlay s`), the breadth-first layout of T
//! (`layout s`), and the UVs of all subdivision corners (`uv s`).

use ricci::flow::{ricci_flow, FlowOptions, TargetSpec};
use ricci::mesh::io::read_surface;
use ricci::metric::common_subdivision::{layout_euclidean, layout_hyperbolic, CommonSubdivision};
use ricci::metric::{Geometry, Scheme};
use ricci::progress::NoProgress;
use std::path::PathBuf;
use std::time::Instant;

fn main() {
    let dir = match std::env::var_os("RICCI_MESHES") {
        Some(d) => PathBuf::from(d),
        None => {
            eprintln!("set RICCI_MESHES to the shared mesh folder");
            return;
        }
    };
    let filter: Vec<String> = std::env::args().skip(1).collect();
    use Geometry::*;
    let cases: [(&str, &str, Geometry, TargetSpec); 6] = [
        (
            "face E2 free",
            "face.off",
            Euclidean,
            TargetSpec::FreeBoundary,
        ),
        (
            "kitten E2",
            "kitten.nf20k.off",
            Euclidean,
            TargetSpec::Uniform,
        ),
        (
            "bunny E2 free",
            "bunny.off",
            Euclidean,
            TargetSpec::FreeBoundary,
        ),
        ("eight H2", "eight.off", Hyperbolic, TargetSpec::Uniform),
        ("3holes H2", "3holes.off", Hyperbolic, TargetSpec::Uniform),
        (
            "fertility H2",
            "fertility.off",
            Hyperbolic,
            TargetSpec::Uniform,
        ),
    ];
    println!(
        "{:<14} {:>7} {:>7} {:>7} {:>8} {:>7} {:>9} {:>9} {:>8} {:>8} {:>8} {:>7} {:>6}",
        "case",
        "V",
        "F",
        "flips",
        "crossing",
        "shared",
        "sub V",
        "sub F",
        "overlay",
        "layout",
        "uv",
        "flipped",
        "order"
    );
    for (name, file, geometry, target) in cases {
        if !filter.is_empty() && !filter.iter().any(|f| name.contains(f.as_str())) {
            continue;
        }
        let (s, _) = match read_surface(&dir.join(file)) {
            Ok(x) => x,
            Err(e) => {
                println!("{name}: {e}");
                continue;
            }
        };
        let o = FlowOptions {
            geometry,
            scheme: Scheme::Conformal,
            target,
            ..FlowOptions::default()
        };
        let lengths = s.edge_lengths();
        let r = match ricci_flow(&s.mesh, &lengths, &o, &mut NoProgress) {
            Ok(r) => r,
            Err(e) => {
                println!("{name}: flow failed: {e}");
                continue;
            }
        };
        let it = r.triangulation.as_ref().expect("conformal scheme");
        let scaled: Vec<f64> = lengths.iter().map(|l| l * r.input_scale).collect();
        let t = Instant::now();
        let sub = match CommonSubdivision::from_triangulation(
            &s.mesh,
            geometry,
            &scaled,
            &it.triangulation,
            &r.u,
        ) {
            Ok(x) => x,
            Err(e) => {
                println!("{name}: overlay failed: {e}");
                continue;
            }
        };
        let t_overlay = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let layout = if geometry == Euclidean {
            layout_euclidean(&sub.triangulation, &r.u)
        } else {
            layout_hyperbolic(&sub.triangulation, &r.u)
        };
        let layout = match layout {
            Ok(l) => l,
            Err(e) => {
                println!("{name}: layout failed: {e}");
                continue;
            }
        };
        let t_layout = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let uv = sub.uv(geometry, &r.u, &layout).expect("uv");
        let t_uv = t.elapsed().as_secs_f64();
        let flipped = sub.flipped_triangles(geometry, &uv);
        println!(
            "{:<14} {:>7} {:>7} {:>7} {:>8} {:>7} {:>9} {:>9} {:>8.4} {:>8.4} {:>8.4} {:>7} {:>6}",
            name,
            s.mesh.n_vertices(),
            s.mesh.n_faces(),
            it.triangulation.flip_log.len(),
            sub.crossings.len(),
            sub.report.shared_edges,
            sub.n_vertices(),
            sub.triangles.len(),
            t_overlay,
            t_layout,
            t_uv,
            flipped,
            sub.report.order_violations
        );
        if !r.converged {
            println!("    flow not converged: {:?}", r.notes);
        }
    }
}
