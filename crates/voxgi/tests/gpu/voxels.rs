//! The voxel kernels against their plain-Rust twins in `voxel::cpu` (voxelization exactly,
//! filtering within fp16 rounding), and the voxel debug views.

use crate::common::*;
use std::collections::BTreeSet;
use voxgi::gpu::readback::{f16_to_f32, read_buffer_copy, read_texture_3d};
use voxgi::scene::glam::{Mat4, Vec3, Vec4};
use voxgi::scene::{Material, Mesh, Scene, builtin};
use voxgi::voxel::{Grid, cpu};
use voxgi::{FrameParams, Renderer, RendererOptions, ViewMode};

/// One mesh holding `tris` (world space), each with its own vertices and face normal.
fn triangle_scene(tris: &[[Vec3; 3]]) -> Scene {
    let mut mesh = Mesh {
        name: "triangles".into(),
        positions: Vec::new(),
        normals: Vec::new(),
        uvs: Vec::new(),
        indices: Vec::new(),
        material: 0,
    };
    for t in tris {
        let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize();
        for p in t {
            mesh.indices.push(mesh.positions.len() as u32);
            mesh.positions.push(*p);
            mesh.normals.push(n);
        }
    }
    let mut s = Scene::default();
    s.add_mesh(mesh, Material::diffuse("grey", [0.5; 3]), Mat4::IDENTITY);
    s
}

/// Voxel coordinates of the non-zero entries of the occupancy buffer (x fastest), and the
/// values themselves.
fn occupied(r: &Renderer) -> (BTreeSet<[u32; 3]>, Vec<u32>) {
    let (device, queue) = (&ctx().device, &ctx().queue);
    let vol = r.structure::<voxgi::voxel::dense::DenseVolume>().unwrap();
    let bytes = read_buffer_copy(device, queue, &vol.occupancy).expect("occupancy readback");
    let words: &[u32] = bytemuck::cast_slice(&bytes);
    let res = vol.grid.resolution;
    let mut set = BTreeSet::new();
    let mut values = Vec::new();
    for (i, &w) in words.iter().take((res * res * res) as usize).enumerate() {
        if w != 0 {
            let i = i as u32;
            set.insert([i % res, (i / res) % res, i / (res * res)]);
            values.push(w);
        }
    }
    (set, values)
}

