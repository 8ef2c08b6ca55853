//! Direct light against closed forms: the rasterizer must reproduce the radiometry exactly,
//! because the cone tracer and the path tracer are compared against it.

use crate::common::*;
use std::f32::consts::PI;
use voxgi::scene::glam::{Mat4, Vec3};
use voxgi::scene::{AreaShape, Camera, Light, LightKind, Material};

const W: u32 = 64;
const H: u32 = 64;
const ALBEDO: f32 = 0.5;

fn light(kind: LightKind, intensity: f32, position: Vec3, direction: Vec3) -> Light {
    Light {
        name: "test".into(),
        kind,
        color: [1.0; 3],
        intensity,
        position,
        direction: direction.normalize(),
        range: None,
        cast_shadows: true,
    }
}

fn overhead_camera() -> Camera {
    Camera::look_at(Vec3::new(0.0, 2.5, 0.0), Vec3::ZERO, 70.0)
}

// Five probes: the centre and four points spread over the image.
const PROBES: [(u32, u32); 5] = [(32, 32), (10, 12), (52, 9), (14, 50), (55, 54)];

#[test]
fn lambertian_plane_under_a_point_light() {
    let mut scene = plane_scene(ALBEDO);
    let lp = Vec3::new(0.3, 1.0, -0.2);
    let intensity = 2.0;
    scene
        .lights
        .push(light(LightKind::Point, intensity, lp, Vec3::NEG_Y));
    let cam = overhead_camera();
    let out = render(&scene, measuring(), &cam, W, H);
    for (x, y) in PROBES {
        let p = pixel_on_ground(&cam, W, H, x, y);
        let to = lp - p;
        let cos = to.normalize().y;
        let expected = ALBEDO / PI * intensity * cos / to.length_squared();
        let got = out.radiance(x, y)[0];
        // 2 %: the G-buffer stores albedo and normals as fp16 (relative error ~1e-3) and the
        // pixel's surface point is interpolated in fp32; anything larger is a real error.
        assert!(
            rel(got, expected) < 0.02,
            "pixel ({x},{y}) at {p}: got {got}, expected {expected}"
        );
    }
}

#[test]
fn lambertian_plane_under_a_sun() {
    let mut scene = plane_scene(ALBEDO);
    let dir = Vec3::new(-0.3, -1.0, -0.2).normalize();
    let irradiance = 2.0;
    scene
        .lights
        .push(light(LightKind::Directional, irradiance, Vec3::ZERO, dir));
    let cam = overhead_camera();
    let out = render(&scene, measuring(), &cam, W, H);
    let expected = ALBEDO / PI * irradiance * (-dir).dot(Vec3::Y);
    for (x, y) in PROBES {
        let got = out.radiance(x, y)[0];
        // 1 %: the radiance is constant over the plane; only fp16 storage errors remain.
        assert!(
            rel(got, expected) < 0.01,
            "pixel ({x},{y}): got {got}, expected {expected}"
        );
    }
}

