//! Stage `layout`: the cut surface laid out isometrically in the Poincaré disk, its deck group
//! (a Fuchsian group), a tiling of the universal cover and the checkerboard on the surface
//! (paper 001 §V–VI, paper 002 §4.3.3).

use super::common::*;
use super::report::{Picture, Section, Status, Table};
use super::Env;
use ricci::layout::cover::{tiles_by_radius, word_string, Tile};
use ricci::layout::export::obj_with_uv;
use ricci::layout::isometry::Complex;
use ricci::layout::pipeline::CutDisk;
use ricci::layout::place::{layout as place, minimax_centre};
use ricci::layout::{deck_group, DeckGroup, Isometry, Layout, Mobius};
use ricci::metric::Hyperbolic;
use ricci_render::plot::{layout_figure, Item, LayoutCopy, LayoutPlot, Side};
use ricci_render::render::Uvs;
use ricci_render::{color, gltf, render, Checker, Paint, Style, View};
use serde_json::json;

pub fn layout(ctx: &mut Ctx, env: &mut Env) -> anyhow::Result<Section> {
    let mut sec = Section::new("layout", "", "");
    let d = ctx.disk.as_ref().ok_or_else(|| anyhow::anyhow!("no cut"))?;
    env.bar.step("layout in the Poincaré disk");
    let l = place::<Hyperbolic>(&d.mesh, &d.metric, None)?;
    env.bar.step("deck group");
    let g = deck_group::<Hyperbolic>(&l, &d.polygon)?;
    let relation_error = g
        .relation_error
        .ok_or_else(|| anyhow::anyhow!("the deck group relation could not be evaluated"))?;
    let uv: Vec<[f64; 2]> = l.positions.iter().map(|z| [z.re, z.im]).collect();
    env.bar.step("pictures of the polygon");
    let mut plot = LayoutPlot::new(LayoutCopy::new(&uv, d.mesh.faces()));
    plot.sides = polygon_sides(d, &l, &Mobius::identity(), true);
    plot.disk = true;
    plot.title = "Fundamental polygon".into();
    plot.size = 720.0;
    let fig = layout_figure(&plot)?;
    sec.pictures.push(figure(
        env,
        "polygon",
        &fig,
        &format!("The cut surface laid out isometrically in the Poincaré disk: the polygon {}, sides coloured by generator.", d.polygon.word()),
        true,
    )?);

    env.bar.step(&format!("tiling with {TILES} copies"));
    let (tiling, tiles) = tiling_picture(env, d, &l, &g, &uv)?;
    sec.pictures.push(tiling);

    env.bar.step("checkerboard, uv.obj and surface.glb");
    checker_pictures_and_files(&mut sec, env, d, &uv)?;

    let flipped = l.flipped_faces.len();
    if flipped > 0 {
        sec.status = Status::Warning(format!("{flipped} faces are flipped in the layout"));
    }
    sec.paragraphs.push(format!(
        "The cut mesh is laid out face by face in the Poincaré disk with the hyperbolic edge \
         lengths; the Möbius maps pairing its sides generate the deck group, a Fuchsian group. \
         Its relation a1 b1 a1⁻¹ b1⁻¹ a2 b2 a2⁻¹ b2⁻¹ = id holds to {relation_error:.1e} \
         (double-precision layout; `ricci layout` without `--no-polish` polishes the metric \
         and the layout in double-double and reaches ~1e-28)."
    ));
    let (gt, gens_json) = generators_table(&g);
    sec.tables.push(gt);
    sec.tables.push(Table::key_values(
        "Layout",
        vec![
            ("relation error", format!("{relation_error:.3e}")),
            (
                "max side-pairing spread",
                format!("{:.3e}", g.max_edge_spread),
            ),
            (
                "max edge length error",
                format!("{:.3e}", l.max_length_error),
            ),
            ("flipped faces", flipped.to_string()),
            ("seed face", l.seed_face.to_string()),
            ("tiles drawn", tiles.len().to_string()),
        ],
    ));
    sec.files = vec![
        (
            "uv.obj".into(),
            "the surface with Poincaré-disk texture coordinates (as `ricci layout --out` writes it)"
                .into(),
        ),
        (
            "surface.glb".into(),
            "glTF binary with the UVs and an embedded checker texture, for any glTF viewer".into(),
        ),
    ];
    sec.summary = json!({
        "geometry": "hyperbolic",
        "flipped_faces": flipped,
        "relation_error": relation_error,
        "relation_condition": g.relation_condition,
        "max_edge_spread": g.max_edge_spread,
        "max_length_error": l.max_length_error,
        "seed_face": l.seed_face,
        "deck_generators": gens_json,
        "tiles": tiles.len(),
        "tile_words": tiles.iter().take(12).map(|t| word_string(&g.letters, &t.word)).collect::<Vec<_>>(),
        "boundary_word": d.polygon.word(),
    });
    sec.commands = vec![
        // The same metric and the same double-precision layout (without --no-polish the
        // command polishes the metric and the layout in double-double: relation error
        // ~1e-28 instead of the ~1e-12 shown here).
        "ricci layout surface.off --metric hyperbolic-metric.json --no-polish --out uv.obj --svg polygon.svg".into(),
        format!("ricci layout surface.off --metric hyperbolic-metric.json --no-polish --tiling {TILES} --svg tiling.svg"),
    ];
    sec.headline = format!(
        "relation error {relation_error:.1e}, {flipped} flipped faces, {} copies tiled",
        tiles.len()
    );
    ctx.layout = Some(l);
    ctx.group = Some(g);
    Ok(sec)
}

