//! Demo stage `geodesics`: the shortest closed geodesics of the hyperbolic metric drawn on the
//! built-in surface (paper 002 §6.3.3): the classes of `ricci spectrum`
//! (`ricci::analysis::spectrum::fuchsian_spectrum` on the layout of the fundamental polygon),
//! each traced along the axis of its representative for one period and pulled back into the
//! polygon across the side pairings (`ricci::analysis::spectrum::trace::closed_geodesic`).

use super::report::{Picture, Section, Table};
use super::{Ctx, Env};
use ricci::analysis::spectrum::fuchsian_spectrum;
use ricci::analysis::spectrum::trace::closed_geodesic;
use ricci_render::{render, Polyline, RenderOptions, Style, View};
use serde_json::json;

/// Classes drawn.
const DRAWN: usize = 6;
/// Points per geodesic.
const SAMPLES: usize = 600;

const COLOURS: [[f32; 3]; DRAWN] = [
    [0.85, 0.1, 0.1],
    [0.1, 0.35, 0.85],
    [0.05, 0.6, 0.2],
    [0.85, 0.5, 0.0],
    [0.55, 0.1, 0.7],
    [0.0, 0.6, 0.65],
];

pub fn geodesics(ctx: &mut Ctx, env: &mut Env) -> anyhow::Result<Section> {
    let mut sec = Section::new("geodesics", "", "");
    let (Some(d), Some(l), Some(g)) = (&ctx.disk, &ctx.layout, &ctx.group) else {
        anyhow::bail!("no layout");
    };
    let pos = d
        .cut
        .refined
        .positions
        .as_ref()
        .ok_or_else(|| anyhow::anyhow!("the cut lost the positions"))?;
    env.bar.step("shortest closed geodesics on the surface");
    let sp = fuchsian_spectrum(l, &d.polygon, g, DRAWN, 2_000_000)?;
    let faces = d.mesh.faces();
    let mut lines = Vec::new();
    let mut t = Table::new(
        "Closed geodesics drawn",
        &["k", "colour", "length", "points on the surface"],
    );
    for (k, c) in sp.classes.iter().enumerate() {
        let pts = closed_geodesic(&d.mesh, l, &d.polygon, g, &c.representative, SAMPLES)?;
        let points: Vec<[f64; 3]> = pts
            .iter()
            .map(|&(f, b)| {
                let v = faces[f as usize].map(|v| pos[d.vertex_origin[v as usize] as usize]);
                std::array::from_fn(|i| b[0] * v[0][i] + b[1] * v[1][i] + b[2] * v[2][i])
            })
            .collect();
        let col = COLOURS[k % DRAWN];
        t.row(vec![
            (k + 1).to_string(),
            format!(
                "#{:02x}{:02x}{:02x}",
                (col[0] * 255.0) as u8,
                (col[1] * 255.0) as u8,
                (col[2] * 255.0) as u8
            ),
            format!("{:.6}", c.length),
            points.len().to_string(),
        ]);
        lines.push(Polyline {
            points,
            color: col,
            width: 3.0,
            closed: false,
        });
    }
    sec.tables.push(t);
    let st = Style {
        polylines: lines,
        ..Style::default()
    };
    let tris = d.cut.refined.mesh.faces();
    for (file, eye, caption) in [
        (
            "geodesics.png",
            View::default().eye_direction,
            "The shortest closed geodesics of the hyperbolic metric on the surface, front.",
        ),
        (
            "geodesics-back.png",
            [-0.4, -0.3, -1.0],
            "The same geodesics, from behind.",
        ),
    ] {
        let img = render(
            pos,
            tris,
            &st,
            &RenderOptions {
                width: 760,
                height: 520,
                supersample: 3,
                view: View {
                    eye_direction: eye,
                    ..View::default()
                },
                ..RenderOptions::default()
            },
        )?;
        env.out.write(file, &img.image.to_png()?)?;
        sec.pictures.push(Picture {
            file: file.into(),
            caption: caption.into(),
            width: img.image.width,
            height: img.image.height,
            alternatives: Vec::new(),
        });
    }
    sec.paragraphs.push(
        "Each class of the length spectrum is drawn as the axis of its representative deck \
         transformation, walked for one period and mapped back into the fundamental polygon \
         whenever it crosses a side (by the side pairing), then placed on the surface by the \
         barycentric coordinates of its point in the laid-out triangle."
            .into(),
    );
    sec.commands = vec![format!("ricci spectrum surface.off --count {DRAWN}")];
    sec.headline = format!(
        "{} geodesics drawn, lengths {:.4} … {:.4}",
        sp.classes.len(),
        sp.classes.first().map_or(0.0, |c| c.length),
        sp.classes.last().map_or(0.0, |c| c.length)
    );
    sec.summary = json!({
        "lengths": sp.lengths(),
        "samples": SAMPLES,
    });
    Ok(sec)
}
