//! Integration tests of the glTF loader: hand-built round trips, the Khronos conformance samples,
//! and malformed input that must fail with a message naming the file, never a panic.

use serde_json::{Value, json};
use std::path::{Path, PathBuf};
use voxgi_scene::glam::{Mat4, Vec2, Vec3};
use voxgi_scene::{AlphaMode, LightKind, Projection, Scene, io};

mod common;
use common::load_warned;

// ------------------------------------------------------------------------------------------
// Helpers: building glTF files in memory

fn base64(data: &[u8]) -> String {
    const T: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::new();
    for c in data.chunks(3) {
        let b = [c[0], *c.get(1).unwrap_or(&0), *c.get(2).unwrap_or(&0)];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= c.len() {
                s.push(T[(n >> (18 - 6 * k)) as usize & 63] as char);
            } else {
                s.push('=');
            }
        }
    }
    s
}

/// Binary data plus buffer views/accessors describing it.
#[derive(Default)]
struct Bin {
    data: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Bin {
    fn align(&mut self) {
        while !self.data.len().is_multiple_of(4) {
            self.data.push(0);
        }
    }

    /// Appends bytes as a new buffer view; returns the view index.
    fn view(&mut self, bytes: &[u8]) -> usize {
        self.align();
        self.views
            .push(json!({"buffer": 0, "byteOffset": self.data.len(), "byteLength": bytes.len()}));
        self.data.extend_from_slice(bytes);
        self.views.len() - 1
    }

    fn accessor(&mut self, view: usize, component: u32, count: usize, ty: &str) -> usize {
        self.accessors.push(
            json!({"bufferView": view, "componentType": component, "count": count, "type": ty}),
        );
        self.accessors.len() - 1
    }

    fn vec3(&mut self, v: &[[f32; 3]]) -> usize {
        let bytes: Vec<u8> = v.iter().flatten().flat_map(|f| f.to_le_bytes()).collect();
        let view = self.view(&bytes);
        self.accessor(view, 5126, v.len(), "VEC3")
    }

    fn vec2(&mut self, v: &[[f32; 2]]) -> usize {
        let bytes: Vec<u8> = v.iter().flatten().flat_map(|f| f.to_le_bytes()).collect();
        let view = self.view(&bytes);
        self.accessor(view, 5126, v.len(), "VEC2")
    }

    fn u16s(&mut self, v: &[u16]) -> usize {
        let bytes: Vec<u8> = v.iter().flat_map(|f| f.to_le_bytes()).collect();
        let view = self.view(&bytes);
        self.accessor(view, 5123, v.len(), "SCALAR")
    }

    fn f32s(&mut self, v: &[f32]) -> usize {
        let bytes: Vec<u8> = v.iter().flat_map(|f| f.to_le_bytes()).collect();
        let view = self.view(&bytes);
        self.accessor(view, 5126, v.len(), "SCALAR")
    }

    fn vec4(&mut self, v: &[[f32; 4]]) -> usize {
        let bytes: Vec<u8> = v.iter().flatten().flat_map(|f| f.to_le_bytes()).collect();
        let view = self.view(&bytes);
        self.accessor(view, 5126, v.len(), "VEC4")
    }
}

fn tmp_dir() -> PathBuf {
    let d = std::env::temp_dir().join(format!("voxgi_gltf_tests_{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn write(name: &str, bytes: &[u8]) -> PathBuf {
    let p = tmp_dir().join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

fn glb(json: &Value, bin: &[u8]) -> Vec<u8> {
    let mut j = serde_json::to_vec(json).unwrap();
    while !j.len().is_multiple_of(4) {
        j.push(b' ');
    }
    let mut b = bin.to_vec();
    while !b.len().is_multiple_of(4) {
        b.push(0);
    }
    let total = 12 + 8 + j.len() + 8 + b.len();
    let mut out = Vec::new();
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(j.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&j);
    out.extend_from_slice(&(b.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&b);
    out
}

fn png(img: image::DynamicImage) -> Vec<u8> {
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

fn aabb_of(scene: &Scene, inst: usize) -> (Vec3, Vec3) {
    let i = &scene.instances[inst];
    let m = &scene.meshes[i.mesh];
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for &p in &m.positions {
        let w = i.transform.transform_point3(p);
        lo = lo.min(w);
        hi = hi.max(w);
    }
    (lo, hi)
}

fn close3(a: Vec3, b: Vec3, tol: f32) -> bool {
    (a - b).abs().max_element() <= tol
}

// ------------------------------------------------------------------------------------------
// Round trips

const QUAD_POS: [[f32; 3]; 4] = [[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]];
const QUAD_UV: [[f32; 2]; 4] = [[0., 1.], [1., 1.], [1., 0.], [0., 0.]];
const QUAD_IDX: [u16; 6] = [0, 1, 2, 0, 2, 3];

/// A document with: a textured quad (normals, UVs, u16 indices) under a parent node, a
/// non-indexed triangle without normals, a rotated spot light, a rotated camera, an orphan node
/// outside the default scene, and a material with every supported factor.
fn rich_document(uri: Option<String>) -> (Value, Vec<u8>) {
    let mut b = Bin::default();
    let pos = b.vec3(&QUAD_POS);
    let nrm = b.vec3(&[[0., 0., 1.]; 4]);
    let uv = b.vec2(&QUAD_UV);
    let idx = b.u16s(&QUAD_IDX);
    let tri = b.vec3(&[[0., 0., 0.], [0., 0., -2.], [0., 3., 0.]]);
    // 2x1 RGB image: red, green -> RGBA with opaque alpha.
    let img = png(image::DynamicImage::ImageRgb8(
        image::RgbImage::from_raw(2, 1, vec![255, 0, 0, 0, 255, 0]).unwrap(),
    ));
    let img_view = b.view(&img);
    b.align();
    let s = std::f32::consts::FRAC_1_SQRT_2;
    let mut buffer = json!({"byteLength": b.data.len()});
    if let Some(u) = uri {
        buffer["uri"] = json!(u.replace("{}", &base64(&b.data)));
    }
    let doc = json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_emissive_strength"],
        "scene": 0,
        "scenes": [{"nodes": [0, 2, 3, 4]}],
        "nodes": [
            {"name": "parent", "translation": [1.0, 2.0, 3.0], "scale": [2.0, 2.0, 2.0], "children": [1]},
            {"name": "child", "translation": [1.0, 0.0, 0.0], "mesh": 0},
            // -90 degrees about X: the light's -Z axis turns to -Y.
            {"name": "spot node", "translation": [0.0, 5.0, 0.0], "rotation": [-s, 0.0, 0.0, s],
             "extensions": {"KHR_lights_punctual": {"light": 0}}},
            // +90 degrees about Y: the camera's -Z axis turns to -X.
            {"name": "cam node", "translation": [0.0, 1.0, 5.0], "rotation": [0.0, s, 0.0, s], "camera": 0},
            {"mesh": 1},
            {"name": "orphan", "mesh": 0}
        ],
        "meshes": [
            {"name": "quad", "primitives": [{"attributes": {"POSITION": pos, "NORMAL": nrm, "TEXCOORD_0": uv}, "indices": idx, "material": 0}]},
            {"primitives": [{"attributes": {"POSITION": tri}}]}
        ],
        "materials": [{
            "name": "glowing",
            "pbrMetallicRoughness": {"baseColorFactor": [0.2, 0.4, 0.6, 0.5], "roughnessFactor": 0.3,
                                     "metallicFactor": 0.7, "baseColorTexture": {"index": 0}},
            "emissiveFactor": [1.0, 0.5, 0.25],
            "emissiveTexture": {"index": 0},
            "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4.0}},
            "alphaMode": "MASK", "alphaCutoff": 0.25, "doubleSided": true
        }],
        "textures": [{"source": 0}],
        "images": [{"bufferView": img_view, "mimeType": "image/png"}],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "spot", "name": "spotty", "color": [1.0, 0.5, 0.25], "intensity": 10.0, "range": 7.0,
             "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.6}}
        ]}},
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "aspectRatio": 1.5, "znear": 0.1, "zfar": 50.0}}],
        "buffers": [buffer],
        "bufferViews": b.views,
        "accessors": b.accessors,
    });
    (doc, b.data)
}

