//! The dense mip-mapped volume (the 3D-texture approach of Aherne et al. 2020): the finest level
//! as 3D textures (albedo/opacity, normal, emission, radiance), and above it six directional mip
//! chains of radiance (anisotropic voxels, Crassin et al. 2011 §9) or one isotropic chain.
//!
//! The six chains are blocks of one 3D texture stacked along z (+X at z = 0, then -X, +Y, -Y,
//! +Z, -Z), so a cone picks a direction's chain by an offset instead of a branch: branches
//! around texture fetches that differ between SIMD lanes make CPU drivers run every side of
//! them, which cost more than the fetches themselves (lavapipe: gather 2.2x slower).
//!
//! Built from voxel fragments by `dense_build.wgsl`: occupied voxels get compact slots, so
//! injection and bounces run over occupied voxels only, and clearing touches only the voxels
//! the previous build filled.

pub mod debug;
pub mod filter;

use super::{GpuVolume, Grid, texture_bytes};
use crate::fragments::Fragments;
use crate::frame::targets::FrameTargets;
use crate::gpu::checked;
use crate::gpu::shader::StructureShaders;
use crate::gpu::timer::GpuTimer;
use crate::gpu::{layout, shader};
use crate::voxel::registry::{KindInfo, StructureDesc};
use crate::voxel::{
    DebugView, Filtering, FragmentBind, POOL_COUNTERS, StructureBindings, VoxelStructure,
};
use crate::{Error, Result};
use debug::DebugPass;
use filter::FilterPass;
use glam::IVec3;
use std::sync::Arc;
use wgpu::util::DeviceExt;

/// Format of the radiance textures: the finest level holds optical depth, rgb L·sigma and a
/// sigma (see `to_depth` in shaders/shared/volume.wgsl), the chains premultiplied rgb L·alpha
/// and a alpha.
pub const RADIANCE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// Format of the finest level's albedo: rgb linear albedo, a opacity.
pub const ALBEDO_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
/// Format of the finest level's normals: xyz mean normal, w how well the fragments' normals agree.
pub const NORMAL_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Snorm;
/// Format of the finest level's emission: rgb emitted radiance, W/(m² sr).
pub const EMISSION_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// u32 sums per slot (`ACCUM_STRIDE` in build_shared.wgsl).
const ACCUM_STRIDE: u64 = 13;
/// u32 per slot of the dynamic part (`DYN_STRIDE` in build_shared.wgsl).
const DYN_STRIDE: u64 = 15;
/// Bytes of the largest per-slot buffer (the dynamic part).
pub const SLOT_BYTES: u64 = DYN_STRIDE * 4;
/// The dense volume in the registry of kinds.
pub const KIND: KindInfo = KindInfo {
    name: "dense",
    summary: "the dense mip-mapped volume: every voxel stored, fastest to sample and to update",
    // The occupancy buffer of 512³ is 512 MiB, the most a device's storage binding usually takes.
    max_resolution: 512,
    build_passes: &["dense_build", "dense_update"],
    filter_passes: &["filter"],
    shaders: StructureShaders {
        name: "dense",
        sources: crate::wgsl![
            "voxels/dense/sample.wgsl",
            "voxels/dense/windows.wgsl",
            "voxels/dense/leaves.wgsl",
            "voxels/dense/placement.wgsl",
            "voxels/dense/leaf_store.wgsl",
            "voxels/dense/changed.wgsl",
            "voxels/dense/slots.wgsl",
            "voxels/dense/carry.wgsl",
            "voxels/dense/irradiance.wgsl",
            "voxels/dense/build_shared.wgsl",
            "voxels/dense/dense_build.wgsl",
            "voxels/dense/dense_update.wgsl",
            "voxels/dense/filter.wgsl",
            "voxels/dense/debug.wgsl",
        ],
        passes: &[
            "voxels/dense/dense_build.wgsl",
            "voxels/dense/dense_update.wgsl",
            "voxels/dense/filter.wgsl",
            "voxels/dense/debug.wgsl",
        ],
        base: None,
    },
    sampling_layout: DenseVolume::sampling_layout,
    leaves_layout: DenseVolume::leaves_layout,
    leaf_store_layout: DenseVolume::leaf_store_layout,
    irradiance_layout: DenseVolume::irradiance_layout,
    // Its carry.wgsl reads nothing: any group fits.
    carry_layout: DenseVolume::irradiance_layout,
    sampling_constants: super::sampling_constants,
    create,
};

/// A dense volume for `desc`, with the pipelines of `previous` when it is one.
fn create(
    device: &wgpu::Device,
    desc: &StructureDesc,
    previous: Option<&dyn VoxelStructure>,
) -> Result<Box<dyn VoxelStructure>> {
    let previous = previous.and_then(|v| v.as_any().downcast_ref::<DenseVolume>());
    let v = DenseVolume::create(device, desc.grid, 1, desc, desc.leaves, previous)?;
    Ok(Box::new(v))
}

/// The counters' word of the windows a build rebuilds (`REBUILD` in build_shared.wgsl).
const REBUILD_WORD: u64 = 7;

/// The counters' word of the fragments made (`FRAGMENTS` in build_shared.wgsl).
const FRAGMENTS_WORD: u64 = 2;

/// Where a moved window's occupancy begins in `DenseVolume::kept`, in words (`KEPT_OCCUPANCY`
/// in build_shared.wgsl): after the head's words, at an offset a storage binding may start at.
const KEPT_OCCUPANCY_WORD: u64 = 64;

/// The constants the Rust side shares with the build's WGSL, by their WGSL names (a test
/// compares them).
pub const SHARED_CONSTANTS: &[(&str, u64)] = &[
    ("ACCUM_STRIDE", ACCUM_STRIDE),
    ("DYN_STRIDE", DYN_STRIDE),
    ("REBUILD", REBUILD_WORD),
    ("FRAGMENTS", FRAGMENTS_WORD),
    ("KEPT_OCCUPANCY", KEPT_OCCUPANCY_WORD),
    ("WINDOW_WORDS", filter::WINDOW_WORDS),
    ("MAX_WINDOWS", filter::MAX_WINDOWS),
    ("WINDOW_STRIDE", filter::WINDOW_STRIDE),
    ("W_KEPT", filter::W_KEPT),
];

