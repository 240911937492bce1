//! The geodesic spectrum of a closed hyperbolic surface from its own triangulation
//! ([`surface_spectrum`]): the search over a compact fundamental domain grown by hyperbolic
//! distance, with a cover by balls to drop tiles (the parent module [`super`] states the
//! method and why it is complete).

use super::*;

/// What [`surface_spectrum`] did besides the lengths.
#[derive(Debug, Clone)]
pub struct CompactDomain {
    /// Radius of the compact fundamental domain around its centre (the bound of the search
    /// is `L + 2·radius`).
    pub radius: f64,
    /// Faces of the domain and edges on its boundary (each edge twice).
    pub faces: usize,
    pub boundary_edges: usize,
    /// Distinct side pairings of the domain (a generating set of the deck group).
    pub generators: usize,
    /// Balls covering the domain (the tile test of the search).
    pub balls: usize,
    /// Wall seconds of the two parts: the domain (growth, slicing, double-double layout, side
    /// pairings, ball cover) and the search (tiles and classes, all rounds).
    pub seconds_domain: f64,
    pub seconds_search: f64,
    /// The vertex the domain grows from; its copy in the seed face is the origin of the disk
    /// and `radius` is measured from it.
    pub centre: u32,
    /// The developed domain in the Poincaré disk (rounded from double-double): its points,
    /// the mesh vertex each point is a copy of, and its triangles (indices into `points`).
    pub points: Vec<[f64; 2]>,
    pub point_vertex: Vec<u32>,
    pub triangles: Vec<[u32; 3]>,
}

/// A two-level cover of a fundamental domain `F` by hyperbolic balls, for the conservative
/// test `d(F, gF) ≤ L ⇒ ∃ a, b: d(c_a, g c_b) ≤ L + r_a + r_b`. Coarse balls `B(C_J, R_J)`
/// (radius about 1) each hold a set of the domain's triangles, and fine balls (radius about
/// [`BallCover::FINE`]) cover the triangles of their coarse ball: a pair of fine balls is
/// tried only when its coarse pair passes. The fine pairs shrink the slack of the test from
/// `R_J + R_K ≈ 2` to `r_a + r_b ≈ 0.7`, so far fewer tiles are kept (their number grows like
/// `e^{L + slack}`); the coarse pairs keep the test cheap.
struct BallCover {
    /// Coarse balls: (centre on the hyperboloid, centre in the disk, radius).
    balls: Vec<([f64; 3], Complex, f64)>,
    /// `(cosh R_J, sinh R_J)` of the coarse balls.
    coarse_cs: Vec<(f64, f64)>,
    /// Fine balls of each coarse ball: (centre on the hyperboloid, radius).
    fine: Vec<Vec<([f64; 3], f64)>>,
    /// `(cosh r_a, sinh r_a)` of the fine balls.
    fine_cs: Vec<Vec<(f64, f64)>>,
    /// The coarse ball of each triangle.
    face_ball: Vec<usize>,
    /// Largest distance from the domain's centre to one of its points.
    radius: f64,
    centre: [f64; 3],
}

/// Thresholds of [`BallCover::may_be_within`] for one length bound, in cosh form.
struct CoverLimits {
    /// cosh(L + R_J + R_K), widened, row-major.
    pair: Vec<f64>,
    /// cosh(L + R_J + radius), widened: a ball farther than this from g o cannot be near gF.
    reach: Vec<f64>,
    /// `(cosh(L + r_a), sinh(L + r_a))` of the fine balls: `cosh(L + r_a + r_b)` is
    /// `cosh(L + r_a) cosh r_b + sinh(L + r_a) sinh r_b`.
    fine_l: Vec<Vec<(f64, f64)>>,
}

/// cosh of the hyperbolic distance between two hyperboloid points (at least 1).
fn cosh_dist(x: &[f64; 3], y: &[f64; 3]) -> f64 {
    (x[2] * y[2] - x[0] * y[0] - x[1] * y[1]).max(1.0)
}

