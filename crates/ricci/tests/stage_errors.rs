//! The stage errors carry the vertex, face or edge they are about as data (issue 21): every
//! test builds an input whose fault is known by construction (a face whose lengths violate
//! the triangle inequality, a cone vertex of too low valence for Thurston's packing, a target
//! whose sum is not 2πχ, a base vertex or seed face past the end, a negative length) and
//! matches the enum got back from `ricci::Error` against it. The sentences are the ones the
//! stages always gave (the CLI tests check them); here only that the data agree with them.

use ricci::cut::{canonical_cut, CutError, CutOptions};
use ricci::error::{Error, Kind};
use ricci::flow::{ricci_flow, FlowError, FlowOptions, TargetSpec};
use ricci::layout::{layout, LayoutError};
use ricci::mesh::{generate, Mesh};
use ricci::metric::IntrinsicMetric;
use ricci::metric::{Euclidean, Geometry, MetricError, Scheme};
use ricci::progress::NoProgress;
use std::f64::consts::PI;

/// A unit square split along its diagonal 0–2: faces (0, 1, 2) and (0, 2, 3).
fn square() -> Mesh {
    Mesh::from_triangles(4, vec![[0, 1, 2], [0, 2, 3]]).unwrap()
}

fn edge(mesh: &Mesh, a: u32, b: u32) -> usize {
    mesh.he_edge(mesh.halfedge_between(a, b).unwrap()) as usize
}

#[test]
fn a_degenerate_face_is_named_by_index() {
    let mesh = square();
    let mut lengths = vec![1.0; mesh.n_edges()];
    lengths[edge(&mesh, 0, 2)] = 1.5; // 1 + 1 > 1.5: face 0 is a triangle
    lengths[edge(&mesh, 2, 3)] = 3.0; // 3 ≥ 1.5 + 1: face 1 is not
    let opts = FlowOptions {
        geometry: Geometry::Euclidean,
        scheme: Scheme::Yamabe,
        target: TargetSpec::FreeBoundary,
        ..FlowOptions::default()
    };
    let e = ricci_flow(&mesh, &lengths, &opts, &mut NoProgress).unwrap_err();
    let Some(MetricError::DegenerateFace {
        face,
        vertices,
        lengths: l,
    }) = e.stage_error::<MetricError>()
    else {
        panic!("not a degenerate-face error: {e:?}");
    };
    assert_eq!(*face, 1);
    assert_eq!(*vertices, mesh.face(1));
    let mut sides = *l;
    sides.sort_by(f64::total_cmp);
    assert_eq!(sides, [1.0, 1.5, 3.0]);
    assert_eq!(e.kind(), Some(Kind::InvalidInput));
    assert!(e.to_string().starts_with("face 1 "), "{e}");
}

#[test]
fn a_chow_luo_refusal_names_the_cone_vertex() {
    // All of 2πχ = −4π on one vertex of a genus-2 surface: Thurston's packing needs valence
    // ≥ 4 − 2K̄/π = 12 there (paper 000 eq. 7); take the vertex of least valence.
    let s = generate::genus(2, 24).unwrap();
    let m = &s.mesh;
    let v = (0..m.n_vertices() as u32)
        .filter(|&v| !m.is_isolated(v))
        .min_by_key(|&v| (m.valence(v), v))
        .unwrap();
    assert!(m.valence(v) < 12, "valence {}", m.valence(v));
    let opts = FlowOptions {
        geometry: Geometry::Euclidean,
        scheme: Scheme::Thurston,
        target: TargetSpec::SingleCone(Some(v)),
        ..FlowOptions::default()
    };
    let e = ricci_flow(m, &s.edge_lengths(), &opts, &mut NoProgress).unwrap_err();
    let Some(FlowError::ChowLuo {
        vertex,
        one_ring,
        shortfall,
        ..
    }) = e.stage_error::<FlowError>()
    else {
        panic!("not a Chow–Luo refusal: {e:?}");
    };
    assert_eq!(*vertex, v);
    assert!(!one_ring);
    assert!(*shortfall > 0.0);
    assert!(
        e.to_string().contains(&format!("the single vertex {v} ")),
        "{e}"
    );
    assert_eq!(e.kind(), Some(Kind::InvalidInput));
}

