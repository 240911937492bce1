//! The affine atlas (paper 000 §4) on generated surfaces and the shared real meshes
//! (`RICCI_MESHES`): every property is re-checked here from the atlas's raw data, not from
//! its own report:
//!
//! * flatness: the curvature of the returned metric, recomputed from the edge lengths, is
//!   ≤ 1e-9 at every interior non-singular vertex, the cone carries 2πχ (Gauss–Bonnet), and
//!   the cone valence satisfies paper 000 Step 2 (i), and (ii): every vertex within 3 edge
//!   rings of a cone (breadth-first search over the atlas's mesh) has valence ≥ 6;
//! * every chart reproduces the metric lengths, has no flipped face, and two charts holding
//!   the same face are related there by a rigid motion to ≤ 1e-9;
//! * the home chart of every face not at a cone holds all faces sharing a vertex with it
//!   with one coordinate per vertex;
//! * random points (face, barycentric) off the cone are covered, and their coordinates in
//!   two charts are related by the charts' transition on that face.

use ricci::atlas::{fit_rigid, AffineAtlas, AtlasOptions, FlatCharts, Singularity};
use ricci::layout::isometry::Isometry;
use ricci::mesh::io::read_surface;
use ricci::mesh::{generate, Surface};
use ricci::metric::IntrinsicMetric;
use ricci::metric::{curvature, Geometry};
use ricci::progress::NoProgress;
use std::f64::consts::PI;
use std::path::PathBuf;

fn mesh_dir() -> Option<PathBuf> {
    let d = ricci_meshes()?;
    d.is_dir().then_some(d)
}

fn load(name: &str) -> Option<Surface> {
    let Some(dir) = mesh_dir() else {
        eprintln!("RICCI_MESHES is not set: skipping {name}");
        return None;
    };
    Some(read_surface(&dir.join(name)).unwrap().0)
}

fn euler(s: &Surface) -> i64 {
    ricci::mesh::topology(&s.mesh).euler_characteristic()
}

/// Paper 000 §4 Step 2 (ii), recomputed from the atlas's mesh: every vertex within 3 edge
/// rings of a cone (breadth-first over edges) has valence ≥ 6.
fn check_ring_valence(name: &str, a: &AffineAtlas) {
    let m = a.mesh();
    let mut d = vec![usize::MAX; m.n_vertices()];
    let mut q = std::collections::VecDeque::new();
    for &c in a.singular_vertices() {
        d[c as usize] = 0;
        q.push_back(c);
    }
    let mut low = Vec::new();
    while let Some(v) = q.pop_front() {
        if d[v as usize] >= 1 && m.valence(v) < 6 {
            low.push((v, d[v as usize], m.valence(v)));
        }
        if d[v as usize] == 3 {
            continue;
        }
        for w in m.vertex_neighbors(v) {
            if d[w as usize] == usize::MAX {
                d[w as usize] = d[v as usize] + 1;
                q.push_back(w);
            }
        }
    }
    let r = &a.report.refinement;
    eprintln!(
        "{name}: Step 2 (ii): {} low before, {} after; {} flips, {} + {} splits",
        r.low_valence_before, r.low_valence_after, r.flips_ring, r.splits_ring, r.splits_ring_room
    );
    assert!(
        low.is_empty(),
        "{name}: {} vertices within 3 rings of a cone have valence < 6 (vertex, ring, \
         valence): {:?}",
        low.len(),
        &low[..low.len().min(10)]
    );
    assert_eq!(r.low_valence_after, 0, "{name}: the report disagrees");
}

