//! Decoding material textures with memory bounded by the texture limits: an image is refused
//! above `MAX_TEXTURE_DIM`, kept as it is up to `MAX_DECODED_DIM`, and reduced in between: a
//! PNG while it is decoded, row by row, so the full-size picture never exists in memory;
//! another format (JPEG) once decoded in its own layout, without a full-size RGBA copy.
//! (The renderer keeps at most its `max_texture_size` of each on the GPU.)

use crate::limits::{MAX_DECODED_DIM, MAX_TEXTURE_DIM};
use crate::{Texture, srgb_to_linear};
use std::io::Cursor;

/// Decodes an encoded image (PNG, JPEG) to an RGBA8 texture called `name`; the error says
/// why, without the name (the caller names the file or the glTF image).
pub fn decode(bytes: &[u8], name: String) -> Result<Texture, String> {
    let reader = image::ImageReader::new(Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| e.to_string())?;
    let Some(format) = reader.format() else {
        return Err("unknown image format (voxgi reads PNG and JPEG)".into());
    };
    let (w, h) = reader.into_dimensions().map_err(|e| e.to_string())?;
    if w > MAX_TEXTURE_DIM || h > MAX_TEXTURE_DIM {
        return Err(format!(
            "{w}x{h} is larger than the {MAX_TEXTURE_DIM}x{MAX_TEXTURE_DIM} texture limit"
        ));
    }
    if w.max(h) > MAX_DECODED_DIM {
        if format == image::ImageFormat::Png {
            return decode_png_reduced(bytes, name, w, h);
        }
        return decode_reduced(bytes, name, w, h);
    }
    // Room for the largest kept image at 16 bits per channel RGBA.
    let reader = limited_reader(bytes, u64::from(MAX_DECODED_DIM).pow(2) * 8)?;
    // to_rgba8 converts any decoded layout (L8, LA8, RGB8, 16-bit, float) to RGBA8: grey is
    // replicated, missing alpha is opaque, wider channels are rescaled.
    let rgba = reader.decode().map_err(|e| e.to_string())?.to_rgba8();
    Ok(Texture {
        name,
        width: rgba.width(),
        height: rgba.height(),
        rgba8: rgba.into_raw(),
    })
}

/// A reader of `bytes` that allocates at most `max_alloc` bytes while decoding.
fn limited_reader(
    bytes: &[u8],
    max_alloc: u64,
) -> Result<image::ImageReader<Cursor<&[u8]>>, String> {
    let mut reader = image::ImageReader::new(Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| e.to_string())?;
    let mut limits = image::Limits::default();
    limits.max_alloc = Some(max_alloc);
    reader.limits(limits);
    Ok(reader)
}

/// The smallest power of two that brings `w` × `h` within `MAX_DECODED_DIM`.
fn reduction(w: u32, h: u32) -> u32 {
    let mut k = 2u32;
    while w.max(h).div_ceil(k) > MAX_DECODED_DIM {
        k *= 2;
    }
    k
}

/// An image of another format (JPEG) larger than `MAX_DECODED_DIM`: decoded whole in its own
/// layout (at most `MAX_TEXTURE_DIM`² RGB, 768 MiB, for a JPEG), then reduced row by row as
/// `decode_png_reduced` does, without a full-size RGBA copy.
fn decode_reduced(bytes: &[u8], name: String, w: u32, h: u32) -> Result<Texture, String> {
    let img = limited_reader(bytes, u64::from(MAX_TEXTURE_DIM).pow(2) * 4)?
        .decode()
        .map_err(|e| e.to_string())?;
    let mut reduce = Reducer::new(w, h, reduction(w, h));
    let mut rgba = vec![0u8; w as usize * 4];
    let (src, channels) = match &img {
        image::DynamicImage::ImageRgb8(b) => (b.as_raw().as_slice(), 3),
        image::DynamicImage::ImageLuma8(b) => (b.as_raw().as_slice(), 1),
        image::DynamicImage::ImageRgba8(b) => (b.as_raw().as_slice(), 4),
        other => return Err(format!("{w}x{h} {:?}: too large to convert", other.color())),
    };
    for row in src.chunks_exact(w as usize * channels) {
        for (px, o) in row.chunks_exact(channels).zip(rgba.chunks_exact_mut(4)) {
            o.copy_from_slice(&match channels {
                1 => [px[0], px[0], px[0], 255],
                3 => [px[0], px[1], px[2], 255],
                _ => [px[0], px[1], px[2], px[3]],
            });
        }
        reduce.row(&rgba);
    }
    let (ow, oh, out) = reduce.finish();
    log::warn!(
        "texture {name}: {w}x{h} reduced to {ow}x{oh} (textures are kept at most \
         {MAX_DECODED_DIM}x{MAX_DECODED_DIM})"
    );
    Ok(Texture {
        name,
        width: ow,
        height: oh,
        rgba8: out,
    })
}

