//! The flat pieces of the manifold spline (paper 000 §5): complex/point conversions, the
//! development of faces and vertex stars from edge lengths ([`star_frame`]), the rotation of
//! partials under a transition ([`rotate_partials`]), and the independent chart provider
//! [`LocalCharts`].

use super::*;
use crate::metric::{Geometry, IntrinsicMetric};

#[inline]
pub(crate) fn cz(p: Point) -> C {
    C::new(p[0], p[1])
}
#[inline]
pub(crate) fn pt(z: C) -> Point {
    [z.re, z.im]
}
#[inline]
pub(crate) fn apply(m: &RigidMotion, p: Point) -> Point {
    pt(m.rot * cz(p) + m.t)
}
#[inline]
pub(crate) fn rotate(rot: C, p: Point) -> Point {
    pt(rot * cz(p))
}

/// Side lengths of face `f`: `l[i]` is the edge opposite corner `i`.
pub fn face_side_lengths(mesh: &Mesh, lengths: &[f64], f: u32) -> [f64; 3] {
    let h = mesh.face_halfedges(f);
    [
        lengths[mesh.he_edge(h[1]) as usize],
        lengths[mesh.he_edge(h[2]) as usize],
        lengths[mesh.he_edge(h[0]) as usize],
    ]
}

/// The corners of a triangle with side lengths `l` (opposite corners 0, 1, 2): corner 0 at the
/// origin, corner 1 on the positive x axis, corner 2 above.
pub fn develop_face(l: [f64; 3]) -> [Point; 3] {
    let x = (l[1] * l[1] + l[2] * l[2] - l[0] * l[0]) / (2.0 * l[2]);
    let y = (l[1] * l[1] - x * x).max(0.0).sqrt();
    [[0.0, 0.0], [l[2], 0.0], [x, y]]
}

pub(crate) fn corner_angle(l: [f64; 3], i: usize) -> f64 {
    let (a, b, c) = (l[i], l[(i + 1) % 3], l[(i + 2) % 3]);
    ((b * b + c * c - a * a) / (2.0 * b * c))
        .clamp(-1.0, 1.0)
        .acos()
}

pub(crate) fn check_metric(mesh: &Mesh, lengths: &[f64]) -> Result<()> {
    if lengths.len() != mesh.n_edges() {
        return Err(Error::input(format!(
            "manifold spline: {} edge lengths for {} edges",
            lengths.len(),
            mesh.n_edges()
        )));
    }
    for f in 0..mesh.n_faces() as u32 {
        let l = face_side_lengths(mesh, lengths, f);
        let ok = l.iter().all(|x| x.is_finite() && *x > 0.0)
            && l[0] < l[1] + l[2]
            && l[1] < l[0] + l[2]
            && l[2] < l[0] + l[1];
        if !ok {
            return Err(Error::input(format!(
                "manifold spline: face {f} violates the triangle inequality in the flat metric (lengths {:.3e}, {:.3e}, {:.3e})",
                l[0], l[1], l[2]
            )));
        }
    }
    Ok(())
}

/// The development of the star of `v` from the edge lengths: `v` at the origin, the first
/// outgoing half-edge of [`Mesh::outgoing`] along `+x`, faces counter-clockwise. Each entry is a
/// face with its corner coordinates (in [`Mesh::face`] order) and the angle at which its first
/// edge at `v` leaves `v`; `total_angle` is the angle sum at `v`.
#[derive(Debug, Clone)]
pub struct StarFrame {
    pub faces: Vec<(u32, [Point; 3])>,
    pub start_angles: Vec<f64>,
    pub corner_angles: Vec<f64>,
    pub total_angle: f64,
}

impl StarFrame {
    pub(crate) fn coords_of(&self, f: u32) -> Option<&[Point; 3]> {
        self.faces.iter().find(|(g, _)| *g == f).map(|(_, c)| c)
    }
}

