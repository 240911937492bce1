//! `layout::input_uv::face_uvs_with_lengths` ranks deck images by a cheap distance key and
//! skips maps by their displacement bound (perf12). Its results must be those of the
//! exhaustive search it replaced — every copy, every candidate map, `Space::distance` — which
//! is written out here as the reference: the same corners (bit for bit), sources, seam-face
//! counts and flipped faces, with and without side lengths, on hyperbolic and flat layouts.

mod ricci_meshes;

use ricci::layout::input_uv::{candidate_maps, face_uvs_with_lengths, InputUvs};
use ricci::layout::pipeline::{
    cut_disk, cut_disk_polished, polish_uniformization, uniformization_metric,
};
use ricci::layout::{deck_group, layout_dd, DeckGroup, Isometry, Space};
use ricci::mesh::generate::genus;
use ricci::mesh::Surface;
use ricci::metric::{Euclidean, Geometry, Hyperbolic, IntrinsicMetric, Scheme};
use ricci::progress::NoProgress;

type Found<P> = (f64, P, (u32, u32));
/// Corners, sources and seam-face count of a search.
type Uvs<P> = (Vec<P>, Vec<(u32, u32)>, usize);
/// A face's mismatch, corners and sources.
type Choice<P> = (f64, [P; 3], [(u32, u32); 3]);

/// The search before perf12: every copy of `w`, every one of the first `n` maps.
fn nearest<S: Space>(
    copies: &[Vec<u32>],
    positions: &[S::Point],
    cands: &[S::Iso],
    w: u32,
    p: S::Point,
    n: usize,
) -> Found<S::Point>
where
    S::Iso: Isometry<Point = S::Point>,
{
    let mut best = (f64::INFINITY, p, (u32::MAX, 0));
    for &c in &copies[w as usize] {
        let q = positions[c as usize];
        for (k, g) in cands[..n].iter().enumerate() {
            let gq = g.apply(q);
            let d = S::distance(gq, p);
            if d < best.0 {
                best = (d, gq, (c, k as u32));
            }
        }
    }
    best
}

fn matching<S: Space>(
    copies: &[Vec<u32>],
    positions: &[S::Point],
    cands: &[S::Iso],
    w: u32,
    p: S::Point,
    want: f64,
) -> Vec<Found<S::Point>>
where
    S::Iso: Isometry<Point = S::Point>,
{
    let mut v = Vec::new();
    for &c in &copies[w as usize] {
        let q = positions[c as usize];
        for (k, g) in cands.iter().enumerate() {
            let gq = g.apply(q);
            v.push(((S::distance(gq, p) - want).abs(), gq, (c, k as u32)));
        }
    }
    v.sort_by(|a, b| a.0.total_cmp(&b.0));
    v.truncate(6);
    v
}

/// `face_uvs_with_lengths` as it was before perf12 (same levels, thresholds and order).
fn reference<S: Space>(
    faces: &[[u32; 3]],
    side_lengths: Option<&[[f64; 3]]>,
    positions: &[S::Point],
    origin: &[u32],
    group: Option<&DeckGroup<S::Iso>>,
    nv: usize,
) -> Uvs<S::Point>
where
    S::Iso: Isometry<Point = S::Point>,
{
    let mut copies: Vec<Vec<u32>> = vec![Vec::new(); nv];
    for (c, &v) in origin.iter().enumerate() {
        if (v as usize) < nv {
            copies[v as usize].push(c as u32);
        }
    }
    let (cands, level_end) = candidate_maps(group);
    let near = |w, p, n| nearest::<S>(&copies, positions, &cands, w, p, n);
    let (mut spread, mut corner, mut source) = (Vec::new(), Vec::new(), Vec::new());
    for t in faces {
        let ca = copies[t[0] as usize][0];
        let pa = positions[ca as usize];
        let (db, pb, sb) = near(t[1], pa, 1);
        let (dc, pc, sc) = near(t[2], pa, 1);
        spread.push(db.max(dc).max(S::distance(pb, pc)));
        corner.extend([pa, pb, pc]);
        source.extend([(ca, 0), sb, sc]);
    }
    let mut sorted: Vec<f64> = spread.iter().copied().filter(|x| x.is_finite()).collect();
    sorted.sort_by(f64::total_cmp);
    let median = sorted.get(sorted.len() / 2).copied().unwrap_or(0.0);
    let mut seam_faces = 0;
    for (f, t) in faces.iter().enumerate() {
        let orient = S::orientation(corner[3 * f], corner[3 * f + 1], corner[3 * f + 2]);
        if !(spread[f] > 4.0 * median || orient <= 0.0) || group.is_none() {
            continue;
        }
        let mut best = (
            f64::INFINITY,
            [corner[3 * f], corner[3 * f + 1], corner[3 * f + 2]],
            [source[3 * f], source[3 * f + 1], source[3 * f + 2]],
        );
        for &n in &level_end[1..] {
            for &ca in &copies[t[0] as usize] {
                let pa = positions[ca as usize];
                let (db, pb, sb) = near(t[1], pa, n);
                let (dc, pc, sc) = near(t[2], pa, n);
                let total = db.max(dc).max(S::distance(pb, pc));
                if total < best.0 {
                    best = (total, [pa, pb, pc], [(ca, 0), sb, sc]);
                }
            }
            let [pa, pb, pc] = best.1;
            if best.0 <= 4.0 * median && S::orientation(pa, pb, pc) > 0.0 {
                break;
            }
        }
        if best.0 < spread[f] {
            seam_faces += 1;
            corner[3 * f..3 * f + 3].copy_from_slice(&best.1);
            source[3 * f..3 * f + 3].copy_from_slice(&best.2);
        }
    }
    let (Some(lengths), Some(_)) = (side_lengths, group) else {
        return (corner, source, seam_faces);
    };
    let mismatch = |p: [S::Point; 3], l: [f64; 3]| {
        (S::distance(p[0], p[1]) - l[0])
            .abs()
            .max((S::distance(p[1], p[2]) - l[1]).abs())
            .max((S::distance(p[2], p[0]) - l[2]).abs())
    };
    for (f, t) in faces.iter().enumerate() {
        let l = lengths[f];
        let now = [corner[3 * f], corner[3 * f + 1], corner[3 * f + 2]];
        let m0 = mismatch(now, l);
        if S::orientation(now[0], now[1], now[2]) > 0.0 && m0 <= 1e-6 * l[0].max(l[1]).max(l[2]) {
            continue;
        }
        let mut best: Option<Choice<S::Point>> = None;
        for &ca in &copies[t[0] as usize] {
            let pa = positions[ca as usize];
            let bs = matching::<S>(&copies, positions, &cands, t[1], pa, l[0]);
            let cs = matching::<S>(&copies, positions, &cands, t[2], pa, l[2]);
            for &(_, pb, sb) in &bs {
                for &(_, pc, sc) in &cs {
                    if S::orientation(pa, pb, pc) <= 0.0 {
                        continue;
                    }
                    let m = mismatch([pa, pb, pc], l);
                    if best.as_ref().is_none_or(|b| m < b.0) {
                        best = Some((m, [pa, pb, pc], [(ca, 0), sb, sc]));
                    }
                }
            }
        }
        if let Some((m, p, src)) = best {
            if m < m0 || S::orientation(now[0], now[1], now[2]) <= 0.0 {
                corner[3 * f..3 * f + 3].copy_from_slice(&p);
                source[3 * f..3 * f + 3].copy_from_slice(&src);
                seam_faces += 1;
            }
        }
    }
    (corner, source, seam_faces)
}

