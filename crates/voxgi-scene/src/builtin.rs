//! Scenes that need no files: the Cornell box and the small procedural scenes that tests use.

use crate::{
    AreaShape, Camera, Light, LightKind, Material, Mesh, PointCloud, Result, Scene, SceneError,
};
use glam::{Mat4, Vec3};

/// Names accepted by [`by_name`], with a one-line description each.
pub const BUILTINS: &[(&str, &str)] = &[
    (
        "cornell-box",
        "the Cornell box from its published measurements, lit by its ceiling light",
    ),
    (
        "open-plane",
        "a 20 m grey plane under a sun: nothing occludes anything",
    ),
    (
        "closed-box",
        "a closed 1 m room whose walls emit and reflect (the furnace test)",
    ),
    (
        "two-rooms",
        "two rooms sharing a 1 cm wall, a point light in the left one",
    ),
    (
        "cube",
        "a 1 m white cube centred on the origin, no light: an object to include and move",
    ),
    (
        "point-cave",
        "a scanned-looking cave of 1.4 million points without normals (the thesis' cave's size), \
         two spot lights and an area light",
    ),
];

pub fn by_name(name: &str) -> Result<Scene> {
    match name {
        "cornell-box" => Ok(cornell_box()),
        "open-plane" => Ok(open_plane(0.5)),
        "closed-box" => Ok(closed_box(0.5, 0.5)),
        "two-rooms" => Ok(two_rooms(0.01)),
        "cube" => Ok(cube([0.8; 3])),
        "point-cave" => Ok(point_cave(POINT_CAVE_POINTS)),
        _ => Err(SceneError::UnknownBuiltin {
            name: name.into(),
            available: BUILTINS.iter().map(|b| b.0).collect::<Vec<_>>().join(", "),
        }),
    }
}

/// A list of flat quads sharing one material; each quad gets its own four vertices.
#[derive(Default)]
struct QuadList {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    indices: Vec<u32>,
}

impl QuadList {
    /// Adds the planar quad a-b-c-d, its normal turned to face `towards`.
    fn quad(&mut self, q: [Vec3; 4], towards: Vec3) {
        let mut n = (q[1] - q[0]).cross(q[2] - q[0]).normalize();
        let centre = (q[0] + q[1] + q[2] + q[3]) * 0.25;
        let flip = n.dot(towards - centre) < 0.0;
        if flip {
            n = -n;
        }
        let base = self.positions.len() as u32;
        self.positions.extend_from_slice(&q);
        self.normals.extend_from_slice(&[n; 4]);
        let idx = if flip {
            [0, 2, 1, 0, 3, 2]
        } else {
            [0, 1, 2, 0, 2, 3]
        };
        self.indices.extend(idx.iter().map(|i| base + i));
    }

    /// An extruded convex footprint from y = 0 to `height`: top and sides, normals outward.
    fn block(&mut self, top: [Vec3; 4], height: f32) {
        let inside = (top[0] + top[1] + top[2] + top[3]) * 0.25 - Vec3::Y * height * 0.5;
        let up = Vec3::Y * (height + 1.0);
        self.quad(top, inside + up);
        for i in 0..4 {
            let (a, b) = (top[i], top[(i + 1) % 4]);
            let (a0, b0) = (Vec3::new(a.x, 0.0, a.z), Vec3::new(b.x, 0.0, b.z));
            let mid = (a + b0) * 0.5;
            self.quad([a0, b0, b, a], mid + (mid - inside));
        }
    }

