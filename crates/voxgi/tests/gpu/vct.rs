//! Physical invariants of the cone tracer, each on a small procedural scene, each asserting a
//! number. The tolerances are measured, and each comment says what limits them.

use crate::common::*;
use voxgi::scene::builtin;
use voxgi::scene::glam::{Mat4, Vec3};
use voxgi::scene::{Camera, Material, Mesh, Scene};
use voxgi::{IndirectShading, RendererOptions, ViewMode, VoxelKind};

pub(crate) fn vct(view: ViewMode, res: u32, bounces: u32) -> Setup {
    Setup {
        options: RendererOptions {
            default_light: false,
            voxel_resolution: res,
            bounces,
            ..RendererOptions::default()
        },
        view,
    }
}

/// A voxel structure and how pixels read its indirect light: what the shared invariant checks
/// run on (a `VoxelKind` alone means per-pixel cones).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Variant {
    pub kind: VoxelKind,
    pub indirect: IndirectShading,
    /// `RendererOptions::ndf_mips`.
    pub ndf: bool,
}

impl Variant {
    /// Structure `kind` read through the fast shading.
    pub(crate) fn leaves(kind: VoxelKind) -> Self {
        Variant {
            indirect: IndirectShading::Leaves,
            ..kind.into()
        }
    }

    /// Structure `kind` with isotropic leaves in the first directional level (no NDF).
    pub(crate) fn isotropic_leaves(kind: VoxelKind) -> Self {
        Variant {
            ndf: false,
            ..kind.into()
        }
    }
}

impl From<VoxelKind> for Variant {
    fn from(kind: VoxelKind) -> Self {
        Variant {
            kind,
            indirect: IndirectShading::Cones,
            ndf: RendererOptions::default().ndf_mips,
        }
    }
}

/// `vct` on voxel structure `kind` (with its indirect shading).
pub(crate) fn on(kind: impl Into<Variant>, mut s: Setup) -> Setup {
    let v = kind.into();
    s.options.voxels = v.kind;
    // A clipmap's levels stack along z, at most 1024 voxels and (with six directions of half
    // the resolution) 2048 texels deep.
    s.options.clipmap_levels = (2048 / (3 * s.options.voxel_resolution)).clamp(2, 5);
    s.options.indirect = v.indirect;
    s.options.ndf_mips = v.ndf;
    s
}

/// Mean of channel `c` over a pixel rectangle.
pub(crate) fn mean(out: &voxgi::RenderOutput, x0: u32, y0: u32, x1: u32, y1: u32, c: usize) -> f32 {
    let mut s = 0.0;
    for y in y0..y1 {
        for x in x0..x1 {
            s += out.radiance(x, y)[c];
        }
    }
    s / ((x1 - x0) * (y1 - y0)) as f32
}

pub(crate) fn wall_mesh(x: f32, height: f32, depth: f32) -> Mesh {
    // A vertical quad in the plane x = const, facing -X, from y = 0 to height.
    Mesh {
        name: "wall".into(),
        positions: vec![
            Vec3::new(x, 0.0, -depth),
            Vec3::new(x, 0.0, depth),
            Vec3::new(x, height, depth),
            Vec3::new(x, height, -depth),
        ],
        normals: vec![Vec3::NEG_X; 4],
        uvs: Vec::new(),
        indices: vec![0, 2, 1, 0, 3, 2],
        material: 0,
    }
}

#[test]
fn ao_of_an_open_plane_is_one() {
    ao_of_an_open_plane(&plane_scene(0.5));
}

/// The AO of `plane_scene` (or a version of it) seen from above, for every structure.
pub(crate) fn ao_of_an_open_plane(scene: &Scene) {
    for &kind in VoxelKind::ALL {
        ao_of_an_open_plane_on(scene, kind.into());
    }
}

/// `ao_of_an_open_plane` on one variant.
pub(crate) fn ao_of_an_open_plane_on(scene: &Scene, kind: Variant) {
    let cam = Camera::look_at(Vec3::new(0.0, 4.0, 0.01), Vec3::ZERO, 40.0);
    {
        let mut s = on(kind, vct(ViewMode::Ao, 64, 0));
        s.options.ao_radius = Some(3.0);
        let out = render(scene, s, &cam, 32, 32);
        let ao = mean(&out, 8, 8, 24, 24, 0);
        eprintln!("open plane AO ({kind:?}) {ao}");
        // Measured 1.000 at 64³ (both structures): samples stay far enough above their own
        // surface that no level of the plane's voxels reaches them (see `cone_sample_size`).
        // 0.98 allows fp16 storage and other drivers' filtering; self-occlusion showed as
        // 0.89 (too little clearance) or 0.61 (optical depth without it).
        assert!(ao > 0.98, "AO of an unoccluded plane ({kind:?}): {ao}");
    }
}

