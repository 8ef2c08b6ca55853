//! Image comparison: mean FLIP (NVIDIA's perceptual error, via the `nv-flip` crate), RMSE and
//! relative MSE.
//!
//! - LDR images (PNG): LDR-FLIP on the sRGB-encoded 8-bit values.
//! - HDR images (EXR): HDR-FLIP as its paper defines it (Andersson et al. 2021, "Visualizing
//!   Errors in Rendered High Dynamic Range Images"): exposures from the reference's luminance
//!   (start: the maximum maps to ACES output 0.85; stop: the median does), LDR-FLIP of both
//!   images tone mapped with FLIP's ACES at each exposure, the per-pixel maximum. The tone-mapped
//!   images are quantised to 8 bits for nv-flip's LDR entry point, which changes FLIP values
//!   by well under 1e-2.
//! - RMSE and relative MSE (mean of (t - r)² / (r² + 0.01)) over all RGB values, on linear
//!   values (PNGs are sRGB-decoded).

use crate::output::linear_to_srgb;
use crate::{Error, Result};
use std::path::Path;

/// An image to compare: linear RGB, plus its 8-bit sRGB encoding for LDR images.
#[derive(Clone, Debug)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Linear RGB, row-major from the top-left.
    pub linear: Vec<[f32; 3]>,
    /// The sRGB-encoded RGB8 values of an LDR image; `None` for HDR images.
    pub srgb8: Option<Vec<u8>>,
}

impl Image {
    /// An HDR image from linear RGBA f32 (as `RenderOutput::hdr`).
    pub fn from_hdr_rgba(width: u32, height: u32, rgba: &[f32]) -> Self {
        Image {
            width,
            height,
            linear: rgba.chunks_exact(4).map(|p| [p[0], p[1], p[2]]).collect(),
            srgb8: None,
        }
    }

    /// An LDR image from sRGB-encoded RGBA8 (as `RenderOutput::ldr`).
    pub fn from_ldr_rgba8(width: u32, height: u32, rgba: &[u8]) -> Self {
        let srgb8: Vec<u8> = rgba
            .chunks_exact(4)
            .flat_map(|p| [p[0], p[1], p[2]])
            .collect();
        Image {
            width,
            height,
            linear: srgb8
                .chunks_exact(3)
                .map(|p| [0, 1, 2].map(|c| voxgi_scene::srgb_to_linear(p[c] as f32 / 255.0)))
                .collect(),
            srgb8: Some(srgb8),
        }
    }

    /// Whether this is an HDR image (no 8-bit sRGB values), compared with HDR-FLIP.
    pub fn is_hdr(&self) -> bool {
        self.srgb8.is_none()
    }

    /// Loads by extension: `.exr` as HDR, `.png` (or `.jpg`) as LDR.
    pub fn load(path: &Path) -> Result<Self> {
        let fail = |reason: String| Error::Output {
            path: path.to_path_buf(),
            reason,
        };
        if !path.exists() {
            return Err(fail("no such file".into()));
        }
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .unwrap_or("")
            .to_ascii_lowercase();
        match ext.as_str() {
            "exr" => {
                let (w, h, px) = crate::output::load_linear(path)?;
                Ok(Image {
                    width: w,
                    height: h,
                    linear: px,
                    srgb8: None,
                })
            }
            "png" | "jpg" | "jpeg" => {
                let img = image::open(path)
                    .map_err(|e| fail(e.to_string()))?
                    .to_rgba8();
                Ok(Image::from_ldr_rgba8(
                    img.width(),
                    img.height(),
                    img.as_raw(),
                ))
            }
            _ => Err(fail(format!(
                "unknown image type '.{ext}' (use .png or .exr)"
            ))),
        }
    }
}

/// The result of comparing a test image with a reference.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Comparison {
    /// Mean FLIP error in [0, 1] (LDR-FLIP for LDR images, HDR-FLIP for HDR images).
    pub flip_mean: f32,
    /// Root mean square error over all linear RGB values.
    pub rmse: f64,
    /// Relative MSE: mean of (t - r)² / (r² + 0.01) over all linear RGB values.
    pub rel_mse: f64,
    /// Whether HDR-FLIP was used.
    pub hdr: bool,
}

/// Compares `test` with `reference`; the per-pixel FLIP error map comes back with it.
pub fn compare_with_map(reference: &Image, test: &Image) -> Result<(Comparison, Vec<f32>)> {
    if reference.width != test.width || reference.height != test.height {
        return Err(Error::Setting(format!(
            "image sizes differ: reference {}x{}, test {}x{}",
            reference.width, reference.height, test.width, test.height
        )));
    }
    if reference.is_hdr() != test.is_hdr() {
        return Err(Error::Setting(
            "cannot compare an HDR image with an LDR one: compare EXR with EXR or PNG with PNG"
                .into(),
        ));
    }
    if reference.linear.is_empty() {
        return Err(Error::Setting("the images are empty".into()));
    }
    let (mut se, mut rel) = (0f64, 0f64);
    for (r, t) in reference.linear.iter().zip(&test.linear) {
        for c in 0..3 {
            let (r, t) = (r[c] as f64, t[c] as f64);
            se += (t - r) * (t - r);
            rel += (t - r) * (t - r) / (r * r + 1e-2);
        }
    }
    let n = (reference.linear.len() * 3) as f64;
    let (w, h) = (reference.width, reference.height);
    let map = match (&reference.srgb8, &test.srgb8) {
        (Some(r), Some(t)) => ldr_flip(w, h, r, t),
        _ => hdr_flip(w, h, &reference.linear, &test.linear),
    };
    let flip_mean = (map.iter().map(|&e| e as f64).sum::<f64>() / map.len() as f64) as f32;
    Ok((
        Comparison {
            flip_mean,
            rmse: (se / n).sqrt(),
            rel_mse: rel / n,
            hdr: reference.is_hdr(),
        },
        map,
    ))
}

