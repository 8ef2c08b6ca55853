//! `voxgi::compare` on known inputs, and the CPU tone mapping against the GPU pass.

use crate::common::*;
use voxgi::compare::{Image, compare};
use voxgi::output::tonemap;
use voxgi::{FrameParams, RendererOptions, Tonemap};

fn constant_hdr(w: u32, h: u32, v: f32) -> Image {
    Image::from_hdr_rgba(w, h, &vec![v; (w * h * 4) as usize])
}

/// A small HDR test pattern with structure (so FLIP's filters have something to see).
fn pattern_hdr(w: u32, h: u32) -> Vec<f32> {
    (0..w * h)
        .flat_map(|i| {
            let (x, y) = ((i % w) as f32, (i / w) as f32);
            let v = 0.05 + 2.0 * ((x * 0.4).sin() * (y * 0.3).cos()).abs();
            [v, v * 0.7, v * 0.3, 1.0]
        })
        .collect()
}

#[test]
fn compare_identical_images_is_zero() {
    let (w, h) = (32, 24);
    let hdr = pattern_hdr(w, h);
    let a = Image::from_hdr_rgba(w, h, &hdr);
    let c = compare(&a, &a.clone()).unwrap();
    assert!(c.hdr);
    assert_eq!((c.flip_mean, c.rmse, c.rel_mse), (0.0, 0.0, 0.0));
    let ldr = tonemap(&hdr, 0.0, Tonemap::Aces);
    let b = Image::from_ldr_rgba8(w, h, &ldr);
    let c = compare(&b, &b.clone()).unwrap();
    assert!(!c.hdr);
    assert_eq!((c.flip_mean, c.rmse, c.rel_mse), (0.0, 0.0, 0.0));
}

#[test]
fn compare_known_perturbation() {
    let (w, h) = (32, 32);
    // HDR: +0.1 on every channel of a constant 0.5 image.
    let c = compare(&constant_hdr(w, h, 0.5), &constant_hdr(w, h, 0.6)).unwrap();
    assert!(c.hdr);
    assert!((c.rmse - 0.1).abs() < 1e-6, "rmse {}", c.rmse);
    let rel = 0.01 / (0.25 + 0.01);
    assert!((c.rel_mse - rel).abs() < 1e-6, "rel_mse {}", c.rel_mse);
    assert!(
        c.flip_mean > 0.0 && c.flip_mean < 1.0,
        "HDR-FLIP {}",
        c.flip_mean
    );
    // LDR: 8-bit sRGB 128 vs 154 (+0.1 in encoded units); RMSE is on the decoded values, so the
    // expected step comes from the sRGB decoding formula.
    let img = |v: u8| Image::from_ldr_rgba8(w, h, &[v, v, v, 255].repeat((w * h) as usize));
    let decode = |v: u8| ((v as f64 / 255.0 + 0.055) / 1.055).powf(2.4);
    let expected = decode(154) - decode(128);
    let c = compare(&img(128), &img(154)).unwrap();
    assert!(!c.hdr);
    assert!(
        (c.rmse - expected).abs() < 1e-6,
        "rmse {} vs {expected}",
        c.rmse
    );
    assert!(
        c.flip_mean > 0.0 && c.flip_mean < 1.0,
        "LDR-FLIP {}",
        c.flip_mean
    );
}

#[test]
fn compare_rejects_mismatched_images() {
    let a = constant_hdr(8, 8, 0.5);
    assert!(compare(&a, &constant_hdr(8, 9, 0.5)).is_err());
    let ldr = Image::from_ldr_rgba8(8, 8, &[128; 8 * 8 * 4]);
    assert!(compare(&a, &ldr).is_err());
}

#[test]
fn hdr_flip_grows_with_the_error() {
    let (w, h) = (32, 32);
    let r = pattern_hdr(w, h);
    let reference = Image::from_hdr_rgba(w, h, &r);
    let scaled = |k: f32| {
        let t: Vec<f32> = r.iter().map(|v| v * k).collect();
        compare(&reference, &Image::from_hdr_rgba(w, h, &t))
            .unwrap()
            .flip_mean
    };
    let (small, large) = (scaled(1.05), scaled(1.5));
    assert!(
        0.0 < small && small < large,
        "HDR-FLIP 5 %: {small}, 50 %: {large}"
    );
}

#[test]
fn cpu_tonemap_matches_the_gpu_pass() {
    let scene = voxgi::scene::builtin::cornell_box();
    let cam = scene.cameras[0].clone();
    // The tone curve is a frame parameter: one renderer draws all three. Coarse voxels still
    // give the picture its range, the lamp above 1 and the bounced light far below.
    let options = RendererOptions {
        voxel_resolution: 32,
        ..RendererOptions::default()
    };
    let mut r = renderer(&scene, &options);
    for curve in [Tonemap::Aces, Tonemap::Neutral, Tonemap::Clamp] {
        let params = FrameParams {
            tonemap: curve,
            exposure: 1.5,
            ..FrameParams::new(cam.clone())
        };
        let out = frame(&mut r, &params, 48, 48);
        let cpu = tonemap(&out.hdr, 1.5, curve);
        let worst = cpu
            .iter()
            .zip(&out.ldr)
            .map(|(a, b)| (*a as i32 - *b as i32).abs())
            .max()
            .unwrap();
        assert!(
            worst <= 1,
            "{curve:?}: CPU and GPU tone mapping differ by {worst}"
        );
    }
}
