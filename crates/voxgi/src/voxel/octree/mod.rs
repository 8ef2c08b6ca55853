//! The sparse voxel octree (Crassin et al. 2011 §4, the thesis's §4.3–4.4): node tiles of
//! 2×2×2 with one child pointer per node, bricks of 2×2×2 voxels with a positive border stored
//! as 3×3×3 texels in two brick atlases, and negative neighbour pointers. The layout is
//! described once, in shaders/voxels/octree/tree.wgsl.
//!
//! Why these bricks: a voxel-centred 2³ brick with its positive border is the same lattice as
//! the dense volume, so one hardware trilinear fetch inside a brick blends exactly the eight
//! voxels the dense volume's fetch blends, and the box filter between levels is the dense
//! filter. The two structures sample the same function (up to the atlases' rounding), so the
//! invariants and path-tracer agreement calibrated on the dense volume carry over. Vertex-centred
//! 3³ bricks (seeds 000 and 003) cost the same 27 texels per node but put values on voxel corners:
//! every leaf value is then a blend of eight voxels (docs/QUALITY.md measures the difference).
//!
//! Built on the GPU level by level from the fragment list (octree_build.wgsl): a level-synchronous
//! scheme that needs no locks, deterministic in everything but allocation order.

pub mod cpu;
pub mod debug;

use super::registry::{KindInfo, StructureDesc};
use super::{DebugView, Filtering, Grid, POOL_COUNTERS, VoxelStructure};
use crate::fragments::Fragments;
use crate::frame::targets::FrameTargets;
use crate::gpu::checked;
use crate::gpu::shader::StructureShaders;
use crate::gpu::timer::GpuTimer;
use crate::gpu::{layout, shader};
use bytemuck::{Pod, Zeroable};
use debug::DebugPass;
use std::sync::Arc;
use wgpu::util::DeviceExt;

/// The sparse voxel octree in the registry of kinds.
pub const KIND: KindInfo = KindInfo {
    name: "octree",
    summary: "the sparse voxel octree: memory in proportion to the occupied voxels",
    // Node coordinates are packed ten bits per axis (`pack_coord`).
    max_resolution: 1024,
    build_passes: &["octree_build", "octree_update"],
    filter_passes: &["octree_filter"],
    shaders: StructureShaders {
        name: "octree",
        sources: crate::wgsl![
            "voxels/octree/tree.wgsl",
            "voxels/octree/sample.wgsl",
            "voxels/octree/leaves.wgsl",
            "voxels/octree/leaf_store.wgsl",
            "voxels/octree/irradiance.wgsl",
            "voxels/octree/build_shared.wgsl",
            "voxels/octree/octree_build.wgsl",
            "voxels/octree/octree_update.wgsl",
            "voxels/octree/octree_filter.wgsl",
            "voxels/octree/debug.wgsl",
        ],
        passes: &[
            "voxels/octree/octree_build.wgsl",
            "voxels/octree/octree_update.wgsl",
            "voxels/octree/octree_filter.wgsl",
            "voxels/octree/debug.wgsl",
        ],
    },
    sampling_layout: OctreeVolume::sampling_layout,
    leaves_layout: OctreeVolume::leaves_layout,
    leaf_store_layout: OctreeVolume::leaf_store_layout,
    irradiance_layout: OctreeVolume::irradiance_layout,
    sampling_constants: OctreeVolume::sampling_constants,
    create,
};

/// An octree for `desc`, with the pipelines of `previous` when it is one.
fn create(
    device: &wgpu::Device,
    desc: &StructureDesc,
    previous: Option<&dyn VoxelStructure>,
) -> crate::Result<Box<dyn VoxelStructure>> {
    let p = match previous.and_then(|v| v.as_any().downcast_ref::<OctreeVolume>()) {
        Some(v) => v.pipelines.clone(),
        None => checked(device, "pipeline creation", || OctreePipelines::new(device))?,
    };
    let l = device.limits();
    let pools = OctreePools::for_leaves(desc.leaves)
        .within(l.max_storage_buffer_binding_size.min(l.max_buffer_size));
    let v = checked(device, "voxel octree", || {
        OctreeVolume::new(device, &p, desc.grid, desc.filtering, pools, desc.dynamic)
    })??;
    Ok(Box::new(v))
}

/// Format of both atlases: optical depth (L sigma, sigma), as the dense volume's radiance.
pub const ATLAS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// u32 per node above the leaves: child pointer and the -x, -y, -z neighbours (`NODE_STRIDE`;
/// a leaf voxel keeps its child word only).
pub const NODE_WORDS: u64 = 4;
/// u32 per leaf slot (`SLOT_STRIDE` in tree.wgsl): what the leaf is, and the build's sums.
pub const SLOT_WORDS: u64 = 19;
/// Bytes per leaf slot across the slot, direct-light and bounce buffers.
pub const SLOT_BYTES: u64 = SLOT_WORDS * 4 + 32;
/// Words of counters before the nodes in the node buffer (`NODE_HEADER` in tree.wgsl).
const NODE_HEADER: u64 = 64;
/// Dispatch sizes (u32): fragments, leaves, the nodes of each depth, the new nodes of each
/// depth, the last update's leaves (`ARGS_NEW`, `ARGS_CLEAR` in octree_update.wgsl).
const ARGS_WORDS: u64 = 75;
const ARGS_NEW: u64 = 39;
const ARGS_CLEAR: u64 = 72;
/// u32 per tile in the tile buffer (`TILE_WORDS` in tree.wgsl).
const TILE_WORDS: u64 = 2;
/// Deepest depth of the top grid (`GRID_DEPTH` in tree.wgsl).
const GRID_DEPTH: u32 = 6;
/// Stride of the per-depth uniforms (the minimum dynamic-offset alignment).
const LEVEL_STRIDE: u64 = 256;
/// Texels per brick side.
const BRICK: u32 = 3;

