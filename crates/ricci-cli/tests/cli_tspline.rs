//! `ricci tspline` fit flags (issue 18): `--correction-gain`, `--rms-marks`, `--area-weights`
//! reach the library (echoed in the JSON, and they change the fit the way their definitions
//! say), bad values are refused with exit code 2, on a generated torus (no `RICCI_MESHES`);
//! the genus-2 default (the domain-mesh spline) against the input's topology; and genus 2
//! with boundary loops (a generated surface with two holes; `eight.hole.off` of
//! `RICCI_MESHES`): the exported surface is one closed genus-2 surface (the loops filled) and
//! every input vertex lies within the reported error of it.

use std::path::PathBuf;
use std::process::{Command, Output};

fn ricci(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_ricci"))
        .args(args)
        .output()
        .expect("run ricci")
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("ricci_cli_tspline_{}_{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn json(o: &Output) -> serde_json::Value {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).expect("one JSON object on stdout")
}

fn torus() -> PathBuf {
    let d = tmp("mesh");
    let mesh = d.join("torus.off");
    // a thick torus: the vertex areas differ by a factor 3 between the outer and inner rings
    let o = ricci(&[
        "generate",
        "torus",
        "--major",
        "1",
        "--minor",
        "0.5",
        "-n",
        "24",
        "--out",
        mesh.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    mesh
}

fn last_step_rms(v: &serde_json::Value) -> f64 {
    v["steps"].as_array().unwrap().last().unwrap()["rms_error_percent"]
        .as_f64()
        .unwrap()
}

/// One fit over the same T-mesh (`--max-iterations 1`, no correction): the area-weighted fit
/// has the smaller area-weighted rms, the plain fit the smaller vertex rms (each minimises its
/// own sum of squares; the fairness weight is 1e-5 of the data term). With `--area-weights`
/// the steps' rms is the weighted one: it equals the report's area-weighted rms, computed by
/// another function; the report's `rms_error_percent` stays the vertex rms.
#[test]
fn area_weights_fit_the_area_weighted_sum_and_the_report_keeps_the_vertex_rms() {
    let mesh = torus();
    let m = mesh.to_str().unwrap();
    let base = [
        "tspline",
        m,
        "--tolerance",
        "0.01%",
        "--max-iterations",
        "1",
        "--initial-faces",
        "16",
        "--max-points-per-face",
        "0",
        "--json",
    ];
    let plain = json(&ricci(&base));
    let mut args = base.to_vec();
    args.push("--area-weights");
    let weighted = json(&ricci(&args));
    assert_eq!(weighted["area_weights"], true);
    assert_eq!(plain["area_weights"], false);
    assert_eq!(plain["control_points"], weighted["control_points"]);
    // genus 1 reports `cells` and `patches` as genus ≥ 2 does: with no T-junction every T-mesh
    // face is one cell and one exported patch
    let n = |k: &str| plain[k].as_u64().unwrap();
    if n("t_junctions") == 0 {
        assert_eq!(
            (n("cells"), n("patches")),
            (n("faces"), n("faces")),
            "{plain}"
        );
    } else {
        assert!(
            n("faces") <= n("patches") && n("patches") <= n("cells"),
            "{plain}"
        );
    }
    let f = |v: &serde_json::Value, k: &str| v[k].as_f64().unwrap();
    let (pv, pa) = (
        f(&plain, "rms_error_percent"),
        f(&plain, "rms_error_percent_area_weighted"),
    );
    let (wv, wa) = (
        f(&weighted, "rms_error_percent"),
        f(&weighted, "rms_error_percent_area_weighted"),
    );
    assert!((last_step_rms(&plain) - pv).abs() <= 1e-12 * pv, "{plain}");
    assert!(
        (last_step_rms(&weighted) - wa).abs() <= 1e-9 * wa,
        "{weighted}"
    );
    assert!(
        wa < pa,
        "area-weighted rms: weighted fit {wa} vs plain fit {pa}"
    );
    assert!(pv < wv, "vertex rms: plain fit {pv} vs weighted fit {wv}");
}

/// `--correction-gain` and `--rms-marks` are echoed and act: with a rms target and
/// `--rms-marks 1`, each refit of the rms phase splits one face (so the control points grow
/// by a few per iteration, not by the θ rule's many), and a gain of 0.9 stops every correction
/// after its first round (a different fit from the full rounds).
#[test]
fn correction_gain_and_rms_marks_reach_the_fit() {
    let mesh = torus();
    let m = mesh.to_str().unwrap();
    let run = |gain: &str, marks: &str| {
        json(&ricci(&[
            "tspline",
            m,
            "--tolerance",
            "1%",
            "--rms-tolerance",
            "0.001%",
            "--max-iterations",
            "4",
            "--parameter-correction",
            "3",
            "--correction-gain",
            gain,
            "--rms-marks",
            marks,
            "--json",
        ]))
    };
    let greedy = run("0", "1");
    assert_eq!(greedy["rms_marks"], 1);
    assert_eq!(greedy["correction_gain"], 0.0);
    let steps = greedy["steps"].as_array().unwrap();
    let cps: Vec<u64> = steps
        .iter()
        .map(|s| s["control_points"].as_u64().unwrap())
        .collect();
    let theta = run("0", "0");
    let theta_cps: Vec<u64> = theta["steps"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["control_points"].as_u64().unwrap())
        .collect();
    assert!(
        cps.last() < theta_cps.last(),
        "one split per refit {cps:?} vs the θ rule {theta_cps:?}"
    );
    let stopped = run("0.9", "1");
    assert_eq!(stopped["correction_gain"], 0.9);
    assert_ne!(
        stopped["rms_error_percent"], greedy["rms_error_percent"],
        "the gain did not change the fit"
    );
}

#[test]
fn bad_fit_flags_are_refused_with_exit_code_2() {
    for (flag, value) in [
        ("--correction-gain", "1"),
        ("--correction-gain", "-0.1"),
        ("--rms-marks", "1000000"),
    ] {
        let arg = format!("{flag}={value}");
        let o = ricci(&["tspline", "no-such.off", &arg, "--json"]);
        assert_eq!(o.status.code(), Some(2), "{flag} {value}");
        let e = String::from_utf8_lossy(&o.stderr);
        assert!(e.contains(flag), "{flag} {value}: {e}");
    }
}

/// Genus 2, the default: one spline on the quad mesh of the glued strips. Checked against the
/// topology of the input (generated genus 2, χ = −2): the quad mesh is closed, so control
/// points − cells = χ; 2g − 2 = 2 simple zeros, each a vertex of valence 8, so 16 cell sides
/// with a zero at an end; those sides C¹ in the translation chart (G¹: the fit keeps the
/// conditions at the zeros), all the others C². The per-cylinder
/// fit stays reachable by `--per-cylinder`.
#[test]
fn genus_two_default_is_the_domain_mesh_spline_and_per_cylinder_is_an_option() {
    let d = tmp("genus2");
    let mesh = generated_genus_two(&d);
    let m = mesh.to_str().unwrap();
    let out = d.join("out");
    let v = json(&ricci(&[
        "tspline",
        m,
        "--tolerance",
        "1%",
        "--json",
        "--out",
        out.to_str().unwrap(),
    ]));
    assert_eq!(v["spline"], "domain_mesh", "{v}");
    for key in [
        "control_points",
        "rms_error_percent",
        "max_error_percent",
        "iterations",
        "continuity",
        "seconds",
    ] {
        assert!(!v[key].is_null(), "no {key}: {v}");
    }
    check_closed_domain_mesh(&v, -2, 1.0);
    // the exported faces are the Bézier elements: cells merged where the spline is one
    // polynomial (the graded lines end in T-junctions, so some cells are parts of one)
    assert_eq!(v["bezier_patches"], v["patches"]);
    assert_eq!(v["bezier_elements"]["elements"], v["patches"]);
    assert_eq!(v["bezier_elements"]["cells"], v["cells"]);
    let count = |k: &str| v[k].as_u64().unwrap();
    if count("t_junctions") > 0 {
        assert!(count("patches") < count("cells"), "{v}");
    } else {
        assert!(count("patches") <= count("cells"), "{v}");
    }
    assert_eq!(v["continuity"]["extraordinary_points"], 2);
    for f in [
        "tspline.step",
        "tspline.igs",
        "surface.obj",
        "samples.json",
        "tspline.json",
    ] {
        assert!(out.join(f).is_file(), "{f} not written");
    }
    for f in ["tmesh-surface.png", "zebra.png"] {
        assert_eq!(png_size(&out.join(f)), (1200, 900), "{f}");
    }
    // between the vertices: every point of the exported tessellation (points of the spline)
    // to the input triangles, measured here by brute force, within the reported maximum (its
    // samples are other points of the same cells: 25 % + 0.1 % of the longest side of slack)
    // and within 3 % of the longest side
    let (surface, _) = ricci::mesh::io::read_surface(&mesh).unwrap();
    let tris: Vec<[usize; 3]> = surface
        .mesh
        .faces()
        .iter()
        .map(|t| t.map(|x| x as usize))
        .collect();
    let scale = longest_side(&surface.positions);
    let (spline_points, _) = read_obj(&out.join("surface.obj"));
    let measured = 100.0 * max_distance(&spline_points, &surface.positions, &tris) / scale;
    let reported = v["max_deviation_between_vertices_percent"]
        .as_f64()
        .unwrap();
    let rms = v["rms_deviation_between_vertices_percent"]
        .as_f64()
        .unwrap();
    assert!(
        measured <= 1.25 * reported + 0.1 && measured <= 3.0 && rms <= reported,
        "between the vertices: measured {measured} %, reported max {reported} %, rms {rms} %"
    );
    let p = json(&ricci(&[
        "tspline",
        m,
        "--tolerance",
        "2%",
        "--json",
        "--per-cylinder",
    ]));
    assert_eq!(p["spline"], "per_cylinder", "{p}");
    assert!(p["cylinders"].as_array().is_some_and(|c| !c.is_empty()));
}

/// Genus 3 (a generated surface; genus3.off and fertility with `$RICCI_MESHES`): one spline on
/// the glued domain mesh, not the per-cylinder fallback — a closed quad mesh of χ = 2 − 2g whose
/// irregular vertices are the zeros, G¹ there and C² elsewhere, within the tolerance. Fertility's
/// cylinders have unequal zero copies on their two circles: points are added (JSON `gluing`).
#[test]
fn genus_three_and_four_glue_into_one_domain_mesh() {
    let d = tmp("genus3");
    let generated = d.join("genus3.off");
    let o = ricci(&[
        "generate",
        "genus3",
        "-n",
        "30",
        "--out",
        generated.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mut cases = vec![(generated, 3, "1%")];
    match ricci_meshes::ricci_meshes().filter(|d| d.is_dir()) {
        Some(dir) => cases.push((dir.join("fertility.off"), 4, "0.5%")),
        None => eprintln!("RICCI_MESHES is not set: only the generated genus-3 surface"),
    }
    for (mesh, genus, tolerance) in cases {
        let o = ricci(&[
            "tspline",
            mesh.to_str().unwrap(),
            "--tolerance",
            tolerance,
            "--json",
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(
            !stderr.contains("do not glue"),
            "{}: {stderr}",
            mesh.display()
        );
        let v = json(&o);
        assert!(v["domain_mesh_refused"].is_null(), "{v}");
        let t: f64 = tolerance.trim_end_matches('%').parse().unwrap();
        check_closed_domain_mesh(&v, 2 - 2 * genus, t);
        let zeros = v["continuity"]["extraordinary_points"].as_i64().unwrap();
        assert_eq!(zeros, 2 * genus - 2, "{v}");
        let g = &v["gluing"];
        eprintln!(
            "{}: {} control points, gluing {g}",
            mesh.display(),
            v["control_points"]
        );
        if genus == 4 {
            assert!(g["added_points"].as_u64().unwrap() > 0, "{g}");
            assert_eq!(g["sheared_cylinders"], false, "{g}");
        }
    }
}

/// The longest side of the bounding box of `positions`.
fn longest_side(positions: &[[f64; 3]]) -> f64 {
    (0..3)
        .map(|k| {
            let (lo, hi) = positions.iter().fold((f64::MAX, f64::MIN), |(lo, hi), p| {
                (lo.min(p[k]), hi.max(p[k]))
            });
            hi - lo
        })
        .fold(0.0, f64::max)
}

/// `ricci generate genus --genus 2` into `dir`.
fn generated_genus_two(dir: &std::path::Path) -> PathBuf {
    let mesh = dir.join("genus2.off");
    let o = ricci(&[
        "generate",
        "genus",
        "--genus",
        "2",
        "--out",
        mesh.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    mesh
}

/// The report `v` of a domain-mesh spline of a closed surface of Euler characteristic `chi` (or
/// of one with its loops filled), against the topology: the full graded quad mesh is closed, so
/// its vertices − cells = χ (the control points, the T-mesh's vertices, are fewer when graded
/// lines end in T-junctions); Σ (valence − 4) over the zeros = −4χ, so the sides with a zero at
/// an end number 4·zeros − 4χ (16 for the two simple zeros of genus 2, of valence 8); those sides
/// C¹ in the translation chart (G¹), all the others C²; converged within `tolerance_percent`.
fn check_closed_domain_mesh(v: &serde_json::Value, chi: i64, tolerance_percent: f64) {
    assert_eq!(v["spline"], "domain_mesh", "{v}");
    let n = |k: &str| v[k].as_i64().unwrap();
    assert_eq!(n("mesh_vertices") - n("cells"), chi, "{v}");
    assert!(n("control_points") <= n("mesh_vertices"), "{v}");
    assert_eq!(
        n("t_junctions") > 0,
        n("control_points") < n("mesh_vertices"),
        "{v}"
    );
    let c = &v["continuity"];
    let zeros = c["extraordinary_points"].as_i64().unwrap();
    assert!(zeros >= 1, "{c}");
    assert_eq!(
        c["at_zeros"]["sides"].as_i64().unwrap(),
        4 * zeros - 4 * chi,
        "{c}"
    );
    assert_eq!(c["at_zeros"]["class"], "C1", "{c}");
    for k in ["one_interval_from_zeros", "elsewhere"] {
        assert!(c[k]["class"] == "C2" || c[k]["class"] == "C3", "{k}: {c}");
    }
    assert_eq!(v["converged"], true, "{v}");
    assert!(
        v["max_error_percent"].as_f64().unwrap() <= tolerance_percent,
        "{v}"
    );
}

/// Width and height from a PNG's IHDR chunk.
fn png_size(path: &std::path::Path) -> (u32, u32) {
    let b = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert_eq!(
        &b[..8],
        b"\x89PNG\r\n\x1a\n",
        "{} is not a PNG",
        path.display()
    );
    let be = |i: usize| u32::from_be_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]);
    (be(16), be(20))
}

/// The `v` and `f` lines of an OBJ file (triangles, 1-based indices).
fn read_obj(path: &std::path::Path) -> (Vec<[f64; 3]>, Vec<[usize; 3]>) {
    let text = std::fs::read_to_string(path).unwrap();
    let (mut v, mut f) = (Vec::new(), Vec::new());
    for line in text.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        match w.first() {
            Some(&"v") => v.push([1, 2, 3].map(|i| w[i].parse::<f64>().unwrap())),
            Some(&"f") => f.push([1, 2, 3].map(|i| w[i].parse::<usize>().unwrap() - 1)),
            _ => {}
        }
    }
    (v, f)
}

/// The triangles with their points merged when closer than `eps` (a grid of cells `eps` wide,
/// searching the 27 around each point): Euler characteristic, and whether every edge lies in
/// exactly two triangles.
fn welded_euler(points: &[[f64; 3]], tris: &[[usize; 3]], eps: f64) -> (i64, bool) {
    use std::collections::HashMap;
    let cell = |p: &[f64; 3]| p.map(|x| (x / eps).floor() as i64);
    let mut grid: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
    let mut id = vec![usize::MAX; points.len()];
    let mut n = 0;
    for (i, p) in points.iter().enumerate() {
        let c = cell(p);
        let mut found = None;
        'search: for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    if let Some(list) = grid.get(&[c[0] + dx, c[1] + dy, c[2] + dz]) {
                        for &j in list {
                            let d2: f64 = (0..3).map(|k| (points[j][k] - p[k]).powi(2)).sum();
                            if d2 <= eps * eps {
                                found = Some(id[j]);
                                break 'search;
                            }
                        }
                    }
                }
            }
        }
        id[i] = found.unwrap_or_else(|| {
            n += 1;
            n - 1
        });
        grid.entry(c).or_default().push(i);
    }
    let mut edges: HashMap<(usize, usize), usize> = HashMap::new();
    let mut faces = 0i64;
    for t in tris {
        let t = t.map(|v| id[v]);
        if t[0] == t[1] || t[1] == t[2] || t[2] == t[0] {
            continue;
        }
        faces += 1;
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *edges.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    let closed = edges.values().all(|&c| c == 2);
    (n as i64 - edges.len() as i64 + faces, closed)
}

/// The distance from `p` to the triangle `abc` (closest point by regions, Ericson §5.1.5).
fn point_triangle(p: [f64; 3], a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    let sub = |x: [f64; 3], y: [f64; 3]| [x[0] - y[0], x[1] - y[1], x[2] - y[2]];
    let dot = |x: [f64; 3], y: [f64; 3]| x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
    let at = |s: f64, t: f64| {
        let q = [0, 1, 2].map(|k| a[k] + s * (b[k] - a[k]) + t * (c[k] - a[k]));
        dot(sub(p, q), sub(p, q)).sqrt()
    };
    let (ab, ac, ap) = (sub(b, a), sub(c, a), sub(p, a));
    let (d1, d2) = (dot(ab, ap), dot(ac, ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return at(0.0, 0.0);
    }
    let bp = sub(p, b);
    let (d3, d4) = (dot(ab, bp), dot(ac, bp));
    if d3 >= 0.0 && d4 <= d3 {
        return at(1.0, 0.0);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return at(d1 / (d1 - d3), 0.0);
    }
    let cp = sub(p, c);
    let (d5, d6) = (dot(ab, cp), dot(ac, cp));
    if d6 >= 0.0 && d5 <= d6 {
        return at(0.0, 1.0);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return at(0.0, d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return at(1.0 - w, w);
    }
    let den = 1.0 / (va + vb + vc);
    at(vb * den, vc * den)
}

/// The largest distance from a point of `queries` to the triangle mesh (brute force, the
/// triangles pruned by their bounding spheres).
fn max_distance(queries: &[[f64; 3]], points: &[[f64; 3]], tris: &[[usize; 3]]) -> f64 {
    let dist = |x: [f64; 3], y: [f64; 3]| (0..3).map(|k| (x[k] - y[k]).powi(2)).sum::<f64>().sqrt();
    let spheres: Vec<([f64; 3], f64)> = tris
        .iter()
        .map(|t| {
            let c = [0, 1, 2].map(|k| t.iter().map(|&v| points[v][k]).sum::<f64>() / 3.0);
            (c, t.iter().map(|&v| dist(c, points[v])).fold(0.0, f64::max))
        })
        .collect();
    let mut worst = 0.0f64;
    for &q in queries {
        let mut best = points
            .iter()
            .map(|&p| dist(p, q))
            .fold(f64::INFINITY, f64::min);
        for (t, &(c, r)) in tris.iter().zip(&spheres) {
            if dist(c, q) - r < best {
                best = best.min(point_triangle(q, points[t[0]], points[t[1]], points[t[2]]));
            }
        }
        worst = worst.max(best);
    }
    worst
}

/// `ricci tspline MESH --tolerance 1% --out` on a connected genus-2 surface with `loops`
/// boundary loops, checked against the input: the loops are filled (JSON `filled_loops`),
/// the domain mesh is that of a closed genus-2 surface (control points − cells = χ = −2;
/// Σ (valence − 4) over the zeros = −4χ = 8, so the sides at the zeros number 4·zeros + 8),
/// G¹ (class C1) at the zeros and C² elsewhere as measured; the exported tessellation `surface.obj`,
/// welded, is one closed surface of Euler characteristic −2 (the patches meet: C⁰ and the
/// fills included), and every input vertex lies within the reported L∞ error (≤ the
/// tolerance) of it, up to the tessellation's chords.
fn check_bordered_genus_two(mesh: &std::path::Path, loops: usize, name: &str) {
    let (surface, _) = ricci::mesh::io::read_surface(mesh).unwrap();
    let out = tmp(name);
    let v = json(&ricci(&[
        "tspline",
        mesh.to_str().unwrap(),
        "--tolerance",
        "1%",
        "--json",
        "--tessellation",
        "16",
        "--out",
        out.to_str().unwrap(),
    ]));
    assert_eq!(v["spline"], "domain_mesh", "{v}");
    assert_eq!(v["filled_loops"]["loops"], loops, "{v}");
    assert_eq!(v["data_points"], surface.positions.len());
    check_closed_domain_mesh(&v, -2, 1.0);
    let max = v["max_error_percent"].as_f64().unwrap();
    let scale = longest_side(&surface.positions);
    let (points, tris) = read_obj(&out.join("surface.obj"));
    let (chi, closed) = welded_euler(&points, &tris, 1e-9 * scale);
    assert!(
        closed,
        "surface.obj, welded, has edges not in exactly two triangles"
    );
    assert_eq!(chi, -2, "surface.obj, welded");
    let d = max_distance(&surface.positions, &points, &tris);
    // chords of 16 segments per cell side: below 1e-3 of the longest side on these cells;
    // vertices without cylinder coordinates (JSON `unassigned_points`, on a critical level)
    // are no data and the reported L∞ does not cover them: then the bound is the tolerance
    let unassigned = v["unassigned_points"].as_u64().unwrap();
    let bound = if unassigned > 0 { max.max(1.0) } else { max };
    assert!(
        d <= bound / 100.0 * scale + 1e-3 * scale,
        "an input vertex is {:.3} % of the longest side from the spline (reported L∞ {max:.3} %, {unassigned} unassigned)",
        100.0 * d / scale
    );
    for f in [
        "tmesh-surface.png",
        "zebra.png",
        "tspline.step",
        "tspline.json",
    ] {
        assert!(out.join(f).is_file(), "{f} not written");
    }
}

/// A generated genus-2 surface with two holes: the faces around two far-apart vertices
/// removed (and the two vertices).
#[test]
fn genus_two_with_two_holes_fits_the_filled_surface_within_the_tolerance() {
    let d = tmp("holes");
    let mesh = generated_genus_two(&d);
    let (s, _) = ricci::mesh::io::read_surface(&mesh).unwrap();
    let p = &s.positions;
    let far = (0..p.len())
        .max_by(|&i, &j| {
            let d = |k: usize| (0..3).map(|m| (p[k][m] - p[0][m]).powi(2)).sum::<f64>();
            d(i).total_cmp(&d(j))
        })
        .unwrap();
    let gone = [0, far];
    let keep: Vec<usize> = (0..p.len()).filter(|v| !gone.contains(v)).collect();
    let mut new = vec![usize::MAX; p.len()];
    for (i, &v) in keep.iter().enumerate() {
        new[v] = i;
    }
    let faces: Vec<[usize; 3]> = s
        .mesh
        .faces()
        .iter()
        .map(|f| f.map(|v| v as usize))
        .filter(|f| !f.iter().any(|v| gone.contains(v)))
        .collect();
    let mut text = format!("OFF\n{} {} 0\n", keep.len(), faces.len());
    for &v in &keep {
        text += &format!("{} {} {}\n", p[v][0], p[v][1], p[v][2]);
    }
    for f in &faces {
        text += &format!("3 {} {} {}\n", new[f[0]], new[f[1]], new[f[2]]);
    }
    let holed = d.join("genus2-holes.off");
    std::fs::write(&holed, text).unwrap();
    check_bordered_genus_two(&holed, 2, "holes-out");
}

/// The shared mesh of genus 2 with a boundary loop (`eight.hole.off`, RICCI_MESHES).
#[test]
fn eight_with_a_hole_fits_the_filled_surface_within_the_tolerance() {
    let Some(dir) = ricci_meshes::ricci_meshes().filter(|d| d.is_dir()) else {
        eprintln!("RICCI_MESHES not set: skipped");
        return;
    };
    check_bordered_genus_two(&dir.join("eight.hole.off"), 1, "eight-hole-out");
}

#[path = "../../ricci/tests/ricci_meshes/mod.rs"]
mod ricci_meshes;
