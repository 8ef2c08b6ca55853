//! voxgi inside an application: the embed example's pixels, every kind of target format, and
//! voxel pools that grow a frame later while no frame waits for the GPU.

#[path = "../../examples/embed.rs"]
#[allow(dead_code)]
mod example;

use crate::common::*;
use voxgi::gpu::readback::{f16_to_f32, read_texture};
use voxgi::output::linear_to_srgb;
use voxgi::scene::builtin;
use voxgi::{FrameParams, Renderer, RendererOptions, Target, VoxelKind, wgpu};

/// The embed example opens its own device and texture; its pixels are those of the headless
/// path (`voxgi render` writes the same bytes, checked by the CLI tests) to the bit.
#[test]
fn embed_example_renders_what_headless_renders() {
    let (w, h) = (64, 48);
    let app = example::render_cornell(w, h).expect("embed example");
    let scene = builtin::cornell_box();
    let mut r = renderer(&scene, &RendererOptions::default());
    let params = FrameParams::new(r.default_camera().clone());
    let out = frame(&mut r, &params, w, h);
    assert_eq!(app.len(), out.ldr.len());
    let differing = app.iter().zip(&out.ldr).filter(|(a, b)| a != b).count();
    assert_eq!(differing, 0, "{differing} bytes differ");
    // Not a blank image: the lit box has a mean 8-bit value of about 60.
    let mean = app.iter().map(|&v| v as f64).sum::<f64>() / app.len() as f64;
    assert!(mean > 20.0, "mean {mean}");
}

fn texture(format: wgpu::TextureFormat, w: u32, h: u32) -> wgpu::Texture {
    ctx().device.create_texture(&wgpu::TextureDescriptor {
        label: Some("test target"),
        size: wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    })
}

/// Records one frame into `t` and submits it; waits only so the test can look.
fn draw(r: &mut Renderer, params: &FrameParams, t: &wgpu::Texture) {
    let view = t.create_view(&Default::default());
    let target = Target::new(&view, t.format(), t.width(), t.height());
    let mut encoder = ctx().device.create_command_encoder(&Default::default());
    r.render(&mut encoder, &target, params).expect("render");
    ctx().queue.submit([encoder.finish()]);
    ctx()
        .device
        .poll(wgpu::PollType::wait_indefinitely())
        .expect("poll");
}

/// RGBA of an 8-bit texture, channels in RGBA order.
fn rgba8(t: &wgpu::Texture) -> Vec<u8> {
    let mut px = read_texture(&ctx().device, &ctx().queue, t).expect("readback");
    if matches!(
        t.format(),
        wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb
    ) {
        for p in px.chunks_exact_mut(4) {
            p.swap(0, 2);
        }
    }
    px
}

