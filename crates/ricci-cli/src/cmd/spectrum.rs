//! `ricci spectrum MESH --count N [--metric METRIC.json] [--base V] [--json]`: geodesic length
//! spectrum of a closed surface of genus ≥ 1 (paper 002 §6.3.3): uniformization metric (E² for
//! genus 1, H² for genus ≥ 2; or the given metric), then the `N` shortest free homotopy
//! classes (unoriented, powers included), sorted. Genus 1: canonical cut, layout, deck group,
//! lattice vectors; lengths are normalized by the shortest (paper 002 Table 2). Genus ≥ 2: the
//! metric is polished to double-double (as in `ricci layout`, `metric_polish` in the report)
//! and the search runs on a compact fundamental domain grown from a central vertex (`--base`
//! chooses it) with a budget of 2 000 000 tiles (`ricci::analysis::spectrum::surface_spectrum`;
//! `details` gives the domain's radius, the tiles and the bound `complete_up_to`); lengths are
//! absolute (curvature −1, Tables 3–4) and also given normalized. A metric that did not
//! converge is refused.
//!
//! A surface with boundary: the spectrum of its double ([`double`]; genus `2g + b − 1`, the
//! JSON's `spectrum_of` is `double` and `double` describes it). `--base` names a vertex of the
//! surface (the double keeps its ids).

mod double;

use super::layout::{polished_metric, FlowLimits, Polish, PolishedLengths};
use crate::util::read_surface;
use crate::util::Reporter;
use crate::util::{print_json, UsageError};
use ricci::analysis::spectrum::{lattice_spectrum, surface_spectrum};
use ricci::layout::deck_group;
use ricci::layout::pipeline::cut_disk;
use ricci::layout::place::layout;
use ricci::metric::{Euclidean, Geometry};
use ricci::progress::Progress;
use serde_json::json;
use std::path::PathBuf;
use std::time::Instant;

