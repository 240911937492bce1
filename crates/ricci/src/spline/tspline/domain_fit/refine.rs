//! The refinement decisions of [`super::fit_domain_mesh_on_triangles`] between two steps (module
//! doc of [`super`], paper 003 §3.3): blocks where the errors are away from the zeros, or a
//! finer spacing with the blocks **carried over** (what they split stays split at least as
//! finely: [`carry_blocks`]), and the next step's mesh with the fallbacks when a T-mesh is not
//! analysis-suitable or over the budget.

use super::*;
use crate::spline::tspline::domain_mesh::blocks::{carry_blocks, place_blocks};

/// The blocks of the next step of [`fit_domain_mesh_on_triangles`]: the boxes around the
/// points `far` beyond the tolerance away from the zeros (in the indices of the next graded mesh,
/// `d` more levels), or — when no block can be placed or they would cover more than
/// [`BLOCK_SHARE`] of the cells — none, and the spacing times `refine` everywhere (`true`; the
/// caller carries the blocks over: [`carried`]); `what` says which.
pub(super) fn next_blocks(
    (use_blocks, far, last, d): (bool, &[u32], Option<&DomainFit>, usize),
    blocks: &mut Vec<Block>,
    (spacing, refine): (&mut f64, f64),
    what: &mut Vec<String>,
) -> bool {
    let placed = match (use_blocks, far.is_empty(), last) {
        (_, true, _) => Ok(blocks.clone()),
        (false, _, _) => Err("blocks are off".to_string()),
        (true, false, Some(fit)) => place_blocks(&fit.mesh, far),
        (true, false, None) => Err("no mesh".to_string()),
    };
    // in the indices of the next graded mesh (one more level: one more column and row
    // at each end)
    let shifted = placed.map(|bs| bs.iter().map(|b| b.shifted(d)).collect::<Vec<_>>());
    let cells: usize = last.map_or(0, |f| {
        f.mesh.rects.iter().map(|r| r.base_m * r.base_n).sum()
    });
    match shifted {
        Ok(bs) if far.is_empty() => {
            *blocks = bs;
            false
        }
        Ok(bs) if graded_cells(&bs) as f64 > BLOCK_SHARE * cells as f64 => {
            *spacing *= refine;
            blocks.clear();
            what.push(format!(
                "the spacing × 1/√2 everywhere (blocks would cover more than {:.0} % of the cells)",
                100.0 * BLOCK_SHARE
            ));
            true
        }
        Ok(bs) => {
            what.push(format!(
                "{} blocks split 2×2, or across one direction where the other is near a strip's end ({} levels, {} graded cells in their boxes; {} points beyond the tolerance away from the zeros)",
                bs.len(),
                bs.iter().map(|b| b.level).max().unwrap_or(0),
                graded_cells(&bs),
                far.len()
            ));
            *blocks = bs;
            false
        }
        Err(why) => {
            *spacing *= refine;
            blocks.clear();
            what.push(format!("the spacing × 1/√2 everywhere (no block: {why})"));
            true
        }
    }
}

/// The blocks of the `last` fit carried over to the graded mesh of `spacing` and `levels` when
/// there is one (`true`, and `what` says how many; `false` when none is carried).
pub(super) fn carry_over(
    (domain, gluing): (&GenusDomain, &Gluing),
    (spacing, levels): (f64, usize),
    last: Option<&DomainFit>,
    blocks: &mut Vec<Block>,
    what: &mut Vec<String>,
) -> Result<bool> {
    let Some(f) = last else {
        return Ok(false);
    };
    *blocks = carried(domain, gluing, (spacing, levels), &f.mesh)?;
    if !blocks.is_empty() {
        what.push(format!("{} blocks carried over", blocks.len()));
    }
    Ok(!blocks.is_empty())
}

/// The blocks of `old` carried over to the graded mesh of `spacing` and `levels`
/// ([`carry_blocks`]: what they split stays split at least as finely).
pub(super) fn carried(
    domain: &GenusDomain,
    gluing: &Gluing,
    (spacing, levels): (f64, usize),
    old: &DomainMesh,
) -> Result<Vec<Block>> {
    if old.blocks.is_empty() {
        return Ok(Vec::new());
    }
    let new = DomainMesh::graded(domain, gluing, spacing, levels).map_err(Error::numerical)?;
    Ok(carry_blocks(old, &new))
}

