//! The clipmap against the dense volume it is built from, and its levels' hand-over.

use crate::common::*;
use crate::contract::run_probes;
use voxgi::scene::builtin;
use voxgi::scene::glam::Vec3;
use voxgi::voxel::Grid;
use voxgi::voxel::clipmap::Clipmap;
use voxgi::{RendererOptions, VoxelKind};

/// The dense volume's options for the Cornell box at 32³, one bounce, every frame a still.
fn dense() -> RendererOptions {
    RendererOptions {
        voxel_resolution: 32,
        bounces: 2,
        shadow_map_size: 256,
        temporal: false,
        ..RendererOptions::default()
    }
}

/// A clipmap whose finest voxels are the dense volume's and whose finest level is as wide as
/// the scene's cube lies exactly on the dense volume's grid (the windows stay inside the
/// cube, on a lattice from its corner), wherever the camera is: it renders the dense
/// volume's picture. Not to the bit: the samples' texture coordinates are normalised over
/// two stacked windows, so filter weights round differently; measured 2e-6 apart (HDR) on
/// lavapipe, 1e-3 allows other drivers' 8-bit filter weights.
#[test]
fn a_clipmap_on_the_dense_grid_renders_the_dense_picture() {
    let scene = builtin::cornell_box();
    let b = scene.swept_bounds();
    let voxel = Grid::around(b.min, b.max, 32).voxel_size;
    let clip = RendererOptions {
        voxels: VoxelKind::CLIPMAP,
        clipmap_levels: 2,
        voxel_size: Some(voxel),
        ..dense()
    };
    let mut d = renderer(&scene, &dense());
    let mut c = renderer(&scene, &clip);
    let p = clamped(d.default_camera());
    let (want, got) = (frame(&mut d, &p, 48, 48), frame(&mut c, &p, 48, 48));
    let level0 = c.structure::<Clipmap>().expect("a clipmap").levels()[0];
    let grid = d.volume().grid();
    assert!(
        level0.origin.abs_diff_eq(grid.origin, 1e-6) && level0.voxel_size == grid.voxel_size,
        "level 0 {level0:?} is not the dense grid {grid:?}"
    );
    let worst = got
        .hdr
        .iter()
        .zip(&want.hdr)
        .map(|(a, b)| (a - b).abs() / b.abs().max(0.05))
        .fold(0.0f32, f32::max);
    eprintln!("clipmap on the dense grid: largest relative HDR difference {worst}");
    assert!(worst < 1e-3, "{worst}");
}

/// Along a line that leaves the finest level, the levels hand over across a band of voxels
/// instead of switching: just above the Cornell box's floor, where the finest level's floor
/// voxels and the next level's (twice as thick) differ, no step between samples a twentieth
/// of a finest voxel apart is more than a tenth of the change across the border. A switch
/// makes one step all of it (0.124 of 0.124 with the band cut to a hundredth of a voxel); the
/// band spreads it over 80 samples, linearly in optical depth, so in opacity the largest step
/// measured 0.0063 of 0.124.
#[test]
fn levels_hand_over_without_a_step() {
    let scene = builtin::cornell_box();
    let b = scene.swept_bounds();
    let dense_voxel = Grid::around(b.min, b.max, 32).voxel_size;
    let options = RendererOptions {
        voxels: VoxelKind::CLIPMAP,
        voxel_resolution: 16,
        clipmap_levels: 3,
        // The finest level a third of the box wide, the next two thirds, the third all of it.
        voxel_size: Some(dense_voxel * 0.75),
        ..dense()
    };
    let mut r = renderer(&scene, &options);
    // Inside the box, low, in front of the blocks: the finest level sits on the floor, in the
    // middle along x.
    let camera = voxgi::scene::Camera::look_at(
        Vec3::new(0.28, 0.05, 0.52),
        Vec3::new(0.28, 0.05, 0.8),
        60.0,
    );
    frame(&mut r, &clamped(&camera), 16, 16);
    let level0 = r.structure::<Clipmap>().expect("a clipmap").levels()[0];
    let s = level0.voxel_size;
    // Kept inside the box's bounds, its lowest face on the floor (y = 0).
    assert!(
        level0.origin.y.abs() < 1e-5,
        "level 0 {level0:?} is not on the floor"
    );
    // Along x just above the floor, from wall to wall, clear of the blocks (which reach
    // z = 0.46): it crosses level 0's two x faces.
    let (y, z) = (1.2 * s, 0.52);
    let step = s / 20.0;
    let xs: Vec<f32> = (0..((0.50 / step) as usize))
        .map(|i| 0.03 + i as f32 * step)
        .collect();
    let probes: Vec<[f32; 8]> = xs
        .iter()
        .map(|&x| [x, y, z, s, 0.0, 1.0, 0.0, 0.0])
        .collect();
    let got = run_probes(&r, &probes);
    let lo = level0.origin.x;
    let hi = lo + level0.extent();
    // Near each x face of level 0 (within 12 of its voxels, which spans the band): the
    // largest step between neighbours and the range, in opacity.
    for face in [lo, hi] {
        let near: Vec<(f32, f32)> = xs
            .iter()
            .zip(&got)
            .filter(|(x, _)| (**x - face).abs() < 12.0 * s)
            .map(|(x, v)| (*x, v.w))
            .collect();
        let step_max = near
            .windows(2)
            .map(|w| (w[1].1 - w[0].1).abs())
            .fold(0.0f32, f32::max);
        let (min, max) = near
            .iter()
            .fold((f32::MAX, f32::MIN), |(a, b), v| (a.min(v.1), b.max(v.1)));
        eprintln!(
            "level 0's face at x = {face:.3}: opacity {min:.3}..{max:.3}, largest step {step_max:.4}"
        );
        // The levels must differ here, or the test could not see a switch.
        assert!(max - min > 0.02, "the levels agree at {face}: {min}..{max}");
        assert!(
            step_max < 0.1 * (max - min),
            "a step of {step_max} across {min}..{max} at x = {face}"
        );
    }
}