    /// An axis-aligned box seen from outside (all six faces, normals outward).
    fn cuboid(&mut self, min: Vec3, max: Vec3) {
        let c = (min + max) * 0.5;
        let p = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
        let (a, b) = (min, max);
        let faces = [
            [
                p(a.x, a.y, a.z),
                p(a.x, b.y, a.z),
                p(a.x, b.y, b.z),
                p(a.x, a.y, b.z),
            ],
            [
                p(b.x, a.y, a.z),
                p(b.x, b.y, a.z),
                p(b.x, b.y, b.z),
                p(b.x, a.y, b.z),
            ],
            [
                p(a.x, a.y, a.z),
                p(b.x, a.y, a.z),
                p(b.x, a.y, b.z),
                p(a.x, a.y, b.z),
            ],
            [
                p(a.x, b.y, a.z),
                p(b.x, b.y, a.z),
                p(b.x, b.y, b.z),
                p(a.x, b.y, b.z),
            ],
            [
                p(a.x, a.y, a.z),
                p(b.x, a.y, a.z),
                p(b.x, b.y, a.z),
                p(a.x, b.y, a.z),
            ],
            [
                p(a.x, a.y, b.z),
                p(b.x, a.y, b.z),
                p(b.x, b.y, b.z),
                p(a.x, b.y, b.z),
            ],
        ];
        for f in faces {
            let fc = (f[0] + f[2]) * 0.5;
            self.quad(f, fc + (fc - c));
        }
    }

    fn into_mesh(self, name: &str) -> Mesh {
        Mesh {
            name: name.into(),
            positions: self.positions,
            normals: self.normals,
            uvs: Vec::new(),
            indices: self.indices,
            material: 0,
        }
    }
}

/// Reflectances: RGB fits of the measured Cornell box spectra.
pub const CORNELL_WHITE: [f32; 3] = [0.725, 0.71, 0.68];
pub const CORNELL_RED: [f32; 3] = [0.63, 0.065, 0.05];
pub const CORNELL_GREEN: [f32; 3] = [0.14, 0.45, 0.091];
/// Radiance of the ceiling light, W/(m² sr).
pub const CORNELL_LIGHT: [f32; 3] = [17.0, 12.0, 4.0];

/// The Cornell box from the Cornell Program of Computer Graphics' published measurements
/// (coordinates in millimetres, converted to metres here). Seen from the standard camera the red
/// wall is on the left and the green wall on the right.
pub fn cornell_box() -> Scene {
    let mm = |x: f32, y: f32, z: f32| Vec3::new(x, y, z) * 0.001;
    let inside = mm(278.0, 274.4, 279.6);
    let mut scene = Scene {
        name: "cornell-box".into(),
        ..Default::default()
    };
    let add = |scene: &mut Scene, name: &str, rgb: [f32; 3], quads: QuadList| {
        scene.add_mesh(
            quads.into_mesh(name),
            Material::diffuse(name, rgb),
            Mat4::IDENTITY,
        );
    };

    let mut q = QuadList::default();
    q.quad(
        [
            mm(552.8, 0.0, 0.0),
            mm(0.0, 0.0, 0.0),
            mm(0.0, 0.0, 559.2),
            mm(549.6, 0.0, 559.2),
        ],
        inside,
    );
    add(&mut scene, "floor", CORNELL_WHITE, q);
    let mut q = QuadList::default();
    q.quad(
        [
            mm(556.0, 548.8, 0.0),
            mm(556.0, 548.8, 559.2),
            mm(0.0, 548.8, 559.2),
            mm(0.0, 548.8, 0.0),
        ],
        inside,
    );
    add(&mut scene, "ceiling", CORNELL_WHITE, q);
    let mut q = QuadList::default();
    q.quad(
        [
            mm(549.6, 0.0, 559.2),
            mm(0.0, 0.0, 559.2),
            mm(0.0, 548.8, 559.2),
            mm(556.0, 548.8, 559.2),
        ],
        inside,
    );
    add(&mut scene, "back wall", CORNELL_WHITE, q);
    let mut q = QuadList::default();
    q.quad(
        [
            mm(0.0, 0.0, 559.2),
            mm(0.0, 0.0, 0.0),
            mm(0.0, 548.8, 0.0),
            mm(0.0, 548.8, 559.2),
        ],
        inside,
    );
    add(&mut scene, "green wall", CORNELL_GREEN, q);
    let mut q = QuadList::default();
    q.quad(
        [
            mm(552.8, 0.0, 0.0),
            mm(549.6, 0.0, 559.2),
            mm(556.0, 548.8, 559.2),
            mm(556.0, 548.8, 0.0),
        ],
        inside,
    );
    add(&mut scene, "red wall", CORNELL_RED, q);
    let mut q = QuadList::default();
    q.block(
        [
            mm(130.0, 165.0, 65.0),
            mm(82.0, 165.0, 225.0),
            mm(240.0, 165.0, 272.0),
            mm(290.0, 165.0, 114.0),
        ],
        0.165,
    );
    add(&mut scene, "short block", CORNELL_WHITE, q);
    let mut q = QuadList::default();
    q.block(
        [
            mm(423.0, 330.0, 247.0),
            mm(265.0, 330.0, 296.0),
            mm(314.0, 330.0, 456.0),
            mm(472.0, 330.0, 406.0),
        ],
        0.330,
    );
    add(&mut scene, "tall block", CORNELL_WHITE, q);

    // The measured light is 130 x 105 mm, hung 0.5 mm below the ceiling so the two never overlap.
    scene.add_area_light(Light {
        name: "ceiling light".into(),
        kind: LightKind::Area {
            shape: AreaShape::Rect {
                u: mm(65.0, 0.0, 0.0),
                v: mm(0.0, 0.0, 52.5),
            },
        },
        color: CORNELL_LIGHT,
        intensity: 1.0,
        position: mm(278.0, 548.3, 279.5),
        direction: Vec3::NEG_Y,
        range: None,
        cast_shadows: true,
    });

    let mut cam = Camera::look_at(mm(278.0, 273.0, -800.0), mm(278.0, 273.0, -799.0), 39.3077);
    cam.name = "cornell".into();
    scene.cameras.push(cam);
    scene
}

