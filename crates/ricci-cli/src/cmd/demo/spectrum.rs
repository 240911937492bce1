//! Stage `spectrum`: the shortest closed geodesics from the Fuchsian group,
//! ℓ = 2 acosh(|tr|/2) (paper 002 §6.3.3).

use super::common::*;
use super::report::{Section, Status, Table};
use super::Env;
use ricci::analysis::spectrum::fuchsian_spectrum;
use serde_json::json;

pub fn spectrum(ctx: &mut Ctx, env: &mut Env) -> anyhow::Result<Section> {
    let mut sec = Section::new("spectrum", "", "");
    let (Some(d), Some(l), Some(g)) = (&ctx.disk, &ctx.layout, &ctx.group) else {
        anyhow::bail!("no layout");
    };
    env.bar.step("enumerating closed geodesics");
    let sp = fuchsian_spectrum(l, &d.polygon, g, SPECTRUM_COUNT, 2_000_000)?;
    let lengths = sp.lengths();
    let shortest_generator = g
        .named_generators()
        .iter()
        .map(|(_, m)| m.translation_length())
        .fold(f64::INFINITY, f64::min);
    sec.paragraphs.push(format!(
        "The shortest closed geodesics of the hyperbolic metric: one length 2 acosh(|tr γ|/2) \
         per free homotopy class (unoriented, powers included). Every class shorter than \
         {:.4} is guaranteed to be listed. The generators are closed geodesic classes too, so \
         none is shorter than the first length.",
        sp.complete_up_to
    ));
    let mut t = Table::new(
        "Shortest closed geodesics (curvature −1)",
        &["k", "length", "length / shortest"],
    );
    let first = lengths.first().copied().unwrap_or(1.0);
    for (i, x) in lengths.iter().enumerate() {
        t.row(vec![
            (i + 1).to_string(),
            format!("{x:.6}"),
            format!("{:.4}", x / first),
        ]);
    }
    sec.tables.push(t);
    sec.tables.push(Table::key_values(
        "Search",
        vec![
            ("complete up to", format!("{:.6}", sp.complete_up_to)),
            ("tiles visited", sp.tiles.to_string()),
            ("unmatched links", sp.unmatched_links.to_string()),
            ("shortest generator", format!("{shortest_generator:.6}")),
        ],
    ));
    if sp.unmatched_links > 0 {
        sec.status = Status::Warning(format!(
            "{} links to unenumerated tiles: classes may be over-counted",
            sp.unmatched_links
        ));
    }
    sec.commands = vec![format!(
        "ricci spectrum surface.off --count {SPECTRUM_COUNT}"
    )];
    sec.headline = format!(
        "systole {:.6}; {} lengths up to {:.4}",
        first,
        lengths.len(),
        lengths.last().copied().unwrap_or(0.0)
    );
    sec.summary = json!({
        "genus": d.cut.genus,
        "lengths": lengths,
        "complete_up_to": sp.complete_up_to,
        "tiles": sp.tiles,
        "unmatched_links": sp.unmatched_links,
        "shortest_generator_translation_length": shortest_generator,
    });
    Ok(sec)
}
