//! The exported Bézier elements of the genus ≥ 2 domain-mesh spline (issue 18): the cells of
//! every strip merged where the spline is one bicubic polynomial. Checked against things
//! computed elsewhere: the faces of the extended T-mesh (from the T-mesh's lines and
//! T-junctions, Li et al. 2012 §3: every element is one face), the spline's own evaluation from its blending functions
//! (`DomainMesh::point`) at points of every cell an element covers, the T-mesh's lines (no
//! element crosses one: the spline is only C² there), the derivatives of neighbouring elements
//! on both sides of every element side, and an extrapolation of one element into its
//! neighbour (two neighbours that are one polynomial would have been merged).

mod ricci_meshes;
mod tspline_cases;

use crate::tspline_domain_mesh::Rng;
use tspline_cases::{genus_two_cases, glued_domain};

use ricci::spline::tspline::bezier_elements::{domain_elements, strip_cells, SAME_POLYNOMIAL};
use ricci::spline::tspline::domain_mesh::DomainMesh;

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

fn norm(a: [f64; 3]) -> f64 {
    dist(a, [0.0; 3])
}

/// Graded meshes whose graded lines end in T-junctions, and a T-spline net on each (random free
/// values expanded by the reduction: G¹ at the zeros, in the T-mesh's spline space).
fn cases() -> Vec<(String, DomainMesh, Vec<[f64; 3]>)> {
    let mut rng = Rng(0x2545f4914f6cdd1d);
    let mut out = Vec::new();
    for (name, s) in genus_two_cases() {
        let (d, g, l) = glued_domain(&s);
        for (k, levels, margin) in [(25.0, 2, 1), (40.0, 3, 2)] {
            let m = DomainMesh::graded(&d, &g, l / k, levels)
                .and_then(|m| m.with_t_junctions(margin))
                .unwrap_or_else(|e| panic!("{name}: {e}"));
            let free: Vec<[f64; 3]> = (0..m.reduction.free)
                .map(|_| [rng.next(), rng.next(), rng.next()])
                .collect();
            let control = m.expand(&free);
            out.push((
                format!("{name} at L/{k}, {levels} levels, margin {margin}"),
                m,
                control,
            ));
        }
    }
    out
}

/// The faces of the extended T-mesh of strip `r` (Li, Zheng, Sederberg, Hughes, Scott 2012
/// §3: every T-junction's line extended ahead until it has crossed two perpendicular edges) as
/// a component number per cell `j * m + i`, computed from the T-mesh's lines alone.
fn extended_t_mesh_faces(mesh: &DomainMesh, r: usize) -> Vec<usize> {
    let rc = &mesh.rects[r];
    let (m, n) = (rc.m, rc.n);
    // vb[i * n + j]: the edge of column line i between rows j and j + 1; hb[j * m + i]: the
    // edge of row line j between columns i and i + 1
    let mut vb: Vec<bool> = (0..=m)
        .flat_map(|i| (0..n).map(move |j| (i, j)))
        .map(|(i, j)| mesh.on_line_v(r, i, j) && mesh.on_line_v(r, i, j + 1))
        .collect();
    let mut hb: Vec<bool> = (0..=n)
        .flat_map(|j| (0..m).map(move |i| (i, j)))
        .map(|(i, j)| mesh.on_line_u(r, i, j) && mesh.on_line_u(r, i + 1, j))
        .collect();
    let (v0, h0) = (vb.clone(), hb.clone());
    let junctions = &mesh.tjunctions.as_ref().unwrap().junctions;
    for &(jr, i, j, along_v) in junctions {
        if jr as usize != r {
            continue;
        }
        let (i, j) = (i as usize, j as usize);
        if along_v {
            // the line of column i ends at row j; ahead is where its edge is missing
            let up = j > 0 && v0[i * n + j - 1];
            let crosses = |jj: usize| (i > 0 && h0[jj * m + i - 1]) || (i < m && h0[jj * m + i]);
            let mut crossed = 0;
            let mut jj = j;
            while crossed < 2 && jj > 0 && jj < n {
                let k = if up { jj } else { jj - 1 };
                vb[i * n + k] = true;
                jj = if up { jj + 1 } else { jj - 1 };
                crossed += crosses(jj) as usize;
            }
        } else {
            let right = i > 0 && h0[j * m + i - 1];
            let crosses = |ii: usize| (j > 0 && v0[ii * n + j - 1]) || (j < n && v0[ii * n + j]);
            let mut crossed = 0;
            let mut ii = i;
            while crossed < 2 && ii > 0 && ii < m {
                let k = if right { ii } else { ii - 1 };
                hb[j * m + k] = true;
                ii = if right { ii + 1 } else { ii - 1 };
                crossed += crosses(ii) as usize;
            }
        }
    }
    // cells joined across every side that is no edge of the extended T-mesh
    let mut parent: Vec<usize> = (0..m * n).collect();
    fn root(p: &mut [usize], mut x: usize) -> usize {
        while p[x] != x {
            p[x] = p[p[x]];
            x = p[x];
        }
        x
    }
    for j in 0..n {
        for i in 0..m {
            if i + 1 < m && !vb[(i + 1) * n + j] {
                let (a, b) = (
                    root(&mut parent, j * m + i),
                    root(&mut parent, j * m + i + 1),
                );
                parent[a] = b;
            }
            if j + 1 < n && !hb[(j + 1) * m + i] {
                let (a, b) = (
                    root(&mut parent, j * m + i),
                    root(&mut parent, (j + 1) * m + i),
                );
                parent[a] = b;
            }
        }
    }
    (0..m * n).map(|c| root(&mut parent, c)).collect()
}