/// Slot pools more than this many times the last build's count shrink.
const SHRINK_BELOW: u64 = 4;

/// Bytes of `DenseVolume::kept` per slot of a window's part: its voxel, its static sums and
/// its direct light (`direct` bytes: with its lobe, if any) twice (as it was, and handed to
/// its new slot).
fn kept_slot_bytes(direct: u64) -> u64 {
    4 * (1 + ACCUM_STRIDE) + 2 * direct
}

/// Where the regions of `DenseVolume::kept` begin, in bytes (build_shared.wgsl's `kept`),
/// for windows of `resolution`³ voxels and `window_slots` slots: after the head, the moved
/// window's occupancy, then per slot of its part its voxel, its static sums, its direct light
/// and the direct light `keep` hands to its new slot; `end` is the buffer's size.
struct KeptLayout {
    occupancy: u64,
    slots: u64,
    sums: u64,
    direct: u64,
    handed: u64,
    end: u64,
}

fn kept_layout(resolution: u32, window_slots: u32, direct_bytes: u64) -> KeptLayout {
    let part = window_slots as u64;
    let occupancy = KEPT_OCCUPANCY_WORD * 4;
    let slots = occupancy + (resolution as u64).pow(3) * 4;
    let sums = slots + part * 4;
    let direct = sums + part * ACCUM_STRIDE * 4;
    let handed = direct + part * direct_bytes;
    KeptLayout {
        occupancy,
        slots,
        sums,
        direct,
        handed,
        end: slots + part * kept_slot_bytes(direct_bytes),
    }
}

/// The most occupied voxels `windows` cubes of `grid` can hold on this device: the per-slot
/// buffers' limit, and for several windows the moved window's copy (`kept`: its occupancy and
/// one window's part, bound whole).
fn slot_limit(device: &wgpu::Device, grid: &Grid, windows: u32) -> u64 {
    let most = crate::gpu::max_entries(device, SLOT_BYTES);
    if windows < 2 {
        return most;
    }
    let room = device
        .limits()
        .max_storage_buffer_binding_size
        .saturating_sub(kept_layout(grid.resolution, 0, 0).slots);
    most.min(room / kept_slot_bytes(Filtering::MOST_DIRECT_BYTES) * windows as u64)
}

/// Checks a slot capacity (occupied voxels) against the device's storage-buffer limit.
fn slot_capacity(device: &wgpu::Device, wanted: u64) -> Result<u32> {
    crate::gpu::pool_capacity(device, wanted, SLOT_BYTES, "occupied voxels")
}

/// Checks that the per-voxel buffers and textures of `windows` cubes of `grid` fit the
/// device's limits.
fn check_volume_fits(
    device: &wgpu::Device,
    grid: &Grid,
    windows: u32,
    filtering: Filtering,
) -> Result<()> {
    let l = device.limits();
    let occupancy = (grid.resolution as u64).pow(3) * windows as u64 * 4;
    if occupancy > l.max_storage_buffer_binding_size {
        let cubes = if windows > 1 {
            format!("{windows} windows of {}³ voxels", grid.resolution)
        } else {
            format!("a {}³ volume", grid.resolution)
        };
        return Err(Error::TooLarge(format!(
            "{cubes} need a {} MiB occupancy buffer, more than this GPU's {} MiB \
             storage-buffer limit; use a voxel resolution of at most {}",
            occupancy >> 20,
            l.max_storage_buffer_binding_size >> 20,
            ((l.max_storage_buffer_binding_size / 4 / windows as u64) as f64)
                .cbrt()
                .log2()
                .floor()
                .exp2() as u32,
        )));
    }
    // The deepest texture: the directional mips' blocks of every window, along z.
    let blocks = filtering.blocks();
    let depth = (grid.resolution * windows).max(grid.resolution / 2 * blocks * windows);
    if grid.resolution > l.max_texture_dimension_3d || depth > l.max_texture_dimension_3d {
        let lobes = if filtering.lobes {
            " (with specular_bounces' two lobe blocks a level; without them it would be \
             three quarters as deep)"
        } else {
            ""
        };
        return Err(Error::TooLarge(format!(
            "{} stacked {}³ voxel textures ({depth} texels deep{lobes}) exceed this GPU's 3D \
             texture limit of {}",
            windows, grid.resolution, l.max_texture_dimension_3d
        )));
    }
    Ok(())
}

