//! Genus ≥ 2: the refinement keeps what it has learnt (`domain_mesh/blocks.rs`: blocks grow at
//! their edges and are carried over to a finer spacing; `domain_fit.rs`; issue 18, paper 003
//! §3.3). Checked against facts from elsewhere: the cell sizes of the meshes before and after a
//! carry-over, measured here at the centre of every split cell; analysis suitability by the
//! library's walk and `check_t_spline`; and on fertility.off the steps' L∞ and the control points
//! at 1 % against those at 0.5 % (both computed here).

mod ricci_meshes;
mod tspline_cases;

use crate::tspline_domain_mesh::{check_t_spline, Rng};
use ricci::spline::tspline::domain_mesh::blocks::{carry_blocks, place_blocks, CLEAR};
use ricci::spline::tspline::domain_mesh::DomainMesh;
use tspline_cases::{fit_at, genus_two_cases, glued_domain, max_vertex_error};

/// The width and height of the cell of `m` at `(x, y)` of strip `r`.
fn cell_size(m: &DomainMesh, r: usize, x: f64, y: f64) -> (f64, f64) {
    let rc = &m.rects[r];
    let ((i, _), (j, _)) = (rc.column(x), rc.row(y));
    (rc.x(i + 1) - rc.x(i), rc.y(j + 1) - rc.y(j))
}

/// Blocks of two levels in every strip with room, carried to the spacing × 1/√2 (and one more
/// level at the zeros): at the centre of every cell the old blocks split, the new cell is no
/// wider and no taller; the carried T-mesh is analysis-suitable and a T-spline
/// (`check_t_spline`).
#[test]
fn carried_blocks_split_their_region_at_least_as_finely() {
    let mut rng = Rng(0x9e3779b97f4a7c15);
    let mut tested = 0;
    for (name, s) in genus_two_cases() {
        let (d, g, l) = glued_domain(&s);
        // the coarsest of these spacings with a strip that has room for two levels
        let (levels, margin) = (0, 2);
        let (mut spacing, mut base, mut marked) = (l, None, Vec::new());
        for k in [40.0, 80.0, 160.0] {
            spacing = l / k;
            let m = DomainMesh::graded(&d, &g, spacing, levels).unwrap();
            for rc in &m.rects {
                let (m, n) = (rc.m, rc.n);
                if m >= 2 * CLEAR + 8 && n >= 2 * CLEAR + 6 {
                    marked.push((rc.first_cell + (n / 2) * m + m / 2) as u32);
                }
            }
            base = Some(m);
            if !marked.is_empty() {
                break;
            }
        }
        let base = base.unwrap();
        if marked.is_empty() {
            eprintln!("{name}: no strip with room for a block");
            continue;
        }
        let first = place_blocks(&base, &marked).unwrap();
        let m1 = DomainMesh::refined(&d, &g, spacing, levels, &first).unwrap();
        // the cells at the middle of every block: a nested block there
        let middle: Vec<u32> = (0..m1.n_cells() as u32)
            .filter(|&c| {
                let (r, i, j) = m1.cell_at[c as usize];
                let rc = &m1.rects[r as usize];
                first.iter().any(|b| {
                    let s = b.cell_fine();
                    b.rect == r as usize
                        && rc.u_fine[i as usize] == s * (b.i0 + b.i1) / 2
                        && rc.v_fine[j as usize] == s * (b.j0 + b.j1) / 2
                })
            })
            .collect();
        let nested = place_blocks(&m1, &middle).unwrap();
        let old = DomainMesh::refined(&d, &g, spacing, levels, &nested).unwrap();
        let deepest = nested.iter().map(|b| b.level).max().unwrap();
        assert_eq!(deepest, 2, "{name}: {nested:?}");
        let finer = spacing * std::f64::consts::FRAC_1_SQRT_2;
        let graded = DomainMesh::graded(&d, &g, finer, levels + 1).unwrap();
        let carried = carry_blocks(&old, &graded);
        assert_eq!(
            carried.iter().map(|b| b.level).max(),
            Some(deepest),
            "{name}: {carried:?}"
        );
        let new = DomainMesh::refined(&d, &g, finer, levels + 1, &carried)
            .unwrap()
            .with_t_junctions(margin)
            .unwrap();
        // every split cell of the old mesh: the new cell at its centre no larger
        let (mut split, mut worst) = (0, 0.0f64);
        for c in 0..old.n_cells() as u32 {
            if old.block_of_cell(c).is_none() {
                continue;
            }
            split += 1;
            let (r, i, j) = old.cell_at[c as usize];
            let rc = &old.rects[r as usize];
            let (i, j) = (i as usize, j as usize);
            let (x, y) = (0.5 * (rc.x(i) + rc.x(i + 1)), 0.5 * (rc.y(j) + rc.y(j + 1)));
            let (w0, h0) = (rc.x(i + 1) - rc.x(i), rc.y(j + 1) - rc.y(j));
            let (w1, h1) = cell_size(&new, r as usize, x, y);
            worst = worst.max(w1 / w0).max(h1 / h0);
        }
        let label = format!(
            "{name}: {} blocks (levels ≤ {deepest}) carried as {} to the spacing × 1/√2",
            nested.len(),
            carried.len()
        );
        eprintln!(
            "{label}: {split} split cells, new cell / old cell at their centres ≤ {worst:.3}; {} → {} control points",
            DomainMesh::refined(&d, &g, spacing, levels, &nested)
                .unwrap()
                .with_t_junctions(margin)
                .unwrap()
                .n_control_points(),
            new.n_control_points()
        );
        assert!(split > 0 && worst <= 1.0 + 1e-9, "{label}: {worst}");
        assert_eq!(new.extensions_meet().unwrap(), None, "{label}");
        check_t_spline(&label, &new, new.n_vertices(), &mut rng);
        tested += 1;
    }
    assert!(tested > 0, "no mesh had room for a block");
}

