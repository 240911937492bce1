//! UVs on the input's own faces (`layout::input_uv`) from the layout of the conformal flow's
//! intrinsic triangulation: every input face positively oriented, and across every seam the
//! two faces' UVs of the shared edge related by an isometry that is a deck transformation
//! (composition of side pairings), with the edge's length the same on both sides.

mod ricci_meshes;

use ricci::layout::input_uv::input_face_uvs;
use ricci::layout::pipeline::{
    cut_disk, cut_disk_polished, polish_uniformization, uniformization_metric,
};
use ricci::layout::{deck_group, layout_dd, DeckGroup, Isometry, Space};
use ricci::mesh::generate::genus;
use ricci::mesh::Surface;
use ricci::metric::IntrinsicMetric;
use ricci::metric::{Euclidean, Geometry, Hyperbolic, Scheme};
use ricci::progress::NoProgress;

/// The deck elements a seam can carry: pairings, inverses, products of two, corner
/// transitions (what a face of the surface can straddle).
fn deck_elements<I: Isometry>(g: &DeckGroup<I>) -> Vec<I> {
    let pairs: Vec<I> = g
        .pairings
        .iter()
        .flat_map(|p| [p.map, p.map.inverse()])
        .collect();
    let mut out = pairs.clone();
    for x in &pairs {
        for y in &pairs {
            out.push(x.compose(y));
        }
    }
    let q: Vec<I> = g.corner_maps.iter().flatten().copied().collect();
    for a in &q {
        for b in &q {
            out.push(a.compose(&b.inverse()));
        }
    }
    out
}

