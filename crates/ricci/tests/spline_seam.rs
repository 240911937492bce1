//! The tessellation of a manifold spline with its G¹ fill patch is one closed surface: the
//! spline part is trimmed at the seam curve and the fill's outer ring is made of the same
//! vertices (paper 000 §5, last paragraph; [`ricci::spline::surface::tessellate`]). Checked
//! against things the tessellation does not construct:
//!
//! * the topology of the input — one connected, manifold, consistently oriented mesh without
//!   boundary whose Euler characteristic is `2 − 2g` (the mesh builder rejects non-manifold
//!   edges and inconsistent orientation);
//! * the seam vertices lie on the spline (re-evaluated at their face and barycentric
//!   coordinates) and on the fill ([`Hole::fill_point`] at `t = 1` and their `ψ`);
//! * the surface does not kink at the seam: the dihedral angles across the seam edges are
//!   no larger than those of the spline part at the same resolution;
//! * the per-vertex domain face / chart columns are those of the spline (fill vertices −1).
//!
//! The generated genus-2 surface always runs; eight.off needs `RICCI_MESHES`.

#[path = "ricci_meshes/mod.rs"]
mod ricci_meshes;
use ricci_meshes::ricci_meshes;

use ricci::mesh::io::read_surface;
use ricci::mesh::{topology, Mesh, Surface};
use ricci::progress::NoProgress;
use ricci::spline::dms::{KnotOptions, Workspace};
use ricci::spline::hole::Hole;
use ricci::spline::manifold::ManifoldSpace;
use ricci::spline::surface::{
    build, flat_domain, tessellate, Singularity, SplineOptions, Tessellation,
};
use std::collections::HashMap;

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn norm(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}
fn unit_normal(p: &[[f64; 3]], f: [u32; 3]) -> [f64; 3] {
    let [a, b, c] = f.map(|v| p[v as usize]);
    let (u, v) = (sub(b, a), sub(c, a));
    let n = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    let l = norm(n).max(1e-300);
    [n[0] / l, n[1] / l, n[2] / l]
}
fn angle_deg(a: [f64; 3], b: [f64; 3]) -> f64 {
    (a[0] * b[0] + a[1] * b[1] + a[2] * b[2])
        .clamp(-1.0, 1.0)
        .acos()
        .to_degrees()
}
/// Smallest interior angle of a triangle (degrees).
fn min_angle_deg(p: &[[f64; 3]], f: [u32; 3]) -> f64 {
    let q = f.map(|v| p[v as usize]);
    (0..3)
        .map(|k| {
            let (u, v) = (sub(q[(k + 1) % 3], q[k]), sub(q[(k + 2) % 3], q[k]));
            angle_deg(
                u.map(|x| x / norm(u).max(1e-300)),
                v.map(|x| x / norm(v).max(1e-300)),
            )
        })
        .fold(180.0, f64::min)
}

fn quantile(mut v: Vec<f64>, q: f64) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[((v.len() - 1) as f64 * q).round() as usize]
}

