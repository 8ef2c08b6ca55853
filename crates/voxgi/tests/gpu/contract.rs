//! The seam between cone tracing and the voxel structures: every structure defines the WGSL
//! contract with the right signatures, cone tracing uses nothing else of a structure, and the
//! dense volume's `sample_voxels` agrees with its CPU twin at random points of a tiny volume.

use crate::common::*;
use voxgi::gpu::readback::{f16_to_f32, read_texture_3d};
use voxgi::gpu::shader;
use voxgi::scene::builtin;
use voxgi::scene::glam::{UVec3, Vec3, Vec4};
use voxgi::voxel::VoxelKind;

/// `voxel::compose_for` of a registered kind.
fn compose_for(name: &str, kind: &str) -> String {
    voxgi::voxel::compose_for(name, kind).expect("a registered kind")
}
use voxgi::voxel::cpu::{DenseSampler, Texture3d};
use voxgi::{FrameParams, RendererOptions, wgpu};

fn parse(src: &str) -> naga::Module {
    naga::front::wgsl::parse_str(src).unwrap_or_else(|e| panic!("{}", e.emit_to_string(src)))
}

fn validate(module: &naga::Module) {
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::all(),
    )
    .validate(module)
    .unwrap_or_else(|e| panic!("{e:?}"));
}

/// A type's WGSL spelling, as far as the contract needs it.
fn type_name(m: &naga::Module, ty: naga::Handle<naga::Type>) -> String {
    use naga::{ScalarKind as K, TypeInner as T, VectorSize as V};
    let scalar = |s: naga::Scalar| match (s.kind, s.width) {
        (K::Float, 4) => "f32",
        (K::Bool, _) => "bool",
        (K::Uint, 4) => "u32",
        (K::Sint, 4) => "i32",
        _ => "?",
    };
    match &m.types[ty].inner {
        T::Scalar(s) => scalar(*s).into(),
        T::Vector { size, scalar: s } => {
            let n = match size {
                V::Bi => 2,
                V::Tri => 3,
                V::Quad => 4,
            };
            format!("vec{n}<{}>", scalar(*s))
        }
        other => format!("{other:?}"),
    }
}

/// Checks that `m` defines each function with these argument and result types ("": none).
fn check_functions(m: &naga::Module, kind: &str, contract: &[(&str, &[&str], &str)]) {
    for (name, args, result) in contract {
        let f = m
            .functions
            .iter()
            .map(|(_, f)| f)
            .find(|f| f.name.as_deref() == Some(name))
            .unwrap_or_else(|| panic!("{kind}: no fn {name}"));
        let got: Vec<String> = f.arguments.iter().map(|a| type_name(m, a.ty)).collect();
        assert_eq!(got, *args, "{kind}: {name}'s arguments");
        let ret = f.result.as_ref().map(|r| type_name(m, r.ty));
        assert_eq!(ret.unwrap_or_default(), *result, "{kind}: {name}'s result");
    }
}

/// The contract: each function's argument types and result type.
const CONTRACT: &[(&str, &[&str], &str)] = &[
    ("voxels_voxel_size", &[], "f32"),
    ("voxels_voxel_size_at", &["vec3<f32>"], "f32"),
    ("voxels_contains", &["vec3<f32>"], "bool"),
    (
        "sample_depth",
        &["vec3<f32>", "f32", "vec3<f32>"],
        "vec4<f32>",
    ),
    (
        "sample_depth_wide",
        &["vec3<f32>", "f32", "vec3<f32>"],
        "vec4<f32>",
    ),
    (
        "sample_voxels",
        &["vec3<f32>", "f32", "vec3<f32>"],
        "vec4<f32>",
    ),
];

#[test]
fn every_structure_defines_the_voxel_contract() {
    for kind in VoxelKind::names() {
        let src = compose_for(&format!("voxels/{kind}/sample.wgsl"), kind);
        let m = parse(&src);
        validate(&m);
        check_functions(&m, kind, CONTRACT);
        let wide = m
            .constants
            .iter()
            .find(|(_, c)| c.name.as_deref() == Some("WIDE_SAMPLE"))
            .unwrap_or_else(|| panic!("{kind}: no const WIDE_SAMPLE"))
            .1;
        assert_eq!(type_name(&m, wide.ty), "f32", "{kind}: WIDE_SAMPLE");
        // A structure's resources are @group(1): group 0 and 2 belong to the frame and the pass.
        for (_, g) in m.global_variables.iter() {
            if let Some(b) = &g.binding {
                assert_eq!(b.group, 1, "{kind}: {:?} is not in group 1", g.name);
            }
        }
    }
}