#[test]
fn voxelize_matches_cpu_exactly() {
    const RES: u32 = 16;
    // The large triangle spans [0, 0.875]^3, so `Grid::around` gives a side of exactly
    // 0.875 * 16 / 14 = 1 m: voxel size 1/16, origin -1/16 on every axis. World -> voxel space
    // is then exact in f32 on both sides (the GPU multiplies by 1/size, the CPU divides).
    let e = 0.875;
    let large = [
        Vec3::new(0.0, 0.13, e),
        Vec3::new(e, 0.0, 0.31),
        Vec3::new(0.23, e, 0.0),
    ];
    // A long sliver, about 12 voxels long and 1/200 voxel wide, in general position.
    let sliver = [
        Vec3::new(0.1017, 0.2093, 0.3071),
        Vec3::new(0.7013, 0.6029, 0.5047),
        Vec3::new(0.7016, 0.6032, 0.5049),
    ];
    // Axis-aligned, exactly in the face plane z = 0.25 m (voxel z = 5.0) between the voxel
    // centres of layers 4 and 5: a deliberate tie. It is chosen because its arithmetic is exact
    // on both sides (z = 0.25 and the grid are dyadic, the cross product's x and y are exactly
    // 0, every dot product along Z is exactly ±0.5), so the GPU and CPU float paths must agree.
    // Both kernels take candidates from floor(min)..=floor(max) of the triangle's bounds, so a
    // triangle lying in a face plane lands in the layer above the plane only (5, not 4).
    let in_face = [
        Vec3::new(0.3011, 0.2027, 0.25),
        Vec3::new(0.6043, 0.2519, 0.25),
        Vec3::new(0.3537, 0.7049, 0.25),
    ];
    // Tiny, inside voxel (7, 8, 9) (voxel coordinates 7.56.., 8.52.., 9.48..).
    let tiny = [
        Vec3::new(0.4101, 0.4702, 0.5303),
        Vec3::new(0.4131, 0.4709, 0.5311),
        Vec3::new(0.4113, 0.4731, 0.5297),
    ];
    let tris = [large, sliver, in_face, tiny];
    let scene = triangle_scene(&tris);
    let b = scene.bounds();
    let grid = Grid::around(b.min, b.max, RES);
    assert_eq!(
        grid.voxel_size,
        1.0 / 16.0,
        "the grid is not the dyadic one"
    );
    assert_eq!(grid.origin, Vec3::splat(-1.0 / 16.0));

    let settings = RendererOptions {
        voxel_resolution: RES,
        bounces: 0,
        ..measuring()
    };
    let mut r = renderer(&scene, &settings);
    assert_eq!(r.volume().grid(), grid);
    let cam = clamped(r.default_camera());
    frame(&mut r, &cam, 16, 16);

    let (gpu, values) = occupied(&r);
    let expected = cpu::voxelize(&tris, &grid);
    // The test scene does what it claims.
    let single: BTreeSet<[u32; 3]> = [[7, 8, 9]].into();
    assert_eq!(cpu::voxelize(&[tiny], &grid), single, "tiny triangle");
    let face = cpu::voxelize(&[in_face], &grid);
    assert!(
        face.contains(&[6, 6, 5]) && face.iter().all(|v| v[2] == 5),
        "the in-face triangle is in layer 5 only: {face:?}"
    );
    assert!(cpu::voxelize(&[sliver], &grid).len() >= 12, "sliver");
    let missing: Vec<_> = expected.difference(&gpu).collect();
    let extra: Vec<_> = gpu.difference(&expected).collect();
    assert!(
        missing.is_empty() && extra.is_empty(),
        "GPU voxelization differs from the CPU's ({} voxels): missing on the GPU {:?}, extra \
         on the GPU {:?}",
        expected.len(),
        missing,
        extra
    );

    let voxgi::VoxelCounts {
        fragments,
        occupied: count,
    } = r.voxel_counts().expect("counts");
    assert_eq!(
        count,
        gpu.len() as u64,
        "occupied voxels vs the slot counter"
    );
    assert!(
        fragments >= count,
        "{fragments} fragments < {count} occupied voxels"
    );
    // After the build every occupied voxel holds 2 + its slot, and the slots are 0..count.
    let mut slots: Vec<u32> = values
        .iter()
        .map(|&v| {
            assert!(v >= 2, "occupancy value {v}");
            v - 2
        })
        .collect();
    slots.sort_unstable();
    assert!(
        slots.iter().enumerate().all(|(i, &s)| s == i as u32),
        "slots are not 0..{count}"
    );
}

/// One triangle over most of a 1024³ grid's floor (about 1 M candidate columns) makes every
/// fragment the CPU twin counts. A CPU driver (llvmpipe) ends an invocation's loops after
/// 65535 iterations in all, silently; with one workgroup per triangle, 64 threads of 16 k
/// columns each, the GPU made 151 552 of the 774 094 fragments (20 %), 73 % at 512³. Split
/// into workgroups of `CHUNK_COLUMNS`, every column is done on any device. The tolerance:
/// the GPU and CPU round differently where the plane meets a voxel face exactly (348 voxels
/// here, 0.045 %; 4 of 3081 at 64³).
#[test]
fn a_triangle_over_a_whole_large_grid_makes_every_fragment() {
    let tri = [
        Vec3::new(0.0, 0.013, 0.0),
        Vec3::new(1.0, 0.3, 0.0),
        Vec3::new(0.0, 0.2, 1.0),
    ];
    let options = RendererOptions {
        voxels: voxgi::VoxelKind::OCTREE,
        voxel_resolution: 1024,
        bounces: 0,
        temporal: false,
        ..measuring()
    };
    let mut r = renderer(&triangle_scene(&[tri]), &options);
    let cam = clamped(r.default_camera());
    // A second frame in case the first outgrew the pools (it is then rebuilt with room).
    frame(&mut r, &cam, 16, 16);
    frame(&mut r, &cam, 16, 16);
    let gpu = r.voxel_counts().expect("counts").fragments as f64;
    let cpu = cpu::voxelize(&[tri], &r.volume().grid()).len() as f64;
    assert!(
        (gpu - cpu).abs() <= 0.002 * cpu,
        "{gpu} fragments on the GPU, {cpu} on the CPU"
    );
}