/// The constants above that octree_update.wgsl (and tree.wgsl, which it includes) defines
/// too, by their WGSL names: a test holds the two sides equal.
#[cfg(test)]
pub(crate) const SHARED_CONSTANTS: &[(&str, u64)] = &[
    ("NODE_STRIDE", NODE_WORDS),
    ("SLOT_STRIDE", SLOT_WORDS),
    ("NODE_HEADER", NODE_HEADER),
    ("TILE_WORDS", TILE_WORDS),
    ("GRID_DEPTH", GRID_DEPTH as u64),
    ("ARGS_NEW", ARGS_NEW),
    ("ARGS_CLEAR", ARGS_CLEAR),
];

/// Mirrors `Octree` in shaders/voxels/octree/tree.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuOctree {
    /// World position of the volume's minimum corner, metres.
    pub origin: [f32; 3],
    /// Finest voxels per side.
    pub resolution: u32,
    /// Edge of a finest voxel, metres.
    pub voxel_size: f32,
    /// log2(resolution).
    pub depth: u32,
    /// 1: six directional values above the finest level.
    pub anisotropic: u32,
    /// Atlas slots per brick above level 0.
    pub dirs: u32,
    /// First tile of class V (leaf voxels).
    pub base_v: u32,
    /// First tile of class E (bricks of even levels above 0).
    pub base_e: u32,
    /// First tile of class O (bricks of odd levels).
    pub base_o: u32,
    /// Tiles in the pool.
    pub tiles: u32,
    /// Leaf slots.
    pub slots: u32,
    /// 1: the first directional level weighs the leaves by their normals (`Filtering::ndf`).
    pub ndf: u32,
    /// Padding; zero.
    pub _pad: [u32; 2],
    /// The even atlas's region of level 0.
    pub leaf_atlas: GpuAtlasShape,
    /// The even atlas's region of levels 2, 4, …
    pub even_atlas: GpuAtlasShape,
    /// The odd atlas (levels 1, 3, …).
    pub odd_atlas: GpuAtlasShape,
}

/// Mirrors `AtlasShape` in shaders/voxels/octree/tree.wgsl: where a region of an atlas keeps
/// its bricks.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct GpuAtlasShape {
    /// log2 of the bricks per row and per layer.
    pub shift: [u32; 2],
    /// Texels of one direction block along z.
    pub block: u32,
    /// The region's first texel along z.
    pub z0: u32,
    /// 1 / the atlas size in texels; w unused.
    pub inv_size: [f32; 4],
}

impl GpuAtlasShape {
    /// The regions of one atlas texture within `max_dim` texels a side, each `(bricks, blocks)`
    /// (bricks in `blocks` direction blocks), one after another along z: rows and layers of a
    /// power of two bricks, the texture as close to a cube as that allows.
    pub fn regions<const N: usize>(regions: [(u64, u32); N], max_dim: u32) -> Option<[Self; N]> {
        let total: u64 = regions.iter().map(|(b, k)| b.max(&1) * *k as u64).sum();
        let max_shift = (max_dim / BRICK).max(1).ilog2();
        let side = (total as f64).cbrt().ceil() as u64;
        let shift = side.next_power_of_two().ilog2().min(max_shift);
        let per_layer = 1u64 << (2 * shift);
        let mut z0 = 0u64;
        let mut out = [(0u64, 0u64); N];
        for (o, (bricks, blocks)) in out.iter_mut().zip(regions) {
            let block = bricks.max(1).div_ceil(per_layer) * BRICK as u64;
            *o = (z0, block);
            z0 += block * blocks as u64;
        }
        if z0 > max_dim as u64 {
            return None;
        }
        let width = (BRICK << shift) as f32;
        let inv_size = [1.0 / width, 1.0 / width, 1.0 / z0 as f32, 0.0];
        Some(out.map(|(z0, block)| GpuAtlasShape {
            shift: [shift, shift],
            block: block as u32,
            z0: z0 as u32,
            inv_size,
        }))
    }

    /// The atlas texture's size in texels.
    pub fn size(&self) -> [u32; 3] {
        [
            (1.0 / self.inv_size[0]).round() as u32,
            (1.0 / self.inv_size[1]).round() as u32,
            (1.0 / self.inv_size[2]).round() as u32,
        ]
    }

    /// First texel of direction block `block` of brick `b` (`brick_texel` in tree.wgsl).
    pub fn brick_texel(&self, b: u32, block: u32) -> [u32; 3] {
        let [sx, sy] = self.shift;
        [
            3 * (b & ((1 << sx) - 1)),
            3 * ((b >> sx) & ((1 << sy) - 1)),
            3 * (b >> (sx + sy)) + self.z0 + block * self.block,
        ]
    }
}

/// How many of each pool an octree holds: leaf slots, and tiles of the three classes (leaf
/// voxels, even levels above 0, odd levels).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OctreePools {
    /// Occupied finest voxels.
    pub slots: u32,
    /// Tiles of eight leaf voxels (one level-0 brick each).
    pub leaf_tiles: u32,
    /// Tiles whose parents' bricks hold an even level above 0.
    pub even_tiles: u32,
    /// Tiles whose parents' bricks hold an odd level.
    pub odd_tiles: u32,
}

impl OctreePools {
    /// A first guess for `leaves` occupied voxels: surfaces fill about half of a 2³ group, and
    /// each level above holds about a quarter of the one below; the dilation for the bricks'
    /// borders roughly doubles each. The first build's counters correct it.
    pub fn for_leaves(leaves: u64) -> Self {
        let c = |n: u64| n.clamp(64, u32::MAX as u64 / 8) as u32;
        OctreePools {
            slots: c(leaves),
            leaf_tiles: c(leaves / 2),
            even_tiles: c(leaves / 16),
            odd_tiles: c(leaves / 8),
        }
    }

    /// These pools, shrunk where a buffer would exceed `max_binding` bytes: a first guess
    /// must not fail where the scene itself would fit (growth then reports a real excess).
    pub fn within(self, max_binding: u64) -> Self {
        let mut p = self;
        p.slots = p
            .slots
            .min((max_binding / (SLOT_WORDS * 4)).min(u32::MAX as u64) as u32);
        let node_bytes = |p: &OctreePools| {
            let interior = 1 + p.even_tiles as u64 + p.odd_tiles as u64;
            (NODE_HEADER + 8 * interior * NODE_WORDS + 8 * p.leaf_tiles as u64) * 4
        };
        while node_bytes(&p) > max_binding && p.leaf_tiles > 64 {
            p.leaf_tiles /= 2;
            p.even_tiles = (p.even_tiles / 2).max(64);
            p.odd_tiles = (p.odd_tiles / 2).max(64);
        }
        p
    }