/// The leaves' contract of the lighting passes: names, signatures, and the groups (2 for the
/// leaves, 3 for their radiance store).
const LEAVES: &[(&str, &[&str], &str)] = &[
    ("leaf_slot", &["u32"], "u32"),
    ("leaf_exists", &["u32"], "bool"),
    ("leaf_is_new", &["u32"], "bool"),
    ("leaf_coord", &["u32"], "vec3<u32>"),
    ("leaf_center", &["u32"], "vec3<f32>"),
    ("leaf_size", &["u32"], "f32"),
    ("leaf_size_max", &[], "f32"),
    ("leaf_albedo", &["u32"], "vec4<f32>"),
    ("leaf_normal", &["u32"], "vec4<f32>"),
    ("leaf_emission", &["u32"], "vec3<f32>"),
];

#[test]
fn every_structure_defines_the_leaf_contract() {
    for kind in VoxelKind::names() {
        let src = compose_for(&format!("voxels/{kind}/leaf_store.wgsl"), kind);
        let m = parse(&src);
        validate(&m);
        check_functions(&m, kind, LEAVES);
        check_functions(
            &m,
            kind,
            &[("store_leaf_radiance", &["u32", "vec4<f32>"], "")],
        );
        for var in ["leaf_direct", "leaf_next"] {
            let g = m
                .global_variables
                .iter()
                .find(|(_, g)| g.name.as_deref() == Some(var))
                .unwrap_or_else(|| panic!("{kind}: no {var}"))
                .1;
            assert!(
                matches!(
                    g.space,
                    naga::AddressSpace::Storage {
                        access
                    } if access.contains(naga::StorageAccess::STORE)
                ),
                "{kind}: {var} must be writable storage"
            );
        }
        for (_, g) in m.global_variables.iter() {
            if let Some(b) = &g.binding {
                assert!(
                    b.group == 2 || b.group == 3,
                    "{kind}: {:?} is in group {}",
                    g.name,
                    b.group
                );
            }
        }
    }
}

/// The irradiance lookup of the fast shading (shared/leaf_irradiance.wgsl): names and
/// signatures, and its own resources at group 3 (the sampling group's at 1).
#[test]
fn every_structure_defines_the_irradiance_lookup() {
    for kind in VoxelKind::names() {
        let src = compose_for(&format!("voxels/{kind}/irradiance.wgsl"), kind);
        let m = parse(&src);
        validate(&m);
        check_functions(
            &m,
            kind,
            &[
                ("irradiance_grid", &["vec3<f32>"], "vec3<f32>"),
                ("leaf_irradiance_at", &["vec3<i32>"], "vec4<u32>"),
            ],
        );
        let own: Vec<_> = m
            .global_variables
            .iter()
            .filter_map(|(_, g)| g.binding.as_ref().map(|b| (g.name.clone(), b.group)))
            .filter(|(_, group)| *group != 1)
            .collect();
        assert!(
            own.iter().all(|(_, group)| *group == 3) && !own.is_empty(),
            "{kind}: the lookup's own resources must be in group 3: {own:?}"
        );
    }
}

