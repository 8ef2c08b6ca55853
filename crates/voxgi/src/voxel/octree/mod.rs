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

mod build;
pub mod cpu;
pub mod debug;
mod filter;
mod pipelines;
mod pools;
mod tree;

pub use pipelines::OctreePipelines;
pub use pools::{OctreePools, STATIC_COUNTED, STOOD_IN_COUNTED};
#[cfg(test)]
pub(crate) use tree::SHARED_CONSTANTS;
pub use tree::{
    ACCUM_WORDS, ATLAS_FORMAT, GpuAtlasShape, GpuOctree, NODE_WORDS, SLOT_BYTES, SLOT_WORDS,
};
use tree::{
    ARGS_WORDS, FLAG_FORMAT, FLAG_SHIFT, GRID_DEPTH, LEVEL_STRIDE, NODE_HEADER, TILE_WORDS, atlas,
    storage_buffer,
};

use super::registry::{KindInfo, StructureDesc};
use super::{
    DebugView, Filtering, FragmentBind, Grid, POOL_COUNTERS, StructureBindings, VoxelStructure,
};
use crate::fragments::Fragments;
use crate::frame::targets::FrameTargets;
use crate::gpu::checked;
use crate::gpu::shader::StructureShaders;
use crate::gpu::timer::GpuTimer;
use crate::gpu::{layout, shader};
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
            "voxels/octree/carry.wgsl",
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
        base: None,
    },
    sampling_layout: OctreeVolume::sampling_layout,
    leaves_layout: OctreeVolume::leaves_layout,
    leaf_store_layout: OctreeVolume::leaf_store_layout,
    irradiance_layout: OctreeVolume::irradiance_layout,
    // Its carry.wgsl reads nothing: any group fits.
    carry_layout: OctreeVolume::irradiance_layout,
    sampling_constants: super::sampling_constants,
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
    let guess = OctreePools::for_leaves(desc.leaves);
    log::info!(
        "octree: pools for an estimated {} leaves: {} leaf tiles, {} MiB of nodes",
        desc.leaves,
        guess.leaf_tiles,
        guess.node_bytes() >> 20
    );
    let pools = guess.within(max_binding(device));
    let v = checked(device, "voxel octree", || {
        OctreeVolume::new(device, &p, desc.grid, desc.filtering, pools, desc.dynamic)
    })??;
    Ok(Box::new(v))
}