/// See [`StarFrame`].
pub fn star_frame(mesh: &Mesh, lengths: &[f64], v: u32) -> StarFrame {
    let mut faces = Vec::new();
    let mut start_angles = Vec::new();
    let mut corner_angles = Vec::new();
    let mut ang = 0.0f64;
    for h in mesh.outgoing(v) {
        if mesh.is_boundary_halfedge(h) {
            continue;
        }
        let f = h / 3;
        let i = h as usize % 3;
        let l = face_side_lengths(mesh, lengths, f);
        let th = corner_angle(l, i);
        let mut c = [[0.0; 2]; 3];
        let (la, lb) = (l[(i + 2) % 3], l[(i + 1) % 3]);
        c[(i + 1) % 3] = [la * ang.cos(), la * ang.sin()];
        c[(i + 2) % 3] = [lb * (ang + th).cos(), lb * (ang + th).sin()];
        faces.push((f, c));
        start_angles.push(ang);
        corner_angles.push(th);
        ang += th;
    }
    StarFrame {
        faces,
        start_angles,
        corner_angles,
        total_angle: ang,
    }
}

/// Partials of `F(u) = G(rot·u + t)` from the partials of `G` (same layout as
/// [`crate::spline::simplex::partial_index`], up to `order`): `∂_x = c ∂_1 + s ∂_2`,
/// `∂_y = −s ∂_1 + c ∂_2` with `rot = c + i s`, expanded per order.
pub fn rotation_matrix(order: usize, rot: C) -> Vec<f64> {
    let np = n_partials(order);
    let mut t = vec![0.0; np * np];
    rotation_matrix_into(order, rot, &mut t);
    t
}

/// Largest order whose rotation [`rotate_partials`] builds on the stack.
const STACK_ORDER: usize = 6;

/// [`rotation_matrix`] into `t` (`n_partials(order)²` zeros on entry), with the polynomial of
/// each row on the stack: the same operations in the same order, so the same numbers, without
/// the small allocations per row (this runs once per basis triangle and point of the fit's
/// quadrature).
fn rotation_matrix_into(order: usize, rot: C, t: &mut [f64]) {
    let np = n_partials(order);
    let (c, s) = (rot.re, rot.im);
    let (mut poly_stack, mut next_stack) = ([0.0; 32], [0.0; 32]);
    let (mut poly_heap, mut next_heap) = (Vec::new(), Vec::new());
    let (poly, next): (&mut [f64], &mut [f64]) = if order + 2 <= 32 {
        (&mut poly_stack, &mut next_stack)
    } else {
        poly_heap.resize(order + 2, 0.0);
        next_heap.resize(order + 2, 0.0);
        (&mut poly_heap, &mut next_heap)
    };
    for k in 0..=order {
        for a in 0..=k {
            let b = k - a;
            // poly[p] = coefficient of ∂_1^p ∂_2^(deg − p)
            poly[0] = 1.0;
            let mut len = 1;
            for (times, (cx, cy)) in [(a, (c, s)), (b, (-s, c))] {
                for _ in 0..times {
                    next[..=len].fill(0.0);
                    for p in 0..len {
                        let w = poly[p];
                        next[p + 1] += cx * w;
                        next[p] += cy * w;
                    }
                    len += 1;
                    poly[..len].copy_from_slice(&next[..len]);
                }
            }
            let row = partial_index(a, b);
            for (p, &w) in poly[..len].iter().enumerate() {
                t[row * np + partial_index(p, k - p)] += w;
            }
        }
    }
}

/// Apply [`rotation_matrix`] to `n` functions' partials in place (`vals[i * np ..]`).
pub fn rotate_partials(order: usize, rot: C, vals: &mut [f64]) {
    if order == 0 || (rot.re == 1.0 && rot.im == 0.0) {
        return;
    }
    let np = n_partials(order);
    if order > STACK_ORDER {
        let t = rotation_matrix(order, rot);
        apply_rotation(&t, np, vals);
        return;
    }
    // Order ≤ 2 (the fit's quadrature, the tessellation): a 6 × 6 matrix, zeroed alone.
    if order == 2 {
        let mut t = [0.0; 36];
        rotation_matrix_into(order, rot, &mut t);
        apply_rotation_fixed::<6>(&t, vals);
        return;
    }
    if order == 1 {
        let mut t = [0.0; 9];
        rotation_matrix_into(order, rot, &mut t);
        apply_rotation_fixed::<3>(&t, vals);
        return;
    }
    const NP: usize = n_partials(STACK_ORDER);
    let mut t = [0.0; NP * NP];
    rotation_matrix_into(order, rot, &mut t[..np * np]);
    apply_rotation(&t[..np * np], np, vals);
}