fn check_rich(scene: &Scene) {
    // Two glTF primitives -> two meshes; the orphan node adds no mesh and no instance.
    assert_eq!(scene.meshes.len(), 2);
    assert_eq!(scene.instances.len(), 2);
    let quad = &scene.meshes[0];
    let want_pos: Vec<Vec3> = QUAD_POS.iter().map(|&p| Vec3::from(p)).collect();
    let want_uv: Vec<Vec2> = QUAD_UV.iter().map(|&p| Vec2::from(p)).collect();
    // Exact: f32 values stored and read back bit for bit.
    assert_eq!(quad.positions, want_pos);
    assert_eq!(quad.uvs, want_uv);
    assert_eq!(quad.normals, vec![Vec3::Z; 4]);
    assert_eq!(quad.indices, QUAD_IDX.map(u32::from).to_vec());
    assert_eq!(quad.name, "quad");

    let tri = &scene.meshes[1];
    assert_eq!(
        tri.indices,
        vec![0, 1, 2],
        "non-indexed primitive gets 0..n"
    );
    // Computed normal of (0,0,0), (0,0,-2), (0,3,0): e1 x e2 = (0,0,-2) x (0,3,0) = (6,0,0) -> +X.
    // Exact: a single axis-aligned face normalises without rounding.
    assert_eq!(tri.normals, vec![Vec3::X; 3]);
    assert!(tri.uvs.is_empty());
    // No material on the triangle -> the default material, appended after the file's one.
    assert_eq!(scene.materials.len(), 2);
    assert_eq!(tri.material, 1);
    assert_eq!(scene.materials[1].name, "default");

    // Hierarchy: world = T(1,2,3) S(2) T(1,0,0); vertex (1,1,0) -> 2*(2,1,0) + (1,2,3) = (5,4,3).
    let inst = &scene.instances[0];
    assert_eq!(inst.name, "child");
    assert_eq!(inst.mesh, 0);
    let w = inst.transform.transform_point3(Vec3::new(1.0, 1.0, 0.0));
    // 1e-6: exact small integers through one f32 matrix product.
    assert!(close3(w, Vec3::new(5.0, 4.0, 3.0), 1e-6), "{w}");
    assert_eq!(scene.instances[1].name, "node 4");
    assert_eq!(scene.instances[1].transform, Mat4::IDENTITY);

    let m = &scene.materials[0];
    assert_eq!(m.name, "glowing");
    assert_eq!(m.base_color, [0.2, 0.4, 0.6, 0.5]);
    assert_eq!(m.base_color_texture, Some(0));
    // 4 x (1, 0.5, 0.25): exact in binary floating point.
    assert_eq!(m.emissive, [4.0, 2.0, 1.0]);
    assert_eq!(m.emissive_texture, Some(0));
    assert_eq!((m.roughness, m.metallic), (0.3, 0.7));
    assert_eq!(m.alpha_mode, AlphaMode::Mask(0.25));
    assert!(m.double_sided);

    assert_eq!(scene.textures.len(), 1);
    let t = &scene.textures[0];
    assert_eq!((t.width, t.height), (2, 1));
    assert_eq!(t.rgba8, vec![255, 0, 0, 255, 0, 255, 0, 255]);

    assert_eq!(scene.lights.len(), 1);
    let l = &scene.lights[0];
    assert_eq!(l.name, "spotty");
    assert_eq!(
        l.kind,
        LightKind::Spot {
            inner_angle: 0.2,
            outer_angle: 0.6
        }
    );
    assert_eq!(
        (l.color, l.intensity, l.range),
        ([1.0, 0.5, 0.25], 10.0, Some(7.0))
    );
    // 1e-6: the rotation is built from the rounded f32 value of 1/sqrt(2).
    assert!(close3(l.position, Vec3::new(0.0, 5.0, 0.0), 1e-6));
    assert!(close3(l.direction, Vec3::NEG_Y, 1e-6), "{}", l.direction);
    assert!(l.cast_shadows);

    assert_eq!(scene.cameras.len(), 1);
    let c = &scene.cameras[0];
    assert_eq!(c.name, "cam node");
    // 1e-6: as above, f32 rounding of the quaternion only.
    assert!(close3(c.position, Vec3::new(0.0, 1.0, 5.0), 1e-6));
    assert!(close3(c.forward, Vec3::NEG_X, 1e-6), "{}", c.forward);
    assert!(close3(c.up, Vec3::Y, 1e-6), "{}", c.up);
    assert_eq!(c.projection, Projection::Perspective { yfov: 0.8 });
    assert_eq!((c.znear, c.zfar, c.aspect), (0.1, Some(50.0), Some(1.5)));
}

#[test]
fn round_trip_embedded_gltf() {
    let (doc, _) = rich_document(Some("data:application/octet-stream;base64,{}".into()));
    let p = write(
        "rich_embedded.gltf",
        &serde_json::to_vec_pretty(&doc).unwrap(),
    );
    let scene = io::load(&p).unwrap();
    assert_eq!(scene.name, "rich_embedded");
    check_rich(&scene);
}

#[test]
fn round_trip_glb() {
    let (doc, bin) = rich_document(None);
    let p = write("rich.glb", &glb(&doc, &bin));
    let scene = io::load(&p).unwrap();
    assert_eq!(scene.name, "rich");
    check_rich(&scene);
}

#[test]
fn round_trip_external_buffer_and_image() {
    let (doc, bin) = rich_document(Some("rich external.bin".into()));
    let mut doc = doc;
    // Percent-encoded space in the URI must resolve to the file next to the .gltf.
    doc["buffers"][0]["uri"] = json!("rich%20external.bin");
    // Replace the embedded image by an external grey (L8) PNG: converted to RGBA8.
    let grey = png(image::DynamicImage::ImageLuma8(
        image::GrayImage::from_raw(1, 2, vec![10, 200]).unwrap(),
    ));
    write("grey.png", &grey);
    doc["images"] = json!([{"uri": "grey.png"}]);
    write("rich external.bin", &bin);
    let p = write("rich_external.gltf", &serde_json::to_vec(&doc).unwrap());
    let scene = io::load(&p).unwrap();
    let t = &scene.textures[0];
    assert_eq!((t.width, t.height), (1, 2));
    assert_eq!(t.rgba8, vec![10, 10, 10, 255, 200, 200, 200, 255]);
    assert_eq!(scene.meshes[0].positions[2], Vec3::new(1.0, 1.0, 0.0));
}

#[test]
fn strips_fans_points_and_defaults() {
    let mut b = Bin::default();
    let pos = b.vec3(&QUAD_POS);
    b.align();
    let doc = json!({
        "asset": {"version": "2.0"},
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 7,8,9,1]}],
        "meshes": [{"name": "m", "primitives": [
            {"attributes": {"POSITION": pos}, "mode": 5},
            {"attributes": {"POSITION": pos}, "mode": 6},
            {"attributes": {"POSITION": pos}, "mode": 0}
        ]}],
        "buffers": [{"byteLength": b.data.len(), "uri": format!("data:application/octet-stream;base64,{}", base64(&b.data))}],
        "bufferViews": b.views,
        "accessors": b.accessors,
    });
    let p = write("modes.gltf", &serde_json::to_vec(&doc).unwrap());
    let scene = io::load(&p).unwrap();
    // The points primitive is skipped; strip and fan become lists.
    assert_eq!(scene.meshes.len(), 2);
    assert_eq!(scene.meshes[0].indices, vec![0, 1, 2, 2, 1, 3]);
    assert_eq!(scene.meshes[1].indices, vec![0, 1, 2, 0, 2, 3]);
    assert_eq!(scene.meshes[0].name, "m primitive 0");
    assert_eq!(scene.instances.len(), 2);
    // Column-major matrix: the translation is the last column.
    assert_eq!(
        scene.instances[0]
            .transform
            .transform_point3(Vec3::new(1.0, 1.0, 0.0)),
        Vec3::new(8.0, 9.0, 9.0)
    );
    // No `scene` property: scene 0 is used. No cameras or lights in the file.
    assert!(scene.cameras.is_empty() && scene.lights.is_empty());
}

#[test]
fn directional_point_and_orthographic_defaults() {
    let doc = json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "scene": 0,
        "scenes": [{"nodes": [0, 1, 2, 3]}],
        "nodes": [
            {"extensions": {"KHR_lights_punctual": {"light": 0}}},
            {"translation": [1.0, 2.0, 3.0], "extensions": {"KHR_lights_punctual": {"light": 1}}},
            {"name": "ortho", "camera": 0, "translation": [0.0, 0.0, 4.0]},
            {"extensions": {"KHR_lights_punctual": {"light": 2}}}
        ],
        "cameras": [{"type": "orthographic", "orthographic": {"xmag": 2.0, "ymag": 1.5, "znear": 0.5, "zfar": 9.0}}],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "directional", "intensity": 3.0},
            {"type": "point", "color": [0.5, 0.5, 1.0]},
            {"type": "spot", "spot": {}}
        ]}}
    });
    let p = write("lights.gltf", &serde_json::to_vec(&doc).unwrap());
    let scene = io::load(&p).unwrap();
    assert_eq!(scene.lights.len(), 3);
    let d = &scene.lights[0];
    assert_eq!(d.kind, LightKind::Directional);
    assert_eq!(
        (d.intensity, d.direction, d.color),
        (3.0, Vec3::NEG_Z, [1.0; 3])
    );
    let pt = &scene.lights[1];
    assert_eq!(pt.kind, LightKind::Point);
    // glTF's default intensity is 1 and range infinite.
    assert_eq!((pt.intensity, pt.range), (1.0, None));
    assert_eq!(pt.position, Vec3::new(1.0, 2.0, 3.0));
    assert_eq!(pt.color, [0.5, 0.5, 1.0]);
    // Spot defaults from the spec: inner 0, outer pi/4.
    assert_eq!(
        scene.lights[2].kind,
        LightKind::Spot {
            inner_angle: 0.0,
            outer_angle: std::f32::consts::FRAC_PI_4
        }
    );
    let c = &scene.cameras[0];
    assert_eq!(
        c.projection,
        Projection::Orthographic {
            xmag: 2.0,
            ymag: 1.5
        }
    );
    assert_eq!((c.znear, c.zfar, c.aspect), (0.5, Some(9.0), None));
    assert_eq!(
        (c.position, c.forward, c.up),
        (Vec3::new(0.0, 0.0, 4.0), Vec3::NEG_Z, Vec3::Y)
    );
    assert!(scene.meshes.is_empty() && scene.instances.is_empty());
}

