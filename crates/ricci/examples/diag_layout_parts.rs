//! Time the parts of `ricci layout` on a mesh (flow, polish, cut, layout, deck group, input
//! UVs): wall and CPU seconds of each (CPU of the main thread, from /proc/self/schedstat), and
//! the accuracy figures of the result (relation error, edge spreads, length error).
//!
//! `cargo run --release -p ricci --example diag_layout_parts -- MESH [SCHEME]`
use ricci::layout::input_uv::input_face_uvs;
use ricci::layout::pipeline::{cut_disk_polished, polish_uniformization, uniformization_metric};
use ricci::layout::{deck_group, layout_dd};
use ricci::metric::IntrinsicMetric;
use ricci::metric::{Geometry, Hyperbolic, Scheme};
use ricci::progress::NoProgress;
use std::time::Instant;

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

struct Clock(Instant, f64, f64, f64);
impl Clock {
    fn new() -> Clock {
        Clock(Instant::now(), cpu_seconds(), 0.0, 0.0)
    }
    /// Print the stage's wall and CPU seconds and restart.
    fn lap(&mut self, what: &str, extra: String) {
        let (w, c) = (self.0.elapsed().as_secs_f64(), cpu_seconds() - self.1);
        self.2 += w;
        self.3 += c;
        println!("{what:<8} wall {w:6.2} s  cpu {c:6.2} s  {extra}");
        self.0 = Instant::now();
        self.1 = cpu_seconds();
    }
}

fn main() {
    let path = std::env::args().nth(1).expect("mesh");
    let scheme: Scheme = std::env::args()
        .nth(2)
        .unwrap_or("conformal".into())
        .parse()
        .unwrap();
    let (s, _) = ricci::mesh::io::read_surface(std::path::Path::new(&path)).unwrap();
    let mut clock = Clock::new();
    let f = uniformization_metric(
        &s.mesh,
        &IntrinsicMetric::euclidean(s.edge_lengths()),
        Geometry::Hyperbolic,
        scheme,
        1e-12,
        &mut NoProgress,
    )
    .unwrap();
    clock.lap("flow", format!("({} it)", f.iterations));
    let work = f
        .triangulation
        .as_ref()
        .map(|t| t.simplicial.mesh.clone())
        .unwrap_or(s.mesh.clone());
    let p =
        polish_uniformization(&s.mesh, &IntrinsicMetric::euclidean(s.edge_lengths()), &f).unwrap();
    clock.lap(
        "polish",
        format!(
            "({} steps, {:.1e} → {:.1e})",
            p.steps, p.residual_start, p.residual_dd
        ),
    );
    let pos = f.triangulation.is_none().then_some(&s.positions[..]);
    let d = cut_disk_polished(&work, &p.metric, pos, None, &mut NoProgress).unwrap();
    clock.lap(
        "cut",
        format!(
            "({} → {} vertices; canonical_cut {:.2} s wall; refined polish {})",
            work.n_vertices(),
            d.cut.refined.mesh.n_vertices(),
            d.cut.report.seconds,
            serde_json::to_string(&d.refined_polish).unwrap()
        ),
    );
    println!(
        "         cut report {}",
        serde_json::to_string(&d.cut.report).unwrap()
    );
    let l = layout_dd::<Hyperbolic>(&d.mesh, &d.metric, None).unwrap();
    clock.lap(
        "layout",
        format!(
            "({} faces, depth {}, flipped {}, max length error {:.1e})",
            d.mesh.n_faces(),
            l.depth,
            l.flipped_faces.len(),
            l.max_length_error
        ),
    );
    let g = deck_group::<Hyperbolic>(&l, &d.polygon).unwrap();
    clock.lap(
        "deck",
        format!(
            "(relation error {:.1e}, edge spread {:.1e}, matrix spread {:.1e})",
            g.relation_error.unwrap_or(f64::NAN),
            g.max_edge_spread,
            g.max_edge_spread_matrix
        ),
    );
    let u =
        input_face_uvs::<Hyperbolic>(&s.mesh, &l.positions, &d.vertex_origin, Some(&g)).unwrap();
    clock.lap(
        "input uv",
        format!("(flipped {}, seam {})", u.flipped_faces.len(), u.seam_faces),
    );
    println!("total    wall {:6.2} s  cpu {:6.2} s", clock.2, clock.3);
}