/// An order-2 rotation kept for reuse: the rotation `(re, im)` and its 6 × 6 matrix.
pub type CachedRotation2 = Option<([f64; 2], [f64; 36])>;

/// [`rotate_partials`] at order 2 with the matrix kept in `cache`: rebuilt only when `rot`
/// differs (bitwise) from the cached rotation. The same matrix and the same products as
/// [`rotate_partials`], so the same numbers; the fit's quadrature evaluates one face's
/// candidate bases at 315 points, each with the same transition per candidate.
pub(crate) fn rotate_partials2_cached(rot: C, cache: &mut CachedRotation2, vals: &mut [f64]) {
    if rot.re == 1.0 && rot.im == 0.0 {
        return;
    }
    let key = [rot.re, rot.im];
    let hit = matches!(cache, Some((k, _))
        if k[0].to_bits() == key[0].to_bits() && k[1].to_bits() == key[1].to_bits());
    if !hit {
        let mut t = [0.0; 36];
        rotation_matrix_into(2, rot, &mut t);
        *cache = Some((key, t));
    }
    if let Some((_, t)) = cache {
        apply_rotation_fixed::<6>(t, vals);
    }
}

/// [`apply_rotation`] for `N` partials known at compile time (orders 1 and 2): the same sums
/// in the same order, unrolled (inlined: called out of line from the cached path it cost more
/// than the matrix it saved).
#[inline(always)]
fn apply_rotation_fixed<const N: usize>(t: &[f64], vals: &mut [f64]) {
    let t: &[f64] = &t[..N * N];
    for chunk in vals.chunks_exact_mut(N) {
        let mut x = [0.0; N];
        x.copy_from_slice(chunk);
        for i in 0..N {
            let mut s = 0.0;
            for j in 0..N {
                s += t[i * N + j] * x[j];
            }
            chunk[i] = s;
        }
    }
}

/// `chunk ← t · chunk` for every chunk of `np` partials of `vals`.
fn apply_rotation(t: &[f64], np: usize, vals: &mut [f64]) {
    let mut stack = [0.0; n_partials(STACK_ORDER)];
    let mut heap = Vec::new();
    let tmp: &mut [f64] = if np <= stack.len() {
        &mut stack[..np]
    } else {
        heap.resize(np, 0.0);
        &mut heap
    };
    for chunk in vals.chunks_exact_mut(np) {
        for i in 0..np {
            let mut s = 0.0;
            for j in 0..np {
                s += t[i * np + j] * chunk[j];
            }
            tmp[i] = s;
        }
        chunk.copy_from_slice(tmp);
    }
}

// ---------------------------------------------------------------------------------------------
// An independent chart provider

/// A chart provider built directly from a flat cone metric, independent of the affine atlas:
/// one chart per face `f`, the breadth-first development (from the edge lengths) of `f` and
/// every face sharing a vertex with `f` that is not incident to a singular vertex. A flat metric
/// is developable on that simply connected set, so it satisfies the [`FlatCharts`] contract;
/// with a `seed`, every chart is additionally moved by a pseudo-random rigid motion (a second,
/// differently placed provider for chart-independence tests).
#[derive(Debug, Clone)]
pub struct LocalCharts {
    mesh: Mesh,
    lengths: Vec<f64>,
    positions: Vec<[f64; 3]>,
    singular: Vec<u32>,
    charts: Vec<Vec<(u32, [Point; 3])>>,
    of_face: Vec<Vec<ChartId>>,
    home: Vec<Option<ChartId>>,
}