#[test]
fn spot_light_cone_falloff() {
    let mut scene = plane_scene(ALBEDO);
    let lp = Vec3::new(0.0, 1.0, 0.0);
    let (inner, outer) = (20f32.to_radians(), 30f32.to_radians());
    let intensity = 3.0;
    scene.lights.push(light(
        LightKind::Spot {
            inner_angle: inner,
            outer_angle: outer,
        },
        intensity,
        lp,
        Vec3::NEG_Y,
    ));
    let cam = Camera::look_at(Vec3::new(0.0, 2.0, 0.0), Vec3::ZERO, 60.0);
    let (w, h) = (128, 128);
    let out = render(&scene, measuring(), &cam, w, h);
    // The documented falloff: squared linear ramp in cos between the outer and inner angles.
    let falloff = |a: f32| {
        ((a.cos() - outer.cos()) / (inner.cos() - outer.cos()))
            .clamp(0.0, 1.0)
            .powi(2)
    };
    for target_deg in [10f32, 25.0, 35.0] {
        // The pixel on the centre row whose ground point is nearest the target angle.
        let y = h / 2;
        let (x, p) = (0..w)
            .map(|x| (x, pixel_on_ground(&cam, w, h, x, y)))
            .min_by(|a, b| {
                let ang = |p: Vec3| (p - lp).normalize().dot(Vec3::NEG_Y).acos().to_degrees();
                (ang(a.1) - target_deg)
                    .abs()
                    .total_cmp(&(ang(b.1) - target_deg).abs())
            })
            .unwrap();
        let to = lp - p;
        let angle = (-to.normalize()).dot(Vec3::NEG_Y).acos();
        let expected =
            ALBEDO / PI * intensity * falloff(angle) * to.normalize().y / to.length_squared();
        let got = out.radiance(x, y)[0];
        if expected == 0.0 {
            // Outside the cone nothing at all may arrive.
            assert!(
                got < 1e-6,
                "{target_deg}° ({:.2}°): got {got}, expected 0",
                angle.to_degrees()
            );
        } else {
            // 2 %: as for the point light; the falloff itself is evaluated exactly.
            assert!(
                rel(got, expected) < 0.02,
                "{target_deg}° ({:.2}°): got {got}, expected {expected}",
                angle.to_degrees()
            );
        }
    }
}

#[test]
fn occluder_casts_a_shadow_and_nothing_else() {
    let lp = Vec3::new(0.0, 1.0, 0.0);
    let mut open = plane_scene(ALBEDO);
    open.lights
        .push(light(LightKind::Point, 2.0, lp, Vec3::NEG_Y));
    let mut blocked = open.clone();
    // A 0.2 m square halfway up: its umbra on the ground is the 0.4 m square around the origin.
    blocked.add_mesh(
        quad_mesh("occluder", Vec3::new(0.0, 0.5, 0.0), 0.2),
        Material::diffuse("occluder", [0.5; 3]),
        Mat4::IDENTITY,
    );
    let cam = Camera::look_at(Vec3::new(0.0, 2.5, 0.001), Vec3::ZERO, 60.0);
    let (w, h) = (96, 96);
    let a = render(&open, measuring(), &cam, w, h);
    let b = render(&blocked, measuring(), &cam, w, h);
    // The occluder itself covers the centre of the image; find ground pixels in the umbra that
    // the camera still sees: none, since the occluder hides exactly them from above. So look
    // from the side instead for the umbra, and check the ground far outside it here.
    for (x, y) in [(5u32, 5u32), (90, 8), (8, 88)] {
        let p = pixel_on_ground(&cam, w, h, x, y);
        assert!(
            p.x.abs() > 0.45 || p.z.abs() > 0.45,
            "probe {p} must be outside the penumbra"
        );
        let (ra, rb) = (a.radiance(x, y)[0], b.radiance(x, y)[0]);
        // Outside the penumbra the occluder must not darken the ground at all (1 %: fp16).
        assert!(
            rel(rb, ra) < 0.01,
            "lit pixel ({x},{y}) at {p}: {rb} vs unshadowed {ra}"
        );
    }
    let side = Camera::look_at(Vec3::new(1.2, 0.35, 0.0), Vec3::new(0.0, 0.0, 0.0), 50.0);
    let a = render(&open, measuring(), &side, w, h);
    let b = render(&blocked, measuring(), &side, w, h);
    let mut checked = 0;
    for y in 0..h {
        for x in 0..w {
            let d = pixel_ray(&side, w, h, x, y);
            if d.y >= -1e-3 {
                continue;
            }
            let p = pixel_on_ground(&side, w, h, x, y);
            // Deep inside the umbra (half-size 0.2 m, kept 0.05 m away from its edge).
            if p.x.abs() < 0.15 && p.z.abs() < 0.15 {
                // Also make sure the occluder does not hide this ground point from the camera.
                let seg = p - side.position;
                let t = (0.5 - side.position.y) / seg.y;
                let q = side.position + seg * t;
                if t > 0.0 && t < 1.0 && q.x.abs() < 0.1 && q.z.abs() < 0.1 {
                    continue;
                }
                let (ra, rb) = (a.radiance(x, y)[0], b.radiance(x, y)[0]);
                assert!(ra > 0.0);
                assert!(
                    rb < 0.02 * ra,
                    "umbra pixel ({x},{y}) at {p}: {rb} vs unshadowed {ra}"
                );
                checked += 1;
            }
        }
    }
    assert!(checked >= 10, "only {checked} umbra pixels were visible");
}