/// Check everything listed in the module docs; `singular` = expected number of cones.
fn check(name: &str, s: &Surface, a: &AffineAtlas, singular: usize) {
    let m = a.mesh();
    let l = a.lengths();
    let r = &a.report;
    eprintln!(
        "{name}: cones {:?}, {} charts, distortion {:.4}, flow {:.2e} ({}), transitions {:.2e}, {:.2} s",
        r.singular_vertices,
        a.n_charts(),
        r.area_distortion,
        r.max_curvature_error,
        r.scheme,
        r.max_transition_error,
        r.seconds
    );
    assert_eq!(
        a.singular_vertices().len(),
        singular,
        "{name}: singular vertices"
    );
    if singular > 0 {
        check_ring_valence(name, a);
    }
    assert!(r.flow_converged, "{name}: flow did not converge");
    assert_eq!(a.positions().len(), m.n_vertices());
    // Flatness, recomputed.
    let k = curvature(m, Geometry::Euclidean, l);
    let chi = euler(s) as f64;
    for v in 0..m.n_vertices() as u32 {
        if m.is_boundary_vertex(v) || a.singular_vertices().contains(&v) {
            continue;
        }
        assert!(
            k[v as usize].abs() <= 1e-9,
            "{name}: vertex {v} has curvature {:e}",
            k[v as usize]
        );
    }
    if singular == 1 {
        let c = a.singular_vertices()[0];
        assert!(
            (k[c as usize] - 2.0 * PI * chi).abs() < 1e-8,
            "{name}: the cone carries {} instead of 2πχ = {}",
            k[c as usize],
            2.0 * PI * chi
        );
        let need = 4.0 - 2.0 * (2.0 * PI * chi) / PI;
        assert!(
            m.valence(c) as f64 >= need,
            "{name}: cone valence {}",
            m.valence(c)
        );
    }
    let scale = l.iter().sum::<f64>() / l.len() as f64;
    // Charts: lengths, orientation, transitions.
    let mut worst: f64 = 0.0;
    for f in 0..m.n_faces() as u32 {
        let cs = a.charts_of_face(f);
        assert!(!cs.is_empty(), "{name}: face {f} is in no chart");
        let hs = m.face_halfedges(f);
        for &c in &cs {
            let co = a.face_coords(c, f).unwrap();
            let area2 = (co[1][0] - co[0][0]) * (co[2][1] - co[0][1])
                - (co[1][1] - co[0][1]) * (co[2][0] - co[0][0]);
            assert!(area2 > 0.0, "{name}: face {f} is flipped in chart {c}");
            for i in 0..3 {
                let (p, q) = (co[i], co[(i + 1) % 3]);
                let d = (p[0] - q[0]).hypot(p[1] - q[1]);
                let want = l[m.he_edge(hs[i]) as usize];
                assert!(
                    (d - want).abs() <= 1e-9 * scale.max(want),
                    "{name}: face {f} chart {c}: side {d} vs length {want}"
                );
            }
        }
        let c0 = a.face_coords(cs[0], f).unwrap();
        for &c in &cs[1..] {
            let (_, res) = fit_rigid(&c0, &a.face_coords(c, f).unwrap());
            worst = worst.max(res);
        }
    }
    assert!(
        worst <= 1e-9 * scale.max(1.0),
        "{name}: transition residual {worst:e}"
    );
    // Home charts.
    let at_cone = |f: u32| m.face(f).iter().any(|v| a.singular_vertices().contains(v));
    for f in 0..m.n_faces() as u32 {
        if at_cone(f) {
            assert_eq!(
                a.home_chart(f),
                None,
                "{name}: face {f} at a cone has a home"
            );
            continue;
        }
        let h = a
            .home_chart(f)
            .unwrap_or_else(|| panic!("{name}: face {f} has no home chart"));
        let mut seen: Vec<(u32, [f64; 2])> = Vec::new();
        for v in m.face(f) {
            for g in m.vertex_faces(v) {
                if at_cone(g) {
                    continue;
                }
                let co = a
                    .face_coords(h, g)
                    .unwrap_or_else(|| panic!("{name}: home chart {h} of {f} lacks face {g}"));
                for (i, &w) in m.face(g).iter().enumerate() {
                    match seen.iter().find(|x| x.0 == w) {
                        Some(x) => assert!(
                            (x.1[0] - co[i][0]).hypot(x.1[1] - co[i][1]) <= 1e-7 * scale,
                            "{name}: vertex {w} has two coordinates in the home chart of {f}"
                        ),
                        None => seen.push((w, co[i])),
                    }
                }
            }
        }
    }
    // Random points.
    let mut state = 0x2545_F491_4F6C_DD1Du64;
    let mut rnd = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let nf = m.n_faces();
    for _ in 0..2000 {
        let f = ((rnd() * nf as f64) as usize).min(nf - 1) as u32;
        let (x, y) = (rnd(), rnd());
        let (x, y) = if x + y > 1.0 {
            (1.0 - x, 1.0 - y)
        } else {
            (x, y)
        };
        let bary = [1.0 - x - y, x, y];
        let hits = a.locate(f, bary);
        assert!(!hits.is_empty(), "{name}: point on face {f} is not covered");
        for &(c, p) in &hits[1..] {
            let (mo, _) = a.transition(hits[0].0, c, f).unwrap();
            let z = mo.apply(num_complex::Complex64::new(hits[0].1[0], hits[0].1[1]));
            assert!(
                (z.re - p[0]).hypot(z.im - p[1]) <= 1e-9 * scale.max(1.0),
                "{name}: point on face {f}: charts {} and {c} disagree",
                hits[0].0
            );
        }
    }
    assert_eq!(r.faces_without_home, 0);
    assert_eq!(r.flipped_faces, 0);
}