/// Cone tracing compiles against a stand-in structure that defines the contract and nothing
/// else: it reaches into no structure's own names.
#[test]
fn cone_tracing_uses_only_the_contract() {
    let cone = compose_for("shared/cone.wgsl", "dense");
    let dense = compose_for("voxels/dense/sample.wgsl", "dense");
    // What the including shader brings: the shared structs and constants.
    let volume = shader::compose("shared/volume.wgsl");
    let scene = shader::compose("shared/scene.wgsl");
    assert!(
        cone.contains(&dense),
        "cone.wgsl no longer includes voxels/sample.wgsl"
    );
    let stub = format!(
        "{volume}
const WIDE_SAMPLE: f32 = 2.0;
fn voxels_voxel_size() -> f32 {{ return 0.1; }}
fn voxels_voxel_size_at(p: vec3<f32>) -> f32 {{ return 0.1; }}
fn voxels_contains(p: vec3<f32>) -> bool {{ return true; }}
fn sample_depth(p: vec3<f32>, d: f32, dir: vec3<f32>) -> vec4<f32> {{ return vec4<f32>(0.0); }}
fn sample_depth_wide(p: vec3<f32>, d: f32, dir: vec3<f32>) -> vec4<f32> {{ return vec4<f32>(0.0); }}
fn sample_voxels(p: vec3<f32>, d: f32, dir: vec3<f32>) -> vec4<f32> {{ return vec4<f32>(0.0); }}
"
    );
    let src = scene
        + &cone.replace(&dense, &stub)
        + "@group(0) @binding(0) var<uniform> cones: Cones;
@compute @workgroup_size(1)
fn main() {
    let g = gather_diffuse(vec3<f32>(0.0), vec3<f32>(0.0, 0.0, 1.0), vec2<f32>(0.0), true, ALL_CONES, 0.1, 0u, 0u);
}
";
    validate(&parse(&src));
}

/// A mip chain read back from an fp16 3D texture.
pub fn read_chain(t: &wgpu::Texture) -> Texture3d {
    let levels = (0..t.mip_level_count())
        .map(|mip| {
            let bytes = read_texture_3d(&ctx().device, &ctx().queue, t, mip).expect("readback");
            let halves: &[u16] = bytemuck::cast_slice(&bytes);
            let texels = halves
                .chunks_exact(4)
                .map(|h| Vec4::from_array([0, 1, 2, 3].map(|i| f16_to_f32(h[i]))))
                .collect();
            let size = UVec3::new(
                t.width() >> mip,
                t.height() >> mip,
                t.depth_or_array_layers() >> mip,
            )
            .max(UVec3::ONE);
            (texels, size)
        })
        .collect();
    Texture3d { levels }
}

const PROBE: &str = "
struct Probe { p: vec4<f32>, dir: vec4<f32> }
@group(0) @binding(0) var<storage, read> probes: array<Probe>;
@group(0) @binding(1) var<storage, read_write> results: array<vec4<f32>>;
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= arrayLength(&probes) {
        return;
    }
    let q = probes[id.x];
    results[id.x] = sample_voxels(q.p.xyz, q.p.w, q.dir.xyz);
}
";

/// Random probes: points over the volume and a little outside it (where the answer is 0),
/// diameters of one to `max_voxels` voxels, directions over the sphere; a fixed LCG, so the
/// test is the same every run. Each probe is (p, diameter, dir, 0).
pub fn random_probes(grid: voxgi::voxel::Grid, n: usize, max_voxels: f32) -> Vec<[f32; 8]> {
    let mut seed = 0x2545_f491_u32;
    let mut rnd = move || {
        seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (seed >> 8) as f32 / (1u32 << 24) as f32
    };
    (0..n)
        .map(|_| {
            let p = grid.origin + Vec3::new(rnd(), rnd(), rnd()) * 1.1 * grid.extent()
                - 0.05 * grid.extent();
            let d = grid.voxel_size * max_voxels.powf(rnd());
            let dir = Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5).normalize_or(Vec3::Y);
            [p.x, p.y, p.z, d, dir.x, dir.y, dir.z, 0.0]
        })
        .collect()
}

