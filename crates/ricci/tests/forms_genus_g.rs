//! Genus ≥ 2: Riemann's bilinear relations for the period matrix and the holomorphic basis
//! (periods summed along the loops against areas summed over the faces), the Gauss–Bonnet
//! count of zeros (2g − 2), and independence of the base vertex of the cut: the period
//! matrix changes by Sp(2g, Z), the energies of its period lattice do not (the test compares
//! those, which undoes the action without knowing it).

mod ricci_meshes;

use ricci::analysis::forms::cochain::{on_halfedge, period};
use ricci::analysis::forms::{holomorphic_forms, FormsOptions, HolomorphicForms};
use ricci::cut::CutOptions;
use ricci::mesh::Surface;
use ricci::metric::IntrinsicMetric;
use ricci::progress::NoProgress;

fn forms(s: &Surface, base: Option<u32>) -> HolomorphicForms {
    let opts = FormsOptions {
        cut: CutOptions {
            base,
            ..Default::default()
        },
        ..Default::default()
    };
    holomorphic_forms(
        &s.mesh,
        &IntrinsicMetric::euclidean(s.edge_lengths()),
        Some(&s.positions),
        &opts,
        &mut NoProgress,
    )
    .unwrap()
}

/// `∫ α ∧ β` summed over the faces (cup product).
fn wedge(h: &HolomorphicForms, a: &[f64], b: &[f64]) -> f64 {
    let m = h.mesh();
    (0..m.n_faces() as u32)
        .map(|f| {
            let (a1, a2) = (on_halfedge(m, a, 3 * f), on_halfedge(m, a, 3 * f + 1));
            let (b1, b2) = (on_halfedge(m, b, 3 * f), on_halfedge(m, b, 3 * f + 1));
            0.5 * (a1 * b2 - a2 * b1)
        })
        .sum()
}

/// `Σ_e w_e α_e β_e` (Dirichlet inner product, cotangent weights).
fn energy(h: &HolomorphicForms, a: &[f64], b: &[f64]) -> f64 {
    h.weights
        .iter()
        .zip(a)
        .zip(b)
        .map(|((w, x), y)| w * x * y)
        .sum()
}

