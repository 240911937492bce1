//! Diagnostic: where the spline over the affine atlas jumps, and how large the faces there
//! are against their charts (issue 7, atlas Step 5 conditioning).
//!
//! `cargo run --release -p ricci --example atlas_edge_jumps -- MESH` (a file under
//! `RICCI_MESHES`, or `genus2:RES`). Builds the atlas, the degree-3 spline (fairness 1) over it
//! and over `LocalCharts` on the same metric with the same control points, and prints the 15
//! interior edges with the largest order-2 jump over the atlas: the jump relative to the
//! largest order-2 partial anywhere and at the edge, the same edge over `LocalCharts`, and for
//! both faces the home chart, the face's longest side `h` and `|u|/h` (largest coordinate of
//! the face in its home chart over `h`), then the distribution of
//! [`AffineAtlas::conditioning`] over the home charts.

use ricci::atlas::{AffineAtlas, AtlasOptions, FlatCharts};
use ricci::mesh::io::read_surface;
use ricci::progress::NoProgress;
use ricci::spline::dms::{KnotOptions, Workspace};
use ricci::spline::fit::fair;
use ricci::spline::manifold::{rotate_partials, LocalCharts, ManifoldSpace};
use ricci::spline::simplex::n_partials;
use ricci::spline::space::evaluate;

fn edge_jumps<A: FlatCharts + Sync>(
    space: &ManifoldSpace<'_, A>,
    control: &[f64],
) -> Vec<(u32, u32, u32, f64, f64)> {
    let n = space.degree();
    let np = n_partials(n);
    let charts = space.charts();
    let mesh = charts.mesh();
    let mut out = Vec::new();
    let mut ws = Workspace::default();
    for h in 0..mesh.n_corners() as u32 {
        let t = mesh.he_twin(h);
        if mesh.is_boundary_halfedge(t) || t < h {
            continue;
        }
        let (g1, g2) = (h / 3, t / 3);
        if !(space.is_active(g1) && space.is_active(g2)) {
            continue;
        }
        let i = h as usize % 3;
        let tt = t as usize % 3;
        let c1 = space.canonical_coords(g1);
        let c2 = space.canonical_coords(g2);
        let (mut jmax, mut smax) = (0.0f64, 0.0f64);
        for s in [0.25, 0.5, 0.75] {
            let mut b1 = [0.0; 3];
            b1[i] = 1.0 - s;
            b1[(i + 1) % 3] = s;
            let mut b2 = [0.0; 3];
            b2[(tt + 1) % 3] = 1.0 - s;
            b2[tt] = s;
            let u1: [f64; 2] = std::array::from_fn(|k| (0..3).map(|m| b1[m] * c1[m][k]).sum());
            let u2: [f64; 2] = std::array::from_fn(|k| (0..3).map(|m| b2[m] * c2[m][k]).sum());
            let mut a = vec![0.0; np * 3];
            evaluate(space, control, 3, g1, u1, n, &mut ws, &mut a).unwrap();
            let mut b = vec![0.0; np * 3];
            evaluate(space, control, 3, g2, u2, n, &mut ws, &mut b).unwrap();
            let (m, _) = charts
                .transition(space.canonical_chart(g1), space.canonical_chart(g2), g2)
                .unwrap();
            for d in 0..3 {
                let mut col: Vec<f64> = (0..np).map(|k| b[k * 3 + d]).collect();
                rotate_partials(n, m.rot, &mut col);
                for k in 0..np {
                    b[k * 3 + d] = col[k];
                }
            }
            for idx in n_partials(2) - 3..n_partials(2) {
                for d in 0..3 {
                    smax = smax.max(a[idx * 3 + d].abs()).max(b[idx * 3 + d].abs());
                    jmax = jmax.max((a[idx * 3 + d] - b[idx * 3 + d]).abs());
                }
            }
        }
        out.push((h, g1, g2, jmax, smax));
    }
    out
}