/// The Cornell box's walls at 256³ leave no hole. Its back wall lies on the scene bounds, one
/// float step from a voxel face (z = 255.00002 in voxel space): on an NVIDIA H100 the plane's
/// depth per column once came out below the triangle's own depth range, the candidate range
/// was then empty, and one of the wall's two triangles vanished (32 k of 422 k fragments; the
/// mean indirect light at 256³ fell 8 %). lavapipe rounds differently and never showed it, so
/// this test guards the real GPUs the suite is also run on.
#[test]
fn walls_on_voxel_faces_leave_no_holes() {
    let mut r = cornell(256, true);
    let cam = clamped(r.default_camera());
    frame(&mut r, &cam, 8, 8);
    let (gpu, _) = occupied(&r);
    let grid = r.volume().grid();
    let voxel = |m: f32, axis: usize| (m * 0.001 - grid.origin[axis]) / grid.voxel_size;

    // (wall, axis of its normal, its plane in mm, and its extent in mm along the other two
    // axes, taken 2 voxels inside the edges so that only whole columns are checked).
    let walls = [
        ("floor", 1, 0.0, [(0.0, 549.6), (0.0, 559.2)]),
        ("ceiling", 1, 548.8, [(0.0, 556.0), (0.0, 559.2)]),
        ("back wall", 2, 559.2, [(0.0, 549.6), (0.0, 548.8)]),
    ];
    let mut report = Vec::new();
    for (name, axis, plane, extent) in walls {
        let others = [(axis + 1) % 3, (axis + 2) % 3];
        let range = |i: usize| {
            let (lo, hi) = extent[if others[i] < axis {
                others[i]
            } else {
                others[i] - 1
            }];
            let (lo, hi) = (voxel(lo, others[i]), voxel(hi, others[i]));
            (lo.ceil() as u32 + 2)..(hi.floor() as u32).saturating_sub(2)
        };
        // A face plane's voxels are the layer on either side, depending on rounding.
        let k = voxel(plane, axis).round() as u32;
        let (mut columns, mut holes) = (0, 0);
        for cu in range(0) {
            for cv in range(1) {
                let at = |w: u32| {
                    let mut c = [0u32; 3];
                    c[axis] = w;
                    c[others[0]] = cu;
                    c[others[1]] = cv;
                    c
                };
                columns += 1;
                if !gpu.contains(&at(k.saturating_sub(1))) && !gpu.contains(&at(k)) {
                    holes += 1;
                }
            }
        }
        assert!(
            columns > 200 * 200,
            "{name}: only {columns} columns checked"
        );
        report.push((name, holes, columns));
    }
    assert!(
        report.iter().all(|&(_, holes, _)| holes == 0),
        "columns without a voxel (wall, holes, columns): {report:?}"
    );
}