#[test]
fn bezier_elements_are_the_spline_merged_only_inside_t_mesh_faces_and_meet_c2() {
    let mut merged_somewhere = false;
    for (name, m, control) in cases() {
        let (elements, stats) = domain_elements(&m, &control);
        let ids = strip_cells(&m);
        let offsets = m.export_offsets();
        let scale = {
            let mut lo = [f64::INFINITY; 3];
            let mut hi = [f64::NEG_INFINITY; 3];
            for c in &control {
                for d in 0..3 {
                    lo[d] = lo[d].min(c[d]);
                    hi[d] = hi[d].max(c[d]);
                }
            }
            dist(lo, hi)
        };
        eprintln!(
            "{name}: {} cells, {} T-junctions, {} Bézier elements; {stats:?}",
            m.n_cells(),
            m.n_t_junctions(),
            elements.len()
        );
        assert!(m.n_t_junctions() > 0, "{name}: no T-junction to test");
        // every cell in exactly one element
        let mut owner = vec![usize::MAX; m.n_cells()];
        for (e, el) in elements.iter().enumerate() {
            let [i0, i1, j0, j1] = el.cells;
            for j in j0..j1 {
                for i in i0..i1 {
                    let c = ids[el.strip][j * m.rects[el.strip].m + i] as usize;
                    assert_eq!(owner[c], usize::MAX, "{name}: cell {c} in two elements");
                    owner[c] = e;
                }
            }
        }
        assert!(
            owner.iter().all(|&e| e != usize::MAX),
            "{name}: a cell in no element"
        );
        assert_eq!(stats.elements, elements.len());
        assert_eq!(stats.cells, m.n_cells());
        assert!(stats.worst_merged <= SAME_POLYNOMIAL, "{name}: {stats:?}");
        // the T-junctions' lines end inside strips: the cells there are fewer polynomials
        assert!(elements.len() < m.n_cells(), "{name}: nothing merged");
        merged_somewhere = true;

        // the elements are the faces of the extended T-mesh, strip by strip
        let mut faces = 0;
        for r in 0..m.rects.len() {
            let face = extended_t_mesh_faces(&m, r);
            let mut count = std::collections::HashMap::new();
            for f in &face {
                *count.entry(*f).or_insert(0usize) += 1;
            }
            faces += count.len();
            let mr = m.rects[r].m;
            for el in elements.iter().filter(|e| e.strip == r) {
                let [i0, i1, j0, j1] = el.cells;
                let f = face[j0 * mr + i0];
                for j in j0..j1 {
                    for i in i0..i1 {
                        assert_eq!(face[j * mr + i], f, "{name}: element {:?} of strip {r} spans two faces of the extended T-mesh", el.cells);
                    }
                }
                assert_eq!(
                    count[&f],
                    (i1 - i0) * (j1 - j0),
                    "{name}: element {:?} of strip {r} is not a whole face of the extended T-mesh",
                    el.cells
                );
            }
        }
        eprintln!("{name}: {faces} faces of the extended T-mesh");
        assert_eq!(faces, elements.len(), "{name}");

        // every element is the spline (its blending functions) at points of every cell it covers
        let mut worst = 0.0f64;
        for (c, &e) in owner.iter().enumerate() {
            let el = &elements[e];
            let [u0, u1, v0, v1] = m.cell_box(c as u32);
            for (s, t) in [(0.0, 0.0), (0.2, 0.7), (0.9, 0.35), (1.0, 1.0)] {
                let x = m.point(c as u32, s, t, &control);
                let (u, v) = (offsets[el.strip] + u0 + s * (u1 - u0), v0 + t * (v1 - v0));
                worst = worst.max(dist(el.patch.point(u, v), x));
            }
        }
        eprintln!(
            "{name}: elements vs blending functions ≤ {:e} of the size",
            worst / scale
        );
        assert!(worst <= 1e-12 * scale, "{name}: {:e}", worst / scale);

        // no element crosses a line of the T-mesh (an edge between two of its mesh points)
        for el in &elements {
            let r = &m.rects[el.strip];
            let [i0, i1, j0, j1] = el.cells;
            for i in i0 + 1..i1 {
                for j in j0..j1 {
                    let edge = m.on_line_v(el.strip, i, j) && m.on_line_v(el.strip, i, j + 1);
                    assert!(!edge, "{name}: element {:?} of strip {} crosses the T-mesh line x({i}) ({} columns)", el.cells, el.strip, r.m);
                }
            }
            for j in j0 + 1..j1 {
                for i in i0..i1 {
                    let edge = m.on_line_u(el.strip, i, j) && m.on_line_u(el.strip, i + 1, j);
                    assert!(
                        !edge,
                        "{name}: element {:?} of strip {} crosses the T-mesh line y({j})",
                        el.cells, el.strip
                    );
                }
            }
        }

        // neighbouring elements across every cell side between two of them: C⁰ everywhere, C²
        // on sides with no zero at an end; and not one polynomial (else they would be merged)
        let mut jumps = [0.0f64; 3];
        let mut at_zeros = 0.0f64;
        let mut magnitude = [0.0f64; 3];
        let mut closest = f64::INFINITY;
        let mut rng = Rng(7);
        for (c, side, zero) in m.sides() {
            let nb = m.across(c, side);
            let (ea, eb) = (owner[c as usize], owner[nb as usize]);
            if ea == eb {
                continue;
            }
            let (a, b) = (&elements[ea], &elements[eb]);
            let (ba, bb) = (m.cell_box(c), m.cell_box(nb));
            let (oa, ob) = (offsets[a.strip], offsets[b.strip]);
            for t in [0.25, 0.5, 0.75] {
                // the same point of the surface in the two cells' charts (glued by translation)
                let (pa, pb) = if side == 0 {
                    let va = ba[2] + t * (ba[3] - ba[2]);
                    let vb = bb[2] + t * (bb[3] - bb[2]);
                    ((oa + ba[1], va), (ob + bb[0], vb))
                } else {
                    let ua = ba[0] + t * (ba[1] - ba[0]);
                    let ub = bb[0] + t * (bb[1] - bb[0]);
                    ((oa + ua, ba[3]), (ob + ub, bb[2]))
                };
                for order in 0..3 {
                    for i in 0..=order {
                        let x = a.patch.partial(pa.0, pa.1, i, order - i);
                        let y = b.patch.partial(pb.0, pb.1, i, order - i);
                        magnitude[order] = magnitude[order].max(norm(x));
                        if order == 0 || !zero {
                            jumps[order] = jumps[order].max(dist(x, y));
                        }
                        if order == 0 && zero {
                            at_zeros = at_zeros.max(dist(x, y));
                        }
                    }
                }
            }
            // b's polynomial at points of the cell of a, translated into b's chart
            let (du, dv) = if side == 0 {
                (ob + bb[0] - oa - ba[1], bb[2] - ba[2])
            } else {
                (ob + bb[0] - oa - ba[0], bb[2] - ba[3])
            };
            let mut gap = 0.0f64;
            for _ in 0..3 {
                let (s, t) = (rng.next(), rng.next());
                let (u, v) = (
                    oa + ba[0] + s * (ba[1] - ba[0]),
                    ba[2] + t * (ba[3] - ba[2]),
                );
                gap = gap.max(dist(a.patch.point(u, v), b.patch.point(u + du, v + dv)));
            }
            closest = closest.min(gap / scale);
        }
        let rel: Vec<f64> = (0..3).map(|k| jumps[k] / magnitude[k]).collect();
        eprintln!(
            "{name}: element sides: C⁰ jump {:e} (at zeros {:e}), C¹ {:e}, C² {:e} relative; nearest neighbouring polynomials {closest:e}",
            rel[0],
            at_zeros / magnitude[0],
            rel[1],
            rel[2]
        );
        assert!(jumps[0] <= 1e-12 * scale, "{name}: C⁰ {rel:?}");
        assert!(rel[1] <= 1e-10 && rel[2] <= 1e-9, "{name}: {rel:?}");
        assert!(
            closest > 1e-8,
            "{name}: two neighbouring elements are one polynomial ({closest:e})"
        );
    }
    assert!(merged_somewhere);
}