/// The polygon's sides under the deck transformation `map`, coloured by generator (labelled
/// for the fundamental domain only).
fn polygon_sides(d: &CutDisk, l: &Layout<Complex>, map: &Mobius, labelled: bool) -> Vec<Side> {
    let letters = &d.polygon.letters;
    d.polygon
        .sides
        .iter()
        .map(|s| Side {
            points: s
                .vertices
                .iter()
                .map(|&v| {
                    let z = map.apply(l.positions[v as usize]);
                    [z.re, z.im]
                })
                .collect(),
            color: generator_color(letters, &s.label),
            label: if labelled {
                s.label.clone()
            } else {
                String::new()
            },
        })
        .collect()
}

/// Copies of the polygon under the deck group, breadth first: the fundamental domain with
/// its triangles, every other copy as one filled polygon under its sides, tinted by its word
/// so that neighbours differ.
fn tiling_picture(
    env: &mut Env,
    d: &CutDisk,
    l: &Layout<Complex>,
    g: &DeckGroup<Mobius>,
    uv: &[[f64; 2]],
) -> anyhow::Result<(Picture, Vec<Tile<Mobius>>)> {
    // Tiling: copies of the polygon (as a fan around the image of its centre), breadth first.
    let centre = minimax_centre::<Hyperbolic>(&l.positions);
    let tiles = tiles_by_radius::<Hyperbolic>(g, &d.polygon, centre, 12.0, TILES)?;
    let boundary: Vec<u32> = d
        .polygon
        .sides
        .iter()
        .flat_map(|s| {
            s.vertices[..s.vertices.len().saturating_sub(1)]
                .iter()
                .copied()
        })
        .collect();
    // The fundamental domain with its triangles; every other copy as one filled polygon
    // under its sides, tinted by its word so that neighbours differ.
    let mut tp = LayoutPlot::new(LayoutCopy::new(uv, d.mesh.faces()));
    tp.sides = tiles
        .iter()
        .enumerate()
        .flat_map(|(i, t)| polygon_sides(d, l, &t.map, i == 0))
        .collect();
    tp.disk = true;
    tp.title = format!("{} copies of the polygon", tiles.len());
    tp.size = 720.0;
    let mut fig = layout_figure(&tp)?;
    // Disk pictures start with the disk itself: its centre and radius give the frame.
    let frame = match fig.items.first() {
        Some(Item::Circle { center, radius, .. }) => Some((*center, *radius)),
        _ => None,
    };
    if let Some((c, r)) = frame {
        let mut by_depth: std::collections::BTreeMap<usize, Vec<Vec<[f64; 2]>>> =
            Default::default();
        for t in tiles.iter().skip(1) {
            let pts = boundary
                .iter()
                .map(|&v| {
                    let z = t.map.apply(l.positions[v as usize]);
                    [c[0] + r * z.re, c[1] - r * z.im]
                })
                .collect();
            // Neighbouring copies differ in the last letter of their words (or its sign).
            let last = t.word.last().map_or(0, |&(l, inv)| 2 * l + inv as usize);
            by_depth
                .entry((last + t.word.len()) % 8)
                .or_default()
                .push(pts);
        }
        for (k, (tint, polygons)) in by_depth.into_iter().enumerate() {
            fig.items.insert(
                1 + k,
                Item::Polygons {
                    polygons,
                    fill: Some(color::tint(color::categorical(tint), 0.75)),
                    stroke: None,
                    stroke_width: 0.0,
                    class: "tiles",
                },
            );
        }
    }
    let picture = figure(
        env,
        "tiling",
        &fig,
        "A part of the universal cover: images of the polygon under the deck group (the unit circle is the circle at infinity).",
        false,
    )?;
    Ok((picture, tiles))
}