/// One mip level of a rgba16float 3D texture as f32 texels (x fastest), and its side.
fn read_level(t: &wgpu::Texture, mip: u32) -> (Vec<Vec4>, u32) {
    let (device, queue) = (&ctx().device, &ctx().queue);
    let bytes = read_texture_3d(device, queue, t, mip).expect("3D readback");
    let halves: &[u16] = bytemuck::cast_slice(&bytes);
    let texels = halves
        .chunks_exact(4)
        .map(|h| {
            Vec4::new(
                f16_to_f32(h[0]),
                f16_to_f32(h[1]),
                f16_to_f32(h[2]),
                f16_to_f32(h[3]),
            )
        })
        .collect();
    (texels, (t.width() >> mip).max(1))
}

/// Checks every parent of `parent` (side n) against `cpu::filter_parent` of its children in
/// `child` (side 2n), both premultiplied (as the chains store them). Returns (parents checked,
/// parents with 0 < opacity < 1).
fn check_filter_step(
    child: &[Vec4],
    parent: &[Vec4],
    n: u32,
    dir: Option<u32>,
    what: &str,
) -> (u32, u32) {
    let m = 2 * n;
    assert_eq!(
        child.len(),
        (m * m * m) as usize,
        "{what}: child level size"
    );
    assert_eq!(
        parent.len(),
        (n * n * n) as usize,
        "{what}: parent level size"
    );
    let mut partial = 0;
    let mut worst = (0.0f32, [0u32; 3]);
    for z in 0..n {
        for y in 0..n {
            for x in 0..n {
                let children: [Vec4; 8] = std::array::from_fn(|i| {
                    let (cx, cy, cz) = (
                        2 * x + (i as u32 & 1),
                        2 * y + ((i as u32 >> 1) & 1),
                        2 * z + (i as u32 >> 2),
                    );
                    child[(cx + m * (cy + m * cz)) as usize]
                });
                let want = cpu::filter_parent(&children, dir);
                let got = parent[(x + n * (y + n * z)) as usize];
                // rgba16float keeps 11 significant bits: storing the GPU's f32 result rounds
                // it by at most 2^-11 ≈ 4.9e-4 relative; both sides compute in f32 from the
                // same fp16 children, so anything beyond 1e-3 relative is a real difference.
                // The absolute floor, 2^-14, is fp16's smallest normal (a GPU may flush fp16
                // subnormals).
                for c in 0..4 {
                    let err = (got[c] - want[c]).abs();
                    let tol = 1e-3 * want[c].abs() + 6.2e-5;
                    assert!(
                        err <= tol,
                        "{what}: parent ({x}, {y}, {z}) channel {c}: GPU {got}, CPU {want} \
                         (children {children:?})"
                    );
                    if err / tol > worst.0 {
                        worst = (err / tol, [x, y, z]);
                    }
                }
                if got.w > 0.01 && got.w < 0.99 {
                    partial += 1;
                }
            }
        }
    }
    (n * n * n, partial)
}

/// A measuring renderer of the Cornell box at `voxel_resolution`.
fn cornell(voxel_resolution: u32, anisotropic: bool) -> Renderer {
    renderer(
        &builtin::cornell_box(),
        &cornell_options(voxel_resolution, anisotropic),
    )
}

fn cornell_options(voxel_resolution: u32, anisotropic: bool) -> RendererOptions {
    RendererOptions {
        voxel_resolution,
        anisotropic,
        ..measuring()
    }
}

