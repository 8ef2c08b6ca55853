//! Golden images, compared with FLIP. `VOXGI_BLESS=1` rewrites them on purpose; a failing test
//! writes the new image and the FLIP error map to `target/test-output/`. Each is one frame
//! with temporal accumulation on (the default): a history's first frame, the unjittered still
//! (the temporal tests cover accumulation).

use crate::common::*;
use std::path::{Path, PathBuf};
use voxgi::{FrameParams, RendererOptions};

fn golden_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden")
}

fn output_dir() -> PathBuf {
    let d = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target/test-output");
    std::fs::create_dir_all(&d).expect("create target/test-output");
    d
}

fn rgb(rgba: &[u8]) -> Vec<u8> {
    rgba.chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect()
}

/// Compares an RGBA8 image with the golden PNG `name`, asserting mean FLIP below `threshold`.
fn assert_golden(name: &str, width: u32, height: u32, rgba: &[u8], threshold: f32) {
    let path = golden_dir().join(format!("{name}.png"));
    if std::env::var_os("VOXGI_BLESS").is_some() {
        image::save_buffer(&path, rgba, width, height, image::ExtendedColorType::Rgba8)
            .expect("write golden");
        eprintln!("blessed {}", path.display());
        return;
    }
    let golden = image::open(&path)
        .unwrap_or_else(|e| {
            panic!(
                "{}: {e} (run with VOXGI_BLESS=1 to create it)",
                path.display()
            )
        })
        .to_rgb8();
    assert_eq!(
        (golden.width(), golden.height()),
        (width, height),
        "{name}: size changed"
    );
    let reference = nv_flip::FlipImageRgb8::with_data(width, height, golden.as_raw());
    let test = nv_flip::FlipImageRgb8::with_data(width, height, &rgb(rgba));
    let error = nv_flip::flip(reference, test, nv_flip::DEFAULT_PIXELS_PER_DEGREE);
    let mean = nv_flip::FlipPool::from_image(&error).mean();
    if mean >= threshold {
        let out = output_dir();
        image::save_buffer(
            out.join(format!("{name}.png")),
            rgba,
            width,
            height,
            image::ExtendedColorType::Rgba8,
        )
        .expect("write failing image");
        let map = error.apply_color_lut(&nv_flip::magma_lut());
        image::save_buffer(
            out.join(format!("{name}_flip.png")),
            &map.to_vec(),
            width,
            height,
            image::ExtendedColorType::Rgb8,
        )
        .expect("write error map");
        panic!(
            "{name}: mean FLIP {mean:.4} >= {threshold}; wrote the image and its error map to {}",
            out.display()
        );
    }
    eprintln!("{name}: mean FLIP {mean:.5} (threshold {threshold})");
}

#[test]
fn cornell_box_direct_light() {
    let scene = voxgi::scene::builtin::cornell_box();
    let cam = scene.cameras[0].clone();
    let settings = RendererOptions {
        bounces: 0,
        voxel_resolution: 32,
        ..RendererOptions::default()
    };
    let out = render_with(&scene, &settings, &FrameParams::new(cam), 128, 128);
    // 0.02: the same driver reproduces the image bit for bit (see `rendering_is_deterministic`);
    // the margin absorbs other drivers' rounding in rasterization and transcendental functions
    // (a one-texel shift of a shadow edge costs about 0.005), while a changed light, shadow or
    // tone curve costs well over 0.05.
    assert_golden("cornell_direct", 128, 128, &out.ldr, 0.02);
}

fn cornell_golden(name: &str, view: voxgi::ViewMode, bounces: u32) {
    let scene = voxgi::scene::builtin::cornell_box();
    let cam = scene.cameras[0].clone();
    let settings = RendererOptions {
        bounces,
        voxel_resolution: 32,
        ..RendererOptions::default()
    };
    let params = FrameParams {
        view,
        ..FrameParams::new(cam)
    };
    let out = render_with(&scene, &settings, &params, 96, 96);
    // 0.03: as for the direct-light golden, plus the cone tracer's sums of many 3D texture
    // filtering steps, whose rounding differs between drivers more than rasterization does. A
    // changed cone weight, aperture or filter moves these images by 0.05 or more.
    assert_golden(name, 96, 96, &out.ldr, 0.03);
}

#[test]
fn cornell_box_ambient_occlusion() {
    cornell_golden("cornell_ao", voxgi::ViewMode::Ao, 0);
}

#[test]
fn cornell_box_indirect_light() {
    cornell_golden("cornell_indirect", voxgi::ViewMode::Indirect, 2);
}

#[test]
fn cornell_box_final() {
    cornell_golden("cornell_final", voxgi::ViewMode::Final, 2);
}
