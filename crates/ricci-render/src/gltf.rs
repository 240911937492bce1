//! glTF 2.0 binary export (`.glb`): positions, smooth normals, optional UVs with an embedded
//! checkerboard PNG texture (so any glTF viewer shows the parameterization), optional
//! per-vertex colours (e.g. a scalar field through a colormap).
//!
//! Conventions: glTF puts the texture origin at the top-left of the image, so a UV (u, v) is
//! stored as TEXCOORD_0 = (u, 1 − v); the sampler repeats, and the texture holds `n × n` checks
//! where n is the checker frequency rounded to an integer (checks per UV unit). Colours are
//! stored in linear light as glTF requires.

use crate::color::{self, Rgb};
use crate::image::Image;
use crate::render::Uvs;
use crate::{check_mesh, input_err, Error, Result};
use gltf_json as json;
use json::validation::{Checked::Valid, USize64};
use std::collections::HashMap;

/// What to put in the file besides positions, normals and triangles.
#[derive(Debug, Clone, Default)]
pub struct GlbOptions<'a> {
    /// Texture coordinates, per vertex or per corner (vertices are split where corners of
    /// one vertex have different UVs, e.g. along a cut; normals stay those of the welded
    /// mesh so shading is smooth across seams).
    pub uvs: Option<Uvs<'a>>,
    /// Checks per UV unit of the embedded checker texture (used with `uvs`; default 8).
    pub checker_frequency: Option<f64>,
    /// One sRGB colour per vertex (COLOR_0).
    pub colors: Option<&'a [Rgb]>,
    /// Name of the mesh node.
    pub name: Option<String>,
}

/// A checkerboard texture with `checks × checks` squares of `px` pixels, light square at the
/// texture origin; black and white.
pub fn checker_texture(checks: u32, px: u32) -> Image {
    let n = checks.max(1) * px.max(1);
    let mut img = Image::new(n, n, [1.0; 3], 255);
    for y in 0..n {
        for x in 0..n {
            if ((x / px) + (y / px)) % 2 == 1 {
                let i = 4 * (y * n + x) as usize;
                img.data[i..i + 3].copy_from_slice(&[16, 16, 16]);
            }
        }
    }
    img
}

/// Build a `.glb` file in memory.
pub fn glb(positions: &[[f64; 3]], triangles: &[[u32; 3]], opts: &GlbOptions) -> Result<Vec<u8>> {
    check_mesh(positions, triangles)?;
    let n = positions.len();
    if let Some(c) = opts.colors {
        if c.len() != n {
            return input_err(format!("there are {} colours for {n} vertices", c.len()));
        }
    }
    match opts.uvs {
        None => glb_welded(positions, triangles, None, opts),
        Some(Uvs::PerVertex(uv)) => glb_welded(positions, triangles, Some(uv), opts),
        Some(Uvs::PerCorner(uv)) => {
            if uv.len() != 3 * triangles.len() {
                return input_err(format!(
                    "there are {} corner texture coordinates for {} corners",
                    uv.len(),
                    3 * triangles.len()
                ));
            }
            // Split vertices by (vertex, uv) and carry positions, normals and colours along.
            let normals = crate::render::vertex_normals(positions, triangles);
            let mut index: HashMap<(u32, u64, u64), u32> = HashMap::new();
            let (mut p2, mut n2, mut uv2, mut c2) =
                (Vec::new(), Vec::new(), Vec::new(), Vec::new());
            let mut t2 = Vec::with_capacity(triangles.len());
            for (f, t) in triangles.iter().enumerate() {
                let mut nt = [0u32; 3];
                for i in 0..3 {
                    let v = t[i];
                    let q = uv[3 * f + i];
                    let key = (v, q[0].to_bits(), q[1].to_bits());
                    nt[i] = *index.entry(key).or_insert_with(|| {
                        p2.push(positions[v as usize]);
                        n2.push(normals[v as usize]);
                        uv2.push(q);
                        if let Some(c) = opts.colors {
                            c2.push(c[v as usize]);
                        }
                        (p2.len() - 1) as u32
                    });
                }
                t2.push(nt);
            }
            let o2 = GlbOptions {
                uvs: None,
                colors: opts.colors.map(|_| c2.as_slice()),
                ..opts.clone()
            };
            glb_build(&p2, &t2, &n2, Some(&uv2), &o2)
        }
    }
}