/// The dense volume: the finest level's textures, the compact slots of its occupied voxels, the
/// radiance mip chains above it, and the bind groups the passes reach it through.
pub struct DenseVolume {
    /// Where the volume lies and its finest resolution.
    pub grid: Grid,
    /// Cubes of `grid.resolution` voxels stacked along z in every texture and buffer: 1, or a
    /// clipmap's levels (which place them; `grid` then places the first).
    pub windows: u32,
    /// Six directional chains (true) or one isotropic chain.
    pub anisotropic: bool,
    /// The first chain level weighs the finest voxels by their normals (`Filtering::ndf`).
    pub ndf: bool,
    /// The slots keep specular lobes beside their direct light (`Filtering::lobes`).
    pub lobes: bool,
    /// The volume's placement as a `GpuVolume` uniform.
    pub volume: wgpu::Buffer,
    /// Occupied voxels the slot buffers hold: `windows` parts of `window_slots`.
    pub slot_capacity: u32,
    /// Occupied voxels each window's part of the slots holds (voxels/dense/slots.wgsl).
    pub window_slots: u32,
    /// `[0]` occupied voxels (slots asked for, past the capacity), `[1]` the most a window
    /// asked for, `[2]` the fragments made (`FRAGMENTS_WORD`), `[3]` and `[4]` slots the
    /// dynamic geometry touched in this and the previous update (see dense_update.wgsl), `[6]`
    /// the voxels above the finest the last filter redid (one for all its directions; 0 when
    /// it filtered everything, after a build), `[7]` a bit
    /// per window the next build rebuilds, from `[8]` each level's count of voxels with a
    /// changed child, from `[18]` each window's slot counts (`WINDOW_WORDS`), then the levels'
    /// bits and lists (voxels/dense/changed.wgsl).
    pub counters: wgpu::Buffer,
    /// Per finest voxel (x fastest): 0 empty, 2 + slot once allocated, or a lock value while
    /// allocating or past the capacity.
    pub occupancy: wgpu::Buffer,
    /// Per slot: the linear index of its voxel.
    pub slot_voxel: wgpu::Buffer,
    accum: wgpu::Buffer,
    /// The dynamic geometry's part (`dense_update`): per slot, the dynamic fragments' sums,
    /// whether it is listed as touched, and an entry of the list of slots the last update
    /// touched. One slot for a scene without dynamic instances.
    dyn_accum: wgpu::Buffer,
    /// A moved window's state from before its build, which the build keeps where the window
    /// overlaps its old place (`build_windows`; build_shared.wgsl's `kept`): the window and
    /// how far it moved, then from `KEPT_OCCUPANCY_WORD` its occupancy, then its part's slots'
    /// voxels, static sums and direct light, then the direct light the build's `keep` hands to
    /// the slots that keep their voxel. Only the head for a volume of one window.
    kept: wgpu::Buffer,
    /// Whether the pools have room for dynamic geometry.
    pub dynamic: bool,
    /// Per slot: direct radiance (rgb) and opacity from inject, kept for the bounces, and the
    /// specular lobe beside it with `lobes` (one or two vec4 f32, `Filtering::direct_bytes`).
    pub slot_direct: wgpu::Buffer,
    /// Per slot: the last bounce's outgoing radiance and opacity (vec4 f32).
    pub slot_next: wgpu::Buffer,
    /// Per slot: the irradiance record for the fast shading (`VoxelStructure::leaf_irradiance`).
    pub slot_irradiance: wgpu::Buffer,
    /// Indirect dispatch sizes: [0..3] over slots, [3..6] over fragments, [6..9] over the
    /// touched slots.
    pub args: wgpu::Buffer,
    /// Finest level: albedo and opacity per voxel (`ALBEDO_FORMAT`).
    pub albedo: wgpu::Texture,
    /// Finest level: mean normal and normal agreement per voxel (`NORMAL_FORMAT`).
    pub normal: wgpu::Texture,
    /// Finest level: emitted radiance per voxel (`EMISSION_FORMAT`).
    pub emission: wgpu::Texture,
    /// Finest level: radiance as optical depth (`RADIANCE_FORMAT`), written by inject and the
    /// bounces.
    pub radiance: wgpu::Texture,
    /// The directional chains (+X, -X, +Y, -Y, +Z, -Z) as `chain_blocks()` blocks stacked along z,
    /// each block one level coarser than the finest. In isotropic mode one block, the isotropic
    /// chain.
    pub chains: wgpu::Texture,
    sampling: wgpu::BindGroup,
    leaves: wgpu::BindGroup,
    leaf_store: wgpu::BindGroup,
    irradiance: wgpu::BindGroup,
    /// The filter's bind groups for this volume's textures.
    filter_binds: filter::FilterBinds,
    /// A build since the last filter: the next filter redoes every voxel.
    built: std::sync::atomic::AtomicBool,
    /// dense_build's and dense_update's bind group over the fragments (`bind_fragments`).
    fragment_bind: FragmentBind,
    /// The build steps' dispatch sizes, bound for the steps that write them.
    args_bind: wgpu::BindGroup,
    pipelines: Arc<DensePipelines>,
}

impl DenseVolume {
    /// How the volume filters (what it was made with).
    fn filtering(&self) -> Filtering {
        Filtering {
            anisotropic: self.anisotropic,
            ndf: self.ndf,
            lobes: self.lobes,
        }
    }

    /// The volume made again with `slots` slots (the contents are lost: the next build
    /// refills them).
    fn resize(&mut self, device: &wgpu::Device, slots: u32) -> crate::Result<()> {
        let grown = crate::gpu::checked(device, "voxel pools", || {
            DenseVolume::new(
                device,
                &self.pipelines,
                self.grid,
                self.windows,
                self.filtering(),
                slots,
                self.dynamic,
            )
        })?;
        *self = grown;
        Ok(())
    }

    /// A volume of `windows` cubes of `grid`, filtered and made dynamic as `desc` says, with
    /// room for `leaves` occupied voxels (as many as the device allows), sharing the pipelines
    /// of `previous`; errors name what does not fit the device. The dense kind's `create` and
    /// a structure built on the volume (the clipmap) make theirs here.
    pub(crate) fn create(
        device: &wgpu::Device,
        grid: Grid,
        windows: u32,
        desc: &StructureDesc,
        leaves: u64,
        previous: Option<&DenseVolume>,
    ) -> Result<DenseVolume> {
        check_volume_fits(device, &grid, windows, desc.filtering)?;
        let slots = slot_capacity(device, leaves.min(slot_limit(device, &grid, windows)))?;
        let p = match previous {
            Some(v) => v.pipelines.clone(),
            None => checked(device, "pipeline creation", || DensePipelines::new(device))?,
        };
        checked(device, "voxel volume", || {
            DenseVolume::new(
                device,
                &p,
                grid,
                windows,
                desc.filtering,
                slots,
                desc.dynamic,
            )
        })
    }

    /// A bit for each of its windows (a build of all of them).
    pub(crate) fn every_window(&self) -> u32 {
        (1 << self.windows) - 1
    }