/// The tone-mapped image in a swapchain's formats and an HDR one agrees with the 8-bit image
/// voxgi encodes itself: BGRA is RGBA reordered; the GPU's sRGB encoder rounds within one
/// step of voxgi's; a float target holds the tone-mapped linear values.
#[test]
fn every_target_format_gets_the_same_image() {
    let (w, h) = (40, 32);
    let scene = builtin::cornell_box();
    let mut r = renderer(&scene, &measuring());
    let params = FrameParams::new(r.default_camera().clone());
    let reference = texture(wgpu::TextureFormat::Rgba8Unorm, w, h);
    draw(&mut r, &params, &reference);
    let want = rgba8(&reference);
    let max_diff = |got: &[u8]| {
        got.iter()
            .zip(&want)
            .map(|(a, b)| (*a as i32 - *b as i32).abs())
            .max()
            .unwrap_or(0)
    };
    for (format, tolerance) in [
        (wgpu::TextureFormat::Bgra8Unorm, 0),
        (wgpu::TextureFormat::Rgba8UnormSrgb, 1),
        (wgpu::TextureFormat::Bgra8UnormSrgb, 1),
    ] {
        let t = texture(format, w, h);
        // Each image a first frame: without jitter or accumulation.
        r.reset_history();
        draw(&mut r, &params, &t);
        let d = max_diff(&rgba8(&t));
        assert!(d <= tolerance, "{format:?}: differs by {d} steps");
    }
    // A 10-bit swapchain format without sRGB gets voxgi's sRGB curve too: within one 8-bit
    // step once its 1023 levels are scaled to 255.
    let t = texture(wgpu::TextureFormat::Rgb10a2Unorm, w, h);
    r.reset_history();
    draw(&mut r, &params, &t);
    let bytes = read_texture(&ctx().device, &ctx().queue, &t).expect("readback");
    let ten: Vec<u8> = bytemuck::cast_slice::<u8, u32>(&bytes)
        .iter()
        .flat_map(|&p| {
            let c = |shift: u32| ((((p >> shift) & 1023) as f32) * 255.0 / 1023.0).round() as u8;
            [c(0), c(10), c(20), 255]
        })
        .collect();
    let d = max_diff(&ten);
    assert!(d <= 1, "Rgb10a2Unorm: differs by {d} steps");
    let t = texture(wgpu::TextureFormat::Rgba16Float, w, h);
    r.reset_history();
    draw(&mut r, &params, &t);
    let bytes = read_texture(&ctx().device, &ctx().queue, &t).expect("readback");
    let halves: &[u16] = bytemuck::cast_slice(&bytes);
    // Encoded here, the fp16 values (3 significant digits) land within one step of 255.
    let encoded: Vec<u8> = halves
        .iter()
        .enumerate()
        .map(|(i, &v)| {
            let v = f16_to_f32(v);
            if i % 4 == 3 {
                (v * 255.0).round() as u8
            } else {
                (linear_to_srgb(v) * 255.0).round() as u8
            }
        })
        .collect();
    let d = max_diff(&encoded);
    assert!(d <= 1, "Rgba16Float: differs by {d} steps");
}

/// A 32³ volume whose fragment and voxel pools start at the minimum: the Cornell box overflows
/// both.
fn tiny_pools() -> RendererOptions {
    RendererOptions {
        voxel_resolution: 32,
        fragment_capacity: Some(1),
        voxel_capacity: Some(1),
        // Growth is judged frame by frame against a fresh renderer's single frame.
        temporal: false,
        ..RendererOptions::default()
    }
}

/// A renderer whose pools are far too small for the scene still gets the right image: the
/// first build counts what did not fit, the counters come back without any frame waiting, the
/// pools grow and a later frame rebuilds. From then on every frame equals, to the bit, the
/// frame of a renderer sized right from the start.
#[test]
fn overflowing_pools_grow_and_converge_to_the_right_image() {
    let scene = builtin::cornell_box();
    let (w, h) = (32, 32);
    let small = tiny_pools();
    let mut r = renderer(&scene, &small);
    let (frags0, slots0) = (
        r.fragments().capacity,
        r.structure::<voxgi::voxel::dense::DenseVolume>()
            .unwrap()
            .slot_capacity,
    );
    let params = FrameParams::new(r.default_camera().clone());
    let t = texture(wgpu::TextureFormat::Rgba8Unorm, w, h);
    let mut frames = Vec::new();
    for _ in 0..4 {
        draw(&mut r, &params, &t);
        frames.push(rgba8(&t));
    }
    let counts = r.last_voxel_counts().expect("counters came back");
    let (frags1, slots1) = (
        r.fragments().capacity,
        r.structure::<voxgi::voxel::dense::DenseVolume>()
            .unwrap()
            .slot_capacity,
    );
    // The Cornell box at 32³ has several thousand fragments and occupied voxels: the
    // 1024-entry minimum pools overflowed, and grew to the exact counts.
    assert!(
        counts.fragments > frags0 as u64 && counts.occupied > slots0 as u64,
        "the test scene must overflow both pools: {counts:?} vs {frags0}/{slots0}"
    );
    assert_eq!(
        (frags1 as u64, slots1 as u64),
        (counts.fragments, counts.occupied)
    );

    let right = RendererOptions {
        fragment_capacity: Some(counts.fragments),
        voxel_capacity: Some(counts.occupied),
        ..small
    };
    let mut sized = renderer(&scene, &right);
    draw(&mut sized, &params, &t);
    let want = rgba8(&t);
    assert_eq!(
        sized
            .structure::<voxgi::voxel::dense::DenseVolume>()
            .unwrap()
            .slot_capacity,
        slots1,
        "no growth when sized right"
    );
    // The overflowing first frame misses voxels. A build that dropped fragments counts the
    // voxels of those it kept only, so the voxel pool may need a second round: by the third
    // frame every voxel is there, and it stays so.
    assert_ne!(frames[0], want, "the first frame should show the overflow");
    let first = frames.iter().position(|f| *f == want);
    eprintln!("overflow: first right frame {first:?} of {}", frames.len());
    let first = first.expect("no frame converged to the right-sized renderer's image");
    assert!(first <= 2, "converged only at frame {first}");
    for (i, f) in frames.iter().enumerate().skip(first) {
        assert!(
            *f == want,
            "frame {i} differs from the right-sized renderer's"
        );
    }
}