/// The floor beside a 10 m wall at x = 0 (`ao_beside_a_wall`'s scene), and a camera looking at
/// the floor next to the wall from above and in front.
pub(crate) fn floor_beside_a_wall() -> (Scene, Camera) {
    let mut scene = plane_scene(0.5);
    scene.add_mesh(
        wall_mesh(0.0, 10.0, 10.0),
        Material::diffuse("wall", [0.5; 3]),
        Mat4::IDENTITY,
    );
    let cam = Camera::look_at(Vec3::new(-1.0, 3.0, 0.01), Vec3::new(-0.4, 0.0, 0.0), 30.0);
    (scene, cam)
}

#[test]
fn ao_beside_a_wall_matches_the_closed_form() {
    let (scene, cam) = floor_beside_a_wall();
    for &kind in VoxelKind::ALL {
        ao_beside_a_wall(&scene, &cam, kind);
    }
}

pub(crate) fn ao_beside_a_wall(scene: &Scene, cam: &Camera, kind: impl Into<Variant>) -> f32 {
    let kind = kind.into();
    let mut s = on(kind, vct(ViewMode::Ao, 64, 0));
    let radius = 4.0;
    s.options.ao_radius = Some(radius);
    let mut r = renderer(scene, &s.options);
    let params = voxgi::FrameParams {
        view: s.view,
        ..clamped(cam)
    };
    let out = frame(&mut r, &params, 64, 64);
    // A floor point at distance x from a wall far taller and wider than the AO radius R sees
    // the wall along every direction with a component towards it above x / R: with cosine
    // weighting (directions uniform on the unit disc below them) the occluded share is the
    // disc's segment beyond a = x / R, (acos a - a sqrt(1 - a^2)) / pi; 1/2 at the foot.
    let expected = |x: f32| {
        let a = (x / radius).min(1.0);
        1.0 - (a.acos() - a * (1.0 - a * a).sqrt()) / std::f32::consts::PI
    };
    // Probes 2 to 4 voxels from the wall: nearer, the probe's cones start inside the wall's
    // voxels (they cover a voxel either side of its plane) and see it in every direction.
    let mut worst: (f32, f32, f32, f32) = (0.0, 0.0, 0.0, 0.0);
    let mut n = 0;
    let mut probed_voxel = 0.0;
    for y in 0..64 {
        for x in 0..64 {
            let p = pixel_on_ground(cam, 64, 64, x, y);
            let d = -p.x;
            // The voxels the probe's cones start at (a clipmap's coarsen away from the camera).
            let voxel = r.volume().voxel_size_at(p);
            probed_voxel = voxel;
            if d < 2.0 * voxel || d > 4.0 * voxel || p.z.abs() > 2.0 {
                continue;
            }
            let (got, want) = (out.radiance(x, y)[0], expected(d));
            n += 1;
            if (got - want).abs() > worst.0 {
                worst = ((got - want).abs(), d, got, want);
            }
        }
    }
    eprintln!(
        "AO beside a wall ({kind:?}, {n} probes, voxel {probed_voxel} m): worst at {:.3} m, {:.3} vs closed form {:.3}",
        worst.1, worst.2, worst.3
    );
    assert!(
        n >= 10,
        "only {n} probes between 2 and 4 voxels from the wall"
    );
    // Measured: worst 0.713 against 0.680 (0.684 against 0.603 along fixed axes; the cones
    // towards the wall are narrowed near the floor, so the wall's first voxels weigh less);
    // 0.1 allows that. A wall
    // that did not occlude would give 1 against the closed form's ~0.6. The clipmap (five
    // levels of 64³, the probes in the second, the floor below the first) moves with where its
    // windows lie against the wall: measured 0.641 against 0.591 (0.626 against 0.577 reading
    // the leaves' irradiance; the wall of points 0.699 against 0.595, whose partly covered
    // fine voxels make the coarser level's mips lighter than its own voxels), and 0.488
    // against 0.551 (the points 0.524 against 0.559) with the windows' lattice started at
    // the scene's corner; 0.12 allows both.
    let tolerance = if kind.kind == VoxelKind::CLIPMAP {
        0.12
    } else {
        0.1
    };
    assert!(
        worst.0 < tolerance,
        "AO ({kind:?}) {:.3} at {:.3} m from the wall, closed form {:.3}",
        worst.2,
        worst.1,
        worst.3
    );
    worst.0
}

