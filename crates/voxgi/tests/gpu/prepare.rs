//! Voxel work recorded ahead (`Renderer::prepare`) and submitted a piece at a time, with other
//! work between the pieces (a window's frames): the frames after it are the frames a renderer
//! that never prepared draws, to the bit.

use crate::common::*;
use voxgi::scene::builtin;
use voxgi::scene::glam::{Mat4, Vec3};
use voxgi::{FrameParams, Renderer, RendererOptions, UNLIMITED_BOUNCES};

const SIZE: u32 = 40;

/// Prepares `r`'s pending voxel work and submits it piece by piece, a frame of `other`
/// between pieces (its queue writes and submissions land between them, as a window's do).
/// Returns the pieces' passes.
fn prepare_between(r: &mut Renderer, p: &FrameParams, other: &mut Renderer) -> Vec<&'static str> {
    let pieces = r.prepare(p).expect("prepare");
    let mut passes = Vec::new();
    for piece in pieces {
        frame(other, p, SIZE, SIZE);
        ctx().queue.submit([piece.commands]);
        passes.push(piece.pass);
    }
    passes
}

fn cube_at(x: f32) -> Mat4 {
    Mat4::from_translation(Vec3::new(x, 0.061, 0.2)) * Mat4::from_scale(Vec3::splat(0.12))
}

/// A new renderer's whole build in pieces, then a moved dynamic cube's update in pieces, each
/// followed by three frames (temporal accumulation on, so the history's restart is part of
/// what must match): equal to a renderer that did it all in its frames. Both structures, with
/// stored bounces and with progressive ones.
#[test]
fn prepared_voxel_work_renders_like_a_frame_that_records_it() {
    let mut scene = builtin::cornell_box();
    let cube = scene.instances.len();
    scene.append(builtin::cube([0.3, 0.3, 0.8]), cube_at(0.4), true);
    for &voxels in voxgi::VoxelKind::ALL {
        for progressive in [false, true] {
            let options = RendererOptions {
                voxels,
                voxel_resolution: 32,
                shadow_map_size: 256,
                bounces: if progressive { UNLIMITED_BOUNCES } else { 3 },
                progressive,
                ..RendererOptions::default()
            };
            let what = format!("{voxels:?}, progressive {progressive}");
            let mut prepared = renderer(&scene, &options);
            let mut plain = renderer(&scene, &options);
            let mut other = renderer(&builtin::cornell_box(), &options);
            let p = clamped(prepared.default_camera());
            let passes = prepare_between(&mut prepared, &p, &mut other);
            eprintln!("{what}: {passes:?}");
            for pass in ["shadow", "voxelize", "build", "inject", "bounce"] {
                assert!(
                    passes.contains(&pass),
                    "{what}: no {pass} piece in {passes:?}"
                );
            }
            let compare = |a: &mut Renderer, b: &mut Renderer, when: &str| {
                for i in 0..3 {
                    let got = frame(a, &p, SIZE, SIZE);
                    let want = frame(b, &p, SIZE, SIZE);
                    let off = got
                        .hdr
                        .iter()
                        .zip(&want.hdr)
                        .filter(|(a, b)| a != b)
                        .count();
                    assert_eq!(off, 0, "{what}, {when}, frame {i}: values that differ");
                }
            };
            compare(&mut prepared, &mut plain, "the first frames");
            for r in [&mut prepared, &mut plain] {
                r.set_instance_transform(cube, cube_at(0.25))
                    .expect("dynamic");
            }
            let passes = prepare_between(&mut prepared, &p, &mut other);
            assert!(
                passes.contains(&"update"),
                "{what}: no update in {passes:?}"
            );
            compare(&mut prepared, &mut plain, "after the cube moved");
        }
    }
}
