//! Integration tests of the glTF loader: hand-built round trips, the Khronos conformance samples,
//! and malformed input that must fail with a message naming the file, never a panic.

use serde_json::{Value, json};
use std::path::{Path, PathBuf};
use voxgi_scene::glam::{Mat4, Vec2, Vec3};
use voxgi_scene::{AlphaMode, LightKind, Projection, Scene, io};

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
            "larger than the 16384x16384 limit",
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