/// The mean of the white furnace's image (`builtin::closed_box(0.5, 1.0)` or a version of it),
/// at 32³: the series is the same at any resolution, and at 64³ the four tests that run it (for
/// every structure) were among the test binary's slowest.
fn furnace(scene: &Scene, kind: Variant, bounces: u32) -> f32 {
    let cam = scene.cameras[0].clone();
    let out = render(
        scene,
        on(kind, vct(ViewMode::Final, 32, bounces)),
        &cam,
        24,
        24,
    );
    mean(&out, 4, 4, 20, 20, 0)
}

#[test]
fn furnace_matches_the_geometric_series() {
    let scene = builtin::closed_box(0.5, 1.0);
    for &kind in VoxelKind::ALL {
        furnace_series(&scene, kind, &FURNACE_CASES);
    }
}

/// Bounces, the furnace's expected mean (albedo 0.5, emission 1) and the tolerance.
pub(crate) const FURNACE_CASES: [(u32, f32, f32); 4] = [
    (0, 1.0, 0.01),
    (1, 1.5, 0.02),
    (2, 1.75, 0.02),
    (voxgi::UNLIMITED_BOUNCES, 2.0, 0.03),
];

pub(crate) fn furnace_series(scene: &Scene, kind: impl Into<Variant>, cases: &[(u32, f32, f32)]) {
    let kind = kind.into();
    let got: Vec<f32> = cases.iter().map(|c| furnace(scene, kind, c.0)).collect();
    for (c, g) in cases.iter().zip(&got) {
        eprintln!(
            "furnace ({kind:?}), {} bounces: {g} (expected {})",
            c.0, c.1
        );
    }
    for (c, g) in cases.iter().zip(&got) {
        // Without bounces the image is the emission, exact but for fp16 storage (1 %).
        // Measured at 32³ 1.491, 1.733 and 1.969 against 1.5, 1.75 and 2 (0.6 %, 1.0 %, 1.5 %
        // short; 0.3 %, 0.5 %, 0.8 % at 64³: the 0.999 opacity cap lets 0.1 % through a wall
        // per crossing, the walls' edge leaves hold two faces, and the unlimited series stops
        // early). 2 % and 3 % allow fp16 and other drivers; with interpolated
        // opacity instead of optical depth each bounce was 15 % short.
        assert!(
            rel(*g, c.1) < c.2,
            "{kind:?}, {} bounces: {g} vs {}",
            c.0,
            c.1
        );
    }
}

/// `builtin::two_rooms` with its wall exactly one finest voxel thick at `res`³ (the rooms'
/// bounds do not depend on the wall's thickness).
pub(crate) fn one_voxel_wall_rooms(res: u32) -> Scene {
    let b = builtin::two_rooms(0.01).bounds();
    builtin::two_rooms(voxgi::voxel::Grid::around(b.min, b.max, res).voxel_size)
}

#[test]
fn thin_wall_leaks_less_than_one_percent() {
    let res = 64;
    let scene = one_voxel_wall_rooms(res);
    for &kind in VoxelKind::ALL {
        let leak = thin_wall_leak(&scene, kind, res);
        eprintln!("indirect radiance ({kind:?}): room B / room A {leak}");
        // Measured 0.33 % (dense, octree; clipmap 0.37 %), 0.50 % with isotropic leaves,
        // against the DESIGN target of 1 % (5.2 % when the volume interpolated opacity: a cone
        // crossed the one-voxel wall through a ramp of partial opacity).
        assert!(
            leak < 0.01,
            "{kind:?}: room B gets {leak} of room A's indirect light"
        );
    }
}