fn check_surface(name: &str, s: &Surface, other_base: u32) {
    let h = forms(s, None);
    let g = h.genus;
    let r = &h.report;
    let om = &h.period_matrix;
    eprintln!(
        "{name}: genus {g}, {} vertices, star defect {:.1e}, raw asymmetry {:.1e}, {:.2} s",
        r.vertices, r.star_defect, r.raw_asymmetry, r.seconds
    );
    assert!(r.harmonic_residual < 1e-9 && r.closedness < 1e-12, "{r:?}");
    // Bilinear relations (1): Ω = Ωᵀ and Im Ω > 0.
    assert!(
        om.asymmetry() < 1e-8,
        "{name}: Ω asymmetric by {:e}",
        om.asymmetry()
    );
    let eig = om.im_eigenvalues().unwrap();
    assert!(eig[0] > 0.0, "{name}: Im Ω not positive definite: {eig:?}");
    // The least-squares star before its normalization: symmetric up to discretization.
    assert!(
        r.raw_asymmetry < 1e-2,
        "{name}: raw asymmetry {:e}",
        r.raw_asymmetry
    );
    // Periods along the loops (line sums) are the normalization and Ω.
    let loops = &h.cut.loops;
    let m = h.mesh();
    for (i, w) in h.basis.iter().enumerate() {
        for j in 0..g {
            let a = &loops[2 * j].halfedges;
            let b = &loops[2 * j + 1].halfedges;
            let (ar, ai) = (period(m, &w.re, a), period(m, &w.im, a));
            let (br, bi) = (period(m, &w.re, b), period(m, &w.im, b));
            let d = if i == j { 1.0 } else { 0.0 };
            assert!(
                (ar - d).abs() < 1e-9 && ai.abs() < 1e-9,
                "{name}: ∫_a{} ω{} = {ar} + {ai}i",
                j + 1,
                i + 1
            );
            assert!(
                (br - om.re[i][j]).abs() < 1e-9 && (bi - om.im[i][j]).abs() < 1e-9,
                "{name}: ∫_b{} ω{} = {br} + {bi}i vs Ω = {} + {}i",
                j + 1,
                i + 1,
                om.re[i][j],
                om.im[i][j]
            );
        }
    }
    // Bilinear relations (2), face sums against periods: ∫ ω_i ∧ ω_j = 0 and
    // (i/2) ∫ ω_i ∧ ω̄_j = Im Ω_ij; and (3) the Dirichlet energy ½(‖Re ω_i‖² + ‖Im ω_i‖²)
    // = Im Ω_ii up to the discretization of the Hodge star.
    for i in 0..g {
        for j in 0..g {
            let (wi, wj) = (&h.basis[i], &h.basis[j]);
            let re = wedge(&h, &wi.re, &wj.re) - wedge(&h, &wi.im, &wj.im);
            let im = wedge(&h, &wi.re, &wj.im) + wedge(&h, &wi.im, &wj.re);
            assert!(
                re.abs() < 1e-9 && im.abs() < 1e-9,
                "{name}: ∫ ω{} ∧ ω{} = {re} + {im}i",
                i + 1,
                j + 1
            );
            let area = 0.5 * (wedge(&h, &wi.re, &wj.im) - wedge(&h, &wi.im, &wj.re));
            assert!(
                (area - om.im[i][j]).abs() < 1e-9,
                "{name}: (i/2)∫ω{}∧ω̄{} = {area} vs Im Ω = {}",
                i + 1,
                j + 1,
                om.im[i][j]
            );
        }
        let w = &h.basis[i];
        let e = 0.5 * (energy(&h, &w.re, &w.re) + energy(&h, &w.im, &w.im));
        let rel = (e - om.im[i][i]).abs() / om.im[i][i];
        eprintln!("  energy of ω{} vs Im Ω: {rel:.1e}", i + 1);
        assert!(
            rel < 20.0 * r.star_defect.max(1e-6),
            "{name}: energy {e} vs Im Ω_{i}{i} = {}",
            om.im[i][i]
        );
    }
    // Zeros: 2g − 2 with multiplicity, no spurious singularity, for ω_1.
    let z = h.zeros(&h.basis[0]).unwrap();
    eprintln!("  zeros of ω1: {:?}", z.zeros);
    assert_eq!(z.total_index, 2 - 2 * g as i64, "{name}: Poincaré–Hopf");
    assert!(
        z.spurious.is_empty(),
        "{name}: positive indices {:?}",
        z.spurious
    );
    assert_eq!(
        z.count as usize,
        2 * g - 2,
        "{name}: zeros of ω1 {:?}",
        z.zeros
    );
    // Another base vertex: another canonical basis, the same period lattice.
    let h2 = forms(s, Some(other_base));
    let (e1, e2) = (
        h.lattice_energies(10).unwrap(),
        h2.lattice_energies(10).unwrap(),
    );
    let worst = e1
        .iter()
        .zip(&e2)
        .map(|(a, b)| (a - b).abs() / a)
        .fold(0.0, f64::max);
    eprintln!("  lattice energies {e1:.5?}, base {other_base}: {worst:.1e}");
    assert!(
        worst < 1e-3,
        "{name}: the period lattice changed with the base vertex: {e1:?} vs {e2:?}"
    );
}

#[test]
fn generated_genus_2() {
    let s = ricci::mesh::generate::genus(2, 20).unwrap();
    check_surface("genus(2, 20)", &s, 98);
}

#[test]
fn shared_meshes() {
    let Some(dir) = ricci_meshes::ricci_meshes().filter(|d| d.is_dir()) else {
        eprintln!("RICCI_MESHES not set; skipped");
        return;
    };
    for (m, base) in [
        ("eight.off", 255),
        ("3holes.off", 1198),
        ("genus3.off", 2217),
        ("fertility.off", 1498),
    ] {
        let (s, _) = ricci::mesh::io::read_surface(&dir.join(m)).unwrap();
        check_surface(m, &s, base);
    }
}

/// Botijo (genus 5, 41k vertices): the heaviest mesh of the must-show list, in a test of
/// its own (bilinear relations, 2g − 2 = 8 zeros, another base vertex).
#[test]
fn botijo() {
    let Some(dir) = ricci_meshes::ricci_meshes().filter(|d| d.is_dir()) else {
        eprintln!("RICCI_MESHES not set; skipped");
        return;
    };
    let (s, _) = ricci::mesh::io::read_surface(&dir.join("botijo.off")).unwrap();
    check_surface("botijo.off", &s, 20000);
}