    /// Bytes these pools take on the GPU (bricks with six directions above level 0).
    pub fn bytes(&self) -> u64 {
        let brick = 27 * 8;
        self.slots as u64 * SLOT_BYTES
            + self.leaf_tiles as u64 * (brick + 8 * 4 + 8)
            + (self.even_tiles as u64 + self.odd_tiles as u64) * (6 * brick + 8 * 16 + 8)
    }

    /// The pools to make after a build that counted `counted` (`OctreeVolume::pool_counter`'s
    /// first four words), or None to keep these. A pool that overflowed hides what the levels
    /// below it would have needed, so every pool grows at least by half once one overflows.
    /// Pools more than twice what the build needed (the first guess comes from an upper bound
    /// on the fragments) shrink to the counts and an eighth: the octree's point is its memory.
    pub fn resized_for(&self, counted: &[u32]) -> Option<Self> {
        let have = [self.slots, self.leaf_tiles, self.even_tiles, self.odd_tiles];
        if counted.iter().zip(have).all(|(&n, h)| n <= h) {
            let need = |n: u32| n.saturating_add(n / 8).max(64);
            let fit = OctreePools {
                slots: need(counted[0]),
                leaf_tiles: need(counted[1]),
                even_tiles: need(counted[2]),
                odd_tiles: need(counted[3]),
            };
            // Below a few MiB a shrink is not worth a rebuild.
            let oversized = self.bytes() > 2 * fit.bytes() && self.bytes() > 8 << 20;
            return oversized.then_some(fit);
        }
        let grow = |n: u32, h: u32| -> u32 {
            let half = h.saturating_add(h / 2);
            n.max(half).max(64)
        };
        Some(OctreePools {
            slots: grow(counted[0], self.slots),
            leaf_tiles: grow(counted[1], self.leaf_tiles),
            even_tiles: grow(counted[2], self.even_tiles),
            odd_tiles: grow(counted[3], self.odd_tiles),
        })
    }
}

/// The octree's pipelines (octree_build, octree_filter, debug): made once per renderer and
/// shared by every octree it makes (one is remade whenever its pools grow).
pub struct OctreePipelines {
    build_layout: wgpu::BindGroupLayout,
    args_layout: wgpu::BindGroupLayout,
    filter_layout: wgpu::BindGroupLayout,
    build: BuildPipelines,
    update: UpdatePipelines,
    filter: wgpu::ComputePipeline,
    filter_top: wgpu::ComputePipeline,
    debug: DebugPass,
}

/// octree_update's entry points (shaders/voxels/octree/octree_update.wgsl).
struct UpdatePipelines {
    begin_clear: wgpu::ComputePipeline,
    clear_leaves: wgpu::ComputePipeline,
    clear_nodes: wgpu::ComputePipeline,
    begin_update: wgpu::ComputePipeline,
    bounds: wgpu::ComputePipeline,
    prepare_depth: wgpu::ComputePipeline,
    end_update: wgpu::ComputePipeline,
    flag: wgpu::ComputePipeline,
    mark: wgpu::ComputePipeline,
    count: wgpu::ComputePipeline,
    scan: wgpu::ComputePipeline,
    allocate: wgpu::ComputePipeline,
    finish_update: wgpu::ComputePipeline,
    init: wgpu::ComputePipeline,
    repair: wgpu::ComputePipeline,
    allocate_slots: wgpu::ComputePipeline,
    accumulate: wgpu::ComputePipeline,
    prepare_slots: wgpu::ComputePipeline,
    resolve: wgpu::ComputePipeline,
}

struct BuildPipelines {
    begin: wgpu::ComputePipeline,
    flag: wgpu::ComputePipeline,
    dilate: wgpu::ComputePipeline,
    mark: wgpu::ComputePipeline,
    count: wgpu::ComputePipeline,
    scan: wgpu::ComputePipeline,
    allocate: wgpu::ComputePipeline,
    finish: wgpu::ComputePipeline,
    init: wgpu::ComputePipeline,
    allocate_slots: wgpu::ComputePipeline,
    accumulate: wgpu::ComputePipeline,
    prepare_slots: wgpu::ComputePipeline,
    resolve: wgpu::ComputePipeline,
    seal: wgpu::ComputePipeline,
}