#[test]
fn a_gauss_bonnet_violation_carries_the_sum_and_the_euler_characteristic() {
    // A torus (χ = V − E + F = 0) asked for 0.5 of curvature in all: a flat metric needs 0.
    let s = generate::genus(1, 16).unwrap();
    let m = &s.mesh;
    let chi = m.n_vertices() as i64 - m.n_edges() as i64 + m.n_faces() as i64;
    let mut k = vec![0.0; m.n_vertices()];
    k[0] = 0.5;
    let opts = FlowOptions {
        geometry: Geometry::Euclidean,
        target: TargetSpec::PerVertex(k),
        ..FlowOptions::default()
    };
    let e = ricci_flow(m, &s.edge_lengths(), &opts, &mut NoProgress).unwrap_err();
    let Some(FlowError::GaussBonnet {
        geometry,
        curvature_sum,
        euler_characteristic,
        ..
    }) = e.stage_error::<FlowError>()
    else {
        panic!("not a Gauss–Bonnet violation: {e:?}");
    };
    assert_eq!(*geometry, Geometry::Euclidean);
    assert_eq!(*euler_characteristic, chi);
    assert!((curvature_sum - 0.5).abs() < 1e-15);
    assert!((0.5 - 2.0 * PI * chi as f64).abs() > 0.4);
}

#[test]
fn a_missing_base_vertex_is_named_with_the_vertex_count() {
    let s = generate::genus(1, 16).unwrap();
    let n = s.mesh.n_vertices();
    let options = CutOptions {
        base: Some(n as u32 + 5),
        ..CutOptions::default()
    };
    let e = canonical_cut(
        &s.mesh,
        &IntrinsicMetric::new(Geometry::Euclidean, s.edge_lengths()),
        None,
        &options,
        &mut NoProgress,
    )
    .unwrap_err();
    assert_eq!(
        e.stage_error::<CutError>(),
        Some(&CutError::BaseVertexMissing {
            vertex: n as u32 + 5,
            n_vertices: n,
        })
    );
    assert!(matches!(e, Error::Stage { .. }));
}

#[test]
fn layout_errors_name_the_edge_and_the_seed_face() {
    let mesh = square();
    let mut lengths = vec![1.0; mesh.n_edges()];
    lengths[edge(&mesh, 0, 2)] = 2f64.sqrt();
    let e = layout::<Euclidean>(
        &mesh,
        &IntrinsicMetric::new(ricci::metric::Geometry::Euclidean, lengths.to_vec()),
        Some(7),
    )
    .unwrap_err();
    assert_eq!(
        e.stage_error::<LayoutError>(),
        Some(&LayoutError::SeedFaceMissing {
            face: 7,
            n_faces: 2
        })
    );
    let bad = edge(&mesh, 2, 3);
    lengths[bad] = -1.0;
    let e = layout::<Euclidean>(
        &mesh,
        &IntrinsicMetric::new(ricci::metric::Geometry::Euclidean, lengths.to_vec()),
        None,
    )
    .unwrap_err();
    let Some(LayoutError::InvalidLength {
        edge: got,
        vertices,
        ..
    }) = e.stage_error::<LayoutError>()
    else {
        panic!("not an invalid length: {e:?}");
    };
    assert_eq!(*got as usize, bad);
    let mut vs = *vertices;
    vs.sort();
    assert_eq!(vs, [2, 3]);
    // A stage error is not mistaken for another stage's.
    assert!(e.stage_error::<FlowError>().is_none());
}

/// The atlas's cone checks (Step 1) name the vertex, and carry the sum and χ of a
/// Gauss–Bonnet violation; every expected value comes from the list given or the mesh.
#[test]
fn atlas_errors_name_the_cone_vertex() {
    use ricci::atlas::{AffineAtlas, AtlasError, AtlasOptions, Singularity};
    let s = generate::genus(2, 16).unwrap();
    let m = &s.mesh;
    let n = m.n_vertices();
    let chi = n as i64 - m.n_edges() as i64 + m.n_faces() as i64;
    assert_eq!(chi, -2);
    let kappa = 2.0 * PI * chi as f64;
    let build = |cones: Vec<(u32, f64)>| {
        let options = AtlasOptions {
            cones: Some(cones),
            ..AtlasOptions::default()
        };
        AffineAtlas::build(&s, &options, &mut NoProgress).unwrap_err()
    };
    // A vertex past the end.
    let e = build(vec![(n as u32 + 3, kappa)]);
    assert_eq!(
        e.stage_error::<AtlasError>(),
        Some(&AtlasError::VertexMissing {
            role: "cone",
            vertex: n as u32 + 3,
            n_vertices: n
        })
    );
    assert_eq!(e.kind(), Some(Kind::InvalidInput));
    // A cone angle 2π − 7 < 0.
    let e = build(vec![(4, 7.0), (5, kappa - 7.0)]);
    assert_eq!(
        e.stage_error::<AtlasError>(),
        Some(&AtlasError::NoConeAngle {
            vertex: 4,
            curvature: 7.0
        })
    );
    // Σ K̄ = 1 ≠ 2πχ.
    let e = build(vec![(4, 1.0)]);
    assert_eq!(
        e.stage_error::<AtlasError>(),
        Some(&AtlasError::GaussBonnet {
            sum: 1.0,
            euler_characteristic: chi
        })
    );
    // The same vertex twice (the sum is right).
    let e = build(vec![(9, kappa / 2.0), (9, kappa / 2.0)]);
    assert_eq!(
        e.stage_error::<AtlasError>(),
        Some(&AtlasError::ConeListedTwice { vertex: 9 })
    );
    assert_eq!(e.stage_error::<AtlasError>().unwrap().vertex(), Some(9));
    // A singular vertex on a torus, whose flat metric has none.
    let t = generate::genus(1, 16).unwrap();
    let options = AtlasOptions {
        singularity: Singularity::Vertex(2),
        ..AtlasOptions::default()
    };
    let e = AffineAtlas::build(&t, &options, &mut NoProgress).unwrap_err();
    assert_eq!(
        e.stage_error::<AtlasError>(),
        Some(&AtlasError::SingularVertexNotNeeded {
            vertex: 2,
            genus_one: true
        })
    );
    assert!(e.to_string().contains("genus-1"), "{e}");
    // And on a disk (open surface).
    let d = generate::disk(8).unwrap();
    let e = AffineAtlas::build(&d, &options, &mut NoProgress).unwrap_err();
    assert_eq!(
        e.stage_error::<AtlasError>(),
        Some(&AtlasError::SingularVertexNotNeeded {
            vertex: 2,
            genus_one: false
        })
    );
    assert!(e.stage_error::<FlowError>().is_none());
}