/// `is_idle` is what lets an application skip frames: once it says so, the next frame is the
/// last one again, to the bit. An overflowing first build is not idle (its counters are on the
/// way back and will make a frame rebuild), and neither is a moved light.
#[test]
fn an_idle_renderer_draws_its_last_image_again() {
    let scene = builtin::cornell_box();
    let (w, h) = (32, 32);
    let small = tiny_pools();
    let mut r = renderer(&scene, &small);
    let params = FrameParams::new(r.default_camera().clone());
    let t = texture(wgpu::TextureFormat::Rgba8Unorm, w, h);
    draw(&mut r, &params, &t);
    let mut last = rgba8(&t);
    assert!(
        !r.is_idle(),
        "idle right after a build whose counters are still out"
    );
    let mut idle_at = None;
    for i in 1..10 {
        r.receive_feedback().unwrap();
        let idle = r.is_idle();
        draw(&mut r, &params, &t);
        let now = rgba8(&t);
        if idle {
            assert!(
                now == last,
                "frame {i} changed although the renderer was idle"
            );
            idle_at.get_or_insert(i);
        }
        last = now;
    }
    let idle_at = idle_at.expect("never idle");
    // The pools grow once or twice (see the test above), each a frame or two later.
    assert!(idle_at <= 6, "idle only at frame {idle_at}");
    let mut light = r.lights()[0].clone();
    light.intensity *= 0.5;
    r.set_light(0, &light).unwrap();
    assert!(!r.is_idle(), "idle with a light change waiting");
}

/// With temporal accumulation a still view keeps changing while it accumulates, so the
/// renderer is not idle; after `TEMPORAL_STILL_FRAMES` still frames it is, and from then on
/// draws the same image to the bit. Moving the camera ends it.
#[test]
fn a_temporal_still_becomes_idle_once_converged() {
    let scene = builtin::cornell_box();
    let (w, h) = (16, 16);
    let options = RendererOptions {
        voxel_resolution: 16,
        ..RendererOptions::default()
    };
    let mut r = renderer(&scene, &options);
    let mut params = FrameParams::new(r.default_camera().clone());
    let t = texture(wgpu::TextureFormat::Rgba8Unorm, w, h);
    let mut idle_at = None;
    let mut last = Vec::new();
    let limit = voxgi::TEMPORAL_STILL_FRAMES;
    for i in 0..limit + 8 {
        r.receive_feedback().unwrap();
        if r.is_idle() {
            idle_at.get_or_insert(i);
        }
        draw(&mut r, &params, &t);
        let now = rgba8(&t);
        if idle_at.is_some() {
            assert!(
                now == last,
                "frame {i} changed although the renderer was idle"
            );
        }
        last = now;
    }
    // The first frame starts the history (a build settles within it); then `limit` still
    // frames accumulate.
    let idle_at = idle_at.expect("never idle");
    assert!(
        (limit..=limit + 3).contains(&idle_at),
        "idle at frame {idle_at}, expected just after {limit} still frames"
    );
    params.camera.position += voxgi::scene::glam::Vec3::new(0.01, 0.0, 0.0);
    assert!(r.is_idle(), "is_idle says nothing about parameters to come");
    draw(&mut r, &params, &t);
    assert!(!r.is_idle(), "idle right after the camera moved");
}