// ------------------------------------------------------------------------------------------
// Khronos conformance samples

fn samples_dir() -> Option<PathBuf> {
    let d = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes/gltf_samples");
    if d.join("EXPECT.md").exists() {
        Some(d)
    } else {
        println!("skipped: ../shared/scenes/gltf_samples not present");
        None
    }
}

fn expect_entries(dir: &Path) -> Vec<Value> {
    let md = std::fs::read_to_string(dir.join("EXPECT.md")).unwrap();
    let start = md.find("```json").expect("EXPECT.md has a ```json block") + "```json".len();
    let len = md[start..].find("```").expect("json block is closed");
    let v: Value = serde_json::from_str(&md[start..start + len]).unwrap();
    v.as_array().unwrap().clone()
}

#[test]
fn khronos_samples_match_expect_md() {
    let Some(dir) = samples_dir() else { return };
    let mut checked = 0;
    for e in expect_entries(&dir) {
        let Some(file) = e["file"].as_str() else {
            continue;
        };
        let scene = io::load(&dir.join(file)).unwrap_or_else(|err| panic!("{file}: {err}"));
        let n = |k: &str| e[k].as_u64().unwrap_or_else(|| panic!("{file}: {k}")) as usize;
        assert_eq!(scene.meshes.len(), n("primitives"), "{file}: primitives");
        let unique_tris: usize = scene.meshes.iter().map(|m| m.indices.len() / 3).sum();
        assert_eq!(unique_tris, n("unique_tris"), "{file}: unique triangles");
        let default = e["default_scene"].as_u64().unwrap_or(0) as usize;
        let drawn = e["scene_tris"][default].as_u64().unwrap() as usize;
        assert_eq!(scene.triangle_count(), drawn, "{file}: drawn triangles");
        let verts: usize = scene.meshes.iter().map(|m| m.positions.len()).sum();
        assert_eq!(verts, n("unique_verts"), "{file}: vertices");
        assert_eq!(scene.textures.len(), n("images"), "{file}: images");
        let kinds: Vec<&str> = scene
            .cameras
            .iter()
            .map(|c| match c.projection {
                Projection::Perspective { .. } => "perspective",
                Projection::Orthographic { .. } => "orthographic",
            })
            .collect();
        let want: Vec<&str> = e["cameras"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_str().unwrap())
            .collect();
        assert_eq!(kinds, want, "{file}: cameras");
        assert_eq!(scene.lights.len(), n("lights"), "{file}: lights");
        let b = scene.bounds();
        let aabb = &e["world_aabb_default_scene"];
        let v3 = |a: &Value| {
            Vec3::new(
                a[0].as_f64().unwrap() as f32,
                a[1].as_f64().unwrap() as f32,
                a[2].as_f64().unwrap() as f32,
            )
        };
        // 1e-3: EXPECT.md rounds to 4 decimals (5e-5), and Cameras.gltf's quaternion
        // (-0.383, 0, 0, 0.924) is not unit: we normalise it, which moves that AABB by up to 7e-4.
        assert!(
            close3(b.min, v3(&aabb[0]), 1e-3) && close3(b.max, v3(&aabb[1]), 1e-3),
            "{file}: bounds {:?} vs {aabb}",
            b
        );
        checked += 1;
    }
    // Ten staged files; one entry of the JSON block has no "file" and is skipped.
    assert_eq!(checked, 10);
}

#[test]
fn orientation_test_arrows() {
    let Some(dir) = samples_dir() else { return };
    let scene = io::load(&dir.join("OrientationTest.gltf")).unwrap();
    let table = [
        ("ArrowX1", [4.669, -1.059, -1.721], [5.331, 2.457, 0.916]),
        ("ArrowX2", [-5.331, -1.033, -0.606], [-4.669, 2.989, 0.820]),
        ("ArrowY1", [-1.083, 4.669, -1.093], [2.819, 5.331, 0.735]),
        ("ArrowY2", [-0.956, -5.331, -1.065], [0.617, -4.669, 2.934]),
        ("ArrowZ1", [-1.010, -1.074, 4.669], [0.663, 2.898, 5.331]),
        ("ArrowZ2", [-0.692, -1.079, -5.331], [1.044, 2.869, -4.669]),
    ];
    for (name, lo, hi) in table {
        let idx: Vec<usize> = (0..scene.instances.len())
            .filter(|&i| scene.instances[i].name == name)
            .collect();
        assert_eq!(idx.len(), 1, "{name}: one instance");
        let (a, b) = aabb_of(&scene, idx[0]);
        // 2e-3: the table is rounded to 3 decimals (5e-4) plus f32 transform rounding; a
        // transposed rotation moves these bounds by tenths.
        assert!(
            close3(a, Vec3::from(lo), 2e-3) && close3(b, Vec3::from(hi), 2e-3),
            "{name}: {a} {b}"
        );
    }
}

#[test]
fn texture_coordinate_test_orientation() {
    let Some(dir) = samples_dir() else { return };
    let scene = io::load(&dir.join("TextureCoordinateTest.gltf")).unwrap();
    let i = scene
        .instances
        .iter()
        .position(|i| i.name.starts_with("TopLeft"))
        .expect("a TopLeft instance");
    let m = &scene.meshes[scene.instances[i].mesh];
    let (mut lo, mut hi) = (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY));
    for &uv in &m.uvs {
        lo = lo.min(uv);
        hi = hi.max(uv);
    }
    assert_eq!(m.uvs.len(), m.positions.len());
    // 1e-5: the accessor stores 0 and 0.4 as f32; UVs are passed through, not flipped.
    assert!((lo - Vec2::ZERO).abs().max_element() < 1e-5, "{lo}");
    assert!((hi - Vec2::splat(0.4)).abs().max_element() < 1e-5, "{hi}");
    let (a, b) = aabb_of(&scene, i);
    // 1e-5: positions 0.2 and 1.2 stored as f32 under an identity transform.
    assert!((a.x - 0.2).abs() < 1e-5 && (a.y - 0.2).abs() < 1e-5, "{a}");
    assert!((b.x - 1.2).abs() < 1e-5 && (b.y - 1.2).abs() < 1e-5, "{b}");
    let t = &scene.textures[0];
    assert_eq!(
        (t.width, t.height, t.rgba8.len()),
        (512, 512, 512 * 512 * 4)
    );
    assert!(scene.materials.iter().all(|m| m.double_sided));
}

#[test]
fn sparse_accessor_is_applied() {
    let Some(dir) = samples_dir() else { return };
    let scene = io::load(&dir.join("SimpleSparseAccessor.gltf")).unwrap();
    let p = &scene.meshes[0].positions;
    // Exact: the sparse values are stored f32 small integers.
    assert_eq!(p[8], Vec3::new(1.0, 2.0, 0.0));
    assert_eq!(p[10], Vec3::new(3.0, 3.0, 0.0));
    assert_eq!(p[12], Vec3::new(5.0, 4.0, 0.0));
    assert_eq!(p[9], Vec3::new(2.0, 1.0, 0.0), "untouched base value");
    assert_eq!(scene.bounds().max.y, 4.0);
}