/// A 20 m x 20 m plane at y = 0 with the given grey albedo, lit by a sun from straight above.
pub fn open_plane(albedo: f32) -> Scene {
    let mut scene = Scene {
        name: "open-plane".into(),
        ..Default::default()
    };
    let mut q = QuadList::default();
    let h = 10.0;
    q.quad(
        [
            Vec3::new(-h, 0.0, -h),
            Vec3::new(h, 0.0, -h),
            Vec3::new(h, 0.0, h),
            Vec3::new(-h, 0.0, h),
        ],
        Vec3::Y,
    );
    scene.add_mesh(
        q.into_mesh("plane"),
        Material::diffuse("plane", [albedo; 3]),
        Mat4::IDENTITY,
    );
    scene.lights.push(Light {
        name: "sun".into(),
        kind: LightKind::Directional,
        color: [1.0; 3],
        intensity: 1.0,
        position: Vec3::ZERO,
        direction: Vec3::NEG_Y,
        range: None,
        cast_shadows: true,
    });
    let mut cam = Camera::look_at(Vec3::new(0.0, 3.0, 6.0), Vec3::ZERO, 45.0);
    cam.name = "overview".into();
    scene.cameras.push(cam);
    scene
}

/// A closed cube room, 1 m on a side centred at (0, 0.5, 0), whose inward-facing walls have
/// Lambertian albedo `albedo` and emit radiance `emission`: the white furnace. With k bounces the
/// radiance everywhere is emission * (1 + albedo + ... + albedo^k).
pub fn closed_box(albedo: f32, emission: f32) -> Scene {
    let mut scene = Scene {
        name: "closed-box".into(),
        ..Default::default()
    };
    let mut q = QuadList::default();
    let c = Vec3::new(0.0, 0.5, 0.0);
    room_walls(
        &mut q,
        Vec3::new(-0.5, 0.0, -0.5),
        Vec3::new(0.5, 1.0, 0.5),
        c,
    );
    let mut m = Material::diffuse("wall", [albedo; 3]);
    m.emissive = [emission; 3];
    scene.add_mesh(q.into_mesh("room"), m, Mat4::IDENTITY);
    let mut cam = Camera::look_at(Vec3::new(0.0, 0.5, 0.45), Vec3::new(0.0, 0.5, -0.5), 60.0);
    cam.name = "inside".into();
    scene.cameras.push(cam);
    scene
}

