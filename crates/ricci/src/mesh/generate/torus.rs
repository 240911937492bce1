//! Torus of revolution meshed by an equilateral staggered grid in **conformal coordinates**.
//!
//! The torus `P(u, v) = ((R + r cos v) cos u, (R + r cos v) sin u, r sin v)` has the metric
//! `ds² = λ² du² + r² dv²`, `λ = R + r cos v`. With `dw = r dv / λ` it becomes
//! `ds² = λ² (du² + dw²)`: the coordinates `(u, w)` are conformal and fill the rectangle
//! `[0, 2π) × [0, W)`, `W = 2π r / √(R² − r²)`. So the torus is conformal to a flat torus with
//! side ratio `W / 2π = r / √(R² − r²)` (docs/DESIGN.md §5), and an equilateral triangle grid in
//! `(u, w)` maps to triangles that are close to equilateral in R³ (the conformal factor `λ`
//! changes by a relative `|sin v|·Δw` across a row). Integrating,
//! `w(v) = (2r/c) atan(k tan(v/2))`, `c = √(R² − r²)`, `k = √((R − r)/(R + r))`, with inverse
//! `v = 2 atan2(sin φ, k cos φ)`, `φ = c w / (2r)`, continuous on the whole period.
//!
//! Row `j` sits at `w_j = j W / n_w`; its `n_u` vertices at `u = (i + (j mod 2)/2) · 2π/n_u`.
//! `n_w` is even (so the stagger closes up) and chosen so the row spacing is as close as possible
//! to `√3/2` times the column spacing. `F = 2 n_u n_w`.

use super::{too_many_faces, MAX_FACES};
use crate::error::{Error, Result};
use crate::mesh::Surface;
use std::f64::consts::PI;

/// Fewest segments around the major circle.
pub const MIN_RESOLUTION: u32 = 6;

/// The numbers of columns (around the major circle) and rows (around the tube) of the grid the
/// torus generator uses for `resolution` columns, and the conformal height `W`.
pub fn torus_grid(major: f64, minor: f64, resolution: u32) -> Result<(u32, u32, f64)> {
    if !(major.is_finite() && minor.is_finite()) || minor <= 0.0 || major <= minor {
        return Err(Error::input(format!(
            "torus: the radii must satisfy 0 < minor < major (got major = {major}, minor = {minor})"
        )));
    }
    if resolution < MIN_RESOLUTION {
        return Err(Error::input(format!(
            "torus: resolution = {resolution} is too small (at least {MIN_RESOLUTION} segments \
             around the major circle)"
        )));
    }
    // Scale-free: W = 2π q / √(1 − q²), q = r / R (no overflow for huge radii).
    let q = minor / major;
    let height = 2.0 * PI * q / ((1.0 - q) * (1.0 + q)).sqrt();
    let a = 2.0 * PI / resolution as f64;
    let rows = height / (a * 3f64.sqrt() / 2.0);
    if !rows.is_finite() || rows > 1e9 {
        return Err(too_many_faces("torus", u64::MAX));
    }
    let n_w = (2.0 * (rows / 2.0).round()).max(4.0) as u64;
    let faces = 2 * resolution as u64 * n_w;
    if faces > MAX_FACES {
        return Err(too_many_faces("torus", faces));
    }
    Ok((resolution, n_w as u32, height))
}

/// Torus of revolution around the z axis with major radius `major` (centre of the tube) and
/// minor radius `minor` (tube), `resolution` grid columns around the major circle.
pub fn torus(major: f64, minor: f64, resolution: u32) -> Result<Surface> {
    let (n_u, n_w, height) = torus_grid(major, minor, resolution)?;
    let (rr, r) = (major, minor);
    let q = r / rr;
    // c / r with c = √(R² − r²), computed without squaring the radii.
    let c_over_r = ((1.0 - q) * (1.0 + q)).sqrt() / q;
    let k = ((rr - r) / (rr + r)).sqrt();
    let (nu, nw) = (n_u as usize, n_w as usize);
    let mut positions = Vec::with_capacity(nu * nw);
    for j in 0..nw {
        let w = height * j as f64 / nw as f64;
        let phi = c_over_r * w / 2.0;
        let v = 2.0 * phi.sin().atan2(k * phi.cos());
        let lambda = rr + r * v.cos();
        let z = r * v.sin();
        let shift = if j % 2 == 1 { 0.5 } else { 0.0 };
        for i in 0..nu {
            let u = 2.0 * PI * (i as f64 + shift) / nu as f64;
            positions.push([lambda * u.cos(), lambda * u.sin(), z]);
        }
    }
    let id = |i: usize, j: usize| ((j % nw) * nu + (i % nu)) as u32;
    let mut faces = Vec::with_capacity(2 * nu * nw);
    for j in 0..nw {
        for i in 0..nu {
            if j % 2 == 0 {
                // Row j unshifted, row j+1 shifted right by half a cell.
                faces.push([id(i, j), id(i + 1, j), id(i, j + 1)]);
                faces.push([id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
            } else {
                // Row j shifted, row j+1 unshifted.
                faces.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                faces.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
    }
    Surface::new(positions, faces)
}