/// A PNG larger than `MAX_DECODED_DIM` reduced by the smallest power of two that brings it
/// within, each texel the mean of its k×k block in linear light (alpha as it is), decoded row
/// by row: memory holds one input row and one row of sums besides the result.
fn decode_png_reduced(bytes: &[u8], name: String, w: u32, h: u32) -> Result<Texture, String> {
    let k = reduction(w, h);
    let mut decoder = png::Decoder::new(Cursor::new(bytes));
    decoder.set_transformations(png::Transformations::normalize_to_color8());
    let mut reader = decoder.read_info().map_err(|e| e.to_string())?;
    if reader.info().interlaced {
        return Err(format!(
            "{w}x{h} interlaced PNG: larger than {MAX_DECODED_DIM}x{MAX_DECODED_DIM}, and an \
             interlaced one cannot be reduced row by row; save it without interlacing"
        ));
    }
    let channels = match reader.output_color_type().0 {
        png::ColorType::Grayscale => 1,
        png::ColorType::GrayscaleAlpha => 2,
        png::ColorType::Rgb => 3,
        png::ColorType::Rgba => 4,
        png::ColorType::Indexed => return Err("palette left unexpanded".into()),
    };
    let mut reduce = Reducer::new(w, h, k);
    let mut rgba = vec![0u8; w as usize * 4];
    for y in 0..h {
        let row = reader
            .next_row()
            .map_err(|e| format!("row {y}: {e}"))?
            .ok_or_else(|| format!("ends at row {y} of {h}"))?;
        for (px, o) in row
            .data()
            .chunks_exact(channels)
            .zip(rgba.chunks_exact_mut(4))
        {
            o.copy_from_slice(&match channels {
                1 => [px[0], px[0], px[0], 255],
                2 => [px[0], px[0], px[0], px[1]],
                3 => [px[0], px[1], px[2], 255],
                _ => [px[0], px[1], px[2], px[3]],
            });
        }
        reduce.row(&rgba);
    }
    let (ow, oh, out) = reduce.finish();
    log::warn!(
        "texture {name}: {w}x{h} reduced to {ow}x{oh} while decoding (textures are kept at \
         most {MAX_DECODED_DIM}x{MAX_DECODED_DIM})"
    );
    Ok(Texture {
        name,
        width: ow,
        height: oh,
        rgba8: out,
    })
}

/// Reduces an sRGB RGBA8 image row by row by an integer factor `k`: each texel the mean of
/// its k×k block (fewer at the right and bottom edges) in linear light, alpha as it is.
pub struct Reducer {
    k: u32,
    width: u32,
    height: u32,
    rows: u32,
    to_linear: Vec<f32>,
    sums: Vec<f32>,
    counts: Vec<u32>,
    out: Vec<u8>,
}

impl Reducer {
    /// A reducer of a `width` × `height` image.
    pub fn new(width: u32, height: u32, k: u32) -> Self {
        let (ow, oh) = (width.div_ceil(k), height.div_ceil(k));
        Reducer {
            k,
            width,
            height,
            rows: 0,
            to_linear: (0..=255u8)
                .map(|v| srgb_to_linear(v as f32 / 255.0))
                .collect(),
            sums: vec![0.0; ow as usize * 4],
            counts: vec![0; ow as usize],
            out: Vec::with_capacity(ow as usize * oh as usize * 4),
        }
    }

    /// The next row, `width` RGBA8 texels.
    pub fn row(&mut self, rgba: &[u8]) {
        let k = self.k as usize;
        for (x, px) in rgba.chunks_exact(4).take(self.width as usize).enumerate() {
            let o = x / k;
            let s = &mut self.sums[o * 4..o * 4 + 4];
            for c in 0..3 {
                s[c] += self.to_linear[px[c] as usize];
            }
            s[3] += px[3] as f32 / 255.0;
            self.counts[o] += 1;
        }
        self.rows += 1;
        if self.rows.is_multiple_of(self.k) || self.rows == self.height {
            for (s, &n) in self.sums.chunks_exact_mut(4).zip(&self.counts) {
                let n = n.max(1) as f32;
                self.out
                    .extend([0, 1, 2].map(|c| crate::io::cloud::linear_to_srgb8(s[c] / n)));
                self.out
                    .push((s[3] / n * 255.0).round().clamp(0.0, 255.0) as u8);
                s.fill(0.0);
            }
            self.counts.fill(0);
        }
    }

