//! The normal-distribution-weighted first level (`RendererOptions::ndf_mips`, the point-cloud
//! thesis' §4.4.2) is the default, so every other test runs with it; these run the shared
//! invariants and the Cornell comparison with it off (isotropic leaves), which stays an option.
//! The filter itself against its CPU twin is in voxels.rs
//! (`voxel_filter_weighs_leaves_by_their_normals`).

use crate::common::*;
use crate::point_gi::as_points;
use crate::vct::{
    FURNACE_CASES, Variant, ao_of_an_open_plane_on, cornell_variant_against_the_path_tracer,
    furnace_series, one_voxel_wall_rooms, thin_wall_leak,
};
use voxgi::VoxelKind;
use voxgi::scene::builtin;

#[test]
fn isotropic_leaves_keep_the_furnace_series() {
    // Inside a closed box every cone ends on a wall it meets head-on: weights that lost light
    // (or counted a back face) would show here as a bounce short. Measured at 32³ 1.489, 1.728
    // and 1.959 (dense; octree 1.490, 1.732, 1.966) against 1.491, 1.733, 1.969 without: the
    // walls' leaves at the box's edges hold two faces and count less along each.
    let scene = builtin::closed_box(0.5, 1.0);
    for &kind in VoxelKind::ALL {
        furnace_series(&scene, Variant::isotropic_leaves(kind), &FURNACE_CASES);
    }
}

#[test]
fn isotropic_leaves_see_an_open_plane_of_points_unoccluded() {
    // The plane's own leaves, seen edge-on by the ring's cones, now count half: AO must stay
    // 1 (the bound and its reasons in `ao_of_an_open_plane`).
    let scene = as_points(&plane_scene(0.5), 64, 2.0);
    for &kind in VoxelKind::ALL {
        ao_of_an_open_plane_on(&scene, Variant::isotropic_leaves(kind));
    }
}

#[test]
fn isotropic_leaves_keep_a_thin_wall_closed() {
    let res = 64;
    let scene = one_voxel_wall_rooms(res);
    for &kind in VoxelKind::ALL {
        let leak = thin_wall_leak(&scene, Variant::isotropic_leaves(kind), res);
        eprintln!("thin wall with NDF mips ({kind:?}): {:.2} %", leak * 100.0);
        // The one-voxel wall holds both faces: their normals cancel and its own leaves count
        // as isotropic; the floor's and ceiling's leaves beside it, seen edge-on, now count
        // half, so less of room A's light reaches the wall's foot from them. Measured 0.42 %
        // (both structures; 0.71 % without). The 1 %, as for the isotropic leaves.
        assert!(
            leak < 0.01,
            "{kind:?}: {:.2} % through the wall",
            leak * 100.0
        );
    }
}

#[test]
fn isotropic_leaves_cornell_box_against_the_path_tracer() {
    // Measured (dense; the octree within 0.01): back wall 1.031, floor 0.994, red wall 1.047,
    // green wall 1.040, ceiling 1.365, against 1.039, 1.040, 1.047, 1.039 and 1.357 without:
    // the floor, whose cones skim the box's edge-on walls, comes down to the path tracer.
    // LDR-FLIP 0.132 (dense) and 0.131 (octree), 0.143 and 0.142 without.
    let images =
        cornell_variant_against_the_path_tracer("isotropic leaves", |o| o.ndf_mips = false);
    // The octree filters its leaves' normals from its slots, the dense volume from its normal
    // texture: the same weights, so the same pictures (as `octree_and_dense_renders_agree`).
    let worst = largest_difference(&images[0].ldr, &images[1].ldr);
    eprintln!("NDF mips, octree vs dense: largest difference {worst}/255");
    assert!(worst <= 4, "octree and dense {worst}/255 apart");
}