/// Greedy farthest-point centres for the points `pts` (hyperboloid), starting from `first`
/// and adding the farthest point until every point is within `target` (cosh of the radius)
/// of a centre or `max` centres are chosen; also each point's nearest centre (cosh of the
/// distance, index).
fn farthest_points(
    pts: &[[f64; 3]],
    first: [f64; 3],
    target: f64,
    max: usize,
) -> (Vec<[f64; 3]>, Vec<(f64, usize)>) {
    let mut near: Vec<(f64, usize)> = pts.iter().map(|x| (cosh_dist(x, &first), 0)).collect();
    let mut centres = vec![first];
    while centres.len() < max {
        let (far, &(worst, _)) = near
            .iter()
            .enumerate()
            .max_by(|a, b| a.1 .0.total_cmp(&b.1 .0))
            .unwrap_or((0, &(1.0, 0)));
        if worst <= target {
            break;
        }
        let c = pts[far];
        let k = centres.len();
        centres.push(c);
        for (x, n) in pts.iter().zip(near.iter_mut()) {
            let d = cosh_dist(x, &c);
            if d < n.0 {
                *n = (d, k);
            }
        }
    }
    (centres, near)
}

/// Each triangle (corner indices into `pts`) given to the centre, among the nearest ones of
/// its corners, that holds its three corners within the smallest distance; returns cosh of
/// each centre's radius (at least each point's distance to its nearest centre). Hyperbolic
/// balls are convex and a geodesic triangle is the convex hull of its corners, so each
/// triangle lies in its centre's ball.
fn ball_radii(
    pts: &[[f64; 3]],
    tris: &[[usize; 3]],
    centres: &[[f64; 3]],
    near: &[(f64, usize)],
    owner: &mut Vec<usize>,
) -> Vec<f64> {
    let mut rad = vec![1.0f64; centres.len()];
    for n in near {
        rad[n.1] = rad[n.1].max(n.0);
    }
    owner.clear();
    for t in tris {
        let (k, need) = t
            .iter()
            .map(|&v| {
                let k = near[v].1;
                let need = t
                    .iter()
                    .map(|&w| cosh_dist(&pts[w], &centres[k]))
                    .fold(1.0, f64::max);
                (k, need)
            })
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap_or((0, 1.0));
        rad[k] = rad[k].max(need);
        owner.push(k);
    }
    rad
}

impl BallCover {
    /// Radius (about) of the fine balls.
    const FINE: f64 = 0.35;

    /// The cover of a triangulated domain (vertices `points`, geodesic triangles `faces`)
    /// around `centre`: coarse balls of radius about `r` (at most `max_balls`; the radius
    /// grows when the budget is reached), fine balls of radius about [`Self::FINE`] (at most
    /// 64 per coarse ball). No radius is padded: triangles lie in their balls (see
    /// [`ball_radii`]), and the domain in the ball of radius `radius` around `centre`.
    fn of_domain(
        points: &[Complex],
        faces: &[[u32; 3]],
        centre: Complex,
        r: f64,
        max_balls: usize,
    ) -> Self {
        let h: Vec<[f64; 3]> = points.iter().map(|&p| poincare_to_hyperboloid(p)).collect();
        let c0 = poincare_to_hyperboloid(centre);
        let radius = h
            .iter()
            .map(|x| cosh_dist(x, &c0))
            .fold(1.0, f64::max)
            .acosh();
        let tris: Vec<[usize; 3]> = faces.iter().map(|f| f.map(|v| v as usize)).collect();
        let (centres, near) = farthest_points(&h, c0, r.cosh(), max_balls);
        let mut owner = Vec::new();
        let rad = ball_radii(&h, &tris, &centres, &near, &mut owner);
        // Fine balls per coarse ball, over the corners of its triangles.
        let mut local = vec![usize::MAX; h.len()];
        let mut fine = Vec::with_capacity(centres.len());
        let mut fine_owner = Vec::new();
        let mut by_owner: Vec<Vec<usize>> = vec![Vec::new(); centres.len()];
        for (t, &k) in owner.iter().enumerate() {
            by_owner[k].push(t);
        }
        for (&ck, mine) in centres.iter().zip(&by_owner) {
            let mut pts: Vec<[f64; 3]> = Vec::new();
            let mut ids: Vec<usize> = Vec::new();
            let mut own: Vec<[usize; 3]> = Vec::new();
            for t in mine.iter().map(|&t| &tris[t]) {
                own.push(t.map(|v| {
                    if local[v] == usize::MAX {
                        local[v] = pts.len();
                        pts.push(h[v]);
                        ids.push(v);
                    }
                    local[v]
                }));
            }
            for &v in &ids {
                local[v] = usize::MAX;
            }
            let (fc, fnear) = farthest_points(&pts, ck, Self::FINE.cosh(), 64);
            let frad = ball_radii(&pts, &own, &fc, &fnear, &mut fine_owner);
            fine.push(
                fc.into_iter()
                    .zip(frad)
                    .map(|(c, rc)| (c, rc.acosh()))
                    .collect::<Vec<_>>(),
            );
        }
        let disk = |x: &[f64; 3]| Complex::new(x[0], x[1]) / (1.0 + x[2]);
        let balls: Vec<([f64; 3], Complex, f64)> = centres
            .iter()
            .zip(rad)
            .map(|(c, rc)| (*c, disk(c), rc.acosh()))
            .collect();
        let cs = |r: f64| (r.cosh(), r.sinh());
        BallCover {
            coarse_cs: balls.iter().map(|b| cs(b.2)).collect(),
            fine_cs: fine
                .iter()
                .map(|f: &Vec<([f64; 3], f64)>| f.iter().map(|b| cs(b.1)).collect())
                .collect(),
            balls,
            fine,
            face_ball: owner,
            radius,
            centre: c0,
        }
    }

