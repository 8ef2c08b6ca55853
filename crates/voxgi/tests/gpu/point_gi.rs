//! Point clouds as GI geometry: the splat pass against its CPU twin, and the invariants of
//! vct.rs on point-sampled versions of the same scenes (`pointcloud::sample_surfaces`), for
//! every voxel structure: points must block, reflect and emit light as the surfaces they
//! sample do.

use crate::common::*;
use crate::reference::{opts, region, trace_with};
use crate::vct::{
    FURNACE_CASES, ao_beside_a_wall, ao_of_an_open_plane, floor_beside_a_wall, furnace_series, on,
    one_voxel_wall_rooms, thin_wall_leak, vct,
};
use voxgi::compare::{Image, compare};
use voxgi::gpu::readback::read_buffer_copy;
use voxgi::scene::glam::{Mat4, Vec3};
use voxgi::scene::{Camera, Material, PointCloud, Scene, builtin, pointcloud};
use voxgi::voxel::{Grid, cpu};
use voxgi::{RendererOptions, ViewMode, VoxelKind};

/// The voxel size of `scene` at `res`³ (the grid the renderer will lay around it).
fn voxel_size(scene: &Scene, res: u32) -> f32 {
    let b = scene.bounds();
    Grid::around(b.min, b.max, res).voxel_size
}

/// `scene`'s surfaces as points `per_voxel` to a voxel edge at `res`³, on the same grid: two
/// more points mark the corners of the meshes' bounds (the lattice stops short of them), so the
/// renderer lays the grid it lays for the meshes and the two are compared voxel for voxel. Their
/// discs and regions are a tenth of a millimetre (two lone points would get discs as wide as
/// the distance between them).
pub(crate) fn as_points(scene: &Scene, res: u32, per_voxel: f32) -> Scene {
    let mut points = pointcloud::sample_surfaces(scene, voxel_size(scene, res) / per_voxel);
    let b = scene.bounds();
    points.point_clouds.push(PointCloud {
        name: "bounds".into(),
        positions: vec![b.min, b.max],
        colors: vec![[0.5; 3]; 2],
        normals: vec![Vec3::Y; 2],
        radii: vec![1e-4; 2],
        transform: Mat4::IDENTITY,
        ..Default::default()
    });
    assert_eq!(points.bounds().min, b.min);
    assert_eq!(points.bounds().max, b.max);
    points
}

/// Deterministic numbers in [0, 1) (xorshift).
fn rng(seed: u64) -> impl FnMut() -> f32 {
    let mut s = seed.max(1);
    move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 40) as f32 / (1u64 << 24) as f32
    }
}

