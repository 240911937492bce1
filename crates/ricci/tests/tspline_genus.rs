//! Genus ≥ 2 T-spline domain and fit (issue 18, paper 003 §2): data points in cylinder
//! coordinates developed from the holomorphic form, one spline per cylinder, Bézier export.
//! Checked against facts from elsewhere: Σ L·H over the developed cylinders against the net's
//! signed uv area (computed face by face by the decomposition; the coarea formula),
//! the errors recomputed here from the exported Bézier patches against the mesh vertices and a
//! bounding box computed here, the patches against the spline at random points, and C²
//! inside the cylinders from the patches' derivative jumps.

mod ricci_meshes;

use ricci::analysis::forms::{holomorphic_forms, FormsOptions, HolomorphicForms};
use ricci::mesh::Surface;
use ricci::progress::NoProgress;
use ricci::spline::tspline::cylinder_fit::{fit_cylinders, GenusFitOptions};
use ricci::spline::tspline::genus_domain::{best_genus_domain, GenusDomain};

fn forms(s: &Surface) -> HolomorphicForms {
    holomorphic_forms(
        &s.mesh,
        &s.edge_lengths(),
        Some(&s.positions),
        &FormsOptions::default(),
        &mut NoProgress,
    )
    .unwrap()
}

fn cases() -> Vec<(&'static str, Surface)> {
    let mut cases = vec![("genus(2, 20)", ricci::mesh::generate::genus(2, 20).unwrap())];
    match ricci_meshes::ricci_meshes() {
        Some(dir) => cases.push((
            "eight",
            ricci::mesh::io::read_surface(&dir.join("eight.off"))
                .unwrap()
                .0,
        )),
        None => eprintln!("RICCI_MESHES is not set: skipping eight.off"),
    }
    cases
}

fn check_domain(name: &str, s: &Surface, d: &GenusDomain) {
    let dec = &d.decomposition;
    eprintln!(
        "{name}: class {}, {} cylinders {:?}, {} unassigned of {}, {} crossings, holonomy defect {:e}",
        dec.class,
        d.cylinders.len(),
        d.cylinders
            .iter()
            .map(|c| (c.band, c.height, c.circumference, c.data_points))
            .collect::<Vec<_>>(),
        d.unassigned.len(),
        s.positions.len(),
        d.crossings.len(),
        d.holonomy_defect
    );
    // every cylinder is developed: Σ L·H over the charts is the net's signed uv area, computed
    // face by face by the decomposition (coarea formula, exact for piecewise-linear maps)
    let area: f64 = d.cylinders.iter().map(|c| c.circumference * c.height).sum();
    let rel = (area - dec.area).abs() / dec.area.abs();
    eprintln!(
        "{name}: saddles of v {:?} at levels {:?}; zeros {:?} at levels {:?}; Σ L·H {area} vs area {} (relative {rel:e})",
        d.saddles, d.levels, dec.zeros, dec.levels, dec.area
    );
    assert!(
        rel < 1e-9,
        "{name}: Σ L·H {area} vs the net's area {}",
        dec.area
    );
    for c in &d.cylinders {
        assert!(c.data_points > 0 && c.circumference > 0.0, "{name}: {c:?}");
    }
    assert!(d.holonomy_defect < 1e-9, "{name}: {}", d.holonomy_defect);
    // nearly every data point is assigned (the zeros and a few neighbours may not be)
    assert_eq!(
        d.points.len() + d.unassigned.len(),
        s.positions.len(),
        "{name}"
    );
    assert!(
        d.unassigned.len() * 50 <= s.positions.len(),
        "{name}: {} unassigned",
        d.unassigned.len()
    );
    for p in &d.points {
        let c = &d.cylinders[p.cylinder];
        assert!(p.u >= 0.0 && p.u < c.circumference, "{name}: {p:?}");
        assert!(p.v > 0.0 && p.v < c.height, "{name}: {p:?}");
    }
    // every cylinder's top and bottom is met by mesh edges crossing the critical levels
    for k in 0..d.cylinders.len() {
        assert!(
            d.crossings.iter().any(|x| x.lower == k),
            "{name}: top of {k}"
        );
        assert!(
            d.crossings.iter().any(|x| x.upper == k),
            "{name}: bottom of {k}"
        );
    }
}

#[test]
fn genus_two_data_points_get_cylinder_coordinates() {
    for (name, s) in cases() {
        let h = forms(&s);
        let d = best_genus_domain(&h, s.positions.len()).unwrap();
        check_domain(name, &s, &d);
    }
}