/// Compares `test` with `reference`.
pub fn compare(reference: &Image, test: &Image) -> Result<Comparison> {
    compare_with_map(reference, test).map(|c| c.0)
}

fn ldr_flip(w: u32, h: u32, reference: &[u8], test: &[u8]) -> Vec<f32> {
    if reference == test {
        // FLIP of identical images is 0; skip the filters.
        return vec![0.0; (w * h) as usize];
    }
    let r = nv_flip::FlipImageRgb8::with_data(w, h, reference);
    let t = nv_flip::FlipImageRgb8::with_data(w, h, test);
    nv_flip::flip(r, t, nv_flip::DEFAULT_PIXELS_PER_DEGREE).to_vec()
}

/// FLIP's ACES fit (with its 0.6 pre-exposure cancellation), as rational coefficients
/// (a x² + b x + c) / (d x² + e x + f).
const FLIP_ACES: [f32; 6] = [
    0.6 * 0.6 * 2.51,
    0.6 * 0.03,
    0.0,
    0.6 * 0.6 * 2.43,
    0.6 * 0.59,
    0.14,
];

fn flip_aces(x: f32) -> f32 {
    let c = FLIP_ACES;
    ((x * x * c[0] + x * c[1] + c[2]) / (x * x * c[3] + x * c[4] + c[5])).clamp(0.0, 1.0)
}

fn luminance(c: &[f32; 3]) -> f32 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

/// HDR-FLIP's exposure range from the reference (FLIP's `computeExposures`).
pub fn hdr_exposures(reference: &[[f32; 3]]) -> (f32, f32) {
    let c = FLIP_ACES;
    let t = 0.85;
    let (a, b, cc) = (c[0] - t * c[3], c[1] - t * c[4], c[2] - t * c[5]);
    // The larger root of a x² + b x + c = 0.
    let d1 = -0.5 * (b / a);
    let x_max = d1 + (d1 * d1 - cc / a).sqrt();
    let mut lum: Vec<f32> = reference.iter().map(luminance).collect();
    lum.sort_by(f32::total_cmp);
    let y_max = *lum.last().unwrap_or(&0.0);
    let mid = (lum.len() / 2).saturating_sub(1);
    let mut y_median = (lum[mid] + lum[(mid + 1).min(lum.len() - 1)]) * 0.5;
    if y_median <= 0.0 {
        // Mostly black references: FLIP's stop exposure would be infinite; use the dimmest
        // non-black pixel instead.
        y_median = lum.iter().copied().find(|&y| y > 0.0).unwrap_or(0.0);
    }
    let start = (x_max / y_max).log2();
    let stop = (x_max / y_median).log2();
    (start, stop)
}

fn hdr_flip(w: u32, h: u32, reference: &[[f32; 3]], test: &[[f32; 3]]) -> Vec<f32> {
    if reference == test {
        return vec![0.0; (w * h) as usize];
    }
    let (mut start, mut stop) = hdr_exposures(reference);
    // A black (or single-valued) reference has no usable range: fall back to exposure 0.
    if !start.is_finite() || !stop.is_finite() {
        (start, stop) = (0.0, 0.0);
    }
    let count = ((stop - start).ceil() as i32).max(2);
    let step = (stop - start) / (count - 1) as f32;
    let encode = |img: &[[f32; 3]], scale: f32| -> Vec<u8> {
        img.iter()
            .flat_map(|p| {
                p.map(|v| (linear_to_srgb(flip_aces((v * scale).max(0.0))) * 255.0 + 0.5) as u8)
            })
            .collect()
    };
    let mut max = vec![0f32; (w * h) as usize];
    for i in 0..count {
        let scale = 2f32.powf(start + i as f32 * step);
        let e = ldr_flip(w, h, &encode(reference, scale), &encode(test, scale));
        for (m, v) in max.iter_mut().zip(e) {
            *m = m.max(v);
        }
    }
    max
}

/// Writes a FLIP error map as a PNG coloured with the magma LUT.
pub fn save_error_map(path: &Path, width: u32, height: u32, map: &[f32]) -> Result<()> {
    let img = nv_flip::FlipImageFloat::with_data(width, height, map);
    let rgb = img.apply_color_lut(&nv_flip::magma_lut()).to_vec();
    crate::scene::io::atomic::replace_with(path, |w| {
        image::write_buffer_with_format(
            w,
            &rgb,
            width,
            height,
            image::ExtendedColorType::Rgb8,
            image::ImageFormat::Png,
        )
        .map_err(std::io::Error::other)
    })
    .map_err(|e| Error::Output {
        path: path.to_path_buf(),
        reason: e.to_string(),
    })
}