#[test]
fn splat_matches_its_cpu_twin() {
    // Random points in a unit cube with regions from a hundredth of a voxel to three voxels,
    // some with none (0: a point alone); every region's fragments as the CPU makes them. The
    // normals are the six axes, which the GPU decodes exactly from their octahedral encoding,
    // so both shift the regions behind the points alike.
    let res = 32;
    let mut r = rng(11);
    let n = 3000;
    let mut pc = PointCloud {
        name: "random".into(),
        transform: Mat4::IDENTITY,
        ..Default::default()
    };
    for i in 0..n {
        pc.positions
            .push(Vec3::new(r(), r(), r()) * 0.98 + Vec3::splat(0.01));
        pc.colors.push([0.5; 3]);
        let axis = [
            Vec3::X,
            Vec3::NEG_X,
            Vec3::Y,
            Vec3::NEG_Y,
            Vec3::Z,
            Vec3::NEG_Z,
        ];
        pc.normals.push(axis[i % 6]);
        pc.radii.push(0.01);
        let voxel = 1.0 / 30.0;
        pc.regions.push(if i % 10 == 0 {
            0.0
        } else {
            voxel * 0.01 * 300f32.powf(r())
        });
    }
    // Corners of the cube, so the bounds are exactly the unit cube whatever the random points.
    for c in 0..8 {
        pc.positions.push(Vec3::new(
            (c & 1) as f32,
            ((c >> 1) & 1) as f32,
            (c >> 2) as f32,
        ));
        pc.colors.push([0.5; 3]);
        pc.normals.push(Vec3::Y);
        pc.radii.push(0.01);
        pc.regions.push(0.02);
    }
    let scene = Scene {
        point_clouds: vec![pc.clone()],
        ..Default::default()
    };
    let options = RendererOptions {
        voxel_resolution: res,
        bounces: 0,
        ..RendererOptions::default()
    };
    let mut renderer = renderer(&scene, &options);
    let params = voxgi::FrameParams::new(renderer.default_camera().clone());
    frame(&mut renderer, &params, 8, 8);
    let (device, queue) = (&ctx().device, &ctx().queue);
    let f = renderer.fragments();
    let grid = f.grids[0];
    let count = read_buffer_copy(device, queue, &f.count).expect("count");
    let count = bytemuck::cast_slice::<u8, u32>(&count)[0] as usize;
    let bytes = read_buffer_copy(device, queue, &f.buffer).expect("fragments");
    let words: &[u32] = bytemuck::cast_slice(&bytes);
    assert!(count * 5 <= words.len(), "the fragment buffer overflowed");
    let mut gpu: Vec<([u32; 3], u32)> = words
        .chunks_exact(5)
        .take(count)
        .map(|w| {
            assert_ne!(w[4] & 0x8000_0000, 0, "a point fragment without DENSITY");
            let c = w[0];
            (
                [c & 1023, (c >> 10) & 1023, (c >> 20) & 1023],
                w[4] & 0xffff,
            )
        })
        .collect();
    let mut want: Vec<([u32; 3], u32)> = pc
        .positions
        .iter()
        .zip(&pc.regions)
        .zip(&pc.normals)
        .enumerate()
        .flat_map(|(i, ((&p, &e), &n))| cpu::splat(&grid, i as u32, p, n, e))
        .filter(|f| f.weight > 0)
        .map(|f| (f.cell, f.weight))
        .collect();
    gpu.sort_unstable();
    want.sort_unstable();
    eprintln!(
        "splat: {} fragments on the GPU, {} on the CPU",
        gpu.len(),
        want.len()
    );
    assert!(want.len() > n, "too few fragments to test: {}", want.len());
    // Exact: both take the same integer steps from positions computed alike.
    assert_eq!(gpu.len(), want.len(), "fragment counts differ");
    let differ = gpu.iter().zip(&want).filter(|(a, b)| a != b).count();
    assert_eq!(differ, 0, "{differ} fragments differ from the CPU twin");
}

#[test]
fn points_of_an_open_plane_have_ao_one() {
    // The mesh plane's test and tolerance (vct.rs): the plane's voxels, opaque or split
    // between two layers, must not occlude the samples above them.
    ao_of_an_open_plane(&as_points(&plane_scene(0.5), 64, 2.0));
}

#[test]
fn points_beside_a_wall_have_the_meshes_ao() {
    let (mesh, cam) = floor_beside_a_wall();
    let scene = as_points(&mesh, 64, 2.0);
    for &kind in VoxelKind::ALL {
        // The closed form and the mesh's tolerance (vct.rs).
        ao_beside_a_wall(&scene, &cam, kind);
    }
}

#[test]
fn a_box_of_points_passes_the_furnace() {
    // The glowing white box with its walls as points that emit and reflect.
    let scene = as_points(&builtin::closed_box(0.5, 1.0), 64, 2.0);
    for &kind in VoxelKind::ALL {
        furnace_series(&scene, kind, &FURNACE_CASES);
    }
}

#[test]
fn a_wall_of_points_leaks_as_little_as_the_mesh_wall() {
    let res = 64;
    let scene = one_voxel_wall_rooms(res);
    let points = as_points(&scene, res, 2.0);
    for &kind in VoxelKind::ALL {
        let mesh = thin_wall_leak(&scene, kind, res);
        let pts = thin_wall_leak(&points, kind, res);
        eprintln!(
            "thin wall ({kind:?}): room B gets {:.3} % of room A's indirect light through the \
             mesh wall, {:.3} % through the wall of points",
            mesh * 100.0,
            pts * 100.0
        );
        // The bound: within one percentage point of the mesh wall.
        assert!(
            pts < mesh + 0.01,
            "{kind:?}: {:.3} % through points against {:.3} % through the mesh",
            pts * 100.0,
            mesh * 100.0
        );
    }
}