    /// Its debug pass, for a structure built on it.
    pub fn debug_pass(&self) -> &DebugPass {
        &self.pipelines.debug
    }

    /// Its filter pass and its steps' bind groups, for a structure built on it.
    pub fn filter(&self) -> (&filter::FilterPass, &filter::FilterBinds) {
        (&self.pipelines.filter, &self.filter_binds)
    }
}

/// How a step of dense_build or dense_update is dispatched.
enum Run {
    /// One thread that writes dispatch sizes (it binds the arguments buffer).
    Prepare,
    /// One thread.
    One,
    /// Sized by the dispatch arguments at this byte offset.
    Indirect(u64),
    /// A thread per item of this many, sized by the host.
    Over(u32),
}

/// The dense volume's own pipelines (dense_build, filter, debug): made once per renderer and
/// shared by every volume it makes, since a volume is remade whenever it grows or its
/// resolution changes.
pub struct DensePipelines {
    build_layout: wgpu::BindGroupLayout,
    args_layout: wgpu::BindGroupLayout,
    build: BuildPipelines,
    update: UpdatePipelines,
    filter: FilterPass,
    debug: DebugPass,
}

/// dense_update's entry points (shaders/voxels/dense/dense_update.wgsl).
struct UpdatePipelines {
    begin: wgpu::ComputePipeline,
    restore: wgpu::ComputePipeline,
    free: wgpu::ComputePipeline,
    allocate: wgpu::ComputePipeline,
    accumulate: wgpu::ComputePipeline,
    prepare: wgpu::ComputePipeline,
    resolve: wgpu::ComputePipeline,
}

struct BuildPipelines {
    begin: wgpu::ComputePipeline,
    clear_previous: wgpu::ComputePipeline,
    keep: wgpu::ComputePipeline,
    prepare_fragments: wgpu::ComputePipeline,
    allocate: wgpu::ComputePipeline,
    accumulate: wgpu::ComputePipeline,
    prepare_slots: wgpu::ComputePipeline,
    resolve: wgpu::ComputePipeline,
}

/// `blocks` cubes of `res` texels stacked along z.
fn texture_3d_blocks(
    device: &wgpu::Device,
    label: &str,
    res: u32,
    blocks: u32,
    mips: u32,
    format: wgpu::TextureFormat,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width: res,
            height: res,
            depth_or_array_layers: res * blocks,
        },
        mip_level_count: mips,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D3,
        format,
        usage: wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC
            | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    })
}

fn storage_buffer(
    device: &wgpu::Device,
    label: &str,
    size: u64,
    extra: wgpu::BufferUsages,
) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size.max(16),
        usage: wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_DST
            | wgpu::BufferUsages::COPY_SRC
            | extra,
        mapped_at_creation: false,
    })
}

/// A view of one mip level, for writing it as a storage texture or reading it with textureLoad.
pub fn mip_view(t: &wgpu::Texture, mip: u32) -> wgpu::TextureView {
    t.create_view(&wgpu::TextureViewDescriptor {
        base_mip_level: mip,
        mip_level_count: Some(1),
        ..Default::default()
    })
}

impl DensePipelines {
    /// Compiles the build pipelines and the filter and debug passes.
    pub fn new(device: &wgpu::Device) -> Arc<Self> {
        let build_layout = build_layout(device);
        let args_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("dense_build args"),
            entries: &[layout::storage(0, wgpu::ShaderStages::COMPUTE, false)],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("dense_build"),
            bind_group_layouts: &[Some(&build_layout)],
            immediate_size: 0,
        });
        // The kernels that write dispatch sizes bind the arguments too.
        let prepare_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("dense_build prepare"),
            bind_group_layouts: &[Some(&build_layout), Some(&args_layout)],
            immediate_size: 0,
        });
        let pipe = |module: &wgpu::ShaderModule, label: &str, entry: &str, args: bool| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(label),
                layout: Some(if args {
                    &prepare_layout
                } else {
                    &pipeline_layout
                }),
                module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        let m = shader::module_for(device, "voxels/dense/dense_build.wgsl", &KIND.shaders);
        let b = |entry: &str| {
            pipe(
                &m,
                "dense_build",
                entry,
                matches!(entry, "begin" | "prepare_fragments" | "prepare_slots"),
            )
        };
        let build = BuildPipelines {
            begin: b("begin"),
            clear_previous: b("clear_previous"),
            keep: b("keep"),
            prepare_fragments: b("prepare_fragments"),
            allocate: b("allocate"),
            accumulate: b("accumulate"),
            prepare_slots: b("prepare_slots"),
            resolve: b("resolve"),
        };
        let m = shader::module_for(device, "voxels/dense/dense_update.wgsl", &KIND.shaders);
        let u = |entry: &str| {
            pipe(
                &m,
                "dense_update",
                entry,
                matches!(entry, "begin" | "prepare"),
            )
        };
        let update = UpdatePipelines {
            begin: u("begin"),
            restore: u("restore"),
            free: u("free"),
            allocate: u("allocate"),
            accumulate: u("accumulate"),
            prepare: u("prepare"),
            resolve: u("resolve"),
        };
        Arc::new(DensePipelines {
            build_layout,
            args_layout,
            build,
            update,
            filter: FilterPass::new(device),
            debug: DebugPass::new(device),
        })
    }
}