fn check<S: Space>(name: &str, s: &Surface, geometry: Geometry)
where
    S::Iso: Isometry<Point = S::Point>,
{
    let f = uniformization_metric(
        &s.mesh,
        &IntrinsicMetric::euclidean(s.edge_lengths()),
        geometry,
        Scheme::Conformal,
        1e-11,
        &mut NoProgress,
    )
    .unwrap();
    assert!(f.converged, "{name}: flow {:e}", f.max_curvature_error);
    let work = &f.triangulation.as_ref().expect("intrinsic").simplicial.mesh;
    let bordered = s.mesh.has_boundary();
    let (positions, origin, group) = if bordered {
        let l = layout_dd::<S>(work, &f.metric(), None).unwrap();
        assert!(l.flipped_faces.is_empty());
        (l.positions, (0..work.n_vertices() as u32).collect(), None)
    } else {
        // H²: the metric polished to double-double first, as `ricci layout` does (the two
        // sides of a seam are laid out along different paths; in double precision they
        // disagree by the flow's residual times sinh of the distance from the seed).
        let d = if geometry == Geometry::Hyperbolic {
            let p =
                polish_uniformization(&s.mesh, &IntrinsicMetric::euclidean(s.edge_lengths()), &f)
                    .unwrap();
            cut_disk_polished(work, &p.metric, None, None, &mut NoProgress).unwrap()
        } else {
            cut_disk(
                work,
                &IntrinsicMetric::new(geometry, f.lengths.to_vec()),
                None,
                None,
                &mut NoProgress,
            )
            .unwrap()
        };
        let l = layout_dd::<S>(&d.mesh, &d.metric, None).unwrap();
        assert!(l.flipped_faces.is_empty(), "{name}: intrinsic layout");
        let g = deck_group::<S>(&l, &d.polygon).unwrap();
        (l.positions, d.vertex_origin.clone(), Some(g))
    };
    let u = input_face_uvs::<S>(&s.mesh, &positions, &origin, group.as_ref()).unwrap();
    assert!(
        u.flipped_faces.is_empty(),
        "{name}: {} input faces flipped in UV (e.g. {:?})",
        u.flipped_faces.len(),
        &u.flipped_faces[..u.flipped_faces.len().min(5)]
    );
    // Seams: the same input edge seen from its two faces.
    let m = &s.mesh;
    let elements = group.as_ref().map(deck_elements).unwrap_or_default();
    let (mut seams, mut worst_len, mut worst_map) = (0, 0.0f64, 0.0f64);
    for e in 0..m.n_edges() as u32 {
        if m.is_boundary_edge(e) {
            continue;
        }
        let h = m.edge_halfedge(e);
        let t = m.he_twin(h);
        let uv = |h: u32| {
            let (f, i) = (h as usize / 3, h as usize % 3);
            (u.corner[3 * f + i], u.corner[3 * f + (i + 1) % 3])
        };
        let (a0, b0) = uv(h); // a → b in the face of h
        let (b1, a1) = uv(t); // b → a in the twin's face
        if S::distance(a0, a1) + S::distance(b0, b1) <= 1e-9 {
            continue;
        }
        seams += 1;
        // Same length on both sides, and the map between them is a deck element — measured
        // in units of the rounding of the double-precision UVs there: a point of the
        // Poincaré disk at distance r from the centre is stored to ~1e-16·2cosh²(r/2).
        let ulp = |p: S::Point| {
            if geometry == Geometry::Hyperbolic {
                let r = S::distance(S::base_point(), p);
                1e-16 * 2.0 * (0.5 * r).cosh().powi(2)
            } else {
                1e-16 * (1.0 + S::distance(S::base_point(), p))
            }
        };
        let unit = ulp(a0).max(ulp(b0)).max(ulp(a1)).max(ulp(b1));
        let (l0, l1) = (S::distance(a0, b0), S::distance(a1, b1));
        worst_len = worst_len.max((l0 - l1).abs() / unit);
        let best = elements
            .iter()
            .map(|g| S::distance(g.apply(a1), a0) + S::distance(g.apply(b1), b0))
            .fold(f64::INFINITY, f64::min);
        worst_map = worst_map.max(best / unit);
    }
    assert!(
        (seams > 0) != bordered,
        "{name}: {seams} seam edges on a {} surface",
        if bordered { "bordered" } else { "closed" }
    );
    // In units of the UVs' own rounding (see above); 1e5 units = 1e-11 relative near the
    // centre.
    assert!(
        worst_len <= 1e5,
        "{name}: seam edge lengths differ by {worst_len:.3e} rounding units"
    );
    assert!(
        worst_map <= 1e5,
        "{name}: a seam's two sides are not related by a deck transformation \
         ({worst_map:.3e} rounding units)"
    );
    eprintln!(
        "{name}: {} faces, {seams} seam edges, {} faces mapped across seams, length mismatch \
         {worst_len:.1e}, deck mismatch {worst_map:.1e} (rounding units)",
        m.n_faces(),
        u.seam_faces
    );
}

#[test]
fn generated_genus_2_surface_gets_uvs_on_its_own_faces() {
    let s = genus(2, 24).unwrap();
    check::<Hyperbolic>("genus2:24", &s, Geometry::Hyperbolic);
}

#[test]
fn shared_meshes_get_uvs_on_their_own_faces() {
    let Some(dir) = ricci_meshes::ricci_meshes().filter(|d| d.is_dir()) else {
        eprintln!("RICCI_MESHES not set; skipped");
        return;
    };
    let read = |n: &str| ricci::mesh::io::read_surface(&dir.join(n)).unwrap().0;
    check::<Hyperbolic>("eight", &read("eight.off"), Geometry::Hyperbolic);
    check::<Hyperbolic>("3holes", &read("3holes.off"), Geometry::Hyperbolic);
    check::<Hyperbolic>("genus3", &read("genus3.off"), Geometry::Hyperbolic);
    check::<Euclidean>("kitten", &read("kitten.nf20k.off"), Geometry::Euclidean);
    check::<Euclidean>("rocker-arm", &read("rocker-arm.off"), Geometry::Euclidean);
    check::<Euclidean>("face", &read("face.off"), Geometry::Euclidean);
    check::<Euclidean>("camelhead", &read("camelhead.off"), Geometry::Euclidean);
}
