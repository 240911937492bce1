//! Writers for CAD systems: the bicubic Bézier patches of a T-spline ([`super::bezier`]) as
//! STEP AP214 (ISO 10303-21; each patch a `B_SPLINE_SURFACE_WITH_KNOTS` of degree 3×3 with
//! knots `(u0, u1)`, `(v0, v1)` of multiplicity 4 — the patch keeps the T-spline's parameters —
//! bounded by its four boundary curves in an `ADVANCED_FACE`, all faces in one `OPEN_SHELL`),
//! as IGES 5.3 (one rational B-spline surface, entity 128, per patch, weights 1), and the
//! tessellation as OBJ.

use super::bezier::BezierPatch;
use std::fmt::Write as _;

/// A real in a form both STEP and IGES read back exactly (17 significant digits, a decimal
/// point always present).
fn real(x: f64) -> String {
    let x = if x == 0.0 { 0.0 } else { x };
    format!("{x:.16E}")
}

/// The STEP AP214 text of the patches (`name` goes into the header and the product).
pub fn step(patches: &[BezierPatch], name: &str) -> String {
    let mut s = String::new();
    let name = name.replace('\'', "");
    let _ = write!(
        s,
        "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION(('ricci manifold T-spline (bicubic Bezier patches)'),'2;1');\n\
         FILE_NAME('{name}','2026-01-01T00:00:00',(''),(''),'ricci','ricci','');\n\
         FILE_SCHEMA(('AUTOMOTIVE_DESIGN {{ 1 0 10303 214 1 1 1 1 }}'));\nENDSEC;\nDATA;\n"
    );
    let mut id = 0usize;
    let mut ent = |s: &mut String, body: String| -> usize {
        id += 1;
        let _ = writeln!(s, "#{id}={body};");
        id
    };
    let app = ent(&mut s, "APPLICATION_CONTEXT('automotive design')".into());
    ent(
        &mut s,
        format!("APPLICATION_PROTOCOL_DEFINITION('international standard','automotive_design',2000,#{app})"),
    );
    let pc = ent(&mut s, format!("PRODUCT_CONTEXT('',#{app},'mechanical')"));
    let prod = ent(&mut s, format!("PRODUCT('{name}','{name}','',(#{pc}))"));
    let pdc = ent(
        &mut s,
        format!("PRODUCT_DEFINITION_CONTEXT('part definition',#{app},'design')"),
    );
    let pdf = ent(
        &mut s,
        format!("PRODUCT_DEFINITION_FORMATION('','',#{prod})"),
    );
    let pd = ent(
        &mut s,
        format!("PRODUCT_DEFINITION('design','',#{pdf},#{pdc})"),
    );
    let pds = ent(&mut s, format!("PRODUCT_DEFINITION_SHAPE('','',#{pd})"));
    let lu = ent(
        &mut s,
        "(LENGTH_UNIT()NAMED_UNIT(*)SI_UNIT(.MILLI.,.METRE.))".into(),
    );
    let au = ent(
        &mut s,
        "(NAMED_UNIT(*)PLANE_ANGLE_UNIT()SI_UNIT($,.RADIAN.))".into(),
    );
    let su = ent(
        &mut s,
        "(NAMED_UNIT(*)SI_UNIT($,.STERADIAN.)SOLID_ANGLE_UNIT())".into(),
    );
    let unc = ent(
        &mut s,
        format!("UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE(1.E-09),#{lu},'distance_accuracy_value','confusion accuracy')"),
    );
    let ctx = ent(
        &mut s,
        format!(
            "(GEOMETRIC_REPRESENTATION_CONTEXT(3)GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT((#{unc}))\
             GLOBAL_UNIT_ASSIGNED_CONTEXT((#{lu},#{au},#{su}))REPRESENTATION_CONTEXT('Context #1','3D Context with UNIT and UNCERTAINTY'))"
        ),
    );
    let o = ent(&mut s, "CARTESIAN_POINT('',(0.,0.,0.))".into());
    let z = ent(&mut s, "DIRECTION('',(0.,0.,1.))".into());
    let x = ent(&mut s, "DIRECTION('',(1.,0.,0.))".into());
    let axis = ent(&mut s, format!("AXIS2_PLACEMENT_3D('',#{o},#{z},#{x})"));
    let mut faces = Vec::with_capacity(patches.len());
    for p in patches {
        let mut cp = [[0usize; 4]; 4];
        for i in 0..4 {
            for j in 0..4 {
                let c = p.control[i][j];
                cp[i][j] = ent(
                    &mut s,
                    format!(
                        "CARTESIAN_POINT('',({},{},{}))",
                        real(c[0]),
                        real(c[1]),
                        real(c[2])
                    ),
                );
            }
        }
        let rows: Vec<String> = (0..4)
            .map(|i| format!("(#{},#{},#{},#{})", cp[i][0], cp[i][1], cp[i][2], cp[i][3]))
            .collect();
        let surf = ent(
            &mut s,
            format!(
                "B_SPLINE_SURFACE_WITH_KNOTS('',3,3,({}),.UNSPECIFIED.,.F.,.F.,.F.,(4,4),(4,4),({},{}),({},{}),.UNSPECIFIED.)",
                rows.join(","),
                real(p.u0),
                real(p.u1),
                real(p.v0),
                real(p.v1)
            ),
        );
        // corners counter-clockwise in (u, v): 00, 30, 33, 03
        let corner_ids = [(0, 0), (3, 0), (3, 3), (0, 3)];
        let verts: Vec<usize> = corner_ids
            .iter()
            .map(|&(i, j)| ent(&mut s, format!("VERTEX_POINT('',#{})", cp[i][j])))
            .collect();
        let sides: [[usize; 4]; 4] = [
            [cp[0][0], cp[1][0], cp[2][0], cp[3][0]],
            [cp[3][0], cp[3][1], cp[3][2], cp[3][3]],
            [cp[3][3], cp[2][3], cp[1][3], cp[0][3]],
            [cp[0][3], cp[0][2], cp[0][1], cp[0][0]],
        ];
        let mut oes = Vec::with_capacity(4);
        for k in 0..4 {
            let c = sides[k];
            let curve = ent(
                &mut s,
                format!(
                    "B_SPLINE_CURVE_WITH_KNOTS('',3,(#{},#{},#{},#{}),.UNSPECIFIED.,.F.,.F.,(4,4),(0.,1.),.UNSPECIFIED.)",
                    c[0], c[1], c[2], c[3]
                ),
            );
            let e = ent(
                &mut s,
                format!(
                    "EDGE_CURVE('',#{},#{},#{curve},.T.)",
                    verts[k],
                    verts[(k + 1) % 4]
                ),
            );
            oes.push(ent(&mut s, format!("ORIENTED_EDGE('',*,*,#{e},.T.)")));
        }
        let lp = ent(
            &mut s,
            format!(
                "EDGE_LOOP('',(#{},#{},#{},#{}))",
                oes[0], oes[1], oes[2], oes[3]
            ),
        );
        let b = ent(&mut s, format!("FACE_OUTER_BOUND('',#{lp},.T.)"));
        faces.push(ent(&mut s, format!("ADVANCED_FACE('',(#{b}),#{surf},.T.)")));
    }
    let list: Vec<String> = faces.iter().map(|f| format!("#{f}")).collect();
    let shell = ent(&mut s, format!("OPEN_SHELL('',({}))", list.join(",")));
    let model = ent(&mut s, format!("SHELL_BASED_SURFACE_MODEL('',(#{shell}))"));
    let rep = ent(
        &mut s,
        format!("MANIFOLD_SURFACE_SHAPE_REPRESENTATION('{name}',(#{axis},#{model}),#{ctx})"),
    );
    ent(
        &mut s,
        format!("SHAPE_DEFINITION_REPRESENTATION(#{pds},#{rep})"),
    );
    s.push_str("ENDSEC;\nEND-ISO-10303-21;\n");
    s
}