impl LocalCharts {
    /// Build the charts of the flat `metric` (Euclidean, with cone points). `singular` lists
    /// the cone vertices (their incident faces get charts but no home chart).
    pub fn new(
        mesh: Mesh,
        metric: IntrinsicMetric,
        positions: Vec<[f64; 3]>,
        singular: Vec<u32>,
        seed: Option<u64>,
    ) -> Result<LocalCharts> {
        metric.require(Geometry::Euclidean, "the local charts of a manifold spline")?;
        let (_, lengths, _) = metric.into_parts();
        check_metric(&mesh, &lengths)?;
        if positions.len() != mesh.n_vertices() {
            return Err(Error::input(format!(
                "local charts: {} positions for {} vertices",
                positions.len(),
                mesh.n_vertices()
            )));
        }
        let mut is_sing = vec![false; mesh.n_vertices()];
        for &s in &singular {
            if s as usize >= mesh.n_vertices() {
                return Err(Error::input(format!(
                    "local charts: singular vertex {s} does not exist"
                )));
            }
            is_sing[s as usize] = true;
        }
        let at_cone = |f: u32| mesh.face(f).iter().any(|&v| is_sing[v as usize]);
        let nf = mesh.n_faces() as u32;
        let charts: Vec<Vec<(u32, [Point; 3])>> = (0..nf)
            .into_par_iter()
            .map(|f| -> Result<Vec<(u32, [Point; 3])>> {
                let mut set: Vec<u32> = vec![f];
                for v in mesh.face(f) {
                    for g in mesh.vertex_faces(v) {
                        if !at_cone(g) {
                            set.push(g);
                        }
                    }
                }
                set.sort_unstable();
                set.dedup();
                let mut coords: HashMap<u32, [Point; 3]> = HashMap::with_capacity(set.len());
                let mut seedc = develop_face(face_side_lengths(&mesh, &lengths, f));
                if let Some(s) = seed {
                    let key = hash64(s ^ hash64(f as u64));
                    let m = RigidMotion::new(
                        2.0 * PI * unit(key),
                        C::new(10.0 * unit(key + 1) - 5.0, 10.0 * unit(key + 2) - 5.0),
                    );
                    seedc = seedc.map(|p| apply(&m, p));
                }
                coords.insert(f, seedc);
                let mut queue = std::collections::VecDeque::from([f]);
                while let Some(g) = queue.pop_front() {
                    let cg = coords[&g];
                    for h in mesh.face_halfedges(g) {
                        let t = mesh.he_twin(h);
                        if mesh.is_boundary_halfedge(t) {
                            continue;
                        }
                        let g2 = t / 3;
                        if coords.contains_key(&g2) || set.binary_search(&g2).is_err() {
                            continue;
                        }
                        let i = h as usize % 3;
                        let j = t as usize % 3;
                        let c2 = develop_face(face_side_lengths(&mesh, &lengths, g2));
                        let (m, _) =
                            fit_rigid(&[c2[j], c2[(j + 1) % 3]], &[cg[(i + 1) % 3], cg[i]]);
                        coords.insert(g2, c2.map(|p| apply(&m, p)));
                        queue.push_back(g2);
                    }
                }
                if coords.len() != set.len() {
                    return Err(Error::topology(format!(
                        "local charts: the faces around face {f} are not connected through edges"
                    )));
                }
                let mut v: Vec<(u32, [Point; 3])> = coords.into_iter().collect();
                v.sort_unstable_by_key(|x| x.0);
                Ok(v)
            })
            .collect::<Result<_>>()?;
        let mut of_face = vec![Vec::new(); nf as usize];
        for (c, ch) in charts.iter().enumerate() {
            for (g, _) in ch {
                of_face[*g as usize].push(c as ChartId);
            }
        }
        let home = (0..nf).map(|f| (!at_cone(f)).then_some(f)).collect();
        Ok(LocalCharts {
            mesh,
            lengths,
            positions,
            singular,
            charts,
            of_face,
            home,
        })
    }
}

impl FlatCharts for LocalCharts {
    fn mesh(&self) -> &Mesh {
        &self.mesh
    }
    fn lengths(&self) -> &[f64] {
        &self.lengths
    }
    fn positions(&self) -> &[[f64; 3]] {
        &self.positions
    }
    fn singular_vertices(&self) -> &[u32] {
        &self.singular
    }
    fn n_charts(&self) -> usize {
        self.charts.len()
    }
    fn face_coords(&self, c: ChartId, f: u32) -> Option<[[f64; 2]; 3]> {
        let ch = self.charts.get(c as usize)?;
        ch.binary_search_by_key(&f, |x| x.0).ok().map(|i| ch[i].1)
    }
    fn charts_of_face(&self, f: u32) -> Vec<ChartId> {
        self.of_face.get(f as usize).cloned().unwrap_or_default()
    }
    fn home_chart(&self, f: u32) -> Option<ChartId> {
        self.home.get(f as usize).copied().flatten()
    }
}