impl DenseVolume {
    /// A volume on `grid` (`windows` cubes of it stacked along z), its levels filtered as
    /// `filtering` says, with room for `slot_capacity` occupied voxels, and for updates by
    /// dynamic geometry when `dynamic`.
    pub fn new(
        device: &wgpu::Device,
        pipelines: &Arc<DensePipelines>,
        grid: Grid,
        windows: u32,
        filtering: Filtering,
        slot_capacity: u32,
        dynamic: bool,
    ) -> Self {
        let anisotropic = filtering.anisotropic;
        let res = grid.resolution;
        let levels = grid.levels();
        // Whole parts per window, four slots at least, so that the shaders find a part's size
        // from the buffer's length.
        let window_slots = (slot_capacity / windows).max(4);
        let slots = window_slots as u64 * windows as u64;
        let volume = GpuVolume {
            origin: grid.origin.to_array(),
            resolution: res,
            voxel_size: grid.voxel_size,
            levels,
            anisotropic: if anisotropic && filtering.lobes {
                2
            } else {
                anisotropic as u32
            },
            windows,
        };
        let chains = texture_3d_blocks(
            device,
            "voxel radiance mips",
            res / 2,
            filtering.blocks() * windows,
            levels - 1,
            RADIANCE_FORMAT,
        );
        let no = wgpu::BufferUsages::empty();
        let volume = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("volume"),
            contents: bytemuck::bytes_of(&volume),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        });
        let stacked =
            |label: &str, format| texture_3d_blocks(device, label, res, windows, 1, format);
        let radiance = stacked("voxel radiance", RADIANCE_FORMAT);
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("voxels"),
            address_mode_u: wgpu::AddressMode::ClampToEdge,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            address_mode_w: wgpu::AddressMode::ClampToEdge,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            ..Default::default()
        });
        let radiance_views = [
            radiance.create_view(&Default::default()),
            chains.create_view(&Default::default()),
        ];
        let sampling = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("voxel sampling"),
            layout: &Self::sampling_layout(device),
            entries: &layout::entries(Self::sampling_resources(&volume, &radiance_views, &sampler)),
        });
        let albedo = stacked("voxel albedo", ALBEDO_FORMAT);
        let normal = stacked("voxel normal", NORMAL_FORMAT);
        let emission = stacked("voxel emission", EMISSION_FORMAT);
        let slot_voxel = storage_buffer(device, "voxel slots", slots * 4, no);
        // From word 8: the levels' voxels the build and update changed (changed.wgsl).
        let counters = storage_buffer(
            device,
            "voxel counters",
            filter::counter_bytes(grid, windows),
            no,
        );
        let dyn_slots = if dynamic { slots } else { 1 };
        // Only the head for one window.
        let kept_bytes = if windows > 1 {
            kept_layout(res, window_slots, filtering.direct_bytes()).end
        } else {
            KEPT_OCCUPANCY_WORD * 4 + 4
        };
        let kept = storage_buffer(device, "voxel kept window", kept_bytes, no);
        let direct_bytes = filtering.direct_bytes();
        let slot_direct = storage_buffer(device, "voxel direct light", slots * direct_bytes, no);
        let slot_next = storage_buffer(device, "voxel bounce light", slots * 16, no);
        let slot_irradiance = storage_buffer(device, "voxel leaf irradiance", slots * 16, no);
        let occupancy = storage_buffer(
            device,
            "voxel occupancy",
            (res as u64).pow(3) * windows as u64 * 4,
            no,
        );
        let irradiance = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("voxel irradiance"),
            layout: &Self::irradiance_layout(device),
            entries: &layout::entries(vec![
                occupancy.as_entire_binding(),
                slot_irradiance.as_entire_binding(),
            ]),
        });
        let view = |t: &wgpu::Texture| t.create_view(&Default::default());
        let surface = [view(&albedo), view(&normal), view(&emission)];
        let leaves = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("voxel leaves"),
            layout: &Self::leaves_layout(device),
            entries: &layout::entries(Self::leaves_resources(
                &volume,
                &surface,
                [&slot_voxel, &counters, &slot_direct, &slot_next],
            )),
        });
        let leaf_store = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("voxel leaf store"),
            layout: &Self::leaf_store_layout(device),
            entries: &layout::entries(vec![wgpu::BindingResource::TextureView(&view(&radiance))]),
        });
        let args = storage_buffer(
            device,
            "voxel dispatch sizes",
            9 * 4,
            wgpu::BufferUsages::INDIRECT,
        );
        let filter_binds = pipelines.filter.bind(
            device,
            grid,
            windows,
            filtering,
            [&radiance, &chains, &normal],
            [&counters, &occupancy, &slot_direct],
        );
        DenseVolume {
            grid,
            windows,
            anisotropic,
            ndf: filtering.ndf,
            lobes: filtering.lobes,
            volume,
            slot_capacity: slots as u32,
            window_slots,
            counters,
            occupancy,
            slot_voxel,
            accum: storage_buffer(device, "voxel sums", slots * ACCUM_STRIDE * 4, no),
            dyn_accum: storage_buffer(device, "voxel dynamic sums", dyn_slots * DYN_STRIDE * 4, no),
            kept,
            dynamic,
            slot_direct,
            slot_next,
            slot_irradiance,
            fragment_bind: FragmentBind::default(),
            args_bind: device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("dense args"),
                layout: &pipelines.args_layout,
                entries: &layout::entries(vec![args.as_entire_binding()]),
            }),
            args,
            albedo,
            normal,
            emission,
            radiance,
            chains,
            sampling,
            leaves,
            leaf_store,
            irradiance,
            filter_binds,
            built: true.into(),
            pipelines: pipelines.clone(),
        }
    }

    /// Blocks of `chains`: six directions, or one in isotropic mode, and with the lobe chain
    /// the lobes' two.
    pub fn chain_blocks(&self) -> u32 {
        self.filtering().blocks()
    }

    fn memory_report(&self) -> Vec<(&'static str, u64)> {
        let res = self.grid.resolution;
        let aniso_mips = self.grid.levels() - 1;
        let w = self.windows as u64;
        vec![
            ("voxel occupancy", self.occupancy.size()),
            (
                "voxel slots",
                self.slot_voxel.size()
                    + self.accum.size()
                    + self.slot_direct.size()
                    + self.slot_next.size()
                    + self.slot_irradiance.size(),
            ),
            ("voxel dynamic sums", self.dyn_accum.size()),
            ("voxel kept window", self.kept.size()),
            ("voxel filter lists", self.counters.size()),
            ("voxel albedo", w * texture_bytes(res, 4, 1)),
            ("voxel normal", w * texture_bytes(res, 4, 1)),
            ("voxel emission", w * texture_bytes(res, 8, 1)),
            ("voxel radiance", w * texture_bytes(res, 8, 1)),
            (
                if self.lobes {
                    "voxel radiance mips (6 dirs, 2 lobes)"
                } else if self.anisotropic {
                    "voxel radiance mips (6 directions)"
                } else {
                    "voxel radiance mips"
                },
                w * self.chain_blocks() as u64 * texture_bytes(res / 2, 8, aniso_mips),
            ),
        ]
    }

    /// The layout of @group(1) in every pipeline that samples voxels, the twin of
    /// shaders/voxels/dense/sample.wgsl: the volume's placement, radiance0, the chains and the
    /// sampler. Layouts with the same entries are one layout to wgpu, so each pass makes its
    /// own and binds the volume's `sampling` group.
    pub fn sampling_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
        device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("voxel sampling"),
            entries: &Self::sampling_entries(),
        })
    }

    /// `sampling_layout`'s entries (bindings 0 to 3), for a structure built on the volume.
    pub fn sampling_entries() -> Vec<wgpu::BindGroupLayoutEntry> {
        let c = wgpu::ShaderStages::COMPUTE;
        let texture = |binding| {
            layout::texture(
                binding,
                c,
                wgpu::TextureSampleType::Float { filterable: true },
                wgpu::TextureViewDimension::D3,
            )
        };
        vec![
            layout::uniform(0, c, false),
            texture(1),
            texture(2),
            layout::sampler(3, c),
        ]
    }

    /// The resources of `sampling_layout`'s entries: the `volume` uniform, the views of the
    /// finest radiance and the chains, the sampler.
    pub fn sampling_resources<'a>(
        volume: &'a wgpu::Buffer,
        views: &'a [wgpu::TextureView; 2],
        sampler: &'a wgpu::Sampler,
    ) -> Vec<wgpu::BindingResource<'a>> {
        vec![
            volume.as_entire_binding(),
            wgpu::BindingResource::TextureView(&views[0]),
            wgpu::BindingResource::TextureView(&views[1]),
            wgpu::BindingResource::Sampler(sampler),
        ]
    }

    /// The layout of @group(2) of the lighting passes, twin of voxels/dense/leaves.wgsl.
    pub fn leaves_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
        device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("voxel leaves"),
            entries: &Self::leaves_entries(),
        })
    }

    /// `leaves_layout`'s entries (bindings 0 to 7), for a structure built on the volume.
    pub fn leaves_entries() -> Vec<wgpu::BindGroupLayoutEntry> {
        let c = wgpu::ShaderStages::COMPUTE;
        vec![
            layout::uniform(0, c, false),
            layout::texture_3d_load(1, c),
            layout::texture_3d_load(2, c),
            layout::texture_3d_load(3, c),
            layout::storage(4, c, true),
            layout::storage(5, c, false),
            layout::storage(6, c, false),
            layout::storage(7, c, false),
        ]
    }

    /// The resources of `leaves_layout`'s entries: the `volume` uniform, the views of the
    /// albedo, normal and emission, and the slots' voxels, the counters, the slots' direct
    /// and bounced light.
    pub fn leaves_resources<'a>(
        volume: &'a wgpu::Buffer,
        views: &'a [wgpu::TextureView; 3],
        slots: [&'a wgpu::Buffer; 4],
    ) -> Vec<wgpu::BindingResource<'a>> {
        let mut r = vec![volume.as_entire_binding()];
        r.extend(views.iter().map(wgpu::BindingResource::TextureView));
        r.extend(slots.map(|b| b.as_entire_binding()));
        r
    }

    /// The layout of @group(3) of the gather, twin of voxels/dense/irradiance.wgsl: the
    /// occupancy (voxel to slot) and the slots' irradiance records.
    pub fn irradiance_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
        let c = wgpu::ShaderStages::COMPUTE;
        device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("voxel irradiance"),
            entries: &[layout::storage(0, c, true), layout::storage(1, c, true)],
        })
    }

    /// The layout of @group(3) of the passes that store leaf radiance, twin of
    /// voxels/dense/leaf_store.wgsl.
    pub fn leaf_store_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
        device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("voxel leaf store"),
            entries: &[layout::storage_texture_3d(0, RADIANCE_FORMAT)],
        })
    }

    /// The occupancy a moved window had before its last build, as `kept` holds it (its new
    /// leaves' light starts from its leaves there: voxels/clipmap/carry.wgsl).
    pub(crate) fn kept_occupancy(&self) -> wgpu::BindingResource<'_> {
        wgpu::BindingResource::Buffer(wgpu::BufferBinding {
            buffer: &self.kept,
            offset: kept_layout(self.grid.resolution, 0, 0).occupancy,
            size: wgpu::BufferSize::new((self.grid.resolution as u64).pow(3) * 4),
        })
    }

    /// Records a build from `fragments`: forget the previous build and clear what it filled,
    /// then allocate a slot per occupied voxel, sum its fragments and resolve the finest level.
    /// Records a build of the windows in `rebuild` (a bit each) from `fragments`: every other
    /// window keeps its slots, sums and textures (a clipmap rebuilding the levels that moved).
    /// The last update is taken out of every window first (the static build is what an update
    /// merges into). With `kept`, window `.0` of them moved by `.1` voxels (its new corner
    /// minus the old) and keeps the static sums of the voxels it holds in both places: the
    /// fragments are only those of the voxels newly inside (`Region::all_but_kept`).
    pub(crate) fn build_windows(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        fragments: &Fragments,
        rebuild: u32,
        kept: Option<(u32, IVec3)>,
        timer: &mut GpuTimer,
    ) {
        let bind = self
            .fragment_bind
            .get(fragments, || self.build_bind_group(device, fragments));
        copy_fragment_count(encoder, fragments, &self.counters);
        // Every build says whether it keeps a window: the kernels skip its kept voxels.
        let kept = kept.filter(|(w, _)| self.windows > 1 && rebuild & (1 << w) != 0);
        // Word 4: the words of a slot's direct light (build_shared.wgsl's `kept`).
        let direct_bytes = self.filtering().direct_bytes();
        let words = (direct_bytes / 4) as i32;
        let head: [i32; 8] = match kept {
            Some((w, by)) => [w as i32 + 1, by.x, by.y, by.z, words, 0, 0, 0],
            None => [0, 0, 0, 0, words, 0, 0, 0],
        };
        let staging = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("dense_build kept (staging)"),
            contents: bytemuck::cast_slice(&head),
            usage: wgpu::BufferUsages::COPY_SRC,
        });
        encoder.copy_buffer_to_buffer(&staging, 0, &self.kept, 0, 32);
        let voxels = (self.grid.resolution as u64).pow(3) * 4;
        let sums = self.window_slots as u64 * ACCUM_STRIDE * 4;
        let at = kept_layout(self.grid.resolution, self.window_slots, direct_bytes);
        // Per slot of a window's part: its voxel, its direct light.
        let (part, direct) = (
            self.window_slots as u64 * 4,
            self.window_slots as u64 * direct_bytes,
        );
        // The occupancy with the last update's slots (their light is kept too), the sums
        // without (below).
        if let Some((w, _)) = kept {
            let occupancy = &self.occupancy;
            let w = w as u64;
            encoder.copy_buffer_to_buffer(occupancy, w * voxels, &self.kept, at.occupancy, voxels);
        }
        if self.dynamic {
            let u = &self.pipelines.update;
            let restore = [
                (&u.begin, Run::Prepare),
                (&u.restore, Run::Indirect(24)),
                (&u.free, Run::One),
            ];
            self.run_steps(encoder, "dense_build", &bind, &restore, timer);
        }
        if let Some((w, _)) = kept {
            let (w, kept) = (w as u64, &self.kept);
            encoder.copy_buffer_to_buffer(&self.slot_voxel, w * part, kept, at.slots, part);
            encoder.copy_buffer_to_buffer(&self.accum, w * sums, kept, at.sums, sums);
            encoder.copy_buffer_to_buffer(&self.slot_direct, w * direct, kept, at.direct, direct);
        }
        let mask = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("dense_build windows (staging)"),
            contents: bytemuck::bytes_of(&rebuild),
            usage: wgpu::BufferUsages::COPY_SRC,
        });
        encoder.copy_buffer_to_buffer(&mask, 0, &self.counters, REBUILD_WORD * 4, 4);
        let b = &self.pipelines.build;
        // The rebuilt windows' previous slots, from begin's dispatch size over them.
        let forget = [
            (&b.begin, Run::Prepare),
            (&b.clear_previous, Run::Indirect(0)),
        ];
        self.run_steps(encoder, "dense_build", &bind, &forget, timer);
        let all = self.every_window();
        if rebuild & all == all {
            encoder.clear_buffer(&self.occupancy, 0, None);
            encoder.clear_buffer(&self.accum, 0, None);
            encoder.clear_buffer(&self.dyn_accum, 0, None);
        } else {
            // Each window's voxels and slots are one range of their buffers.
            for w in (0..self.windows as u64).filter(|w| rebuild & (1 << w) != 0) {
                encoder.clear_buffer(&self.occupancy, w * voxels, Some(voxels));
                encoder.clear_buffer(&self.accum, w * sums, Some(sums));
            }
        }
        if let Some((w, _)) = kept {
            // A thread per slot of the window's part.
            let keep = [(&b.keep, Run::Over(self.window_slots))];
            self.run_steps(encoder, "dense_build", &bind, &keep, timer);
            // The kept slots' direct light, by their new slots. The part's other slots take
            // stale light here, but they are new leaves: a frame with voxel work always injects,
            // and inject lights every new leaf it was not handed.
            let light = &self.slot_direct;
            encoder.copy_buffer_to_buffer(&self.kept, at.handed, light, w as u64 * direct, direct);
        }
        let steps = [
            (&b.prepare_fragments, Run::Prepare),
            (&b.allocate, Run::Indirect(12)),
            (&b.accumulate, Run::Indirect(12)),
            (&b.prepare_slots, Run::Prepare),
            (&b.resolve, Run::Indirect(0)),
        ];
        self.run_steps(encoder, "dense_build", &bind, &steps, timer);
        // A build of some windows lists what it wrote for the filter, as updates do.
        if rebuild & all == all {
            self.built.store(true, std::sync::atomic::Ordering::Relaxed);
        }
    }

    /// Records an update by the dynamic fragments (those past the build's): undo the
    /// previous update, then merge these into the static build.
    fn update(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        fragments: &Fragments,
        timer: &mut GpuTimer,
    ) {
        let bind = self
            .fragment_bind
            .get(fragments, || self.build_bind_group(device, fragments));
        copy_fragment_count(encoder, fragments, &self.counters);
        let u = &self.pipelines.update;
        let steps = [
            (&u.begin, Run::Prepare),
            (&u.restore, Run::Indirect(24)),
            (&u.free, Run::One),
            (&u.allocate, Run::Indirect(12)),
            (&u.accumulate, Run::Indirect(12)),
            (&u.prepare, Run::Prepare),
            (&u.resolve, Run::Indirect(24)),
        ];
        self.run_steps(encoder, "dense_update", &bind, &steps, timer);
    }

    /// Records `steps` of dense_build or dense_update, one compute pass each: each step reads
    /// what the one before wrote (dispatch sizes, slots). Timed as `label`.
    fn run_steps(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        label: &'static str,
        bind: &wgpu::BindGroup,
        steps: &[(&wgpu::ComputePipeline, Run)],
        timer: &mut GpuTimer,
    ) {
        let args = &self.args_bind;
        for (pipeline, run) in steps {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some(label),
                timestamp_writes: timer.compute(label),
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, bind, &[]);
            match run {
                Run::Prepare => {
                    pass.set_bind_group(1, args, &[]);
                    pass.dispatch_workgroups(1, 1, 1);
                }
                Run::One => pass.dispatch_workgroups(1, 1, 1),
                Run::Over(n) => {
                    let (x, y) = layout::groups_2d(*n, 64);
                    pass.dispatch_workgroups(x, y, 1);
                }
                Run::Indirect(offset) => pass.dispatch_workgroups_indirect(&self.args, *offset),
            }
        }
    }

    fn build_bind_group(&self, device: &wgpu::Device, fragments: &Fragments) -> wgpu::BindGroup {
        let v = |t: &wgpu::Texture| t.create_view(&Default::default());
        let (a, n, e, r) = (
            v(&self.albedo),
            v(&self.normal),
            v(&self.emission),
            v(&self.radiance),
        );
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("dense_build"),
            layout: &self.pipelines.build_layout,
            entries: &layout::entries(vec![
                self.volume.as_entire_binding(),
                fragments.buffer.as_entire_binding(),
                self.counters.as_entire_binding(),
                self.occupancy.as_entire_binding(),
                self.slot_voxel.as_entire_binding(),
                self.accum.as_entire_binding(),
                wgpu::BindingResource::TextureView(&a),
                wgpu::BindingResource::TextureView(&n),
                wgpu::BindingResource::TextureView(&e),
                wgpu::BindingResource::TextureView(&r),
                self.dyn_accum.as_entire_binding(),
                self.kept.as_entire_binding(),
            ]),
        })
    }
}

