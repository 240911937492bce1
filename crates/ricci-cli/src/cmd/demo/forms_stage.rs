//! Demo stage `forms`: holomorphic 1-forms of the built-in surface (`ricci forms`,
//! `ricci::analysis::forms`, paper 002 §4.2): the period matrix, the 2g − 2 zeros of ω₁, and
//! its conformal net as a checkerboard on the surface with the zeros circled and the critical
//! horizontal trajectories through them (`ricci::analysis::forms::trajectories`).

use super::report::{Picture, Section, Table};
use super::{Ctx, Env};
use crate::cmd::forms::{critical_lines, net_picture};
use ricci::analysis::forms::{holomorphic_forms, FormsOptions};
use ricci::layout::isometry::Complex;
use ricci::metric::IntrinsicMetric;
use ricci::progress::NoProgress;
use serde_json::json;

/// Checks per unit of the a₁-period of ω₁.
const FORMS_CHECKS: f64 = 12.0;

pub fn forms(ctx: &mut Ctx, env: &mut Env) -> anyhow::Result<Section> {
    let mut sec = Section::new("forms", "", "");
    let s = ctx
        .surface
        .as_ref()
        .ok_or_else(|| anyhow::anyhow!("no surface"))?;
    env.bar
        .step("holomorphic 1-forms: harmonic basis, Hodge star, period matrix, net");
    let h = holomorphic_forms(
        &s.mesh,
        &IntrinsicMetric::euclidean(s.edge_lengths()),
        Some(&s.positions),
        &FormsOptions::default(),
        &mut NoProgress,
    )?;
    let g = h.genus;
    let mut c = vec![Complex::new(0.0, 0.0); g];
    c[0] = Complex::new(1.0, 0.0);
    let w = h.combination(&c);
    let zeros = h.zeros(&w)?;
    let net = h.net(&w)?;
    let cm = &h.cut.cut_mesh;
    let corner_uv: Vec<[f64; 2]> = (0..cm.n_corners() as u32)
        .map(|c| net.uv[cm.corner_vertex(c) as usize])
        .collect();
    let lines = critical_lines(&h, &w, &zeros, 1.0);
    let png = net_picture(&h, &zeros, &corner_uv, FORMS_CHECKS, &lines, None)?;
    env.out.write("forms-net.png", &png)?;
    let size = image_size(&png);
    sec.pictures.push(Picture {
        file: "forms-net.png".into(),
        caption: format!(
            "Conformal net of ω₁ (its integral as a checkerboard, {FORMS_CHECKS} checks per \
             a₁-period): squares everywhere except at the {} zeros (red circles; a zero on the far \
             side of the surface is not in this view), where 2(m + 1) critical horizontal \
             trajectories (blue) meet.",
            zeros.zeros.len()
        ),
        width: size.0,
        height: size.1,
        alternatives: Vec::new(),
    });
    let om = &h.period_matrix;
    let header: Vec<String> = std::iter::once(String::new())
        .chain((1..=g).map(|j| format!("b{j}")))
        .collect();
    let header: Vec<&str> = header.iter().map(|x| x.as_str()).collect();
    let mut t = Table::new("Riemann period matrix Ω (b-periods of ω₁ … ω_g)", &header);
    for i in 0..g {
        let mut row = vec![format!("ω{}", i + 1)];
        row.extend((0..g).map(|j| format!("{:+.5} {:+.5}i", om.re[i][j], om.im[i][j])));
        t.row(row);
    }
    sec.tables.push(t);
    let eig = om.im_eigenvalues()?;
    sec.tables.push(Table::key_values(
        "Checks",
        vec![
            ("Ω − Ωᵀ", format!("{:.1e}", om.asymmetry())),
            ("eigenvalues of Im Ω", format!("{eig:.5?}")),
            (
                "zeros of ω₁ (with multiplicity; 2g − 2)",
                format!("{} (2g − 2 = {})", zeros.count, 2 * g - 2),
            ),
            ("critical trajectories drawn", lines.len().to_string()),
            (
                "net angle distortion p95",
                format!("{:.4}", net.quality.qc_p95),
            ),
            ("Hodge star defect", format!("{:.1e}", h.report.star_defect)),
        ],
    ));
    sec.paragraphs.push(
        "A basis of holomorphic 1-forms ω_i = α_i + i *α_i (harmonic forms dual to the \
         canonical loops and their Hodge stars), normalised on the a-cycles; their b-periods \
         form the period matrix, symmetric with positive definite imaginary part (Riemann's \
         bilinear relations). Integrating ω₁ on the cut surface gives the conformal net."
            .into(),
    );
    sec.commands = vec!["ricci forms surface.off --png forms-net.png --out net.obj --json".into()];
    sec.headline = format!(
        "{} zeros (2g − 2 = {}), |Ω − Ωᵀ| {:.0e}, Im Ω > 0",
        zeros.count,
        2 * g - 2,
        om.asymmetry()
    );
    sec.summary = json!({
        "genus": g, "period_matrix": {"re": om.re, "im": om.im}, "im_eigenvalues": eig,
        "zeros": zeros.zeros, "zero_count": zeros.count,
        "critical_trajectories": lines.len(), "qc_p95": net.quality.qc_p95,
    });
    Ok(sec)
}

/// Width and height from a PNG header.
fn image_size(png: &[u8]) -> (u32, u32) {
    let be = |i: usize| {
        png.get(i..i + 4)
            .map(|b| u32::from_be_bytes([b[0], b[1], b[2], b[3]]))
            .unwrap_or(0)
    };
    (be(16), be(20))
}
