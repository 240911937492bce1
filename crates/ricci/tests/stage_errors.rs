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
        &s.edge_lengths(),
        Geometry::Euclidean,
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
    let e = layout::<Euclidean>(&mesh, &lengths, Some(7)).unwrap_err();
    assert_eq!(
        e.stage_error::<LayoutError>(),
        Some(&LayoutError::SeedFaceMissing {
            face: 7,
            n_faces: 2
        })
    );
    let bad = edge(&mesh, 2, 3);
    lengths[bad] = -1.0;
    let e = layout::<Euclidean>(&mesh, &lengths, None).unwrap_err();
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