/// The Cornell box's regions away from the emitter (reference.rs): back wall, floor, the two
/// walls, ceiling.
/// A pixel rectangle: x0, y0, x1, y1.
pub(crate) type Rect = (u32, u32, u32, u32);

pub(crate) const CORNELL_REGIONS: [(&str, Rect); 5] = [
    ("back wall", (25, 20, 40, 35)),
    ("floor", (20, 56, 44, 62)),
    ("red wall", (2, 20, 8, 40)),
    ("green wall", (56, 20, 62, 40)),
    ("ceiling", (10, 1, 54, 4)),
];

#[test]
fn cornell_box_of_points_agrees_with_the_path_tracer() {
    let mesh = builtin::cornell_box();
    let res = 64;
    let points = as_points(&mesh, res, 2.0);
    let cam = mesh.cameras[0].clone();
    let (w, h) = (64, 64);
    let settings = RendererOptions {
        voxel_resolution: res,
        ..RendererOptions::default()
    };
    let aces = voxgi::FrameParams::new(cam.clone());
    let spp = opts(128, voxgi::Bounces::Exactly(2));
    let pt_mesh = trace_with(&mesh, &settings, &aces, w, h, spp);
    let pt_points = trace_with(&points, &settings, &aces, w, h, spp);
    // The path tracer's discs against its triangles: the same box.
    for (name, r) in CORNELL_REGIONS {
        let (a, b) = (
            region(&pt_mesh, r.0, r.1, r.2, r.3),
            region(&pt_points, r.0, r.1, r.2, r.3),
        );
        eprintln!(
            "{name}: path-traced mesh {a:.4}, path-traced points {b:.4}, ratio {:.3}",
            b / a
        );
        // Measured 1.004, 0.977, 1.045, 1.080 and 1.092 (the ceiling: 44 x 3 pixels of
        // bounced light, the noisiest region at 128 spp). The discs are the same surfaces but
        // for their overlapping edges at corners; a tracer that missed the discs would lose the
        // walls and their bleeding entirely.
        let tolerance = 0.12;
        assert!(
            (b / a - 1.0).abs() < tolerance,
            "{name}: discs {b} against triangles {a}"
        );
    }
    for &kind in VoxelKind::ALL {
        let settings = RendererOptions {
            voxels: kind,
            ..settings.clone()
        };
        let vct = render_with(&points, &settings, &aces, w, h);
        let vct_mesh = render_with(&mesh, &settings, &aces, w, h);
        let c = compare(
            &Image::from_ldr_rgba8(w, h, &pt_points.ldr),
            &Image::from_ldr_rgba8(w, h, &vct.ldr),
        )
        .unwrap();
        let cm = compare(
            &Image::from_ldr_rgba8(w, h, &pt_mesh.ldr),
            &Image::from_ldr_rgba8(w, h, &vct_mesh.ldr),
        )
        .unwrap();
        eprintln!(
            "Cornell box of points ({kind:?}, {res}³): mean FLIP {:.3} against the path-traced \
             points (the mesh: {:.3})",
            c.flip_mean, cm.flip_mean
        );
        for (name, r) in CORNELL_REGIONS {
            let (a, b) = (
                region(&pt_points, r.0, r.1, r.2, r.3),
                region(&vct, r.0, r.1, r.2, r.3),
            );
            let (am, bm) = (
                region(&pt_mesh, r.0, r.1, r.2, r.3),
                region(&vct_mesh, r.0, r.1, r.2, r.3),
            );
            eprintln!(
                "{name} ({kind:?}): cone-traced points / path-traced points {:.3}, mesh {:.3}",
                b / a,
                bm / am
            );
            // Measured (dense; the octree within 0.01): back wall 1.09, floor 1.08, red wall
            // 1.09, green wall 1.08, ceiling 1.18; the mesh against its own path tracing 1.07,
            // 1.07, 1.06, 1.06 and 1.24 (64³). Along fixed axes the walls read 1.02-1.09, the
            // quadrature's error offsetting the cones' own excess (`voxgi probe`,
            // docs/QUALITY.md). 13 % holds the walls with the 128-spp references' noise; a
            // lost bounce or the bleeding moves them by 20 % or more. 50 % for the ceiling.
            let tolerance = if name == "ceiling" { 0.5 } else { 0.13 };
            assert!(
                (b / a - 1.0).abs() < tolerance,
                "{kind:?}, {name}: {b} vs {a}"
            );
        }
        // Measured 0.187 (the mesh against its own path tracing: 0.167); 0.21 leaves room for
        // other drivers.
        assert!(c.flip_mean < 0.21, "{kind:?}: mean FLIP {}", c.flip_mean);
    }
}