#[test]
fn rectangular_area_light_irradiance() {
    let mut scene = plane_scene(ALBEDO);
    let (half_u, half_v) = (0.3f32, 0.2f32);
    let center = Vec3::new(0.1, 0.8, 0.0);
    let radiance = 1.5;
    scene.add_area_light(Light {
        name: "panel".into(),
        kind: LightKind::Area {
            shape: AreaShape::Rect {
                u: Vec3::X * half_u,
                v: Vec3::Z * half_v,
            },
        },
        color: [1.0; 3],
        intensity: radiance,
        position: center,
        direction: Vec3::NEG_Y,
        range: None,
        cast_shadows: true,
    });
    let cam = Camera::look_at(Vec3::new(0.0, 2.0, 2.2), Vec3::new(0.0, 0.0, -0.2), 60.0);
    let out = render(&scene, measuring(), &cam, W, H);
    // Irradiance by midpoint quadrature of L cos cos' / d^2 over the panel (400 x 400 cells:
    // relative error far below 1e-4 at these distances).
    let irradiance = |p: Vec3| {
        let n = 400;
        let mut e = 0.0f64;
        let da = (4.0 * half_u * half_v) as f64 / (n * n) as f64;
        for i in 0..n {
            for j in 0..n {
                let q = center
                    + Vec3::X * half_u * ((i as f32 + 0.5) / n as f32 * 2.0 - 1.0)
                    + Vec3::Z * half_v * ((j as f32 + 0.5) / n as f32 * 2.0 - 1.0);
                let d = q - p;
                let r2 = d.length_squared() as f64;
                let cos_r = (d.y as f64 / r2.sqrt()).max(0.0);
                e += radiance as f64 * cos_r * cos_r / r2 * da;
            }
        }
        e as f32
    };
    let mut probed = 0;
    for (x, y) in [(32u32, 40u32), (12, 50), (50, 50), (20, 30), (45, 34)] {
        let d = pixel_ray(&cam, W, H, x, y);
        // Skip pixels that see the panel itself.
        let t = (center.y - cam.position.y) / d.y;
        let q = cam.position + d * t;
        if (q.x - center.x).abs() < half_u && (q.z - center.z).abs() < half_v {
            continue;
        }
        let p = pixel_on_ground(&cam, W, H, x, y);
        let expected = ALBEDO / PI * irradiance(p);
        let got = out.radiance(x, y)[0];
        // 1 %: the polygon formula is exact for an unoccluded Lambertian receiver; fp16 albedo
        // and normals leave ~0.1 %.
        assert!(
            rel(got, expected) < 0.01,
            "pixel ({x},{y}) at {p}: got {got}, expected {expected}"
        );
        probed += 1;
    }
    assert!(probed >= 4);
}

#[test]
fn rendering_is_deterministic() {
    let scene = voxgi::scene::builtin::cornell_box();
    let cam = scene.cameras[0].clone();
    let a = render(&scene, measuring(), &cam, 48, 48);
    let b = render(&scene, measuring(), &cam, 48, 48);
    assert!(a.hdr == b.hdr, "two renders of the same frame differ");
}

