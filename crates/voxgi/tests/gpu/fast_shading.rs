//! The fast shading (`IndirectShading::Leaves`, the thesis' §4.6): pixels read the irradiance
//! the leaves kept instead of tracing cones. The invariants the per-pixel gather keeps, its
//! agreement with the path tracer and with the gather, and the two structures' lookups.

use crate::common::*;
use crate::vct::{
    FURNACE_CASES, Variant, ao_beside_a_wall, ao_of_an_open_plane_on,
    cornell_variant_against_the_path_tracer, floor_beside_a_wall, furnace_series,
    octree_against_dense, one_voxel_wall_rooms, thin_wall_leak,
};
use voxgi::scene::builtin;
use voxgi::{IndirectShading, RendererOptions, VoxelKind};

#[test]
fn leaves_keep_the_furnace_series() {
    // A uniform field: whatever the filter's weights, a pixel reads the leaves' one value, so
    // the bounce count is all that can go wrong (one bounce short or long is 12 % off).
    let scene = builtin::closed_box(0.5, 1.0);
    for &kind in VoxelKind::ALL {
        furnace_series(&scene, Variant::leaves(kind), &FURNACE_CASES);
    }
}

#[test]
fn leaves_see_an_open_plane_unoccluded() {
    for &kind in VoxelKind::ALL {
        ao_of_an_open_plane_on(&plane_scene(0.5), Variant::leaves(kind));
    }
}

#[test]
fn leaves_occlude_beside_a_wall() {
    let (scene, cam) = floor_beside_a_wall();
    for &kind in VoxelKind::ALL {
        // The closed form's bound (0.1) holds as for the gather.
        let worst = ao_beside_a_wall(&scene, &cam, Variant::leaves(kind));
        eprintln!("leaves beside a wall ({kind:?}): worst error {worst:.3}");
    }
}

#[test]
fn leaves_keep_a_thin_wall_nearly_closed() {
    let res = 64;
    let scene = one_voxel_wall_rooms(res);
    for &kind in VoxelKind::ALL {
        let leak = thin_wall_leak(&scene, Variant::leaves(kind), res);
        eprintln!(
            "thin wall ({kind:?}): room B gets {:.2} % of room A's indirect light with leaves",
            leak * 100.0
        );
        // The wall's own leaves hold both faces: their record is the mean of both rooms'
        // light, and the floor of room B within two voxels of it could read some of it, but
        // as a two-sided leaf it weighs a quarter beside the floor's own. Measured 0.67 %
        // (both structures; the cones 0.71 %). 2 % bounds it as the wall test bounds
        // points: a lookup that ignored the normals reads about half the wall's record.
        assert!(
            leak < 0.02,
            "{kind:?}: {:.2} % through the wall",
            leak * 100.0
        );
    }
}

#[test]
fn leaves_agree_with_the_path_tracer_and_the_gather() {
    // Measured within 0.6 % of the cones' ratios (back wall 1.04, floor 1.03-1.04, walls
    // 1.03-1.05; the ceiling 1.33-1.35, the cones' known error), and a whole-image LDR-FLIP
    // of 0.143 (dense) and 0.142 (octree), the same as the cones'. The bounds are the
    // gather's plus room for the window filter's blur at the regions' edges; a bounce lost or
    // counted twice moves a region 15 %.
    cornell_variant_against_the_path_tracer("leaves", |o| {
        o.indirect = IndirectShading::Leaves;
    });
}

#[test]
fn leaves_read_the_same_light_from_both_structures() {
    let scene = builtin::cornell_box();
    let params = voxgi::FrameParams::new(scene.cameras[0].clone());
    let options = RendererOptions {
        voxel_resolution: 64,
        indirect: IndirectShading::Leaves,
        ..RendererOptions::default()
    };
    let (c, worst) = octree_against_dense(&scene, &options, &params, 64, 64);
    eprintln!("leaves, octree vs dense: {c:?}, largest difference {worst}/255");
    // The octree finds a voxel's leaf by a descent, the dense volume by its occupancy: both
    // must find the same leaves, whose bounces agree as the gather's do (vct.rs,
    // `octree_and_dense_renders_agree`: at most 2/255). A lookup that missed leaves or found
    // the wrong ones would change whole regions.
    assert!(worst <= 4, "{worst}/255 apart");
    assert!(c.flip_mean < 0.02, "mean FLIP {}", c.flip_mean);
}

#[test]
fn progressive_leaves_converge_to_unlimited_leaves() {
    // Progressive bounces keep the records at every step, so pixels follow the light as it
    // converges; the converged light must be the unlimited bounces' (not to the bit: the
    // stored steps turn their bundles by the records' layout).
    let scene = builtin::closed_box(0.5, 1.0);
    let params = clamped(&scene.cameras[0]);
    let options = |progressive: bool| RendererOptions {
        voxel_resolution: 32,
        bounces: voxgi::UNLIMITED_BOUNCES,
        progressive,
        indirect: IndirectShading::Leaves,
        default_light: false,
        ..RendererOptions::default()
    };
    let mut unlimited = renderer(&scene, &options(false));
    let want = frame(&mut unlimited, &params, 24, 24).mean_radiance()[0];
    let mut r = renderer(&scene, &options(true));
    let mut means = vec![frame(&mut r, &params, 24, 24).mean_radiance()[0]];
    while !r.voxels_settled() {
        assert!(means.len() < 100, "progressive bounces never settle");
        means.push(frame(&mut r, &params, 24, 24).mean_radiance()[0]);
    }
    let got = *means.last().unwrap();
    eprintln!("progressive leaves by frame: {means:?}; unlimited {want}");
    // Measured 1.97493 against 1.97550 (0.03 %), rising 1, 1.493, 1.737, … one bounce per
    // frame. 0.5 %: a step lost or counted twice moves it by ρ^k of the series, 12 % at the
    // second step and still 0.8 % at the eighth.
    assert!(
        rel(got, want) < 0.005,
        "progressive {got} against unlimited {want}"
    );
    for w in means.windows(2) {
        assert!(w[1] >= w[0] - 1e-3, "progressive light fell: {means:?}");
    }
}