fn check_filtering(anisotropic: bool) {
    // The leaves as they are (NDF weights: `voxel_filter_weighs_leaves_by_their_normals`).
    let settings = RendererOptions {
        ndf_mips: false,
        ..cornell_options(16, anisotropic)
    };
    let mut r = renderer(&builtin::cornell_box(), &settings);
    let cam = clamped(r.default_camera());
    frame(&mut r, &cam, 16, 16);
    let vol = r.structure::<voxgi::voxel::dense::DenseVolume>().unwrap();
    let levels = vol.grid.levels();
    let (finest, res) = read_level(&vol.radiance, 0);
    assert_eq!(res, 16);
    // The test can only fail if the volume has structure: lit and unlit voxels, coloured ones.
    let lit = finest
        .iter()
        .filter(|v| v.w > 0.0 && v.x + v.y + v.z > 1e-3)
        .count();
    let empty = finest.iter().filter(|v| v.w == 0.0).count();
    let reddish = finest
        .iter()
        .filter(|v| v.w > 0.0 && v.x > 2.0 * v.y + 1e-4)
        .count();
    assert!(
        lit > 50 && empty > 100 && reddish > 5,
        "lit {lit}, empty {empty}, red {reddish}"
    );

    let dirs: Vec<Option<u32>> = if anisotropic {
        (0..6).map(Some).collect()
    } else {
        vec![None]
    };
    assert_eq!(vol.chain_blocks() as usize, dirs.len());
    let chains: Vec<Vec<Vec4>> = (0..levels - 1)
        .map(|mip| read_level(&vol.chains, mip).0)
        .collect();
    let mut partial = 0;
    // The finest level stores optical depth, the chains premultiplied opacity.
    let finest: Vec<Vec4> = finest.iter().map(|v| cpu::from_depth(*v)).collect();
    for (block, dir) in dirs.into_iter().enumerate() {
        let mut child = finest.clone();
        for (mip, level) in chains.iter().enumerate() {
            // Blocks are stacked along z, so each is a contiguous run of n^3 texels.
            let n = (res >> (mip + 1)).max(1);
            let cube = (n * n * n) as usize;
            let parent = level[block * cube..(block + 1) * cube].to_vec();
            let what = format!("chain {dir:?}, level {}", mip + 1);
            partial += check_filter_step(&child, &parent, n, dir, &what).1;
            child = parent;
        }
    }
    // Partly transparent parents: the directional compositing (not just the mean) is tested.
    assert!(partial > 20, "only {partial} partly transparent parents");
}

#[test]
fn voxel_filter_matches_cpu_anisotropic() {
    check_filtering(true);
}

#[test]
fn voxel_filter_matches_cpu_isotropic() {
    check_filtering(false);
}

/// With `ndf_mips` the first directional level weighs each finest voxel by its normals
/// (`cpu::ndf_weight`) before the front-to-back pairs: the GPU's level 1 against the CPU's, per
/// direction, from the finest radiance and normals read back.
#[test]
fn voxel_filter_weighs_leaves_by_their_normals() {
    let settings = RendererOptions {
        voxel_resolution: 16,
        ndf_mips: true,
        ..measuring()
    };
    let mut r = renderer(&builtin::cornell_box(), &settings);
    let cam = clamped(r.default_camera());
    frame(&mut r, &cam, 16, 16);
    let vol = r.structure::<voxgi::voxel::dense::DenseVolume>().unwrap();
    let (finest, res) = read_level(&vol.radiance, 0);
    let (device, queue) = (&ctx().device, &ctx().queue);
    let bytes = read_texture_3d(device, queue, &vol.normal, 0).expect("normal readback");
    let normals: Vec<Vec4> = bytes
        .chunks_exact(4)
        .map(|b| {
            let f = |v: u8| (v as i8 as f32 / 127.0).max(-1.0);
            Vec4::new(f(b[0]), f(b[1]), f(b[2]), f(b[3]))
        })
        .collect();
    assert_eq!(normals.len(), finest.len());
    let level = read_level(&vol.chains, 0).0;
    let n = res / 2;
    let cube = (n * n * n) as usize;
    let mut reduced = 0;
    for dir in 0..6u32 {
        // The children as this direction counts them, premultiplied as the chains store them.
        let child: Vec<Vec4> = finest
            .iter()
            .zip(&normals)
            .map(|(c, nl)| cpu::ndf_weight(*nl, dir) * cpu::from_depth(*c))
            .collect();
        reduced += finest
            .iter()
            .zip(&normals)
            .filter(|(c, nl)| c.w > 0.0 && cpu::ndf_weight(**nl, dir) < 0.9)
            .count();
        let parent = level[dir as usize * cube..(dir as usize + 1) * cube].to_vec();
        check_filter_step(
            &child,
            &parent,
            n,
            Some(dir),
            &format!("NDF, direction {dir}"),
        );
    }
    // The walls are seen edge-on or from behind along most directions: the weights must bite.
    assert!(reduced > 100, "only {reduced} leaves weighed below 0.9");
}

