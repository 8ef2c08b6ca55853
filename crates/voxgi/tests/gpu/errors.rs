//! Bad input to the renderer: a clear error, never a panic or a black image.

use crate::common::*;
use voxgi::scene::glam::Vec3;
use voxgi::scene::{Camera, Scene};
use voxgi::{Error, FrameParams, RendererOptions};

#[test]
fn empty_scene_is_an_error() {
    let err = ctx()
        .renderer(&Scene::default(), &RendererOptions::default())
        .err()
        .expect("must fail");
    assert!(matches!(err, Error::EmptyScene), "{err}");
}

#[test]
fn absurd_settings_are_errors() {
    let scene = voxgi::scene::builtin::cornell_box();
    let cases: Vec<(&str, RendererOptions)> = vec![
        (
            "shadow map 5 texels",
            RendererOptions {
                shadow_map_size: 5,
                ..Default::default()
            },
        ),
        (
            "shadow map 100000",
            RendererOptions {
                shadow_map_size: 100_000,
                ..Default::default()
            },
        ),
        (
            "texture size 0",
            RendererOptions {
                max_texture_size: 0,
                ..Default::default()
            },
        ),
        (
            "voxels 100",
            RendererOptions {
                voxel_resolution: 100,
                ..Default::default()
            },
        ),
        (
            "voxels 1024",
            RendererOptions {
                voxel_resolution: 1024,
                ..Default::default()
            },
        ),
        (
            "9 bounces",
            RendererOptions {
                bounces: 9,
                ..Default::default()
            },
        ),
        (
            "AO radius 0",
            RendererOptions {
                ao_radius: Some(0.0),
                ..Default::default()
            },
        ),
        (
            "4 gather axes",
            RendererOptions {
                gather_axes: 4,
                ..Default::default()
            },
        ),
        (
            "step 0",
            RendererOptions {
                step_factor: 0.0,
                ..Default::default()
            },
        ),
    ];
    for (what, s) in cases {
        match ctx().renderer(&scene, &s) {
            Err(Error::Setting(msg)) => assert!(!msg.is_empty(), "{what}"),
            Err(e) => panic!("{what}: wrong error {e}"),
            Ok(_) => panic!("{what}: accepted"),
        }
    }
    // Per-frame parameters are checked by every frame, and a refused frame leaves the
    // renderer working.
    let mut r = renderer(&scene, &measuring());
    let cam = scene.cameras[0].clone();
    let frames: Vec<(&str, FrameParams)> = vec![
        (
            "exposure NaN",
            FrameParams {
                exposure: f32::NAN,
                ..FrameParams::new(cam.clone())
            },
        ),
        (
            "exposure 1000",
            FrameParams {
                exposure: 1000.0,
                ..FrameParams::new(cam.clone())
            },
        ),
        (
            "negative softness",
            FrameParams {
                shadow_softness: -1.0,
                ..FrameParams::new(cam.clone())
            },
        ),
        (
            "infinite background",
            FrameParams {
                background: [f32::INFINITY, 0.0, 0.0],
                ..FrameParams::new(cam.clone())
            },
        ),
        (
            "voxel level 6 of a 32³ volume",
            FrameParams {
                debug_level: 6,
                ..FrameParams::new(cam.clone())
            },
        ),
        (
            "voxel direction 6",
            FrameParams {
                debug_direction: 6,
                ..FrameParams::new(cam.clone())
            },
        ),
    ];
    for (what, p) in frames {
        match voxgi::headless::render(ctx(), &mut r, &p, 8, 8) {
            Err(Error::Setting(msg)) => assert!(!msg.is_empty(), "{what}"),
            Err(e) => panic!("{what}: wrong error {e}"),
            Ok(_) => panic!("{what}: accepted"),
        }
    }
    let ok = frame(&mut r, &FrameParams::new(cam), 8, 8);
    assert!(ok.mean_radiance()[0] > 0.0);
}

#[test]
fn absurd_sizes_and_cameras_are_errors() {
    let scene = voxgi::scene::builtin::cornell_box();
    let mut r = renderer(&scene, &RendererOptions::default());
    let cam = FrameParams::new(scene.cameras[0].clone());
    for (w, h) in [(0, 16), (16, 0), (100_000, 16)] {
        assert!(
            matches!(
                voxgi::headless::render(ctx(), &mut r, &cam, w, h),
                Err(Error::Setting(_))
            ),
            "{w}x{h} accepted"
        );
    }
    let mut bad = cam.clone();
    bad.camera.position = Vec3::new(f32::NAN, 0.0, 0.0);
    assert!(matches!(
        voxgi::headless::render(ctx(), &mut r, &bad, 16, 16),
        Err(Error::Setting(_))
    ));
    // The renderer still works after refusing bad requests.
    let ok = frame(&mut r, &cam, 16, 16);
    assert!(ok.mean_radiance()[0] > 0.0);
}

#[test]
fn unlit_scene_gets_a_default_sun_instead_of_black() {
    let scene = plane_scene(0.5);
    let cam = Camera::look_at(Vec3::new(0.0, 3.0, 3.0), Vec3::ZERO, 45.0);
    let lit = render(&scene, RendererOptions::default(), &cam, 32, 32);
    assert!(
        lit.mean_radiance()[0] > 0.05,
        "mean {:?}",
        lit.mean_radiance()
    );
    // And with the default light switched off the same scene is black, as asked.
    let dark = render(&scene, measuring(), &cam, 32, 32);
    assert_eq!(dark.mean_radiance(), [0.0; 3]);
}

