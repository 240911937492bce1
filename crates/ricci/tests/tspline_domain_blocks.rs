//! Genus ≥ 2: error-driven local refinement away from the zeros (issue 18, paper 003 §3.3) —
//! boxes of cells of the domain mesh split 2×2 by lines ending in T-junctions
//! (`domain_mesh/blocks.rs`). Checked against facts from elsewhere: the T-mesh's analysis
//! suitability from its lines (strip by strip, here) and by the library's walk across the
//! gluings, the anchors a 2×2 split adds (counted from the box's size), partition of unity,
//! the blending functions against ray casting + Cox–de Boor, C² across every cell side not at a
//! zero for random nets, and the fit's error recomputed from the patches, against the fit that
//! refines the spacing everywhere instead (both computed here).

mod ricci_meshes;
mod tspline_cases;

use crate::tspline_domain_mesh::{check_t_spline, Rng};
use ricci::spline::tspline::domain_fit::{
    deviation_between_vertices, fit_domain_mesh, fit_domain_mesh_on_triangles, DomainFitOptions,
};
use ricci::spline::tspline::domain_mesh::blocks::{place_blocks, CLEAR};
use ricci::spline::tspline::domain_mesh::DomainMesh;
use ricci::spline::tspline::fit::bbox_scale;
use tspline_cases::{genus_two_cases, glued_domain, max_vertex_error};

/// Anchors a block of `a × b` cells inside a strip adds: `a` lines along `v` over the box's
/// `b` rows and one row beyond each end (`b + 3` crossings of the old rows, `b` of the new
/// ones) and `b` lines along `u` across its `a` columns (`a + 1` crossings of the old columns).
fn added_anchors(a: usize, b: usize) -> usize {
    a * (2 * b + 3) + b * (a + 1)
}

/// Blocks in the middle of every strip large enough, two close ones merged, one at a strip's
/// side: analysis-suitable (checked here and by the library), the anchors the boxes' sizes
/// say, partition of unity, blending functions, C² off the zeros, G¹ at them.
#[test]
fn blocks_split_cells_2x2_in_an_analysis_suitable_t_spline() {
    let mut rng = Rng(0xbb67ae8584caa73b);
    let mut tested = 0;
    for (name, s) in genus_two_cases() {
        let (d, g, l) = glued_domain(&s);
        for (k, levels, margin) in [(25.0, 0, 2), (25.0, 2, 2), (40.0, 2, 2)] {
            let spacing = l / k;
            let base = DomainMesh::graded(&d, &g, spacing, levels).unwrap();
            let plain = DomainMesh::graded(&d, &g, spacing, levels).unwrap();
            let plain = if levels > 0 {
                plain.with_t_junctions(margin).unwrap()
            } else {
                plain
            };
            // a cell in the middle of every strip with room, and one three cells right of it
            // and two up (closer than the gap: one box); a cell at a strip's left side
            let mut marked = Vec::new();
            let mut side = None;
            for rc in &base.rects {
                let (m, n) = (rc.m, rc.n);
                if m < 2 * CLEAR + 8 || n < 2 * CLEAR + 6 {
                    continue;
                }
                let (i, j) = (m / 2 - 2, n / 2 - 1);
                let cell = |i: usize, j: usize| (rc.first_cell + j * m + i) as u32;
                marked.push(cell(i, j));
                marked.push(cell(i + 3, j + 2));
                if side.is_none() && n >= 2 * CLEAR + 12 {
                    side = Some(cell(0, j));
                }
            }
            if marked.is_empty() {
                eprintln!("{name} at L/{k}: no strip with room for a block");
                continue;
            }
            let blocks = place_blocks(&base, &marked).unwrap();
            // one box per strip: the two cells' neighbourhoods, merged
            for b in &blocks {
                assert_eq!(
                    (b.i1 - b.i0, b.j1 - b.j0),
                    (6, 5),
                    "{name}: {b:?} is not the bounding box of the two 3 × 3 neighbourhoods"
                );
            }
            let m = DomainMesh::refined(&d, &g, spacing, levels, &blocks)
                .unwrap()
                .with_t_junctions(margin)
                .unwrap();
            let label = format!("{name} at L/{k}, {levels} levels, {} blocks", blocks.len());
            assert_eq!(m.extensions_meet().unwrap(), None, "{label}");
            let want: usize = blocks.iter().map(|_| added_anchors(6, 5)).sum();
            eprintln!(
                "{label}: {} anchors, {} without the blocks (+{want} from the boxes' sizes), {} T-junctions",
                m.n_control_points(),
                plain.n_control_points(),
                m.n_t_junctions()
            );
            assert_eq!(
                m.n_control_points(),
                plain.n_control_points() + want,
                "{label}"
            );
            check_t_spline(&label, &m, m.n_vertices(), &mut rng);
            tested += 1;
            // a box at a strip's side splits only its rows
            if let Some(c) = side {
                let mut with_side = marked.clone();
                with_side.push(c);
                let blocks = place_blocks(&base, &with_side).unwrap();
                let m = DomainMesh::refined(&d, &g, spacing, levels, &blocks)
                    .unwrap()
                    .with_t_junctions(margin)
                    .unwrap();
                let label = format!("{label}, one at a strip's side");
                assert_eq!(m.extensions_meet().unwrap(), None, "{label}");
                check_t_spline(&label, &m, m.n_vertices(), &mut rng);
            }
        }
    }
    assert!(tested > 0, "no mesh had room for a block");
}