    fn limits(&self, l: f64, radius: f64) -> CoverLimits {
        // Widened by a relative 1e-9 so that rounding can only keep a tile more.
        let widen = |x: f64| x.cosh() * (1.0 + 1e-9) + 1e-9;
        let n = self.balls.len();
        CoverLimits {
            pair: (0..n * n)
                .map(|i| widen(l + self.balls[i / n].2 + self.balls[i % n].2))
                .collect(),
            reach: self.balls.iter().map(|b| widen(l + b.2 + radius)).collect(),
            fine_l: self
                .fine
                .iter()
                .map(|f| {
                    f.iter()
                        .map(|b| ((l + b.1).cosh(), (l + b.1).sinh()))
                        .collect()
                })
                .collect(),
        }
    }

    /// False only if `d(F, gF) > L` is certain: no pair of fine balls `a` (in coarse ball
    /// `J`), `b` (in `K`) with `d(C_J, g o) ≤ L + R_J + radius`, `d(C_J, g C_K) ≤ L + R_J +
    /// R_K`, `d(c_a, g C_K) ≤ L + r_a + R_K` and `d(c_a, g c_b) ≤ L + r_a + r_b` (each
    /// necessary for a point of ball `a` within `L` of a point of `g` ball `b`).
    fn may_be_within(&self, g: &Mobius, go: [f64; 3], lim: &CoverLimits) -> bool {
        let widen = |x: f64| x * (1.0 + 1e-9) + 1e-9;
        let k = g.klein_matrix();
        let n = self.balls.len();
        let mut moved: Vec<Option<[f64; 3]>> = vec![None; n];
        let mut moved_fine: Vec<Vec<[f64; 3]>> = vec![Vec::new(); n];
        for (j, bj) in self.balls.iter().enumerate() {
            if cosh_dist(&bj.0, &go) > lim.reach[j] {
                continue;
            }
            let row = &lim.pair[j * n..(j + 1) * n];
            for (kk, bk) in self.balls.iter().enumerate() {
                let gk = *moved[kk].get_or_insert_with(|| apply_h(&k, bk.0));
                if cosh_dist(&bj.0, &gk) > row[kk] {
                    continue;
                }
                if moved_fine[kk].is_empty() {
                    moved_fine[kk] = self.fine[kk].iter().map(|b| apply_h(&k, b.0)).collect();
                }
                let (ch, sh) = self.coarse_cs[kk];
                for (fa, &(cl, sl)) in self.fine[j].iter().zip(&lim.fine_l[j]) {
                    if cosh_dist(&fa.0, &gk) > widen(cl * ch + sl * sh) {
                        continue;
                    }
                    for (gb, &(chb, shb)) in moved_fine[kk].iter().zip(&self.fine_cs[kk]) {
                        if cosh_dist(&fa.0, gb) <= widen(cl * chb + sl * shb) {
                            return true;
                        }
                    }
                }
            }
        }
        false
    }

