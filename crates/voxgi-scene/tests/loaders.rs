//! Loader tests: round trips with exact values, bad input, and (when present) the real files in
//! /work/shared/scenes. Every file a test needs is written to the temp directory by the test.

use std::path::{Path, PathBuf};
use voxgi_scene::glam::{Mat4, Vec2, Vec3};
use voxgi_scene::{
    AlphaMode, AreaShape, LightKind, PointCloud, Projection, builtin, io, pointcloud,
    srgb_to_linear,
};

mod common;
use common::load_warned;

/// A fresh directory for one test (tests run in parallel).
fn tmp(test: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("voxgi-loaders-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn write(dir: &Path, name: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

/// Exact comparisons are used where the loader only copies or converts with one f32 operation;
/// `close` (1e-6) where a normalisation or trigonometric function is involved.
fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).length() < 1e-6
}

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
fn obj_with_mtl_and_texture() {
    let dir = tmp("obj");
    std::fs::create_dir_all(dir.join("tex")).unwrap();
    let mut png = image::RgbaImage::new(2, 1);
    png.put_pixel(0, 0, image::Rgba([255, 0, 0, 255]));
    png.put_pixel(1, 0, image::Rgba([0, 10, 200, 128]));
    png.save(dir.join("tex/checker.png")).unwrap();
    write(
        &dir,
        "mats.mtl",
        "newmtl red\nKd 0.5 0.25 0.125\nNs 98\nd 0.5\nmap_Kd tex/checker.png\n\nnewmtl glow\nKd 0 0 0\nKe 2 3 4\n",
    );
    let obj = write(
        &dir,
        "room.obj",
        "mtllib mats.mtl\n\
         v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
         vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n\
         o quad\nusemtl red\nf 1/1/1 2/2/1 3/3/1 4/4/1\n\
         o lamp\nv 0 2 0\nv 1 2 0\nv 1 2 1\nv 0 2 1\nusemtl glow\nf 5 6 7 8\n",
    );
    let s = io::load(&obj).unwrap();
    assert_eq!(s.name, "room");
    assert_eq!(s.meshes.len(), 2);
    assert_eq!(s.instances.len(), 2);
    assert_eq!(s.triangle_count(), 4);
    let quad = s.meshes.iter().find(|m| m.name == "quad").unwrap();
    assert!(quad.normals.iter().all(|n| *n == Vec3::Z));
    // OBJ v runs up from the bottom; the model's runs down from the top: v' = 1 - v, exact.
    let i0 = quad
        .positions
        .iter()
        .position(|p| *p == Vec3::ZERO)
        .unwrap();
    assert_eq!(quad.uvs[i0], Vec2::new(0.0, 1.0));
    let red = &s.materials[quad.material];
    assert_eq!(red.base_color, [0.5, 0.25, 0.125, 0.5]);
    assert_eq!(red.alpha_mode, AlphaMode::Blend);
    // sqrt(2 / (98 + 2)) = sqrt(0.02); one f32 sqrt.
    assert!((red.roughness - 0.02f32.sqrt()).abs() < 1e-6);
    let t = &s.textures[red.base_color_texture.unwrap()];
    assert_eq!((t.width, t.height), (2, 1));
    assert_eq!(t.rgba8, vec![255, 0, 0, 255, 0, 10, 200, 128]);

    // The lamp is an emissive parallelogram: promoted to an area light facing -Y (CCW seen from
    // below), radiance copied from Ke.
    assert_eq!(s.lights.len(), 1);
    let l = &s.lights[0];
    assert_eq!(l.radiometric(), Vec3::new(2.0, 3.0, 4.0));
    assert!(close(l.direction, Vec3::NEG_Y));
    assert!(close(l.position, Vec3::new(0.5, 2.0, 0.5)));
    assert!((l.area() - 1.0).abs() < 1e-6);
    let lamp_inst = s.instances.iter().find(|i| i.name == "lamp").unwrap();
    assert_eq!(lamp_inst.light, Some(0));

    // Without its MTL the OBJ still loads, with default materials.
    std::fs::remove_file(dir.join("mats.mtl")).unwrap();
    let s = io::load(&obj).unwrap();
    assert_eq!(s.triangle_count(), 4);
    assert!(s.lights.is_empty());
    assert!(
        s.materials
            .iter()
            .all(|m| m.base_color == [0.8, 0.8, 0.8, 1.0])
    );
}

#[test]
fn ascii_ply_mesh() {
    let dir = tmp("ply_ascii");
    let p = write(
        &dir,
        "quad.ply",
        "ply\nformat ascii 1.0\ncomment made by hand\nelement vertex 5\nproperty float x\nproperty float y\n\
         property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n\
         element face 2\nproperty list uchar int vertex_indices\nelement edge 1\nproperty int a\nproperty int b\nend_header\n\
         0 0 0 255 0 0\n1 0 0 0 255 0\n1 1 0 0 0 255\n0 1 0 10 10 10\n0.5 0.5 -1.25 0 0 0\n\
         4 0 1 2 3\n3 0 4 1\n0 1\n",
    );
    let s = io::load(&p).unwrap();
    assert_eq!(s.meshes.len(), 1);
    let m = &s.meshes[0];
    assert_eq!(m.positions[4], Vec3::new(0.5, 0.5, -1.25));
    // The quad becomes the fan (0 1 2) (0 2 3), then the triangle.
    assert_eq!(m.indices, vec![0, 1, 2, 0, 2, 3, 0, 4, 1]);
    // Vertex 2 only touches the quad, whose CCW normal is +Z.
    assert!(close(m.normals[2], Vec3::Z));
    assert!(s.point_clouds.is_empty());
    assert_eq!(s.instances.len(), 1);

    // The `vertex_index` spelling, and a float index list, are read the same way.
    let text = std::fs::read_to_string(&p).unwrap();
    let alt = text.replace(
        "list uchar int vertex_indices",
        "list uchar float vertex_index",
    );
    let p2 = write(&dir, "quad_alt.ply", alt);
    assert_eq!(io::load(&p2).unwrap().meshes[0].indices, m.indices);
}

/// Builds a binary PLY point cloud: double or float xyz, float normals, uchar colours, radius.
/// One test point: position, normal, sRGB colour, radius.
type TestPoint = ([f64; 3], [f32; 3], [u8; 3], f32);

fn binary_cloud(big: bool, double: bool, pts: &[TestPoint]) -> Vec<u8> {
    let fmt = if big {
        "binary_big_endian"
    } else {
        "binary_little_endian"
    };
    let pt = if double { "double" } else { "float" };
    let mut out = format!(
        "ply\nformat {fmt} 1.0\nelement vertex {}\nproperty {pt} x\nproperty {pt} y\nproperty {pt} z\n\
         property float nx\nproperty float ny\nproperty float nz\nproperty uchar red\nproperty uchar green\n\
         property uchar blue\nproperty float radius\nend_header\n",
        pts.len()
    )
    .into_bytes();
    let f32b = |v: f32| {
        if big {
            v.to_be_bytes()
        } else {
            v.to_le_bytes()
        }
    };
    for (p, n, c, r) in pts {
        for v in p {
            if double {
                out.extend(if big {
                    v.to_be_bytes()
                } else {
                    v.to_le_bytes()
                });
            } else {
                out.extend(f32b(*v as f32));
            }
        }
        for v in n {
            out.extend(f32b(*v));
        }
        out.extend(c);
        out.extend(f32b(*r));
    }
    out
}

#[test]
fn binary_ply_point_clouds_le_and_be() {
    let dir = tmp("ply_bin");
    let pts = [
        ([1.5, -2.0, 3.25], [0.0, 0.0, 2.0], [255, 128, 0], 0.01),
        ([-7.0, 0.125, 1e3], [0.0, -1.0, 0.0], [10, 20, 30], 0.5),
        ([0.0, 0.0, 0.0], [3.0, 4.0, 0.0], [0, 0, 0], 2.0),
    ];
    for (big, double) in [(false, false), (true, false), (false, true), (true, true)] {
        let name = format!("cloud_{big}_{double}.ply");
        let p = write(&dir, &name, binary_cloud(big, double, &pts));
        let s = io::load(&p).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(s.meshes.is_empty());
        let pc = &s.point_clouds[0];
        assert_eq!(pc.positions.len(), 3);
        for (i, (pos, n, c, r)) in pts.iter().enumerate() {
            // All values are exactly representable in f32: exact equality.
            assert_eq!(
                pc.positions[i],
                Vec3::new(pos[0] as f32, pos[1] as f32, pos[2] as f32)
            );
            assert!(
                close(pc.normals[i], Vec3::from(*n).normalize()),
                "{name} {i}"
            );
            assert_eq!(pc.colors[i], c.map(|c| srgb_to_linear(c as f32 / 255.0)));
            assert_eq!(pc.radii[i], *r);
        }
    }
    // Without colour properties points are 0.8 grey; float colours are taken as linear.
    let p = write(
        &dir,
        "plain.ply",
        "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n1 1 1\n",
    );
    let s = io::load(&p).unwrap();
    assert_eq!(s.point_clouds[0].colors, vec![[0.8; 3]; 2]);
    assert!(s.point_clouds[0].normals.is_empty());
    let p = write(
        &dir,
        "fcol.ply",
        "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n\
         property float diffuse_red\nproperty float diffuse_green\nproperty float diffuse_blue\nend_header\n0 0 0 0.25 0.5 1\n",
    );
    assert_eq!(
        io::load(&p).unwrap().point_clouds[0].colors,
        vec![[0.25, 0.5, 1.0]]
    );
}