fn same<S: Space>(name: &str, got: &InputUvs<S::Point>, want: &Uvs<S::Point>)
where
    S::Point: PartialEq,
{
    assert_eq!(got.source, want.1, "{name}: sources differ");
    assert!(got.corner == want.0, "{name}: corners differ");
    assert_eq!(got.seam_faces, want.2, "{name}: seam faces differ");
}

fn check<S: Space>(name: &str, s: &Surface, geometry: Geometry)
where
    S::Iso: Isometry<Point = S::Point>,
    S::Point: PartialEq,
{
    let input = IntrinsicMetric::euclidean(s.edge_lengths());
    let f = uniformization_metric(
        &s.mesh,
        &input,
        geometry,
        Scheme::Conformal,
        1e-11,
        &mut NoProgress,
    )
    .unwrap();
    assert!(f.converged, "{name}: flow {:e}", f.max_curvature_error);
    let work = &f.triangulation.as_ref().expect("intrinsic").simplicial.mesh;
    let d = if geometry == Geometry::Hyperbolic {
        let p = polish_uniformization(&s.mesh, &input, &f).unwrap();
        cut_disk_polished(work, &p.metric, None, None, &mut NoProgress).unwrap()
    } else {
        let m = IntrinsicMetric::new(geometry, f.lengths.to_vec());
        cut_disk(work, &m, None, None, &mut NoProgress).unwrap()
    };
    let l = layout_dd::<S>(&d.mesh, &d.metric, None).unwrap();
    let g = deck_group::<S>(&l, &d.polygon).unwrap();
    let (positions, origin) = (&l.positions, &d.vertex_origin);
    let nv = s.mesh.n_vertices();
    let used = vec![true; nv];
    let faces = s.mesh.faces();
    let plain =
        face_uvs_with_lengths::<S>(&used, faces, None, positions, origin, Some(&g)).unwrap();
    same::<S>(
        name,
        &plain,
        &reference::<S>(faces, None, positions, origin, Some(&g), nv),
    );
    // Side lengths 0.1 % off the first images' (every face searched for matching lengths),
    // and those of the faces' nearest images (faces straddling seams searched).
    for scale in [1.001, 1.0] {
        let lengths: Vec<[f64; 3]> = (0..faces.len())
            .map(|f| {
                let c = &plain.corner[3 * f..3 * f + 3];
                [0, 1, 2].map(|i| scale * S::distance(c[i], c[(i + 1) % 3]))
            })
            .collect();
        let got =
            face_uvs_with_lengths::<S>(&used, faces, Some(&lengths), positions, origin, Some(&g))
                .unwrap();
        let want = reference::<S>(faces, Some(&lengths), positions, origin, Some(&g), nv);
        same::<S>(&format!("{name} (lengths × {scale})"), &got, &want);
        eprintln!(
            "{name} × {scale}: {} faces, {} seam faces",
            faces.len(),
            got.seam_faces
        );
    }
}

#[test]
fn pruned_image_search_equals_the_exhaustive_one_on_a_generated_genus_2_surface() {
    let s = genus(2, 24).unwrap();
    check::<Hyperbolic>("genus2:24", &s, Geometry::Hyperbolic);
}

#[test]
fn pruned_image_search_equals_the_exhaustive_one_on_shared_meshes() {
    let Some(dir) = ricci_meshes::ricci_meshes().filter(|d| d.is_dir()) else {
        eprintln!("RICCI_MESHES not set; skipped");
        return;
    };
    let read = |n: &str| ricci::mesh::io::read_surface(&dir.join(n)).unwrap().0;
    check::<Hyperbolic>("eight", &read("eight.off"), Geometry::Hyperbolic);
    check::<Hyperbolic>("genus3", &read("genus3.off"), Geometry::Hyperbolic);
    check::<Euclidean>("kitten", &read("kitten.nf20k.off"), Geometry::Euclidean);
}
