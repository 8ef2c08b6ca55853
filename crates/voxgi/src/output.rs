//! Rendered images and (with the `image-io` feature) writing them: PNG (sRGB, tone mapped) and
//! EXR (linear HDR).

use crate::Tonemap;
#[cfg(feature = "image-io")]
use crate::{Error, Result};
#[cfg(feature = "image-io")]
use std::path::Path;

/// What one render produced.
#[derive(Clone, Debug)]
pub struct RenderOutput {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Linear radiance, RGBA f32, row-major from the top-left, before exposure.
    pub hdr: Vec<f32>,
    /// Tone-mapped sRGB-encoded RGBA8.
    pub ldr: Vec<u8>,
}

impl RenderOutput {
    /// Linear radiance of pixel (x, y).
    pub fn radiance(&self, x: u32, y: u32) -> [f32; 3] {
        let i = ((y * self.width + x) * 4) as usize;
        [self.hdr[i], self.hdr[i + 1], self.hdr[i + 2]]
    }

    /// Mean linear radiance over the image.
    pub fn mean_radiance(&self) -> [f32; 3] {
        let mut s = [0f64; 3];
        for p in self.hdr.chunks_exact(4) {
            for c in 0..3 {
                s[c] += p[c] as f64;
            }
        }
        let n = (self.width * self.height).max(1) as f64;
        [(s[0] / n) as f32, (s[1] / n) as f32, (s[2] / n) as f32]
    }

    /// Writes by extension: `.png` gets the tone-mapped image, `.exr` the linear radiance.
    #[cfg(feature = "image-io")]
    pub fn save(&self, path: &Path) -> Result<()> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .unwrap_or("")
            .to_ascii_lowercase();
        let fail = |reason: String| Error::Output {
            path: path.to_path_buf(),
            reason,
        };
        let write = |w: &mut std::io::BufWriter<std::fs::File>| match ext.as_str() {
            "png" => image::write_buffer_with_format(
                w,
                &self.ldr,
                self.width,
                self.height,
                image::ExtendedColorType::Rgba8,
                image::ImageFormat::Png,
            )
            .map_err(std::io::Error::other),
            _ => {
                use exr::prelude::WritableImage as _;
                let (wd, ht) = (self.width as usize, self.height as usize);
                let channels =
                    exr::prelude::SpecificChannels::rgb(|p: exr::prelude::Vec2<usize>| {
                        let i = (p.1 * wd + p.0) * 4;
                        (self.hdr[i], self.hdr[i + 1], self.hdr[i + 2])
                    });
                exr::prelude::Image::from_channels((wd, ht), channels)
                    .write()
                    .to_buffered(w)
                    .map_err(std::io::Error::other)
            }
        };
        match ext.as_str() {
            "png" | "exr" => {
                crate::scene::io::atomic::replace_with(path, write).map_err(|e| fail(e.to_string()))
            }
            _ => Err(fail(format!(
                "unknown image type '.{ext}' (use .png or .exr)"
            ))),
        }
    }
}

/// The sRGB opto-electronic transfer function (IEC 61966-2-1), clamping to [0, 1].
pub fn linear_to_srgb(c: f32) -> f32 {
    let c = c.clamp(0.0, 1.0);
    if c <= 0.0031308 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// Narkowicz's fit of the ACES reference rendering transform (as tonemap.wgsl).
fn aces(x: f32) -> f32 {
    let x = x.min(1e4);
    ((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14)).clamp(0.0, 1.0)
}

/// Khronos PBR Neutral (as tonemap.wgsl).
fn pbr_neutral(c: [f32; 3]) -> [f32; 3] {
    let start = 0.8 - 0.04;
    let desaturation = 0.15;
    let x = c[0].min(c[1]).min(c[2]);
    let offset = if x < 0.08 { x - 6.25 * x * x } else { 0.04 };
    let mut c = c.map(|v| v - offset);
    let peak = c[0].max(c[1]).max(c[2]);
    if peak < start {
        return c;
    }
    let d = 1.0 - start;
    let new_peak = 1.0 - d * d / (peak + d - start);
    c = c.map(|v| v * new_peak / peak);
    let g = 1.0 - 1.0 / (desaturation * (peak - new_peak) + 1.0);
    c.map(|v| v + (new_peak - v) * g)
}

/// The CPU twin of `shaders/tonemap.wgsl`: linear RGBA f32 radiance -> exposure (2^EV), tone
/// curve, sRGB encoding -> RGBA8 with opaque alpha. Used for images made without the
/// rasterizer (the path tracer); agrees with the GPU pass within one unit per channel.
pub fn tonemap(hdr: &[f32], exposure_ev: f32, curve: Tonemap) -> Vec<u8> {
    let scale = 2f32.powf(exposure_ev);
    hdr.chunks_exact(4)
        .flat_map(|p| {
            let c = [p[0], p[1], p[2]].map(|v| (v * scale).max(0.0));
            let t = match curve {
                Tonemap::Aces => c.map(aces),
                Tonemap::Neutral => pbr_neutral(c),
                Tonemap::Clamp => c,
            };
            let e = t.map(|v| (linear_to_srgb(v) * 255.0 + 0.5) as u8);
            [e[0], e[1], e[2], 255]
        })
        .collect()
}

/// Reads an image as linear RGB f32: EXR as stored, PNG/JPEG sRGB-decoded.
#[cfg(feature = "image-io")]
pub fn load_linear(path: &Path) -> Result<(u32, u32, Vec<[f32; 3]>)> {
    let fail = |reason: String| Error::Output {
        path: path.to_path_buf(),
        reason,
    };
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    if ext == "exr" {
        let img = exr::prelude::read_first_rgba_layer_from_file(
            path,
            |res, _| (res.width(), vec![[0f32; 3]; res.width() * res.height()]),
            |(w, px), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
                px[pos.y() * *w + pos.x()] = [r, g, b]
            },
        )
        .map_err(|e| fail(e.to_string()))?;
        let size = img.layer_data.size;
        return Ok((
            size.width() as u32,
            size.height() as u32,
            img.layer_data.channel_data.pixels.1,
        ));
    }
    let img = image::open(path)
        .map_err(|e| fail(e.to_string()))?
        .to_rgb8();
    let px = img
        .pixels()
        .map(|p| p.0.map(|v| voxgi_scene::srgb_to_linear(v as f32 / 255.0)))
        .collect();
    Ok((img.width(), img.height(), px))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Radiance far past what a tone curve needs (a bright light, a high exposure) saturates:
    /// ACES's quadratics overflowed f32 past about 1e19 and gave NaN, written as black.
    #[test]
    fn huge_radiance_saturates_every_curve() {
        for curve in [Tonemap::Aces, Tonemap::Neutral, Tonemap::Clamp] {
            for v in [1e4f32, 1e20, 3e38] {
                let px = tonemap(&[v, v, v, 1.0], 0.0, curve);
                assert_eq!(px, [255, 255, 255, 255], "{curve:?} at {v}");
            }
        }
    }
}
