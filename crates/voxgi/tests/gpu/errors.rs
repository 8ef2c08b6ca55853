//! Bad input to the renderer: a clear error, never a panic or a black image.

use crate::common::*;
use voxgi::scene::glam::Vec3;
use voxgi::scene::{Camera, Scene};
use voxgi::{Error, Renderer, Settings};

#[test]
fn empty_scene_is_an_error() {
    let err = Renderer::new(ctx(), &Scene::default(), Settings::default())
        .err()
        .expect("must fail");
    assert!(matches!(err, Error::EmptyScene), "{err}");
}

#[test]
fn absurd_settings_are_errors() {
    let scene = voxgi::scene::builtin::cornell_box();
    let cases: Vec<(&str, Settings)> = vec![
        (
            "shadow map 5 texels",
            Settings {
                shadow_map_size: 5,
                ..Default::default()
            },
        ),
        (
            "shadow map 100000",
            Settings {
                shadow_map_size: 100_000,
                ..Default::default()
            },
        ),
        (
            "exposure NaN",
            Settings {
                exposure: f32::NAN,
                ..Default::default()
            },
        ),
        (
            "exposure 1000",
            Settings {
                exposure: 1000.0,
                ..Default::default()
            },
        ),
        (
            "negative softness",
            Settings {
                shadow_softness: -1.0,
                ..Default::default()
            },
        ),
        (
            "infinite background",
            Settings {
                background: [f32::INFINITY, 0.0, 0.0],
                ..Default::default()
            },
        ),
        (
            "texture size 0",
            Settings {
                max_texture_size: 0,
                ..Default::default()
            },
        ),
        (
            "voxels 100",
            Settings {
                voxel_resolution: 100,
                ..Default::default()
            },
        ),
        (
            "voxels 1024",
            Settings {
                voxel_resolution: 1024,
                ..Default::default()
            },
        ),
        (
            "9 bounces",
            Settings {
                bounces: 9,
                ..Default::default()
            },
        ),
        (
            "AO radius 0",
            Settings {
                ao_radius: Some(0.0),
                ..Default::default()
            },
        ),
        (
            "4 gather axes",
            Settings {
                gather_axes: 4,
                ..Default::default()
            },
        ),
        (
            "step 0",
            Settings {
                step_factor: 0.0,
                ..Default::default()
            },
        ),
    ];
    for (what, s) in cases {
        match Renderer::new(ctx(), &scene, s) {
            Err(Error::Setting(msg)) => assert!(!msg.is_empty(), "{what}"),
            Err(e) => panic!("{what}: wrong error {e}"),
            Ok(_) => panic!("{what}: accepted"),
        }
    }
}

#[test]
fn absurd_sizes_and_cameras_are_errors() {
    let scene = voxgi::scene::builtin::cornell_box();
    let mut r = Renderer::new(ctx(), &scene, Settings::default()).expect("renderer");
    let cam = scene.cameras[0].clone();
    for (w, h) in [(0, 16), (16, 0), (100_000, 16)] {
        assert!(
            matches!(r.render(&cam, w, h), Err(Error::Setting(_))),
            "{w}x{h} accepted"
        );
    }
    let mut bad = cam.clone();
    bad.position = Vec3::new(f32::NAN, 0.0, 0.0);
    assert!(matches!(r.render(&bad, 16, 16), Err(Error::Setting(_))));
    // The renderer still works after refusing bad requests.
    let ok = r.render(&cam, 16, 16).expect("render after errors");
    assert!(ok.mean_radiance()[0] > 0.0);
}

#[test]
fn unlit_scene_gets_a_default_sun_instead_of_black() {
    let scene = plane_scene(0.5);
    let cam = Camera::look_at(Vec3::new(0.0, 3.0, 3.0), Vec3::ZERO, 45.0);
    let lit = render(&scene, Settings::default(), &cam, 32, 32);
    assert!(
        lit.mean_radiance()[0] > 0.05,
        "mean {:?}",
        lit.mean_radiance()
    );
    // And with the default light switched off the same scene is black, as asked.
    let dark = render(&scene, measuring(), &cam, 32, 32);
    assert_eq!(dark.mean_radiance(), [0.0; 3]);
}

#[test]
fn invalid_scene_data_is_an_error_not_a_panic() {
    let mut scene = plane_scene(0.5);
    scene.meshes[0].indices[1] = 999;
    let err = Renderer::new(ctx(), &scene, Settings::default())
        .err()
        .expect("must fail");
    assert!(err.to_string().contains("out of range"), "{err}");
}