const SIZE: u32 = 48;

fn voxel_view(r: &mut Renderer, view: ViewMode, level: u32, dir: u32) -> voxgi::RenderOutput {
    let p = FrameParams {
        view,
        debug_level: level,
        debug_direction: dir,
        ..clamped(r.default_camera())
    };
    frame(r, &p, SIZE, SIZE)
}

#[test]
fn voxel_debug_views_are_plausible() {
    let mut r = cornell(32, true);
    let (c, mid) = (SIZE / 2, SIZE / 2);
    // Seen from the standard camera, the red wall is on the left, the green one on the right.
    let (left, right) = (SIZE / 10, SIZE - 1 - SIZE / 10);
    for level in [0, 2] {
        // Opacity: the centre sees an opaque surface (the tall block or the back wall).
        let out = voxel_view(&mut r, ViewMode::VoxelOpacity, level, 4);
        let o = out.radiance(c, mid);
        assert!(
            o[0] > 0.5 && o[0] <= 1.0 + 1e-3 && o[0] == o[1],
            "level {level}: opacity {o:?}"
        );
        // Albedo: the finest albedo under the hit. Each side wall in the chain of the cones
        // that meet its face (the red wall's faces -X, the +X chain's; the green wall's +X):
        // above the finest level a face seen from behind is not there (`cpu::ndf_weight`).
        let out = voxel_view(&mut r, ViewMode::VoxelAlbedo, level, 0);
        let red = out.radiance(left, mid);
        let white = out.radiance(c, SIZE / 5);
        let green = voxel_view(&mut r, ViewMode::VoxelAlbedo, level, 1).radiance(right, mid);
        assert!(
            red[0] > 0.4 && red[0] > 3.0 * red[1] && red[0] > 3.0 * red[2],
            "level {level}: red wall {red:?}"
        );
        assert!(
            green[1] > 0.3 && green[1] > 2.0 * green[0],
            "level {level}: green wall {green:?}"
        );
        assert!(
            white.iter().all(|&v| (0.6..0.8).contains(&v)),
            "level {level}: back wall {white:?}"
        );
        // Radiance: finite and non-negative everywhere; the red wall reflects mostly red.
        let out = voxel_view(&mut r, ViewMode::VoxelRadiance, level, 0);
        assert!(
            out.hdr.iter().all(|v| v.is_finite() && *v >= 0.0),
            "level {level}"
        );
        let m = out.mean_radiance();
        assert!(
            m.iter().all(|&v| v > 0.0),
            "level {level}: mean radiance {m:?}"
        );
        let red = out.radiance(left, mid);
        assert!(
            red[0] > red[1] && red[0] > red[2],
            "level {level}: red wall radiance {red:?}"
        );
    }
    // Out-of-range levels and directions are errors, not clamps.
    for bad in [
        FrameParams {
            debug_level: 6,
            ..clamped(r.default_camera())
        },
        FrameParams {
            debug_direction: 6,
            ..clamped(r.default_camera())
        },
    ] {
        assert!(voxgi::headless::render(ctx(), &mut r, &bad, 8, 8).is_err());
    }
}