/// Room B's indirect radiance over room A's (two bounces), in `builtin::two_rooms` or a
/// version of it.
pub(crate) fn thin_wall_leak(scene: &Scene, kind: impl Into<Variant>, res: u32) -> f32 {
    let cam_a = Camera::look_at(Vec3::new(-0.9, 0.5, 0.9), Vec3::new(-0.1, 0.3, 0.1), 70.0);
    let cam_b = Camera::look_at(Vec3::new(0.9, 0.5, 0.9), Vec3::new(0.1, 0.3, 0.1), 70.0);
    let s = on(kind, vct(ViewMode::Indirect, res, 2));
    let a = render(scene, s.clone(), &cam_a, 32, 32).mean_radiance()[0];
    let b = render(scene, s, &cam_b, 32, 32).mean_radiance()[0];
    assert!(a > 0.0, "no indirect light in room A");
    b / a
}

#[test]
fn cornell_floor_bleeds_red_near_red_wall_and_green_near_green() {
    let scene = builtin::cornell_box();
    let cam = scene.cameras[0].clone();
    for &kind in VoxelKind::ALL {
        bleeding(&scene, &cam, kind);
    }
}

fn bleeding(scene: &Scene, cam: &Camera, kind: VoxelKind) {
    let out = render(scene, on(kind, vct(ViewMode::Indirect, 64, 2)), cam, 64, 64);
    // Floor strips next to each wall, in the lower part of the image (red wall on the left).
    let (near_red_r, near_red_g) = (mean(&out, 6, 54, 14, 60, 0), mean(&out, 6, 54, 14, 60, 1));
    let (near_green_r, near_green_g) =
        (mean(&out, 50, 54, 58, 60, 0), mean(&out, 50, 54, 58, 60, 1));
    let red_ratio = near_red_r / near_red_g;
    let green_ratio = near_green_r / near_green_g;
    eprintln!("floor r/g ({kind:?}) near red {red_ratio}, near green {green_ratio}");
    // Measured 4.1 against 0.75: the walls' reflectances differ by a factor of ~50 in r/g, so
    // any working bounce separates them by far more than the 1.5 asked here.
    assert!(
        red_ratio > 1.5 * green_ratio,
        "{kind:?}: r/g {red_ratio} vs {green_ratio}"
    );
}

#[test]
fn mean_indirect_is_consistent_between_64_and_256() {
    let scene = builtin::cornell_box();
    let cam = scene.cameras[0].clone();
    for &kind in VoxelKind::ALL {
        let at = |res| {
            let m = render(
                &scene,
                on(kind, vct(ViewMode::Indirect, res, 1)),
                &cam,
                32,
                32,
            )
            .mean_radiance();
            (m[0] + m[1] + m[2]) / 3.0
        };
        let (l, h) = (at(64), at(256));
        eprintln!("mean indirect ({kind:?}) 64³ {l}, 256³ {h}");
        // DESIGN: less than 10 % between 64³ and 256³ (measured 5.6 % for both structures).
        assert!(rel(l, h) < 0.10, "{kind:?}: 64³ {l} vs 256³ {h}");
    }
}

/// Mean indirect radiance of the Cornell box at 32³ and 32×32, one bounce, with `change`
/// applied to the settings.
fn cornell_mean_indirect(change: impl FnOnce(&mut RendererOptions)) -> f32 {
    let scene = builtin::cornell_box();
    let mut s = vct(ViewMode::Indirect, 32, 1);
    change(&mut s.options);
    let m = render(&scene, s, &scene.cameras[0], 32, 32).mean_radiance();
    (m[0] + m[1] + m[2]) / 3.0
}

#[test]
fn isotropic_mode_keeps_less_of_the_indirect_light() {
    let iso = cornell_mean_indirect(|s| s.anisotropic = false);
    let aniso = cornell_mean_indirect(|_| {});
    eprintln!("mean indirect: isotropic {iso}, anisotropic {aniso}");
    // An isotropic voxel averages a wall's lit face with its unlit views at the levels above
    // the finest, where one voxel holds one face. Cones whose samples span the whole footprint
    // read those levels and saw 0.58 of the light; cones tracing one quarter of it
    // (shared/cone.wgsl) read the finest levels more, and see 0.89 (measured; the isotropic
    // light rose by half, the anisotropic fell 8 %). A fetch from the wrong block would read
    // another direction's data or nothing: outside 0.8..0.96.
    let ratio = iso / aniso;
    assert!(
        (0.8..0.96).contains(&ratio),
        "isotropic / anisotropic {ratio}"
    );
}