fn glb_welded(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    uvs: Option<&[[f64; 2]]>,
    opts: &GlbOptions,
) -> Result<Vec<u8>> {
    let normals = crate::render::vertex_normals(positions, triangles);
    glb_build(positions, triangles, &normals, uvs, opts)
}

fn glb_build(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    normals: &[[f64; 3]],
    uvs: Option<&[[f64; 2]]>,
    opts: &GlbOptions,
) -> Result<Vec<u8>> {
    let n = positions.len();
    if let Some(uv) = uvs {
        if uv.len() != n {
            return input_err(format!(
                "there are {} texture coordinates for {n} vertices",
                uv.len()
            ));
        }
        if let Some(i) = uv
            .iter()
            .position(|p| !(p[0].is_finite() && p[1].is_finite()))
        {
            return input_err(format!("texture coordinate of vertex {i} is not finite"));
        }
    }
    let mut w = GlbWriter::default();
    let attributes = w.vertex_attributes(positions, normals, uvs, opts.colors);
    let indices = w.indices(triangles);
    let material = w.material(uvs.is_some(), opts)?;
    w.scene(attributes, indices, material, opts.name.clone());
    w.into_glb()
}

/// A glTF document being written: the JSON root and the binary buffer its views point into.
#[derive(Default)]
struct GlbWriter {
    root: json::Root,
    bin: Vec<u8>,
}

type Attributes = std::collections::BTreeMap<
    json::validation::Checked<json::mesh::Semantic>,
    json::Index<json::Accessor>,
>;

impl GlbWriter {
    /// A buffer view over `bytes`, appended to the buffer at a 4-byte boundary.
    fn view(
        &mut self,
        bytes: &[u8],
        target: Option<json::buffer::Target>,
        stride: Option<usize>,
    ) -> json::Index<json::buffer::View> {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        self.root.push(json::buffer::View {
            buffer: json::Index::<json::Buffer>::new(0),
            byte_length: USize64::from(bytes.len()),
            byte_offset: Some(USize64::from(offset)),
            byte_stride: stride.map(json::buffer::Stride),
            name: None,
            target: target.map(Valid),
            extensions: None,
            extras: Default::default(),
        })
    }