/// Everything the module docs claim, for the spline of `s` tessellated with `m` segments per
/// domain edge. Returns (median, 90 %, max) of the spline part's dihedral angles and the
/// largest dihedral angle across the seam, in degrees.
fn check(name: &str, s: &Surface, m: usize) -> (f64, f64, f64, f64) {
    let genus = topology(&s.mesh).genus();
    let diag = s.diagonal();
    let dom = flat_domain(s, Singularity::Auto, &mut NoProgress).unwrap();
    let space = ManifoldSpace::new(&dom.charts, 3, &KnotOptions::default()).unwrap();
    let sp = build(&space, &SplineOptions::default(), &mut NoProgress).unwrap();
    assert_eq!(sp.holes.len(), 1, "{name}: one extraordinary point");
    let t: Tessellation = tessellate(&space, &sp, m).unwrap();
    let nv = t.positions.len();
    assert_eq!(t.vertex_face.len(), nv);
    assert_eq!(t.vertex_chart.len(), nv);
    assert_eq!(t.vertex_bary.len(), nv);

    // One closed, connected, consistently oriented manifold of the input's genus.
    let mesh = Mesh::from_triangles(nv, t.triangles.clone())
        .unwrap_or_else(|e| panic!("{name} m={m}: not a manifold mesh: {e}"));
    let top = topology(&mesh);
    assert_eq!(top.components.len(), 1, "{name} m={m}: connected");
    assert_eq!(top.boundary_loops(), 0, "{name} m={m}: no boundary");
    assert_eq!(
        top.euler_characteristic(),
        2 - 2 * genus,
        "{name} m={m}: χ = 2 − 2g"
    );
    let mut used = vec![false; nv];
    for f in &t.triangles {
        for &v in f {
            used[v as usize] = true;
        }
    }
    assert!(used.iter().all(|&u| u), "{name}: unused vertices");

    // Vertex columns: spline vertices are the spline at their (face, bary) in an active face
    // of their canonical chart; fill vertices are −1 and only in fill triangles.
    let mut ws = Workspace::default();
    let mut out = [0.0; 3];
    let mut worst_spline: f64 = 0.0;
    for v in 0..nv {
        let (f, c) = (t.vertex_face[v], t.vertex_chart[v]);
        assert_eq!(f < 0, c < 0, "{name}: vertex {v} face {f} chart {c}");
        if f < 0 {
            assert_eq!((f, c), (-1, -1));
            continue;
        }
        let f = f as u32;
        assert!(
            space.is_active(f),
            "{name}: vertex {v} in inactive face {f}"
        );
        assert_eq!(c, space.canonical_chart(f) as i64, "{name}: vertex {v}");
        let b = t.vertex_bary[v];
        assert!(
            b.iter().all(|&x| x >= -1e-12) && (b.iter().sum::<f64>() - 1.0).abs() < 1e-12,
            "{name}: vertex {v} bary {b:?}"
        );
        space
            .evaluate(&sp.control, 3, f, b, 0, &mut ws, &mut out)
            .unwrap();
        worst_spline = worst_spline.max(norm(sub(out, t.positions[v])));
    }
    assert!(
        worst_spline <= 1e-9 * diag,
        "{name}: a spline vertex is {worst_spline:e} off the spline"
    );
    for (k, f) in t.triangles.iter().enumerate() {
        if k < t.spline_triangles {
            assert!(f.iter().all(|&v| t.vertex_face[v as usize] >= 0));
        }
    }

    // Seam: one closed loop of mesh edges, each vertex on the spline (above) and on the fill.
    assert_eq!(t.seams.len(), 1);
    let seam = &t.seams[0];
    let hole: &Hole = &sp.holes[seam.hole];
    let n = seam.vertices.len();
    assert!(n >= 3 * m, "{name}: only {n} seam vertices");
    let mut worst_fill: f64 = 0.0;
    for (&v, &psi) in seam.vertices.iter().zip(&seam.psi) {
        let p = hole
            .fill_point(&space, &sp.control, 1.0, psi, &mut ws)
            .unwrap();
        worst_fill = worst_fill.max(norm(sub(p, t.positions[v as usize])));
        assert!(t.vertex_face[v as usize] >= 0);
    }
    assert!(
        worst_fill <= 1e-9 * diag,
        "{name}: a seam vertex is {worst_fill:e} off the fill patch"
    );

    // Dihedral angles: the spline part's grid (edges between triangles with no vertex on the
    // seam) vs the seam edges (one spline and one fill triangle), the spline triangles cut by
    // the seam, and the fill.
    let seam_set: std::collections::HashSet<u32> = seam.vertices.iter().copied().collect();
    let on_seam = |f: &[u32; 3]| f.iter().any(|v| seam_set.contains(v));
    let mut owner: HashMap<(u32, u32), usize> = HashMap::new();
    let mut grid_angles = Vec::new();
    let mut trimmed_angles = Vec::new();
    let mut seam_angles = Vec::new();
    let mut fill_angles = Vec::new();
    for (i, f) in t.triangles.iter().enumerate() {
        for e in 0..3 {
            let (a, b) = (f[e], f[(e + 1) % 3]);
            let key = (a.min(b), a.max(b));
            if let Some(&j) = owner.get(&key) {
                let g = &t.triangles[j];
                let d = angle_deg(unit_normal(&t.positions, *f), unit_normal(&t.positions, *g));
                match (i < t.spline_triangles, j < t.spline_triangles) {
                    (true, true) if on_seam(f) || on_seam(g) => trimmed_angles.push(d),
                    (true, true) => grid_angles.push(d),
                    (false, false) => fill_angles.push(d),
                    _ => seam_angles.push(d),
                }
            } else {
                owner.insert(key, i);
            }
        }
    }
    assert_eq!(seam_angles.len(), n, "{name}: every seam edge is shared");
    let seam_max = seam_angles.iter().copied().fold(0.0, f64::max);
    let (med, q90, max) = (
        quantile(grid_angles.clone(), 0.5),
        quantile(grid_angles.clone(), 0.9),
        quantile(grid_angles, 1.0),
    );
    let trimmed_max = trimmed_angles.iter().copied().fold(0.0, f64::max);
    let fill_max = fill_angles.iter().copied().fold(0.0, f64::max);
    let seam_q90 = quantile(seam_angles.clone(), 0.9);
    let spline_tris = &t.triangles[..t.spline_triangles];
    let min_of = |it: &mut dyn Iterator<Item = &[u32; 3]>| {
        it.map(|&f| min_angle_deg(&t.positions, f))
            .fold(180.0, f64::min)
    };
    let min_grid = min_of(&mut spline_tris.iter().filter(|f| !on_seam(f)));
    let min_trimmed = min_of(&mut spline_tris.iter().filter(|f| on_seam(f)));
    let min_fill = min_of(&mut t.triangles[t.spline_triangles..].iter());
    eprintln!(
        "{name} m={m}: {nv} vertices, {} triangles ({} fill), seam {n} vertices ({} snapped); \
         dihedral grid median {med:.2}° 90% {q90:.2}° max {max:.2}° | seam 90% {seam_q90:.2}° \
         max {seam_max:.2}° | trimmed max {trimmed_max:.2}° | fill max {fill_max:.2}°; min angle grid {min_grid:.1}° trimmed \
         {min_trimmed:.1}° fill {min_fill:.1}°; seam off spline {worst_spline:.1e}, off fill \
         {worst_fill:.1e} (diag {diag:.3})",
        t.triangles.len(),
        t.triangles.len() - t.spline_triangles,
        seam.snapped
    );
    // No kink at the seam and no fold where the grid is cut: their dihedral angles are within
    // those of the spline's grid.
    assert!(
        seam_q90 <= q90,
        "{name} m={m}: 90th percentile dihedral across the seam {seam_q90:.2}° > spline {q90:.2}°"
    );
    assert!(
        seam_max <= max,
        "{name} m={m}: largest dihedral across the seam {seam_max:.2}° > spline {max:.2}°"
    );
    assert!(
        trimmed_max <= max,
        "{name} m={m}: largest dihedral at the cut triangles {trimmed_max:.2}° > grid {max:.2}°"
    );
    // No slivers: trimming keeps half the grid's smallest angle, the fill above 1°.
    assert!(
        min_trimmed >= 0.5 * min_grid,
        "{name} m={m}: trimmed triangles down to {min_trimmed:.2}° (grid {min_grid:.2}°)"
    );
    assert!(
        min_fill >= 1.0,
        "{name} m={m}: fill triangles down to {min_fill:.2}°"
    );
    (med, q90, max, seam_max)
}

#[test]
fn generated_genus2_tessellation_is_one_closed_surface() {
    let s = ricci::mesh::generate::genus(2, 16).unwrap();
    for m in [4, 8] {
        check("genus2:16", &s, m);
    }
}

#[test]
fn eight_tessellation_is_one_closed_surface() {
    let Some(dir) = ricci_meshes() else {
        eprintln!("note: RICCI_MESHES is not set; skipping eight.off");
        return;
    };
    let s = read_surface(&dir.join("eight.off")).expect("eight.off").0;
    for m in [4, 8] {
        check("eight", &s, m);
    }
}
