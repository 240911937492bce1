//! Where is the area of `ricci param`'s map with qc above a threshold (issue 16, quality at
//! equal cone count)? For one mesh, `N` greedy cones and rigid or free seams, splits the 3D
//! area of the map's triangles (the common subdivision's pieces when the map lives there,
//! else the input's faces) with qc > T by
//!
//! * whether the piece's input face is cut into several pieces (the flow flipped an input
//!   edge through it) or is whole;
//! * the input face's distance in edge hops (rings) to the nearest cone and to the nearest
//!   seam vertex;
//!
//! and prints the same split of the input faces' own UV triangles (`corner_uv`: exact at the
//! vertices, linear on the face — what a tool writing UVs on the input's faces shows).
//!
//! With a UV OBJ of the same mesh instead of `N` (same `v` and `f` order, e.g. Boundary First
//! Flattening's output) the same split of that map, its cones given by `CONES=v,v,…` and its
//! seam vertices those with several `vt`.
//!
//! ```sh
//! cargo run --release -p ricci --example diag_qc_where -- ../shared/meshes/seahorse2_100K.off 8 free 1.2
//! CONES=869,2249 cargo run --release -p ricci --example diag_qc_where -- seahorse.off bff.obj x 1.2
//! ```

use ricci::analysis::distortion::face_distortions;
use ricci::mesh::Mesh;
use ricci::param::{parametrize, ConeSpec, ParamOptions, SeamMode};
use ricci::progress::NoProgress;
use std::collections::VecDeque;

/// Hop distance of every vertex from `sources` (u32::MAX if unreachable).
fn rings(mesh: &Mesh, sources: &[u32]) -> Vec<u32> {
    let n = mesh.n_vertices();
    let mut adj = vec![Vec::new(); n];
    for e in 0..mesh.n_edges() as u32 {
        let [a, b] = mesh.edge_vertices(e);
        adj[a as usize].push(b);
        adj[b as usize].push(a);
    }
    let mut d = vec![u32::MAX; n];
    let mut q = VecDeque::new();
    for &s in sources {
        d[s as usize] = 0;
        q.push_back(s);
    }
    while let Some(v) = q.pop_front() {
        for &w in &adj[v as usize] {
            if d[w as usize] == u32::MAX {
                d[w as usize] = d[v as usize] + 1;
                q.push_back(w);
            }
        }
    }
    d
}

/// Corner UVs of an OBJ whose `f` lines are `v/vt` triangles in the mesh's face order.
fn obj_corner_uv(path: &str) -> Result<Vec<[f64; 2]>, Box<dyn std::error::Error>> {
    let text = std::fs::read_to_string(path)?;
    let mut vt = Vec::new();
    let mut out = Vec::new();
    for line in text.lines() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("vt") => {
                let a: f64 = it.next().ok_or("vt")?.parse()?;
                let b: f64 = it.next().ok_or("vt")?.parse()?;
                vt.push([a, b]);
            }
            Some("f") => {
                for c in it {
                    let t: usize = c.split('/').nth(1).ok_or("f needs v/vt")?.parse()?;
                    out.push(vt[t - 1]);
                }
            }
            _ => {}
        }
    }
    Ok(out)
}

const BINS: [(u32, u32); 5] = [(0, 1), (2, 4), (5, 10), (11, 30), (31, u32::MAX)];

fn bin(d: u32) -> usize {
    BINS.iter()
        .position(|&(a, b)| d >= a && d <= b)
        .unwrap_or(4)
}