#[test]
fn the_bunnys_vertices_bounce_light_as_its_mesh_does() {
    // The Stanford bunny on a floor under a spot light, once as its mesh and once as the
    // point cloud of the same file's vertices (their normals the mesh's): the same bounds, so
    // the same grid. The indirect light on the floor around it and on the bunny itself.
    let Some(path) = shared_scene("stanford_bunny/bun_zipper.ply") else {
        return;
    };
    let bunny = voxgi::scene::io::load(&path).expect("bunny");
    // A 3 m floor: the voxels (128³) are 2.4 cm, the bunny 30 of them across.
    let mut mesh = Scene::default();
    mesh.add_mesh(
        quad_mesh("floor", Vec3::ZERO, 3.0),
        Material::diffuse("floor", [0.5; 3]),
        Mat4::IDENTITY,
    );
    mesh.append(
        bunny,
        Mat4::from_scale(Vec3::splat(5.0)) * Mat4::from_translation(Vec3::new(0.0, -0.033, 0.0)),
        false,
    );
    mesh.lights.push(voxgi::scene::Light {
        name: "key".into(),
        kind: voxgi::scene::LightKind::Spot {
            inner_angle: 20f32.to_radians(),
            outer_angle: 30f32.to_radians(),
        },
        color: [1.0; 3],
        intensity: 12.0,
        position: Vec3::new(1.2, 1.8, 1.0),
        direction: (Vec3::new(0.0, 0.3, 0.0) - Vec3::new(1.2, 1.8, 1.0)).normalize(),
        range: None,
        cast_shadows: true,
    });
    let points = pointcloud::mesh_vertices(&mesh);
    // The floor stays a mesh in both.
    let mut points_scene = mesh.clone();
    points_scene.instances.truncate(1);
    points_scene.point_clouds = points
        .point_clouds
        .into_iter()
        .filter(|pc| pc.positions.len() > 4)
        .collect();
    assert_eq!(points_scene.point_clouds.len(), 1);
    let cam = Camera::look_at(Vec3::new(-0.3, 0.6, 1.9), Vec3::new(-0.1, 0.35, 0.0), 40.0);
    let (w, h) = (96, 64);
    for &kind in VoxelKind::ALL {
        let s = on(kind, vct(ViewMode::Indirect, 128, 2));
        let a = render(&mesh, s.clone(), &cam, w, h);
        let b = render(&points_scene, s, &cam, w, h);
        let c = compare(
            &Image::from_hdr_rgba(w, h, &a.hdr),
            &Image::from_hdr_rgba(w, h, &b.hdr),
        )
        .unwrap();
        eprintln!("bunny ({kind:?}): indirect light, points against mesh: {c:?}");
        if std::env::var_os("VOXGI_TEST_IMAGES").is_some() {
            a.save(std::path::Path::new("/tmp/bunny_mesh_ind.png"))
                .unwrap();
            b.save(std::path::Path::new("/tmp/bunny_points_ind.png"))
                .unwrap();
        }
        // Measured 0.108 (HDR-FLIP, both structures): the two differ where the vertices' discs
        // leave the silhouette ragged and where regions round the surface differently; a
        // points bunny that bounced or occluded nothing would differ by its whole shading.
        assert!(c.flip_mean < 0.13, "{kind:?}: HDR-FLIP {}", c.flip_mean);
        let regions = [
            ("whole", (0, 0, w, h)),
            ("floor", (0, 52, w, h)),
            ("bunny", (30, 14, 62, 44)),
        ];
        for (name, r) in regions {
            let (ra, rb) = (
                region(&a, r.0, r.1, r.2, r.3),
                region(&b, r.0, r.1, r.2, r.3),
            );
            eprintln!(
                "{name} ({kind:?}): mesh {ra:.4}, points {rb:.4}, ratio {:.3}",
                rb / ra
            );
        }
    }
}