/// `sample_voxels` of `r`'s structure at `probes`, run by a probe shader on the GPU.
pub fn run_probes(r: &voxgi::Renderer, probes: &[[f32; 8]]) -> Vec<Vec4> {
    let n = probes.len();
    let kind = r.options().voxels;
    let anisotropic = r.options().anisotropic;
    let device = &ctx().device;
    let queue = &ctx().queue;
    use wgpu::util::DeviceExt;
    let input = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("probes"),
        contents: bytemuck::cast_slice(probes),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let output = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("probe results"),
        size: (n * 16) as u64,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let src = compose_for(&format!("voxels/{}/sample.wgsl", kind.name()), kind.name()) + PROBE;
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("probe"),
        source: wgpu::ShaderSource::Wgsl(src.into()),
    });
    let c = wgpu::ShaderStages::COMPUTE;
    let own = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("probe"),
        entries: &[
            voxgi::gpu::layout::storage(0, c, true),
            voxgi::gpu::layout::storage(1, c, false),
        ],
    });
    let voxels = kind.sampling_layout(device);
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("probe"),
        bind_group_layouts: &[Some(&own), Some(&voxels)],
        immediate_size: 0,
    });
    let constants = kind.sampling_constants(anisotropic, false, 3);
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("probe"),
        layout: Some(&layout),
        module: &module,
        entry_point: Some("main"),
        compilation_options: wgpu::PipelineCompilationOptions {
            constants: &constants,
            ..Default::default()
        },
        cache: None,
    });
    let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("probe"),
        layout: &own,
        entries: &voxgi::gpu::layout::entries(vec![
            input.as_entire_binding(),
            output.as_entire_binding(),
        ]),
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind, &[]);
        pass.set_bind_group(1, r.volume().bindings().sampling, &[]);
        pass.dispatch_workgroups((n as u32).div_ceil(64), 1, 1);
    }
    queue.submit([encoder.finish()]);
    let bytes = voxgi::gpu::readback::read_buffer_copy(device, queue, &output).expect("results");
    bytemuck::cast_slice::<u8, [f32; 4]>(&bytes)
        .iter()
        .map(|v| Vec4::from_array(*v))
        .collect()
}

/// `sample_voxels` of the dense volume, run by a probe shader at random points, diameters and
/// directions of the lit Cornell box at 16³, against `cpu::DenseSampler`.
fn probe_matches_cpu(anisotropic: bool) {
    let options = RendererOptions {
        voxel_resolution: 16,
        anisotropic,
        ..measuring()
    };
    let mut r = renderer(&builtin::cornell_box(), &options);
    let params = FrameParams::new(r.default_camera().clone());
    frame(&mut r, &params, 8, 8);
    let vol = r.structure::<voxgi::voxel::dense::DenseVolume>().unwrap();
    let grid = vol.grid;
    // Diameters of one to 24 voxels: every level.
    let n = 512;
    let probes = random_probes(grid, n, 24.0);
    let gpu = run_probes(&r, &probes);
    let (radiance0, chains) = (read_chain(&vol.radiance), read_chain(&vol.chains));
    let cpu = DenseSampler {
        grid,
        anisotropic,
        windows: 1,
        radiance0: &radiance0,
        chains: &chains,
    };
    let mut errors = Errors::default();
    let mut nonzero = 0;
    for (q, g) in probes.iter().zip(gpu) {
        let p = Vec3::new(q[0], q[1], q[2]);
        let dir = Vec3::new(q[4], q[5], q[6]);
        let want = cpu.sample_voxels(p, q[3], dir);
        errors.add((g - want).abs().max_element(), || {
            format!("sample_voxels({p}, {}, {dir}): GPU {g}, CPU {want}", q[3])
        });
        if want.w > 0.01 {
            nonzero += 1;
        }
    }
    errors.check(
        filtering_tolerance(),
        &format!("probe (anisotropic {anisotropic})"),
    );
    // The probe must look at something: most samples inside the box see its walls.
    assert!(nonzero > n / 4, "only {nonzero} of {n} samples see voxels");
}

#[test]
fn dense_sample_voxels_matches_its_cpu_twin() {
    probe_matches_cpu(true);
    probe_matches_cpu(false);
}

