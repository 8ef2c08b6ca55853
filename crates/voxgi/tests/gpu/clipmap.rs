//! The clipmap against the dense volume it is built from, and its levels' hand-over.

use crate::common::*;
use crate::contract::{Errors, random_probes, read_chain, run_probes};
use voxgi::scene::builtin;
use voxgi::scene::glam::Vec3;
use voxgi::voxel::Grid;
use voxgi::voxel::clipmap::Clipmap;
use voxgi::voxel::cpu::{DenseSampler, Texture3d};
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

/// The Cornell box in three clipmap levels of `resolution`³ voxels, the finest `finest` times
/// the dense volume's 32³ voxel, rendered once from a camera low in the box.
fn three_levels_in_the_box(resolution: u32, finest: f32, anisotropic: bool) -> voxgi::Renderer {
    let scene = builtin::cornell_box();
    let b = scene.swept_bounds();
    let dense_voxel = Grid::around(b.min, b.max, 32).voxel_size;
    let options = RendererOptions {
        voxels: VoxelKind::CLIPMAP,
        voxel_resolution: resolution,
        clipmap_levels: 3,
        voxel_size: Some(dense_voxel * finest),
        anisotropic,
        ..dense()
    };
    let mut r = renderer(&scene, &options);
    let camera =
        voxgi::scene::Camera::look_at(Vec3::new(0.2, 0.1, 0.4), Vec3::new(0.3, 0.2, 0.1), 60.0);
    frame(&mut r, &clamped(&camera), 16, 16);
    r
}

/// A clipmap's levels read back: the finest voxels and the chains.
fn read_levels(clip: &Clipmap) -> (Texture3d, Texture3d) {
    (
        read_chain(&clip.volume().radiance),
        read_chain(&clip.volume().chains),
    )
}

/// The dense CPU twin over levels read back (`read_levels`).
fn cpu_levels<'a>(
    clip: &Clipmap,
    (radiance0, chains): &'a (Texture3d, Texture3d),
) -> DenseSampler<'a> {
    DenseSampler {
        grid: clip.volume().grid,
        anisotropic: clip.volume().anisotropic,
        windows: clip.levels().len() as u32,
        radiance0,
        chains,
    }
}