/// A target format the tone mapping cannot write is an error naming it, every time it is
/// asked for, and the renderer keeps working for good formats.
#[test]
fn an_unrenderable_target_format_is_an_error_every_time() {
    let scene = builtin::cornell_box();
    let mut r = renderer(&scene, &measuring());
    let params = FrameParams::new(r.default_camera().clone());
    let bad = texture(wgpu::TextureFormat::Rgba8Uint, 8, 8);
    let view = bad.create_view(&Default::default());
    for attempt in 0..2 {
        let target = Target::new(&view, bad.format(), 8, 8);
        let mut encoder = ctx().device.create_command_encoder(&Default::default());
        match r.render(&mut encoder, &target, &params) {
            Err(voxgi::Error::Setting(msg)) => assert!(msg.contains("Rgba8Uint"), "{msg}"),
            other => panic!("attempt {attempt}: {other:?}"),
        }
    }
    let good = texture(wgpu::TextureFormat::Rgba8Unorm, 8, 8);
    draw(&mut r, &params, &good);
    assert!(rgba8(&good).iter().any(|&v| v > 0));
}

/// The octree's pools (leaf slots and three classes of tiles) start at the minimum of 64 and
/// the Cornell box overflows them all: a pool that overflows hides what the levels below it
/// would have needed, so growth takes a few rounds, each a build a frame or two later. Once
/// the renderer is idle it holds the same tree as one sized right from the start (every node at
/// every depth, every leaf) and draws the same image.
#[test]
fn an_overflowing_octree_grows_and_converges_to_the_right_image() {
    use voxgi::voxel::octree::cpu::walk;
    let scene = builtin::cornell_box();
    let (w, h) = (32, 32);
    let small = RendererOptions {
        voxels: VoxelKind::OCTREE,
        ..tiny_pools()
    };
    let mut r = renderer(&scene, &small);
    let pools0 = r
        .structure::<voxgi::voxel::octree::OctreeVolume>()
        .unwrap()
        .pools;
    let params = FrameParams::new(r.default_camera().clone());
    let t = texture(wgpu::TextureFormat::Rgba8Unorm, w, h);
    let mut frames = 0;
    while frames < 12 {
        draw(&mut r, &params, &t);
        frames += 1;
        r.receive_feedback().unwrap();
        if r.is_idle() {
            break;
        }
    }
    assert!(r.is_idle(), "still growing after {frames} frames");
    draw(&mut r, &params, &t);
    let got = rgba8(&t);
    let pools1 = r
        .structure::<voxgi::voxel::octree::OctreeVolume>()
        .unwrap()
        .pools;
    eprintln!("octree pools {pools0:?} grew to {pools1:?} in {frames} frames");
    assert!(pools1.slots > pools0.slots && pools1.leaf_tiles > pools0.leaf_tiles);

    let right = RendererOptions {
        voxel_capacity: Some(1 << 16),
        fragment_capacity: None,
        ..small
    };
    let mut sized = renderer(&scene, &right);
    draw(&mut sized, &params, &t);
    let want = rgba8(&t);
    let tree = |r: &voxgi::Renderer| {
        let o = r.structure::<voxgi::voxel::octree::OctreeVolume>().unwrap();
        let bytes = voxgi::gpu::readback::read_buffer_copy(&ctx().device, &ctx().queue, &o.nodes)
            .expect("nodes");
        walk(bytemuck::cast_slice(&bytes), &o.layout)
    };
    assert_eq!(
        tree(&r),
        tree(&sized),
        "the grown tree differs from the right-sized one"
    );
    assert_eq!(
        r.voxel_counts().unwrap(),
        sized.voxel_counts().unwrap(),
        "fragments and leaves"
    );
    // Bricks lie elsewhere in atlases of another size, and a fetch's position in an atlas
    // rounds its filtering weights: measured identical on lavapipe; 1/255 allows other
    // filtering hardware.
    let worst = got
        .iter()
        .zip(&want)
        .map(|(a, b)| a.abs_diff(*b))
        .max()
        .unwrap();
    assert!(worst <= 1, "the grown octree's image is {worst}/255 off");
}
