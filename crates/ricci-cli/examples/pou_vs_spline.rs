//! The partition-of-unity surface (paper 004, `ricci pou`) side by side with the manifold
//! spline (paper 000, `ricci spline`) on the same meshes: fitting error, zebra pictures from
//! the same view, smoothness at the spline's extraordinary point, time.
//!
//! `RICCI_MESHES=/work/shared/meshes cargo run --release -p ricci-cli --example pou_vs_spline -- OUT_DIR [files…]`
//! (default: eight.off 3holes.off fertility.off). Writes `OUT_DIR/NAME-pou-zebra.png` and
//! `OUT_DIR/NAME-spline-zebra.png` (same camera: the default view, and a second one looking
//! at the spline's extraordinary point) and prints a Markdown table. Smoothness at the
//! extraordinary point: the spline's G¹ fill (its normal jump along the seam, and its
//! order-3 jump everywhere, a cubic being C²) against the pou surface's jumps of orders 0–3
//! across chart boundaries on the edges around the same vertex.

use ricci::mesh::io::read_surface;
use ricci::progress::NoProgress;
use ricci::spline::pou::measure::{continuity_on_edges, edges_near_vertex};
use ricci::spline::pou::{run as run_pou, PouOptions};
use ricci::spline::surface::{
    flat_domain, run as run_spline, MeshDistance, Singularity, SplineOptions,
};
use ricci_render::{render, Paint, RenderOptions, Style, View, Zebra};
use std::path::PathBuf;
use std::time::Instant;

fn zebra(
    pos: &[[f64; 3]],
    tris: &[[u32; 3]],
    view: View,
    file: &std::path::Path,
) -> anyhow::Result<()> {
    let st = Style {
        paint: Paint::Zebra(Zebra {
            stripes: 10.0,
            ..Zebra::default()
        }),
        ..Style::default()
    };
    let o = RenderOptions {
        width: 700,
        height: 700,
        supersample: 2,
        view,
        ..RenderOptions::default()
    };
    let img = render(pos, tris, &st, &o)?;
    std::fs::write(file, img.image.to_png()?)?;
    Ok(())
}

fn main() -> anyhow::Result<()> {
    let dir = PathBuf::from(
        std::env::var("RICCI_MESHES").unwrap_or_else(|_| "/work/shared/meshes".into()),
    );
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    if args.is_empty() {
        anyhow::bail!("usage: pou_vs_spline OUT_DIR [meshes…]");
    }
    let out = PathBuf::from(args.remove(0));
    std::fs::create_dir_all(&out)?;
    if args.is_empty() {
        args = ["eight.off", "3holes.off", "fertility.off"]
            .map(String::from)
            .to_vec();
    }
    println!("| mesh | method | control points | rms % | max % | jumps 0 / 1 / 2 / 3 (everywhere) | at the spline's extraordinary point | wall s |");
    println!("|---|---|---:|---:|---:|---|---|---:|");
    for name in &args {
        let (surface, _) = read_surface(&dir.join(name))?;
        let stem = name.trim_end_matches(".off");
        // Spline.
        let t = Instant::now();
        let dom = flat_domain(&surface, Singularity::Auto, &mut NoProgress)?;
        let dist = MeshDistance::new(&surface.positions, surface.mesh.faces());
        let (srep, stess, _) = run_spline(
            &dom.charts,
            &dist,
            &SplineOptions::default(),
            8,
            &mut NoProgress,
        )?;
        let t_spline = t.elapsed().as_secs_f64();
        // Partition of unity.
        let t = Instant::now();
        let popts = PouOptions {
            tessellation: 8,
            ..PouOptions::default()
        };
        let (prep, ptess, c) = run_pou(&surface, &popts, &mut NoProgress)?;
        let t_pou = t.elapsed().as_secs_f64();
        let sing = dom.singular;
        let near = match sing {
            Some(v) if (v as usize) < surface.mesh.n_vertices() => {
                let s = c.surface();
                let edges = edges_near_vertex(&s, v);
                let j = continuity_on_edges(&s, &edges)?;
                format!(
                    "vertex {v}: jumps {} on {} edges around it; no special point",
                    j.relative
                        .iter()
                        .map(|x| format!("{x:.0e}"))
                        .collect::<Vec<_>>()
                        .join(" / "),
                    edges.len()
                )
            }
            _ => "–".into(),
        };
        let e = |v: &[f64]| {
            v.iter()
                .map(|x| format!("{x:.0e}"))
                .collect::<Vec<_>>()
                .join(" / ")
        };
        println!(
            "| {stem} | pou (local quadratics) | {} | {:.3} | {:.3} | {} | {near} | {t_pou:.1} |",
            prep.control_points,
            prep.rms_error_percent,
            prep.max_error_percent,
            e(&prep.continuity.relative_jumps)
        );
        println!(
            "| {stem} | spline (degree {}, r = {}) | {} | {:.3} | {:.3} | {} | vertex {}: G¹ fill, normal jump {:.1e}° along its seam | {t_spline:.1} |",
            srep.degree,
            srep.fairness,
            srep.control_points,
            srep.rms_error_percent,
            srep.max_error_percent,
            e(&srep.continuity.relative_jumps),
            sing.map(|v| v.to_string()).unwrap_or_else(|| "–".into()),
            srep.continuity.max_seam_normal_jump_deg
        );
        // Zebra pictures: the default view, and a view onto the extraordinary point.
        let mut views = vec![("", View::default())];
        if let Some(v) = sing {
            // Look along the surface normal at the extraordinary point (area-weighted sum of
            // the normals of its faces).
            let mut n = [0.0; 3];
            for f in surface.mesh.vertex_faces(v) {
                let [a, b, c] = surface.mesh.face(f).map(|x| surface.positions[x as usize]);
                let (u, w) = (
                    [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
                    [c[0] - a[0], c[1] - a[1], c[2] - a[2]],
                );
                n[0] += u[1] * w[2] - u[2] * w[1];
                n[1] += u[2] * w[0] - u[0] * w[2];
                n[2] += u[0] * w[1] - u[1] * w[0];
            }
            views.push((
                "-singular",
                View {
                    eye_direction: n,
                    ..View::default()
                },
            ));
        }
        for (suffix, view) in views {
            zebra(
                &ptess.positions,
                &ptess.triangles,
                view,
                &out.join(format!("{stem}-pou-zebra{suffix}.png")),
            )?;
            zebra(
                &stess.positions,
                &stess.triangles,
                view,
                &out.join(format!("{stem}-spline-zebra{suffix}.png")),
            )?;
        }
    }
    Ok(())
}