#[test]
fn invalid_scene_data_is_an_error_not_a_panic() {
    let mut scene = plane_scene(0.5);
    scene.meshes[0].indices[1] = 999;
    let err = ctx()
        .renderer(&scene, &RendererOptions::default())
        .err()
        .expect("must fail");
    assert!(err.to_string().contains("out of range"), "{err}");
}

/// A device opened without voxgi's limits is refused with an error that names what it lacks,
/// before anything is created on it.
#[test]
fn a_device_below_the_minimum_limits_is_refused_by_name() {
    use voxgi::wgpu;
    let instance =
        wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter =
        pollster::block_on(instance.request_adapter(&Default::default())).expect("an adapter");
    // GLES 3.1-level limits: among others a 3D texture side of 256 where voxgi needs 2048.
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        required_limits: wgpu::Limits::downlevel_defaults(),
        ..Default::default()
    }))
    .expect("a device with low limits");
    let scene = voxgi::scene::builtin::cornell_box();
    match voxgi::Renderer::new(&device, &queue, &scene, &RendererOptions::default()) {
        Err(Error::DeviceLimits(msg)) => {
            assert!(msg.contains("max_texture_dimension_3d"), "{msg}");
            let e = Error::DeviceLimits(msg).to_string();
            assert!(
                e.contains("required_limits"),
                "the error says how to fix it: {e}"
            );
        }
        Err(e) => panic!("wrong error: {e}"),
        Ok(_) => panic!("a device below the minimum was accepted"),
    }
}

/// More shadow maps than a texture array holds: an error naming the count and the device's
/// limit, before the atlas is made (wgpu's validation error named neither); the same lights
/// without shadows render.
#[test]
fn too_many_shadow_maps_name_the_limit() {
    let ctx = ctx();
    let max = ctx.device.limits().max_texture_array_layers;
    // 64² maps: the layer count, not the memory, is what runs out.
    let mut scene = voxgi::scene::builtin::cornell_box();
    let base = scene.lights[0].clone();
    // Six layers per point light: one light more than the array holds.
    let n = max / 6 + 1;
    for i in 0..n {
        let mut l = base.clone();
        l.kind = voxgi::scene::LightKind::Point;
        l.position = Vec3::new(0.1 + 0.3 * i as f32 / n as f32, 0.4, 0.3);
        l.intensity = 0.01;
        scene.lights.push(l);
    }
    let options = RendererOptions {
        voxel_resolution: 32,
        shadow_map_size: 64,
        ..Default::default()
    };
    let err = ctx.renderer(&scene, &options).err().expect("must fail");
    let msg = err.to_string();
    assert!(
        msg.contains(&format!("limit of {max} texture array layers"))
            && msg.contains("cast_shadows"),
        "{msg}"
    );
    for l in &mut scene.lights[1..] {
        l.cast_shadows = false;
    }
    ctx.renderer(&scene, &options)
        .expect("the same lights without shadow maps");
}

/// A shadow atlas larger than one allocation may be: an error naming its size and the limit
/// (on lavapipe 85 point lights with 1024² maps took 2 GiB and failed inside wgpu).
#[test]
fn a_shadow_atlas_too_large_to_allocate_names_its_size() {
    let ctx = ctx();
    let limits = ctx.device.limits();
    let mut scene = voxgi::scene::builtin::cornell_box();
    let base = scene.lights[0].clone();
    let res = 2048u64;
    // Enough point lights for one layer more than the allocation limit, within the layer limit.
    let layers = (limits.max_buffer_size / (res * res * 4) + 1) as u32;
    let n = layers.div_ceil(6);
    if n * 6 > limits.max_texture_array_layers {
        eprintln!("skipped: this device's allocation limit lies beyond its layer limit");
        return;
    }
    for i in 0..n {
        let mut l = base.clone();
        l.kind = voxgi::scene::LightKind::Point;
        l.position = Vec3::new(0.1 + 0.3 * i as f32 / n as f32, 0.4, 0.3);
        scene.lights.push(l);
    }
    let options = RendererOptions {
        voxel_resolution: 32,
        shadow_map_size: res as u32,
        ..Default::default()
    };
    let msg = ctx
        .renderer(&scene, &options)
        .err()
        .expect("must fail")
        .to_string();
    assert!(
        msg.contains(&format!(
            "{} MiB this GPU allocates at once",
            limits.max_buffer_size >> 20
        )) && msg.contains("shadow_map_size"),
        "{msg}"
    );
}

/// A lost device (here destroyed; a driver reset reports the same way) is
/// `Error::DeviceLost` for the frame that finds it and every call after, never a panic or a
/// message about buffer mapping.
#[test]
fn a_lost_device_is_an_error_naming_it() {
    // A device of its own: the shared one must survive.
    let ctx = voxgi::headless::GpuContext::from_env().expect("a device");
    let scene = voxgi::scene::builtin::cornell_box();
    let options = RendererOptions {
        voxel_resolution: 32,
        ..Default::default()
    };
    let mut r = ctx.renderer(&scene, &options).unwrap();
    let params = FrameParams::new(scene.cameras[0].clone());
    voxgi::headless::render(&ctx, &mut r, &params, 32, 32).expect("a frame before the loss");
    ctx.device.destroy();
    let lost = |e: Error| {
        assert!(matches!(e, Error::DeviceLost { .. }), "{e}");
        assert!(
            e.to_string()
                .contains("device was lost (the device was destroyed)"),
            "{e}"
        );
    };
    lost(voxgi::headless::render(&ctx, &mut r, &params, 32, 32).expect_err("must fail"));
    lost(voxgi::headless::render_still(&ctx, &mut r, &params, 32, 32, 4).expect_err("must fail"));
    lost(ctx.renderer(&scene, &options).err().expect("must fail"));
}
