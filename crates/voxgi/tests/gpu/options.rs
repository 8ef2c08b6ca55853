//! Creation-time options against per-frame parameters: a renderer whose options were changed
//! renders exactly what a renderer made with the new options renders, and per-frame
//! parameters change the picture without any option.

use crate::common::*;
use voxgi::scene::builtin;
use voxgi::{ConeSet, FrameParams, RendererOptions, Tonemap, ViewMode};

const SIZE: u32 = 32;

fn base() -> RendererOptions {
    RendererOptions {
        voxel_resolution: 16,
        bounces: 1,
        ..RendererOptions::default()
    }
}

/// Each change, applied with `set_options` to a renderer that has already rendered, gives the
/// image of a fresh renderer with those options, to the bit.
#[test]
fn changed_options_render_like_a_fresh_renderer() {
    let scene = builtin::cornell_box();
    let changes: Vec<(&str, RendererOptions)> = vec![
        (
            "voxel resolution",
            RendererOptions {
                voxel_resolution: 32,
                ..base()
            },
        ),
        (
            "isotropic",
            RendererOptions {
                anisotropic: false,
                ..base()
            },
        ),
        (
            "gather axes",
            RendererOptions {
                gather_axes: 2,
                ..base()
            },
        ),
        (
            "cones",
            RendererOptions {
                cones: ConeSet::Nine45,
                ..base()
            },
        ),
        (
            "bounces",
            RendererOptions {
                bounces: 3,
                ..base()
            },
        ),
        (
            "cone step",
            RendererOptions {
                step_factor: 1.0,
                ..base()
            },
        ),
        (
            "half resolution",
            RendererOptions {
                half_resolution: true,
                ..base()
            },
        ),
        (
            "cone shadows",
            RendererOptions {
                cone_shadows: true,
                ..base()
            },
        ),
        (
            "shadow map",
            RendererOptions {
                shadow_map_size: 256,
                ..base()
            },
        ),
        // Lighting changes relight the voxels the renderer has instead of voxelizing again.
        (
            "longest cone",
            RendererOptions {
                max_distance: Some(0.1),
                ..base()
            },
        ),
        (
            "cone origin",
            RendererOptions {
                origin_offset: 3.0,
                ..base()
            },
        ),
        (
            "leaves",
            RendererOptions {
                indirect: voxgi::IndirectShading::Leaves,
                ..base()
            },
        ),
        (
            "unlimited bounces",
            RendererOptions {
                bounces: voxgi::UNLIMITED_BOUNCES,
                ..base()
            },
        ),
    ];
    let mut r = renderer(&scene, &base());
    r.enable_timing(true);
    let params = FrameParams::new(r.default_camera().clone());
    let first = frame(&mut r, &params, SIZE, SIZE);
    for (what, options) in changes {
        r.set_options(&base()).expect("back to the base options");
        let again = frame(&mut r, &params, SIZE, SIZE);
        assert!(again.hdr == first.hdr, "{what}: back to the base options");
        r.pass_times().expect("times");
        r.set_options(&options).expect(what);
        let changed = frame(&mut r, &params, SIZE, SIZE);
        let passes: Vec<&str> = r
            .pass_times()
            .expect("times")
            .into_iter()
            .map(|(n, _)| n)
            .collect();
        let lighting = voxgi::settings::changes_between(&base(), &options)
            == Some(voxgi::settings::Changes::Lighting);
        // Relit, not rebuilt (where the device times passes: lavapipe does).
        if lighting && !passes.is_empty() {
            assert!(
                passes.contains(&"inject") && !passes.contains(&"voxelize"),
                "{what}: {passes:?}"
            );
        }
        let fresh = render_with(&scene, &options, &params, SIZE, SIZE);
        assert!(
            changed.hdr == fresh.hdr,
            "{what}: differs from a fresh renderer"
        );
        // Each change changes the picture, so the comparison could fail.
        assert!(changed.hdr != first.hdr, "{what}: no visible effect");
    }
}