/// Records the copy of the fragments' count into `counters`' `FRAGMENTS_WORD`, where the build
/// and update steps read it.
fn copy_fragment_count(encoder: &mut wgpu::CommandEncoder, f: &Fragments, counters: &wgpu::Buffer) {
    encoder.copy_buffer_to_buffer(&f.count, 0, counters, FRAGMENTS_WORD * 4, 4);
}

fn build_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let c = wgpu::ShaderStages::COMPUTE;
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("dense_build"),
        entries: &[
            layout::uniform(0, c, false),
            layout::storage(1, c, true),
            layout::storage(2, c, false),
            layout::storage(3, c, false),
            layout::storage(4, c, false),
            layout::storage(5, c, false),
            layout::storage_texture_3d(6, ALBEDO_FORMAT),
            layout::storage_texture_3d(7, NORMAL_FORMAT),
            layout::storage_texture_3d(8, EMISSION_FORMAT),
            layout::storage_texture_3d(9, RADIANCE_FORMAT),
            layout::storage(10, c, false),
            layout::storage(11, c, false),
        ],
    })
}

impl VoxelStructure for DenseVolume {
    fn kind(&self) -> crate::voxel::VoxelKind {
        crate::voxel::VoxelKind::DENSE
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }

    fn grid(&self) -> Grid {
        self.grid
    }