/// A clipmap whose finest voxels are the dense volume's and whose finest level is as wide as
/// the scene's cube lies exactly on the dense volume's grid (a window wider than the scene's
/// bounds is centred on them), wherever the camera is: it renders the dense volume's
/// picture. Not to the bit: the samples' texture coordinates are normalised over
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
/// voxels and the next level's (twice as thick, the mean of the finer ones) differ, no step
/// between samples a twentieth of a finest voxel apart is more than a tenth of the change
/// across the border. The windows of 16 voxels lie within each other's bands here: measured,
/// the largest step is 0.059 of 0.985; blending the finest level with the next where that one
/// was itself handing over to the third made a step of 0.34 (of 0.53, with level 0 a voxel
/// higher).
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
    // Kept inside the box's bounds (within half a step, two voxels), its lowest face at the
    // floor (y = 0).
    assert!(
        level0.origin.y.abs() <= 2.0 * s,
        "level 0 {level0:?} is not at the floor"
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

/// `sample_voxels` on the GPU equals its CPU twin (`Clipmap::sample_voxels_cpu` over the
/// levels' textures read back): the Cornell box in three levels of 16³ around a camera low in
/// the box, probed at random points over the coarsest level (and a little past it), in random
/// directions, with diameters of one to 24 finest voxels, so that samples fall in every level,
/// in the hand-over bands and past the windows. Both anisotropic and isotropic. The tolerance
/// is the dense twin's (`filtering_tolerance`): each level's read is the dense volume's.
#[test]
fn sample_voxels_matches_its_cpu_twin() {
    for anisotropic in [true, false] {
        let r = three_levels_in_the_box(16, 0.75, anisotropic);
        let clip = r.structure::<Clipmap>().expect("a clipmap");
        let levels = read_levels(clip);
        let cpu = cpu_levels(clip, &levels);
        let finest = clip.levels()[0].voxel_size;
        // A third of the probes over each level's window (and a little past it), diameters
        // of one to 24 finest voxels.
        let probes: Vec<[f32; 8]> = clip
            .levels()
            .iter()
            .flat_map(|g| random_probes(*g, 256, 1.0))
            .enumerate()
            .map(|(i, mut q)| {
                q[3] = finest * 24f32.powf((i as f32 * 0.618_034).fract());
                q
            })
            .collect();
        let gpu = run_probes(&r, &probes);
        let mut errors = Errors::default();
        let (mut nonzero, mut levels_used, mut bands) = (0, [0usize; 3], 0);
        for (q, g) in probes.iter().zip(gpu) {
            let p = Vec3::new(q[0], q[1], q[2]);
            let dir = Vec3::new(q[4], q[5], q[6]);
            let want = clip.sample_voxels_cpu(&cpu, p, q[3], dir);
            errors.add((g - want).abs().max_element(), || {
                format!("sample_voxels({p}, {}, {dir}): GPU {g}, CPU {want}", q[3])
            });
            nonzero += (want.w > 0.01) as usize;
            let (k, w) = clip.level_at(p, q[3]);
            levels_used[k] += 1;
            bands += (w < 1.0 && k + 1 < levels_used.len()) as usize;
        }
        errors.check(
            filtering_tolerance(),
            &format!("clipmap probe (anisotropic {anisotropic})"),
        );
        assert!(
            nonzero > probes.len() / 4,
            "only {nonzero} samples see voxels"
        );
        eprintln!("levels read {levels_used:?}, {bands} in a hand-over band");
        // The probes read every level, and some read two (in a hand-over band).
        assert!(
            levels_used.iter().all(|&n| n > 20) && bands > 20,
            "levels read {levels_used:?}, in bands {bands}"
        );
    }
}

/// Inside the finer window a coarser level holds what the finer level's mips hold (the nest,
/// shaders/voxels/clipmap/nest.wgsl): level 1 read at a footprint of one of its chain texels
/// equals level 0 read at the same footprint (its chain level one above), at random points
/// and directions inside level 0 (clear of its faces by more than a filter's reach), over the
/// levels' textures read back, directional and isotropic. Copies of the same texels at the
/// same places: the only difference is the texture coordinates' rounding, measured 2e-5 of
/// 4.6 on lavapipe; 1e-4 of the largest value allows another driver's. Filtered from level
/// 1's own finest voxels instead (its texels not copied), the worst is 3.7.
#[test]
fn inside_a_finer_level_the_coarser_one_reads_its_mips() {
    for anisotropic in [true, false] {
        let r = three_levels_in_the_box(32, 0.375, anisotropic);
        let clip = r.structure::<Clipmap>().expect("a clipmap");
        let (fine, coarse) = (clip.levels()[0], clip.levels()[1]);
        // Windows step by an eighth of themselves (4 voxels of 32): level 0's corner lies an
        // even number of level 1's voxels in, so level 1's first chain level (texels of two
        // voxels) lies on level 0's lattice.
        let o = (fine.origin - coarse.origin) / coarse.voxel_size;
        assert!(
            o.abs_diff_eq(o.round(), 1e-3) && (o.round() % 2.0).abs().max_element() < 0.5,
            "level 0 lies {o} voxels into level 1"
        );
        let levels = read_levels(clip);
        let cpu = cpu_levels(clip, &levels);
        // Level 0's samples keep half a texel of the level read inside its window, and the
        // probes spread 5 % past the grid.
        let margin = 6.0 * fine.voxel_size;
        let inner = Grid {
            origin: fine.origin + Vec3::splat(margin),
            voxel_size: (fine.extent() - 2.0 * margin) / fine.resolution as f32,
            resolution: fine.resolution,
        };
        // random_probes spreads 5 % past the grid: the margin keeps that inside level 0.
        let probes = random_probes(inner, 600, 1.0);

        let (mut worst, mut largest, mut seen) = (0.0f32, 0.0f32, 0);
        for q in &probes {
            let p = Vec3::new(q[0], q[1], q[2]);
            let dir = Vec3::new(q[4], q[5], q[6]);
            let at = |g: &Grid| (p - g.origin) / g.extent();
            let want = cpu.window_depth(at(&fine), 2.0, dir, 0);
            let got = cpu.window_depth(at(&coarse), 1.0, dir, 1);
            worst = worst.max((got - want).abs().max_element());
            largest = largest.max(want.abs().max_element());
            seen += (want.w > 0.05) as usize;
        }
        eprintln!(
            "anisotropic {anisotropic}: level 1 against level 0's mips, worst {worst:e} of \
             {largest}; {seen} samples see voxels"
        );
        assert!(seen > 30, "only {seen} samples see voxels");
        assert!(worst <= 1e-4 * largest, "{worst} of {largest}");
    }
}

/// Voxelize skips a draw whose box misses the window it voxelizes (the host's spans of the
/// table, `TriangleTable::spans`, and voxelize.wgsl's `draw_in_region`), and no other: every
/// level of a clipmap over cubes inside, astride and
/// outside its finest window holds the voxels the CPU voxelizer finds there for all of them.
/// Not to the voxel: the GPU multiplies by the inverse voxel size where the CPU divides, so a
/// face within rounding of a voxel face may land a layer apart (the cubes' faces lie off the
/// windows' lattices: measured none); a skipped cube would miss hundreds.
#[test]
fn every_level_holds_the_voxels_of_the_draws_it_reaches() {
    use voxgi::scene::glam::Mat4;
    let mut scene = voxgi::scene::Scene::default();
    // 30 cm cubes along a line from the camera out past the finest window.
    let centres: Vec<Vec3> = (0..12)
        .map(|i| Vec3::new(0.1234 + 0.37 * i as f32, 0.0517 * i as f32, -0.0291))
        .collect();
    for &c in &centres {
        let m = Mat4::from_translation(c) * Mat4::from_scale(Vec3::splat(0.3));
        scene.append(builtin::cube([0.6, 0.6, 0.6]), m, false);
    }
    let triangles: Vec<[Vec3; 3]> = scene
        .instances
        .iter()
        .flat_map(|inst| {
            let m = &scene.meshes[inst.mesh];
            m.indices
                .chunks_exact(3)
                .map(|t| {
                    [t[0], t[1], t[2]]
                        .map(|i| inst.transform.transform_point3(m.positions[i as usize]))
                })
                .collect::<Vec<_>>()
        })
        .collect();
    let options = RendererOptions {
        voxels: VoxelKind::CLIPMAP,
        voxel_resolution: 32,
        clipmap_levels: 3,
        voxel_size: Some(0.04),
        bounces: 0,
        ..dense()
    };
    let mut r = renderer(&scene, &options);
    let camera = voxgi::scene::Camera::look_at(centres[0], centres[11], 60.0);
    frame(&mut r, &clamped(&camera), 16, 16);
    let clip = r.structure::<Clipmap>().expect("a clipmap");
    let c = ctx();
    let occupancy =
        voxgi::gpu::readback::read_buffer_copy(&c.device, &c.queue, &clip.volume().occupancy)
            .expect("occupancy");
    let occupancy: &[u32] = bytemuck::cast_slice(&occupancy);
    let res = 32usize;
    let mut reached = Vec::new();
    for (k, grid) in clip.levels().iter().enumerate() {
        let want = voxgi::voxel::cpu::voxelize(&triangles, grid);
        let window = &occupancy[k * res.pow(3)..(k + 1) * res.pow(3)];
        let got: std::collections::BTreeSet<[u32; 3]> = (0..res.pow(3))
            .filter(|&i| window[i] != 0)
            .map(|i| {
                [
                    (i % res) as u32,
                    (i / res % res) as u32,
                    (i / res / res) as u32,
                ]
            })
            .collect();
        let apart = want.symmetric_difference(&got).count();
        assert!(
            !want.is_empty() && apart * 200 <= want.len(),
            "level {k}: {} voxels by the CPU, {} on the GPU, {apart} apart",
            want.len(),
            got.len()
        );
        // Which cubes the window reaches at all.
        reached.push(
            centres
                .iter()
                .filter(|&&p| {
                    let q = (p - grid.origin) / grid.voxel_size;
                    q.cmpge(Vec3::splat(-4.0)).all() && q.cmplt(Vec3::splat(36.0)).all()
                })
                .count(),
        );
    }
    // The finest window leaves cubes out (so the test sees skipped draws); the coarsest
    // reaches all of them.
    assert!(
        reached[0] < centres.len() && reached[2] == centres.len(),
        "cubes reached per level: {reached:?}"
    );
}