    /// The sides of the domain's boundary `bnd` that the axis (the real diameter in the
    /// frame `fr`) crosses or touches, as [`super::sides_crossed`] over the whole boundary,
    /// testing only the boundary edges (`edges`: per coarse ball, those of its triangles) of
    /// the balls within 0.01 of the axis: an edge that crosses the axis has its crossing point
    /// in its ball, and one that touches it within the tolerance `1e-8` (in the frame's disk,
    /// hyperbolic ≤ 1e-3 for the points of candidates' frames) is within 0.01 of it.
    fn sides_crossed(
        &self,
        fr: &Mobius,
        bnd: &[(Complex, usize)],
        edges: &[Vec<usize>],
    ) -> Vec<usize> {
        let mut near: Vec<usize> = self
            .balls
            .iter()
            .zip(edges)
            .filter(|(b, _)| {
                let w = fr.apply(b.1);
                let sinh_d = 2.0 * w.im.abs() / (1.0 - w.norm_sqr()).max(1e-300);
                sinh_d.asinh() <= b.2 * (1.0 + 1e-9) + 0.01
            })
            .flat_map(|(_, es)| es.iter().copied())
            .collect();
        near.sort_unstable();
        sides_crossed(fr, bnd, near, 1e-8)
    }
}

/// Length spectrum of a closed hyperbolic surface given by a triangulation with a hyperbolic
/// metric (`metric`, H², with or without double-double low parts, curvature 0 at every
/// vertex; `centre`: the vertex the domain grows from, default a central one), through a **compact fundamental domain** instead of the canonical polygon.
///
/// The domain `F` is the development of the surface along a spanning tree of the dual graph
/// grown in the order of the hyperbolic distance of each face's developed copy from a central
/// vertex (Prim on faces, developed in double precision for the order): the
/// surface is sliced along the edges the tree does not cross (a disk) and laid out in
/// double-double with the central face at the centre. Its side pairings (one per sliced
/// edge, deduplicated) generate the deck group. Because the faces were added nearest first,
/// `F` stays within about the surface's radius of its centre `o` (`radius`, measured on the
/// layout: the largest distance from `o` to a vertex of `F`; faces are geodesic triangles, so
/// `F ⊂ B(o, radius)`), whereas the canonical polygon of a genus-4 or genus-5 mesh reaches 12
/// or more, which made the search of [`fuchsian_spectrum`] visit millions of tiles.
///
/// Completeness (the argument of the module docs with this `F`): every class of length
/// `ℓ ≤ L` has a conjugate `γ` whose axis meets `F`; then `d(o, γo) ≤ ℓ + 2·radius`. The
/// tiles `gF` at distance ≤ L from `F` are connected under side adjacency, and all of them
/// satisfy `d(o, go) ≤ L + 2·radius`, so a breadth-first search through the side pairings
/// that keeps the tiles with `d(o, go) ≤ L + 2·radius` (widened by 1e-9 relative) finds every
/// such `γ`. Tiles are also dropped when a cover of `F` by balls `B(c_j, r_j)` of radius
/// about 1 proves `d(F, gF) > L` (`d(c_j, g c_k) > L + r_j + r_k` for all pairs), and words
/// are composed in double-double (the side pairings move `o` by up to `2·radius`; double
/// products lost the 1e-7 that tells two tiles apart). Classes are formed as in [`fuchsian_spectrum`] (the pieces of one closed geodesic
/// are linked through the sides its axis crosses). `L` starts at the shortest side pairing's
/// translation length; while fewer than `count` classes are complete it grows to the
/// `count`-th distinct length among the candidates up to `1.25 L` (certain to be enough: each
/// distinct length is a class), or to `1.25 L`. The search is grown, not redone: tiles kept
/// under a bound are kept under a larger one, and only the rejected tiles are tested again
/// (so the rounds cost about as much as the last one alone).
///
/// What the result proves: every free homotopy class of closed geodesics of length
/// `≤ complete_up_to` (= the final `L`) is among the classes found, because every tile `γF`
/// with `d(F, γF) ≤ L` was kept (the tests only drop tiles with `d(o, γo) > L + 2·radius` or
/// `d(c_j, γ c_k) > L + r_j + r_k` for all pairs of balls, each implying `d(F, γF) > L`), and
/// the kept tiles are connected to `F`; the `count` returned are the shortest of them.
///
/// Budgets: at most `max_tiles` tiles per search and 16 enlargements of `L`; exceeding either
/// is an error that says so.
pub fn surface_spectrum(
    mesh: &crate::mesh::Mesh,
    metric: &crate::metric::IntrinsicMetric,
    centre: Option<u32>,
    count: usize,
    max_tiles: usize,
) -> Result<(HyperbolicSpectrum, CompactDomain)> {
    let ne = mesh.n_edges();
    let lengths = metric.lengths();
    if metric.geometry() != crate::metric::Geometry::Hyperbolic {
        return Err(Error::input(format!(
            "the length spectrum of a surface is computed from a hyperbolic metric, this one is \
             {}",
            metric.geometry()
        )));
    }
    if lengths.len() != ne {
        return Err(Error::input(format!(
            "{} edge lengths for a mesh with {ne} edges",
            lengths.len()
        )));
    }
    if mesh.has_boundary() || mesh.n_faces() == 0 {
        return Err(Error::topology(
            "the length spectrum needs a closed surface (the mesh has a boundary or no faces)",
        ));
    }
    let o = match centre {
        Some(v) if (v as usize) < mesh.n_vertices() => v,
        Some(v) => {
            return Err(Error::input(format!(
                "centre vertex {v} does not exist (the mesh has {} vertices)",
                mesh.n_vertices()
            )))
        }
        None => crate::cut::central_vertex(mesh, lengths)?,
    };
    let clock = std::time::Instant::now();
    let (seed, crossed) = grow_domain(mesh, lengths, o)?;
    let dom = DomainPairings::new(mesh, metric, o, seed, &crossed)?;
    let cover = BallCover::of_domain(&dom.positions, &dom.faces, dom.centre, 1.0, 400);
    let radius = cover.radius;
    let mut domain = CompactDomain {
        radius,
        faces: mesh.n_faces(),
        boundary_edges: dom.boundary.len(),
        generators: dom.generators.len(),
        balls: cover.balls.len(),
        seconds_domain: clock.elapsed().as_secs_f64(),
        seconds_search: 0.0,
        centre: o,
        points: dom.positions.iter().map(|p| [p.re, p.im]).collect(),
        point_vertex: dom.origin.clone(),
        triangles: dom.faces.clone(),
    };
    let clock = std::time::Instant::now();
    let mut l = dom
        .generators
        .iter()
        .map(|g| g.round().translation_length())
        .filter(|x| *x > 0.0)
        .fold(f64::INFINITY, f64::min);
    if !l.is_finite() {
        return Err(Error::numerical(
            "the side pairings are not hyperbolic isometries (is the metric hyperbolic?)",
        ));
    }
    let o_h = cover.centre;
    // The boundary edges of each coarse ball (edge e lies in its triangle, in the ball).
    let mut ball_edges: Vec<Vec<usize>> = vec![Vec::new(); cover.balls.len()];
    for (e, &f) in dom.boundary_faces.iter().enumerate() {
        ball_edges[cover.face_ball[f as usize]].push(e);
    }
    let mut search = TileSearch::new(o_h);
    for _round in 0..16 {
        let bound = ((l + 2.0 * radius) * (1.0 + 1e-9) + 1e-9).cosh();
        let limits = cover.limits(l, radius);
        let cosh_d = |x: [f64; 3], y: [f64; 3]| x[2] * y[2] - x[0] * y[0] - x[1] * y[1];
        let keep = |g: &Mobius, go: [f64; 3]| {
            cosh_d(o_h, go) <= bound && cover.may_be_within(g, go, &limits)
        };
        if !search.grow(o_h, &dom.generators, max_tiles, keep) {
            return Err(Error::numerical(format!(
                "the spectrum search exceeded its budget of {max_tiles} tiles of the \
                 universal cover at length bound {l:.3} (domain radius {radius:.2}); \
                 ask for fewer lengths"
            )));
        }
        // The axis is the real diameter in the frame: skip it when it misses every ball.
        let cross = |fr: &Mobius| cover.sides_crossed(fr, &dom.boundary, &ball_edges);
        if let Some(sp) = search.spectrum(l, &dom.generators, o_h, count, cross) {
            domain.seconds_search = clock.elapsed().as_secs_f64();
            return Ok((sp, domain));
        }
        l = search.next_bound(l, count, cross);
    }
    Err(Error::numerical(format!(
        "the spectrum search did not find {count} classes within its budget of 16 \
         enlargements of the length bound (last bound {l:.3})"
    )))
}