fn build(s: &Surface, singularity: Singularity) -> AffineAtlas {
    let o = AtlasOptions {
        singularity,
        ..AtlasOptions::default()
    };
    AffineAtlas::build(s, &o, &mut NoProgress).unwrap()
}

#[test]
fn generated_genus2_auto() {
    let s = generate::genus(2, 24).unwrap();
    let a = build(&s, Singularity::Auto);
    check("genus2", &s, &a, 1);
    assert!(a.report.placement.is_some());
}

#[test]
fn generated_genus3_user_vertex() {
    let s = generate::genus(3, 20).unwrap();
    let a = build(&s, Singularity::Vertex(7));
    check("genus3 generated", &s, &a, 1);
    assert_eq!(a.singular_vertices(), &[7]);
}

#[test]
fn generated_torus_and_open_surfaces_have_no_singular_point() {
    let t = generate::torus(1.0, 0.5, 24).unwrap();
    check("torus", &t, &build(&t, Singularity::Auto), 0);
    let d = generate::disk(32).unwrap();
    check("disk", &d, &build(&d, Singularity::Auto), 0);
    let p = generate::pair_of_pants(40).unwrap();
    check("pants", &p, &build(&p, Singularity::Auto), 0);
}

#[test]
fn four_cones_on_a_sphere() {
    let s = generate::icosphere(2).unwrap();
    let far = ricci::flow::separated_vertices(&s.mesh, 4, 5);
    let o = AtlasOptions {
        cones: Some(far.iter().map(|&v| (v, PI)).collect()),
        ..AtlasOptions::default()
    };
    let a = AffineAtlas::build(&s, &o, &mut NoProgress).unwrap();
    check("sphere, four cones", &s, &a, 4);
}

#[test]
fn two_user_cones_on_genus2() {
    let s = generate::genus(2, 24).unwrap();
    let far = ricci::flow::separated_vertices(&s.mesh, 2, 5);
    let o = AtlasOptions {
        cones: Some(vec![(far[0], -2.0 * PI), (far[1], -2.0 * PI)]),
        ..AtlasOptions::default()
    };
    let a = AffineAtlas::build(&s, &o, &mut NoProgress).unwrap();
    check("genus2, two cones", &s, &a, 2);
    let k = curvature(a.mesh(), Geometry::Euclidean, a.lengths());
    for &c in a.singular_vertices() {
        assert!((k[c as usize] + 2.0 * PI).abs() < 1e-8);
    }
}