fn hollerith(t: &str) -> String {
    format!("{}H{}", t.len(), t)
}

/// Lines of a fixed-format IGES section: `text` (≤ 72 columns), section letter, sequence.
fn iges_line(out: &mut String, text: &str, letter: char, seq: usize) {
    let _ = writeln!(out, "{text:<72}{letter}{seq:>7}");
}

/// The IGES 5.3 text of the patches: one entity 128 per patch (untrimmed, natural bounds).
pub fn iges(patches: &[BezierPatch], name: &str) -> String {
    let mut out = String::new();
    iges_line(
        &mut out,
        "ricci manifold T-spline: bicubic Bezier patches (entity 128)",
        'S',
        1,
    );
    let name: String = name
        .chars()
        .filter(|c| c.is_ascii_alphanumeric() || *c == '_' || *c == '-' || *c == '.')
        .collect();
    let name = if name.is_empty() {
        "tspline".to_string()
    } else {
        name
    };
    let mut max_coord = 0.0f64;
    for p in patches {
        for row in &p.control {
            for c in row {
                max_coord = max_coord.max(c[0].abs()).max(c[1].abs()).max(c[2].abs());
            }
        }
    }
    let global = [
        "1H,".to_string(),
        "1H;".to_string(),
        hollerith(&name),
        hollerith(&format!("{name}.igs")),
        hollerith("ricci"),
        hollerith("ricci"),
        "32".into(),
        "38".into(),
        "6".into(),
        "308".into(),
        "15".into(),
        hollerith(&name),
        "1.0".into(),
        "2".into(),
        hollerith("MM"),
        "1".into(),
        "1.0".into(),
        hollerith("20260101.000000"),
        "1.0E-9".into(),
        real(max_coord),
        hollerith("ricci"),
        hollerith("ricci"),
        "11".into(),
        "0".into(),
    ];
    let mut gseq = 0;
    let mut line = String::new();
    let n = global.len();
    for (i, t) in global.iter().enumerate() {
        let t = format!("{t}{}", if i + 1 == n { ";" } else { "," });
        if line.len() + t.len() > 72 {
            gseq += 1;
            iges_line(&mut out, &line, 'G', gseq);
            line.clear();
        }
        line.push_str(&t);
    }
    gseq += 1;
    iges_line(&mut out, &line, 'G', gseq);
    // parameter data first (to know the line counts), then the directory
    let mut pdata = String::new();
    let mut dir = String::new();
    let mut pseq = 0usize;
    for (k, p) in patches.iter().enumerate() {
        let de = 2 * k + 1;
        let mut tok: Vec<String> =
            vec!["128".into(), "3".into(), "3".into(), "3".into(), "3".into()];
        tok.extend(["0", "0", "1", "0", "0"].iter().map(|s| s.to_string()));
        for t in [p.u0, p.u0, p.u0, p.u0, p.u1, p.u1, p.u1, p.u1] {
            tok.push(real(t));
        }
        for t in [p.v0, p.v0, p.v0, p.v0, p.v1, p.v1, p.v1, p.v1] {
            tok.push(real(t));
        }
        tok.extend(std::iter::repeat_n("1.0".to_string(), 16));
        // control points: the first (u) index varies fastest
        for j in 0..4 {
            for i in 0..4 {
                for d in 0..3 {
                    tok.push(real(p.control[i][j][d]));
                }
            }
        }
        tok.extend([real(p.u0), real(p.u1), real(p.v0), real(p.v1)]);
        let first = pseq + 1;
        let mut line = String::new();
        let n = tok.len();
        for (i, t) in tok.into_iter().enumerate() {
            let t = t + if i + 1 == n { ";" } else { "," };
            if line.len() + t.len() > 64 {
                pseq += 1;
                let _ = writeln!(pdata, "{line:<64} {de:>7}P{pseq:>7}");
                line.clear();
            }
            line.push_str(&t);
        }
        pseq += 1;
        let _ = writeln!(pdata, "{line:<64} {de:>7}P{pseq:>7}");
        let count = pseq + 1 - first;
        let _ = writeln!(
            dir,
            "{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}D{:>7}",
            128, first, 0, 0, 0, 0, 0, 0, "00000000", de
        );
        let _ = writeln!(
            dir,
            "{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}D{:>7}",
            128,
            0,
            0,
            count,
            0,
            "",
            "",
            "PATCH",
            k + 1,
            de + 1
        );
    }
    out.push_str(&dir);
    out.push_str(&pdata);
    let term = format!("S{:>7}G{:>7}D{:>7}P{:>7}", 1, gseq, 2 * patches.len(), pseq);
    iges_line(&mut out, &term, 'T', 1);
    out
}