impl OctreePipelines {
    /// Compiles the build, filter and debug pipelines.
    pub fn new(device: &wgpu::Device) -> Arc<Self> {
        let c = wgpu::ShaderStages::COMPUTE;
        let build_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("octree_build"),
            entries: &[
                layout::uniform(0, c, false),
                layout::storage(1, c, true),
                layout::storage(2, c, true),
                layout::storage(3, c, false),
                layout::storage(4, c, false),
                layout::storage(5, c, false),
                layout::storage_texture_3d(6, ATLAS_FORMAT),
                layout::storage_texture_3d(7, ATLAS_FORMAT),
                layout::uniform(8, c, true),
                layout::storage(9, c, false),
                layout::storage(10, c, false),
            ],
        });
        let args_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("octree_build args"),
            entries: &[layout::storage(0, c, false)],
        });
        let plain = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("octree_build"),
            bind_group_layouts: &[Some(&build_layout)],
            immediate_size: 0,
        });
        let with_args = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("octree_build prepare"),
            bind_group_layouts: &[Some(&build_layout), Some(&args_layout)],
            immediate_size: 0,
        });
        let pipe = |m: &wgpu::ShaderModule, label: &str, entry: &str, args: bool| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(label),
                layout: Some(if args { &with_args } else { &plain }),
                module: m,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        let m = shader::module_for(device, "voxels/octree/octree_build.wgsl", &KIND.shaders);
        let b = |entry: &str, args: bool| pipe(&m, "octree_build", entry, args);
        let build = BuildPipelines {
            begin: b("begin", true),
            flag: b("flag", false),
            dilate: b("dilate", false),
            mark: b("mark", false),
            count: b("count", false),
            scan: b("scan", false),
            allocate: b("allocate", false),
            finish: b("finish", true),
            init: b("init", false),
            allocate_slots: b("allocate_slots", false),
            accumulate: b("accumulate", false),
            prepare_slots: b("prepare_slots", true),
            resolve: b("resolve", false),
            seal: b("seal", false),
        };
        let m = shader::module_for(device, "voxels/octree/octree_update.wgsl", &KIND.shaders);
        let u = |entry: &str, args: bool| pipe(&m, "octree_update", entry, args);
        let update = UpdatePipelines {
            begin_clear: u("begin_clear", true),
            clear_leaves: u("clear_leaves", false),
            clear_nodes: u("clear_nodes", false),
            begin_update: u("begin_update", true),
            bounds: u("bounds", false),
            prepare_depth: u("prepare_depth", true),
            end_update: u("end_update", true),
            flag: u("flag", false),
            mark: u("mark", false),
            count: u("count", false),
            scan: u("scan", false),
            allocate: u("allocate", false),
            finish_update: u("finish_update", true),
            init: u("init", false),
            repair: u("repair", false),
            allocate_slots: u("allocate_slots", false),
            accumulate: u("accumulate", false),
            prepare_slots: u("prepare_slots", true),
            resolve: u("resolve", false),
        };
        let filter_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("octree_filter"),
            entries: &[
                layout::uniform(0, c, false),
                layout::storage(1, c, true),
                layout::storage(2, c, true),
                layout::texture_3d_load(3, c),
                layout::storage_texture_3d(4, ATLAS_FORMAT),
                layout::uniform(5, c, true),
                layout::storage(6, c, true),
            ],
        });
        let filter_module =
            shader::module_for(device, "voxels/octree/octree_filter.wgsl", &KIND.shaders);
        let filter_pipeline_layout =
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("octree_filter"),
                bind_group_layouts: &[Some(&filter_layout)],
                immediate_size: 0,
            });
        let f = |entry: &str| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("octree_filter"),
                layout: Some(&filter_pipeline_layout),
                module: &filter_module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        let (filter, filter_top) = (f("main"), f("top"));
        Arc::new(OctreePipelines {
            build_layout,
            args_layout,
            filter_layout,
            build,
            update,
            filter,
            filter_top,
            debug: DebugPass::new(device),
        })
    }
}

/// The sparse voxel octree: its node pool, leaf slots, brick atlases and bind groups.
pub struct OctreeVolume {
    /// Where the volume lies and its finest resolution.
    pub grid: Grid,
    /// Six directional values per voxel above the finest level (true) or one.
    pub anisotropic: bool,
    /// The pools' sizes.
    pub pools: OctreePools,
    /// The `GpuOctree` uniform.
    pub tree: wgpu::Buffer,
    /// What `tree` holds.
    pub layout: GpuOctree,
    /// A header of `NODE_HEADER` counters ([0] leaf slots, [1..4] tiles of each class, all
    /// counted past the capacity; then per depth the range of its tiles), then `NODE_WORDS`
    /// u32 per node of the root tile and classes E and O, then one per leaf voxel (class V).
    pub nodes: wgpu::Buffer,
    /// Per tile, `TILE_WORDS` u32: its parent node and the parent's packed coordinate.
    pub tiles: wgpu::Buffer,
    /// The build's per-workgroup counts and their prefix sums (deterministic allocation).
    block_sums: wgpu::Buffer,
    /// The top grid: per depth down to the grid's, the node at every position.
    pub top_grid: wgpu::Buffer,
    /// Per leaf slot, `SLOT_WORDS` u32.
    pub slots: wgpu::Buffer,
    /// Per leaf: direct radiance and opacity (vec4 f32).
    pub leaf_direct: wgpu::Buffer,
    /// Per leaf: the last bounce's radiance and opacity (vec4 f32).
    pub leaf_next: wgpu::Buffer,
    /// Per slot: the irradiance record for the fast shading (`VoxelStructure::leaf_irradiance`).
    pub leaf_irradiance: wgpu::Buffer,
    /// Indirect dispatch sizes: [0..3] over fragments, [3..6] over leaves, then per depth over
    /// its nodes.
    pub args: wgpu::Buffer,
    /// Per depth: the depth, at `LEVEL_STRIDE` bytes (dynamic uniform offsets).
    levels: wgpu::Buffer,
    /// Bricks of level 0 and of the even levels above it (two regions).
    pub even_atlas: wgpu::Texture,
    /// Bricks of the odd levels.
    pub odd_atlas: wgpu::Texture,
    sampling: wgpu::BindGroup,
    leaves: wgpu::BindGroup,
    leaf_store: wgpu::BindGroup,
    irradiance: wgpu::BindGroup,
    /// Filter bind groups: [0] writes the even atlas (reads the odd), [1] the odd (reads the
    /// even).
    filter: [wgpu::BindGroup; 2],
    /// The static build's nodes, tiles, leaves and top grid, which every update starts from;
    /// None for a scene without dynamic instances.
    snapshot: Option<[wgpu::Buffer; 4]>,
    pipelines: Arc<OctreePipelines>,
}

fn storage_buffer(device: &wgpu::Device, label: &str, size: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size.max(16),
        usage: wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_DST
            | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    })
}

fn atlas(device: &wgpu::Device, label: &str, shape: &GpuAtlasShape) -> wgpu::Texture {
    let [width, height, depth] = shape.size();
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: depth,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D3,
        format: ATLAS_FORMAT,
        usage: wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    })
}