/// Genus 1 (and 0): the exported elements of a T-spline over the flat torus, on analysis-
/// suitable T-meshes with T-junctions, are the faces of the extended T-mesh: per T-mesh face,
/// the rectangles cut by the face extensions that cross it (`TMesh::extensions`, in any
/// lattice translate); and each evaluates as the T-spline at points of its sub-rectangles.
#[test]
fn torus_bezier_elements_are_the_faces_of_the_extended_t_mesh() {
    use ricci::spline::tspline::{extract_elements, Lattice, TBasis, TMesh, TSpline};
    let mut rng = Rng(0x9e3779b97f4a7c15);
    for shift in [0.0, 2.5] {
        let lat = Lattice {
            width: 8.0,
            height: 8.0,
            shift,
        };
        let mut m = TMesh::uniform(lat, 8, 8).unwrap();
        for (u, v, quad) in [
            (3.5, 3.5, true),
            (4.5, 4.5, true),
            (1.5, 6.5, false),
            (6.2, 1.3, true),
        ] {
            let f = m.locate(u, v).unwrap();
            m.refine_face(f, quad);
        }
        m.make_analysis_suitable(1000).unwrap();
        assert!(m.is_analysis_suitable() && !m.t_junctions().is_empty());
        let extensions: Vec<_> = m
            .extensions()
            .into_iter()
            .filter(|e| e.b - e.a > 0.0)
            .collect();
        let faces = m.faces().to_vec();
        let basis = TBasis::new(m).unwrap();
        let control = basis
            .anchors
            .iter()
            .map(|a| {
                let (t, p) = (
                    a.u / 8.0 * std::f64::consts::TAU,
                    a.v / 8.0 * std::f64::consts::TAU,
                );
                let r = 2.0 + 0.7 * p.cos() + 0.1 * rng.next();
                [r * t.cos(), r * t.sin(), 0.7 * p.sin() + 0.1 * rng.next()]
            })
            .collect();
        let ts = TSpline { basis, control };
        // expected: per face, (distinct cuts along u + 1)(distinct cuts along v + 1)
        let mut expected = 0;
        for f in &faces {
            let eps = 1e-9 * (f.u1 - f.u0).min(f.v1 - f.v0);
            let (mut us, mut vs) = (Vec::new(), Vec::new());
            for e in &extensions {
                for k in -2i32..=2 {
                    for l in -2i32..=2 {
                        let (du, dv) = (
                            k as f64 * lat.width + l as f64 * lat.shift,
                            l as f64 * lat.height,
                        );
                        if e.horizontal {
                            let (y, a, b) = (e.at + dv, e.a + du, e.b + du);
                            if y > f.v0 + eps && y < f.v1 - eps && a < f.u1 - eps && b > f.u0 + eps
                            {
                                vs.push(y);
                            }
                        } else {
                            let (x, a, b) = (e.at + du, e.a + dv, e.b + dv);
                            if x > f.u0 + eps && x < f.u1 - eps && a < f.v1 - eps && b > f.v0 + eps
                            {
                                us.push(x);
                            }
                        }
                    }
                }
            }
            for xs in [&mut us, &mut vs] {
                xs.sort_by(f64::total_cmp);
                xs.dedup_by(|a, b| (*a - *b).abs() <= eps);
            }
            expected += (us.len() + 1) * (vs.len() + 1);
        }
        let (patches, stats) = extract_elements(&ts);
        eprintln!(
            "shift {shift}: {} T-mesh faces, {} extensions, {} faces of the extended T-mesh, {} exported elements; {stats:?}",
            faces.len(),
            extensions.len(),
            expected,
            patches.len()
        );
        assert_eq!(patches.len(), expected, "shift {shift}: {stats:?}");
        let mut worst = 0.0f64;
        for p in &patches {
            for (s, t) in [(0.1, 0.2), (0.5, 0.5), (0.93, 0.71)] {
                let (u, v) = (p.u0 + s * (p.u1 - p.u0), p.v0 + t * (p.v1 - p.v0));
                worst = worst.max(dist(p.point(u, v), ts.point(u, v)));
            }
        }
        assert!(worst < 1e-12 * 6.0, "shift {shift}: {worst:e}");
    }
}