/// Dirichlet-like growth of a fundamental domain around vertex `o`: develop the faces in the
/// hyperbolic plane (double precision, for the order only) from a face at `o`, attaching next
/// the face whose developed copy lies nearest to `o` (largest |z| of its corners: the
/// hyperbolic distance 2 atanh|z| is monotone in |z|). Returns the seed face and the edges
/// the spanning tree of the dual graph crosses.
fn grow_domain(mesh: &crate::mesh::Mesh, lengths: &[f64], o: u32) -> Result<(u32, Vec<bool>)> {
    use crate::layout::place::Space;
    use crate::metric::Hyperbolic;
    use std::cmp::Reverse;
    use std::collections::BinaryHeap;
    let (nf, ne) = (mesh.n_faces(), mesh.n_edges());
    let seed = mesh
        .outgoing(o)
        .map(|h| mesh.he_face(h))
        .find(|&f| f != crate::mesh::NONE)
        .ok_or_else(|| Error::topology(format!("vertex {o} has no face")))?;
    let mut developed = vec![false; nf];
    let mut crossed = vec![false; ne];
    let mut corner = vec![Complex::new(0.0, 0.0); 3 * nf];
    let len = |h: u32| lengths[mesh.he_edge(h) as usize];
    {
        let hs = mesh.face_halfedges(seed);
        // Rotate the seed so that `o` is its first corner (at the centre of the disk).
        let i0 = mesh.face(seed).iter().position(|&v| v == o).unwrap_or(0);
        let p = Hyperbolic::seed(len(hs[i0]), len(hs[(i0 + 1) % 3]), len(hs[(i0 + 2) % 3]));
        for r in 0..3 {
            corner[3 * seed as usize + (i0 + r) % 3] = p[r];
        }
    }
    // Entries: (key = max |z|² of the copy's corners, face, half-edge of the face on the
    // shared edge, position of the corner opposite).
    type Entry = (Reverse<u64>, u32, u32, (u64, u64));
    let mut heap: BinaryHeap<Entry> = BinaryHeap::new();
    let push_neighbours =
        |f: u32, corner: &[Complex], developed: &[bool], heap: &mut BinaryHeap<Entry>| {
            for h in mesh.face_halfedges(f) {
                let t = mesh.he_twin(h);
                let g = mesh.he_face(t);
                if g == crate::mesh::NONE || developed[g as usize] {
                    continue;
                }
                // t runs b → a in g = (b, a, c).
                let pa = corner[h as usize];
                let pb = corner[mesh.he_next(h) as usize];
                let tn = mesh.he_next(t);
                let pc = Hyperbolic::third(pb, pa, len(t), len(tn), len(mesh.he_next(tn)));
                if pc.norm_sqr().is_nan() || pc.norm_sqr() >= 1.0 {
                    continue; // numerically outside the disk: never the nearest copy
                }
                let key = pa.norm_sqr().max(pb.norm_sqr()).max(pc.norm_sqr());
                let pc_bits = (pc.re.to_bits(), pc.im.to_bits());
                heap.push((Reverse(key.to_bits()), g, t, pc_bits));
            }
        };
    developed[seed as usize] = true;
    push_neighbours(seed, &corner, &developed, &mut heap);
    while let Some((_, g, t, (cre, cim))) = heap.pop() {
        if developed[g as usize] {
            continue;
        }
        developed[g as usize] = true;
        crossed[mesh.he_edge(t) as usize] = true;
        let h = mesh.he_twin(t);
        let tn = mesh.he_next(t);
        corner[t as usize] = corner[mesh.he_next(h) as usize];
        corner[tn as usize] = corner[h as usize];
        corner[mesh.he_next(tn) as usize] = Complex::new(f64::from_bits(cre), f64::from_bits(cim));
        push_neighbours(g, &corner, &developed, &mut heap);
    }
    if developed.iter().any(|&d| !d) {
        return Err(Error::topology("the surface is not connected"));
    }
    Ok((seed, crossed))
}

