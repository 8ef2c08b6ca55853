//! The octree's two brick layouts compared on real geometry, on the CPU: voxgi's voxel-centred
//! 2³ bricks with a positive border (stored as 3³) against the vertex-centred 3³ bricks of
//! Crassin et al. 2011 §4.1. Prints, per scene and resolution, the bricks and bytes each layout
//! needs and how far each one's finest-level opacity lies from the dense volume's (the
//! voxel-centred trilinear field voxgi calibrates against the path tracer).
//!
//!     cargo run --release -p voxgi --example brick_layouts [SCENE.obj|.ply|.gltf ...]
//!
//! Without arguments: the built-in Cornell box and, when `../shared/scenes` is there, Sponza.

use std::collections::BTreeSet;
use voxgi::scene::glam::{IVec3, Vec3};
use voxgi::scene::{Scene, builtin, io};
use voxgi::voxel::Grid;
use voxgi::voxel::cpu::voxelize;
use voxgi::voxel::octree::cpu::subdivided;

/// Optical depth of an occupied voxel: opacity 0.999, the dense volume's cap.
const SIGMA: f32 = 6.907_755;

fn triangles(scene: &Scene) -> Vec<[Vec3; 3]> {
    let mut out = Vec::new();
    for inst in &scene.instances {
        if inst.light.is_some() {
            continue;
        }
        let m = &scene.meshes[inst.mesh];
        for t in m.indices.chunks_exact(3) {
            let p = |i: u32| inst.transform.transform_point3(m.positions[i as usize]);
            out.push([p(t[0]), p(t[1]), p(t[2])]);
        }
    }
    out
}

/// The dense volume's field: trilinear over voxel centres (p in finest-voxel units).
fn voxel_centred(occ: &BTreeSet<[u32; 3]>, p: Vec3) -> f32 {
    let q = p - 0.5;
    let b = q.floor();
    let f = q - b;
    let mut s = 0.0;
    for i in 0..8 {
        let o = IVec3::new(i & 1, (i >> 1) & 1, i >> 2);
        let c = b.as_ivec3() + o;
        let w: f32 = (0..3)
            .map(|a| if o[a] == 1 { f[a] } else { 1.0 - f[a] })
            .product();
        if c.min_element() >= 0 && occ.contains(&[c.x as u32, c.y as u32, c.z as u32]) {
            s += w * SIGMA;
        }
    }
    1.0 - (-s).exp()
}

/// voxgi's bricks: the dense field wherever the brick of the node under floor(p - 0.5) exists,
/// 0 elsewhere (the sampler clamps p - 0.5 to the grid as a clamp-to-edge sampler would).
fn voxgi_bricks(occ: &BTreeSet<[u32; 3]>, nodes: &BTreeSet<[u32; 3]>, res: u32, p: Vec3) -> f32 {
    let q = (p - 0.5).clamp(Vec3::ZERO, Vec3::splat(res as f32 - 1.0));
    let n: voxgi::scene::glam::UVec3 = q.floor().as_uvec3() >> 1u32;
    if !nodes.contains(&[n.x, n.y, n.z]) {
        return 0.0;
    }
    voxel_centred(occ, p)
}

/// Vertex-centred bricks: values on voxel corners (each the mean of the eight voxels around
/// it: the fragments lie on the voxel grid), trilinear inside a node of two voxels, and only
/// where the node holds geometry (`nodes`; None: as if every node had a brick).
fn vertex_centred(occ: &BTreeSet<[u32; 3]>, nodes: Option<&BTreeSet<[u32; 3]>>, p: Vec3) -> f32 {
    let cell = (p / 2.0).floor().as_ivec3();
    let has = |n: &BTreeSet<[u32; 3]>| n.contains(&[cell.x as u32, cell.y as u32, cell.z as u32]);
    if cell.min_element() < 0 || nodes.is_some_and(|n| !has(n)) {
        return 0.0;
    }
    let corner = |c: IVec3| -> f32 {
        let mut n = 0;
        for i in 0..8 {
            let v = c - IVec3::new(i & 1, (i >> 1) & 1, i >> 2);
            if v.min_element() >= 0 && occ.contains(&[v.x as u32, v.y as u32, v.z as u32]) {
                n += 1;
            }
        }
        SIGMA * n as f32 / 8.0
    };
    let b = p.floor();
    let f = p - b;
    let mut s = 0.0;
    for i in 0..8 {
        let o = IVec3::new(i & 1, (i >> 1) & 1, i >> 2);
        let w: f32 = (0..3)
            .map(|a| if o[a] == 1 { f[a] } else { 1.0 - f[a] })
            .product();
        s += w * corner(b.as_ivec3() + o);
    }
    1.0 - (-s).exp()
}