/// The octree's GPU build against its CPU twin: from the fragments of the Cornell box at 32³,
/// the same nodes get children at every depth (exactly: the twin takes the voxels the dense
/// build found occupied, which `voxelize_matches_cpu_exactly` ties to the CPU voxelizer), and
/// every leaf holds exactly the attributes the dense volume's voxel holds (both average the same
/// integer sums with the same rounding).
#[test]
fn octree_build_matches_its_cpu_twin() {
    use voxgi::voxel::octree::{SLOT_WORDS, cpu as ocpu};
    let (device, queue) = (&ctx().device, &ctx().queue);
    let scene = builtin::cornell_box();
    let dense_options = RendererOptions {
        voxel_resolution: 32,
        ..measuring()
    };
    let octree_options = RendererOptions {
        voxels: voxgi::VoxelKind::OCTREE,
        ..dense_options.clone()
    };
    let params = |r: &Renderer| FrameParams::new(r.default_camera().clone());
    let mut dense = renderer(&scene, &dense_options);
    let p = params(&dense);
    frame(&mut dense, &p, 8, 8);
    let (want_voxels, _) = occupied(&dense);
    let mut octree = renderer(&scene, &octree_options);
    let p = params(&octree);
    frame(&mut octree, &p, 8, 8);
    let tree = octree
        .structure::<voxgi::voxel::octree::OctreeVolume>()
        .unwrap();
    let nodes_bytes = read_buffer_copy(device, queue, &tree.nodes).expect("nodes");
    let nodes: &[u32] = bytemuck::cast_slice(&nodes_bytes);
    let got = ocpu::walk(nodes, &tree.layout);
    let want = ocpu::subdivided(&want_voxels, tree.depth());
    for (t, (g, w)) in got.iter().zip(&want).enumerate() {
        eprintln!("depth {t}: {} nodes with children", g.len());
        assert_eq!(
            g, w,
            "depth {t}: the GPU's nodes differ from the CPU twin's"
        );
    }
    assert_eq!(got[5].len(), want_voxels.len());
    assert!(want_voxels.len() > 1000, "the scene must fill the tree");

    // Leaves: every slot's attributes equal the dense volume's at its voxel.
    let vol = dense
        .structure::<voxgi::voxel::dense::DenseVolume>()
        .unwrap();
    let res = vol.grid.resolution;
    let texels = |t: &wgpu::Texture| read_texture_3d(device, queue, t, 0).expect("texture");
    let (albedo, normal, emission) = (
        texels(&vol.albedo),
        texels(&vol.normal),
        texels(&vol.emission),
    );
    let slots_bytes = read_buffer_copy(device, queue, &tree.slots).expect("slots");
    let slots: &[u32] = bytemuck::cast_slice(&slots_bytes);
    let count = nodes[0] as usize;
    assert_eq!(count, want_voxels.len(), "one leaf per occupied voxel");
    let mut seen = BTreeSet::new();
    for s in slots.chunks_exact(SLOT_WORDS as usize).take(count) {
        let c = [s[0] & 1023, (s[0] >> 10) & 1023, s[0] >> 20];
        assert!(seen.insert(c), "voxel {c:?} has two leaves");
        let i = (c[0] + res * (c[1] + res * c[2])) as usize;
        let word =
            |bytes: &[u8], at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap());
        assert_eq!(s[2], word(&albedo, 4 * i), "albedo of {c:?}");
        // The octree packs its normal in the shader (pack4x8snorm: WGSL rounds half to even);
        // the dense volume stores to an rgba8snorm texture, whose conversion Vulkan leaves to
        // the hardware ("should round to nearest"): an H200 rounds a tie the other way. One
        // step (1/127) apart at most.
        let (a, b) = (s[3].to_le_bytes(), word(&normal, 4 * i).to_le_bytes());
        assert!(
            a.iter()
                .zip(&b)
                .all(|(x, y)| (*x as i8).abs_diff(*y as i8) <= 1),
            "normal of {c:?}: {a:?} in the octree, {b:?} in the dense volume"
        );
        assert_eq!(s[4], word(&emission, 8 * i), "emission (rg) of {c:?}");
        assert_eq!(
            s[5] & 0xffff,
            word(&emission, 8 * i + 4) & 0xffff,
            "emission (b) of {c:?}"
        );
    }
    assert_eq!(seen, want_voxels);
}