/// The octree samples the function the dense volume samples: its bricks hold the same voxels
/// on the same lattice, with the same filter between levels (voxels/octree/tree.wgsl). Both
/// structures of the lit Cornell box at 32³, probed at the same random points, directions and
/// diameters of one to 48 voxels (every level, up to the whole volume as one voxel).
fn octree_matches_dense(anisotropic: bool) {
    let dense = RendererOptions {
        voxel_resolution: 32,
        anisotropic,
        ..measuring()
    };
    let octree = RendererOptions {
        voxels: VoxelKind::OCTREE,
        ..dense.clone()
    };
    let scene = builtin::cornell_box();
    let mut results = Vec::new();
    let mut grid = None;
    for options in [&dense, &octree] {
        let mut r = renderer(&scene, options);
        let params = FrameParams::new(r.default_camera().clone());
        frame(&mut r, &params, 8, 8);
        let g = r.volume().grid();
        let probes = random_probes(g, 1024, 48.0);
        grid = Some(g);
        results.push((probes.clone(), run_probes(&r, &probes)));
    }
    let grid = grid.unwrap();
    let (probes, want) = &results[0];
    let got = &results[1].1;
    let mut errors = Errors::default();
    let (mut nonzero, mut compared) = (0, 0);
    for ((q, w), g) in probes.iter().zip(want).zip(got) {
        // The dense volume keeps its chain fetches half a texel inside the volume along z at
        // the coarser level it reads (its six blocks are stacked along z); the octree clamps
        // each level at its own edge. Near the z faces the two differ by design: skip there.
        let lod = (q[3] / grid.voxel_size).max(1.0).log2();
        let upper = (lod.floor() + 1.0).clamp(2.0, grid.levels() as f32 - 1.0);
        let half = 0.5 / (grid.resolution as f32 / upper.exp2());
        let z = (q[2] - grid.origin.z) / grid.extent();
        if z < half || z > 1.0 - half {
            continue;
        }
        compared += 1;
        // Both structures' fetches are filtered by the hardware (the H200 measured 1.4e-2).
        errors.add((*g - *w).abs().max_element(), || {
            format!(
                "sample_voxels({:?}, {}, {:?}): octree {g}, dense {w}",
                &q[0..3],
                q[3],
                &q[4..7]
            )
        });
        if w.w > 0.01 {
            nonzero += 1;
        }
    }
    let (worst, mean) = filtering_tolerance();
    errors.check(
        (2.0 * worst, 2.0 * mean),
        &format!("octree vs dense (anisotropic {anisotropic})"),
    );
    assert!(
        nonzero > compared / 4,
        "only {nonzero} of {compared} samples see voxels"
    );
    assert!(
        compared > probes.len() / 2,
        "only {compared} probes compared"
    );
}

#[test]
fn octree_samples_what_the_dense_volume_samples() {
    octree_matches_dense(true);
    octree_matches_dense(false);
}

/// `sample_voxels` of the octree, run by the probe shader at random points, diameters and
/// directions of the lit Cornell box at 16³, against `octree::cpu::OctreeSampler` reading the
/// same nodes and atlases.
fn octree_probe_matches_cpu(anisotropic: bool) {
    use voxgi::voxel::octree::cpu::OctreeSampler;
    let options = RendererOptions {
        voxels: VoxelKind::OCTREE,
        voxel_resolution: 16,
        anisotropic,
        ..measuring()
    };
    let mut r = renderer(&builtin::cornell_box(), &options);
    let params = FrameParams::new(r.default_camera().clone());
    frame(&mut r, &params, 8, 8);
    let tree = r.structure::<voxgi::voxel::octree::OctreeVolume>().unwrap();
    let probes = random_probes(tree.grid, 512, 24.0);
    let gpu = run_probes(&r, &probes);
    let bytes = voxgi::gpu::readback::read_buffer_copy(&ctx().device, &ctx().queue, &tree.nodes)
        .expect("nodes");
    let (even, odd) = (read_chain(&tree.even_atlas), read_chain(&tree.odd_atlas));
    let cpu = OctreeSampler {
        layout: tree.layout,
        nodes: bytemuck::cast_slice(&bytes),
        even: &even,
        odd: &odd,
    };
    let mut errors = Errors::default();
    let mut nonzero = 0;
    for (q, got) in probes.iter().zip(gpu) {
        let p = Vec3::new(q[0], q[1], q[2]);
        let dir = Vec3::new(q[4], q[5], q[6]);
        let want = cpu.sample_voxels(p, q[3], dir);
        // As for the dense twin: the hardware's filtering weights.
        errors.add((got - want).abs().max_element(), || {
            format!(
                "octree sample_voxels({p}, {}, {dir}): GPU {got}, CPU {want}",
                q[3]
            )
        });
        if want.w > 0.01 {
            nonzero += 1;
        }
    }
    errors.check(
        filtering_tolerance(),
        &format!("octree probe (anisotropic {anisotropic})"),
    );
    assert!(
        nonzero > probes.len() / 4,
        "only {nonzero} samples see voxels"
    );
}

