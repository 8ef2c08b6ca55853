//! Point clouds render as surfels: a dense flat grid of discs shades like a Lambertian plane,
//! with no holes, and clouds without normals or radii get estimated ones.

use crate::common::{ctx, frame, renderer};
use voxgi::scene::glam::{Mat4, Vec3};
use voxgi::scene::{Camera, Light, LightKind, PointCloud, Scene};
use voxgi::{FrameParams, RendererOptions};

const ALBEDO: f32 = 0.5;
const IRRADIANCE: f32 = 1.0;
const N: usize = 200;
const SIZE: f32 = 2.0;

/// `N` x `N` points over a `SIZE` x `SIZE` square in the y = 0 plane, centred on the origin.
fn grid(normals: bool, radii: bool) -> PointCloud {
    let spacing = SIZE / N as f32;
    let positions: Vec<Vec3> = (0..N * N)
        .map(|i| {
            let (x, z) = ((i % N) as f32 + 0.5, (i / N) as f32 + 0.5);
            Vec3::new(x * spacing - SIZE / 2.0, 0.0, z * spacing - SIZE / 2.0)
        })
        .collect();
    let count = positions.len();
    PointCloud {
        name: "grid".into(),
        positions,
        colors: vec![[ALBEDO; 3]; count],
        normals: if normals {
            vec![Vec3::Y; count]
        } else {
            vec![]
        },
        // Covering a square grid needs spacing / sqrt(2); a little more.
        radii: if radii {
            vec![spacing * 0.75; count]
        } else {
            vec![]
        },
        regions: vec![],
        emission: vec![],
        transform: Mat4::IDENTITY,
        dynamic: false,
        light: None,
    }
}

/// The grid under a sun of irradiance 1 from straight above, seen from above.
fn scene(pc: PointCloud) -> Scene {
    let mut scene = Scene {
        name: "point grid".into(),
        point_clouds: vec![pc],
        ..Default::default()
    };
    scene.lights.push(Light {
        name: "sun".into(),
        kind: LightKind::Directional,
        color: [1.0; 3],
        intensity: IRRADIANCE,
        position: Vec3::ZERO,
        direction: Vec3::NEG_Y,
        range: None,
        cast_shadows: true,
    });
    // 1.5 m above, 45° field of view: the image spans about 1.24 m of the 2 m grid.
    scene
        .cameras
        .push(Camera::look_at(Vec3::new(0.0, 1.5, 0.0), Vec3::ZERO, 45.0));
    scene
}

/// Renders at 64x64 and checks that every pixel of the central 32x32 has radiance
/// albedo / π × E (within 3%): the discs cover the plane, face the light, and do not shadow
/// each other.
fn check_lambertian_plane(pc: PointCloud) {
    let scene = scene(pc);
    let mut r = renderer(&scene, &RendererOptions::default());
    let cam = FrameParams::new(r.default_camera().clone());
    let out = frame(&mut r, &cam, 64, 64);
    let expected = ALBEDO / std::f32::consts::PI * IRRADIANCE;
    let mut worst = (0.0f32, 0, 0);
    for y in 16..48 {
        for x in 16..48 {
            let c = out.radiance(x, y);
            for v in c {
                let err = (v / expected - 1.0).abs();
                if err > worst.0 {
                    worst = (err, x, y);
                }
            }
        }
    }
    let (err, x, y) = worst;
    assert!(
        err <= 0.03,
        "pixel ({x}, {y}) has radiance {:?}, expected {expected} (error {:.1}%)",
        out.radiance(x, y),
        err * 100.0
    );
}

#[test]
fn flat_grid_shades_like_a_lambertian_plane() {
    check_lambertian_plane(grid(true, true));
}

#[test]
fn cloud_without_normals_or_radii_renders() {
    // Normals face the camera (the cloud's origin lies inside its bounds), radii from the
    // 8 nearest neighbours: the same plane, the same radiance.
    check_lambertian_plane(grid(false, false));
}

#[test]
fn points_only_scene_is_not_empty() {
    let empty = Scene::default();
    assert!(matches!(
        ctx().renderer(&empty, &RendererOptions::default()),
        Err(voxgi::Error::EmptyScene)
    ));
    // A cloud with no points next to a real one is skipped.
    let mut s = scene(grid(true, true));
    s.point_clouds.push(PointCloud {
        name: "nothing".into(),
        transform: Mat4::IDENTITY,
        ..Default::default()
    });
    let mut r = renderer(&s, &RendererOptions::default());
    let points = r
        .memory()
        .into_iter()
        .find(|(name, _)| *name == "points")
        .expect("points in the memory report")
        .1;
    assert_eq!(points, (N * N * 32) as u64);
    let cam = FrameParams::new(r.default_camera().clone());
    frame(&mut r, &cam, 16, 16);
}