impl OctreeVolume {
    /// An octree on `grid` with `pools`. Errors when an atlas or a pool exceeds the device's
    /// limits.
    pub fn new(
        device: &wgpu::Device,
        pipelines: &Arc<OctreePipelines>,
        grid: Grid,
        filtering: Filtering,
        pools: OctreePools,
        dynamic: bool,
    ) -> crate::Result<Self> {
        let anisotropic = filtering.anisotropic;
        let depth = grid.resolution.ilog2();
        let dirs: u32 = if anisotropic { 6 } else { 1 };
        // Tile 0 is the root's; then classes E, O and V (`child_word` in tree.wgsl).
        let base_e = 1u64;
        let base_o = base_e + pools.even_tiles as u64;
        let base_v = base_o + pools.odd_tiles as u64;
        let tiles = base_v + pools.leaf_tiles as u64;
        // Four words per node above the leaves, one per leaf voxel.
        let node_words = NODE_HEADER + 8 * base_v * NODE_WORDS + 8 * pools.leaf_tiles as u64;
        let limits = device.limits();
        let too_big = |what: &str, bytes: u64| -> crate::Result<()> {
            if bytes
                > limits
                    .max_storage_buffer_binding_size
                    .min(limits.max_buffer_size)
                || tiles > u32::MAX as u64 / 8
            {
                return Err(crate::Error::Setting(format!(
                    "the octree needs {} MiB of {what}, more than this GPU's storage-buffer \
                     limit ({} MiB); lower the voxel resolution",
                    bytes >> 20,
                    limits.max_storage_buffer_binding_size >> 20
                )));
            }
            Ok(())
        };
        too_big("nodes", node_words * 4)?;
        too_big("leaf slots", pools.slots as u64 * SLOT_WORDS * 4)?;
        let max_dim = limits.max_texture_dimension_3d;
        let too_many = |bricks: u64| {
            crate::Error::Setting(format!(
                "the octree needs {bricks} bricks, more than a {max_dim}³ atlas holds; lower \
                 the voxel resolution"
            ))
        };
        let [leaf_shape, even_shape] = GpuAtlasShape::regions(
            [
                (pools.leaf_tiles as u64, 1),
                (pools.even_tiles as u64, dirs),
            ],
            max_dim,
        )
        .ok_or_else(|| too_many(pools.leaf_tiles as u64 + pools.even_tiles as u64))?;
        let [odd_shape] = GpuAtlasShape::regions([(pools.odd_tiles as u64, dirs)], max_dim)
            .ok_or_else(|| too_many(pools.odd_tiles as u64))?;
        let layout = GpuOctree {
            origin: grid.origin.to_array(),
            resolution: grid.resolution,
            voxel_size: grid.voxel_size,
            depth,
            anisotropic: anisotropic as u32,
            dirs,
            base_v: base_v as u32,
            base_e: base_e as u32,
            base_o: base_o as u32,
            tiles: tiles as u32,
            slots: pools.slots,
            ndf: (filtering.ndf && filtering.anisotropic) as u32,
            _pad: [0; 2],
            leaf_atlas: leaf_shape,
            even_atlas: even_shape,
            odd_atlas: odd_shape,
        };
        let tree = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("octree"),
            contents: bytemuck::bytes_of(&layout),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        });
        let mut level_bytes = vec![0u8; (depth as usize + 1) * LEVEL_STRIDE as usize];
        for t in 0..=depth {
            let at = t as usize * LEVEL_STRIDE as usize;
            level_bytes[at..at + 4].copy_from_slice(&t.to_le_bytes());
        }
        let levels = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("octree levels"),
            contents: &level_bytes,
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let slots = pools.slots as u64;
        let nodes = storage_buffer(device, "octree nodes", node_words * 4);
        let tile_buf = storage_buffer(device, "octree tiles", tiles * TILE_WORDS * 4);
        // A depth has at most eight nodes per tile of the pool: a count per 64 of them.
        let block_sums = storage_buffer(device, "octree block sums", (tiles / 8 + 2) * 4);
        let g = (depth - 1).min(GRID_DEPTH);
        let grid_words = ((1u64 << (3 * (g + 1))) - 1) / 7;
        let top_grid = storage_buffer(device, "octree top grid", grid_words * 4);
        let slot_buf = storage_buffer(device, "octree leaf slots", slots * SLOT_WORDS * 4);
        let leaf_direct = storage_buffer(device, "octree direct light", slots * 16);
        let leaf_next = storage_buffer(device, "octree bounce light", slots * 16);
        let leaf_irradiance = storage_buffer(device, "octree leaf irradiance", slots * 16);
        let args = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("octree dispatch sizes"),
            size: ARGS_WORDS * 4,
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::INDIRECT
                | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let even_atlas = atlas(device, "octree even atlas", &even_shape);
        let odd_atlas = atlas(device, "octree odd atlas", &odd_shape);
        let view = |t: &wgpu::Texture| t.create_view(&Default::default());
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("octree bricks"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        let sampling = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("voxel sampling"),
            layout: &Self::sampling_layout(device),
            entries: &layout::entries(vec![
                tree.as_entire_binding(),
                nodes.as_entire_binding(),
                wgpu::BindingResource::TextureView(&view(&even_atlas)),
                wgpu::BindingResource::TextureView(&view(&odd_atlas)),
                wgpu::BindingResource::Sampler(&sampler),
                top_grid.as_entire_binding(),
            ]),
        });
        let leaves = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("voxel leaves"),
            layout: &Self::leaves_layout(device),
            entries: &layout::entries(vec![
                tree.as_entire_binding(),
                slot_buf.as_entire_binding(),
                leaf_direct.as_entire_binding(),
                leaf_next.as_entire_binding(),
                nodes.as_entire_binding(),
            ]),
        });
        let leaf_store = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("voxel leaf store"),
            layout: &Self::leaf_store_layout(device),
            entries: &layout::entries(vec![wgpu::BindingResource::TextureView(&view(&even_atlas))]),
        });
        let irradiance = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("voxel irradiance"),
            layout: &Self::irradiance_layout(device),
            entries: &layout::entries(vec![leaf_irradiance.as_entire_binding()]),
        });
        let level = wgpu::BindingResource::Buffer(wgpu::BufferBinding {
            buffer: &levels,
            offset: 0,
            size: wgpu::BufferSize::new(16),
        });
        let filter_group = |src: &wgpu::Texture, dst: &wgpu::Texture| {
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("octree_filter"),
                layout: &pipelines.filter_layout,
                entries: &layout::entries(vec![
                    tree.as_entire_binding(),
                    nodes.as_entire_binding(),
                    tile_buf.as_entire_binding(),
                    wgpu::BindingResource::TextureView(&view(src)),
                    wgpu::BindingResource::TextureView(&view(dst)),
                    level.clone(),
                    slot_buf.as_entire_binding(),
                ]),
            })
        };
        let filter = [
            filter_group(&odd_atlas, &even_atlas),
            filter_group(&even_atlas, &odd_atlas),
        ];
        let snapshot = dynamic.then(|| {
            [&nodes, &tile_buf, &slot_buf, &top_grid]
                .map(|b| storage_buffer(device, "octree static snapshot", b.size()))
        });
        Ok(OctreeVolume {
            grid,
            anisotropic,
            pools,
            tree,
            layout,
            nodes,
            tiles: tile_buf,
            block_sums,
            top_grid,
            slots: slot_buf,
            leaf_direct,
            leaf_next,
            leaf_irradiance,
            args,
            levels,
            even_atlas,
            odd_atlas,
            sampling,
            leaves,
            leaf_store,
            irradiance,
            filter,
            snapshot,
            pipelines: pipelines.clone(),
        })
    }

    /// log2 of the finest resolution: the depth of the leaf voxels.
    pub fn depth(&self) -> u32 {
        self.layout.depth
    }

    /// Values for voxels/octree/sample.wgsl's `override` constants.
    pub fn sampling_constants(anisotropic: bool, axes: u32) -> [(&'static str, f64); 2] {
        [
            ("ISOTROPIC_ONLY", if anisotropic { 0.0 } else { 1.0 }),
            ("SAMPLE_AXES", f64::from(axes)),
        ]
    }

    /// The layout of @group(1) for the octree, twin of shaders/voxels/octree/sample.wgsl: the
    /// octree uniform, the nodes, both atlases and the brick sampler.
    pub fn sampling_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
        let c = wgpu::ShaderStages::COMPUTE;
        let texture = |binding| {
            layout::texture(
                binding,
                c,
                wgpu::TextureSampleType::Float { filterable: true },
                wgpu::TextureViewDimension::D3,
            )
        };
        device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("voxel sampling"),
            entries: &[
                layout::uniform(0, c, false),
                layout::storage(1, c, true),
                texture(2),
                texture(3),
                layout::sampler(4, c),
                layout::storage(5, c, true),
            ],
        })
    }

    /// The layout of @group(2) of the lighting passes, twin of voxels/octree/leaves.wgsl.
    pub fn leaves_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
        let c = wgpu::ShaderStages::COMPUTE;
        device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("voxel leaves"),
            entries: &[
                layout::uniform(0, c, false),
                layout::storage(1, c, true),
                layout::storage(2, c, false),
                layout::storage(3, c, false),
                layout::storage(4, c, true),
            ],
        })
    }

    /// The layout of @group(3) of the gather, twin of voxels/octree/irradiance.wgsl: the
    /// slots' irradiance records (the voxel's slot comes from a descent of the tree).
    pub fn irradiance_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
        device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("voxel irradiance"),
            entries: &[layout::storage(0, wgpu::ShaderStages::COMPUTE, true)],
        })
    }

    /// The layout of @group(3) of the passes that store leaf radiance, twin of
    /// voxels/octree/leaf_store.wgsl.
    pub fn leaf_store_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
        device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("voxel leaf store"),
            entries: &[layout::storage_texture_3d(0, ATLAS_FORMAT)],
        })
    }

    fn build_bind_group(&self, device: &wgpu::Device, fragments: &Fragments) -> wgpu::BindGroup {
        let view = |t: &wgpu::Texture| t.create_view(&Default::default());
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("octree_build"),
            layout: &self.pipelines.build_layout,
            entries: &layout::entries(vec![
                self.tree.as_entire_binding(),
                fragments.buffer.as_entire_binding(),
                fragments.count.as_entire_binding(),
                self.nodes.as_entire_binding(),
                self.tiles.as_entire_binding(),
                self.slots.as_entire_binding(),
                wgpu::BindingResource::TextureView(&view(&self.even_atlas)),
                wgpu::BindingResource::TextureView(&view(&self.odd_atlas)),
                wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &self.levels,
                    offset: 0,
                    size: wgpu::BufferSize::new(16),
                }),
                self.block_sums.as_entire_binding(),
                self.top_grid.as_entire_binding(),
            ]),
        })
    }

    /// Records a build from every fragment in `fragments`, level by level (octree_build.wgsl).
    fn build(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        fragments: &Fragments,
        timer: &mut GpuTimer,
    ) {
        let bind = self.build_bind_group(device, fragments);
        let args = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("octree_build args"),
            layout: &self.pipelines.args_layout,
            entries: &layout::entries(vec![self.args.as_entire_binding()]),
        });
        let b = &self.pipelines.build;
        let depth = self.depth();
        let over_nodes = |t: u32| Run::Indirect((6 + 3 * t as u64) * 4);
        let mut steps: Vec<(&wgpu::ComputePipeline, u32, Run)> = vec![(&b.begin, 0, Run::Prepare)];
        for t in 0..depth {
            steps.extend([
                (&b.flag, t, Run::Indirect(0)),
                (&b.dilate, t, over_nodes(t)),
                (&b.mark, t, Run::One),
                (&b.count, t, over_nodes(t)),
                (&b.scan, t, Run::One),
                (&b.allocate, t, over_nodes(t)),
                (&b.finish, t, Run::Prepare),
                (&b.init, t + 1, over_nodes(t + 1)),
            ]);
        }
        steps.extend([
            (&b.flag, depth, Run::Indirect(0)),
            (&b.count, depth, over_nodes(depth)),
            (&b.scan, depth, Run::One),
            (&b.allocate_slots, depth, over_nodes(depth)),
            (&b.accumulate, depth, Run::Indirect(0)),
            (&b.prepare_slots, depth, Run::Prepare),
            (&b.resolve, depth, Run::Indirect(12)),
            (&b.seal, depth, Run::One),
        ]);
        // Positions the previous build filled and this one may not.
        encoder.clear_buffer(&self.top_grid, 0, None);
        self.run_steps(encoder, "octree_build", &bind, &args, &steps, timer);
        if let Some(snapshot) = &self.snapshot {
            for (live, copy) in self.snapshotted().iter().zip(snapshot) {
                encoder.copy_buffer_to_buffer(live, 0, copy, 0, live.size());
            }
        }
    }

    /// The buffers an update starts from the static build's copy of.
    fn snapshotted(&self) -> [&wgpu::Buffer; 4] {
        [&self.nodes, &self.tiles, &self.slots, &self.top_grid]
    }

    /// Records `steps` in one compute pass timed as `label`: each dispatch reads what the one
    /// before wrote (dispatch sizes, counters, nodes).
    fn run_steps(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        label: &'static str,
        bind: &wgpu::BindGroup,
        args: &wgpu::BindGroup,
        steps: &[(&wgpu::ComputePipeline, u32, Run)],
        timer: &mut GpuTimer,
    ) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(label),
            timestamp_writes: timer.compute(label),
        });
        for (pipeline, t, run) in steps {
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, bind, &[(*t as u64 * LEVEL_STRIDE) as u32]);
            match run {
                Run::Prepare => {
                    pass.set_bind_group(1, args, &[]);
                    pass.dispatch_workgroups(1, 1, 1);
                }
                Run::One => pass.dispatch_workgroups(1, 1, 1),
                Run::Indirect(offset) => pass.dispatch_workgroups_indirect(&self.args, *offset),
            }
        }
    }

    /// Records an update by the dynamic fragments (those after the static build's): the last
    /// update's texels in the static bricks are zeroed, the static build's nodes, tiles, leaves
    /// and top grid come back from their copy, and the dynamic fragments are merged in depth by
    /// depth (octree_update.wgsl). Without a copy (a scene with no dynamic instances) it is a
    /// build.
    fn update(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        fragments: &Fragments,
        timer: &mut GpuTimer,
    ) {
        let Some(snapshot) = &self.snapshot else {
            self.build(device, encoder, fragments, timer);
            return;
        };
        let bind = self.build_bind_group(device, fragments);
        let args = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("octree_update args"),
            layout: &self.pipelines.args_layout,
            entries: &layout::entries(vec![self.args.as_entire_binding()]),
        });
        let u = &self.pipelines.update;
        let depth = self.depth();
        let over_nodes = |t: u32| Run::Indirect((6 + 3 * t as u64) * 4);
        let over_new = |t: u32| Run::Indirect((ARGS_NEW + 3 * t as u64) * 4);
        let mut clear: Vec<(&wgpu::ComputePipeline, u32, Run)> = vec![
            (&u.begin_clear, 0, Run::Prepare),
            (&u.clear_leaves, 0, Run::Indirect(ARGS_CLEAR * 4)),
        ];
        for t in 1..depth {
            clear.push((&u.clear_nodes, t, over_new(t)));
        }
        self.run_steps(encoder, "octree_update", &bind, &args, &clear, timer);
        for (live, copy) in self.snapshotted().iter().zip(snapshot) {
            encoder.copy_buffer_to_buffer(copy, 0, live, 0, live.size());
        }
        let mut steps: Vec<(&wgpu::ComputePipeline, u32, Run)> = vec![
            (&u.begin_update, 0, Run::Prepare),
            (&u.bounds, 0, Run::Indirect(0)),
        ];
        for t in 0..depth {
            steps.extend([
                (&u.flag, t, Run::Indirect(0)),
                (&u.mark, t, Run::One),
                (&u.prepare_depth, t, Run::Prepare),
                (&u.count, t, over_nodes(t)),
                (&u.scan, t, Run::One),
                (&u.allocate, t, over_nodes(t)),
                (&u.finish_update, t, Run::Prepare),
                (&u.init, t + 1, over_new(t + 1)),
            ]);
            if t + 1 < depth {
                steps.push((&u.repair, t + 1, over_new(t + 1)));
            }
        }
        steps.extend([
            (&u.flag, depth, Run::Indirect(0)),
            (&u.prepare_depth, depth, Run::Prepare),
            (&u.count, depth, over_nodes(depth)),
            (&u.scan, depth, Run::One),
            (&u.allocate_slots, depth, over_nodes(depth)),
            (&u.accumulate, depth, Run::Indirect(0)),
            (&u.prepare_slots, depth, Run::Prepare),
            // Over the box's voxels (prepare_depth's size), not every slot.
            (&u.resolve, depth, over_nodes(depth)),
            (&u.end_update, depth, Run::Prepare),
        ]);
        self.run_steps(encoder, "octree_update", &bind, &args, &steps, timer);
    }

    /// Records the filtering of every level above the leaves, finest first: one dispatch per
    /// depth (octree_filter.wgsl), timed as "octree_filter".
    fn filter(&self, encoder: &mut wgpu::CommandEncoder, timer: &mut GpuTimer) {
        let depth = self.depth();
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("octree_filter"),
            timestamp_writes: timer.compute("octree_filter"),
        });
        pass.set_pipeline(&self.pipelines.filter);
        // Depth t's dispatch runs over the nodes of depth t + 1 and writes level depth - 1 - t.
        for t in (0..depth - 1).rev() {
            let level = depth - 1 - t;
            let group = &self.filter[(level & 1) as usize];
            pass.set_bind_group(0, group, &[(t as u64 * LEVEL_STRIDE) as u32]);
            pass.dispatch_workgroups_indirect(&self.args, (6 + 3 * (t as u64 + 1)) * 4);
        }
        // Level D, the whole volume as one voxel, from the root's brick.
        pass.set_pipeline(&self.pipelines.filter_top);
        pass.set_bind_group(0, &self.filter[(depth & 1) as usize], &[0]);
        pass.dispatch_workgroups(1, 1, 1);
    }

    fn memory_report(&self) -> Vec<(&'static str, u64)> {
        let texels = |t: &wgpu::Texture| {
            let s = t.size();
            s.width as u64 * s.height as u64 * s.depth_or_array_layers as u64 * 8
        };
        vec![
            (
                "octree nodes",
                self.nodes.size()
                    + self.tiles.size()
                    + self.block_sums.size()
                    + self.top_grid.size(),
            ),
            (
                "octree leaf slots",
                self.slots.size()
                    + self.leaf_direct.size()
                    + self.leaf_next.size()
                    + self.leaf_irradiance.size(),
            ),
            (
                "octree static copy (dynamic scenes)",
                self.snapshot.iter().flatten().map(|b| b.size()).sum(),
            ),
            ("octree even atlas", texels(&self.even_atlas)),
            ("octree odd atlas", texels(&self.odd_atlas)),
        ]
    }
}