#[test]
fn octree_sample_voxels_matches_its_cpu_twin() {
    octree_probe_matches_cpu(true);
    octree_probe_matches_cpu(false);
}

/// Interpolation is continuous across brick borders: at every level, pairs of samples a
/// hair's breadth either side of the planes where a fetch passes from one brick to the next
/// (level-k voxel coordinate 2m + 0.5 along x, y or z) agree, in the lit Cornell box at 32³.
/// A brick whose border was not filled from its neighbour reads a step there (up to the
/// opacity of a wall, ~1).
#[test]
fn octree_interpolation_is_continuous_across_bricks() {
    let options = RendererOptions {
        voxels: VoxelKind::OCTREE,
        voxel_resolution: 32,
        ..measuring()
    };
    let mut r = renderer(&builtin::cornell_box(), &options);
    let params = FrameParams::new(r.default_camera().clone());
    frame(&mut r, &params, 8, 8);
    let grid = r.volume().grid();
    let mut seed = 0x1234_5678_u32;
    let mut rnd = move || {
        seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (seed >> 8) as f32 / (1u32 << 24) as f32
    };
    let mut probes = Vec::new();
    let eps = 1e-4;
    for level in 0..4u32 {
        let size = (1u32 << level) as f32;
        let cells = grid.resolution >> level;
        for _ in 0..96 {
            let axis = (rnd() * 3.0) as usize % 3;
            let dir = Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5).normalize_or(Vec3::Y);
            // In level-k voxels: a brick border plane along `axis`, anywhere across the others.
            let m = 1 + (rnd() * (cells / 2 - 1) as f32) as u32;
            let mut q = Vec3::new(rnd(), rnd(), rnd()) * cells as f32;
            for side in [-eps, eps] {
                q[axis] = 2.0 * m as f32 + 0.5 + side;
                let p = grid.origin + q * size * grid.voxel_size;
                probes.push([
                    p.x,
                    p.y,
                    p.z,
                    size * grid.voxel_size,
                    dir.x,
                    dir.y,
                    dir.z,
                    0.0,
                ]);
            }
        }
    }
    let got = run_probes(&r, &probes);
    let (mut worst, mut seen) = (0.0f32, 0);
    for (pair, q) in got.chunks_exact(2).zip(probes.chunks_exact(2)) {
        let jump = (pair[0] - pair[1]).abs().max_element();
        worst = worst.max(jump);
        if pair[0].w > 0.01 {
            seen += 1;
        }
        // Either side lies 2e-4 level voxels apart: opacity changes by at most a step of 1
        // per voxel times that, plus the filtering weights' 8-bit rounding (5e-3).
        assert!(
            jump <= 6e-3,
            "a step of {jump} across a brick border at {:?} (diameter {}): {} vs {}",
            &q[0][0..3],
            q[0][3],
            pair[0],
            pair[1]
        );
    }
    eprintln!(
        "brick borders: largest step {worst:.2e}, {seen} of {} pairs see voxels",
        got.len() / 2
    );
    assert!(seen > got.len() / 8, "only {seen} pairs see voxels");
}

/// The differences of many probes from their twins: the worst (with what it was) and the mean.
#[derive(Default)]
pub struct Errors {
    worst: f32,
    at: String,
    sum: f64,
    count: usize,
}

impl Errors {
    pub fn add(&mut self, err: f32, what: impl FnOnce() -> String) {
        if err > self.worst || self.count == 0 {
            self.worst = err;
            self.at = what();
        }
        self.sum += f64::from(err);
        self.count += 1;
    }

    /// Asserts the worst and the mean within `(worst, mean)`.
    pub fn check(&self, (worst, mean): (f32, f32), what: &str) {
        let m = (self.sum / self.count.max(1) as f64) as f32;
        eprintln!(
            "{what}: worst difference {:.2e}, mean {m:.2e} over {} probes",
            self.worst, self.count
        );
        assert!(
            self.worst <= worst,
            "{what}: worst {}: {}",
            self.worst,
            self.at
        );
        assert!(m <= mean, "{what}: mean difference {m}");
    }
}
