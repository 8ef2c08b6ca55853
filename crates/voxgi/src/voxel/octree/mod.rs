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

use super::{DebugView, Grid, POOL_COUNTERS, VoxelStructure};
use crate::fragments::Fragments;
use crate::gpu::timer::GpuTimer;
use crate::gpu::{layout, shader};
use crate::targets::FrameTargets;
use bytemuck::{Pod, Zeroable};
use debug::DebugPass;
use std::sync::Arc;
use wgpu::util::DeviceExt;

/// Format of both atlases: optical depth (L sigma, sigma), as the dense volume's radiance.
pub const ATLAS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// u32 per node: child pointer and the -x, -y, -z neighbours (`NODE_STRIDE`).
pub const NODE_WORDS: u64 = 4;
/// u32 per leaf slot (`SLOT_STRIDE` in tree.wgsl): what the leaf is, and the build's sums.
pub const SLOT_WORDS: u64 = 17;
/// Bytes per leaf slot across the slot, direct-light and bounce buffers.
pub const SLOT_BYTES: u64 = SLOT_WORDS * 4 + 32;
/// Words of counters before the nodes in the node buffer (`NODE_HEADER` in tree.wgsl).
const NODE_HEADER: u64 = 32;
/// Stride of the per-depth uniforms (the minimum dynamic-offset alignment).
const LEVEL_STRIDE: u64 = 256;
/// Texels per brick side.
const BRICK: u32 = 3;

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
    /// Padding; zero.
    pub _pad0: u32,
    /// Bricks per row and per layer of the even atlas.
    pub even_bricks: [u32; 2],
    /// Bricks per row and per layer of the odd atlas.
    pub odd_bricks: [u32; 2],
    /// Padding; zero.
    pub _pad1: [u32; 2],
    /// 1 / (even atlas size in texels); w unused.
    pub even_texel: [f32; 4],
    /// 1 / (odd atlas size in texels); w unused.
    pub odd_texel: [f32; 4],
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

    /// The pools that hold what a build counted (`OctreeVolume::pool_counter`'s first four
    /// words), or None when these already do. A pool that overflowed hides what the levels
    /// below it would have needed, so every pool grows at least by half once one overflows.
    pub fn grown_for(&self, counted: &[u32]) -> Option<Self> {
        let have = [self.slots, self.leaf_tiles, self.even_tiles, self.odd_tiles];
        if counted.iter().zip(have).all(|(&n, h)| n <= h) {
            return None;
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

/// Bricks per row, per layer and layers of an atlas of `slots` bricks, within `max_dim` texels.
fn atlas_shape(slots: u64, max_dim: u32) -> Option<[u32; 3]> {
    let per_side = (max_dim / BRICK).max(1) as u64;
    let slots = slots.max(1);
    let row = (slots as f64).cbrt().ceil() as u64;
    let row = row.clamp(1, per_side);
    let layers = slots.div_ceil(row * row);
    (layers <= per_side).then_some([row as u32, row as u32, layers as u32])
}

/// The octree's pipelines (octree_build, octree_filter, debug): made once per renderer and
/// shared by every octree it makes (one is remade whenever its pools grow).
pub struct OctreePipelines {
    build_layout: wgpu::BindGroupLayout,
    args_layout: wgpu::BindGroupLayout,
    filter_layout: wgpu::BindGroupLayout,
    build: BuildPipelines,
    filter: wgpu::ComputePipeline,
    filter_top: wgpu::ComputePipeline,
    debug: DebugPass,
}

struct BuildPipelines {
    begin: wgpu::ComputePipeline,
    flag: wgpu::ComputePipeline,
    dilate: wgpu::ComputePipeline,
    mark: wgpu::ComputePipeline,
    allocate: wgpu::ComputePipeline,
    finish: wgpu::ComputePipeline,
    init: wgpu::ComputePipeline,
    allocate_slots: wgpu::ComputePipeline,
    accumulate: wgpu::ComputePipeline,
    prepare_slots: wgpu::ComputePipeline,
    resolve: wgpu::ComputePipeline,
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
        let m = shader::module_for(device, "voxels/octree/octree_build.wgsl", "octree");
        let b = |entry: &str, args: bool| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("octree_build"),
                layout: Some(if args { &with_args } else { &plain }),
                module: &m,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        let build = BuildPipelines {
            begin: b("begin", true),
            flag: b("flag", false),
            dilate: b("dilate", false),
            mark: b("mark", false),
            allocate: b("allocate", false),
            finish: b("finish", true),
            init: b("init", false),
            allocate_slots: b("allocate_slots", false),
            accumulate: b("accumulate", false),
            prepare_slots: b("prepare_slots", true),
            resolve: b("resolve", false),
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
            ],
        });
        let filter_module =
            shader::module_for(device, "voxels/octree/octree_filter.wgsl", "octree");
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
    /// u32 per node, eight nodes per tile.
    pub nodes: wgpu::Buffer,
    /// Per tile: its parent node.
    pub tile_parent: wgpu::Buffer,
    /// Per leaf slot, `SLOT_WORDS` u32.
    pub slots: wgpu::Buffer,
    /// Per leaf: direct radiance and opacity (vec4 f32).
    pub leaf_direct: wgpu::Buffer,
    /// Per leaf: the last bounce's radiance and opacity (vec4 f32).
    pub leaf_next: wgpu::Buffer,
    /// Indirect dispatch sizes: [0..3] over fragments, [3..6] over leaves, then per depth over
    /// its nodes.
    pub args: wgpu::Buffer,
    /// Per depth: the depth, at `LEVEL_STRIDE` bytes (dynamic uniform offsets).
    levels: wgpu::Buffer,
    /// Bricks of level 0 and of the even levels above it.
    pub even_atlas: wgpu::Texture,
    /// Bricks of the odd levels.
    pub odd_atlas: wgpu::Texture,
    sampling: wgpu::BindGroup,
    leaves: wgpu::BindGroup,
    leaf_store: wgpu::BindGroup,
    /// Filter bind groups: [0] writes the even atlas (reads the odd), [1] writes the odd.
    filter: [wgpu::BindGroup; 2],
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

fn atlas(device: &wgpu::Device, label: &str, shape: [u32; 3]) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width: shape[0] * BRICK,
            height: shape[1] * BRICK,
            depth_or_array_layers: shape[2] * BRICK,
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
        anisotropic: bool,
        pools: OctreePools,
    ) -> crate::Result<Self> {
        let depth = grid.resolution.ilog2();
        let dirs: u32 = if anisotropic { 6 } else { 1 };
        let base_v = 1u64;
        let base_e = base_v + pools.leaf_tiles as u64;
        let base_o = base_e + pools.even_tiles as u64;
        let tiles = base_o + pools.odd_tiles as u64;
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
        too_big("nodes", tiles * 8 * NODE_WORDS * 4)?;
        too_big("leaf slots", pools.slots as u64 * SLOT_WORDS * 4)?;
        let even_slots = pools.leaf_tiles as u64 + dirs as u64 * pools.even_tiles as u64;
        let odd_slots = dirs as u64 * pools.odd_tiles as u64;
        let max_dim = limits.max_texture_dimension_3d;
        let shape = |slots: u64| {
            atlas_shape(slots, max_dim).ok_or_else(|| {
                crate::Error::Setting(format!(
                    "the octree needs {slots} bricks, more than a {max_dim}³ atlas holds; \
                     lower the voxel resolution"
                ))
            })
        };
        let (even_shape, odd_shape) = (shape(even_slots)?, shape(odd_slots)?);
        let texel = |s: [u32; 3]| {
            [
                1.0 / (s[0] * BRICK) as f32,
                1.0 / (s[1] * BRICK) as f32,
                1.0 / (s[2] * BRICK) as f32,
                0.0,
            ]
        };
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
            _pad0: 0,
            even_bricks: [even_shape[0], even_shape[1]],
            odd_bricks: [odd_shape[0], odd_shape[1]],
            _pad1: [0; 2],
            even_texel: texel(even_shape),
            odd_texel: texel(odd_shape),
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
        let nodes = storage_buffer(
            device,
            "octree nodes",
            (NODE_HEADER + tiles * 8 * NODE_WORDS) * 4,
        );
        let tile_parent = storage_buffer(device, "octree tile parents", tiles * 4);
        let slot_buf = storage_buffer(device, "octree leaf slots", slots * SLOT_WORDS * 4);
        let leaf_direct = storage_buffer(device, "octree direct light", slots * 16);
        let leaf_next = storage_buffer(device, "octree bounce light", slots * 16);
        let args = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("octree dispatch sizes"),
            size: (6 + 3 * 11) * 4,
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::INDIRECT
                | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let even_atlas = atlas(device, "octree even atlas", even_shape);
        let odd_atlas = atlas(device, "octree odd atlas", odd_shape);
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
                    tile_parent.as_entire_binding(),
                    wgpu::BindingResource::TextureView(&view(src)),
                    wgpu::BindingResource::TextureView(&view(dst)),
                    level.clone(),
                ]),
            })
        };
        let filter = [
            filter_group(&odd_atlas, &even_atlas),
            filter_group(&even_atlas, &odd_atlas),
        ];
        Ok(OctreeVolume {
            grid,
            anisotropic,
            pools,
            tree,
            layout,
            nodes,
            tile_parent,
            slots: slot_buf,
            leaf_direct,
            leaf_next,
            args,
            levels,
            even_atlas,
            odd_atlas,
            sampling,
            leaves,
            leaf_store,
            filter,
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
                self.tile_parent.as_entire_binding(),
                self.slots.as_entire_binding(),
                wgpu::BindingResource::TextureView(&view(&self.even_atlas)),
                wgpu::BindingResource::TextureView(&view(&self.odd_atlas)),
                wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &self.levels,
                    offset: 0,
                    size: wgpu::BufferSize::new(16),
                }),
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
                (&b.allocate, t, over_nodes(t)),
                (&b.finish, t, Run::Prepare),
                (&b.init, t + 1, over_nodes(t + 1)),
            ]);
        }
        steps.extend([
            (&b.flag, depth, Run::Indirect(0)),
            (&b.allocate_slots, depth, over_nodes(depth)),
            (&b.accumulate, depth, Run::Indirect(0)),
            (&b.prepare_slots, depth, Run::Prepare),
            (&b.resolve, depth, Run::Indirect(12)),
        ]);
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("octree_build"),
            timestamp_writes: timer.compute("octree_build"),
        });
        for (pipeline, t, run) in steps {
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &bind, &[(t as u64 * LEVEL_STRIDE) as u32]);
            match run {
                Run::Prepare => {
                    pass.set_bind_group(1, &args, &[]);
                    pass.dispatch_workgroups(1, 1, 1);
                }
                Run::One => pass.dispatch_workgroups(1, 1, 1),
                Run::Indirect(offset) => pass.dispatch_workgroups_indirect(&self.args, offset),
            }
        }
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
            ("octree nodes", self.nodes.size() + self.tile_parent.size()),
            (
                "octree leaf slots",
                self.slots.size() + self.leaf_direct.size() + self.leaf_next.size(),
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
    fn kind(&self) -> &'static str {
        "octree"
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

    /// Rebuilds from the static and dynamic fragments together: correct (it equals a fresh
    /// build of both), but it costs a full build per update; every leaf is new afterwards.
    fn record_update(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        fragments: &Fragments,
        timer: &mut GpuTimer,
    ) {
        self.build(device, encoder, fragments, timer);
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
        self.pools.grown_for(counted).is_some()
    }

    fn grow(&mut self, device: &wgpu::Device, counted: &[u32; POOL_COUNTERS]) -> crate::Result<()> {
        let Some(pools) = self.pools.grown_for(counted) else {
            return Ok(());
        };
        let grown = crate::gpu::checked(device, "octree pools", || {
            OctreeVolume::new(device, &self.pipelines, self.grid, self.anisotropic, pools)
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
        assert_eq!(atlas_shape(1, 2048), Some([1, 1, 1]));
        assert_eq!(atlas_shape(27, 2048), Some([3, 3, 3]));
        // 682 bricks of 3 texels per side fit 2048; one layer more does not.
        assert_eq!(atlas_shape(682 * 682 * 682, 2048), Some([682, 682, 682]));
        assert_eq!(atlas_shape(682 * 682 * 682 + 1, 2048), None);
        let [x, y, z] = atlas_shape(1_000_003, 2048).unwrap();
        assert!(x as u64 * y as u64 * z as u64 >= 1_000_003);
    }

    #[test]
    fn pools_grow_to_what_was_counted_and_by_half_at_least() {
        let p = OctreePools {
            slots: 1000,
            leaf_tiles: 100,
            even_tiles: 10,
            odd_tiles: 10,
        };
        assert_eq!(p.grown_for(&[1000, 100, 10, 10]), None);
        let g = p.grown_for(&[5000, 100, 10, 11]).unwrap();
        assert_eq!(
            (g.slots, g.leaf_tiles, g.even_tiles, g.odd_tiles),
            (5000, 150, 64, 64)
        );
    }
}