/// A 30 cm square lamp 6 cm above a 4 m floor, facing down, emitting 8 W/(m² sr): a quad mesh,
/// or a grid of 30 x 30 emissive points 1 cm apart, each promoted to an area light when
/// `promote`.
pub(crate) fn lamp_over_a_floor(points: bool, promote: bool) -> Scene {
    let mut s = Scene::default();
    s.add_mesh(
        quad_mesh("floor", Vec3::ZERO, 4.0),
        Material::diffuse("floor", [0.6; 3]),
        Mat4::IDENTITY,
    );
    let (y, size, e) = (0.06, 0.3, [8.0; 3]);
    if points {
        let mut pc = PointCloud {
            name: "lamp".into(),
            transform: Mat4::IDENTITY,
            ..Default::default()
        };
        for i in 0..30 {
            for k in 0..30 {
                let at = |j: i32| (j as f32 + 0.5) * 0.01 - 0.5 * size;
                pc.positions.push(Vec3::new(at(i), y, at(k)));
                pc.normals.push(Vec3::NEG_Y);
                pc.colors.push([0.5; 3]);
                pc.emission.push(e);
            }
        }
        s.point_clouds.push(pc);
        if promote {
            voxgi::scene::io::emitters::promote_emissive_points(&mut s);
        }
    } else {
        let mut lamp = quad_mesh("lamp", Vec3::new(0.0, y, 0.0), size);
        // Clockwise seen from above: the quad faces down.
        lamp.indices = vec![0, 2, 1, 0, 3, 2];
        lamp.normals = vec![Vec3::NEG_Y; 4];
        let mut m = Material::diffuse("lamp", [0.5; 3]);
        m.emissive = e;
        s.add_mesh(lamp, m, Mat4::IDENTITY);
        if promote {
            voxgi::scene::io::emitters::promote_emissive_quads(&mut s);
        }
    }
    s
}

/// Mean radiance of the pixels whose view of the floor y = 0 lands where `on_floor` says.
fn floor_mean(out: &voxgi::RenderOutput, cam: &Camera, on_floor: impl Fn(Vec3) -> bool) -> f32 {
    plane_mean(out, cam, 0.0, on_floor)
}

/// Mean radiance of the pixels whose view of the plane y = `height` lands where `on_plane`
/// says.
fn plane_mean(
    out: &voxgi::RenderOutput,
    cam: &Camera,
    height: f32,
    on_plane: impl Fn(Vec3) -> bool,
) -> f32 {
    let (mut sum, mut n) = (0.0, 0);
    for y in 0..out.height {
        for x in 0..out.width {
            let d = pixel_ray(cam, out.width, out.height, x, y);
            let t = (height - cam.position.y) / d.y;
            if d.y >= -1e-3 || !on_plane(cam.position + d * t) {
                continue;
            }
            let r = out.radiance(x, y);
            sum += r[0] + r[1] + r[2];
            n += 3;
        }
    }
    assert!(n > 30, "too few pixels ({n}) to measure");
    sum / n as f32
}