#[test]
fn two_gather_axes_keep_the_indirect_light() {
    let l3 = cornell_mean_indirect(|s| s.gather_axes = 3);
    let l2 = cornell_mean_indirect(|s| s.gather_axes = 2);
    eprintln!("mean indirect: 3 axes {l3}, 2 axes {l2}");
    // Dropping the axis of least weight (at most a third) moves the mean by about 1 % (the
    // furnace after one bounce: 1.496 with three, 1.490 with two); a wrong block or weight
    // (another direction's data, weights not renormalised) moves it by tens of per cent.
    assert!(rel(l2, l3) < 0.03, "2 axes {l2} vs 3 axes {l3}");
    assert_ne!(l2, l3, "the two-axis pipeline was not used");
}

#[test]
fn a_metal_floor_mirrors_the_red_wall_by_its_glossy_cone() {
    // A metal floor has no diffuse reflection: all its indirect light comes from the glossy
    // cone, drawn from the lobe (compiled into the gather only for scenes with a specular
    // lobe somewhere; the Cornell box has none).
    let scene = crate::reference::metal_floor_cornell(0.3);
    let cam = scene.cameras[0].clone();
    let indirect = |scene: &Scene| {
        let out = render(scene, vct(ViewMode::Indirect, 32, 1), &cam, 32, 32);
        // The floor strip beside the red wall (left), in the lower part of the image.
        (mean(&out, 3, 27, 7, 30, 0), mean(&out, 3, 27, 7, 30, 1))
    };
    let (metal_r, metal_g) = indirect(&scene);
    let (diffuse_r, _) = indirect(&builtin::cornell_box());
    // The path tracer's indirect light on the same strip: one bounce less direct light.
    use crate::reference::{opts, trace_with};
    let options = vct(ViewMode::Final, 32, 1).options;
    let plain = clamped(&cam);
    let one = trace_with(
        &scene,
        &options,
        &plain,
        32,
        32,
        opts(512, voxgi::Bounces::One),
    );
    let direct = trace_with(
        &scene,
        &options,
        &plain,
        32,
        32,
        opts(512, voxgi::Bounces::DirectOnly),
    );
    let (pt_r, pt_g) = (
        mean(&one, 3, 27, 7, 30, 0) - mean(&direct, 3, 27, 7, 30, 0),
        mean(&one, 3, 27, 7, 30, 1) - mean(&direct, 3, 27, 7, 30, 1),
    );
    eprintln!(
        "floor by the red wall: metal r {metal_r} g {metal_g} (path tracer r {pt_r} g {pt_g}), \
         white diffuse r {diffuse_r}"
    );
    // The strip mirrors the directly lit red wall: measured r/g 4.4 in one frame (the path
    // tracer's 5.2; the wall's own reflectance ratio is 9.7; the white diffuse floor, which
    // gathers the whole room, is far less red), and its red 1.05 of the path tracer's (one
    // frame of sixteen lobe directions per 4x4 block, on 32³ voxels). Without the glossy cone
    // it is black; with the lobe's weight lost, or one cone along the wrong direction, its red
    // leaves [0.6, 1.8] of the truth or its ratio falls towards the room's.
    assert!(
        metal_r > 2.0 * metal_g,
        "mirror not red: r {metal_r} g {metal_g}"
    );
    assert!(
        (0.6..1.8).contains(&(metal_r / pt_r)),
        "metal r {metal_r} vs the path tracer's {pt_r} (white diffuse r {diffuse_r})"
    );
}