    fn bind_fragments(&mut self, device: &wgpu::Device, fragments: &Fragments) {
        let bind = self.build_bind_group(device, fragments);
        self.fragment_bind.set(fragments, bind);
    }

    fn record_build(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        fragments: &Fragments,
        timer: &mut GpuTimer,
    ) {
        self.build_windows(device, encoder, fragments, self.every_window(), None, timer);
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
        // Recorded in the order the GPU runs it: the build this flag saw comes first.
        let all = self.built.swap(false, std::sync::atomic::Ordering::Relaxed);
        self.pipelines
            .filter
            .record(encoder, &self.filter_binds, all, timer);
    }

    fn pool_counter(&self) -> &wgpu::Buffer {
        // Word 0 counts the slots; the dense volume's other counters are not pools.
        &self.counters
    }

    fn leaf_capacity(&self) -> u64 {
        self.slot_capacity as u64
    }

    fn leaf_limit(&self, device: &wgpu::Device) -> u64 {
        slot_limit(device, &self.grid, self.windows)
    }

    fn needs_growth(&self, counted: &[u32; POOL_COUNTERS]) -> bool {
        // Word 1: the most a window asked for.
        counted[1] > self.window_slots
    }

    fn grow(&mut self, device: &wgpu::Device, counted: &[u32; POOL_COUNTERS]) -> crate::Result<()> {
        let wanted = counted[1] as u64 * self.windows as u64;
        let slots = crate::gpu::pool_capacity(device, wanted, SLOT_BYTES, "occupied voxels")?;
        self.resize(device, slots)
    }

    /// Far above the count (a first guess at the device's limit, which a scene whose estimate
    /// passes it gets: a town's held ten times what it needed), to half as much again as the
    /// count, so that later builds' counts (a moved window, moved objects) still fit.
    fn shrink(
        &mut self,
        device: &wgpu::Device,
        counted: &[u32; POOL_COUNTERS],
    ) -> crate::Result<bool> {
        // Per window: each part holds the most any window asked for.
        let count = (counted[1] as u64).max(1024);
        if (self.window_slots as u64) <= SHRINK_BELOW * count {
            return Ok(false);
        }
        let wanted = count * 3 / 2 * self.windows as u64;
        let slots = crate::gpu::pool_capacity(device, wanted, SLOT_BYTES, "occupied voxels")?;
        self.resize(device, slots)?;
        Ok(true)
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
            leaf_irradiance: &self.slot_irradiance,
            // The build's prepare_slots writes one thread per slot at offset 0.
            leaf_dispatch: (&self.args, 0),
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
        self.pipelines.debug.record(
            device,
            encoder,
            targets,
            self,
            (&self.volume, 0),
            view.mode,
            view.level,
            view.direction,
            timer,
        );
    }
}
