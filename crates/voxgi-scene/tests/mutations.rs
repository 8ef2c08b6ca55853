//! The loaders under mutated input: what the fuzz targets (`fuzz/`, cargo-fuzz) do for hours,
//! done briefly on every test run so the harness stays alive. Seeds: small files of each type
//! written here, the fuzz targets' own (`fuzz/seeds`), the repository's example scene files,
//! and the real scenes' small files when `../shared/scenes` is present. Each seed is mutated
//! (bytes flipped, inserted, deleted, duplicated, truncated, numbers replaced by extreme ones)
//! by a fixed-seed generator, and each mutant loaded: an error is fine, a panic fails the
//! test, naming a file that reproduces it.

use std::path::{Path, PathBuf};
use voxgi_scene::io::fuzz::load_as;

/// Mutants per seed: some tens of thousands of loads in all, seconds in a release build.
const MUTANTS: usize = 1000;

struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        // xorshift64*: fixed seeds make every run load the same mutants.
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

const EXTREMES: &[&str] = &[
    "nan",
    "inf",
    "-inf",
    "-1",
    "0",
    "1e39",
    "-3e38",
    "4294967295",
    "2147483648",
    "1e-45",
    "99999999999999999999",
];

fn mutate(seed: &[u8], rng: &mut Rng) -> Vec<u8> {
    let mut d = seed.to_vec();
    for _ in 0..1 + rng.below(2) {
        let n = d.len();
        match rng.below(7) {
            0 if n > 0 => {
                let i = rng.below(n);
                d[i] ^= 1 << rng.below(8);
            }
            1 => {
                let i = rng.below(n + 1);
                d.insert(i, rng.next() as u8);
            }
            2 if n > 0 => {
                let i = rng.below(n);
                let len = 1 + rng.below((n - i).min(64));
                d.drain(i..i + len);
            }
            3 if n > 0 => {
                let i = rng.below(n);
                let len = 1 + rng.below((n - i).min(256));
                let chunk = d[i..i + len].to_vec();
                let at = rng.below(n + 1);
                d.splice(at..at, chunk);
            }
            4 => d.truncate(rng.below(n + 1)),
            5 if n > 0 => {
                // A number in the text replaced by an extreme one.
                let i = rng.below(n);
                if let Some(start) = (i..n).find(|&k| d[k].is_ascii_digit()) {
                    let end = (start..n)
                        .find(|&k| !(d[k].is_ascii_digit() || d[k] == b'.' || d[k] == b'e'))
                        .unwrap_or(n);
                    let x = EXTREMES[rng.below(EXTREMES.len())].as_bytes();
                    d.splice(start..end, x.iter().copied());
                }
            }
            _ if n >= 4 => {
                // A little-endian u32 (a binary count or offset) set to an extreme.
                let i = rng.below(n - 3);
                let v = [0u32, 1, 0x7fff_ffff, u32::MAX, 1 << 20][rng.below(5)];
                d[i..i + 4].copy_from_slice(&v.to_le_bytes());
            }
            _ => {}
        }
    }
    d
}