/// The largest buffer the octree may bind on `device`.
fn max_binding(device: &wgpu::Device) -> u64 {
    let l = device.limits();
    l.max_storage_buffer_binding_size.min(l.max_buffer_size)
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
    /// One r32uint per node above the leaves, `1 << FLAG_SHIFT` a row: 1 where the node's
    /// value is out of date (tree.wgsl's FLAG_SHIFT); the filter redoes only those.
    pub filter_flags: wgpu::Texture,
    /// [0]: the nodes the last filter redid.
    pub filter_redone: wgpu::Buffer,
    sampling: wgpu::BindGroup,
    leaves: wgpu::BindGroup,
    leaf_store: wgpu::BindGroup,
    irradiance: wgpu::BindGroup,
    /// Filter bind groups: [0] writes the even atlas (reads the odd), [1] the odd (reads the
    /// even).
    filter: [wgpu::BindGroup; 2],
    /// What a dynamic scene's updates start from; None for a scene without dynamic instances
    /// (its build makes its scratch and drops it).
    updates: Option<UpdateBase>,
    /// octree_build's and octree_update's bind group over the fragments (`bind_fragments`).
    fragment_bind: FragmentBind,
    /// The build steps' dispatch sizes, bound for the steps that write them.
    args_bind: wgpu::BindGroup,
    pipelines: Arc<OctreePipelines>,
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
        // With specular lobes, the lobe chain's two blocks after the six (octree_filter.wgsl's
        // `lobe_filtered`).
        let dirs = filtering.blocks();
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
                return Err(crate::Error::TooLarge(format!(
                    "the octree needs {} MiB of {what}, more than this GPU's storage-buffer \
                     limit ({} MiB); lower the voxel resolution",
                    bytes >> 20,
                    limits.max_storage_buffer_binding_size >> 20
                )));
            }
            Ok(())
        };
        too_big("nodes", node_words * 4)?;
        let flag_rows = (8 * base_v).div_ceil(1 << FLAG_SHIFT);
        if flag_rows > limits.max_texture_dimension_2d as u64 {
            return Err(crate::Error::TooLarge(format!(
                "the octree needs {} nodes above its leaves, more than the filter's flags hold \
                 in a {}-texel-high texture; lower the voxel resolution",
                8 * base_v,
                limits.max_texture_dimension_2d
            )));
        }
        // The build's scratch (a flag bit per tile, then the sums per slot) is the larger
        // per-slot buffer.
        too_big("leaf slots", scratch_bytes(tiles, pools.slots as u64))?;
        let max_dim = limits.max_texture_dimension_3d;
        let too_many = |bricks: u64| {
            crate::Error::TooLarge(format!(
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
            lobes: filtering.lobes as u32,
            _pad: 0,
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
        let g = (depth - 1).min(GRID_DEPTH);
        let grid_words = ((1u64 << (3 * (g + 1))) - 1) / 7;
        let top_grid = storage_buffer(device, "octree top grid", grid_words * 4);
        let slot_buf = storage_buffer(device, "octree leaf slots", slots * SLOT_WORDS * 4);
        let leaf_direct = storage_buffer(
            device,
            "octree direct light",
            slots * filtering.direct_bytes(),
        );
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
        let filter_flags = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("octree filter flags"),
            size: wgpu::Extent3d {
                width: 1 << FLAG_SHIFT,
                height: flag_rows.max(1) as u32,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: FLAG_FORMAT,
            usage: wgpu::TextureUsages::STORAGE_BINDING
                | wgpu::TextureUsages::COPY_DST
                | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let filter_redone = storage_buffer(device, "octree filter redone", 16);
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
            entries: &layout::entries(vec![
                wgpu::BindingResource::TextureView(&view(&even_atlas)),
                wgpu::BindingResource::TextureView(&view(&filter_flags)),
            ]),
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
                    wgpu::BindingResource::TextureView(&view(&filter_flags)),
                    filter_redone.as_entire_binding(),
                    leaf_direct.as_entire_binding(),
                ]),
            })
        };
        let filter = [
            filter_group(&odd_atlas, &even_atlas),
            filter_group(&even_atlas, &odd_atlas),
        ];
        let updates = dynamic.then(|| {
            let bytes = scratch_bytes(tiles, pools.update_slots() as u64);
            UpdateBase {
                scratch: storage_buffer(device, "octree update sums", bytes),
                header: storage_buffer(device, "octree static header", NODE_HEADER * 4),
            }
        });
        let args_bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("octree_build args"),
            layout: &pipelines.args_layout,
            entries: &layout::entries(vec![args.as_entire_binding()]),
        });
        Ok(OctreeVolume {
            grid,
            anisotropic,
            pools,
            tree,
            layout,
            nodes,
            tiles: tile_buf,
            top_grid,
            slots: slot_buf,
            leaf_direct,
            leaf_next,
            leaf_irradiance,
            args,
            levels,
            even_atlas,
            odd_atlas,
            filter_flags,
            filter_redone,
            sampling,
            leaves,
            leaf_store,
            irradiance,
            filter,
            updates,
            fragment_bind: FragmentBind::default(),
            args_bind,
            pipelines: pipelines.clone(),
        })
    }

    /// log2 of the finest resolution: the depth of the leaf voxels.
    pub fn depth(&self) -> u32 {
        self.layout.depth
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
            entries: &[
                layout::storage_texture_3d(0, ATLAS_FORMAT),
                layout::storage_texture(1, FLAG_FORMAT),
            ],
        })
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
                    + self.top_grid.size()
                    + self.filter_flags.width() as u64 * self.filter_flags.height() as u64 * 4,
            ),
            (
                "octree leaf slots",
                self.slots.size()
                    + self.leaf_direct.size()
                    + self.leaf_next.size()
                    + self.leaf_irradiance.size(),
            ),
            (
                "octree update sums (dynamic scenes)",
                self.updates
                    .as_ref()
                    .map_or(0, |u| u.scratch.size() + u.header.size()),
            ),
            ("octree even atlas", texels(&self.even_atlas)),
            ("octree odd atlas", texels(&self.odd_atlas)),
        ]
    }
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

    fn bind_fragments(&mut self, device: &wgpu::Device, fragments: &Fragments) {
        // The updates' bind group; a build makes its own, with sums for all its slots.
        if let Some(u) = &self.updates {
            let bind = self.build_bind_group(device, fragments, &u.scratch);
            self.fragment_bind.set(fragments, bind);
        }
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

    fn record_filter(&self, encoder: &mut wgpu::CommandEncoder, timer: &mut GpuTimer) {
        self.filter(encoder, timer);
    }

    fn pool_counter(&self) -> &wgpu::Buffer {
        &self.nodes
    }

    fn leaf_capacity(&self) -> u64 {
        self.pools.slots as u64
    }

    fn leaf_limit(&self, device: &wgpu::Device) -> u64 {
        // The build's scratch holds the tiles' flags before the slots' sums.
        (max_binding(device) / 4).saturating_sub(scratch_bytes(self.layout.tiles as u64, 0) / 4)
            / ACCUM_WORDS
    }

    fn occupied(&self, counted: &[u32; POOL_COUNTERS]) -> u64 {
        // The static leaves an update's slots stand in for are hidden.
        counted[0].saturating_sub(counted[STOOD_IN_COUNTED]) as u64
    }

    fn needs_growth(&self, counted: &[u32; POOL_COUNTERS]) -> bool {
        self.pools
            .resized_for(counted, self.updates.is_some())
            .is_some()
    }

    fn grow(&mut self, device: &wgpu::Device, counted: &[u32; POOL_COUNTERS]) -> crate::Result<()> {
        let Some(pools) = self.pools.resized_for(counted, self.updates.is_some()) else {
            return Ok(());
        };
        let make = |pools: OctreePools| {
            crate::gpu::checked(device, "octree pools", || {
                OctreeVolume::new(
                    device,
                    &self.pipelines,
                    self.grid,
                    Filtering {
                        anisotropic: self.anisotropic,
                        ndf: self.layout.ndf != 0,
                        lobes: self.layout.lobes != 0,
                    },
                    pools,
                    self.updates.is_some(),
                )
            })?
        };
        // Growing by half may pass a limit the counts themselves are within: then the counts
        // (and an eighth) are tried, and their error is the one that names the real need.
        let grown = make(pools).or_else(|e| {
            let fitted = OctreePools::fitting(counted, self.updates.is_some());
            if fitted == pools {
                Err(e)
            } else {
                make(fitted)
            }
        })?;
        *self = grown;
        Ok(())
    }

    fn memory(&self) -> Vec<(&'static str, u64)> {
        self.memory_report()
    }

    fn bindings(&self) -> StructureBindings<'_> {
        StructureBindings {
            sampling: &self.sampling,
            leaves: &self.leaves,
            leaf_store: &self.leaf_store,
            irradiance: &self.irradiance,
            carry: &self.irradiance,
            leaf_irradiance: &self.leaf_irradiance,
            leaf_dispatch: (&self.args, 12),
        }
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

/// What a dynamic scene keeps for its updates.
struct UpdateBase {
    /// The updates' scratch (`scratch` in build_shared.wgsl: the allocation's per-workgroup
    /// counts, then per slot an update may add its fragments' sums and the static slot it
    /// stands in for, which the next update's clear reads): `OctreePools::update_slots` of
    /// them, not the static build's.
    scratch: wgpu::Buffer,
    /// The static build's header of counters (ranges, slots, the first dynamic fragment),
    /// which every update starts from. The rest of what an update writes into the static
    /// nodes and leaves its successor's clear undoes (octree_update.wgsl).
    header: wgpu::Buffer,
}

/// Bytes of the build's scratch for `tiles` tiles and `slots` leaf slots (`block_words` and
/// `sums_of` in build_shared.wgsl).
pub(super) fn scratch_bytes(tiles: u64, slots: u64) -> u64 {
    (tiles / 8 + 2 + slots * ACCUM_WORDS) * 4
}