#[test]
fn genus_two_fit_meets_the_tolerance_and_is_c2_inside_the_cylinders() {
    let tolerance = 0.01;
    for (name, s) in cases() {
        let h = forms(&s);
        let d = best_genus_domain(&h, s.positions.len()).unwrap();
        let opts = GenusFitOptions {
            tolerance,
            ..GenusFitOptions::default()
        };
        let fit = fit_cylinders(&d, &s.positions, &opts).unwrap();
        let patches = fit.patches();
        // the longest bounding-box side, computed here
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in &s.positions {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let side = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max);
        // errors from the exported patches against the mesh vertices
        let (mut worst, mut sq) = (0.0f64, 0.0);
        for p in &d.points {
            let u = p.u + fit.offsets[p.cylinder];
            let q = patches
                .iter()
                .find(|q| {
                    u >= q.u0
                        && u < q.u1
                        && p.v >= q.v0
                        && p.v < q.v1
                        && q.u0 >= fit.offsets[p.cylinder]
                })
                .unwrap_or_else(|| panic!("{name}: no patch holds {p:?}"));
            let x = q.point(u, p.v);
            let y = s.positions[p.vertex as usize];
            let e = ((x[0] - y[0]).powi(2) + (x[1] - y[1]).powi(2) + (x[2] - y[2]).powi(2)).sqrt();
            worst = worst.max(e);
            sq += e * e;
        }
        let rms = (sq / d.points.len() as f64).sqrt();
        let last = fit.steps.last().unwrap();
        eprintln!(
            "{name}: {} control points, {} patches, rms {:.4} % max {:.4} % (reported {:.4} / {:.4}), converged {}",
            fit.control_points(),
            patches.len(),
            100.0 * rms / side,
            100.0 * worst / side,
            last.rms_error_percent,
            last.max_error_percent,
            fit.converged
        );
        assert!(fit.converged, "{name}");
        assert!(
            worst <= tolerance * side,
            "{name}: L∞ {worst} above {tolerance} × {side}"
        );
        assert!(rms < worst, "{name}");
        assert!(
            (100.0 * worst / side - last.max_error_percent).abs() < 1e-9,
            "{name}"
        );
        // the patches are the spline: random points of every cylinder
        let mut state = 12345u64;
        let mut rand = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for (k, sp) in fit.splines.iter().enumerate() {
            for _ in 0..50 {
                let (u, v) = (rand() * sp.circumference, rand() * sp.height);
                let w = u + fit.offsets[k];
                let q = patches
                    .iter()
                    .find(|q| w >= q.u0 && w < q.u1 && v >= q.v0 && v < q.v1)
                    .unwrap();
                let (a, b) = (q.point(w, v), sp.point(u, v));
                let e = (0..3).map(|i| (a[i] - b[i]).abs()).fold(0.0, f64::max);
                assert!(
                    e < 1e-9 * side,
                    "{name}: patch differs from the spline by {e}"
                );
            }
        }
        // C² inside the cylinders, and the third derivatives do jump (the check sees jumps)
        let inside = fit.interior_jumps(&patches, 3);
        let rel = inside.relative();
        eprintln!(
            "{name}: inside relative jumps {rel:?} over {} side points",
            inside.comparisons
        );
        let sides: usize = fit
            .splines
            .iter()
            .map(|s| 3 * (2 * s.nu * s.nv - s.nu))
            .sum();
        assert_eq!(inside.comparisons, sides, "{name}");
        assert!(
            rel[0] < 1e-12 && rel[1] < 1e-10 && rel[2] < 1e-8,
            "{name}: {rel:?}"
        );
        assert!(rel[3] > 1e-6, "{name}: {rel:?}");
        // across the critical trajectories: both sides within the fit of the same surface
        let (glued, mids) = fit.glued_jumps(&patches, &d);
        eprintln!(
            "{name}: across critical trajectories: jumps {:?} at {} crossings ({:.4} % of the side)",
            glued.jumps,
            glued.comparisons,
            100.0 * glued.jumps[0] / side
        );
        assert_eq!(glued.comparisons, d.crossings.len() + mids);
        assert!(mids > 0, "{name}");
        assert!(
            glued.jumps[0] <= 4.0 * tolerance * side,
            "{name}: {:?}",
            glued.jumps
        );
    }
}