/// The six inward-facing walls of an axis-aligned room.
fn room_walls(q: &mut QuadList, a: Vec3, b: Vec3, inside: Vec3) {
    let p = Vec3::new;
    q.quad(
        [
            p(a.x, a.y, a.z),
            p(b.x, a.y, a.z),
            p(b.x, a.y, b.z),
            p(a.x, a.y, b.z),
        ],
        inside,
    );
    q.quad(
        [
            p(a.x, b.y, a.z),
            p(b.x, b.y, a.z),
            p(b.x, b.y, b.z),
            p(a.x, b.y, b.z),
        ],
        inside,
    );
    q.quad(
        [
            p(a.x, a.y, a.z),
            p(a.x, b.y, a.z),
            p(a.x, b.y, b.z),
            p(a.x, a.y, b.z),
        ],
        inside,
    );
    q.quad(
        [
            p(b.x, a.y, a.z),
            p(b.x, b.y, a.z),
            p(b.x, b.y, b.z),
            p(b.x, a.y, b.z),
        ],
        inside,
    );
    q.quad(
        [
            p(a.x, a.y, a.z),
            p(b.x, a.y, a.z),
            p(b.x, b.y, a.z),
            p(a.x, b.y, a.z),
        ],
        inside,
    );
    q.quad(
        [
            p(a.x, a.y, b.z),
            p(b.x, a.y, b.z),
            p(b.x, b.y, b.z),
            p(a.x, b.y, b.z),
        ],
        inside,
    );
}

/// A 1 m cube centred on the origin, Lambertian with `albedo`, without lights or camera.
pub fn cube(albedo: [f32; 3]) -> Scene {
    let mut scene = Scene {
        name: "cube".into(),
        ..Default::default()
    };
    let mut q = QuadList::default();
    q.cuboid(Vec3::splat(-0.5), Vec3::splat(0.5));
    scene.add_mesh(
        q.into_mesh("cube"),
        Material::diffuse("cube", albedo),
        Mat4::IDENTITY,
    );
    scene
}

/// Two 1 m rooms side by side along x (room A: x in [-1, 0], room B: x in [0, 1]) separated by a
/// wall `wall` metres thick centred on x = 0, with a point light in room A. Everything white
/// (albedo 0.8). Indirect light in room B measures how much light leaks through the wall.
pub fn two_rooms(wall: f32) -> Scene {
    let mut scene = Scene {
        name: "two-rooms".into(),
        ..Default::default()
    };
    let white = [0.8; 3];
    let mut q = QuadList::default();
    room_walls(
        &mut q,
        Vec3::new(-1.0, 0.0, 0.0),
        Vec3::new(1.0, 1.0, 1.0),
        Vec3::new(0.0, 0.5, 0.5),
    );
    scene.add_mesh(
        q.into_mesh("shell"),
        Material::diffuse("shell", white),
        Mat4::IDENTITY,
    );
    let mut q = QuadList::default();
    q.cuboid(
        Vec3::new(-wall * 0.5, 0.0, 0.0),
        Vec3::new(wall * 0.5, 1.0, 1.0),
    );
    scene.add_mesh(
        q.into_mesh("dividing wall"),
        Material::diffuse("dividing wall", white),
        Mat4::IDENTITY,
    );
    scene.lights.push(Light {
        name: "lamp A".into(),
        kind: LightKind::Point,
        color: [1.0; 3],
        intensity: 1.0,
        position: Vec3::new(-0.5, 0.7, 0.5),
        direction: Vec3::NEG_Y,
        range: None,
        cast_shadows: true,
    });
    let mut cam = Camera::look_at(Vec3::new(-0.95, 0.6, 0.95), Vec3::new(-0.2, 0.4, 0.2), 70.0);
    cam.name = "room A".into();
    scene.cameras.push(cam);
    scene
}

/// Points in `point-cave`: the size of the scanned cave in seed 004 §5.1 (1.4 million).
pub const POINT_CAVE_POINTS: usize = 1_400_000;