/// The compact fundamental domain laid out in double-double and its side pairings.
struct DomainPairings {
    /// Layout of the sliced surface (double part), centred: the centre vertex is at 0.
    positions: Vec<Complex>,
    /// Faces of the sliced surface (geodesic triangles of the layout).
    faces: Vec<[u32; 3]>,
    /// The copy of the centre vertex in the seed face.
    centre: Complex,
    /// The mesh vertex of each point of `positions`.
    origin: Vec<u32>,
    /// Distinct side pairings (a generating set of the deck group).
    generators: Vec<MobiusDd>,
    /// Boundary cycle: (position, generator of the side starting there).
    boundary: Vec<(Complex, usize)>,
    /// The face of each boundary edge (from point `e` to point `e + 1`).
    boundary_faces: Vec<u32>,
}

impl DomainPairings {
    /// Slice `mesh` along the edges the tree does not cross, lay the disk out in double-double
    /// from `seed`, and read the side pairings: the sliced edge h (face f) and its twin t (face
    /// f') are two sides; the map S_h takes F onto the tile across h, i.e. t's copy onto h's
    /// copy, reversed.
    fn new(
        mesh: &crate::mesh::Mesh,
        metric: &crate::metric::IntrinsicMetric,
        o: u32,
        seed: u32,
        crossed: &[bool],
    ) -> Result<Self> {
        use crate::layout::dd::disk_distance_dd;
        use crate::layout::place::layout_dd;
        use crate::metric::Hyperbolic;
        use crate::numeric::dd::Cdd;
        let cut: Vec<bool> = crossed.iter().map(|&c| !c).collect();
        let (cm, origin) = crate::cut::slice(mesh, &cut)?;
        let lay = layout_dd::<Hyperbolic>(&cm, &metric.carried_to(mesh, &cm), Some(seed))?;
        if !lay.flipped_faces.is_empty() {
            return Err(Error::numerical(format!(
                "the compact fundamental domain has {} flipped faces (face {}); is the metric \
                 hyperbolic and converged?",
                lay.flipped_faces.len(),
                lay.flipped_faces[0]
            )));
        }
        let loops = cm.boundary_loop_halfedges();
        if loops.len() != 1 {
            return Err(Error::numerical(format!(
                "internal error: the sliced surface has {} boundary loops",
                loops.len()
            )));
        }
        let i0 = cm
            .face(seed)
            .iter()
            .position(|&v| origin[v as usize] == o)
            .unwrap_or(0);
        // The domain is moved (in double-double) so that its centre is the origin: the orbit
        // point of a word g is then `g 0 = b/ā` ([`super::orbit_point`]).
        let c = cm.face(seed)[i0] as usize;
        let to_centre = MobiusDd::to_origin(Cdd::from_parts(lay.positions[c], lay.positions_lo[c]));
        let moved: Vec<Cdd> = (0..cm.n_vertices())
            .map(|v| to_centre.apply(Cdd::from_parts(lay.positions[v], lay.positions_lo[v])))
            .collect();
        let pos = |v: u32| moved[v as usize];
        let positions: Vec<Complex> = moved.iter().map(|p| p.hi()).collect();
        let centre = Complex::new(0.0, 0.0);
        let o_h = [0.0, 0.0, 1.0];
        let mut generators: Vec<MobiusDd> = Vec::new();
        let mut gen_index = TileIndex::new();
        let mut boundary: Vec<(Complex, usize)> = Vec::with_capacity(loops[0].len());
        let mut boundary_faces: Vec<u32> = Vec::with_capacity(loops[0].len());
        // The last few pairings found, most recent first: consecutive boundary edges mostly
        // lie on one side (or on the two sides of a slit, paired by the identity).
        let mut recent: Vec<usize> = Vec::with_capacity(5);
        for &h in &loops[0] {
            let t = mesh.he_twin(h);
            let (p0, p1) = (pos(cm.he_origin(t)), pos(cm.he_tip(h)));
            // A deck transformation that maps `p0` within 1e-9 of `p1` is this edge's pairing
            // (two distinct ones differ by an element that moves `p1` by at least the
            // systole), so `from_pairs` is needed only for a pairing not seen lately.
            let seen = recent
                .iter()
                .copied()
                .find(|&k| disk_distance_dd(generators[k].apply(p0), p1) < 1e-9);
            let k = match seen {
                Some(k) => k,
                None => {
                    let m = MobiusDd::from_pairs(p0, pos(cm.he_tip(t)), p1, pos(cm.he_origin(h)))
                        .normalized();
                    let go = orbit_point(&m, o_h);
                    match gen_index.find(go) {
                        Some(k) => k,
                        None => {
                            generators.push(m);
                            gen_index.insert(go)
                        }
                    }
                }
            };
            recent.retain(|&x| x != k);
            recent.insert(0, k);
            recent.truncate(4);
            boundary.push((positions[cm.he_origin(h) as usize], k));
            boundary_faces.push(cm.he_face(h));
        }
        let faces = (0..cm.n_faces() as u32).map(|f| cm.face(f)).collect();
        Ok(DomainPairings {
            positions,
            faces,
            centre,
            origin,
            generators,
            boundary,
            boundary_faces,
        })
    }
}