#[test]
fn cone_shadows_agree_with_the_shadow_map() {
    let scene = builtin::cornell_box();
    let cam = scene.cameras[0].clone();
    let (w, h) = (64, 64);
    let direct = |cone_shadows: bool| {
        let mut s = vct(ViewMode::Direct, 64, 1);
        s.options.cone_shadows = cone_shadows;
        s.options.half_resolution = true;
        render(&scene, s, &cam, w, h)
    };
    let (pcss, cone) = (direct(false), direct(true));
    // The floor in the short block's shadow (right of it), and the open floor in front.
    let lum = |o: &voxgi::RenderOutput, r: (u32, u32, u32, u32)| {
        (0..3).map(|c| mean(o, r.0, r.1, r.2, r.3, c)).sum::<f32>() / 3.0
    };
    let shadow = (50, 57, 56, 61);
    let open = (24, 60, 34, 63);
    let (ps, cs) = (lum(&pcss, shadow), lum(&cone, shadow));
    let (po, co) = (lum(&pcss, open), lum(&cone, open));
    eprintln!("shadowed floor: PCSS {ps:.4}, cone {cs:.4}; open floor: PCSS {po:.4}, cone {co:.4}");
    let mut sq = 0.0;
    let mut ref_sq = 0.0;
    for y in 0..h {
        for x in 0..w {
            for c in 0..3 {
                let (a, b) = (pcss.radiance(x, y)[c], cone.radiance(x, y)[c]);
                sq += (a - b) * (a - b);
                ref_sq += a * a;
            }
        }
    }
    let rms = (sq / ref_sq).sqrt();
    eprintln!("cone vs PCSS direct light: relative RMS difference {rms:.4}");
    // Measured (64³, half resolution): shadowed floor 0.008 against PCSS's 0.0004 (the cone's
    // umbra is lighter: it sees the block at a coarse level), open floor 0.054 against 0.063
    // (the cone's samples near the floor and the ceiling add some opacity), 0.14 overall. The
    // bounds keep a shadow that is clearly there and an open floor within 25 %: no shadow,
    // a black image or a misplaced one fails.
    assert!(
        cs < 0.25 * po,
        "no shadow beside the short block: {cs} vs open {po}"
    );
    assert!(rel(co, po) < 0.25, "open floor: cone {co}, PCSS {po}");
    assert!(rms < 0.25, "cone vs PCSS: relative RMS difference {rms}");
}

#[test]
fn renders_are_identical_run_to_run() {
    // Voxel slots come from atomics in whatever order the GPU runs its threads; nothing the
    // image depends on may follow that order (the voxel bounce once rotated its cones by slot).
    let scene = builtin::cornell_box();
    let cam = scene.cameras[0].clone();
    let images: Vec<Vec<f32>> = (0..3)
        .map(|_| render(&scene, vct(ViewMode::Final, 64, 3), &cam, 48, 48).hdr)
        .collect();
    for (i, img) in images.iter().enumerate().skip(1) {
        let differing = img.iter().zip(&images[0]).filter(|(a, b)| a != b).count();
        // Exact: the same program on the same device must give the same bits.
        assert_eq!(
            differing, 0,
            "render {i}: {differing} values differ from render 0"
        );
    }
}

#[test]
fn half_resolution_gather_matches_full_and_keeps_edges() {
    let scene = builtin::cornell_box();
    let cam = scene.cameras[0].clone();
    let (w, h) = (64, 64);
    let indirect = |half_resolution: bool| {
        let mut s = vct(ViewMode::Indirect, 64, 1);
        s.options.half_resolution = half_resolution;
        render(&scene, s, &cam, w, h)
    };
    let (full, half) = (indirect(false), indirect(true));
    let lum = |o: &voxgi::RenderOutput, x: u32, y: u32| o.radiance(x, y).iter().sum::<f32>() / 3.0;
    // Edge pixels: the full-resolution indirect light jumps by more than half to a neighbour
    // (silhouettes, creases, the walls' colour boundaries).
    let is_edge = |o: &voxgi::RenderOutput, x: u32, y: u32| {
        let l = lum(o, x, y);
        [(1i32, 0i32), (-1, 0), (0, 1), (0, -1)]
            .iter()
            .any(|&(dx, dy)| {
                let n = lum(o, (x as i32 + dx) as u32, (y as i32 + dy) as u32);
                (n - l).abs() > 0.5 * n.max(l).max(1e-4)
            })
    };
    let (mut sq, mut ref_sq, mut edge_sq, mut edge_ref_sq) = (0.0, 0.0, 0.0, 0.0);
    let (mut edges, mut half_edges) = (0, 0);
    let (mut sum_full, mut sum_half) = (0.0, 0.0);
    for y in 1..h - 1 {
        for x in 1..w - 1 {
            let edge = is_edge(&full, x, y);
            edges += edge as u32;
            half_edges += is_edge(&half, x, y) as u32;
            for c in 0..3 {
                let (a, b) = (full.radiance(x, y)[c], half.radiance(x, y)[c]);
                sum_full += a;
                sum_half += b;
                sq += (a - b) * (a - b);
                ref_sq += a * a;
                if edge {
                    edge_sq += (a - b) * (a - b);
                    edge_ref_sq += a * a;
                }
            }
        }
    }
    let (rms, edge_rms) = ((sq / ref_sq).sqrt(), (edge_sq / edge_ref_sq).sqrt());
    let ratio = sum_half / sum_full;
    eprintln!(
        "half vs full resolution indirect: mean ratio {ratio:.4}, relative RMS {rms:.4}, \
         on {edges} edge pixels {edge_rms:.4}; {half_edges} edge pixels at half resolution"
    );
    // Measured at 64x64: ratio 1.035, RMS 0.25, edge RMS 0.39 (both resolutions reconstruct
    // sixteen turns of the bundle from windows of different sizes, so they differ in noise;
    // with each cone tracing one quarter of its footprint, each quarter in four of the
    // sixteen pixels, more than the 0.19 and 0.30 of whole footprints), 568 edge pixels at
    // full and 643 at half resolution (1.042, 0.27, 635 and 673 while the upsample's window
    // lay half a sample off centre). The ratio read 0.99 before each parity of the Bayer ranks drew
    // its own Hammersley set of turns, and 1.028 over 8-frame stills, so it is not noise: the
    // half-resolution gather gathers 3-4 % more, not yet explained. Without edge weights,
    // light bleeds across silhouettes and blurs the jumps away: 293 and 244 edge pixels.
    // Bounds: the mean within 6 %, the RMS within 0.33, the edges within 0.45, and at least
    // 400 edge pixels each.
    assert!(
        edges >= 400 && half_edges >= 400,
        "edges blurred: {edges} edge pixels at full resolution, {half_edges} at half"
    );
    assert!(rel(ratio, 1.0) < 0.06, "half/full mean ratio {ratio}");
    assert!(rms < 0.33, "half vs full relative RMS {rms}");
    assert!(
        edge_rms < 0.45,
        "half vs full on edges: relative RMS {edge_rms}"
    );
}

