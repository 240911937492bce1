//! Cameras that frame a mesh: orthographic or perspective, looking from a chosen direction
//! with a chosen up vector, scaled so the whole mesh fits the viewport with a small margin.
//!
//! Framing: the mesh is centred on its bounding sphere, then the camera is moved sideways so
//! the projected bounding box is centred, and scaled (orthographic: half-height; perspective:
//! distance) so that every vertex lies inside the viewport shrunk by `margin`. Screen
//! coordinates have x to the right and y downwards, in pixels of the target image.

use crate::{input_err, Result};

/// Projection of the camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Projection {
    /// Parallel projection (no foreshortening): best for measuring and for flat layouts.
    Orthographic,
    /// Pinhole camera with the given vertical field of view in degrees.
    Perspective { fov_y_deg: f64 },
}

/// Where the camera looks from: the user-facing description of a camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct View {
    /// Direction from the mesh towards the camera (need not be unit length). (0, 0, 1) looks
    /// at the xy-plane head-on from +z.
    pub eye_direction: [f64; 3],
    /// Approximate up direction on screen (made orthogonal to the eye direction; if parallel
    /// to it, another axis is used).
    pub up: [f64; 3],
    pub projection: Projection,
    /// Ratio of the framed extent to the object's extent (≥ 1); 1.08 leaves a 4% border.
    pub margin: f64,
}

impl Default for View {
    /// A three-quarter view from the front (+z), slightly from the right and above, y up,
    /// orthographic.
    fn default() -> Self {
        View {
            eye_direction: [0.4, 0.3, 1.0],
            up: [0.0, 1.0, 0.0],
            projection: Projection::Orthographic,
            margin: 1.08,
        }
    }
}

impl View {
    /// Head-on view from +z, y up, orthographic.
    pub fn front() -> View {
        View {
            eye_direction: [0.0, 0.0, 1.0],
            ..View::default()
        }
    }
}

/// A camera placed in the scene, with its viewport in the image.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Camera position (for orthographic cameras: a point behind the object on the axis).
    pub eye: [f64; 3],
    /// Orthonormal basis: screen right, screen up, and `back` = towards the viewer.
    pub right: [f64; 3],
    pub up: [f64; 3],
    pub back: [f64; 3],
    pub projection: Projection,
    /// Orthographic: half of the visible height in world units. Perspective: tan(fov_y / 2).
    pub half_height: f64,
    /// Viewport origin and size in image pixels.
    pub viewport: [f64; 4],
    /// Centre of the mesh's bounding sphere and its radius.
    pub center: [f64; 3],
    pub radius: f64,
}

/// A point in view coordinates and on screen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Projected {
    /// Screen position in image pixels (y down).
    pub x: f64,
    pub y: f64,
    /// Distance in front of the camera along the viewing axis (> 0 when visible).
    pub depth: f64,
}