#[test]
fn refusals() {
    let d = generate::disk(16).unwrap();
    let e = AffineAtlas::build(
        &d,
        &AtlasOptions {
            singularity: Singularity::Vertex(3),
            ..AtlasOptions::default()
        },
        &mut NoProgress,
    )
    .unwrap_err();
    assert!(e.to_string().contains("open surface"), "{e}");
    let sphere = generate::icosphere(2).unwrap();
    let e = AffineAtlas::build(&sphere, &AtlasOptions::default(), &mut NoProgress).unwrap_err();
    assert!(e.to_string().contains("genus-0"), "{e}");
    let e = AffineAtlas::build(
        &sphere,
        &AtlasOptions {
            cones: Some(vec![(0, 2.0 * PI), (5, 2.0 * PI)]),
            ..AtlasOptions::default()
        },
        &mut NoProgress,
    )
    .unwrap_err();
    assert!(e.to_string().contains("K̄ < 2π"), "{e}");
    let g = generate::genus(2, 16).unwrap();
    let e = AffineAtlas::build(
        &g,
        &AtlasOptions {
            cones: Some(vec![(1, -PI)]),
            ..AtlasOptions::default()
        },
        &mut NoProgress,
    )
    .unwrap_err();
    assert!(e.to_string().contains("Gauss–Bonnet"), "{e}");
    let e = AffineAtlas::build(
        &g,
        &AtlasOptions {
            singularity: Singularity::Vertex(1 << 30),
            ..AtlasOptions::default()
        },
        &mut NoProgress,
    )
    .unwrap_err();
    assert!(e.to_string().contains("does not exist"), "{e}");
}

#[test]
fn closed_real_meshes_single_cone() {
    for (file, user) in [
        ("eight.off", Some(10)),
        ("eight.off", None),
        ("3holes.off", None),
        ("genus3.off", None),
        ("fertility.off", None),
        ("cup_input_simple_10000.off", None),
    ] {
        let Some(s) = load(file) else { return };
        let sing = user.map_or(Singularity::Auto, Singularity::Vertex);
        let a = build(&s, sing);
        check(file, &s, &a, 1);
        if let Some(v) = user {
            assert_eq!(a.singular_vertices(), &[v]);
        }
    }
}

#[test]
fn open_and_genus1_real_meshes_without_singular_point() {
    for file in [
        "face.off",
        "camelhead.off",
        "eight.open.off",
        "bunny.off",
        "punctured-torus.obj",
        "kitten.nf20k.off",
    ] {
        let Some(s) = load(file) else { return };
        let a = build(&s, Singularity::Auto);
        check(file, &s, &a, 0);
    }
}

/// The query API: a vertex on the cut has several coordinates in the central chart; the
/// transition maps between two charts are the distinct per-face rigid motions, together
/// covering every common face, and a cut chart straddling the cut meets the central chart in
/// two different motions (they differ by a deck transformation).
#[test]
fn query_api_on_genus2() {
    let s = generate::genus(2, 24).unwrap();
    let a = build(&s, Singularity::Auto);
    let m = a.mesh();
    let cone = a.singular_vertices()[0];
    let mut straddling = 0;
    for c in 1..a.n_charts() as u32 {
        let common = (0..m.n_faces() as u32)
            .filter(|&f| a.face_coords(c, f).is_some())
            .count();
        let t = a.transitions_between(c, 0);
        assert_eq!(t.iter().map(|x| x.1).sum::<usize>(), common);
        for &(mo, _, res) in &t {
            assert!(res < 1e-9);
            assert!((mo.rot.norm() - 1.0).abs() < 1e-12);
        }
        if t.len() >= 2 {
            straddling += 1;
        }
    }
    assert!(straddling > 0, "no cut chart straddles the cut");
    // Cut vertices: more than one copy in the central chart.
    let multi = (0..m.n_vertices() as u32)
        .filter(|&v| v != cone)
        .filter(|&v| a.vertex_coords(v).iter().filter(|x| x.0 == 0).count() >= 2)
        .count();
    assert!(multi > 0);
    let interior = (0..m.n_vertices() as u32)
        .find(|&v| a.vertex_coords(v).len() == 1)
        .unwrap();
    let (c, p) = a.vertex_coords(interior)[0];
    let f = m.vertex_faces(interior).next().unwrap();
    let i = m.face(f).iter().position(|&x| x == interior).unwrap();
    let mut bary = [0.0; 3];
    bary[i] = 1.0;
    let hit = a.locate(f, bary).into_iter().find(|x| x.0 == c).unwrap();
    assert!((hit.1[0] - p[0]).hypot(hit.1[1] - p[1]) < 1e-12);
}