/// The mesh of the next step of [`fit_domain_mesh_on_triangles`]: of `spacing` graded `levels`
/// times, T-junctions `margin` cells past the corner blocks, with `blocks` — or, when their
/// T-mesh is not analysis-suitable, the spacing times `refine` with the blocks of the `last`
/// fit carried over ([`carried`]). Carried blocks (those, or the ones just carried over:
/// `carried_now`) whose T-mesh is not analysis-suitable are dropped strip by strip where the
/// extensions meet ([`drop_where_extensions_meet`]); `refinements` says which.
pub(super) fn step_mesh(
    (domain, gluing, opts): (&GenusDomain, &Gluing, &DomainFitOptions),
    (spacing, levels, margin): (&mut f64, usize, usize),
    (blocks, carried_now): (&mut Vec<Block>, bool),
    (last, refine): (Option<&DomainFit>, f64),
    refinements: &mut Vec<String>,
) -> Result<DomainMesh> {
    let mesh = domain_mesh(domain, gluing, (*spacing, levels, margin), blocks, opts)?;
    if blocks.is_empty() {
        return Ok(mesh);
    }
    let Some(v) = mesh.extensions_meet().map_err(Error::numerical)? else {
        return Ok(mesh);
    };
    let mut why =
        format!("the blocks' T-mesh is not analysis-suitable (extensions meet at vertex {v})");
    if !carried_now {
        *spacing *= refine;
        *blocks = match last {
            Some(f) => carried(domain, gluing, (*spacing, levels), &f.mesh)?,
            None => Vec::new(),
        };
        why.push_str(": the spacing × 1/√2 everywhere instead, the last fit's blocks carried over");
    }
    let kept = blocks.len();
    let at = (*spacing, levels, margin);
    let mesh = drop_where_extensions_meet((domain, gluing, opts), at, blocks)?;
    refinements.push(format!(
        "{why}; {} of {kept} carried blocks kept (the others in strips where extensions meet)",
        blocks.len()
    ));
    Ok(mesh)
}

/// `mesh`, or when it has blocks (carried over) and is over the budget, the mesh without them
/// (the largest within the budget follows: [`fill_budget`]).
pub(super) fn within_budget(
    mesh: DomainMesh,
    (domain, gluing, opts): (&GenusDomain, &Gluing, &DomainFitOptions),
    at: (f64, usize, usize),
    blocks: &mut Vec<Block>,
    refinements: &mut Vec<String>,
) -> Result<DomainMesh> {
    if blocks.is_empty() || mesh.n_control_points() <= opts.max_control_points {
        return Ok(mesh);
    }
    refinements.push(format!(
        "{} control points with the {} blocks carried over: over the budget of {}, without them",
        mesh.n_control_points(),
        blocks.len(),
        opts.max_control_points
    ));
    blocks.clear();
    domain_mesh(domain, gluing, at, blocks, opts)
}

/// The mesh of `spacing`, `levels` and `margin` with `blocks`, after dropping the blocks of the
/// strips around a vertex where the extensions of T-junctions meet, until none do (all of them
/// when that vertex's strips have none). Every round drops a block, so it ends; the mesh
/// without blocks is taken as it is (as [`step_mesh`] takes it).
pub(super) fn drop_where_extensions_meet(
    (domain, gluing, opts): (&GenusDomain, &Gluing, &DomainFitOptions),
    at: (f64, usize, usize),
    blocks: &mut Vec<Block>,
) -> Result<DomainMesh> {
    loop {
        let mesh = domain_mesh(domain, gluing, at, blocks, opts)?;
        if blocks.is_empty() {
            return Ok(mesh);
        }
        let Some(v) = mesh.extensions_meet().map_err(Error::numerical)? else {
            return Ok(mesh);
        };
        let strips: Vec<usize> = (0..mesh.n_cells())
            .filter(|&c| mesh.corners[c].contains(&v))
            .map(|c| mesh.cell_at[c].0 as usize)
            .collect();
        let before = blocks.len();
        blocks.retain(|b| !strips.contains(&b.rect));
        if blocks.len() == before {
            blocks.clear();
        }
    }
}