#[test]
fn glossy_plane_reflects_area_lights_as_their_ggx_integral() {
    // A metal plane under a rectangle and under a disc: the specular reflection must be the
    // GGX lobe integrated over the light, for sharp and rough lobes alike.
    let (half_u, half_v, radius) = (0.3f32, 0.2f32, 0.25f32);
    let center = Vec3::new(0.1, 0.8, -0.6);
    let radiance = 1.5;
    let f0 = 0.8f32;
    let cam = Camera::look_at(Vec3::new(0.0, 1.2, 1.6), Vec3::new(0.0, 0.0, -0.2), 50.0);
    let mut worst = 0.0f32;
    for disc in [false, true] {
        for roughness in [0.2f32, 0.4, 0.7] {
            let mut scene = plane_scene(f0);
            scene.materials[0].metallic = 1.0;
            scene.materials[0].roughness = roughness;
            let shape = if disc {
                AreaShape::Disc { radius }
            } else {
                AreaShape::Rect {
                    u: Vec3::X * half_u,
                    v: Vec3::Z * half_v,
                }
            };
            scene.add_area_light(light(
                LightKind::Area { shape },
                radiance,
                center,
                Vec3::NEG_Y,
            ));
            let out = render(&scene, measuring(), &cam, W, H);
            // The GGX lobe (voxgi::brdf, Schlick's Fresnel with f90 = 1) times L cos over the
            // light, by midpoint quadrature over its bounding square (300 x 300 cells).
            let (ext_u, ext_v) = if disc {
                (radius, radius)
            } else {
                (half_u, half_v)
            };
            let reflected = |p: Vec3| {
                let a = voxgi::brdf::ggx_alpha(roughness as f64);
                let v = (cam.position - p).normalize();
                let n = 300;
                let da = (4.0 * ext_u * ext_v) as f64 / (n * n) as f64;
                let mut sum = 0.0f64;
                for i in 0..n {
                    for j in 0..n {
                        let (su, sv) = (
                            (i as f32 + 0.5) / n as f32 * 2.0 - 1.0,
                            (j as f32 + 0.5) / n as f32 * 2.0 - 1.0,
                        );
                        if disc && su * su + sv * sv > 1.0 {
                            continue;
                        }
                        let q = center + Vec3::X * ext_u * su + Vec3::Z * ext_v * sv;
                        let d = q - p;
                        let r2 = d.length_squared() as f64;
                        let l = d.normalize();
                        let h = (l + v).normalize();
                        let (nl, nv, nh, vh) =
                            (l.y as f64, v.y as f64, h.y as f64, v.dot(h) as f64);
                        let f = f0 as f64 + (1.0 - f0 as f64) * (1.0 - vh).powi(5);
                        let spec = voxgi::brdf::d_ggx(nh, a) * voxgi::brdf::v_smith(nv, nl, a) * f;
                        // cos at the receiver, cos at the light (its normal is -y), 1/d^2.
                        sum += spec * nl * nl / r2 * da;
                    }
                }
                (radiance as f64 * sum) as f32
            };
            for (x, y) in [(32u32, 40u32), (28, 46), (36, 36), (20, 44), (44, 44)] {
                let p = pixel_on_ground(&cam, W, H, x, y);
                let expected = reflected(p);
                let got = out.radiance(x, y)[0];
                eprintln!(
                    "{} roughness {roughness}, pixel ({x},{y}): got {got}, expected {expected}",
                    if disc { "disc" } else { "rect" }
                );
                worst = worst.max(rel(got, expected));
            }
        }
    }
    eprintln!("worst relative error {worst}");
    // Measured 8.2 % at worst (linearly transformed cosines fitted to this lobe, interpolated
    // over a 32 x 32 table in fp16; most pixels within 3 %). The representative-point
    // approximation used before was off by up to 67 % here. 12 % leaves room for other
    // drivers' filtering.
    assert!(worst < 0.12, "worst relative error {worst}");
}