/// How a step of octree_build is dispatched.
enum Run {
    /// One thread that writes dispatch sizes (it binds the arguments buffer).
    Prepare,
    /// One thread.
    One,
    /// Sized by the dispatch arguments at this byte offset.
    Indirect(u64),
}

impl VoxelStructure for OctreeVolume {
    fn kind(&self) -> crate::voxel::VoxelKind {
        crate::voxel::VoxelKind::OCTREE
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }

    fn grid(&self) -> Grid {
        self.grid
    }

    fn record_build(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        fragments: &Fragments,
        timer: &mut GpuTimer,
    ) {
        self.build(device, encoder, fragments, timer);
    }

    fn record_update(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        fragments: &Fragments,
        timer: &mut GpuTimer,
    ) {
        self.update(device, encoder, fragments, timer);
    }

    fn record_filter(
        &self,
        _device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
    ) {
        self.filter(encoder, timer);
    }

    fn pool_counter(&self) -> &wgpu::Buffer {
        &self.nodes
    }

    fn leaf_capacity(&self) -> u64 {
        self.pools.slots as u64
    }

    fn needs_growth(&self, counted: &[u32; POOL_COUNTERS]) -> bool {
        self.pools.resized_for(counted).is_some()
    }

    fn grow(&mut self, device: &wgpu::Device, counted: &[u32; POOL_COUNTERS]) -> crate::Result<()> {
        let Some(pools) = self.pools.resized_for(counted) else {
            return Ok(());
        };
        let grown = crate::gpu::checked(device, "octree pools", || {
            OctreeVolume::new(
                device,
                &self.pipelines,
                self.grid,
                Filtering {
                    anisotropic: self.anisotropic,
                    ndf: self.layout.ndf != 0,
                },
                pools,
                self.snapshot.is_some(),
            )
        })??;
        *self = grown;
        Ok(())
    }