impl Camera {
    /// Frame `positions` in the viewport `[x0, y0, width, height]` (pixels) as seen from `view`.
    pub fn frame(positions: &[[f64; 3]], view: &View, viewport: [f64; 4]) -> Result<Camera> {
        if positions.is_empty() {
            return input_err("cannot frame an empty mesh");
        }
        if viewport[2] < 1.0 || viewport[3] < 1.0 {
            return input_err(format!(
                "the viewport {}x{} pixels is too small to draw into",
                viewport[2], viewport[3]
            ));
        }
        let back = normalize(view.eye_direction)
            .ok_or_else(|| crate::Error::Input("the view direction must not be zero".into()))?;
        if !view.margin.is_finite() || view.margin < 1.0 {
            return input_err(format!("the framing margin {} must be ≥ 1", view.margin));
        }
        let up0 = [view.up, [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]
            .into_iter()
            .find_map(|u| {
                let u = sub(u, scale(back, dot(u, back)));
                normalize(u).filter(|_| norm(u) > 1e-3 * norm(view.up).max(1.0))
            })
            .unwrap_or([0.0, 1.0, 0.0]);
        let right = cross(up0, back);
        let (center, radius) = bounding_sphere(positions);
        let radius = if radius > 0.0 { radius } else { 1.0 };
        let aspect = viewport[2] / viewport[3];

        // Centre the projected bounding box.
        let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
        for p in positions {
            let d = sub(*p, center);
            let (x, y) = (dot(d, right), dot(d, up0));
            x0 = x0.min(x);
            x1 = x1.max(x);
            y0 = y0.min(y);
            y1 = y1.max(y);
        }
        let target = add(
            center,
            add(scale(right, 0.5 * (x0 + x1)), scale(up0, 0.5 * (y0 + y1))),
        );
        let tiny = 1e-9 * radius;
        let (half_height, eye) = match view.projection {
            Projection::Orthographic => {
                let hh = (0.5 * (y1 - y0)).max(0.5 * (x1 - x0) / aspect).max(tiny) * view.margin;
                (hh, add(target, scale(back, 3.0 * radius)))
            }
            Projection::Perspective { fov_y_deg } => {
                if !(1.0..=170.0).contains(&fov_y_deg) {
                    return input_err(format!(
                        "the field of view {fov_y_deg}° must be between 1° and 170°"
                    ));
                }
                let ty = (0.5 * fov_y_deg.to_radians()).tan();
                let tx = ty * aspect;
                // Distance that fits every vertex for a given target, then re-centre the
                // target on the perspective image of the mesh; a few rounds make it tight.
                let fit = |target: [f64; 3]| {
                    let mut dist = 0.0f64;
                    let mut zmax = f64::MIN;
                    for p in positions {
                        let d = sub(*p, target);
                        let (x, y, z) = (dot(d, right), dot(d, up0), dot(d, back));
                        dist = dist
                            .max(z + view.margin * x.abs() / tx)
                            .max(z + view.margin * y.abs() / ty);
                        zmax = zmax.max(z);
                    }
                    dist.max(zmax + 0.05 * radius)
                };
                let mut target = target;
                for _ in 0..4 {
                    let dist = fit(target);
                    let (mut a0, mut a1, mut b0, mut b1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
                    for p in positions {
                        let d = sub(*p, target);
                        let (x, y, z) = (dot(d, right), dot(d, up0), dot(d, back));
                        let depth = (dist - z).max(1e-12 * radius);
                        a0 = a0.min(x / depth);
                        a1 = a1.max(x / depth);
                        b0 = b0.min(y / depth);
                        b1 = b1.max(y / depth);
                    }
                    let shift = add(
                        scale(right, 0.5 * (a0 + a1) * dist),
                        scale(up0, 0.5 * (b0 + b1) * dist),
                    );
                    target = add(target, shift);
                }
                let dist = fit(target);
                (ty, add(target, scale(back, dist)))
            }
        };
        Ok(Camera {
            eye,
            right,
            up: up0,
            back,
            projection: view.projection,
            half_height,
            viewport,
            center,
            radius,
        })
    }

    /// Project a world point to the screen.
    #[inline]
    pub fn project(&self, p: [f64; 3]) -> Projected {
        let d = sub(p, self.eye);
        let (x, y, depth) = (dot(d, self.right), dot(d, self.up), -dot(d, self.back));
        let [vx, vy, vw, vh] = self.viewport;
        let aspect = vw / vh;
        let (nx, ny) = match self.projection {
            Projection::Orthographic => (x / (self.half_height * aspect), y / self.half_height),
            Projection::Perspective { .. } => {
                let dd = depth.max(1e-12 * self.radius);
                (
                    x / (dd * self.half_height * aspect),
                    y / (dd * self.half_height),
                )
            }
        };
        Projected {
            x: vx + 0.5 * vw * (1.0 + nx),
            y: vy + 0.5 * vh * (1.0 - ny),
            depth,
        }
    }

    /// Unit vector from a world point towards the viewer.
    #[inline]
    pub fn to_viewer(&self, p: [f64; 3]) -> [f64; 3] {
        match self.projection {
            Projection::Orthographic => self.back,
            Projection::Perspective { .. } => normalize(sub(self.eye, p)).unwrap_or(self.back),
        }
    }

    /// The same camera drawing into a viewport scaled by `s` (for supersampling).
    pub fn scaled(&self, s: f64) -> Camera {
        let mut c = *self;
        c.viewport = self.viewport.map(|v| v * s);
        c
    }
}

/// A bounding sphere (Ritter's algorithm refined by growing; within a few percent of the
/// minimal one): centre and radius.
pub fn bounding_sphere(points: &[[f64; 3]]) -> ([f64; 3], f64) {
    if points.is_empty() {
        return ([0.0; 3], 0.0);
    }
    let far = |from: [f64; 3]| {
        points
            .iter()
            .copied()
            .max_by(|a, b| norm(sub(*a, from)).total_cmp(&norm(sub(*b, from))))
            .unwrap_or(from)
    };
    let a = far(points[0]);
    let b = far(a);
    let mut c = scale(add(a, b), 0.5);
    let mut r = 0.5 * norm(sub(a, b));
    for p in points {
        let d = norm(sub(*p, c));
        if d > r {
            let nr = 0.5 * (r + d);
            c = add(c, scale(sub(*p, c), (nr - r) / d));
            r = nr;
        }
    }
    (c, r)
}

#[inline]
pub(crate) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
#[inline]
pub(crate) fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
#[inline]
pub(crate) fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}
#[inline]
pub(crate) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
#[inline]
pub(crate) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
#[inline]
pub(crate) fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}
#[inline]
pub(crate) fn normalize(a: [f64; 3]) -> Option<[f64; 3]> {
    let n = norm(a);
    (n > 0.0 && n.is_finite()).then(|| scale(a, 1.0 / n))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounding_sphere_contains_all_points_and_is_nearly_minimal() {
        // Points on a unit sphere around (1, 2, 3): minimal radius 1.
        let mut pts = Vec::new();
        for i in 0..20 {
            for j in 0..20 {
                let (t, p) = (i as f64 * 0.33, j as f64 * 0.29);
                pts.push([
                    1.0 + t.sin() * p.cos(),
                    2.0 + t.sin() * p.sin(),
                    3.0 + t.cos(),
                ]);
            }
        }
        let (c, r) = bounding_sphere(&pts);
        assert!(pts.iter().all(|p| norm(sub(*p, c)) <= r * (1.0 + 1e-12)));
        assert!(r < 1.1, "radius {r} too far from the minimal 1");
    }

    #[test]
    fn orthographic_front_camera_maps_square_to_centred_square() {
        let sq = [
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [2.0, 2.0, 0.0],
            [0.0, 2.0, 0.0],
        ];
        let view = View {
            margin: 1.25,
            ..View::front()
        };
        let cam = Camera::frame(&sq, &view, [0.0, 0.0, 100.0, 100.0]).unwrap();
        // The square spans 100/1.25 = 80 pixels, centred: from 10 to 90; y flipped.
        let p = cam.project([0.0, 0.0, 0.0]);
        let q = cam.project([2.0, 2.0, 0.0]);
        assert!(
            (p.x - 10.0).abs() < 1e-9 && (p.y - 90.0).abs() < 1e-9,
            "{p:?}"
        );
        assert!(
            (q.x - 90.0).abs() < 1e-9 && (q.y - 10.0).abs() < 1e-9,
            "{q:?}"
        );
        assert!(p.depth > 0.0);
    }

    #[test]
    fn perspective_camera_keeps_every_vertex_inside() {
        let mut pts = Vec::new();
        for i in 0..50 {
            let t = i as f64 * 0.7;
            pts.push([5.0 * t.cos(), 0.3 * t.sin(), 0.2 * (2.0 * t).cos()]);
        }
        let view = View {
            eye_direction: [0.3, 1.0, 0.2],
            up: [0.0, 0.0, 1.0],
            projection: Projection::Perspective { fov_y_deg: 40.0 },
            margin: 1.1,
        };
        let cam = Camera::frame(&pts, &view, [0.0, 0.0, 200.0, 100.0]).unwrap();
        let mut touched = false;
        for p in &pts {
            let s = cam.project(*p);
            assert!(s.depth > 0.0);
            assert!(
                s.x > 0.0 && s.x < 200.0 && s.y > 0.0 && s.y < 100.0,
                "{s:?}"
            );
            touched |= s.x < 15.0 || s.x > 185.0 || s.y < 8.0 || s.y > 92.0;
        }
        assert!(touched, "the framing is far from tight");
    }
}