/// Small files of each type, written out here so the test needs nothing else.
fn own_seeds() -> Vec<(&'static str, Vec<u8>)> {
    let ply_ascii =
        b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nelement face 1\n\
property list uchar int vertex_indices\nend_header\n0 0 0 255 0 0\n1 0 0 0 255 0\n0 1 0 0 0 255\n\
3 0 1 2\n"
            .to_vec();
    let mut ply_bin = b"ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\n\
property float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\n\
end_header\n"
        .to_vec();
    for v in [0f32, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        ply_bin.extend(v.to_le_bytes());
    }
    let obj = b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\n\
f 1/1/1 2/2/1 3/3/1 4/1/1\ng two\nf 1 3 4\n"
        .to_vec();
    let mut cloud = 2i32.to_le_bytes().to_vec();
    for k in 0..2 {
        for v in [k as f32, 0.0, 0.0, 0.0, 1.0, 0.0] {
            cloud.extend(v.to_le_bytes());
        }
        cloud.extend([200u8, 100, 50]);
    }
    // A triangle with its buffer inline (positions then u16 indices), as JSON and as GLB.
    let mut bin = Vec::new();
    for v in [0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        bin.extend(v.to_le_bytes());
    }
    for i in [0u16, 1, 2, 0] {
        bin.extend(i.to_le_bytes());
    }
    let json = |uri: &str| {
        format!(
            r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],
"nodes":[{{"mesh":0,"translation":[0,0,-1]}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1,"material":0}}]}}],
"materials":[{{"pbrMetallicRoughness":{{"baseColorFactor":[0.8,0.2,0.2,1]}},"emissiveFactor":[0,0,0]}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},
{{"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}}],
"bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":6}}],
"buffers":[{{"byteLength":44{uri}}}]}}"#
        )
    };
    let b64 = base64(&bin);
    let gltf = json(&format!(
        ",\"uri\":\"data:application/octet-stream;base64,{b64}\""
    ));
    let mut glb_json = json("").into_bytes();
    while glb_json.len() % 4 != 0 {
        glb_json.push(b' ');
    }
    let mut glb = b"glTF".to_vec();
    glb.extend(2u32.to_le_bytes());
    glb.extend(((12 + 8 + glb_json.len() + 8 + bin.len()) as u32).to_le_bytes());
    glb.extend((glb_json.len() as u32).to_le_bytes());
    glb.extend(b"JSON");
    glb.extend(&glb_json);
    glb.extend((bin.len() as u32).to_le_bytes());
    glb.extend(b"BIN\0");
    glb.extend(&bin);
    let toml = b"name = \"t\"\n[[include]]\nname = \"cube\"\nbuiltin = \"cube\"\nscale = 0.5\ndynamic = true\n\
[[light]]\ntype = \"area\"\nintensity = 5.0\nposition = [0.0, 2.0, 0.0]\ndirection = [0.0, -1.0, 0.0]\n\
shape = \"rect\"\nsize = [0.5, 0.5]\n[[animation]]\ntarget = \"cube\"\n\
oscillate = { axis = [1.0, 0.0, 0.0], amplitude = 0.5, period = 2.0 }\n[camera]\n\
position = [0.0, 1.0, 4.0]\ntarget = [0.0, 0.0, 0.0]\n[settings]\nvoxel_resolution = 64\n"
        .to_vec();
    let pcd_header = |data: &str| {
        format!(
            "VERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F U\nCOUNT 1 1 1 1\n\
             WIDTH 2\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nDATA {data}\n"
        )
        .into_bytes()
    };
    let mut pcd_ascii = pcd_header("ascii");
    pcd_ascii.extend(b"0 0 0 13120020\n1 0.5 nan 3296456\n");
    let values: [[u32; 4]; 2] = [
        [0, 0, 0, 0xc83214],
        [1f32.to_bits(), 0.5f32.to_bits(), 0, 0x3214c8],
    ];
    let mut pcd_bin = pcd_header("binary");
    pcd_bin.extend(values.iter().flatten().flat_map(|v| v.to_le_bytes()));
    // Fields one after another, compressed (or, too short for LZF, its literal runs).
    let columns: Vec<u8> = (0..4)
        .flat_map(|k| values.iter().flat_map(move |p| p[k].to_le_bytes()))
        .collect();
    let packed = lzf::compress(&columns).unwrap_or_else(|_| {
        columns
            .chunks(32)
            .flat_map(|c| std::iter::once(c.len() as u8 - 1).chain(c.iter().copied()))
            .collect()
    });
    let mut pcd_lzf = pcd_header("binary_compressed");
    pcd_lzf.extend((packed.len() as u32).to_le_bytes());
    pcd_lzf.extend((columns.len() as u32).to_le_bytes());
    pcd_lzf.extend(&packed);
    vec![
        ("ply", ply_ascii),
        ("ply", ply_bin),
        ("obj", obj),
        ("pcd", pcd_ascii),
        ("pcd", pcd_bin),
        ("pcd", pcd_lzf),
        ("cloud", cloud),
        ("gltf", gltf.into_bytes()),
        ("glb", glb),
        ("toml", toml),
    ]
}