/// The fit with blocks against the fit that refines the spacing everywhere instead (the same
/// options otherwise), at 1 % and 0.5 %, the input vertices only and with points on the input
/// triangles: L∞ recomputed here from the patches within the tolerance; never more control
/// points, fewer in at least one case; the distance to the triangles between the vertices.
#[test]
fn blocks_fit_the_tolerance_with_fewer_control_points_than_refining_everywhere() {
    let (mut fewer, mut cases) = (0, 0);
    for (name, s) in genus_two_cases() {
        let (d, g, _) = glued_domain(&s);
        let side = bbox_scale(&s.positions);
        let triangles = s.mesh.faces();
        for tolerance in [0.01, 0.005] {
            for on_triangles in [false, true] {
                let fit = |blocks: bool| {
                    let opts = DomainFitOptions {
                        tolerance,
                        blocks,
                        ..DomainFitOptions::default()
                    };
                    if on_triangles {
                        fit_domain_mesh_on_triangles(&d, &g, &s.positions, triangles, &opts)
                    } else {
                        fit_domain_mesh(&d, &g, &s.positions, &opts)
                    }
                    .unwrap()
                };
                let (f, global) = (fit(true), fit(false));
                let label = format!(
                    "{name} at {:.1} %{}",
                    100.0 * tolerance,
                    if on_triangles {
                        ", on the triangles"
                    } else {
                        ""
                    }
                );
                // L∞ at the vertices, from the patches
                let max = max_vertex_error(&d, &f, &s.positions);
                let between = deviation_between_vertices(&f, &s.positions, triangles, 4);
                let between_global =
                    deviation_between_vertices(&global, &s.positions, triangles, 4);
                eprintln!(
                    "{label}: blocks {} control points ({} blocks, {} T-junctions, L∞ {:.4} %, between max {:.3} % rms {:.3} %), spacing everywhere {} (L∞ {:.4} %, between max {:.3} % rms {:.3} %); {:?}",
                    f.mesh.n_control_points(),
                    f.mesh.blocks.len(),
                    f.mesh.n_t_junctions(),
                    100.0 * max / side,
                    between.0,
                    between.1,
                    global.mesh.n_control_points(),
                    global.steps.last().unwrap().max_error_percent,
                    between_global.0,
                    between_global.1,
                    f.refinements
                );
                assert!(f.converged && global.converged, "{label}");
                assert!(100.0 * max / side <= 100.0 * tolerance, "{label}");
                assert!(
                    f.mesh.n_control_points() <= global.mesh.n_control_points(),
                    "{label}"
                );
                assert!(global.mesh.blocks.is_empty(), "{label}");
                cases += 1;
                if f.mesh.n_control_points() < global.mesh.n_control_points() {
                    assert!(!f.mesh.blocks.is_empty(), "{label}");
                    fewer += 1;
                }
            }
        }
    }
    eprintln!("blocks: fewer control points in {fewer} of {cases} fits");
    assert!(fewer > 0);
}