#[test]
fn emissive_points_light_what_is_near_them_as_a_quad_lamp_does() {
    // The lamp hangs half a voxel (12.5 cm at 32³) above the floor: there the voxels alone
    // cannot carry its light (cones leave their own voxel before they look back at it). Flat
    // rectangles of emissive points, like emissive quads, become area lights whose light is
    // shaded per pixel and injected per voxel, and whose points are drawn but not voxelized.
    let points = lamp_over_a_floor(true, true);
    assert_eq!(points.lights.len(), 1);
    assert_eq!(points.point_clouds[0].light, Some(0));
    // 30 x 30 points 1 cm apart stand for exactly the 30 cm square.
    assert!((points.lights[0].area() - 0.09).abs() < 1e-5);
    let mesh = lamp_over_a_floor(false, true);
    let unpromoted = lamp_over_a_floor(true, false);
    let cam = Camera::look_at(Vec3::new(0.0, 0.5, 0.9), Vec3::new(0.0, 0.0, 0.1), 40.0);
    let (w, h) = (64, 48);
    let options = RendererOptions {
        default_light: false,
        voxel_resolution: 32,
        bounces: 1,
        ..RendererOptions::default()
    };
    let params = clamped(&cam);
    // In front of the lamp (its near field, unseen by the camera's rays past its edge) and
    // beyond, where its light is dimmer.
    let near = |p: Vec3| p.x.abs() < 0.15 && (0.16..0.26).contains(&p.z);
    let far = |p: Vec3| p.x.abs() < 0.3 && (0.3..0.5).contains(&p.z);
    let pt = trace_with(
        &points,
        &options,
        &params,
        w,
        h,
        opts(256, voxgi::Bounces::Exactly(1)),
    );
    let pt_mesh = trace_with(
        &mesh,
        &options,
        &params,
        w,
        h,
        opts(256, voxgi::Bounces::Exactly(1)),
    );
    for &kind in VoxelKind::ALL {
        let options = RendererOptions {
            voxels: kind,
            ..options.clone()
        };
        let vct = render_with(&points, &options, &params, w, h);
        let vct_mesh = render_with(&mesh, &options, &params, w, h);
        let vct_voxels = render_with(&unpromoted, &options, &params, w, h);
        if std::env::var_os("VOXGI_TEST_IMAGES").is_some() {
            for (name, out) in [("vct", &vct), ("mesh", &vct_mesh), ("voxels", &vct_voxels)] {
                out.save(std::path::Path::new(&format!("/tmp/lamp_{name}.png")))
                    .unwrap();
            }
            pt.save(std::path::Path::new("/tmp/lamp_pt.png")).unwrap();
        }
        for (band, on_floor) in [("near", &near as &dyn Fn(Vec3) -> bool), ("far", &far)] {
            let m = |out: &voxgi::RenderOutput| floor_mean(out, &cam, on_floor);
            let (truth, got, as_mesh, truth_mesh, voxels) =
                (m(&pt), m(&vct), m(&vct_mesh), m(&pt_mesh), m(&vct_voxels));
            eprintln!(
                "lamp ({kind:?}), floor {band}: path-traced points {truth:.4} (mesh {truth_mesh:.4}), \
                 cone-traced points {got:.4}, mesh {as_mesh:.4}, points in the voxels only {voxels:.4}"
            );
            // Measured (both structures): near, path-traced points 0.668 and mesh 0.661,
            // cone-traced 0.6575 for both; far 0.0219, 0.0218 and 0.0217. Points and quad give
            // the same light, so the renderer shades the floor identically (2 % is room for a
            // driver's rounding); the path tracer's discs and quad differ by its noise at 256
            // spp, and the renderer is within 2 % of it (5 % allowed for other drivers' noise).
            assert!(
                rel(truth, truth_mesh) < 0.05,
                "{band}: {truth} vs {truth_mesh}"
            );
            assert!(
                rel(got, as_mesh) < 0.02,
                "{kind:?} {band}: {got} vs {as_mesh}"
            );
            assert!(rel(got, truth) < 0.05, "{kind:?} {band}: {got} vs {truth}");
        }
        // An area light's surface emits on the light's side only, and its own light does not
        // reach it: seen from above, the lamp is dark (measured 0.0000, and the path tracer's
        // 0.0019 from light bounced round its edge) where a two-sided emitter, or one lit by
        // itself, would show up to 8.
        let top = |p: Vec3| p.x.abs() < 0.14 && p.z.abs() < 0.14;
        for (name, out) in [("points", &vct), ("mesh", &vct_mesh), ("path tracer", &pt)] {
            let m = plane_mean(out, &cam, 0.06, top);
            eprintln!("lamp ({kind:?}), its top, {name}: {m:.4}");
            assert!(m < 0.1, "{kind:?}: the lamp's top ({name}) shows {m}");
        }
        // Left in the voxels, the same points leave the near floor far darker than the truth
        // (measured 0.099 with the dense volume and the octree, 0.338 with the clipmap, of
        // the path tracer's 0.668): the case the promotion exists for. The bound, 0.6 of the
        // truth, fails a promotion that did nothing (the promoted lamp is within 2 %).
        let voxels = floor_mean(&vct_voxels, &cam, near);
        assert!(voxels < 0.6 * floor_mean(&pt, &cam, near), "{voxels}");
    }
}
