//! RGBA images (8-bit sRGB, straight alpha) and PNG encoding.

use crate::{color::Rgb, Error, Result};

/// An RGBA image, 8 bits per channel, sRGB, straight (not premultiplied) alpha, rows top to
/// bottom.
#[derive(Debug, Clone, PartialEq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    /// `4 * width * height` bytes.
    pub data: Vec<u8>,
}

impl Image {
    /// An image filled with one colour and alpha (0 transparent … 255 opaque).
    pub fn new(width: u32, height: u32, color: Rgb, alpha: u8) -> Image {
        let c = to8(color);
        let px = [c[0], c[1], c[2], alpha];
        let data = px
            .iter()
            .copied()
            .cycle()
            .take(4 * width as usize * height as usize)
            .collect();
        Image {
            width,
            height,
            data,
        }
    }

    /// The RGBA value at (x, y).
    pub fn pixel(&self, x: u32, y: u32) -> [u8; 4] {
        let i = 4 * (y as usize * self.width as usize + x as usize);
        [
            self.data[i],
            self.data[i + 1],
            self.data[i + 2],
            self.data[i + 3],
        ]
    }

    /// Composite a colour with coverage `a` ∈ [0, 1] over pixel (x, y) (ignored outside).
    /// Blending is done in 8-bit sRGB, which is what 2D overlays (text, legend) expect.
    pub fn blend(&mut self, x: i64, y: i64, color: Rgb, a: f32) {
        if x < 0 || y < 0 || x >= self.width as i64 || y >= self.height as i64 || a <= 0.0 {
            return;
        }
        let a = a.min(1.0);
        let i = 4 * (y as usize * self.width as usize + x as usize);
        let c = to8(color);
        let da = self.data[i + 3] as f32 / 255.0;
        let oa = a + da * (1.0 - a);
        for k in 0..3 {
            let dst = self.data[i + k] as f32;
            let v = if oa > 0.0 {
                (c[k] as f32 * a + dst * da * (1.0 - a)) / oa
            } else {
                0.0
            };
            self.data[i + k] = v.round().clamp(0.0, 255.0) as u8;
        }
        self.data[i + 3] = (oa * 255.0).round() as u8;
    }

    /// Fill an axis-aligned rectangle (pixel units, clipped).
    pub fn fill_rect(&mut self, x0: i64, y0: i64, w: i64, h: i64, color: Rgb, a: f32) {
        for y in y0.max(0)..(y0 + h).min(self.height as i64) {
            for x in x0.max(0)..(x0 + w).min(self.width as i64) {
                self.blend(x, y, color, a);
            }
        }
    }

    /// Encode as PNG (RGBA8, or RGB8 when every pixel is opaque).
    pub fn to_png(&self) -> Result<Vec<u8>> {
        let opaque = self.data.chunks_exact(4).all(|p| p[3] == 255);
        let mut out = Vec::new();
        {
            let mut enc = png::Encoder::new(&mut out, self.width, self.height);
            enc.set_depth(png::BitDepth::Eight);
            enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
            enc.set_compression(png::Compression::Fast);
            let enc_err =
                |e: png::EncodingError| Error::Encode(format!("PNG encoding failed: {e}"));
            if opaque {
                enc.set_color(png::ColorType::Rgb);
                let rgb: Vec<u8> = self
                    .data
                    .chunks_exact(4)
                    .flat_map(|p| [p[0], p[1], p[2]])
                    .collect();
                let mut w = enc.write_header().map_err(enc_err)?;
                w.write_image_data(&rgb).map_err(enc_err)?;
            } else {
                enc.set_color(png::ColorType::Rgba);
                let mut w = enc.write_header().map_err(enc_err)?;
                w.write_image_data(&self.data).map_err(enc_err)?;
            }
        }
        Ok(out)
    }

    /// Decode a PNG written by [`Image::to_png`] (RGB8 or RGBA8), e.g. to inspect it in tests.
    pub fn from_png(bytes: &[u8]) -> Result<Image> {
        let dec_err = |e: png::DecodingError| Error::Input(format!("PNG decoding failed: {e}"));
        let mut dec = png::Decoder::new(std::io::Cursor::new(bytes));
        dec.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
        let mut reader = dec.read_info().map_err(dec_err)?;
        let mut buf = vec![0; reader.output_buffer_size().unwrap_or(0)];
        let info = reader.next_frame(&mut buf).map_err(dec_err)?;
        let (w, h) = (info.width, info.height);
        let n = (w * h) as usize;
        let data = match info.color_type {
            png::ColorType::Rgba => buf[..4 * n].to_vec(),
            png::ColorType::Rgb => buf[..3 * n]
                .chunks_exact(3)
                .flat_map(|p| [p[0], p[1], p[2], 255])
                .collect(),
            png::ColorType::Grayscale => buf[..n].iter().flat_map(|&g| [g, g, g, 255]).collect(),
            png::ColorType::GrayscaleAlpha => buf[..2 * n]
                .chunks_exact(2)
                .flat_map(|p| [p[0], p[0], p[0], p[1]])
                .collect(),
            png::ColorType::Indexed => {
                return Err(Error::Input("indexed PNG was not expanded".into()))
            }
        };
        Ok(Image {
            width: w,
            height: h,
            data,
        })
    }

    /// Convert from a tiny-skia pixmap (premultiplied) to straight alpha.
    pub(crate) fn from_pixmap(p: tiny_skia::Pixmap) -> Image {
        let (width, height) = (p.width(), p.height());
        Image {
            width,
            height,
            data: p.take_demultiplied(),
        }
    }
}

/// sRGB [0, 1] to 8-bit.
#[inline]
pub(crate) fn to8(c: Rgb) -> [u8; 3] {
    c.map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8)
}