fn face_size(c: &[[f64; 2]; 3]) -> (f64, f64) {
    let mut h = 0.0f64;
    let mut u = 0.0f64;
    for i in 0..3 {
        let (a, b) = (c[i], c[(i + 1) % 3]);
        h = h.max((a[0] - b[0]).hypot(a[1] - b[1]));
        u = u.max(a[0].abs()).max(a[1].abs());
    }
    (h, u)
}

fn main() {
    let f = std::env::args().nth(1).unwrap();
    let dir = std::env::var("RICCI_MESHES").unwrap_or_else(|_| "/work/shared/meshes".into());
    let surface = if let Some(res) = f.strip_prefix("genus2:") {
        ricci::mesh::generate::genus(2, res.parse().unwrap()).unwrap()
    } else {
        read_surface(&std::path::Path::new(&dir).join(&f))
            .unwrap()
            .0
    };
    let atlas = AffineAtlas::build(&surface, &AtlasOptions::default(), &mut NoProgress).unwrap();
    println!("charts {} (local {}) transition err {:.2e} rel {:.2e} max length err {:.2e} home cond {:.2e} secs {:.2}", atlas.n_charts(), atlas.report.local_charts, atlas.report.max_transition_error, atlas.report.max_relative_transition_error, atlas.report.max_length_error, atlas.report.max_home_conditioning, atlas.report.seconds);
    let space = ManifoldSpace::new(&atlas, 3, &KnotOptions::default()).unwrap();
    let (control, fr) = fair(&space, &space.subdivision_control_points(), 3, 1).unwrap();
    println!("fair converged {}", fr.converged);
    let local = LocalCharts::new(
        atlas.mesh().clone(),
        ricci::metric::IntrinsicMetric::euclidean(atlas.lengths().to_vec()),
        atlas.positions().to_vec(),
        atlas.singular_vertices().to_vec(),
        None,
    )
    .unwrap();
    let space2 = ManifoldSpace::new(&local, 3, &KnotOptions::default()).unwrap();
    let ja = edge_jumps(&space, &control);
    let jl = edge_jumps(&space2, &control);
    let sa = ja.iter().map(|x| x.4).fold(0.0, f64::max);
    let sl = jl.iter().map(|x| x.4).fold(0.0, f64::max);
    println!(
        "global scale atlas {sa:.3e} local {sl:.3e}; max rel jump atlas {:.2e} local {:.2e}",
        ja.iter().map(|x| x.3).fold(0.0, f64::max) / sa,
        jl.iter().map(|x| x.3).fold(0.0, f64::max) / sl
    );
    let mut idx: Vec<usize> = (0..ja.len()).collect();
    idx.sort_by(|&a, &b| ja[b].3.total_cmp(&ja[a].3));
    println!("edge g1 g2 | jump/global | jump/local scale | local-charts jump/local | home1 home2 | h1 |u1|/h1 | h2 |u2|/h2");
    for &k in idx.iter().take(15) {
        let (_, g1, g2, j, s) = ja[k];
        let mut line = format!(
            "{g1} {g2} | {:.2e} | {:.2e} | {:.2e} |",
            j / sa,
            j / s,
            jl[k].3 / jl[k].4
        );
        for g in [g1, g2] {
            let hc = space.home_chart(g).unwrap();
            let c = atlas.face_coords(hc, g).unwrap();
            let (h, u) = face_size(&c);
            line += &format!(" ch{hc} h {h:.2e} |u|/h {:.1e} |", u / h);
        }
        println!("{line}");
    }
    // Distribution of the conditioning over the home charts.
    let mut worst = 0.0f64;
    let mut cnt = [0usize; 6];
    for g in 0..atlas.mesh().n_faces() as u32 {
        let Some(hc) = space.home_chart(g) else {
            continue;
        };
        let r = atlas.conditioning(hc, g);
        worst = worst.max(r);
        let b = (r.log10().max(0.0) as usize).min(5);
        cnt[b] += 1;
    }
    println!("conditioning in the home chart: worst {worst:.2e}; decades 1,10,..1e5+: {cnt:?}");
}