fn report(name: &str, scene: &Scene, res: u32) {
    let b = scene.bounds();
    let grid = Grid::around(b.min, b.max, res);
    let occ = voxelize(&triangles(scene), &grid);
    let depth = res.ilog2();
    // voxgi's layout: the dilated node sets (`subdivided`); the vertex-centred one: the nodes
    // that hold geometry.
    let ours = subdivided(&occ, depth);
    let content: Vec<BTreeSet<[u32; 3]>> = (0..=depth)
        .map(|t| occ.iter().map(|c| c.map(|v| v >> (depth - t))).collect())
        .collect();
    // Bricks: one per subdivided node above the leaves (level 0 isotropic, 8 bytes a texel;
    // six directions above), nodes: 16 bytes above the leaves, 4 per leaf voxel.
    let bytes = |sets: &[BTreeSet<[u32; 3]>]| -> (u64, u64) {
        let mut bricks = 0u64;
        let mut nodes = 0u64;
        for (t, set) in sets.iter().enumerate().take(depth as usize) {
            let n = set.len() as u64;
            let dirs = if t == depth as usize - 1 { 1 } else { 6 };
            bricks += n * 27 * 8 * dirs;
            nodes += n * 8 * if t == depth as usize - 1 { 4 } else { 16 };
        }
        (bricks, nodes)
    };
    let (ob, on) = bytes(&ours);
    let (vb, vn) = bytes(&content);
    // Random points around the occupied voxels (a fixed LCG).
    let voxels: Vec<[u32; 3]> = occ.iter().copied().collect();
    let mut seed = 0x9e37_79b9_u32;
    let mut rnd = move || {
        seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (seed >> 8) as f32 / (1u32 << 24) as f32
    };
    let leaves = &content[depth as usize - 1];
    let (mut err_ours, mut err_vc, mut err_blur, mut n) = (0.0f64, 0.0f64, 0.0f64, 0u32);
    let mut worst_vc = 0.0f32;
    for _ in 0..20000 {
        let v = voxels[(rnd() * voxels.len() as f32) as usize % voxels.len()];
        let p = Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32)
            + Vec3::new(rnd(), rnd(), rnd()) * 4.0
            - 1.5;
        let dense = voxel_centred(&occ, p);
        let ob = voxgi_bricks(&occ, &ours[depth as usize - 1], res, p);
        let vc = vertex_centred(&occ, Some(leaves), p);
        err_blur += (vertex_centred(&occ, None, p) - dense).abs() as f64;
        err_ours += (ob - dense).abs() as f64;
        err_vc += (vc - dense).abs() as f64;
        worst_vc = worst_vc.max((vc - dense).abs());
        n += 1;
    }
    let mib = |b: u64| b as f64 / (1u64 << 20) as f64;
    println!(
        "{name} {res}³: {} occupied voxels\n  voxel-centred 2³ + border: {} bricks, {:.1} MiB bricks + {:.1} MiB nodes; \
         opacity error against the dense volume {:.4} (mean)\n  vertex-centred 3³:         {} bricks, {:.1} MiB bricks + {:.1} MiB nodes; \
         opacity error against the dense volume {:.4} (mean), {:.3} (worst); with a brick in every node {:.4}",
        occ.len(),
        ours[..depth as usize]
            .iter()
            .map(|s| s.len())
            .sum::<usize>(),
        mib(ob),
        mib(on),
        err_ours / n as f64,
        content[..depth as usize]
            .iter()
            .map(|s| s.len())
            .sum::<usize>(),
        mib(vb),
        mib(vn),
        err_vc / n as f64,
        worst_vc,
        err_blur / n as f64,
    );
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut scenes: Vec<(String, Scene)> = Vec::new();
    if args.is_empty() {
        scenes.push(("Cornell box".into(), builtin::cornell_box()));
        let sponza =
            std::path::Path::new("../shared/scenes/sponza_dabrovic_geometry_only/sponza.obj");
        match io::load(sponza) {
            Ok(s) => scenes.push(("Sponza".into(), s)),
            Err(e) => eprintln!("Sponza skipped: {e}"),
        }
    }
    for a in &args {
        match io::load(std::path::Path::new(a)) {
            Ok(s) => scenes.push((a.clone(), s)),
            Err(e) => eprintln!("{a}: {e}"),
        }
    }
    for (name, scene) in &scenes {
        for res in [64, 128, 256] {
            report(name, scene, res);
        }
    }
}