/// Checkerboard of the hyperbolic layout on the (refined) surface, front and back, and the
/// files `uv.obj` and `surface.glb`.
fn checker_pictures_and_files(
    sec: &mut Section,
    env: &mut Env,
    d: &CutDisk,
    uv: &[[f64; 2]],
) -> anyhow::Result<()> {
    // Checkerboard of the hyperbolic layout on the (refined) surface, uv.obj and a glTF.
    let c = &d.cut;
    let pos = c
        .refined
        .positions
        .as_ref()
        .ok_or_else(|| anyhow::anyhow!("the cut lost the positions"))?;
    let faces = c.refined.mesh.faces();
    let corner_uv: Vec<[f64; 2]> = d
        .mesh
        .faces()
        .iter()
        .flat_map(|t| t.iter().map(|&v| uv[v as usize]))
        .collect();
    for (file, view, caption) in [
        (
            "checker.png",
            View::default(),
            "Checkerboard of the Poincaré-disk coordinates on the surface. The map is conformal: in the small the checks are squares (angles are kept), but their size follows the conformal factor — they grow on the surface where the polygon's spikes reach towards the unit circle, which the disk model compresses.",
        ),
        ("checker-back.png", back_view(), "The same texture from behind."),
    ] {
        let st = Style {
            paint: Paint::Checker(Checker::new(Uvs::PerCorner(&corner_uv), CHECKS)),
            ..Style::default()
        };
        let img = render(pos, faces, &st, &opts(view))?;
        sec.pictures.push(png(env, file, &img.image, caption)?);
    }
    let obj = obj_with_uv(
        pos,
        faces,
        uv,
        d.mesh.faces(),
        &[
            "ricci demo: the genus-2 surface with its hyperbolic layout".to_string(),
            "vt: Poincaré-disk coordinates of the cut mesh".to_string(),
        ],
    );
    env.out.write("uv.obj", obj.as_bytes())?;
    let glb = gltf::glb(
        pos,
        faces,
        &gltf::GlbOptions {
            uvs: Some(Uvs::PerCorner(&corner_uv)),
            checker_frequency: Some(CHECKS),
            colors: None,
            name: Some("genus2".into()),
        },
    )?;
    env.out.write("surface.glb", &glb)?;
    Ok(())
}

/// The deck generators z ↦ (az + b)/(b̄z + ā) as a table and as JSON.
fn generators_table(g: &DeckGroup<Mobius>) -> (Table, Vec<serde_json::Value>) {
    let mut gt = Table::new(
        "Deck generators z ↦ (az + b)/(b̄z + ā)",
        &[
            "generator",
            "a",
            "b",
            "|a|² − |b|²",
            "trace",
            "translation length",
        ],
    );
    let mut gens_json = Vec::new();
    for (name, m) in g.named_generators() {
        let det = m.a.norm_sqr() - m.b.norm_sqr();
        gt.row(vec![
            name.clone(),
            format!("{:.6} {:+.6}i", m.a.re, m.a.im),
            format!("{:.6} {:+.6}i", m.b.re, m.b.im),
            format!("{det:.12}"),
            format!("{:.6}", m.trace()),
            format!("{:.6}", m.translation_length()),
        ]);
        gens_json.push(json!({
            "letter": name, "a": [m.a.re, m.a.im], "b": [m.b.re, m.b.im],
            "trace": m.trace(), "translation_length": m.translation_length(),
        }));
    }
    (gt, gens_json)
}