/// The spline's parameter checks carry the parameter given: a degree above the largest
/// supported one, a knot spread outside (0, 0.45], a fairness parameter r ≥ n.
#[test]
fn spline_errors_carry_the_parameter() {
    use ricci::spline::dms::{DmsSpace, Domain, KnotClouds, KnotOptions, MAX_DEGREE};
    use ricci::spline::fit::fairness_constraints;
    use ricci::spline::SplineError;
    let dom = Domain::new(
        vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
        vec![[0, 1, 2], [0, 2, 3]],
    )
    .unwrap();
    let degree = MAX_DEGREE + 3;
    let e = KnotClouds::place(&dom, degree, &KnotOptions::default()).unwrap_err();
    assert_eq!(
        e.stage_error::<SplineError>(),
        Some(&SplineError::DegreeUnsupported {
            spline: "DMS",
            degree,
            min: 1,
            max: MAX_DEGREE
        })
    );
    assert_eq!(e.kind(), Some(Kind::InvalidInput));
    let spread = 0.9;
    let opts = KnotOptions {
        spread,
        ..KnotOptions::default()
    };
    let e = KnotClouds::place(&dom, 3, &opts).unwrap_err();
    assert_eq!(
        e.stage_error::<SplineError>(),
        Some(&SplineError::KnotSpread { spread })
    );
    let space = DmsSpace::with_placed_knots(dom, 3, &KnotOptions::default()).unwrap();
    let e = fairness_constraints(&space, 3).unwrap_err();
    assert_eq!(
        e.stage_error::<SplineError>(),
        Some(&SplineError::FairnessOutOfRange { r: 3, degree: 3 })
    );
    assert!(e.to_string().contains("n − 1 = 2"), "{e}");
}

/// A manifold spline is not defined on the faces around its extraordinary point: evaluating
/// there names the face, which is read off the mesh (a face incident to the cone vertex).
#[test]
fn a_manifold_spline_names_a_face_of_its_hole() {
    use ricci::atlas::FlatCharts;
    use ricci::spline::dms::{KnotOptions, Workspace};
    use ricci::spline::manifold::ManifoldSpace;
    use ricci::spline::surface::{flat_domain, Singularity};
    use ricci::spline::SplineError;
    let s = generate::genus(2, 16).unwrap();
    let m = &s.mesh;
    let v = (0..m.n_vertices() as u32)
        .max_by_key(|&v| (m.valence(v), std::cmp::Reverse(v)))
        .unwrap();
    let dom = flat_domain(&s, Singularity::Vertex(v), &mut NoProgress).unwrap();
    assert_eq!(dom.singular, Some(v));
    let space = ManifoldSpace::new(&dom.charts, 3, &KnotOptions::default()).unwrap();
    let cm = dom.charts.mesh();
    let face = (0..cm.n_faces() as u32)
        .find(|&f| cm.face(f).contains(&v))
        .unwrap();
    let mut ws = Workspace::default();
    let e = space
        .basis_at_bary(face, [1.0 / 3.0; 3], 0, &mut ws)
        .unwrap_err();
    assert_eq!(
        e.stage_error::<SplineError>(),
        Some(&SplineError::FaceInHole { face })
    );
    assert_eq!(e.kind(), Some(Kind::InvalidInput));
}