#[test]
fn cloud_write_then_load() {
    let dir = tmp("cloud");
    let bytes = [0u8, 1, 2, 100, 187, 255];
    let pc = PointCloud {
        name: "c".into(),
        positions: vec![Vec3::new(1.0, 2.0, 3.0), Vec3::new(-0.5, 0.0, 1e-3)],
        colors: vec![
            [bytes[0], bytes[1], bytes[2]].map(|b| srgb_to_linear(b as f32 / 255.0)),
            [bytes[3], bytes[4], bytes[5]].map(|b| srgb_to_linear(b as f32 / 255.0)),
        ],
        normals: vec![Vec3::Y, Vec3::new(0.6, 0.0, -0.8)],
        transform: Mat4::IDENTITY,
        ..Default::default()
    };
    let p = dir.join("pts.cloud");
    voxgi_scene::io::cloud::write(&p, &pc).unwrap();
    let raw = std::fs::read(&p).unwrap();
    // 4-byte count + 27 bytes per record, little endian, packed.
    assert_eq!(raw.len(), 4 + 27 * 2);
    assert_eq!(&raw[0..4], &2i32.to_le_bytes());
    assert_eq!(&raw[4..8], &1.0f32.to_le_bytes());
    assert_eq!(&raw[16..20], &0.0f32.to_le_bytes());
    assert_eq!(&raw[20..24], &1.0f32.to_le_bytes());
    assert_eq!(&raw[28..31], &bytes[0..3]);
    assert_eq!(&raw[55..58], &bytes[3..6]);
    let s = io::load(&p).unwrap();
    let back = &s.point_clouds[0];
    assert_eq!(back.positions, pc.positions);
    // Colours came from 8-bit sRGB, so encoding and decoding reproduces them exactly.
    assert_eq!(back.colors, pc.colors);
    for (a, b) in back.normals.iter().zip(&pc.normals) {
        assert!(close(*a, *b));
    }
}

#[test]
fn scene_file_with_includes_lights_camera_settings() {
    let dir = tmp("scene");
    write(&dir, "tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    write(
        &dir,
        "sub/box.toml",
        "[[include]]\nbuiltin = \"cornell-box\"\n\n[camera]\nposition = [0.0, 0.0, 3.0]\ntarget = [0.0, 0.0, 0.0]\nfov = 30.0\n",
    );
    let main = write(
        &dir,
        "main.toml",
        r#"name = "test scene"
[[include]]
file = "tri.obj"
translate = [1.0, 0.0, 0.0]
rotate = [0.0, 90.0, 0.0]
scale = 2.0
dynamic = true
[include.material]
base_color = [0.1, 0.2, 0.3]
roughness = 0.25
specular = 0.0

[[include]]
file = "sub/box.toml"
translate = [0.0, 0.0, 5.0]
scale = [1.0, 2.0, 1.0]

[[light]]
type = "directional"
intensity = 3.0
direction = [0.0, -2.0, 0.0]

[[light]]
type = "point"
name = "bulb"
color = [1.0, 0.5, 0.25]
intensity = 10.0
position = [0.0, 3.0, 0.0]
range = 8.0

[[light]]
type = "spot"
intensity = 5.0
position = [0.0, 3.0, 0.0]
target = [0.0, 0.0, 0.0]
inner_angle = 20.0
outer_angle = 30.0
cast_shadows = false

[[light]]
type = "area"
intensity = 4.0
position = [0.0, 2.0, 0.0]
direction = [0.0, -1.0, 0.0]
shape = "rect"
size = [0.5, 0.4]

[[light]]
type = "area"
intensity = 1.0
position = [1.0, 1.0, 1.0]
target = [1.0, 1.0, 0.0]
shape = "disc"
radius = 0.25

[camera]
position = [0.0, 1.0, 4.0]
target = [0.0, 1.0, 0.0]
fov = 50.0

[settings]
voxel_resolution = 128
debug = { cones = 6 }
"#,
    );
    let (s, settings) = io::scene_file::load_with_settings(&main).unwrap();
    s.validate().unwrap();
    assert_eq!(s.name, "test scene");
    let settings = settings.unwrap();
    assert_eq!(settings["voxel_resolution"].as_integer(), Some(128));
    assert_eq!(settings["debug"]["cones"].as_integer(), Some(6));

    // The triangle: scale 2, rotate 90° about Y, translate +X. (1,0,0) -> (2,0,0) -> (0,0,-2)
    // -> (1,0,-2); (0,1,0) -> (0,2,0) -> (1,2,0). 1e-6: the rotation's cos(90°) is ~-4e-8.
    let tri = &s.instances[0];
    assert!(tri.dynamic);
    let m = &s.meshes[tri.mesh];
    let w = |i: usize| tri.transform.transform_point3(m.positions[i]);
    assert!(close(w(1), Vec3::new(1.0, 0.0, -2.0)), "{}", w(1));
    assert!(close(w(2), Vec3::new(1.0, 2.0, 0.0)), "{}", w(2));
    let mat = &s.materials[m.material];
    assert_eq!(mat.base_color, [0.1, 0.2, 0.3, 1.0]);
    assert_eq!(mat.roughness, 0.25);
    // A pure Lambertian can be asked for (the default is glTF's 1).
    assert_eq!(mat.specular, 0.0);

    // The nested built-in box keeps its lights; then come the file's five lights in order.
    let cb = builtin::cornell_box();
    let n0 = cb.lights.len();
    assert_eq!(s.lights.len(), n0 + 5);
    assert_eq!(s.instances.len(), 1 + cb.instances.len() + 2);
    assert!(
        s.instances[1..=cb.instances.len()]
            .iter()
            .all(|i| !i.dynamic)
    );
    let l = &s.lights[n0..];
    assert_eq!(l[0].kind, LightKind::Directional);
    assert!(close(l[0].direction, Vec3::NEG_Y));
    assert_eq!(l[1].kind, LightKind::Point);
    assert_eq!(l[1].name, "bulb");
    assert_eq!(l[1].radiometric(), Vec3::new(10.0, 5.0, 2.5));
    assert_eq!(l[1].range, Some(8.0));
    let LightKind::Spot {
        inner_angle,
        outer_angle,
    } = l[2].kind
    else {
        panic!("{:?}", l[2].kind)
    };
    assert!((inner_angle - 20f32.to_radians()).abs() < 1e-6);
    assert!((outer_angle - 30f32.to_radians()).abs() < 1e-6);
    assert!(!l[2].cast_shadows);
    assert!(close(l[2].direction, Vec3::NEG_Y));
    let LightKind::Area {
        shape: AreaShape::Rect { u, v },
    } = l[3].kind
    else {
        panic!()
    };
    assert!((l[3].area() - 0.2).abs() < 1e-6);
    assert!(
        u.cross(v).dot(Vec3::NEG_Y) > 0.0,
        "rect must face its direction"
    );
    assert!(
        matches!(l[4].kind, LightKind::Area { shape: AreaShape::Disc { radius } } if radius == 0.25)
    );
    assert!(close(l[4].direction, Vec3::NEG_Z));
    // Each area light got its emitter instance.
    let emitters: Vec<_> = s
        .instances
        .iter()
        .filter_map(|i| i.light)
        .filter(|&li| li >= n0)
        .collect();
    assert_eq!(emitters, vec![n0 + 3, n0 + 4]);

    // The file's camera wins; the included one follows, moved by its include's transform.
    assert_eq!(s.cameras[0].position, Vec3::new(0.0, 1.0, 4.0));
    assert_eq!(
        s.cameras[0].projection,
        Projection::Perspective {
            yfov: 50f32.to_radians()
        }
    );
    let sub_cam = s
        .cameras
        .iter()
        .find(|c| {
            c.projection
                == Projection::Perspective {
                    yfov: 30f32.to_radians(),
                }
        })
        .unwrap();
    assert!(close(sub_cam.position, Vec3::new(0.0, 0.0, 8.0)));
    assert!(close(sub_cam.forward, Vec3::NEG_Z));

    // Without its own camera the first included camera is the default view.
    let nocam = write(&dir, "nocam.toml", "[[include]]\nfile = \"sub/box.toml\"\n");
    let s = io::load(&nocam).unwrap();
    assert_eq!(
        s.cameras[0].projection,
        Projection::Perspective {
            yfov: 30f32.to_radians()
        }
    );
}