#[test]
fn sixteen_bit_and_grey_alpha_images_become_rgba8() {
    let rgba16 = png(image::DynamicImage::ImageRgba16(
        image::ImageBuffer::from_raw(1, 1, vec![65535u16, 257 * 100, 0, 257 * 7]).unwrap(),
    ));
    let la8 = png(image::DynamicImage::ImageLumaA8(
        image::GrayAlphaImage::from_raw(1, 1, vec![50, 60]).unwrap(),
    ));
    let doc = json!({
        "asset": {"version": "2.0"},
        "images": [
            {"uri": format!("data:image/png;base64,{}", base64(&rgba16))},
            {"uri": format!("data:image/png;base64,{}", base64(&la8))}
        ]
    });
    let p = write("images16.gltf", &serde_json::to_vec(&doc).unwrap());
    let scene = io::load(&p).unwrap();
    // 16-bit channels scale by 255/65535, i.e. v/257 exactly for multiples of 257.
    assert_eq!(scene.textures[0].rgba8, vec![255, 100, 0, 7]);
    // Grey is replicated into RGB, alpha kept.
    assert_eq!(scene.textures[1].rgba8, vec![50, 50, 50, 60]);
}

#[test]
fn sparse_accessor_without_buffer_view() {
    // POSITION has no bufferView (all zeros) and a sparse block setting vertices 1 and 2.
    let mut b = Bin::default();
    let ids = b.view(&[1u8, 2]);
    let vals: Vec<u8> = [1.0f32, 0.0, 0.0, 0.0, 1.0, 0.0]
        .iter()
        .flat_map(|f| f.to_le_bytes())
        .collect();
    let vals = b.view(&vals);
    b.align();
    let doc = json!({
        "asset": {"version": "2.0"},
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "accessors": [{"componentType": 5126, "count": 3, "type": "VEC3",
            "sparse": {"count": 2, "indices": {"bufferView": ids, "componentType": 5121},
                       "values": {"bufferView": vals}}}],
        "buffers": [{"byteLength": b.data.len(), "uri": format!("data:application/octet-stream;base64,{}", base64(&b.data))}],
        "bufferViews": b.views,
    });
    let p = write("sparse_zero_base.gltf", &serde_json::to_vec(&doc).unwrap());
    let scene = io::load(&p).unwrap();
    // Exact: zeros and stored f32 values.
    assert_eq!(
        scene.meshes[0].positions,
        vec![Vec3::ZERO, Vec3::X, Vec3::Y]
    );
    assert_eq!(scene.meshes[0].normals, vec![Vec3::Z; 3]);
}

// ------------------------------------------------------------------------------------------
// Bad input

/// A minimal valid triangle document whose JSON the cases then break.
fn triangle_doc() -> (Value, Vec<u8>) {
    let mut b = Bin::default();
    let pos = b.vec3(&[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]]);
    let idx = b.u16s(&[0, 1, 2]);
    b.align();
    let doc = json!({
        "asset": {"version": "2.0"},
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos}, "indices": idx}]}],
        "buffers": [{"byteLength": b.data.len(), "uri": format!("data:application/octet-stream;base64,{}", base64(&b.data))}],
        "bufferViews": b.views,
        "accessors": b.accessors,
    });
    (doc, b.data)
}

fn edited(f: impl FnOnce(&mut Value)) -> Vec<u8> {
    let (mut doc, _) = triangle_doc();
    f(&mut doc);
    serde_json::to_vec(&doc).unwrap()
}

#[test]
fn the_valid_base_of_the_bad_cases_loads() {
    // Guards the table below: each case must fail because of its own edit.
    let p = write("base_ok.gltf", &edited(|_| {}));
    let s = io::load(&p).unwrap();
    assert_eq!(s.triangle_count(), 1);
    let (mut doc, bin) = triangle_doc();
    doc["buffers"][0].as_object_mut().unwrap().remove("uri");
    let p = write("base_ok.glb", &glb(&doc, &bin));
    assert_eq!(io::load(&p).unwrap().triangle_count(), 1);
}