/// (area with qc > t, total area) per bin, printed as a table row.
fn print_split(title: &str, rows: &[(String, f64, f64)], total_bad: f64, total: f64) {
    println!("{title}");
    for (name, bad, all) in rows {
        println!(
            "  {name:<22} bad {:>6.2} % of all bad area   ({:>5.2} % of its own area; {:>5.2} % of the surface)",
            100.0 * bad / total_bad.max(1e-300),
            100.0 * bad / all.max(1e-300),
            100.0 * all / total
        );
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 2 {
        return Err("usage: diag_qc_where MESH N [free|rigid] [T]".into());
    }
    let (s, _) = ricci::mesh::io::read_surface(std::path::Path::new(&args[0]))?;
    let seams = match args.get(2).map(|x| x.as_str()) {
        Some("rigid") => SeamMode::Rigid,
        _ => SeamMode::Free,
    };
    let t: f64 = args.get(3).map_or(Ok(1.2), |x| x.parse())?;
    let nf = s.mesh.n_faces();
    let obj = args[1].ends_with(".obj");
    let (p, cones, seam_v) = if obj {
        let uv = obj_corner_uv(&args[1])?;
        if uv.len() != 3 * nf {
            return Err("the OBJ's faces are not the mesh's".into());
        }
        let cones: Vec<u32> = std::env::var("CONES")
            .unwrap_or_default()
            .split(',')
            .filter_map(|x| x.parse().ok())
            .collect();
        // Seam vertices: several distinct UVs.
        let mut first = vec![None; s.mesh.n_vertices()];
        let mut seam_v = Vec::new();
        for f in 0..nf {
            for (i, &v) in s.mesh.face(f as u32).iter().enumerate() {
                let q = uv[3 * f + i];
                match first[v as usize] {
                    None => first[v as usize] = Some(q),
                    Some(r) if r != q => seam_v.push(v),
                    _ => {}
                }
            }
        }
        (None, cones, (seam_v, uv))
    } else {
        let opts = ParamOptions {
            cones: ConeSpec::Count(args[1].parse()?),
            seams,
            ..ParamOptions::default()
        };
        let p = parametrize(&s, &opts, &mut NoProgress)?;
        let cones: Vec<u32> = p
            .charts
            .iter()
            .flat_map(|c| c.cones.iter().map(|x| x.vertex))
            .collect();
        let mut seam_v = Vec::new();
        for e in 0..s.mesh.n_edges() as u32 {
            if p.seam[e as usize] {
                seam_v.extend(s.mesh.edge_vertices(e));
            }
        }
        let uv = p.corner_uv.clone();
        (Some(p), cones, (seam_v, uv))
    };
    let (seam_v, corner_uv) = seam_v;
    let dc = rings(&s.mesh, &cones);
    let ds = rings(&s.mesh, &seam_v);
    let face_d = |d: &[u32], f: usize| s.mesh.face(f as u32).iter().map(|&v| d[v as usize]).min();
    // (input face, area, qc) of every carrier triangle.
    let mut pieces: Vec<(usize, f64, f64)> = Vec::new();
    let mut count = vec![0usize; nf];
    match p.as_ref().and_then(|p| p.subdivision.as_ref()) {
        Some(sub) => {
            let tris: Vec<[u32; 3]> = (0..sub.mesh.n_faces() as u32)
                .map(|t| sub.mesh.face(t))
                .collect();
            for (k, x) in face_distortions(&sub.positions, &tris, &sub.corner_uv)
                .iter()
                .enumerate()
            {
                let f = sub.input_face[k] as usize;
                count[f] += 1;
                pieces.push((
                    f,
                    x.area_3d,
                    if x.flipped() { f64::INFINITY } else { x.qc() },
                ));
            }
        }
        None => {
            let tris: Vec<[u32; 3]> = (0..nf as u32).map(|f| s.mesh.face(f)).collect();
            for (f, x) in face_distortions(&s.positions, &tris, &corner_uv)
                .iter()
                .enumerate()
            {
                count[f] = 1;
                pieces.push((
                    f,
                    x.area_3d,
                    if x.flipped() { f64::INFINITY } else { x.qc() },
                ));
            }
        }
    }
    let total: f64 = pieces.iter().map(|x| x.1).sum();
    let bad: f64 = pieces.iter().filter(|x| x.2 > t).map(|x| x.1).sum();
    let (carrier, qp, sg) = match &p {
        Some(p) => (p.uv_on(), p.stats.qc_p95_area, p.stats.log_area_sigma),
        None => ("obj", f64::NAN, f64::NAN),
    };
    println!(
        "{}: {} cones, seams {}, carrier {carrier} ({} triangles), qcA p95 {qp:.4}, σ {sg:.4}; area with qc > {t}: {:.2} %",
        args[0],
        cones.len(),
        if obj { "obj" } else { seams.name() },
        pieces.len(),
        100.0 * bad / total
    );
    let split = |key: &dyn Fn(usize) -> usize, names: &[String]| -> Vec<(String, f64, f64)> {
        let mut rows: Vec<(String, f64, f64)> =
            names.iter().map(|n| (n.clone(), 0.0, 0.0)).collect();
        for &(f, a, q) in &pieces {
            let r = &mut rows[key(f)];
            r.2 += a;
            if q > t {
                r.1 += a;
            }
        }
        rows
    };
    let whole = split(
        &|f| usize::from(count[f] > 1),
        &["whole input face".into(), "split input face".into()],
    );
    print_split("by input face:", &whole, bad, total);
    let names: Vec<String> = BINS
        .iter()
        .map(|&(a, b)| {
            if b == u32::MAX {
                format!("rings ≥ {a}")
            } else {
                format!("rings {a}–{b}")
            }
        })
        .collect();
    let by_cone = split(&|f| bin(face_d(&dc, f).unwrap_or(u32::MAX)), &names);
    print_split("by distance to the nearest cone:", &by_cone, bad, total);
    let by_seam = split(&|f| bin(face_d(&ds, f).unwrap_or(u32::MAX)), &names);
    print_split(
        "by distance to the nearest seam vertex:",
        &by_seam,
        bad,
        total,
    );
    // Far from cones and seams, whole faces: the map's own (discretisation) distortion.
    let far = split(
        &|f| {
            let c = face_d(&dc, f).unwrap_or(u32::MAX) > 4;
            let sm = face_d(&ds, f).unwrap_or(u32::MAX) > 4;
            usize::from(c && sm) + 2 * usize::from(count[f] > 1)
        },
        &[
            "near (≤4) cone/seam, whole".into(),
            "far, whole".into(),
            "near, split".into(),
            "far, split".into(),
        ],
    );
    print_split("combined:", &far, bad, total);
    if p.as_ref().is_some_and(|p| p.subdivision.is_some()) {
        let tris: Vec<[u32; 3]> = (0..nf as u32).map(|f| s.mesh.face(f)).collect();
        let d = face_distortions(&s.positions, &tris, &corner_uv);
        let (mut b1, mut b2, mut all) = (0.0, 0.0, 0.0);
        for (f, x) in d.iter().enumerate() {
            all += x.area_3d;
            if x.flipped() || x.qc() > t {
                b1 += x.area_3d;
                if count[f] > 1 {
                    b2 += x.area_3d;
                }
            }
        }
        let st = ricci::analysis::distortion::stats(&d);
        println!(
            "input faces' own UV triangles: area with qc > {t} (or flipped) {:.2} % ({:.2} % on split faces); flips {}, qc p95 {:.4} (count) {:.4} (area), σ {:.4}",
            100.0 * b1 / all,
            100.0 * b2 / all,
            st.flipped_faces,
            st.qc_p95,
            st.qc_p95_area,
            st.log_area_sigma
        );
    }
    Ok(())
}