#[test]
fn options_that_shape_the_upload_are_refused() {
    let scene = builtin::cornell_box();
    let mut r = renderer(&scene, &base());
    for o in [
        RendererOptions {
            max_texture_size: 64,
            ..base()
        },
        RendererOptions {
            default_light: false,
            ..base()
        },
        RendererOptions {
            voxel_resolution: 100,
            ..base()
        },
    ] {
        assert!(r.set_options(&o).is_err(), "{o:?} accepted");
        assert_eq!(*r.options(), base(), "a refused change leaves the options");
    }
}

/// Per-frame parameters need no option: exposure, curve and view change the image of one
/// renderer, and going back gives the first image again.
#[test]
fn frame_params_change_the_picture_without_rebuilding() {
    let scene = builtin::cornell_box();
    let mut r = renderer(&scene, &base());
    let params = FrameParams::new(r.default_camera().clone());
    let first = frame(&mut r, &params, SIZE, SIZE);
    for p in [
        FrameParams {
            exposure: 1.0,
            ..params.clone()
        },
        FrameParams {
            tonemap: Tonemap::Neutral,
            ..params.clone()
        },
        FrameParams {
            view: ViewMode::Indirect,
            ..params.clone()
        },
        FrameParams {
            background: [1.0, 0.0, 0.0],
            ..params.clone()
        },
    ] {
        let out = frame(&mut r, &p, SIZE, SIZE);
        assert!(out.ldr != first.ldr, "{p:?}: no effect");
    }
    assert!(frame(&mut r, &params, SIZE, SIZE).ldr == first.ldr);
}

/// `specular_bounces` switched on and off on a renderer of a scene with a metal (the Cornell
/// box's floor): the shadow maps gain and lose their material channel and the leaves their
/// lobes, and each state renders like a fresh renderer with those options, to the bit.
#[test]
fn specular_bounces_switch_like_a_fresh_renderer() {
    let scene = crate::reference::metal_floor_cornell(0.3);
    let on = RendererOptions {
        specular_bounces: true,
        ..base()
    };
    let mut r = renderer(&scene, &base());
    let params = FrameParams::new(r.default_camera().clone());
    let off_image = frame(&mut r, &params, SIZE, SIZE);
    r.set_options(&on).expect("specular bounces on");
    let on_image = frame(&mut r, &params, SIZE, SIZE);
    let fresh = frame(&mut renderer(&scene, &on), &params, SIZE, SIZE);
    assert!(
        on_image.hdr == fresh.hdr,
        "switched on: not a fresh renderer's image"
    );
    assert!(on_image.hdr != off_image.hdr, "the lobes changed nothing");
    r.set_options(&base()).expect("specular bounces off");
    let again = frame(&mut r, &params, SIZE, SIZE);
    assert!(
        again.hdr == off_image.hdr,
        "switched off: not the first image"
    );
}

/// In a scene without a metal there is nothing to reflect: `specular_bounces` keeps no lobes,
/// makes no extra blocks and compiles no lobe samples, and the image is the one without it, to
/// the bit, in every structure.
#[test]
fn specular_bounces_without_a_metal_change_nothing() {
    let scene = voxgi::scene::builtin::cornell_box();
    for &voxels in voxgi::VoxelKind::ALL {
        let off = RendererOptions { voxels, ..base() };
        let on = RendererOptions {
            specular_bounces: true,
            ..off.clone()
        };
        let mut plain = renderer(&scene, &off);
        let params = FrameParams::new(plain.default_camera().clone());
        let without = frame(&mut plain, &params, SIZE, SIZE);
        let mut r = renderer(&scene, &on);
        let with = frame(&mut r, &params, SIZE, SIZE);
        assert!(with.hdr == without.hdr, "{voxels:?}: the image changed");
        assert_eq!(r.memory(), plain.memory(), "{voxels:?}: the memory changed");
    }
}