fn base64(bytes: &[u8]) -> String {
    const A: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::new();
    for c in bytes.chunks(3) {
        let n = (c[0] as u32) << 16
            | (*c.get(1).unwrap_or(&0) as u32) << 8
            | *c.get(2).unwrap_or(&0) as u32;
        for k in 0..4 {
            if k <= c.len() {
                s.push(A[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                s.push('=');
            }
        }
    }
    s
}

/// Files under `dir` of a type a loader reads, at most `max` bytes each.
fn seeds_in(dir: &Path, max: u64) -> Vec<(String, PathBuf)> {
    let mut out = Vec::new();
    let Ok(entries) = std::fs::read_dir(dir) else {
        return out;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            out.extend(seeds_in(&p, max));
            continue;
        }
        let ext = p
            .extension()
            .map(|x| x.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        let small = e.metadata().map(|m| m.len() <= max).unwrap_or(false);
        if small && voxgi_scene::io::EXTENSIONS.contains(&ext.as_str()) {
            out.push((ext, p));
        }
    }
    out.sort();
    out
}

#[test]
fn mutated_files_load_or_fail_without_panicking() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut seeds: Vec<(String, Vec<u8>)> = own_seeds()
        .into_iter()
        .map(|(e, d)| (e.to_string(), d))
        .collect();
    // Scene files that include others by relative path: mutants of them still find those
    // beside them only where the path is absolute, which is itself a case worth loading.
    let mut files = seeds_in(&root.join("fuzz/seeds"), 64 << 10);
    files.extend(seeds_in(&root.join("examples"), 64 << 10));
    files.extend(seeds_in(&root.join("../shared/scenes"), 256 << 10));
    for (ext, p) in files {
        if let Ok(d) = std::fs::read(&p) {
            seeds.push((ext, d));
        }
    }
    // A seed must load as it is (a scene file whose includes lie beside it elsewhere does
    // not, once copied): its mutants would only test the missing include.
    seeds.retain(|(ext, d)| load_as(ext, d).is_ok());
    assert!(seeds.len() >= 10, "{} seeds load", seeds.len());
    let quiet = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let mut rng = Rng(0x5eed_1234_abcd_0042);
    let mut failures = Vec::new();
    let (mut loads, mut loaded) = (0, 0);
    for (ext, seed) in &seeds {
        for k in 0..=MUTANTS {
            let data = if k == 0 {
                seed.clone()
            } else {
                mutate(seed, &mut rng)
            };
            loads += 1;
            let outcome = std::panic::catch_unwind(|| load_as(ext, &data).map(|_| ()));
            loaded += matches!(outcome, Ok(Ok(()))) as usize;

            if let Err(p) = outcome {
                let msg = p
                    .downcast_ref::<&str>()
                    .map(|s| s.to_string())
                    .or_else(|| p.downcast_ref::<String>().cloned())
                    .unwrap_or_default();
                let keep =
                    std::env::temp_dir().join(format!("voxgi-mutant-{}.{ext}", failures.len()));
                let _ = std::fs::write(&keep, &data);
                failures.push(format!("{}: panicked: {msg}", keep.display()));
            }
        }
    }
    std::panic::set_hook(quiet);
    println!(
        "{loads} loads of mutants of {} seeds, {loaded} of them loaded",
        seeds.len()
    );
    // Some mutants keep a loadable file (a flipped bit in a float, a changed number): if
    // fewer than one in twenty loaded, the mutations would test only each loader's first
    // checks.
    assert!(
        loaded * 20 > loads,
        "only {loaded} of {loads} mutants loaded"
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