#[test]
fn bad_input_fails_with_the_file_name() {
    let (mut gdoc, gbin) = triangle_doc();
    gdoc["buffers"][0].as_object_mut().unwrap().remove("uri");
    let good_glb = glb(&gdoc, &gbin);
    let mut wrong_magic = good_glb.clone();
    wrong_magic[..4].copy_from_slice(b"gLTf");
    let huge_png = png(image::DynamicImage::ImageLuma8(image::GrayImage::new(
        20000, 1,
    )));

    // (file name, contents, fragment the message must contain)
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        (
            "invalid_json.gltf",
            b"{ \"asset\": ".to_vec(),
            "invalid glTF",
        ),
        ("empty.gltf", Vec::new(), "empty file"),
        (
            "truncated.glb",
            good_glb[..good_glb.len() / 2].to_vec(),
            "binary glTF",
        ),
        ("wrong_magic.glb", wrong_magic, "no 'glTF' magic"),
        (
            "no_bin_chunk.gltf",
            serde_json::to_vec(&gdoc).unwrap(),
            "buffer 0: refers to the GLB binary chunk, but the file has none",
        ),
        (
            "missing_buffer.gltf",
            edited(|d| d["buffers"][0]["uri"] = json!("nowhere.bin")),
            "buffer 0 (nowhere.bin): no such file",
        ),
        (
            "accessor_index.gltf",
            edited(|d| d["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = json!(7)),
            "accessor 7 does not exist",
        ),
        (
            "index_value.gltf",
            {
                let (mut d, mut bin) = triangle_doc();
                // Overwrite the third u16 index (after 36 position bytes) with 40.
                bin[40..42].copy_from_slice(&40u16.to_le_bytes());
                d["buffers"][0]["uri"] = json!(format!(
                    "data:application/octet-stream;base64,{}",
                    base64(&bin)
                ));
                serde_json::to_vec(&d).unwrap()
            },
            "accessor 1: index 40 out of range for 3 vertices",
        ),
        (
            "view_beyond_buffer.gltf",
            edited(|d| d["bufferViews"][0]["byteLength"] = json!(1000)),
            "extends beyond buffer 0",
        ),
        (
            "huge_count.gltf",
            edited(|d| d["accessors"][0]["count"] = json!(1_000_000_000u64)),
            "exceeds the limit",
        ),
        (
            "big_count.gltf",
            edited(|d| d["accessors"][0]["count"] = json!(1_000_000u64)),
            "need more than the 36 bytes",
        ),
        (
            "float_indices.gltf",
            edited(|d| d["accessors"][1]["componentType"] = json!(5126)),
            "not allowed",
        ),
        (
            "byte_length.gltf",
            edited(|d| d["buffers"][0]["byteLength"] = json!(4096)),
            "byteLength is 4096",
        ),
        (
            "bad_base64.gltf",
            edited(|d| d["buffers"][0]["uri"] = json!("data:application/octet-stream;base64,A*B")),
            "invalid base64",
        ),
        (
            "cycle.gltf",
            edited(|d| {
                d["nodes"] = json!([{"mesh": 0, "children": [1]}, {"children": [0]}]);
            }),
            "node",
        ),
        (
            "huge_image.gltf",
            edited(|d| {
                d["images"] =
                    json!([{"uri": format!("data:image/png;base64,{}", base64(&huge_png))}]);
            }),
            "larger than the 16384x16384 texture limit",
        ),
        // Found by the fuzzer: the gltf crate's `Image::source` unwraps what these lack (the
        // loader caught the panic, as "the glTF parser failed").
        (
            "image_without_source.gltf",
            edited(|d| d["images"] = json!([{"uriextras": "data:image/png;base64,AAAA"}])),
            "images[0]: neither a uri nor a bufferView",
        ),
        (
            "image_view_without_mime.gltf",
            edited(|d| d["images"] = json!([{"bufferView": 0}])),
            "images[0]: an image in a buffer view needs a mimeType",
        ),
        (
            "image_view_missing.gltf",
            edited(|d| d["images"] = json!([{"bufferView": 9, "mimeType": "image/png"}])),
            "images[0].bufferView: buffer view 9 does not exist",
        ),
        (
            "stride_too_small.gltf",
            edited(|d| d["bufferViews"][0]["byteStride"] = json!(4)),
            "byteStride 4",
        ),
    ];
    let mut failures = Vec::new();
    for (name, bytes, fragment) in cases {
        let path = write(name, &bytes);
        let outcome = std::panic::catch_unwind(|| io::load(&path));
        match outcome {
            Err(_) => failures.push(format!("{name}: panicked")),
            Ok(Ok(_)) => failures.push(format!("{name}: loaded without error")),
            Ok(Err(e)) => {
                let msg = e.to_string();
                println!("{name}: {msg}");
                if !msg.contains(name) || !msg.contains(fragment) {
                    failures.push(format!(
                        "{name}: message '{msg}' lacks the file name or '{fragment}'"
                    ));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Deterministic mutation of the numbers (indices, counts, offsets, component types) in the
/// Khronos samples. Every outcome must be Ok or a reasoned error; an error from the loader's
/// panic guard means a dependency panicked on input the loader should have rejected first.
#[test]
fn mutated_samples_never_reach_the_panic_guard() {
    let Some(dir) = samples_dir() else { return };
    let mut seed: u64 = 12345;
    let mut rnd = move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 33) as usize
    };
    let values = [
        "0",
        "1",
        "2",
        "3",
        "7",
        "12",
        "255",
        "4000000000",
        "-1",
        "5126",
        "5121",
        "6",
        "1e30",
        "0.5",
        "100000",
    ];
    let files = [
        "Box.gltf",
        "Cameras.gltf",
        "MultipleScenes.gltf",
        "SimpleSparseAccessor.gltf",
    ];
    let mut guarded = Vec::new();
    let mut errors = 0;
    for f in files {
        let text = std::fs::read_to_string(dir.join(f)).unwrap();
        // Byte ranges of the numbers outside strings (so data URIs stay intact).
        let b = text.as_bytes();
        let (mut nums, mut i, mut in_str) = (Vec::new(), 0, false);
        while i < b.len() {
            if b[i] == b'"' {
                in_str = !in_str;
            } else if !in_str && (b[i].is_ascii_digit() || b[i] == b'-') {
                let s = i;
                while i < b.len() && (b[i].is_ascii_digit() || b"-.eE+".contains(&b[i])) {
                    i += 1;
                }
                nums.push((s, i));
                continue;
            }
            i += 1;
        }
        for k in 0..100 {
            let mut t = text.clone();
            // Replace from the back so earlier ranges stay valid.
            let mut picks = vec![nums[rnd() % nums.len()], nums[rnd() % nums.len()]];
            picks.sort();
            picks.dedup();
            for (s, e) in picks.into_iter().rev().take(1 + k % 2) {
                t.replace_range(s..e, values[rnd() % values.len()]);
            }
            let p = write(&format!("mutated_{k}_{f}"), t.as_bytes());
            if let Err(e) = io::load(&p) {
                errors += 1;
                let m = e.to_string();
                assert!(m.contains(&format!("mutated_{k}_{f}")), "{m}");
                if m.contains("parser failed") {
                    guarded.push(m);
                }
            }
        }
    }
    assert!(guarded.is_empty(), "{}", guarded.join("\n"));
    // Sanity: the mutations do hit validation (400 mutations; most change an index or count).
    assert!(errors > 100, "only {errors} mutations were rejected");
}

// ------------------------------------------------------------------------------------------
// Animations

/// The triangle every node of the animation documents shows: (0,0,0), (1,0,0), (0,1,0).
const TRI: [[f32; 3]; 3] = [[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]];

/// A `Bin` whose accessor 0 is the triangle's positions.
fn tri_bin() -> Bin {
    let mut b = Bin::default();
    b.vec3(&TRI);
    b
}

/// A glTF document with `nodes` (mesh 0 is the triangle), the scene's root `roots` and
/// `animations`, on the data of `b`; `extra` is merged into the top level.
fn anim_doc(b: &Bin, nodes: Value, roots: Value, animations: Value, extra: Value) -> Value {
    let mut data = b.data.clone();
    while !data.len().is_multiple_of(4) {
        data.push(0);
    }
    let mut doc = json!({
        "asset": {"version": "2.0"},
        "scenes": [{"nodes": roots}],
        "nodes": nodes,
        "meshes": [{"name": "tri", "primitives": [{"attributes": {"POSITION": 0}}]}],
        "animations": animations,
        "buffers": [{"byteLength": data.len(), "uri": format!("data:application/octet-stream;base64,{}", base64(&data))}],
        "bufferViews": b.views,
        "accessors": b.accessors,
    });
    if let (Some(d), Some(e)) = (doc.as_object_mut(), extra.as_object()) {
        for (k, v) in e {
            d.insert(k.clone(), v.clone());
        }
    }
    doc
}

fn write_doc(name: &str, doc: &Value) -> PathBuf {
    write(name, &serde_json::to_vec(doc).unwrap())
}

/// One sampler and one channel on `node`'s `path`.
fn one_channel(node: usize, path: &str, input: usize, output: usize, interp: &str) -> Value {
    json!([{
        "name": "move",
        "samplers": [{"input": input, "output": output, "interpolation": interp}],
        "channels": [{"sampler": 0, "target": {"node": node, "path": path}}]
    }])
}

/// Where instance `inst` puts the point `p` at time `t`.
fn point_at(scene: &Scene, inst: usize, t: f32, p: Vec3) -> Vec3 {
    scene.at_time(t).instances[inst]
        .transform
        .transform_point3(p)
}

#[test]
fn linear_translation_keeps_the_rest_rotation_and_scale() {
    let mut b = tri_bin();
    let times = b.f32s(&[0.0, 2.0]);
    let values = b.vec3(&[[0.0, 0.0, 0.0], [4.0, 2.0, 0.0]]);
    // Rest pose: 90 degrees about Z, scale 2, translation (0, 0, 5), which the channel replaces.
    let s = std::f32::consts::FRAC_1_SQRT_2;
    let nodes = json!([{"name": "mover", "mesh": 0, "translation": [0.0, 0.0, 5.0],
                        "rotation": [0.0, 0.0, s, s], "scale": [2.0, 2.0, 2.0]}]);
    let doc = anim_doc(
        &b,
        nodes,
        json!([0]),
        one_channel(0, "translation", times, values, "LINEAR"),
        json!({}),
    );
    let scene = io::load(&write_doc("anim_linear.gltf", &doc)).unwrap();
    assert_eq!(scene.animations.len(), 1);
    let a = &scene.animations[0];
    assert_eq!(a.name, "move");
    assert_eq!(a.duration(), 2.0);
    assert!(scene.instances[0].dynamic, "animated instances are dynamic");
    // The rest pose as loaded is the node's own TRS.
    let rest = scene.instances[0].transform.transform_point3(Vec3::X);
    assert!(close3(rest, Vec3::new(0.0, 2.0, 5.0), 1e-6), "{rest}");
    // t = 0.5 is a quarter of the way: translation (1, 0.5, 0). The vertex (1, 0, 0) scales to
    // (2, 0, 0), turns to (0, 2, 0) and moves to (1, 2.5, 0).
    let p = point_at(&scene, 0, 0.5, Vec3::X);
    assert!(close3(p, Vec3::new(1.0, 2.5, 0.0), 1e-6), "{p}");
    // Clamped outside the keyframes (glTF has no repeat).
    assert!(close3(
        point_at(&scene, 0, -1.0, Vec3::X),
        Vec3::new(0.0, 2.0, 0.0),
        1e-6
    ));
    assert!(close3(
        point_at(&scene, 0, 9.0, Vec3::X),
        Vec3::new(4.0, 4.0, 0.0),
        1e-6
    ));
}

#[test]
fn step_holds_each_keyframe_until_the_next() {
    let mut b = tri_bin();
    let times = b.f32s(&[0.0, 1.0, 2.0]);
    let values = b.vec3(&[[1.0; 3], [2.0; 3], [3.0; 3]]);
    let doc = anim_doc(
        &b,
        json!([{"mesh": 0}]),
        json!([0]),
        one_channel(0, "scale", times, values, "STEP"),
        json!({}),
    );
    let scene = io::load(&write_doc("anim_step.gltf", &doc)).unwrap();
    for (t, x) in [
        (0.0, 1.0),
        (0.99, 1.0),
        (1.0, 2.0),
        (1.5, 2.0),
        (1.999, 2.0),
        (2.0, 3.0),
        (5.0, 3.0),
    ] {
        assert_eq!(
            point_at(&scene, 0, t, Vec3::X),
            Vec3::new(x, 0.0, 0.0),
            "t = {t}"
        );
    }
}

#[test]
fn cubic_spline_is_the_hermite_curve_with_scaled_tangents() {
    let mut b = tri_bin();
    let (t0, t1) = (1.0f32, 3.0f32);
    let times = b.f32s(&[t0, t1]);
    // Per keyframe: in-tangent, value, out-tangent. The first in- and the last out-tangent are
    // outside the curve (9s prove it).
    let (v0, b0) = (Vec3::ZERO, Vec3::new(1.0, 0.0, -1.0));
    let (a1, v1) = (Vec3::new(0.0, 2.0, 0.0), Vec3::splat(2.0));
    let out: Vec<[f32; 3]> = [Vec3::splat(9.0), v0, b0, a1, v1, Vec3::splat(9.0)]
        .iter()
        .map(|v| v.to_array())
        .collect();
    let values = b.vec3(&out);
    let doc = anim_doc(
        &b,
        json!([{"mesh": 0}]),
        json!([0]),
        one_channel(0, "translation", times, values, "CUBICSPLINE"),
        json!({}),
    );
    let scene = io::load(&write_doc("anim_cubic.gltf", &doc)).unwrap();
    assert_eq!(scene.animations[0].duration(), 3.0);
    // glTF 2.0 Appendix C, at t = 1.5: s = 0.25, dt = 2.
    let t = 1.5;
    let dt = t1 - t0;
    let s = (t - t0) / dt;
    let want = (2.0 * s.powi(3) - 3.0 * s * s + 1.0) * v0
        + (s.powi(3) - 2.0 * s * s + s) * dt * b0
        + (-2.0 * s.powi(3) + 3.0 * s * s) * v1
        + (s.powi(3) - s * s) * dt * a1;
    // By hand: 0.84375·0 + 0.28125·(1,0,-1) + 0.15625·(2,2,2) - 0.09375·(0,2,0).
    assert!(
        close3(want, Vec3::new(0.59375, 0.125, 0.03125), 1e-6),
        "{want}"
    );
    let got = point_at(&scene, 0, t, Vec3::ZERO);
    assert!(close3(got, want, 1e-6), "{got} vs {want}");
    // Through its keyframes, and clamped beyond them.
    assert!(close3(point_at(&scene, 0, 1.0, Vec3::ZERO), v0, 1e-6));
    assert!(close3(point_at(&scene, 0, 3.0, Vec3::ZERO), v1, 1e-6));
    assert!(close3(point_at(&scene, 0, 0.0, Vec3::ZERO), v0, 1e-6));
}

#[test]
fn linear_rotation_is_slerp_the_short_way() {
    let mut b = tri_bin();
    let times = b.f32s(&[0.0, 1.0]);
    let s = std::f32::consts::FRAC_1_SQRT_2;
    // Identity to 90 degrees about Z, the second stored negated (the same rotation): slerp
    // takes the short way, so halfway is 45 degrees, the quaternion (0, 0, sin 22.5°, cos 22.5°).
    let values = b.vec4(&[[0.0, 0.0, 0.0, 1.0], [0.0, 0.0, -s, -s]]);
    let doc = anim_doc(
        &b,
        json!([{"mesh": 0}]),
        json!([0]),
        one_channel(0, "rotation", times, values, "LINEAR"),
        json!({}),
    );
    let scene = io::load(&write_doc("anim_rotation.gltf", &doc)).unwrap();
    let m = scene.at_time(0.5).instances[0].transform;
    let (_, q, _) = m.to_scale_rotation_translation();
    let want = voxgi_scene::glam::Quat::from_xyzw(0.0, 0.0, 0.382_683_43, 0.923_879_5);
    assert!(q.dot(want).abs() > 1.0 - 1e-6, "{q:?}");
    let p = m.transform_point3(Vec3::X);
    assert!(close3(p, Vec3::new(s, s, 0.0), 1e-6), "{p}");
}

/// A parent that slides along X (animation "slide") with a child that turns about Z (animation
/// "spin"), one unit above it, and a static grandchild one unit along the child's X; each shows
/// the triangle; a point light sits on the grandchild.
fn nested_doc() -> Value {
    let mut b = tri_bin();
    let times = b.f32s(&[0.0, 1.0]);
    let slide = b.vec3(&[[0.0, 0.0, 0.0], [2.0, 0.0, 0.0]]);
    let s = std::f32::consts::FRAC_1_SQRT_2;
    let spin = b.vec4(&[[0.0, 0.0, 0.0, 1.0], [0.0, 0.0, s, s]]);
    let nodes = json!([
        {"name": "parent", "mesh": 0, "children": [1]},
        {"name": "child", "mesh": 0, "translation": [0.0, 1.0, 0.0], "children": [2]},
        {"name": "grandchild", "mesh": 0, "translation": [1.0, 0.0, 0.0],
         "extensions": {"KHR_lights_punctual": {"light": 0}}},
        {"name": "static", "mesh": 0}
    ]);
    let animations = json!([
        {"name": "slide", "samplers": [{"input": times, "output": slide}],
         "channels": [{"sampler": 0, "target": {"node": 0, "path": "translation"}}]},
        {"name": "spin", "samplers": [{"input": times, "output": spin}],
         "channels": [{"sampler": 0, "target": {"node": 1, "path": "rotation"}}]}
    ]);
    anim_doc(
        &b,
        nodes,
        json!([3, 0]),
        animations,
        json!({
            "extensionsUsed": ["KHR_lights_punctual"],
            "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 2.0}]}}
        }),
    )
}

/// The nested document's world transforms at `t`, by hand: parent, child, grandchild.
fn nested_want(t: f32) -> [Mat4; 3] {
    let parent = Mat4::from_translation(Vec3::new(2.0 * t, 0.0, 0.0));
    let child = parent
        * Mat4::from_translation(Vec3::Y)
        * Mat4::from_rotation_z(t * std::f32::consts::FRAC_PI_2);
    [parent, child, child * Mat4::from_translation(Vec3::X)]
}

#[test]
fn a_child_moves_with_its_animated_parent() {
    let scene = io::load(&write_doc("anim_nested.gltf", &nested_doc())).unwrap();
    // Instances in walk order: static, parent, child, grandchild.
    assert_eq!(scene.instances.len(), 4);
    assert!(
        !scene.instances[0].dynamic,
        "the unanimated root stays static"
    );
    assert!(scene.instances[1..].iter().all(|i| i.dynamic));
    // One target per animated node: the parent's moves by "slide"; the child's (with the
    // grandchild and its light) by both, named after both.
    let names: Vec<&str> = scene.animations.iter().map(|a| a.name.as_str()).collect();
    assert_eq!(names, ["slide", "slide, spin"]);
    assert!(scene.animations.iter().all(|a| a.duration() == 1.0));
    let at = scene.at_time(0.5);
    let want = nested_want(0.5);
    for (k, w) in want.iter().enumerate() {
        let got = at.instances[k + 1].transform;
        assert!(
            got.abs_diff_eq(*w, 1e-6),
            "instance {}: {got} vs {w}",
            k + 1
        );
    }
    assert_eq!(at.instances[0].transform, Mat4::IDENTITY);
    // By hand at t = 0.5: parent at (1,0,0); the child one up at (1,1,0) turned 45°; the
    // grandchild one unit along the child's X: (1 + √½, 1 + √½, 0). The light is there.
    let s = std::f32::consts::FRAC_1_SQRT_2;
    let g = at.instances[3].transform.transform_point3(Vec3::ZERO);
    assert!(close3(g, Vec3::new(1.0 + s, 1.0 + s, 0.0), 1e-6), "{g}");
    assert!(
        close3(at.lights[0].position, g, 1e-6),
        "{}",
        at.lights[0].position
    );
    // Sampling is repeatable and t = 0 is the rest pose.
    assert_eq!(
        at.at_time(0.0).instances[3].transform,
        scene.at_time(0.0).instances[3].transform
    );
    assert!(
        scene.at_time(0.0).instances[3]
            .transform
            .abs_diff_eq(scene.instances[3].transform, 1e-6)
    );
}

/// A camera on a child of an animated node flies with it: its eye and its aim follow the
/// node's transform, and the scene's camera list gains no copy.
#[test]
fn a_camera_below_an_animated_node_moves_with_it() {
    let mut b = tri_bin();
    let times = b.f32s(&[0.0, 1.0]);
    let slide = b.vec3(&[[0.0, 0.0, 0.0], [4.0, 0.0, 0.0]]);
    let s = std::f32::consts::FRAC_1_SQRT_2;
    // A quarter turn about +Y: -Z (where a glTF camera looks) turns to -X.
    let turn = b.vec4(&[[0.0, 0.0, 0.0, 1.0], [0.0, s, 0.0, s]]);
    let nodes = json!([
        {"name": "rig", "children": [1]},
        {"name": "eye", "camera": 0, "translation": [0.0, 1.0, 2.0]},
        {"name": "static", "mesh": 0}
    ]);
    let animations = json!([
        {"name": "dolly", "samplers": [{"input": times, "output": slide}, {"input": times, "output": turn}],
         "channels": [{"sampler": 0, "target": {"node": 0, "path": "translation"}},
                      {"sampler": 1, "target": {"node": 0, "path": "rotation"}}]}
    ]);
    let doc = anim_doc(
        &b,
        nodes,
        json!([2, 0]),
        animations,
        json!({"cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}}]}),
    );
    let scene = io::load(&write_doc("anim_camera.gltf", &doc)).unwrap();
    assert_eq!(scene.cameras.len(), 1);
    assert!(scene.camera_is_animated(0));
    assert!(
        scene.instances.iter().all(|i| !i.dynamic),
        "only the camera moves"
    );
    let rest = scene.camera_at(0, 0.0).unwrap();
    assert!(
        close3(rest.position, Vec3::new(0.0, 1.0, 2.0), 1e-6),
        "{}",
        rest.position
    );
    assert!(close3(rest.forward, Vec3::NEG_Z, 1e-6), "{}", rest.forward);
    // At t = 1 the rig stands at x = 4 turned a quarter about +Y: the eye's offset (0, 1, 2)
    // turns to (2, 1, 0), and it looks along -X.
    let end = scene.camera_at(0, 1.0).unwrap();
    assert!(
        close3(end.position, Vec3::new(6.0, 1.0, 0.0), 1e-5),
        "{}",
        end.position
    );
    assert!(close3(end.forward, Vec3::NEG_X, 1e-5), "{}", end.forward);
    assert!(close3(end.up, Vec3::Y, 1e-5), "{}", end.up);
    assert_eq!(end.projection, rest.projection);
}

#[test]
fn an_included_animated_gltf_moves_in_the_include_space() {
    write_doc("anim_included.gltf", &nested_doc());
    let toml = r#"
[[include]]
file = "anim_included.gltf"
translate = [0.0, 0.0, 5.0]
rotate = [0.0, 90.0, 0.0]
scale = 2.0
"#;
    let scene = io::load(&write("anim_include.toml", toml.as_bytes())).unwrap();
    let place = Mat4::from_translation(Vec3::new(0.0, 0.0, 5.0))
        * Mat4::from_rotation_y(std::f32::consts::FRAC_PI_2)
        * Mat4::from_scale(Vec3::splat(2.0));
    assert_eq!(scene.animations.len(), 2);
    for t in [0.0, 0.25, 0.5, 1.0] {
        let at = scene.at_time(t);
        for (k, w) in nested_want(t).iter().enumerate() {
            let got = at.instances[k + 1].transform;
            assert!(
                got.abs_diff_eq(place * *w, 1e-5),
                "t {t} instance {}: {got}",
                k + 1
            );
        }
        let light = place.transform_point3(nested_want(t)[2].transform_point3(Vec3::ZERO));
        assert!(
            close3(at.lights[0].position, light, 1e-5),
            "t {t}: {}",
            at.lights[0].position
        );
    }
}

#[test]
fn skins_morph_targets_and_weights_load_with_warnings() {
    let mut b = tri_bin();
    let times = b.f32s(&[0.0, 1.0]);
    let weights = b.f32s(&[0.0, 1.0]);
    let target = b.vec3(&[[0.0, 0.0, 1.0]; 3]);
    let joint_moves = b.vec3(&[[0.0; 3], [1.0, 0.0, 0.0]]);
    let doc = json!({
        "asset": {"version": "2.0"},
        "scenes": [{"nodes": [0, 1, 2]}],
        "nodes": [{"name": "skinned", "mesh": 0, "skin": 0}, {"name": "joint"}, {"name": "morphing", "mesh": 1}],
        "skins": [{"joints": [1]}],
        "meshes": [
            {"name": "body", "primitives": [{"attributes": {"POSITION": 0}}]},
            {"name": "face", "primitives": [{"attributes": {"POSITION": 0}, "targets": [{"POSITION": target}]}],
             "weights": [0.0]}
        ],
        "animations": [
            {"name": "smile", "samplers": [{"input": times, "output": weights}],
             "channels": [{"sampler": 0, "target": {"node": 2, "path": "weights"}}]},
            {"name": "wave", "samplers": [{"input": times, "output": joint_moves}],
             "channels": [{"sampler": 0, "target": {"node": 1, "path": "translation"}}]}
        ],
        "buffers": [{"byteLength": b.data.len(), "uri": format!("data:application/octet-stream;base64,{}", base64(&b.data))}],
        "bufferViews": b.views,
        "accessors": b.accessors,
    });
    let (scene, warnings) = load_warned(&write_doc("anim_skin_morph.gltf", &doc));
    let scene = scene.unwrap();
    assert_eq!(scene.instances.len(), 2, "both meshes are drawn");
    assert!(
        scene.animations.is_empty(),
        "weights are not played; the joint moves nothing drawn"
    );
    let has = |s: &str| warnings.iter().any(|w| w.contains(s));
    assert!(
        has("skinned mesh 0 'body'") && has("skinning is not supported"),
        "{warnings:?}"
    );
    assert!(has("mesh 1 'face' has morph targets"), "{warnings:?}");
    assert!(
        has("animation 0 'smile'") && has("morph-target weights are not supported"),
        "{warnings:?}"
    );
    assert!(
        has("animation 1 'wave' moves no mesh, light or camera"),
        "{warnings:?}"
    );
}

#[test]
fn two_animations_on_one_property_warn_and_the_later_wins() {
    let mut b = tri_bin();
    let times = b.f32s(&[0.0, 1.0]);
    let first = b.vec3(&[[0.0; 3], [1.0, 0.0, 0.0]]);
    let second = b.vec3(&[[0.0; 3], [0.0, 1.0, 0.0]]);
    let animations = json!([
        {"name": "right", "samplers": [{"input": times, "output": first}],
         "channels": [{"sampler": 0, "target": {"node": 0, "path": "translation"}}]},
        {"name": "up", "samplers": [{"input": times, "output": second}],
         "channels": [{"sampler": 0, "target": {"node": 0, "path": "translation"}}]}
    ]);
    let doc = anim_doc(&b, json!([{"mesh": 0}]), json!([0]), animations, json!({}));
    let (scene, warnings) = load_warned(&write_doc("anim_overlap.gltf", &doc));
    let scene = scene.unwrap();
    assert!(
        warnings
            .iter()
            .any(|w| w.contains("animated by both 'right' and 'up'")),
        "{warnings:?}"
    );
    assert_eq!(scene.animations.len(), 1);
    assert_eq!(scene.animations[0].name, "up");
    assert_eq!(point_at(&scene, 0, 1.0, Vec3::ZERO), Vec3::Y);
}

#[test]
fn bad_animation_data_fails_with_the_file_and_animation() {
    let mut b = tri_bin();
    let unsorted = b.f32s(&[0.0, 2.0, 1.0]);
    let three = b.vec3(&[[0.0; 3]; 3]);
    let two_times = b.f32s(&[0.0, 1.0]);
    let five = b.vec3(&[[0.0; 3]; 5]);
    let nan = b.vec3(&[[0.0; 3], [f32::NAN, 0.0, 0.0]]);
    let negative = b.f32s(&[-1.0, 1.0]);
    let two = b.vec3(&[[0.0; 3]; 2]);
    let zero_quat = b.vec4(&[[0.0; 4], [0.0, 0.0, 0.0, 1.0]]);
    let int_times = b.u16s(&[0, 1]);
    let cases: Vec<(&str, Value, &str)> = vec![
        (
            "anim_unsorted.gltf",
            one_channel(0, "translation", unsorted, three, "LINEAR"),
            "sorted",
        ),
        (
            "anim_cubic_count.gltf",
            one_channel(0, "translation", two_times, five, "CUBICSPLINE"),
            "CUBICSPLINE output has 5 values for 2 keyframe times; it needs 3 per keyframe",
        ),
        (
            "anim_linear_count.gltf",
            one_channel(0, "scale", two_times, five, "LINEAR"),
            "2 keyframe times but 5 output values",
        ),
        (
            "anim_nan.gltf",
            one_channel(0, "translation", two_times, nan, "STEP"),
            "keyframe 1: the value is not finite",
        ),
        (
            "anim_negative.gltf",
            one_channel(0, "translation", negative, two, "LINEAR"),
            ">= 0",
        ),
        (
            "anim_zero_quat.gltf",
            one_channel(0, "rotation", two_times, zero_quat, "LINEAR"),
            "zero quaternion",
        ),
        (
            "anim_vec3_rotation.gltf",
            one_channel(0, "rotation", two_times, two, "LINEAR"),
            "not allowed",
        ),
        (
            "anim_int_times.gltf",
            one_channel(0, "translation", int_times, two, "LINEAR"),
            "not allowed",
        ),
        (
            "anim_no_node.gltf",
            one_channel(7, "translation", two_times, two, "LINEAR"),
            "node 7 does not exist",
        ),
        (
            "anim_bad_interp.gltf",
            one_channel(0, "translation", two_times, two, "SMOOTH"),
            "interpolation",
        ),
    ];
    let mut failures = Vec::new();
    for (name, animations, fragment) in cases {
        let doc = anim_doc(&b, json!([{"mesh": 0}]), json!([0]), animations, json!({}));
        let path = write_doc(name, &doc);
        match std::panic::catch_unwind(|| io::load(&path)) {
            Err(_) => failures.push(format!("{name}: panicked")),
            Ok(Ok(_)) => failures.push(format!("{name}: loaded without error")),
            Ok(Err(e)) => {
                let msg = e.to_string();
                println!("{name}: {msg}");
                // The JSON validation names the animation by its path, the loader by index and name.
                let anim = msg.contains("animation 0 'move'") || msg.contains("animations[0]");
                if !msg.contains(name) || !anim || !msg.contains(fragment) {
                    failures.push(format!(
                        "{name}: '{msg}' lacks the file, the animation or '{fragment}'"
                    ));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

// ------------------------------------------------------------------------------------------
// Khronos animated samples, when present

/// A Khronos sample `name` (`.gltf` or `.glb`) from `../shared/scenes` (or the folder in
/// `VOXGI_GLTF_SAMPLES`), if it is there.
fn animated_sample(name: &str) -> Option<PathBuf> {
    let shared = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes");
    let mut dirs: Vec<PathBuf> = std::env::var_os("VOXGI_GLTF_SAMPLES")
        .map(PathBuf::from)
        .into_iter()
        .collect();
    dirs.extend([
        shared.join("gltf_samples"),
        shared.join(name),
        shared.join("gltf_samples").join(name),
    ]);
    let found = dirs
        .iter()
        .flat_map(|d| ["gltf", "glb"].map(|x| d.join(format!("{name}.{x}"))))
        .find(|p| p.exists());
    if found.is_none() {
        eprintln!("skipped: Khronos sample {name} is not in ../shared/scenes");
    }
    found
}

/// Minimal base64 decoding for reading data URIs in the tests themselves.
fn unbase64(s: &str) -> Vec<u8> {
    let val = |c: u8| match c {
        b'A'..=b'Z' => c - b'A',
        b'a'..=b'z' => c - b'a' + 26,
        b'0'..=b'9' => c - b'0' + 52,
        b'+' => 62,
        _ => 63,
    };
    let (mut out, mut acc, mut bits) = (Vec::new(), 0u32, 0);
    for c in s.bytes().filter(|c| !c.is_ascii_whitespace() && *c != b'=') {
        acc = (acc << 6) | u32::from(val(c));
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
        }
    }
    out
}

/// The float components of accessor `ai` of an embedded glTF, read straight from its JSON and
/// data URIs (tightly packed or strided, no sparse): one Vec per element.
fn accessor_floats(doc: &Value, ai: usize) -> Vec<Vec<f32>> {
    let acc = &doc["accessors"][ai];
    assert_eq!(acc["componentType"], 5126, "float accessor");
    let n = match acc["type"].as_str().unwrap() {
        "SCALAR" => 1,
        "VEC3" => 3,
        "VEC4" => 4,
        t => panic!("type {t}"),
    };
    let view = &doc["bufferViews"][acc["bufferView"].as_u64().unwrap() as usize];
    let buffer = &doc["buffers"][view["buffer"].as_u64().unwrap() as usize];
    let uri = buffer["uri"].as_str().unwrap();
    let data = unbase64(&uri[uri.find(",").unwrap() + 1..]);
    let start = view["byteOffset"].as_u64().unwrap_or(0) as usize
        + acc["byteOffset"].as_u64().unwrap_or(0) as usize;
    let stride = view["byteStride"].as_u64().map_or(4 * n, |s| s as usize);
    (0..acc["count"].as_u64().unwrap() as usize)
        .map(|k| {
            (0..n)
                .map(|c| {
                    let o = start + k * stride + 4 * c;
                    f32::from_le_bytes(data[o..o + 4].try_into().unwrap())
                })
                .collect()
        })
        .collect()
}

/// glTF LINEAR sampling of keyframes `times`/`values` at `t`, written out for the test.
fn lerp_keys(times: &[Vec<f32>], values: &[Vec<f32>], t: f32) -> (usize, f32) {
    // Before the first key: the first segment at s = 0 (glTF clamps).
    let k = times.iter().rposition(|x| x[0] <= t).unwrap_or(0);
    let k = k.min(times.len() - 2);
    let s = ((t - times[k][0]) / (times[k + 1][0] - times[k][0])).clamp(0.0, 1.0);
    assert_eq!(values.len(), times.len());
    (k, s)
}

#[test]
fn khronos_box_animated_matches_its_own_accessors() {
    use voxgi_scene::glam::Quat;
    let Some(path) = animated_sample("BoxAnimated") else {
        return;
    };
    let doc: Value = serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    let scene = io::load(&path).unwrap_or_else(|e| panic!("{e}"));
    // Two animations: node 2 (inner box) rotates; its grandparent node 0 translates. The inner
    // box is moved by both, so they play as one target; the outer box stays static.
    let anims = doc["animations"].as_array().unwrap();
    assert_eq!(anims.len(), 2);
    let channel = |a: usize| {
        let ch = &anims[a]["channels"][0];
        let sm = &anims[a]["samplers"][ch["sampler"].as_u64().unwrap() as usize];
        let (i, o) = (
            sm["input"].as_u64().unwrap() as usize,
            sm["output"].as_u64().unwrap() as usize,
        );
        (
            ch["target"]["node"].as_u64().unwrap(),
            ch["target"]["path"].as_str().unwrap().to_string(),
            accessor_floats(&doc, i),
            accessor_floats(&doc, o),
        )
    };
    let (rot_node, rot_path, rot_t, rot_v) = channel(0);
    let (tr_node, tr_path, tr_t, tr_v) = channel(1);
    assert_eq!(
        (rot_node, rot_path.as_str(), tr_node, tr_path.as_str()),
        (2, "rotation", 0, "translation")
    );
    let end = rot_t.last().unwrap()[0].max(tr_t.last().unwrap()[0]);
    assert_eq!(
        scene.animations.len(),
        1,
        "{:?}",
        scene.animations.iter().map(|a| &a.name).collect::<Vec<_>>()
    );
    assert_eq!(scene.animations[0].name, "animation 0, animation 1");
    assert!((scene.animations[0].duration() - end).abs() < 1e-6);
    let inner = scene
        .instances
        .iter()
        .position(|i| i.name == "node 2")
        .unwrap();
    let outer = scene
        .instances
        .iter()
        .position(|i| i.name == "node 3")
        .unwrap();
    assert!(scene.instances[inner].dynamic && !scene.instances[outer].dynamic);
    // The inner box's world transform at t, from the file: node 0 = T(t) R0, node 1 = I,
    // node 2 = R(t) (rest TRS of node 0 and 2 from the JSON).
    let quat = |v: &[f32]| Quat::from_xyzw(v[0], v[1], v[2], v[3]).normalize();
    let rest_rot = |n: usize| {
        quat(
            &doc["nodes"][n]["rotation"]
                .as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().unwrap() as f32)
                .collect::<Vec<_>>(),
        )
    };
    for t in [0.3, 1.0, 1.6, 2.2, 3.0] {
        let (k, s) = lerp_keys(&tr_t, &tr_v, t);
        let tr = Vec3::from_slice(&tr_v[k]).lerp(Vec3::from_slice(&tr_v[k + 1]), s);
        let (k, s) = lerp_keys(&rot_t, &rot_v, t);
        let rot = quat(&rot_v[k]).slerp(quat(&rot_v[k + 1]), s);
        let want = Mat4::from_rotation_translation(rest_rot(0), tr) * Mat4::from_quat(rot);
        let got = scene.at_time(t).instances[inner].transform;
        assert!(got.abs_diff_eq(want, 1e-5), "t {t}: {got} vs {want}");
        assert_eq!(
            scene.at_time(t).instances[outer].transform,
            scene.instances[outer].transform
        );
    }
}

#[test]
fn khronos_animated_samples_load() {
    for name in [
        "AnimatedTriangle",
        "AnimatedCube",
        "BoxAnimated",
        "InterpolationTest",
        "AnimatedMorphCube",
        "RiggedSimple",
        "RiggedFigure",
        "CesiumMan",
        "Fox",
    ] {
        let Some(path) = animated_sample(name) else {
            continue;
        };
        let doc: Value = if path.extension().is_some_and(|x| x == "gltf") {
            serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap()
        } else {
            json!({})
        };
        let (scene, warnings) = load_warned(&path);
        let scene = scene.unwrap_or_else(|e| panic!("{name}: {e}"));
        println!(
            "{name}: {} animations, warnings {warnings:?}",
            scene.animations.len()
        );
        let skinned = doc["skins"].as_array().is_some_and(|s| !s.is_empty())
            || name.starts_with("Rigged")
            || name == "CesiumMan"
            || name == "Fox";
        if skinned {
            assert!(
                warnings
                    .iter()
                    .any(|w| w.contains("skinning is not supported")),
                "{name}: {warnings:?}"
            );
        } else if name == "AnimatedMorphCube" {
            // Its only channels animate morph-target weights.
            assert!(
                warnings
                    .iter()
                    .any(|w| w.contains("morph-target weights are not supported")),
                "{name}: {warnings:?}"
            );
        } else {
            assert!(!scene.animations.is_empty(), "{name}");
        }
        for a in &scene.animations {
            assert!(
                a.duration() > 0.0 && a.duration().is_finite(),
                "{name}: {}",
                a.name
            );
            for t in [0.0, a.duration() * 0.37, a.duration()] {
                let s = scene.at_time(t);
                assert!(
                    s.instances.iter().all(|i| i.transform.is_finite()),
                    "{name} at {t}"
                );
                s.validate().unwrap();
            }
        }
    }
}