    fn memory(&self) -> Vec<(&'static str, u64)> {
        self.memory_report()
    }

    fn sampling(&self) -> &wgpu::BindGroup {
        &self.sampling
    }

    fn leaves(&self) -> &wgpu::BindGroup {
        &self.leaves
    }

    fn leaf_store(&self) -> &wgpu::BindGroup {
        &self.leaf_store
    }

    fn leaf_irradiance(&self) -> &wgpu::Buffer {
        &self.leaf_irradiance
    }

    fn irradiance(&self) -> &wgpu::BindGroup {
        &self.irradiance
    }

    fn leaf_dispatch(&self) -> (&wgpu::Buffer, u64) {
        (&self.args, 12)
    }

    fn record_debug(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        targets: &FrameTargets,
        view: DebugView,
        timer: &mut GpuTimer,
    ) {
        self.pipelines
            .debug
            .record(device, encoder, targets, self, view, timer);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atlases_stay_within_the_texture_limit() {
        let [one] = GpuAtlasShape::regions([(1, 6)], 2048).unwrap();
        assert_eq!(
            (one.shift, one.block, one.z0, one.size()),
            ([1, 1], 3, 0, [6, 6, 18])
        );
        // 512 bricks of 3 texels a row fit 2048; six blocks of 113 layers do, 114 do not.
        let [big] = GpuAtlasShape::regions([(512 * 512 * 113, 6)], 2048).unwrap();
        assert_eq!(big.size(), [1536, 1536, 6 * 3 * 113]);
        assert_eq!(
            GpuAtlasShape::regions([(512 * 512 * 113 + 1, 6)], 2048),
            None
        );
        for n in [27u64, 1000, 1_000_003] {
            let [a, b] = GpuAtlasShape::regions([(n, 1), (n / 3, 6)], 2048).unwrap();
            assert_eq!(a.size(), b.size(), "one texture");
            let [x, y, z] = a.size();
            // The last brick of each region, in its last block, lies inside and after the
            // region before.
            let ta = a.brick_texel(n as u32 - 1, 0);
            let tb = b.brick_texel((n / 3).max(1) as u32 - 1, 5);
            assert!(ta[2] + 3 <= b.z0, "{n}: {ta:?} reaches into {b:?}");
            assert!(
                ta[0] + 3 <= x && ta[1] + 3 <= y && tb[2] + 3 <= z,
                "{n}: {tb:?}"
            );
        }
    }

    #[test]
    fn pools_grow_to_what_was_counted_and_by_half_at_least() {
        let p = OctreePools {
            slots: 1000,
            leaf_tiles: 100,
            even_tiles: 10,
            odd_tiles: 10,
        };
        assert_eq!(p.resized_for(&[1000, 100, 10, 10]), None);
        let g = p.resized_for(&[5000, 100, 10, 11]).unwrap();
        assert_eq!(
            (g.slots, g.leaf_tiles, g.even_tiles, g.odd_tiles),
            (5000, 150, 64, 64)
        );
    }

    #[test]
    fn pools_far_larger_than_needed_shrink_to_the_counts() {
        let big = OctreePools::for_leaves(4_000_000);
        let counted = [400_000, 150_000, 6_000, 25_000];
        let fit = big
            .resized_for(&counted)
            .expect("a tenth of the pools is used");
        assert_eq!(
            (fit.slots, fit.leaf_tiles, fit.even_tiles, fit.odd_tiles),
            (450_000, 168_750, 6_750, 28_125)
        );
        // Sized so, the next build keeps them.
        assert_eq!(fit.resized_for(&counted), None);
    }
}