mod ricci_meshes;
use ricci_meshes::ricci_meshes;

/// `flip_ring_valence` on its own, after the valence raising and the canonical cut of a
/// generated genus-2 surface (as in the atlas): every vertex within 3 rings of the cone gets
/// valence ≥ 6, every cut-loop edge survives, and the metric is the same cone metric —
/// every old vertex keeps its curvature and every new vertex is flat (to 1e-9), the total
/// area is unchanged (to 1e-12 relative), recomputed from the returned lengths.
#[test]
fn flip_ring_valence_keeps_the_cut_and_the_metric() {
    use ricci::atlas::flip_ring_valence;
    use ricci::cut::{canonical_cut, CutOptions};
    use ricci::metric::refine::Refiner;
    use ricci::metric::total_area;
    let s = generate::genus(2, 20).unwrap();
    let cone = 11u32;
    let mut r = Refiner::new(
        &s.mesh,
        &s.edge_lengths(),
        Geometry::Euclidean,
        Some(&s.positions),
    )
    .unwrap();
    r.raise_valence(cone, 16).unwrap();
    let step2 = r.finish().unwrap();
    let cut = canonical_cut(
        &step2.mesh,
        &IntrinsicMetric::new(Geometry::Euclidean, step2.lengths.to_vec()),
        step2.positions.as_deref(),
        &CutOptions {
            base: Some(cone),
            ..CutOptions::default()
        },
        &mut NoProgress,
    )
    .unwrap();
    let mut on_cut = std::collections::HashSet::new();
    for l in &cut.loops {
        for w in l.vertices.windows(2) {
            on_cut.insert((w[0].min(w[1]), w[0].max(w[1])));
        }
    }
    let before = cut.refined.clone();
    let k0 = curvature(&before.mesh, Geometry::Euclidean, &before.lengths);
    let a0 = total_area(&before.mesh, Geometry::Euclidean, &before.lengths);
    let (after, work) = flip_ring_valence(
        cut.refined.clone(),
        &[(cone, -4.0 * PI)],
        3,
        &on_cut,
        100_000,
    )
    .unwrap();
    assert!(work.flips > 0 && work.complete, "{work:?}");
    let m = &after.mesh;
    for &(a, b) in &on_cut {
        assert!(
            m.halfedge_between(a, b).is_some(),
            "cut edge ({a}, {b}) lost"
        );
    }
    let k1 = curvature(m, Geometry::Euclidean, &after.lengths);
    for (v, &k) in k1.iter().enumerate() {
        let want = k0.get(v).copied().unwrap_or(0.0);
        assert!((k - want).abs() < 1e-9, "vertex {v}: K {want} → {k}");
    }
    let a1 = total_area(m, Geometry::Euclidean, &after.lengths);
    assert!((a1 - a0).abs() < 1e-12 * a0, "area {a0} → {a1}");
    // Valence ≥ 6 within 3 rings, by breadth-first search over the returned mesh.
    let mut d = vec![usize::MAX; m.n_vertices()];
    d[cone as usize] = 0;
    let mut q = std::collections::VecDeque::from([cone]);
    while let Some(v) = q.pop_front() {
        if d[v as usize] >= 1 {
            assert!(
                m.valence(v) >= 6,
                "vertex {v} (ring {}) has valence {}",
                d[v as usize],
                m.valence(v)
            );
        }
        if d[v as usize] < 3 {
            for w in m.vertex_neighbors(v) {
                if d[w as usize] == usize::MAX {
                    d[w as usize] = d[v as usize] + 1;
                    q.push_back(w);
                }
            }
        }
    }
}
