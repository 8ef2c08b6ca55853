//! Counting before building: where the scene's fragment estimate does not fit the device, the
//! renderer voxelizes and builds once while it is made. A resolution the device cannot hold is
//! then refused by `Renderer::new`, naming the limit, before any frame; one it can hold renders
//! exactly what a full rebuild renders.

use crate::common::*;
use voxgi::fragments::FRAGMENT_BYTES;
use voxgi::scene::glam::{Mat4, Vec3};
use voxgi::scene::{Camera, Material, PointCloud, Scene};
use voxgi::{FrameParams, RendererOptions, VoxelKind};

/// `n` unit squares stacked between y = 0 and 1: at resolution `r` each covers (r − 2)²
/// voxel columns (`Grid::around` leaves a voxel on each side), so it makes at least that many
/// fragments and occupies that many voxels.
fn stacked_squares(n: u32) -> Scene {
    let mut s = Scene::default();
    for i in 0..n {
        let y = (i as f32 + 0.5) / n as f32;
        s.add_mesh(
            quad_mesh(&format!("square {i}"), Vec3::new(0.0, y, 0.0), 1.0),
            Material::diffuse("grey", [0.5; 3]),
            Mat4::IDENTITY,
        );
    }
    s
}

/// At 1024³ (the octree's largest resolution) a scene with one fragment more than the
/// device's fragment buffer holds, and one with more occupied voxels than the octree's leaf
/// slots hold, are refused by `Renderer::new`, each naming what ran out and the limit. Before,
/// both failed only after the first frame's work (28 s for Sponza at 1024³ on lavapipe).
#[test]
fn an_impossible_resolution_is_refused_before_the_first_frame() {
    let ctx = ctx();
    let limits = ctx.device.limits();
    let binding = limits.max_storage_buffer_binding_size;
    let columns = 1022u64 * 1022;
    let options = RendererOptions {
        voxels: VoxelKind::OCTREE,
        voxel_resolution: 1024,
        bounces: 0,
        ..Default::default()
    };
    // The octree's largest per-slot buffer is the build's sums (`ACCUM_WORDS`), the fragments
    // take 20 bytes each.
    let fragments = binding / FRAGMENT_BYTES / columns + 1;
    let slots = binding / (voxgi::voxel::octree::ACCUM_WORDS * 4) / columns + 1;
    if fragments > 16 {
        eprintln!("skipped: this device's storage-buffer limit needs too large a scene");
        return;
    }
    let msg = ctx
        .renderer(&stacked_squares(fragments as u32), &options)
        .err()
        .expect("more fragments than the device holds")
        .to_string();
    assert!(
        msg.contains("at 1024³ voxels the scene makes")
            && msg.contains("voxel fragments")
            && msg.contains(&format!("storage-buffer limit of {} MiB", binding >> 20))
            && msg.contains("lower the voxel resolution"),
        "{msg}"
    );
    let msg = ctx
        .renderer(&stacked_squares(slots as u32), &options)
        .err()
        .expect("more occupied voxels than the octree's slots hold")
        .to_string();
    assert!(
        msg.contains("MiB of leaf slots")
            && msg.contains(&format!("storage-buffer limit ({} MiB)", binding >> 20))
            && msg.contains("lower the voxel resolution"),
        "{msg}"
    );
}

/// A renderer whose estimate was in doubt has counted and built before its first frame (the
/// counters are set before any frame); that first frame, which skips the static build, is the
/// image of a full rebuild to the byte, and the counts are the rebuild's, for each structure.
/// The scene: a cluster of points each spreading over 8 voxels, so the estimate (8 fragments
/// per point) exceeds the leaf slots the device holds while the real leaves are a few hundred.
#[test]
fn a_scene_counted_before_its_first_frame_renders_as_a_full_rebuild() {
    let ctx = ctx();
    let binding = ctx.device.limits().max_storage_buffer_binding_size;
    // Past the dense volume's 60 and the octree's build sums' 56 bytes per leaf
    // (`ACCUM_WORDS`), as 8 fragments a point.
    let per_leaf = 60.min(voxgi::voxel::octree::ACCUM_WORDS * 4);
    let n = (binding / per_leaf / 8 + 1) as usize;
    if n > 4_000_000 {
        eprintln!("skipped: this device's storage-buffer limit needs too large a cloud");
        return;
    }
    // A 1 m floor sets the volume: 64³ voxels of about 1.6 cm; the points fill a 10 cm cube
    // above it, each with a region of 2 cm (more than a voxel).
    let mut scene = Scene::default();
    scene.add_mesh(
        quad_mesh("floor", Vec3::ZERO, 1.0),
        Material::diffuse("floor", [0.7; 3]),
        Mat4::IDENTITY,
    );
    let side = (n as f64).cbrt().ceil() as usize;
    let positions: Vec<Vec3> = (0..n)
        .map(|i| {
            let (x, y, z) = (i % side, (i / side) % side, i / (side * side));
            Vec3::new(x as f32, y as f32, z as f32) * (0.1 / side as f32) + Vec3::new(0.0, 0.1, 0.0)
        })
        .collect();
    scene.point_clouds.push(PointCloud {
        name: "cluster".into(),
        colors: vec![[0.8, 0.3, 0.2]; n],
        normals: vec![Vec3::Y; n],
        radii: vec![0.002; n],
        regions: vec![0.02; n],
        emission: Vec::new(),
        transform: Mat4::IDENTITY,
        dynamic: false,
        light: None,
        positions,
    });
    let camera = Camera::look_at(Vec3::new(0.4, 0.5, 0.6), Vec3::new(0.05, 0.1, 0.05), 50.0);
    let params = FrameParams::new(camera);
    for voxels in [VoxelKind::DENSE, VoxelKind::OCTREE] {
        let options = RendererOptions {
            voxels,
            voxel_resolution: 64,
            temporal: false,
            ..Default::default()
        };
        let mut r = renderer(&scene, &options);
        let counted = r.voxel_counts().unwrap();
        // The floor's 62² voxels and the cluster's few hundred: far below the estimate.
        assert!(
            counted.fragments > 0 && counted.occupied > 0 && counted.occupied < 10_000,
            "{voxels:?}: counted before the first frame: {counted:?}"
        );
        let first = frame(&mut r, &params, 48, 32);
        r.invalidate();
        let rebuilt = frame(&mut r, &params, 48, 32);
        assert_eq!(r.voxel_counts().unwrap(), counted, "{voxels:?}");
        // The same passes over the same counts: equal to the bit, not within a tolerance.
        assert!(
            first.hdr == rebuilt.hdr,
            "{voxels:?}: the first frame differs from a full rebuild"
        );
    }
}