    /// The reduced image: width, height, RGBA8.
    pub fn finish(self) -> (u32, u32, Vec<u8>) {
        (
            self.width.div_ceil(self.k),
            self.height.div_ceil(self.k),
            self.out,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn png(w: u32, h: u32, color: image::ColorType, data: &[u8]) -> Vec<u8> {
        let mut b = Vec::new();
        image::write_buffer_with_format(
            &mut Cursor::new(&mut b),
            data,
            w,
            h,
            color,
            image::ImageFormat::Png,
        )
        .unwrap();
        b
    }

    #[test]
    fn a_png_wider_than_kept_is_reduced_to_block_means_in_linear_light() {
        // Columns alternate black and white, rows alternate alpha 0 and 255: every 2x2 block
        // holds two of each, so each reduced texel is half the light (sRGB 188 after
        // rounding) and half the alpha (128).
        let (w, h) = (MAX_DECODED_DIM * 2, 4);
        let mut data = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let v = if x % 2 == 0 { 0 } else { 255 };
                data.extend([v, v, v, if y % 2 == 0 { 0 } else { 255 }]);
            }
        }
        let t = decode(&png(w, h, image::ColorType::Rgba8, &data), "wide".into()).unwrap();
        assert_eq!((t.width, t.height), (MAX_DECODED_DIM, 2));
        let half = crate::io::cloud::linear_to_srgb8(0.5);
        assert_eq!(half, 188);
        assert!(
            t.rgba8
                .chunks_exact(4)
                .all(|p| p == [half, half, half, 128])
        );
    }

    #[test]
    fn a_grey_png_of_odd_size_keeps_its_last_partial_block() {
        // 8193 columns of grey 200, 3 rows: 4097 texels wide, 2 high, the last column and row
        // the mean of what the image has there (the same grey).
        let (w, h) = (MAX_DECODED_DIM + 1, 3);
        let data = vec![200u8; (w * h) as usize];
        let t = decode(&png(w, h, image::ColorType::L8, &data), "odd".into()).unwrap();
        assert_eq!((t.width, t.height), (MAX_DECODED_DIM / 2 + 1, 2));
        assert!(
            t.rgba8.chunks_exact(4).all(|p| p == [200, 200, 200, 255]),
            "{:?}",
            &t.rgba8[..8]
        );
    }

    #[test]
    fn a_jpeg_wider_than_kept_is_reduced_too() {
        // A flat grey JPEG (JPEG keeps flat areas exact up to a step or two).
        let (w, h) = (MAX_DECODED_DIM + 8, 16);
        let mut b = Vec::new();
        image::codecs::jpeg::JpegEncoder::new_with_quality(&mut b, 95)
            .encode(
                &vec![120u8; (w * h) as usize],
                w,
                h,
                image::ExtendedColorType::L8,
            )
            .unwrap();
        let t = decode(&b, "wide.jpg".into()).unwrap();
        assert_eq!((t.width, t.height), (MAX_DECODED_DIM / 2 + 4, 8));
        assert!(
            t.rgba8
                .chunks_exact(4)
                .all(|p| p[0].abs_diff(120) <= 2 && p[3] == 255),
            "{:?}",
            &t.rgba8[..8]
        );
    }

    #[test]
    fn an_image_within_the_kept_size_is_as_decoded() {
        let data = [10u8, 20, 30, 40, 50, 60];
        let t = decode(&png(2, 1, image::ColorType::Rgb8, &data), "small".into()).unwrap();
        assert_eq!((t.width, t.height), (2, 1));
        assert_eq!(t.rgba8, [10, 20, 30, 255, 40, 50, 60, 255]);
    }

    #[test]
    fn beyond_the_limit_or_not_an_image_is_an_error() {
        let w = MAX_TEXTURE_DIM + 1;
        let b = png(w, 1, image::ColorType::L8, &vec![0; w as usize]);
        let e = decode(&b, "huge".into()).unwrap_err();
        assert!(
            e.contains("16385x1 is larger than the 16384x16384 texture limit"),
            "{e}"
        );
        let e = decode(b"not an image", "text".into()).unwrap_err();
        assert!(e.contains("unknown image format"), "{e}");
    }
}