    /// An accessor of `count` elements of type `ty` over a view.
    fn accessor(
        &mut self,
        view: json::Index<json::buffer::View>,
        count: usize,
        ct: json::accessor::ComponentType,
        ty: json::accessor::Type,
        bounds: Option<(json::Value, json::Value)>,
    ) -> json::Index<json::Accessor> {
        let (min, max) = bounds.unzip();
        self.root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64::from(count),
            component_type: Valid(json::accessor::GenericComponentType(ct)),
            extensions: None,
            extras: Default::default(),
            type_: Valid(ty),
            min,
            max,
            name: None,
            normalized: false,
            sparse: None,
        })
    }

    /// A vertex attribute of `n` vectors of type `ty` (`stride` bytes each) from
    /// little-endian f32 `bytes`.
    fn f32_attribute(
        &mut self,
        bytes: &[u8],
        n: usize,
        (ty, stride): (json::accessor::Type, usize),
        bounds: Option<(json::Value, json::Value)>,
    ) -> json::Index<json::Accessor> {
        let v = self.view(bytes, Some(json::buffer::Target::ArrayBuffer), Some(stride));
        self.accessor(v, n, json::accessor::ComponentType::F32, ty, bounds)
    }

    /// Positions (f32, with bounds), normals (unit; isolated vertices get +z), UVs (v flipped
    /// to glTF's top-left origin) and linear colours.
    fn vertex_attributes(
        &mut self,
        positions: &[[f64; 3]],
        normals: &[[f64; 3]],
        uvs: Option<&[[f64; 2]]>,
        colors: Option<&[Rgb]>,
    ) -> Attributes {
        use json::accessor::Type as T;
        use json::mesh::Semantic;
        let n = positions.len();
        let mut lo = [f32::MAX; 3];
        let mut hi = [f32::MIN; 3];
        let mut bytes = Vec::with_capacity(12 * n);
        for p in positions {
            for k in 0..3 {
                let v = p[k] as f32;
                lo[k] = lo[k].min(v);
                hi[k] = hi[k].max(v);
                bytes.extend_from_slice(&v.to_le_bytes());
            }
        }
        let bounds = (
            json::Value::from(lo.to_vec()),
            json::Value::from(hi.to_vec()),
        );
        let mut attributes = Attributes::new();
        let pos = self.f32_attribute(&bytes, n, (T::Vec3, 12), Some(bounds));
        attributes.insert(Valid(Semantic::Positions), pos);

        let mut bytes = Vec::with_capacity(12 * n);
        for nrm in normals {
            let nrm = if nrm == &[0.0; 3] {
                [0.0, 0.0, 1.0]
            } else {
                *nrm
            };
            for c in nrm {
                bytes.extend_from_slice(&(c as f32).to_le_bytes());
            }
        }
        let nacc = self.f32_attribute(&bytes, n, (T::Vec3, 12), None);
        attributes.insert(Valid(Semantic::Normals), nacc);

        if let Some(uv) = uvs {
            let mut bytes = Vec::with_capacity(8 * n);
            for p in uv {
                bytes.extend_from_slice(&(p[0] as f32).to_le_bytes());
                bytes.extend_from_slice(&((1.0 - p[1]) as f32).to_le_bytes());
            }
            let a = self.f32_attribute(&bytes, n, (T::Vec2, 8), None);
            attributes.insert(Valid(Semantic::TexCoords(0)), a);
        }
        if let Some(cs) = colors {
            let mut bytes = Vec::with_capacity(12 * n);
            for c in cs {
                for x in color::to_linear(*c) {
                    bytes.extend_from_slice(&x.clamp(0.0, 1.0).to_le_bytes());
                }
            }
            let a = self.f32_attribute(&bytes, n, (T::Vec3, 12), None);
            attributes.insert(Valid(Semantic::Colors(0)), a);
        }
        attributes
    }

    /// The triangle indices (u32).
    fn indices(&mut self, triangles: &[[u32; 3]]) -> json::Index<json::Accessor> {
        let mut bytes = Vec::with_capacity(12 * triangles.len());
        for t in triangles {
            for &i in t {
                bytes.extend_from_slice(&i.to_le_bytes());
            }
        }
        let v = self.view(&bytes, Some(json::buffer::Target::ElementArrayBuffer), None);
        self.accessor(
            v,
            3 * triangles.len(),
            json::accessor::ComponentType::U32,
            json::accessor::Type::Scalar,
            None,
        )
    }

    /// The surface's material, with the checker texture when there are UVs.
    fn material(
        &mut self,
        textured: bool,
        opts: &GlbOptions,
    ) -> Result<json::Index<json::Material>> {
        let mut pbr = json::material::PbrMetallicRoughness {
            metallic_factor: json::material::StrengthFactor(0.0),
            roughness_factor: json::material::StrengthFactor(0.75),
            ..Default::default()
        };
        if textured {
            let f = opts.checker_frequency.unwrap_or(8.0);
            if !(f.is_finite() && f > 0.0) {
                return input_err(format!("the checker frequency {f} must be positive"));
            }
            let checks = (f.round() as u32).clamp(1, 64);
            let px = (2048 / checks).clamp(8, 64);
            let png = checker_texture(checks, px).to_png()?;
            let v = self.view(&png, None, None);
            let image = self.root.push(json::Image {
                buffer_view: Some(v),
                mime_type: Some(json::image::MimeType("image/png".into())),
                name: Some("checkerboard".into()),
                uri: None,
                extensions: None,
                extras: Default::default(),
            });
            let sampler = self.root.push(json::texture::Sampler {
                mag_filter: Some(Valid(json::texture::MagFilter::Nearest)),
                min_filter: Some(Valid(json::texture::MinFilter::LinearMipmapLinear)),
                wrap_s: Valid(json::texture::WrappingMode::Repeat),
                wrap_t: Valid(json::texture::WrappingMode::Repeat),
                ..Default::default()
            });
            let texture = self.root.push(json::Texture {
                name: None,
                sampler: Some(sampler),
                source: image,
                extensions: None,
                extras: Default::default(),
            });
            pbr.base_color_texture = Some(json::texture::Info {
                index: texture,
                tex_coord: 0,
                extensions: None,
                extras: Default::default(),
            });
        }
        Ok(self.root.push(json::Material {
            pbr_metallic_roughness: pbr,
            double_sided: true,
            name: Some("surface".into()),
            ..Default::default()
        }))
    }

    /// One mesh of one triangle primitive, in one node of the default scene.
    fn scene(
        &mut self,
        attributes: Attributes,
        indices: json::Index<json::Accessor>,
        material: json::Index<json::Material>,
        name: Option<String>,
    ) {
        let mesh = self.root.push(json::Mesh {
            extensions: None,
            extras: Default::default(),
            name: name.clone(),
            primitives: vec![json::mesh::Primitive {
                attributes,
                extensions: None,
                extras: Default::default(),
                indices: Some(indices),
                material: Some(material),
                mode: Valid(json::mesh::Mode::Triangles),
                targets: None,
            }],
            weights: None,
        });
        let node = self.root.push(json::Node {
            mesh: Some(mesh),
            name,
            ..Default::default()
        });
        let scene = self.root.push(json::Scene {
            extensions: None,
            extras: Default::default(),
            name: None,
            nodes: vec![node],
        });
        self.root.scene = Some(scene);
    }

    /// The binary glTF: header, JSON chunk (space-padded), BIN chunk (zero-padded).
    fn into_glb(mut self) -> Result<Vec<u8>> {
        let bin = &mut self.bin;
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        self.root.push(json::Buffer {
            byte_length: USize64::from(bin.len()),
            extensions: None,
            extras: Default::default(),
            name: None,
            uri: None,
        });
        self.root.asset.generator = Some(format!("ricci-render {}", env!("CARGO_PKG_VERSION")));
        let mut js = json::serialize::to_vec(&self.root)
            .map_err(|e| Error::Encode(format!("glTF JSON: {e}")))?;
        while !js.len().is_multiple_of(4) {
            js.push(b' ');
        }
        let bin = &self.bin;
        let total = 12 + 8 + js.len() + 8 + bin.len();
        let total32 = u32::try_from(total)
            .map_err(|_| Error::Encode("the glTF file would exceed 4 GiB".into()))?;
        let mut out = Vec::with_capacity(total);
        out.extend_from_slice(b"glTF");
        out.extend_from_slice(&2u32.to_le_bytes());
        out.extend_from_slice(&total32.to_le_bytes());
        out.extend_from_slice(&(js.len() as u32).to_le_bytes());
        out.extend_from_slice(b"JSON");
        out.extend_from_slice(&js);
        out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(bin);
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes;

    #[test]
    fn glb_parses_back_with_counts_and_uv_range() {
        let t = shapes::torus(2.0, 0.5, 24, 12);
        let n = t.positions.len();
        let uv: Vec<[f64; 2]> = (0..n)
            .map(|k| {
                [
                    -1.0 + 3.0 * (k / 12) as f64 / 23.0,
                    0.25 + 0.5 * (k % 12) as f64 / 11.0,
                ]
            })
            .collect();
        let colors: Vec<Rgb> = (0..n)
            .map(|k| color::Colormap::Viridis.eval(k as f64 / n as f64))
            .collect();
        let bytes = glb(
            &t.positions,
            &t.triangles,
            &GlbOptions {
                uvs: Some(Uvs::PerVertex(&uv)),
                checker_frequency: Some(6.0),
                colors: Some(&colors),
                name: Some("torus".into()),
            },
        )
        .unwrap();
        let g = ::gltf::Gltf::from_slice(&bytes).expect("valid glb");
        let blob = g.blob.as_deref().expect("binary chunk");
        let mesh = g.meshes().next().unwrap();
        let prim = mesh.primitives().next().unwrap();
        let reader = prim.reader(|_| Some(blob));
        let pos: Vec<[f32; 3]> = reader.read_positions().unwrap().collect();
        assert_eq!(pos.len(), n);
        assert_eq!(reader.read_normals().unwrap().count(), n);
        let idx: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
        assert_eq!(idx.len(), 3 * t.triangles.len());
        assert_eq!(&idx[..3], &t.triangles[0]);
        let tc: Vec<[f32; 2]> = reader.read_tex_coords(0).unwrap().into_f32().collect();
        let (umin, umax) = tc
            .iter()
            .fold((f32::MAX, f32::MIN), |a, p| (a.0.min(p[0]), a.1.max(p[0])));
        let (vmin, vmax) = tc
            .iter()
            .fold((f32::MAX, f32::MIN), |a, p| (a.0.min(p[1]), a.1.max(p[1])));
        assert!(
            (umin + 1.0).abs() < 1e-6 && (umax - 2.0).abs() < 1e-6,
            "u in [{umin}, {umax}]"
        );
        // v is flipped: [0.25, 0.75] -> [0.25, 0.75] (symmetric about 1/2).
        assert!(
            (vmin - 0.25).abs() < 1e-6 && (vmax - 0.75).abs() < 1e-6,
            "v in [{vmin}, {vmax}]"
        );
        assert_eq!(reader.read_colors(0).unwrap().into_rgb_f32().count(), n);
        // Bounds recorded in the accessor match the data.
        let b = prim.bounding_box();
        assert!((b.max[0] - 2.5).abs() < 1e-5 && (b.min[2] + 0.5).abs() < 1e-5);
        // The texture is an embedded PNG of 6 x 6 checks.
        let tex = prim
            .material()
            .pbr_metallic_roughness()
            .base_color_texture()
            .unwrap();
        let img = match tex.texture().source().source() {
            ::gltf::image::Source::View { view, mime_type } => {
                assert_eq!(mime_type, "image/png");
                &blob[view.offset()..view.offset() + view.length()]
            }
            _ => panic!("texture is not embedded"),
        };
        let img = Image::from_png(img).unwrap();
        let px = img.width / 6;
        assert_eq!(img.width, 6 * px);
        assert_ne!(img.pixel(0, 0)[0], img.pixel(px, 0)[0]);
        assert_eq!(img.pixel(0, 0)[0], img.pixel(px, px)[0]);
    }

    #[test]
    fn glb_without_uvs_has_no_texture_and_rejects_bad_lengths() {
        let s = shapes::icosphere(1);
        let bytes = glb(&s.positions, &s.triangles, &GlbOptions::default()).unwrap();
        let g = ::gltf::Gltf::from_slice(&bytes).unwrap();
        let prim = g.meshes().next().unwrap().primitives().next().unwrap();
        assert!(prim
            .material()
            .pbr_metallic_roughness()
            .base_color_texture()
            .is_none());
        assert_eq!(g.textures().count(), 0);
        assert!(glb(
            &s.positions,
            &s.triangles,
            &GlbOptions {
                uvs: Some(Uvs::PerVertex(&[[0.0; 2]])),
                ..Default::default()
            }
        )
        .is_err());
    }

    #[test]
    fn per_corner_uvs_split_vertices_only_at_seams() {
        // A torus with wrapping per-corner UVs: vertices on the two seam circles are split,
        // so the file has (n + 1)(m + 1) vertices instead of n m.
        let (n, m) = (10usize, 6usize);
        let t = shapes::torus(2.0, 0.5, n, m);
        let mut corner = Vec::new();
        for f in 0..t.triangles.len() {
            let (i, j) = ((f / 2) / m, (f / 2) % m);
            let uv =
                |di: usize, dj: usize| [(i + di) as f64 / n as f64, (j + dj) as f64 / m as f64];
            if f % 2 == 0 {
                corner.extend([uv(0, 0), uv(1, 0), uv(1, 1)]);
            } else {
                corner.extend([uv(0, 0), uv(1, 1), uv(0, 1)]);
            }
        }
        let bytes = glb(
            &t.positions,
            &t.triangles,
            &GlbOptions {
                uvs: Some(Uvs::PerCorner(&corner)),
                ..Default::default()
            },
        )
        .unwrap();
        let g = ::gltf::Gltf::from_slice(&bytes).unwrap();
        let blob = g.blob.as_deref().unwrap();
        let prim = g.meshes().next().unwrap().primitives().next().unwrap();
        let reader = prim.reader(|_| Some(blob));
        assert_eq!(reader.read_positions().unwrap().count(), (n + 1) * (m + 1));
        assert_eq!(
            reader.read_indices().unwrap().into_u32().count(),
            3 * t.triangles.len()
        );
        let tc: Vec<[f32; 2]> = reader.read_tex_coords(0).unwrap().into_f32().collect();
        let umax = tc.iter().map(|p| p[0]).fold(0.0f32, f32::max);
        assert!((umax - 1.0).abs() < 1e-6);
    }
}