/// The patches tessellated on a `k × k` grid each, as OBJ (vertices not shared between
/// patches; see [`torus_obj`] for one closed welded mesh).
pub fn obj(patches: &[BezierPatch], k: usize) -> String {
    let whole: Vec<(Vec<f64>, Vec<f64>)> = patches
        .iter()
        .map(|p| (vec![p.u0, p.u1], vec![p.v0, p.v1]))
        .collect();
    obj_with_breaks(patches, &whole, k)
}

/// The points `k` segments apart in every interval of the increasing `breaks`.
fn tessellation_params(breaks: &[f64], k: usize) -> Vec<f64> {
    let mut out = Vec::with_capacity(k * breaks.len());
    for w in breaks.windows(2) {
        for s in 0..k {
            out.push(w[0] + (w[1] - w[0]) * s as f64 / k as f64);
        }
    }
    out.extend(breaks.last());
    out
}

/// The patches tessellated with `k` segments between consecutive breaks of each,
/// `breaks[p] = (us, vs)` from the patch's first to its last parameter: with the cells a Bézier
/// element covers as its breaks, neighbouring elements have the same tessellation points
/// along their common sides (the OBJ welds into one closed surface where the cells do).
pub fn obj_with_breaks(
    patches: &[BezierPatch],
    breaks: &[(Vec<f64>, Vec<f64>)],
    k: usize,
) -> String {
    let k = k.max(1);
    let mut out = String::from("# ricci T-spline tessellation (per patch)\n");
    let mut base = 1usize;
    for (p, (bu, bv)) in patches.iter().zip(breaks) {
        let (us, vs) = (tessellation_params(bu, k), tessellation_params(bv, k));
        for &v in &vs {
            for &u in &us {
                let x = p.point(u, v);
                let _ = writeln!(out, "v {} {} {}", x[0], x[1], x[2]);
            }
        }
        let n = us.len();
        for j in 0..vs.len() - 1 {
            for i in 0..n - 1 {
                let a = base + j * n + i;
                let (b, c, d) = (a + 1, a + n + 1, a + n);
                let _ = writeln!(out, "f {a} {b} {c}\nf {a} {c} {d}");
            }
        }
        base += n * vs.len();
    }
    out
}

/// The T-spline on the lattice grid `p(i, j) = (i/n) ω₁ + (j/m) ω₂` of the flat torus, as one
/// closed, welded triangle mesh (a torus: `n m` vertices, `2 n m` triangles), in OBJ.
pub fn torus_obj(ts: &super::surface::TSpline, n: usize, m: usize) -> String {
    let (n, m) = (n.max(3), m.max(3));
    let lat = ts.basis.mesh.lattice;
    let mut out = String::from("# ricci T-spline tessellation (lattice grid of the flat torus)\n");
    for j in 0..m {
        for i in 0..n {
            let (a, b) = (i as f64 / n as f64, j as f64 / m as f64);
            let x = ts.point(a * lat.width + b * lat.shift, b * lat.height);
            let _ = writeln!(out, "v {} {} {}", x[0], x[1], x[2]);
        }
    }
    let id = |i: usize, j: usize| (j % m) * n + (i % n) + 1;
    for j in 0..m {
        for i in 0..n {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            let _ = writeln!(out, "f {a} {b} {c}\nf {a} {c} {d}");
        }
    }
    out
}
