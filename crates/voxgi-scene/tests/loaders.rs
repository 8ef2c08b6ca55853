//! Loader tests: round trips with exact values, bad input, and (when present) the real files in
//! /work/shared/scenes. Every file a test needs is written to the temp directory by the test.

use std::path::{Path, PathBuf};
use voxgi_scene::glam::Vec3;
use voxgi_scene::io;

fn shared_scenes() -> Option<PathBuf> {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes");
    if p.is_dir() {
        Some(p)
    } else {
        println!("skipped: {} not found", p.display());
        None
    }
}

#[test]
fn conformance_with_real_files() {
    let Some(root) = shared_scenes() else { return };
    let load = |rel: &str| {
        let t = std::time::Instant::now();
        let s = io::load(&root.join(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"));
        println!("{rel}: {:.2?}", t.elapsed());
        s
    };
    // Triangle and point counts are exact: these are published numbers for the files.
    let sponza = load("sponza_dabrovic_geometry_only/sponza.obj");
    assert_eq!(sponza.triangle_count(), 66_454);
    let bunny = load("stanford_bunny/bun_zipper.ply");
    assert_eq!(bunny.triangle_count(), 69_451);
    let dragon = load("stanford_dragon_100k/dragon.ply");
    assert_eq!(dragon.triangle_count(), 100_000);
    // The file's normals are unit length and are kept (not recomputed): compare with the
    // computed ones, which differ somewhere on a 100k-triangle scan.
    let dm = &dragon.meshes[0];
    let computed = voxgi_scene::compute_normals(&dm.positions, &dm.indices);
    assert!(dm.normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-4));
    assert!(dm.normals.iter().zip(&computed).any(|(a, b)| a.dot(*b) < 0.999));
    let office = load("pointcloud_pcl_office1/office1_xyzrgb.ply");
    assert_eq!(office.point_count(), 254_456);
    assert!(office.point_clouds[0].normals.is_empty());

    let mcguire = load("cornell_box_mcguire/CornellBox-Original.obj");
    assert_eq!(mcguire.lights.len(), 1, "{:?}", mcguire.lights);
    let l = &mcguire.lights[0];
    // Exact: Ke 17 12 4 is copied, intensity 1.
    assert_eq!(l.radiometric(), Vec3::new(17.0, 12.0, 4.0));
    // Float noise only: the light's four vertices lie exactly at y = 1.98.
    assert!((l.direction - Vec3::NEG_Y).length() < 1e-5, "{}", l.direction);
    // 0.47 m x 0.38 m from the file's corner coordinates; 1e-4 for f32 rounding.
    assert!((l.area() - 0.47 * 0.38).abs() < 1e-4, "{}", l.area());
    let n_light_instances = mcguire.instances.iter().filter(|i| i.light.is_some()).count();
    assert_eq!(n_light_instances, 1);

    for m in [
        "back", "ceiling", "floor", "greenwall", "largebox", "luminaire", "redwall", "smallbox",
    ] {
        let s = load(&format!("cornell_box_mitsuba/meshes/cbox_{m}.obj"));
        assert!(s.triangle_count() >= 2, "{m}");
    }
}