#[test]
fn bad_inputs_fail_with_the_file_name() {
    let dir = tmp("bad");
    let ply_head = |fmt: &str, n: &str| {
        format!(
            "ply\nformat {fmt} 1.0\nelement vertex {n}\nproperty float x\nproperty float y\nproperty float z\n"
        )
    };
    let tri_ply = |face: &str| {
        format!(
            "{}element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n{face}\n",
            ply_head("ascii", "3")
        )
    };
    let mut bin_list = ply_head("binary_little_endian", "1");
    bin_list += "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
    let mut bin_list = bin_list.into_bytes();
    bin_list.extend([0u8; 12]);
    bin_list.extend([255u8, 0, 0, 0, 0]);
    let cloud = |count: i32, records: usize, extra: usize| {
        let mut b = count.to_le_bytes().to_vec();
        for _ in 0..records {
            for v in [0f32, 0.0, 0.0, 0.0, 1.0, 0.0] {
                b.extend(v.to_le_bytes());
            }
            b.extend([1u8, 2, 3]);
        }
        b.extend(vec![0u8; extra]);
        b
    };
    let mut zero_ndf = 1i32.to_le_bytes().to_vec();
    zero_ndf.extend([0u8; 27]);
    let mut trunc_bin = (ply_head("binary_little_endian", "3") + "end_header\n").into_bytes();
    trunc_bin.extend([0u8; 20]);
    let light = |body: &str| format!("[[light]]\n{body}\n");
    let colour_ply = |ty: &str, value: &str| {
        format!(
            "{}property {ty} red\nproperty {ty} green\nproperty {ty} blue\nend_header\n0 0 0 {value} 0 0\n",
            ply_head("ascii", "1")
        )
        .into_bytes()
    };

    // (case, file name, contents, fragment the reason must contain ("" = only the file name)).
    #[rustfmt::skip]
    let cases: Vec<(&str, &str, Vec<u8>, &str)> = vec![
        ("ply truncated binary", "trunc_bin.ply", trunc_bin, "truncated"),
        ("ply 2^40 vertices", "huge.ply", (ply_head("binary_little_endian", "1099511627776") + "end_header\n").into_bytes(), "limit"),
        ("ply count larger than file", "big.ply", (ply_head("binary_little_endian", "1000") + "end_header\n").into_bytes(), "body has only"),
        ("ply ascii non-number", "word.ply", (ply_head("ascii", "1") + "end_header\n0 zero 0\n").into_bytes(), "'zero' is not a number"),
        ("ply face index out of range", "face.ply", tri_ply("3 0 1 7").into_bytes(), "vertex index 7 out of range (3 vertices)"),
        ("ply negative face index", "negface.ply", tri_ply("3 0 -1 2").into_bytes(), "out of range"),
        ("ply empty", "empty.ply", vec![], "empty"),
        ("ply no end_header", "noend.ply", ply_head("ascii", "1").into_bytes(), "end_header"),
        ("ply not a ply", "text.ply", b"hello\n".to_vec(), "not a PLY"),
        ("ply missing z", "noz.ply", b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n0 0\n".to_vec(), "x, y, z"),
        ("ply list past end", "list.ply", bin_list, "runs past"),
        ("ply ascii too few values", "short.ply", (ply_head("ascii", "2") + "end_header\n0 0 0\n1 1          \n").into_bytes(), "line 9: too few values for vertex 1"),
        ("ply ascii colour beyond its type", "red300.ply", colour_ply("uchar", "300"), "300 is out of the range of its type uchar"),
        ("ply ascii negative unsigned", "redneg.ply", colour_ply("ushort", "-1"), "out of the range of its type ushort"),
        ("ply nan float colour", "nancol.ply", colour_ply("float", "nan"), "vertex 0: colour NaN is not a reflectance"),
        ("ply negative float colour", "negcol.ply", colour_ply("float", "-0.5"), "colour -0.5"),
        ("obj NaN diffuse colour", "kdnan.obj", b"mtllib kdnan.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl m\nf 1 2 3\n".to_vec(), "base colour [NaN, 0.0, 0.0, 1.0] holds NaN"),
        ("obj negative diffuse colour", "kdneg.obj", b"mtllib kdneg.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl m\nf 1 2 3\n".to_vec(), "holds -1"),
        ("obj emission past f32", "keinf.obj", b"mtllib keinf.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl m\nf 1 2 3\n".to_vec(), "emission [inf, 1.0, 1.0] holds inf"),
        ("obj emission past half floats", "kebig.obj", b"mtllib kebig.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl m\nf 1 2 3\n".to_vec(), "emission 1e30 is more than 65504"),
        ("obj face index out of range", "range.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 40\n".to_vec(), "line 4: face vertex index 40 out of range (3 vertices"),
        ("obj no triangles", "points.obj", b"v 0 0 0\nv 1 0 0\nl 1 2\n".to_vec(), "contains no triangles"),
        ("obj empty", "empty.obj", vec![], "contains no triangles"),
        ("obj nan vertex", "nan.obj", b"v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n".to_vec(), "not finite"),
        ("cloud truncated", "trunc.cloud", cloud(2, 1, 10), "expected"),
        ("cloud negative count", "neg.cloud", cloud(-5, 0, 0), "negative sample count -5"),
        ("cloud count beyond file", "count.cloud", cloud(1000, 1, 0), "27004 bytes"),
        ("cloud trailing bytes", "trail.cloud", cloud(1, 1, 3), "file has 34 bytes"),
        ("cloud shorter than count", "tiny.cloud", vec![1, 0], "too short"),
        ("cloud zero NDF", "ndf.cloud", zero_ndf, "record 0"),
        ("toml syntax error", "syntax.toml", b"[[include]\nfile = \n".to_vec(), ""),
        ("toml unknown key", "typo.toml", b"[camera]\npositon = [0.0, 0.0, 1.0]\ntarget = [0.0, 0.0, 0.0]\n".to_vec(), "positon"),
        ("toml missing include", "missing.toml", b"[[include]]\nfile = \"nope.obj\"\n".to_vec(), "nope.obj"),
        ("toml self include", "self.toml", b"[[include]]\nfile = \"self.toml\"\n".to_vec(), "include cycle"),
        ("toml mutual include", "ping.toml", b"[[include]]\nfile = \"pong.toml\"\n".to_vec(), "include cycle"),
        ("toml bad light type", "laser.toml", light("type = \"laser\"\nintensity = 1.0").into_bytes(), "laser"),
        ("toml spot inner > outer", "spot.toml", light("type = \"spot\"\nintensity = 1.0\nposition = [0.0, 1.0, 0.0]\ndirection = [0.0, -1.0, 0.0]\ninner_angle = 40.0\nouter_angle = 30.0").into_bytes(), "inner"),
        ("toml negative intensity", "negint.toml", light("type = \"point\"\nintensity = -1.0\nposition = [0.0, 1.0, 0.0]").into_bytes(), "intensity -1"),
        ("toml area without size", "nosize.toml", light("type = \"area\"\nintensity = 1.0\nposition = [0.0, 1.0, 0.0]\ndirection = [0.0, -1.0, 0.0]\nshape = \"rect\"").into_bytes(), "size"),
        ("toml unknown builtin", "nobuiltin.toml", b"[[include]]\nbuiltin = \"moon-base\"\n".to_vec(), "moon-base"),
        ("toml overflowing number", "overflow.toml", light("type = \"point\"\nintensity = 1e400\nposition = [0.0, 1.0, 0.0]").into_bytes(), "line 3"),
        ("toml light past the limit", "hotlight.toml", light("type = \"point\"\nintensity = 3e38\nposition = [0.0, 1.0, 0.0]").into_bytes(), "3e38 is more than 1e10"),
        ("toml area light past half floats", "hotarea.toml", light("type = \"area\"\nintensity = 1e5\nposition = [0.0, 1.0, 0.0]\ndirection = [0.0, -1.0, 0.0]\nshape = \"disc\"\nradius = 0.1").into_bytes(), "1e5 is more than 65504"),
        ("toml emission past half floats", "hotmat.toml", b"[[include]]\nbuiltin = \"cube\"\n[include.material]\nemissive = [1e30, 0.0, 0.0]\n".to_vec(), "65504"),
        ("toml geometry past f32", "huge.toml", b"[[include]]\nbuiltin = \"cube\"\ntranslate = [3e38, 0.0, 0.0]\n[[include]]\nbuiltin = \"cube\"\ntranslate = [-3e38, 0.0, 0.0]\n".to_vec(), "reaches from (-3e38, -5e-1, -5e-1) to (3e38, 5e-1, 5e-1) m: its extent overflows single precision"),
        ("toml scene wider than voxgi works with", "wide.toml", b"[[include]]\nbuiltin = \"cube\"\nscale = 1e20\n".to_vec(), "the scene spans 1e20 m, more than the 1e9 m voxgi works with"),
        ("toml specular out of range", "spec.toml", b"[[include]]\nbuiltin = \"cornell-box\"\n[include.material]\nspecular = 2.0\n".to_vec(), "specular"),
        ("unknown extension", "scene.xyz", b"whatever".to_vec(), "unknown file type '.xyz'"),
        ("no extension", "scene", b"whatever".to_vec(), "no file extension to tell its type by"),
        ("gltf invalid json", "bad.gltf", b"{ not json".to_vec(), ""),
        ("glb empty", "empty.glb", vec![], ""),
        ("glb truncated", "trunc.glb", b"glTF\x02\x00\x00\x00\xff\xff\x00\x00".to_vec(), ""),
    ];
    write(&dir, "pong.toml", "[[include]]\nfile = \"ping.toml\"\n");
    for (name, line) in [
        ("kdnan", "Kd nan 0 0"),
        ("kdneg", "Kd -1 0 0"),
        ("keinf", "Ke inf 1 1"),
        ("kebig", "Ke 1e30 0 0"),
    ] {
        write(&dir, &format!("{name}.mtl"), format!("newmtl m\n{line}\n"));
    }
    std::fs::create_dir_all(dir.join("folder.obj")).unwrap();
    let mut rows: Vec<(&str, PathBuf, &str)> = cases
        .iter()
        .map(|(case, name, bytes, frag)| (*case, write(&dir, name, bytes), *frag))
        .collect();
    rows.push((
        "nonexistent path",
        dir.join("does_not_exist.ply"),
        "no such file",
    ));
    rows.push(("directory path", dir.join("folder.obj"), "is a directory"));
    assert!(rows.len() >= 24);
    let mut failures = Vec::new();
    for (case, path, frag) in &rows {
        let name = path.file_name().unwrap().to_str().unwrap();
        let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| io::load(path)));
        match result {
            Err(_) => failures.push(format!("{case}: panicked")),
            Ok(Ok(_)) => failures.push(format!("{case}: loaded without error")),
            Ok(Err(e)) => {
                let msg = e.to_string();
                if !msg.contains(name) || !msg.contains(frag) {
                    failures.push(format!("{case}: message lacks '{name}' or '{frag}': {msg}"));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn emissive_non_quad_stays_geometry() {
    // An emissive triangle pair that forms an L shape (not a parallelogram) is not a light.
    let dir = tmp("nonquad");
    write(&dir, "m.mtl", "newmtl e\nKe 1 1 1\n");
    let p = write(
        &dir,
        "l.obj",
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 2 0 0\nv 2 1 0\nusemtl e\nf 1 2 3\nf 2 4 5\n",
    );
    let s = io::load(&p).unwrap();
    assert!(s.lights.is_empty());
    assert!(
        !s.is_unlit(),
        "the emissive geometry still lights the scene"
    );
}

/// Every prefix of a valid file, and the file with single bytes changed, must load or fail
/// cleanly: never panic, never allocate from a corrupt count. Cheap stand-in for fuzzing.
#[test]
fn truncated_and_corrupted_files_never_panic() {
    let dir = tmp("fuzz");
    let pts: Vec<TestPoint> = (0..4)
        .map(|i| ([i as f64, 1.0, 2.0], [0.0, 1.0, 0.0], [1, 2, 3], 0.1))
        .collect();
    let mut mesh_bin = b"ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar uint vertex_indices\nend_header\n".to_vec();
    for v in [0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        mesh_bin.extend(v.to_be_bytes());
    }
    mesh_bin.push(3);
    for i in [0u32, 1, 2] {
        mesh_bin.extend(i.to_be_bytes());
    }
    let mut cloud = 2i32.to_le_bytes().to_vec();
    for _ in 0..2 {
        for v in [1f32, 2.0, 3.0, 0.0, 1.0, 0.0] {
            cloud.extend(v.to_le_bytes());
        }
        cloud.extend([9u8, 8, 7]);
    }
    let files: Vec<(&str, Vec<u8>)> = vec![
        ("f.ply", binary_cloud(false, false, &pts)),
        ("f.ply", binary_cloud(true, true, &pts)),
        ("f.ply", mesh_bin),
        ("f.ply", b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n".to_vec()),
        ("f.cloud", cloud),
        ("f.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nf 1/1/1 2/1/1 3/1/1\n".to_vec()),
    ];
    let mut tried = 0;
    for (fi, (ext, bytes)) in files.iter().enumerate() {
        assert!(
            io::load(&write(&dir, ext, bytes)).is_ok(),
            "file {fi} must be valid"
        );
        let mut variants: Vec<Vec<u8>> = (0..bytes.len()).map(|n| bytes[..n].to_vec()).collect();
        for i in 0..bytes.len() {
            for x in [0x00u8, 0xff, b'9', b' ', b'\n'] {
                let mut b = bytes.clone();
                b[i] = x;
                variants.push(b);
            }
        }
        for (vi, v) in variants.iter().enumerate() {
            let p = write(&dir, ext, v);
            let r = std::panic::catch_unwind(|| io::load(&p).map(|s| s.validate()));
            assert!(r.is_ok(), "file {fi} variant {vi} panicked: {v:?}");
            tried += 1;
        }
    }
    assert!(tried > 1000);
}

#[test]
fn append_remaps_indices_and_transforms_lights() {
    let mut s = builtin::cornell_box();
    let one = s.clone();
    let t = Mat4::from_translation(Vec3::new(10.0, 0.0, 0.0))
        * Mat4::from_scale(Vec3::new(2.0, 1.0, 3.0));
    s.append(one.clone(), t, true);
    s.validate().unwrap();
    assert_eq!(s.meshes.len(), 2 * one.meshes.len());
    assert_eq!(s.lights.len(), 2 * one.lights.len());
    for (a, b) in one
        .instances
        .iter()
        .zip(&s.instances[one.instances.len()..])
    {
        assert_eq!(b.mesh, a.mesh + one.meshes.len());
        assert_eq!(b.light, a.light.map(|l| l + one.lights.len()));
        assert_eq!(
            s.meshes[b.mesh].material,
            s.meshes[a.mesh].material + one.materials.len()
        );
        assert!(b.dynamic);
        assert_eq!(b.transform, t * a.transform);
    }
    let mut checked_rects = 0;
    for (a, b) in one.lights.iter().zip(&s.lights[one.lights.len()..]) {
        assert!(close(b.position, t.transform_point3(a.position)));
        if let LightKind::Area {
            shape: AreaShape::Rect { u, v },
        } = b.kind
        {
            // Under non-uniform scale the emitting normal must stay perpendicular to the edges
            // (inverse transpose), and keep its side.
            assert!(u.dot(b.direction).abs() < 1e-5 && v.dot(b.direction).abs() < 1e-5);
            assert!(b.direction.dot(a.direction) > 0.0);
            // Area scales with the x and z factors for a light in the y = const plane: 2 x 3.
            if a.direction.y.abs() > 0.999 {
                assert!((b.area() - 6.0 * a.area()).abs() < 1e-5 * b.area());
                checked_rects += 1;
            }
        }
    }
    assert!(
        checked_rects > 0,
        "the built-in box has a ceiling rect light"
    );
}

/// PCL's own office scan, read from its binary_compressed PCD, is the scene's PLY conversion
/// (made outside voxgi, NaN points dropped) point for point: the same 254 456 of the 307 200
/// points, positions to the bit, colours from the same bytes.
#[test]
fn the_pcl_office_scan_as_pcd_is_its_ply_conversion() {
    let Some(root) = shared_scenes() else { return };
    let dir = root.join("pointcloud_pcl_office1");
    let pcd = io::load(&dir.join("office1.pcd")).expect("office1.pcd");
    let ply = io::load(&dir.join("office1_xyzrgb.ply")).expect("office1_xyzrgb.ply");
    let (a, b) = (&pcd.point_clouds[0], &ply.point_clouds[0]);
    assert_eq!(a.positions.len(), 254_456);
    assert!(a.positions == b.positions, "positions differ");
    assert!(a.colors == b.colors, "colours differ");
    assert!(a.normals.is_empty());
}

#[test]
fn conformance_with_real_files() {
    let Some(root) = shared_scenes() else { return };
    let load = |rel: &str| {
        let t = std::time::Instant::now();
        let s = io::load(&root.join(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"));
        let b = s.bounds();
        println!("{rel}: {:.2?}, bounds {} .. {}", t.elapsed(), b.min, b.max);
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
    assert!(
        dm.normals
            .iter()
            .zip(&computed)
            .any(|(a, b)| a.dot(*b) < 0.999)
    );
    let mut office = load("pointcloud_pcl_office1/office1_xyzrgb.ply");
    assert_eq!(office.point_count(), 254_456);
    let pc = &mut office.point_clouds[0];
    assert!(pc.normals.is_empty());
    // The PCL capture's sensor sits at the origin.
    let t = std::time::Instant::now();
    pointcloud::estimate_normals(pc, 16, Vec3::ZERO);
    let t_normals = t.elapsed();
    let t = std::time::Instant::now();
    pointcloud::estimate_radii(pc, 8);
    let t_radii = t.elapsed();
    println!("office cloud: normals (k=16) {t_normals:.2?}, radii (k=8) {t_radii:.2?}");
    assert_eq!(pc.normals.len(), 254_456);
    assert!(pc.normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-4));
    assert!(
        pc.normals
            .iter()
            .zip(&pc.positions)
            .all(|(n, p)| n.dot(-*p) >= 0.0)
    );
    assert!(pc.radii.iter().all(|r| r.is_finite() && *r >= 0.0));
    // The brief's budget is 2 s for 254k points in release; debug builds are ~10x slower.
    if !cfg!(debug_assertions) {
        assert!(t_normals.as_secs_f32() < 2.0, "{t_normals:?}");
    }

    let mcguire = load("cornell_box_mcguire/CornellBox-Original.obj");
    assert_eq!(mcguire.lights.len(), 1, "{:?}", mcguire.lights);
    let l = &mcguire.lights[0];
    // Exact: Ke 17 12 4 is copied, intensity 1.
    assert_eq!(l.radiometric(), Vec3::new(17.0, 12.0, 4.0));
    // Float noise only: the light's four vertices lie exactly at y = 1.98.
    assert!(
        (l.direction - Vec3::NEG_Y).length() < 1e-5,
        "{}",
        l.direction
    );
    // 0.47 m x 0.38 m from the file's corner coordinates; 1e-4 for f32 rounding.
    assert!((l.area() - 0.47 * 0.38).abs() < 1e-4, "{}", l.area());
    let n_light_instances = mcguire
        .instances
        .iter()
        .filter(|i| i.light.is_some())
        .count();
    assert_eq!(n_light_instances, 1);

    for m in [
        "back",
        "ceiling",
        "floor",
        "greenwall",
        "largebox",
        "luminaire",
        "redwall",
        "smallbox",
    ] {
        let s = load(&format!("cornell_box_mitsuba/meshes/cbox_{m}.obj"));
        assert!(s.triangle_count() >= 2, "{m}");
    }
}

#[test]
fn scene_file_animations_sample_as_hand_computed() {
    let dir = tmp("anim");
    let path = write(
        &dir,
        "moving.toml",
        r#"
[[include]]
name = "box"
builtin = "cornell-box"
translate = [1.0, 0.0, 0.0]
dynamic = true

[[light]]
name = "key"
type = "point"
intensity = 4.0
position = [0.0, 2.0, 0.0]

[[animation]]
target = "box"
name = "slide"
times = [0.0, 2.0]
translate = [[0.0, 0.0, 0.0], [0.0, 0.0, 0.5]]
repeat = "loop"

[[animation]]
target = "key"
times = [0.0, 1.0]
intensity = [4.0, 0.0]
position = [[0.0, 2.0, 0.0], [0.0, 3.0, 0.0]]
"#,
    );
    let s = voxgi_scene::io::load(&path).expect("loads");
    assert_eq!(s.animations.len(), 2);
    assert_eq!(s.animations[0].name, "slide");
    assert_eq!(s.animations[0].duration(), 2.0);
    let rest: Vec<_> = s.instances.iter().map(|i| i.transform).collect();
    // Half way through the slide: 0.25 m along +z on top of the include's placement.
    let half = s.at_time(1.0);
    for (i, r) in half.instances.iter().zip(&rest) {
        let want = glam::Mat4::from_translation(Vec3::new(0.0, 0.0, 0.25)) * *r;
        assert!(i.transform.abs_diff_eq(want, 1e-6), "{}", i.name);
    }
    let key = half.lights.iter().find(|l| l.name == "key").unwrap();
    assert_eq!(key.intensity, 0.0);
    assert!(close(key.position, Vec3::new(0.0, 3.0, 0.0)));
    // Looping: t = 2.5 is t = 0.5.
    let a = s.at_time(2.5);
    let b = s.at_time(0.5);
    assert_eq!(a.instances[0].transform, b.instances[0].transform);
}

/// The scene's camera follows its keyframes (eye, aim, field of view) and generators; a scene
/// whose only animation is the camera's moves no geometry.
#[test]
fn a_camera_follows_its_keyframes_and_orbits() {
    let dir = tmp("anim-camera");
    let path = write(
        &dir,
        "flight.toml",
        r#"
[[include]]
builtin = "cornell-box"

[camera]
position = [0.0, 1.0, 4.0]
target = [0.0, 1.0, 0.0]
fov = 40.0

[[animation]]
target = "camera"
name = "flight"
times = [0.0, 2.0]
position = [[0.0, 1.0, 4.0], [2.0, 1.0, 4.0]]
look_at = [[0.0, 1.0, 0.0], [2.0, 1.0, 0.0]]
fov = [40.0, 60.0]
"#,
    );
    let s = voxgi_scene::io::load(&path).expect("loads");
    assert_eq!(s.animations.len(), 1);
    assert_eq!(s.animations[0].duration(), 2.0);
    assert!(s.camera_is_animated(0));
    assert!(
        s.animated_instances().is_empty(),
        "a camera moves no geometry"
    );
    // Half way: the eye and the aim both 1 m along +x, the field of view half way.
    let c = s.camera_at(0, 1.0).unwrap();
    assert!(
        close(c.position, Vec3::new(1.0, 1.0, 4.0)),
        "{}",
        c.position
    );
    assert!(close(c.forward, Vec3::NEG_Z), "{}", c.forward);
    assert!(close(c.up, Vec3::Y), "{}", c.up);
    match c.projection {
        voxgi_scene::Projection::Perspective { yfov } => {
            assert!(
                (yfov.to_degrees() - 50.0).abs() < 1e-4,
                "{}",
                yfov.to_degrees()
            )
        }
        p => panic!("{p:?}"),
    }
    // set_time moves the scene's own copy the same way.
    assert_eq!(s.at_time(1.0).cameras[0], c);
    // Past the last keyframe it holds (clamp).
    assert!(close(
        s.camera_at(0, 9.0).unwrap().position,
        Vec3::new(2.0, 1.0, 4.0)
    ));

    // An orbit turns the camera's whole frame about the axis: a quarter period about +Y
    // through the origin takes the eye from +z to +x, still looking at the axis.
    let path = write(
        &dir,
        "orbit.toml",
        r#"
[camera]
position = [0.0, 1.0, 4.0]
target = [0.0, 1.0, 0.0]

[[animation]]
target = "camera"
orbit = { center = [0.0, 0.0, 0.0], axis = [0.0, 1.0, 0.0], period = 8.0 }
"#,
    );
    let s = voxgi_scene::io::load(&path).expect("loads");
    let c = s.camera_at(0, 2.0).unwrap();
    assert!(
        close(c.position, Vec3::new(4.0, 1.0, 0.0)),
        "{}",
        c.position
    );
    assert!(close(c.forward, Vec3::NEG_X), "{}", c.forward);
    assert!(close(c.up, Vec3::Y), "{}", c.up);
}

/// An include sampled as points and marked dynamic moves with its animation (it stood still,
/// silently, when only instances moved), and the scene's bounds cover where it goes.
#[test]
fn an_animated_point_include_moves() {
    let dir = tmp("anim-points");
    let path = write(
        &dir,
        "moving-points.toml",
        r#"
[[include]]
name = "boxes"
builtin = "cube"
points = 0.1
dynamic = true

[[animation]]
target = "boxes"
times = [0.0, 2.0]
translate = [[0.0, 0.0, 0.0], [3.0, 0.0, 0.0]]
"#,
    );
    let s = voxgi_scene::io::load(&path).expect("loads");
    assert!(s.instances.is_empty(), "the cube became points");
    assert!(!s.point_clouds.is_empty());
    assert!(s.point_clouds.iter().all(|pc| pc.dynamic));
    let rest: Vec<_> = s.point_clouds.iter().map(|pc| pc.transform).collect();
    let half = s.at_time(1.0);
    for (pc, r) in half.point_clouds.iter().zip(&rest) {
        let want = glam::Mat4::from_translation(Vec3::new(1.5, 0.0, 0.0)) * *r;
        assert!(pc.transform.abs_diff_eq(want, 1e-6), "{}", pc.name);
    }
    // The box around every pose: the cube at rest spans x -0.5..0.5, at t = 2 2.5..3.5.
    let b = s.drawn_bounds();
    assert!(b.min.x <= -0.5 + 1e-4 && b.max.x >= 3.5 - 1e-4, "{b:?}");
}

#[test]
fn bad_animations_are_errors_naming_the_file_and_the_animation() {
    let dir = tmp("badanim");
    let head = "[[include]]\nname = \"box\"\nbuiltin = \"cornell-box\"\ndynamic = true\n\
                [[include]]\nname = \"fixed\"\nbuiltin = \"open-plane\"\n";
    let cases = [
        (
            "unknown target",
            "[[animation]]\ntarget = \"boxx\"\ntimes = [0.0]\ntranslate = [[0.0, 0.0, 0.0]]\n",
            "no include",
        ),
        (
            "static include",
            "[[animation]]\ntarget = \"fixed\"\ntimes = [0.0]\ntranslate = [[0.0, 0.0, 0.0]]\n",
            "dynamic = true",
        ),
        (
            "unsorted",
            "[[animation]]\ntarget = \"box\"\ntimes = [1.0, 0.5]\ntranslate = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]\n",
            "sorted",
        ),
        (
            "count",
            "[[animation]]\ntarget = \"box\"\ntimes = [0.0, 1.0]\ntranslate = [[0.0, 0.0, 0.0]]\n",
            "2 keyframe times but 1",
        ),
        (
            "empty",
            "[[animation]]\ntarget = \"box\"\ntimes = []\ntranslate = []\n",
            "at least one",
        ),
        (
            "non-finite",
            "[[animation]]\ntarget = \"box\"\ntimes = [0.0, nan]\ntranslate = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]\n",
            "finite",
        ),
        (
            "nothing",
            "[[animation]]\ntarget = \"box\"\n",
            "nothing moves",
        ),
        (
            "no times",
            "[[animation]]\ntarget = \"box\"\ntranslate = [[0.0, 0.0, 0.0]]\n",
            "needs keyframe `times`",
        ),
        (
            "bad period",
            "[[animation]]\ntarget = \"box\"\norbit = { center = [0.0, 0.0, 0.0], axis = [0.0, 1.0, 0.0], period = 0.0 }\n",
            "period",
        ),
        (
            "camera with include keys",
            "[camera]\nposition = [0.0, 0.0, 1.0]\ntarget = [0.0, 0.0, 0.0]\n\
             [[animation]]\ntarget = \"camera\"\ntimes = [0.0]\ntranslate = [[0.0, 0.0, 0.0]]\n",
            "a camera takes",
        ),
        (
            "camera fov",
            "[camera]\nposition = [0.0, 0.0, 1.0]\ntarget = [0.0, 0.0, 0.0]\n\
             [[animation]]\ntarget = \"camera\"\ntimes = [0.0]\nfov = [200.0]\n",
            "fov 200",
        ),
        (
            "camera aims twice",
            "[camera]\nposition = [0.0, 0.0, 1.0]\ntarget = [0.0, 0.0, 0.0]\n\
             [[animation]]\ntarget = \"camera\"\ntimes = [0.0]\n\
             look_at = [[0.0, 0.0, 0.0]]\ndirection = [[0.0, 0.0, -1.0]]\n",
            "not both",
        ),
        (
            "bad interpolation",
            "[[animation]]\ntarget = \"box\"\ninterpolation = \"smooth\"\ntimes = [0.0]\ntranslate = [[0.0, 0.0, 0.0]]\n",
            "smooth",
        ),
    ];
    for (what, body, fragment) in cases {
        let path = write(&dir, "a.toml", format!("{head}{body}"));
        let e = voxgi_scene::io::load(&path)
            .err()
            .unwrap_or_else(|| panic!("{what}: accepted"))
            .to_string();
        assert!(
            e.contains("a.toml") && e.contains("animation 1") && e.contains(fragment),
            "{what}: {e}"
        );
    }
    // The builtin boxes bring their cameras; a scene without any has nothing to fly.
    let path = write(
        &dir,
        "a.toml",
        "[[animation]]\ntarget = \"camera\"\ntimes = [0.0]\nposition = [[0.0, 0.0, 1.0]]\n",
    );
    let e = voxgi_scene::io::load(&path)
        .expect_err("accepted")
        .to_string();
    assert!(e.contains("no camera to animate"), "{e}");
}

#[test]
fn ply_point_emission_and_scene_file_points() {
    let dir = tmp("points");
    // A cloud with emitted radiance per point, read as written (linear, any numeric type).
    let p = write(
        &dir,
        "glow.ply",
        "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n\
         property float emission_red\nproperty float emission_green\nproperty uchar emission_blue\nend_header\n\
         0 0 0 1.5 0.25 2\n1 0 0 0 0 0\n",
    );
    let s = io::load(&p).unwrap();
    assert_eq!(s.point_clouds[0].emission, vec![[1.5, 0.25, 2.0], [0.0; 3]]);
    // Some but not all of the three, or a negative radiance: errors naming the problem.
    let partial = write(
        &dir,
        "partial.ply",
        "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n\
         property float emission_red\nend_header\n0 0 0 1\n",
    );
    let e = io::load(&partial).unwrap_err().to_string();
    assert!(e.contains("partial.ply") && e.contains("emission"), "{e}");
    let negative = write(
        &dir,
        "negative.ply",
        "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n\
         property float emission_r\nproperty float emission_g\nproperty float emission_b\nend_header\n0 0 0 1 -1 0\n",
    );
    let e = io::load(&negative).unwrap_err().to_string();
    assert!(e.contains("vertex 0") && e.contains("emission"), "{e}");

    // A scene file includes a mesh as its vertices and as a lattice of points; an emissive
    // override reaches the points.
    let quad = write(
        &dir,
        "quad.ply",
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
         element face 1\nproperty list uchar int vertex_indices\nend_header\n\
         0 0 0\n1 0 0\n1 0 1\n0 0 1\n4 0 3 2 1\n",
    );
    let scene = write(
        &dir,
        "points.toml",
        format!(
            "[[include]]\nfile = '{}'\npoints = 'vertices'\nmaterial = {{ base_color = [0.2, 0.4, 0.6], emissive = [3.0, 2.0, 1.0] }}\n\
             [[include]]\nfile = '{}'\npoints = 0.1\ntranslate = [0.0, 1.0, 0.0]\n\
             [[include]]\nfile = '{}'\npoints = 0.1\nscale = [2.0, 1.0, 0.5]\n",
            quad.display(),
            quad.display(),
            quad.display()
        ),
    );
    let s = io::load(&scene).unwrap();
    assert!(s.instances.is_empty(), "the meshes became points");
    assert_eq!(s.point_clouds.len(), 3);
    // The lattice is laid in the world, after the include's scale: 20 x 5 points on the
    // 2 m x 0.5 m rectangle, not 10 x 10 stretched with it.
    let scaled = &s.point_clouds[2];
    assert_eq!(scaled.positions.len(), 100);
    assert_eq!(scaled.transform, Mat4::IDENTITY);
    let xs: std::collections::BTreeSet<i64> = scaled
        .positions
        .iter()
        .map(|p| (p.x * 1000.0).round() as i64)
        .collect();
    assert_eq!(xs.len(), 20);
    let v = &s.point_clouds[0];
    assert_eq!(v.positions.len(), 4);
    assert_eq!(v.colors, vec![[0.2, 0.4, 0.6]; 4]);
    assert_eq!(v.emission, vec![[3.0, 2.0, 1.0]; 4]);
    assert!(v.normals.iter().all(|n| close(*n, Vec3::Y)));
    // A 1 m square on a 0.1 m lattice: 10 x 10 points, at height 1 after the include's move.
    let l = &s.point_clouds[1];
    assert_eq!(l.positions.len(), 100);
    assert!(
        l.positions
            .iter()
            .all(|&p| (l.transform.transform_point3(p).y - 1.0).abs() < 1e-6)
    );
    // Bad values name the key.
    for (value, what) in [
        ("'edges'", "points"),
        ("-1.0", "points"),
        ("1e-9", "points"),
    ] {
        let bad = write(
            &dir,
            "bad_points.toml",
            format!(
                "[[include]]\nfile = '{}'\npoints = {value}\n",
                quad.display()
            ),
        );
        let e = io::load(&bad).unwrap_err().to_string();
        assert!(e.contains(what), "points = {value}: {e}");
    }
}

#[test]
fn sampled_surfaces_lie_on_a_lattice_with_the_meshes_attributes() {
    // The Cornell box's floor is 0.5496-0.5528 m by 0.5592 m: on a 1 cm lattice about 55 x 56
    // points, every one on the floor's plane with its normal and colour.
    let s = builtin::cornell_box();
    let p = pointcloud::sample_surfaces(&s, 0.01);
    let floor = p
        .point_clouds
        .iter()
        .find(|c| c.name.starts_with("floor"))
        .expect("floor points");
    assert!(
        (3000..=3130).contains(&floor.positions.len()),
        "{} floor points",
        floor.positions.len()
    );
    assert!(floor.positions.iter().all(|q| q.y.abs() < 1e-6));
    assert!(floor.normals.iter().all(|n| close(*n, Vec3::Y)));
    // The area light's emitter stays a mesh; everything else became points.
    assert_eq!(p.instances.len(), 1);
    assert!(p.instances[0].light.is_some());
    assert_eq!(p.point_clouds.len(), s.instances.len() - 1);
    // The points' share of the box's area: each stands for at least spacing² of surface.
    let area = pointcloud::surface_area(&s);
    let n: usize = p.point_clouds.iter().map(|c| c.positions.len()).sum();
    assert!(
        n as f64 <= area / (0.01 * 0.01) * 1.05,
        "{n} points on {area} m²"
    );
}

#[test]
fn the_point_cave_is_a_deterministic_tunnel() {
    let a = builtin::point_cave(20_000);
    let b = builtin::point_cave(20_000);
    let (pa, pb) = (&a.point_clouds[0], &b.point_clouds[0]);
    assert_eq!(pa.positions, pb.positions, "the same cloud every time");
    assert_eq!(pa.positions.len(), 20_000);
    assert!(pa.normals.is_empty(), "a raw scan: normals are estimated");
    // Every point on the wall of a tunnel about 2.5 m in radius (the ripples reach 0.63 m, the
    // floor cuts it 1.6 m below the axis) between z = 0 and 16.
    for p in &pa.positions {
        assert!((0.0..=16.0).contains(&p.z), "{p}");
        let axis = Vec2::new(0.8 * (p.z * 0.35).sin(), 0.3 * (p.z * 0.5).cos());
        let r = (Vec2::new(p.x, p.y) - axis).length();
        assert!((1.5..=3.2).contains(&r), "{p}: {r} m from the axis");
    }
    assert_eq!(a.lights.len(), 3);
    assert_eq!(
        builtin::by_name("point-cave").unwrap().point_count(),
        builtin::POINT_CAVE_POINTS
    );
}

/// What a loader accepts but should not pass over in silence: float colours above 1 (clamped)
/// and data after the last element a PLY header declares (a wrong count), in both encodings.
#[test]
fn ply_oddities_are_warned_about() {
    let dir = tmp("ply_warn");
    let head = |fmt: &str| {
        format!(
            "ply\nformat {fmt} 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nproperty float red\nproperty float green\nproperty float blue\nend_header\n"
        )
    };
    let bright = write(&dir, "bright.ply", head("ascii") + "0 0 0 1.5 0.5 2\n");
    let (scene, w) = load_warned(&bright);
    assert_eq!(scene.unwrap().point_clouds[0].colors[0], [1.0, 0.5, 1.0]);
    assert!(
        w.iter()
            .any(|w| w.contains("2 float colour values above 1")),
        "{w:?}"
    );

    let ascii = write(
        &dir,
        "ascii_tail.ply",
        head("ascii") + "0 0 0 0.5 0.5 0.5\n1 1 1 0.5 0.5 0.5\n\n",
    );
    let (scene, w) = load_warned(&ascii);
    assert_eq!(scene.unwrap().point_clouds[0].positions.len(), 1);
    assert!(
        w.iter()
            .any(|w| w.contains("1 lines after the last element")),
        "{w:?}"
    );

    let mut bin = head("binary_little_endian").into_bytes();
    for v in [0f32, 0.0, 0.0, 0.5, 0.5, 0.5] {
        bin.extend(v.to_le_bytes());
    }
    bin.extend([7u8; 5]);
    let binary = write(&dir, "bin_tail.ply", bin);
    let (scene, w) = load_warned(&binary);
    assert_eq!(scene.unwrap().point_clouds[0].positions.len(), 1);
    assert!(
        w.iter()
            .any(|w| w.contains("5 bytes after the last element")),
        "{w:?}"
    );

    // A file that ends where its header says warns about nothing.
    let exact = write(&dir, "exact.ply", head("ascii") + "0 0 0 0.5 0.5 0.5\n");
    let (scene, w) = load_warned(&exact);
    assert!(scene.is_ok() && w.is_empty(), "{w:?}");
}

/// The volume's box leaves out what lies far outside the rest (`Scene::bulk_bounds`): a stray
/// cube a kilometre or 1e30 m from the Cornell box is left out by name, the box is the Cornell
/// box's, and the default camera looks at it; objects alike far apart are all kept.
#[test]
fn the_bulk_leaves_out_what_lies_far_outside_the_rest() {
    let room = builtin::cornell_box();
    let room_box = room.bounds();
    for x in [1e3f32, 1e30] {
        let mut s = room.clone();
        s.cameras.clear();
        let cube = builtin::cube([0.5; 3]);
        let i = s.add_mesh(
            cube.meshes[0].clone(),
            cube.materials[0].clone(),
            Mat4::from_translation(Vec3::new(x, 0.0, 0.0)) * Mat4::from_scale(Vec3::splat(0.1)),
        );
        s.instances[i].name = "stray".into();
        s.validate().unwrap();
        let (bulk, left_out) = s.bulk_bounds();
        assert_eq!(left_out, ["stray"], "at x = {x}");
        assert_eq!(bulk, room_box, "at x = {x}");
        let cam = s.default_camera();
        assert!(cam.position.is_finite() && cam.position.distance(room_box.center()) < 10.0);
        // What the far plane must reach still holds it.
        assert!(s.drawn_bounds().max.x >= x);
    }
    // A far larger object away from small ones is the scene, not a stray: a 10 m cube 1 km
    // from 10 cm ones keeps them all.
    let mut pair = builtin::cube([0.5; 3]);
    pair.instances[0].transform = Mat4::from_scale(Vec3::splat(10.0));
    let m = pair.meshes[0].clone();
    let mat = pair.materials[0].clone();
    for k in 0..3 {
        pair.add_mesh(
            m.clone(),
            mat.clone(),
            Mat4::from_translation(Vec3::new(1e3 + 0.01 * k as f32, 0.0, 0.0))
                * Mat4::from_scale(Vec3::splat(0.1)),
        );
    }
    let (_, left_out) = pair.bulk_bounds();
    assert!(left_out.is_empty(), "{left_out:?}");
    // Two rooms a kilometre apart: neither is a stray (at most a quarter of the objects go).
    let mut two = room.clone();
    let n = two.instances.len();
    for i in 0..n {
        let mut inst = two.instances[i].clone();
        inst.transform = Mat4::from_translation(Vec3::new(1e3, 0.0, 0.0)) * inst.transform;
        two.instances.push(inst);
    }
    let (bulk, left_out) = two.bulk_bounds();
    assert!(left_out.is_empty(), "{left_out:?}");
    assert!(bulk.max.x > 1e3);
}

/// Geometry that can show nothing is named: a zero scale, a triangle of 1e-30 m sides (its
/// area underflows), a cloud of points all at one place; a sound scene names nothing.
#[test]
fn degenerate_geometry_is_named() {
    assert!(builtin::cornell_box().degenerate().is_empty());
    let mut s = builtin::cube([0.5; 3]);
    s.instances[0].transform = Mat4::from_scale(Vec3::ZERO);
    let d = s.degenerate();
    assert!(
        d.len() == 1 && d[0].contains("12 triangles have no area"),
        "{d:?}"
    );

    let dir = tmp("degenerate");
    let tiny = write(
        &dir,
        "tiny.obj",
        "v 0 0 0\nv 1e-30 0 0\nv 0 1e-30 0\nf 1 2 3\n",
    );
    let d = io::load(&tiny).unwrap().degenerate();
    assert!(
        d.len() == 1 && d[0].contains("1 triangles have no area"),
        "{d:?}"
    );

    let pc = PointCloud {
        name: "dot".into(),
        positions: vec![Vec3::ONE; 5],
        colors: vec![[0.5; 3]; 5],
        ..Default::default()
    };
    let s = voxgi_scene::Scene {
        point_clouds: vec![pc],
        ..Default::default()
    };
    let d = s.degenerate();
    assert!(
        d.len() == 1 && d[0].contains("all its 5 points lie at one place"),
        "{d:?}"
    );
}

/// `[[view]]`s are named cameras after the scene's others (the `[camera]` first, then the
/// included files'), in the file's order; a view without a name, or a `[camera]` with one, is
/// an error that says so.
#[test]
fn scene_file_views_are_named_cameras_after_the_others() {
    let dir = tmp("views");
    let main = write(
        &dir,
        "views.toml",
        r#"[[include]]
builtin = "cornell-box"

[camera]
position = [0.0, 0.0, 3.0]
target = [0.0, 0.0, 0.0]

[[view]]
name = "left"
position = [-2.0, 0.5, 1.0]
target = [0.0, 0.5, 0.0]
fov = 30.0

[[view]]
name = "above"
position = [0.0, 4.0, 0.1]
target = [0.0, 0.0, 0.0]
"#,
    );
    let scene = io::load(&main).unwrap();
    let names: Vec<&str> = scene.cameras.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names.first(), Some(&"scene file camera"));
    assert_eq!(&names[names.len() - 2..], ["left", "above"]);
    let left = &scene.cameras[names.len() - 2];
    assert!(left.position.distance(Vec3::new(-2.0, 0.5, 1.0)) < 1e-6);
    assert!(
        matches!(left.projection, Projection::Perspective { yfov } if (yfov.to_degrees() - 30.0).abs() < 1e-4)
    );

    let unnamed = write(
        &dir,
        "unnamed.toml",
        "[[view]]\nposition = [0.0, 0.0, 1.0]\ntarget = [0.0, 0.0, 0.0]\n",
    );
    let e = io::load(&unnamed).unwrap_err().to_string();
    assert!(e.contains("view 1") && e.contains("needs a name"), "{e}");
    let named = write(
        &dir,
        "named.toml",
        "[camera]\nname = \"x\"\nposition = [0.0, 0.0, 1.0]\ntarget = [0.0, 0.0, 0.0]\n",
    );
    let e = io::load(&named).unwrap_err().to_string();
    assert!(e.contains("[[view]]"), "{e}");
}

#[test]
fn an_array_include_places_copies_that_share_its_meshes() {
    let dir = tmp("array");
    let main = write(
        &dir,
        "array.toml",
        r#"[[include]]
builtin = "cube"
translate = [1.0, 2.0, 3.0]
scale = [2.0, 1.0, 1.0]
array = { count = [3, 1, 2], spacing = [10.0, 0.0, -5.0] }
"#,
    );
    let scene = io::load(&main).unwrap();
    // One mesh, six instances: the copies add transforms, not triangles.
    assert_eq!(scene.meshes.len(), 1);
    assert_eq!(scene.instances.len(), 6);
    assert!(scene.instances.iter().all(|i| i.mesh == 0));
    // Copy (i, k) is the include moved by (10 i, 0, -5 k) in the world, after its own scale:
    // the cube's corner (0.5, 0.5, 0.5) lands at (1 + 1 + 10 i, 2.5, 3.5 - 5 k).
    let corner = Vec3::splat(0.5);
    for (n, inst) in scene.instances.iter().enumerate() {
        let (i, k) = ((n % 3) as f32, (n / 3) as f32);
        let p = inst.transform.transform_point3(corner);
        assert!(
            close(p, Vec3::new(2.0 + 10.0 * i, 2.5, 3.5 - 5.0 * k)),
            "copy {n}: {p}"
        );
    }

    let bad = [
        ("count = [0, 1, 1]", "at least 1"),
        ("count = [1000, 1, 1000]", "at most 65536"),
        ("count = [2, 1, 1], spacing = [nan, 0.0, 0.0]", "finite"),
        ("count = [1, 3, 1], spacing = [5.0, 0.0, 5.0]", "0 along y"),
    ];
    for (array, says) in bad {
        let f = write(
            &dir,
            "bad.toml",
            format!("[[include]]\nbuiltin = \"cube\"\narray = {{ {array} }}\n"),
        );
        let e = io::load(&f).unwrap_err().to_string();
        assert!(e.contains("include 1") && e.contains(says), "{array}: {e}");
    }
    // The Cornell box holds an area light: copying its meshes would leave the copies' lamps
    // dark, so it is refused.
    let f = write(
        &dir,
        "lit.toml",
        "[[include]]\nbuiltin = \"cornell-box\"\narray = { count = [2, 1, 1], spacing = [3.0, 0.0, 0.0] }\n",
    );
    let e = io::load(&f).unwrap_err().to_string();
    assert!(e.contains("lights") && e.contains("once per copy"), "{e}");
}

/// examples/town.toml is what its comment says: a town over 500 m across, sixteen Sponzas
/// sharing one set of meshes, and a camera that walks at 5 m/s, then drives at 20 m/s.
#[test]
fn the_town_example_is_a_town_of_shared_copies_and_a_flight() {
    let Some(_) = shared_scenes() else { return };
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/town.toml");
    let scene = io::load(&file).unwrap();
    let size = scene.bounds().size();
    assert!(size.x >= 500.0 && size.z >= 500.0, "{size}");
    // Sponza's OBJ holds 20-odd meshes: sixteen copies add instances, not meshes.
    assert!(scene.meshes.len() < 50, "{} meshes", scene.meshes.len());
    assert!(
        scene.instances.len() > 600,
        "{} instances",
        scene.instances.len()
    );
    assert!(
        scene.triangle_count() > 1_500_000,
        "{}",
        scene.triangle_count()
    );
    let at = |t: f32| scene.camera_at(0, t).expect("the flight").position;
    // Linear keyframes: the speeds are exact up to f32 rounding of positions 230 m out.
    let walk = at(16.0).distance(at(0.0)) / 16.0;
    let drive = at(35.0).distance(at(16.0)) / 19.0;
    assert!(
        (walk - 5.0).abs() < 1e-3 && (drive - 20.0).abs() < 0.02,
        "{walk} {drive}"
    );
}

/// An ASCII PLY of points (no attributes) for sequence tests.
fn points_ply(points: &[[f32; 3]]) -> String {
    let mut s = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty float x\nproperty float y\n\
         property float z\nend_header\n",
        points.len()
    );
    for p in points {
        s += &format!("{} {} {}\n", p[0], p[1], p[2]);
    }
    s
}

#[test]
fn a_sequence_of_point_files_plays_at_its_frame_rate() {
    let dir = tmp("sequence");
    std::fs::create_dir_all(dir.join("scan")).unwrap();
    // Frame k: k + 2 points along x at height k; frame 2 is the largest and reaches farthest.
    for k in 0..3 {
        let pts: Vec<[f32; 3]> = (0..k + 2).map(|i| [i as f32, k as f32, 0.0]).collect();
        write(
            &dir.join("scan"),
            &format!("f_{k:03}.ply"),
            points_ply(&pts),
        );
    }
    let toml = |extra: &str| {
        format!(
            "[[include]]\nname = \"scan\"\nfile = \"scan/f_%03d.ply\"\ndynamic = true\n\
             translate = [10.0, 0.0, 0.0]\n{extra}\n"
        )
    };
    let file = write(&dir, "seq.toml", toml("fps = 2.0\nrepeat = \"loop\""));
    let mut scene = io::load(&file).unwrap();
    assert_eq!(scene.sequences.len(), 1);
    let seq = scene.sequences[0].clone();
    assert_eq!((seq.cloud, seq.files.len(), seq.capacity), (0, 3, 4));
    assert_eq!(seq.duration(), 1.5);
    // The first frame is loaded, placed by the include.
    let pc = &scene.point_clouds[0];
    assert!(pc.dynamic);
    assert_eq!(pc.positions, vec![Vec3::ZERO, Vec3::X]);
    assert_eq!(
        pc.transform,
        Mat4::from_translation(Vec3::new(10.0, 0.0, 0.0))
    );
    // Every frame's points are inside the bounds, whichever frame the cloud holds.
    let b = scene.swept_bounds();
    assert_eq!(
        (b.min, b.max),
        (Vec3::new(10.0, 0.0, 0.0), Vec3::new(13.0, 2.0, 0.0))
    );
    // 2 fps: t = 0.5 is frame 1, t = 1.2 frame 2, and looping, t = 1.5 frame 0 again.
    for (t, frame) in [(0.5, 1usize), (1.2, 2), (1.5, 0), (-0.1, 2), (3.6, 1)] {
        scene.load_frames_at(t).unwrap();
        let pc = &scene.point_clouds[0];
        assert_eq!(pc.positions.len(), frame + 2, "t = {t}");
        assert_eq!(
            pc.positions[1],
            Vec3::new(1.0, frame as f32, 0.0),
            "t = {t}"
        );
        assert_eq!(
            pc.transform,
            Mat4::from_translation(Vec3::new(10.0, 0.0, 0.0))
        );
        assert_eq!(scene.swept_bounds(), b, "t = {t}");
    }
    scene.validate().unwrap();
    // Clamped (the default), past the end holds the last frame.
    let file = write(&dir, "clamp.toml", toml("fps = 2.0"));
    let mut scene = io::load(&file).unwrap();
    scene.load_frames_at(100.0).unwrap();
    assert_eq!(scene.point_clouds[0].positions.len(), 4);
    // Appended into another scene, the sequence follows its cloud.
    let outer = write(
        &dir,
        "outer.toml",
        "[[include]]\nbuiltin = \"cornell-box\"\n[[include]]\nfile = \"clamp.toml\"\n",
    );
    let scene = io::load(&outer).unwrap();
    assert_eq!(scene.sequences[0].cloud, scene.point_clouds.len() - 1);
    assert_eq!(
        scene.point_clouds[scene.sequences[0].cloud].positions.len(),
        2
    );

    // What is wrong is said, with the key or the file.
    let error = |name: &str, extra: &str| {
        let f = write(&dir, name, extra);
        io::load(&f).unwrap_err().to_string()
    };
    let static_seq = error(
        "static.toml",
        "[[include]]\nfile = \"scan/f_%03d.ply\"\nfps = 2.0\n",
    );
    assert!(static_seq.contains("dynamic = true"), "{static_seq}");
    let no_fps = error("nofps.toml", &toml(""));
    assert!(no_fps.contains("`fps`"), "{no_fps}");
    let bad_fps = error("badfps.toml", &toml("fps = 0.0"));
    assert!(bad_fps.contains("fps"), "{bad_fps}");
    let missing = error(
        "missing.toml",
        "[[include]]\nfile = \"scan/g_%03d.ply\"\ndynamic = true\nfps = 2.0\n",
    );
    assert!(missing.contains("g_000.ply"), "{missing}");
    let not_seq = error(
        "notseq.toml",
        "[[include]]\nfile = \"scan/f_000.ply\"\nfps = 2.0\n",
    );
    assert!(not_seq.contains("frame number"), "{not_seq}");
    // A frame that is not a point cloud names its file.
    write(
        &dir.join("scan"),
        "f_003.ply",
        "ply\nformat ascii 1.0\nend_header\n",
    );
    let bad_frame = error("badframe.toml", &toml("fps = 2.0"));
    assert!(bad_frame.contains("f_003.ply"), "{bad_frame}");
}