/// Paper 002 §4.2.4: up to g − 1 zeros placed at chosen vertices land within one ring of
/// them, and the form still has 2g − 2 zeros in all.
fn check_placement(name: &str, s: &Surface, targets: &[u32]) {
    let h = forms(s, None);
    let g = h.genus;
    let (_, w, residual) = ricci::analysis::forms::placement::form_with_zeros(&h, targets).unwrap();
    let z = h.zeros(&w).unwrap();
    eprintln!(
        "{name}: targets {targets:?}, residual {residual:.1e}, zeros {:?}",
        z.zeros
    );
    assert_eq!(z.total_index, 2 - 2 * g as i64);
    assert_eq!(z.count as usize, 2 * g - 2, "{name}: {:?}", z);
    let m = h.mesh();
    for &p in targets {
        let near = z
            .zeros
            .iter()
            .any(|zz| zz.vertex == p || m.vertex_neighbors(p).any(|q| q == zz.vertex));
        assert!(
            near,
            "{name}: no zero within one ring of vertex {p}: {:?}",
            z.zeros
        );
    }
}

#[test]
fn zeros_placed_at_chosen_vertices() {
    let s = ricci::mesh::generate::genus(2, 20).unwrap();
    check_placement("genus(2, 20)", &s, &[17]);
    check_placement("genus(2, 20)", &s, &[400]);
    let Some(dir) = ricci_meshes::ricci_meshes().filter(|d| d.is_dir()) else {
        return;
    };
    let (s, _) = ricci::mesh::io::read_surface(&dir.join("eight.off")).unwrap();
    check_placement("eight.off", &s, &[100]);
    let (s, _) = ricci::mesh::io::read_surface(&dir.join("genus3.off")).unwrap();
    check_placement("genus3.off", &s, &[1000, 6000]);
}

/// Paper 002 §4.2.1: the most uniform combination has less area distortion than ω₁, its net
/// covers the surface's area, and it is a local minimum (finite steps in every direction of
/// the coefficients do not lower the energy).
#[test]
fn uniform_combination_is_a_local_minimum() {
    use ricci::analysis::forms::uniform::{area_distortion, uniform_combination};
    use ricci::layout::isometry::Complex;
    let s = ricci::mesh::generate::genus(2, 20).unwrap();
    let h = forms(&s, None);
    let (u, w) = uniform_combination(&h, 200).unwrap();
    eprintln!(
        "genus(2, 20): area distortion {:.4} (ω1: {:.4}), {} iterations",
        u.energy, u.energy_first_form, u.iterations
    );
    assert!(u.energy < u.energy_first_form);
    let e0 = area_distortion(&h, &u.coefficients).unwrap();
    assert!((e0 - u.energy).abs() < 1e-9 * u.energy.max(1.0));
    // Net area = surface area (the coefficients are scaled for it).
    let area: f64 = wedge(&h, &w.re, &w.im);
    let m = h.mesh();
    let lengths = h.lengths();
    let surface: f64 = (0..m.n_faces() as u32)
        .map(|f| {
            let l = m.face_edges_opposite(f).map(|e| lengths[e as usize]);
            let p = 0.5 * (l[0] + l[1] + l[2]);
            (p * (p - l[0]) * (p - l[1]) * (p - l[2])).sqrt()
        })
        .sum();
    assert!(
        (area - surface).abs() < 1e-9 * surface,
        "{area} vs {surface}"
    );
    for k in 0..2 * h.genus {
        for sign in [-1.0, 1.0] {
            let mut c = u.coefficients.clone();
            let t = 1e-3 * sign;
            let i = k / 2;
            c[i] += if k % 2 == 0 {
                Complex::new(t, 0.0)
            } else {
                Complex::new(0.0, t)
            };
            let e = area_distortion(&h, &c).unwrap();
            assert!(
                e >= u.energy * (1.0 - 1e-9),
                "a step along coordinate {k} lowers the energy: {e} < {}",
                u.energy
            );
        }
    }
}