#[test]
fn a_glossy_floor_in_a_glowing_box_reflects_its_directional_albedo() {
    // A closed metal box whose every wall emits radiance 1 (the furnace, made glossy): the
    // metal reflects nothing diffusely, so the floor's indirect light is all the glossy
    // cone's, and whatever direction the cone takes it sees radiance 1. The floor then reflects
    // the lobe's directional albedo: f0 a + f90 b of `brdf::specular_albedo`.
    let f0 = 0.8f32;
    for roughness in [0.2f32, 0.5] {
        let mut scene = builtin::closed_box(f0, 1.0);
        for m in &mut scene.materials {
            m.metallic = 1.0;
            m.roughness = roughness;
        }
        // A narrow view of the floor's centre at 60 degrees from its normal: n.v = 0.5.
        let theta = 60f32.to_radians();
        let eye = Vec3::new(0.0, 0.5 * theta.cos(), 0.5 * theta.sin());
        let cam = Camera::look_at(eye, Vec3::ZERO, 2.0);
        let out = render(&scene, vct(ViewMode::Indirect, 32, 1), &cam, 8, 8);
        let got = out.mean_radiance()[0];
        let [a, b] = voxgi::brdf::specular_albedo(0.5, roughness as f64, 64);
        let want = (f0 as f64 * a + b) as f32;
        eprintln!("glossy furnace, roughness {roughness}: {got} (directional albedo {want})");
        // A little low: the table's interpolation and fp16 storage, the emitters' 0.999
        // opacity cap, and the wide lobe's samples where the walls meet, which pass a few per
        // cent of their footprint as the closed box's cones do (probe.rs; the chains average
        // coverage across a cone). 4 % holds that (docs/QUALITY.md has the figures); Karis's
        // analytic fit, used before the table, is 10 % and 16 % low here.
        assert!(
            rel(got, want) < 0.04,
            "roughness {roughness}: {got} vs {want}"
        );
    }
}

