//! Stage `loops`: a canonical system of loops through a base vertex and the cut that opens
//! the surface into a disk (paper 001 §V, paper 002 §4.3.2).

use super::common::*;
use super::report::{num, Section, Table};
use super::Env;
use crate::cmd::cut::cut_obj;
use ricci::layout::pipeline::cut_disk;
use ricci::mesh::topology;
use ricci::metric::{Geometry, IntrinsicMetric};
use ricci_render::{render, Polyline, Style, View};
use serde_json::json;

pub fn loops(ctx: &mut Ctx, env: &mut Env) -> anyhow::Result<Section> {
    let mut sec = Section::new("loops", "", "");
    let s = ctx.surface()?;
    let h = ctx
        .hyperbolic
        .as_ref()
        .ok_or_else(|| anyhow::anyhow!("no hyperbolic metric"))?;
    let d = cut_disk(
        &s.mesh,
        &IntrinsicMetric::new(Geometry::Hyperbolic, h.lengths.clone()),
        Some(&s.positions),
        None,
        env.bar,
    )?;
    env.bar.step("pictures");
    let c = &d.cut;
    let pos = c
        .refined
        .positions
        .as_ref()
        .ok_or_else(|| anyhow::anyhow!("the cut lost the positions"))?;
    let letters = &d.polygon.letters;
    let lines: Vec<Polyline> = c
        .loops
        .iter()
        .map(|l| Polyline {
            points: l.vertices.iter().map(|&v| pos[v as usize]).collect(),
            color: generator_color(letters, &l.label),
            width: 3.5,
            closed: l.vertices.first() != l.vertices.last(),
        })
        .collect();
    let mut lines = lines;
    lines.push(base_marker(pos, c.refined.mesh.faces(), c.base));
    let st = Style {
        polylines: lines,
        ..Style::default()
    };
    for (file, view, caption) in [
        (
            "loops.png",
            View::default(),
            "The loops a1 b1 a2 b2 through the base vertex (black ring; colours as in the polygon), front.",
        ),
        (
            "loops-base.png",
            View {
                eye_direction: {
                    let n = ricci_render::render::vertex_normals(pos, c.refined.mesh.faces())
                        .get(c.base as usize)
                        .copied()
                        .unwrap_or([0.0, 0.0, 1.0]);
                    [n[0], n[1], n[2] + 0.8]
                },
                ..View::default()
            },
            "The same loops seen from above the base vertex, where all eight sides meet.",
        ),
    ] {
        let img = render(pos, c.refined.mesh.faces(), &st, &opts(view))?;
        sec.pictures.push(png(env, file, &img.image, caption)?);
    }
    env.out.write("cut.obj", cut_obj(c).as_bytes())?;
    let disk_ok = {
        let t = topology(&c.cut_mesh);
        t.components.len() == 1 && t.euler_characteristic() == 1 && t.boundary_loops() == 1
    };
    sec.paragraphs.push(format!(
        "A canonical system of loops through base vertex {}: cutting along them opens the \
         surface into a disk whose boundary reads {} ({} sides). The base vertex first gets \
         valence ≥ {} by metric-preserving splits ({} splits). Loop lengths are measured in the \
         hyperbolic metric of the previous stage.",
        c.base,
        c.boundary_word,
        c.polygon.len(),
        c.report.min_valence,
        c.report.refinement_splits
    ));
    let mut lt = Table::new("Loops", &["loop", "edges", "hyperbolic length"]);
    for l in &c.loops {
        lt.row(vec![
            l.label.clone(),
            l.halfedges.len().to_string(),
            num(l.length),
        ]);
    }
    sec.tables.push(lt);
    let labels: Vec<&str> = c.loops.iter().map(|l| l.label.as_str()).collect();
    let mut header = vec!["·"];
    header.extend(labels.iter().copied());
    let mut it = Table::new("Algebraic intersection numbers", &header);
    for (i, row) in c.intersection_matrix.iter().enumerate() {
        let mut cells = vec![labels.get(i).copied().unwrap_or("?").to_string()];
        cells.extend(row.iter().map(|x| x.to_string()));
        it.row(cells);
    }
    sec.tables.push(it);
    sec.tables.push(Table::key_values(
        "Cut",
        vec![
            ("boundary word", c.boundary_word.clone()),
            ("polygon sides", c.polygon.len().to_string()),
            ("base vertex", c.base.to_string()),
            (
                "valence of the base",
                format!("{} → {}", c.report.valence_before, c.report.valence_after),
            ),
            (
                "cut mesh (V / F)",
                format!("{} / {}", c.cut_mesh.n_vertices(), c.cut_mesh.n_faces()),
            ),
            ("cut mesh is a disk", disk_ok.to_string()),
            ("time (s)", format!("{:.3}", c.report.seconds)),
        ],
    ));
    sec.files = vec![(
        "cut.obj".into(),
        "the cut mesh, each polygon side an `l` polyline group (as `ricci cut` writes it)".into(),
    )];
    sec.summary = json!({
        "genus": c.genus,
        "base_vertex": c.base,
        "boundary_word": c.boundary_word,
        "polygon_sides": c.polygon.len(),
        "loops": c.loops.iter().map(|l| json!({"label": l.label, "edges": l.halfedges.len(), "length": l.length})).collect::<Vec<_>>(),
        "intersection_matrix": c.intersection_matrix,
        "disk": disk_ok,
        "refinement_splits": c.report.refinement_splits,
        "cut_vertices": c.cut_mesh.n_vertices(),
        "cut_faces": c.cut_mesh.n_faces(),
    });
    sec.commands =
        vec!["ricci cut surface.off --metric hyperbolic-metric.json --out cut.obj".into()];
    sec.headline = format!("boundary word `{}`", c.boundary_word);
    ctx.disk = Some(d);
    Ok(sec)
}