/// A synthetic cave scan of `n` points: a winding tunnel 16 m long and about 5 m across with a
/// flattened floor, its wall rippled by a few sinusoids, sampled uniformly at random with 2 mm
/// of scanner noise, coloured in rock tones, without normals (the renderer estimates them, as
/// for a raw scan). Lit by two spot lights and a rectangular area light; the camera stands at
/// the entrance. Deterministic: the same `n` gives the same cloud.
pub fn point_cave(n: usize) -> Scene {
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut rand = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    let length = 16.0f32;
    let axis = |z: f32| Vec3::new(0.8 * (z * 0.35).sin(), 0.3 * (z * 0.5).cos(), z);
    let radius = |theta: f32, z: f32| {
        2.5 + 0.35 * (3.0 * theta + 0.7 * z).sin()
            + 0.2 * (5.0 * theta - 1.3 * z).sin()
            + 0.08 * (13.0 * theta + 2.1 * z).sin()
    };
    let mut pc = PointCloud {
        name: "cave".into(),
        transform: Mat4::IDENTITY,
        ..Default::default()
    };
    pc.positions.reserve(n);
    pc.colors.reserve(n);
    let tau = std::f32::consts::TAU;
    for _ in 0..n {
        let (theta, z) = (rand() * tau, rand() * length);
        let r = radius(theta, z) + (rand() - 0.5) * 0.004;
        let mut p = Vec3::new(r * theta.cos(), r * theta.sin(), 0.0);
        // A flat floor 1.6 m below the axis.
        p.y = p.y.max(-1.6 + (rand() - 0.5) * 0.004);
        let p = axis(z) + Vec3::new(p.x, p.y, 0.0);
        let shade = 0.45 + 0.15 * (2.3 * theta + 0.9 * z).sin() + 0.1 * rand();
        pc.positions.push(p);
        pc.colors.push([shade * 0.95, shade * 0.8, shade * 0.62]);
    }
    let mut scene = Scene {
        name: "point-cave".into(),
        point_clouds: vec![pc],
        ..Default::default()
    };
    let spot = |name: &str, position: Vec3, target: Vec3, color: [f32; 3]| Light {
        name: name.into(),
        kind: LightKind::Spot {
            inner_angle: 18f32.to_radians(),
            outer_angle: 28f32.to_radians(),
        },
        color,
        intensity: 60.0,
        position,
        direction: (target - position).normalize(),
        range: None,
        cast_shadows: true,
    };
    scene.lights.push(spot(
        "spot left",
        axis(1.0) + Vec3::new(-1.0, 0.5, 0.0),
        axis(7.0) + Vec3::new(1.5, -1.2, 0.0),
        [1.0, 0.85, 0.7],
    ));
    scene.lights.push(spot(
        "spot right",
        axis(9.0) + Vec3::new(1.0, 0.8, 0.0),
        axis(13.0) + Vec3::new(-1.8, 0.0, 0.0),
        [0.75, 0.85, 1.0],
    ));
    scene.add_area_light(Light {
        name: "lamp".into(),
        kind: LightKind::Area {
            shape: AreaShape::Rect {
                u: Vec3::new(0.3, 0.0, 0.0),
                v: Vec3::new(0.0, 0.0, 0.6),
            },
        },
        color: [1.0, 0.9, 0.7],
        intensity: 12.0,
        position: axis(5.0) + Vec3::new(0.0, 1.7, 0.0),
        direction: Vec3::NEG_Y,
        range: None,
        cast_shadows: true,
    });
    let eye = axis(-1.0) + Vec3::new(0.0, 0.2, 0.0);
    let mut cam = Camera::look_at(eye, axis(6.0) + Vec3::new(0.0, -0.4, 0.0), 60.0);
    cam.name = "entrance".into();
    scene.cameras.push(cam);
    scene
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_builtin_validates() {
        for (name, _) in BUILTINS {
            let s = by_name(name).unwrap();
            s.validate().unwrap_or_else(|e| panic!("{name}: {e}"));
            assert!(s.triangle_count() > 0, "{name}");
        }
        assert!(matches!(
            by_name("nope"),
            Err(SceneError::UnknownBuiltin { .. })
        ));
    }

    #[test]
    fn cornell_box_has_the_published_extent() {
        let s = cornell_box();
        let b = s.bounds();
        // The measured box spans 0..556 x 0..548.8 x 0..559.2 mm.
        assert!((b.min - Vec3::ZERO).abs().max_element() < 1e-6);
        assert!(
            (b.max - Vec3::new(0.556, 0.5488, 0.5592))
                .abs()
                .max_element()
                < 1e-6
        );
        assert_eq!(s.lights.len(), 1);
        // Light area 130 mm x 105 mm.
        assert!((s.lights[0].area() - 0.130 * 0.105).abs() < 1e-7);
        // Walls face the inside: the floor's normal is +Y, the red wall's points to -X.
        let floor = &s.meshes[0];
        assert!((floor.normals[0] - Vec3::Y).length() < 1e-6);
        let red = s.meshes.iter().find(|m| m.name == "red wall").unwrap();
        assert!(red.normals[0].x < -0.99);
        // Every block face points away from its block.
        for name in ["short block", "tall block"] {
            let m = s.meshes.iter().find(|m| m.name == name).unwrap();
            let c = m.positions.iter().copied().sum::<Vec3>() / m.positions.len() as f32;
            for t in m.indices.chunks(3) {
                let p = m.positions[t[0] as usize];
                let geo = (m.positions[t[1] as usize] - p).cross(m.positions[t[2] as usize] - p);
                assert!(geo.dot(p - c) > 0.0 || geo.dot(m.normals[t[0] as usize]) > 0.0);
                assert!(
                    geo.dot(m.normals[t[0] as usize]) > 0.0,
                    "winding agrees with normal"
                );
            }
        }
    }

    #[test]
    fn area_light_emitter_faces_along_the_light() {
        let s = cornell_box();
        let inst = s.instances.iter().find(|i| i.light.is_some()).unwrap();
        let m = &s.meshes[inst.mesh];
        let t = &m.indices[0..3];
        let p = |i: u32| m.positions[i as usize];
        let geo = (p(t[1]) - p(t[0])).cross(p(t[2]) - p(t[0]));
        assert!(geo.normalize().dot(Vec3::NEG_Y) > 0.999);
        assert_eq!(s.materials[m.material].emissive, CORNELL_LIGHT);
    }

    /// `Scene::set_light` moves an area light's visible surface with it (the Cornell box's
    /// ceiling panel follows its lamp, turned a quarter about the vertical); another light's
    /// change leaves the instances alone.
    #[test]
    fn an_area_light_set_anew_takes_its_emitter_along() {
        use glam::{Quat, Vec3};
        let mut scene = cornell_box();
        let light = scene
            .lights
            .iter()
            .position(|l| matches!(l.kind, crate::LightKind::Area { .. }))
            .unwrap();
        let emitter = scene
            .instances
            .iter()
            .position(|i| i.light == Some(light))
            .unwrap();
        let corners = |s: &crate::Scene| -> Vec<Vec3> {
            let inst = &s.instances[emitter];
            let mesh = &s.meshes[inst.mesh];
            mesh.positions
                .iter()
                .map(|p| inst.transform.transform_point3(*p))
                .collect()
        };
        let before = corners(&scene);
        let mut moved = scene.lights[light].clone();
        let turn = Quat::from_rotation_y(std::f32::consts::FRAC_PI_2);
        let shift = Vec3::new(0.1, -0.05, 0.02);
        moved.position += shift;
        if let crate::LightKind::Area {
            shape: crate::AreaShape::Rect { u, v },
        } = &mut moved.kind
        {
            (*u, *v) = (turn * *u, turn * *v);
        }
        let centre = scene.lights[light].position;
        scene.set_light(light, moved.clone());
        for (b, a) in before.iter().zip(corners(&scene)) {
            let want = moved.position + turn * (*b - centre);
            assert!(a.distance(want) < 1e-5, "{a} against {want}");
        }
        let others: Vec<_> = scene.instances.iter().map(|i| i.transform).collect();
        let mut sun = crate::Scene::default_sun();
        sun.intensity = 2.0;
        scene.lights.push(sun.clone());
        let last = scene.lights.len() - 1;
        sun.direction = Vec3::new(0.3, -1.0, 0.0).normalize();
        scene.set_light(last, sun);
        assert!(scene.instances.iter().map(|i| i.transform).eq(others));
    }
}