/// The two structures render the same pictures: the octree samples the dense volume's function
/// (`octree_samples_what_the_dense_volume_samples`), so whole frames of the Cornell box and the
/// two rooms (final image, two bounces) agree at 64³ and 128³.
#[test]
fn octree_and_dense_renders_agree() {
    let rooms = one_voxel_wall_rooms(64);
    let rooms_cam = Camera::look_at(Vec3::new(-0.9, 0.5, 0.9), Vec3::new(-0.1, 0.3, 0.1), 70.0);
    let cornell = builtin::cornell_box();
    let cases = [
        ("Cornell box", &cornell, cornell.cameras[0].clone()),
        ("two rooms", &rooms, rooms_cam),
    ];
    for (name, scene, cam) in cases {
        for res in [64, 128] {
            let (w, h) = (64, 64);
            let params = voxgi::FrameParams::new(cam.clone());
            let options = RendererOptions {
                voxel_resolution: res,
                ..RendererOptions::default()
            };
            let (c, worst) = octree_against_dense(scene, &options, &params, w, h);
            eprintln!("{name} at {res}³: octree vs dense {c:?}, largest difference {worst}/255");
            // The structures differ only by the atlases' filtering rounding (1e-5 in opacity
            // per sample) and the dense volume's z clamp at its chains' edges. Measured: at
            // most 2/255 in any channel, and a mean FLIP of 0.008 (64³) and 0.012 (128³) on
            // the Cornell box, which is what one-code-value differences in a seventh of the
            // channels give. 4/255 and 0.02 allow other drivers; a lost bounce costs 0.1 FLIP.
            assert!(worst <= 4, "{name} at {res}³: {worst}/255 apart");
            assert!(
                c.flip_mean < 0.02,
                "{name} at {res}³: mean FLIP {}",
                c.flip_mean
            );
        }
    }
}

/// `scene` from `params` at `w`×`h` with `options` on the dense volume and on the octree: their
/// LDR comparison and their largest channel difference (code values).
pub(crate) fn octree_against_dense(
    scene: &Scene,
    options: &RendererOptions,
    params: &voxgi::FrameParams,
    w: u32,
    h: u32,
) -> (voxgi::compare::Comparison, u8) {
    use voxgi::compare::{Image, compare};
    let on = |voxels| RendererOptions {
        voxels,
        ..options.clone()
    };
    let dense = render_with(scene, &on(VoxelKind::DENSE), params, w, h);
    let octree = render_with(scene, &on(VoxelKind::OCTREE), params, w, h);
    let c = compare(
        &Image::from_ldr_rgba8(w, h, &dense.ldr),
        &Image::from_ldr_rgba8(w, h, &octree.ldr),
    )
    .unwrap();
    (c, largest_difference(&dense.ldr, &octree.ldr))
}

/// The Cornell box (default options: 128³, two bounces; 64×64) with the options `change` makes,
/// against the path tracer at 128 spp, beside the unchanged options, on each structure: prints
/// both's mean LDR-FLIP and region ratios (reference.rs's regions), and asserts the changed
/// renders within the gather's bounds there (each region within 12 %, the ceiling's known
/// error within 50 %; FLIP below 0.17, the gather's 0.16 with room for other drivers). Returns
/// the changed renders, in `VoxelKind::ALL`'s order.
pub(crate) fn cornell_variant_against_the_path_tracer(
    what: &str,
    change: impl Fn(&mut RendererOptions),
) -> Vec<voxgi::RenderOutput> {
    use crate::point_gi::CORNELL_REGIONS;
    use crate::reference::{cornell_reference, region};
    use voxgi::compare::{Image, compare};
    let scene = builtin::cornell_box();
    let settings = RendererOptions::default();
    let params = voxgi::FrameParams::new(scene.cameras[0].clone());
    let pt = cornell_reference();
    let (w, h) = (pt.width, pt.height);
    let ldr = |o: &voxgi::RenderOutput| Image::from_ldr_rgba8(w, h, &o.ldr);
    let mut renders = Vec::new();
    // The plain gather's own figures are `cone_traced_cornell_box_agrees_with_the_path_tracer`'s.
    for &kind in VoxelKind::ALL {
        let mut changed = RendererOptions {
            voxels: kind,
            ..settings.clone()
        };
        change(&mut changed);
        let b = render_with(&scene, &changed, &params, w, h);
        let cb = compare(&ldr(pt), &ldr(&b)).unwrap();
        eprintln!(
            "Cornell box ({kind:?}): mean FLIP against the path tracer {:.3} with {what}",
            cb.flip_mean
        );
        for (name, r) in CORNELL_REGIONS {
            let got = region(&b, r.0, r.1, r.2, r.3) / region(pt, r.0, r.1, r.2, r.3);
            eprintln!("{name} ({kind:?}): {what} / path tracer {got:.3}");
            let tolerance = if name == "ceiling" { 0.5 } else { 0.12 };
            assert!(
                (got - 1.0).abs() < tolerance,
                "{kind:?}, {name}: {what} {got} of the path tracer"
            );
        }
        assert!(cb.flip_mean < 0.17, "{kind:?}: mean FLIP {}", cb.flip_mean);
        renders.push(b);
    }
    renders
}