/// fertility.off (genus 4) at 1 %: no step's L∞ is above 1.5 times the smallest of the steps
/// before it (the fit refines by blocks that grow where an error sits at their edge instead of
/// dropping them all for a finer spacing: before, 1.25 % → 3.71 % at step 7), it meets the
/// tolerance (L∞ recomputed from the patches) and with no more control points than the fit at
/// 0.5 %.
#[test]
fn fertility_at_one_percent_keeps_what_it_has_and_needs_fewer_points_than_at_half() {
    one_percent_keeps_what_it_has_and_needs_no_more_points_than_half("fertility", 1.0);
}

/// 3holes.off at 1 %: one point next to a zero stalled at 1.009 → 1.008 % while three more
/// levels at the zeros were added (6 078 points against 4 623 at 0.5 %); a level that does not
/// help a point that close to the tolerance now stops the levels (`LEVEL_STALL`). The two fits
/// refine along different paths, so 1 % may take a few more points than 0.5 % (4 606 against
/// 4 396 for the vertices-only fit): at most 10 % more here, against 38 % before.
#[test]
fn three_holes_at_one_percent_needs_about_the_points_of_half() {
    one_percent_keeps_what_it_has_and_needs_no_more_points_than_half("3holes", 1.1);
}

/// `name`.off at 1 %: no step's L∞ above 1.5 times the smallest before it, and at most
/// `factor` times the control points of the fit at 0.5 %.
fn one_percent_keeps_what_it_has_and_needs_no_more_points_than_half(name: &str, factor: f64) {
    let Some(dir) = ricci_meshes::ricci_meshes() else {
        eprintln!("RICCI_MESHES is not set: {name}.off skipped");
        return;
    };
    let s = ricci::mesh::io::read_surface(&dir.join(format!("{name}.off")))
        .unwrap()
        .0;
    let (d, g, _) = glued_domain(&s);
    let side = ricci::spline::tspline::fit::bbox_scale(&s.positions);
    let (one, half) = (
        fit_at(&d, &g, &s.positions, 0.01, true),
        fit_at(&d, &g, &s.positions, 0.005, true),
    );
    for (f, tolerance) in [(&one, 0.01), (&half, 0.005)] {
        let max = max_vertex_error(&d, f, &s.positions) / side;
        eprintln!(
            "{name} at {} %: {} control points, L∞ {:.4} %, steps {:?}",
            100.0 * tolerance,
            f.mesh.n_control_points(),
            100.0 * max,
            f.steps
                .iter()
                .map(|s| (s.control_points, s.max_error_percent))
                .collect::<Vec<_>>()
        );
        assert!(f.converged && max <= tolerance, "{max} at {tolerance}");
    }
    let mut least = f64::INFINITY;
    for (k, st) in one.steps.iter().enumerate() {
        assert!(
            st.max_error_percent <= 1.5 * least,
            "step {}: L∞ {} % after {least} %: {:#?}",
            k + 1,
            st.max_error_percent,
            one.refinements
        );
        least = least.min(st.max_error_percent);
    }
    assert!(
        one.mesh.n_control_points() as f64 <= factor * half.mesh.n_control_points() as f64,
        "{} control points at 1 %, {} at 0.5 %",
        one.mesh.n_control_points(),
        half.mesh.n_control_points()
    );
}