#[derive(clap::Args)]
pub struct Args {
    /// Mesh file (a closed surface of genus ≥ 1).
    pub mesh: PathBuf,
    /// Number of lengths.
    #[arg(long, default_value_t = 8)]
    pub count: usize,
    /// Discrete conformal scheme of the flow (see `ricci flow`; default: conformal, vertex
    /// scaling with intrinsic Delaunay flips). Ignored with --metric.
    #[arg(long)]
    pub scheme: Option<ricci::metric::Scheme>,
    /// Metric from `ricci flow --out` (flat for genus 1, hyperbolic otherwise).
    #[arg(long)]
    pub metric: Option<PathBuf>,
    /// Base vertex of the canonical loops (genus 1) or centre of the compact fundamental
    /// domain (genus ≥ 2).
    #[arg(long)]
    pub base: Option<u32>,
    /// Newton iteration budget of the flow (default: the scheme's); a flow that runs out of
    /// it is refused with the reason. Ignored with --metric.
    #[arg(long)]
    pub max_iterations: Option<usize>,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let t0 = Instant::now();
    crate::util::stages_start();
    if a.count == 0 || a.count > 10_000 {
        return Err(UsageError("--count must be between 1 and 10000".into()).into());
    }
    let (surface, _) = read_surface(&a.mesh)?;
    crate::util::stage_done("input");
    if let Some(b) = a.base {
        crate::util::check_vertex("--base", b, surface.mesh.n_vertices())?;
    }
    // A closed surface, or a bordered one's double (module docs of [`double`]).
    let (surface, double_info, genus) = double::spectrum_surface(&a, surface)?;
    // An estimate up front: the enumeration grows steeply with N (measured on eight.off, a
    // genus-2 surface, on a loaded 2-core machine: 100 lengths ~3 CPU-s, 400 lengths > 75).
    if a.count > 100 && genus >= 2 {
        let est = 3.0 * (a.count as f64 / 100.0).powf(2.3);
        eprintln!(
            "ricci spectrum: --count {} on a genus-{} surface: the search for closed geodesics \
             grows steeply with N (100 lengths take ~3 CPU-seconds, 400 more than 75); expect \
             roughly {:.0} s",
            a.count, genus, est
        );
    }
    let want = if genus == 1 {
        Geometry::Euclidean
    } else {
        Geometry::Hyperbolic
    };
    // Progress: the spinner on a terminal, else one line per stage on stderr (issue 22 item 4).
    let mut bar = Reporter::new(a.json);
    let first = flowed_metric(&a, &surface, want, &mut bar)?;
    let PolishedLengths {
        metric,
        mesh: own_mesh,
        report: metric_report,
        polish: polish_report,
        ..
    } = first;
    if let Some(why) = super::layout::file_metric::spectrum_refusal(&metric_report) {
        anyhow::bail!("{}: {why}", a.mesh.display());
    }
    let work = own_mesh.as_ref().unwrap_or(&surface.mesh);
    let geometry = metric.geometry();
    // Wall seconds of the compact domain and of the search (in `timings_wall`).
    let mut split = None;
    let (abs, extra, word) = if geometry == Geometry::Euclidean {
        bar.report("cut", None, "cutting along canonical loops");
        let disk = cut_disk(work, &metric, None, a.base, &mut bar)?;
        crate::util::stage_done("cut");
        bar.report("layout", None, "layout, deck group and spectrum");
        let l = layout::<Euclidean>(&disk.mesh, &disk.metric, None)?;
        let g = deck_group::<Euclidean>(&l, &disk.polygon)?;
        let gens = g.named_generators();
        if gens.len() != 2 {
            anyhow::bail!("expected two translation generators, found {}", gens.len());
        }
        let sp = lattice_spectrum(gens[0].1.t, gens[1].1.t, a.count)?;
        let tau = ricci::analysis::spectrum::torus_modulus(gens[0].1.t, gens[1].1.t)?;
        crate::util::stage_done("layout and lattice");
        (
            sp,
            json!({"relation_error": g.relation_error, "modulus": [tau.0, tau.1]}),
            Some(disk.polygon.word()),
        )
    } else {
        // A compact fundamental domain grown from a central vertex (no canonical cut needed;
        // `ricci::analysis::spectrum::surface_spectrum`), searched with a tile budget.
        let (sp, dom) = bar
            .while_running(
                "spectrum",
                "compact fundamental domain and the search for closed geodesics",
                || surface_spectrum(work, &metric, a.base, a.count, 2_000_000),
            )
            .map_err(|e| anyhow::anyhow!("{}: {e}", a.mesh.display()))?;
        crate::util::stage_done("spectrum");
        split = Some((dom.seconds_domain, dom.seconds_search));
        (
            sp.lengths(),
            json!({"method": "compact fundamental domain", "complete_up_to": sp.complete_up_to,
                   "tiles": sp.tiles, "unmatched_links": sp.unmatched_links,
                   "domain": {"radius": dom.radius, "faces": dom.faces,
                              "boundary_edges": dom.boundary_edges, "generators": dom.generators}}),
            None,
        )
    };
    bar.bar.0.finish_and_clear();
    let shortest = abs.first().copied().unwrap_or(1.0);
    let normalized: Vec<f64> = abs.iter().map(|x| x / shortest).collect();
    let lengths_out = if geometry == Geometry::Euclidean {
        &normalized
    } else {
        &abs
    };
    crate::util::stage_done("output");
    let (timings, mut timings_wall) = crate::util::stages_take();
    if let (Some((d, s)), Some(o)) = (split, timings_wall.as_object_mut()) {
        o.insert("spectrum: domain".into(), json!(d));
        o.insert("spectrum: search".into(), json!(s));
    }
    let out = json!({
        "file": a.mesh.display().to_string(),
        "genus": genus,
        "spectrum_of": if double_info.is_some() { "double" } else { "surface" },
        "double": double_info,
        "geometry": geometry.name(),
        "lengths": lengths_out,
        "absolute_lengths": abs,
        "normalized": normalized,
        "metric": metric_report,
        "metric_polish": polish_report,
        "modulus": extra.get("modulus").cloned(),
        "details": extra,
        "boundary_word": word,
        "seconds": t0.elapsed().as_secs_f64(),
        "timings": timings,
        "timings_wall": timings_wall,
    });
    if a.json {
        print_json(&out);
    } else {
        println!(
            "{}: genus {}{}, {} metric",
            a.mesh.display(),
            genus,
            double_info.as_ref().map_or("", |_| " (its double)"),
            geometry.name()
        );
        for (i, (x, n)) in abs.iter().zip(&normalized).enumerate() {
            println!("  {:>3}  {:.6}  ({:.4})", i + 1, x, n);
        }
    }
    Ok(())
}

/// The metric of the spectrum, polished at once to double-double. A hyperbolic uniformization
/// needs the flow only close enough for the polish's Newton steps: flowing to
/// `layout_tolerance` (1e-12) costs up to three times the iterations at the rounding floor of
/// a large mesh (seahorse2_100K: 1.1e-11 at iteration 9, then 18 steps of ~1e-13 before one
/// lands below 1e-12). If that polish does not converge, the flow runs again to 1e-12.
fn flowed_metric(
    a: &Args,
    surface: &ricci::mesh::Surface,
    want: Geometry,
    bar: &mut Reporter,
) -> anyhow::Result<PolishedLengths> {
    let loose = (want == Geometry::Hyperbolic && a.metric.is_none()).then_some(1e-10);
    let run = |tol: Option<f64>, bar: &mut Reporter| {
        polished_metric(
            surface,
            Some(want),
            None,
            a.scheme,
            a.metric.as_ref(),
            Polish::Now,
            FlowLimits {
                tolerance: tol,
                max_iterations: a.max_iterations,
            },
            bar,
        )
        .map_err(|e| anyhow::anyhow!("{}: {}", a.mesh.display(), crate::util::sentence(&e)))
    };
    let first = run(loose, bar)?;
    if loose.is_some() && first.polish["converged"].as_bool() != Some(true) {
        return run(None, bar);
    }
    Ok(first)
}
