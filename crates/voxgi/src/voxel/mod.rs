//! Voxels: the voxel structures built from fragments.
//!
//! A structure is anything cone tracing can sample (DESIGN.md, seam 2). In Rust it implements
//! `VoxelStructure`; in WGSL it provides `shaders/voxels/<kind>/sample.wgsl`, the contract of
//! names cone tracing uses (`shaders/shared/cone.wgsl`), reading only its own `@group(1)`.
//! Two structures: the dense mip-mapped volume (`dense/`) and the sparse voxel octree
//! (`octree/`); `RendererOptions::voxels` picks one.

pub mod cpu;
pub mod dense;
pub mod factory;
pub mod octree;

pub use crate::fragments::Grid;
pub use crate::options::VoxelKind;

use crate::fragments::Fragments;
use crate::frame::targets::FrameTargets;
use crate::gpu::timer::GpuTimer;
use crate::options::ViewMode;
use bytemuck::{Pod, Zeroable};

/// What a voxel debug view shows: one of the voxel `ViewMode`s, at mip `level` (0 = finest),
/// along directional chain `direction` (0..6: +X, -X, +Y, -Y, +Z, -Z) where there are chains.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DebugView {
    /// Which voxel property to show (`ViewMode::is_voxel` holds).
    pub mode: ViewMode,
    /// Mip level to show, 0 = finest.
    pub level: u32,
    /// Directional chain to show, 0..6 for +X, -X, +Y, -Y, +Z, -Z (ignored where there are no
    /// chains).
    pub direction: u32,
}

/// A voxel structure: built from fragments and nothing else, holding the radiance of its
/// leaves, filtered into coarser levels, sampled by cone tracing through `sampling()` at
/// `@group(1)` of every pipeline that traces cones.
pub trait VoxelStructure {
    /// The structure's name, also its WGSL folder: `shaders/voxels/<kind>/`.
    fn kind(&self) -> &'static str;
    /// The grid of its finest voxels (the fragments' grid).
    fn grid(&self) -> Grid;
    /// Records a build from `fragments` (the static geometry's), replacing the previous one:
    /// leaves get albedo, normal, emission and opacity; their radiance is cleared.
    fn record_build(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        fragments: &Fragments,
        timer: &mut GpuTimer,
    );
    /// Records an update by the dynamic geometry's fragments (those past `Fragments::mark`):
    /// what the previous update added is taken out (leaves it made vanish, static leaves it
    /// shared get their static values back), then these fragments are merged in, so that the
    /// structure equals a build of static and dynamic fragments together. Leaves' radiance is
    /// left for the lighting passes to rewrite.
    fn record_update(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        fragments: &Fragments,
        timer: &mut GpuTimer,
    );
    /// Records the filtering of the leaves' radiance into every coarser level.
    fn record_filter(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
    );
    /// A buffer whose first `POOL_COUNTERS` u32 count what the last build asked of each of the
    /// structure's pools, past their capacity (read back asynchronously to grow them). Word 0
    /// is always the leaves (occupied finest voxels); the others are the structure's own (zero
    /// where it has fewer pools).
    fn pool_counter(&self) -> &wgpu::Buffer;
    /// Leaves the pools hold.
    fn leaf_capacity(&self) -> u64;
    /// Whether a build that counted `counted` (`pool_counter`'s words) overflowed a pool.
    fn needs_growth(&self, counted: &[u32; POOL_COUNTERS]) -> bool;
    /// Makes room for what a build counted; the contents are lost (the next build refills
    /// them). On an error (out of memory, a device limit) the structure is left as it was.
    fn grow(&mut self, device: &wgpu::Device, counted: &[u32; POOL_COUNTERS]) -> crate::Result<()>;
    /// Bytes per GPU resource.
    fn memory(&self) -> Vec<(&'static str, u64)>;
    /// The bind group of the WGSL contract's resources, `@group(1)`.
    fn sampling(&self) -> &wgpu::BindGroup;
    /// The leaves' bind group (`voxels/<kind>/leaves.wgsl`), `@group(2)` of the lighting
    /// passes: what each leaf is, and its direct and bounced light.
    fn leaves(&self) -> &wgpu::BindGroup;
    /// The leaves' radiance for writing (`voxels/<kind>/leaf_store.wgsl`), `@group(3)`.
    fn leaf_store(&self) -> &wgpu::BindGroup;
    /// Per leaf slot, what the last bounce kept for the fast shading (`IndirectShading::Leaves`):
    /// a `vec4<u32>` record of irradiance, occlusion and normal (shaders/lighting/bounce.wgsl).
    fn leaf_irradiance(&self) -> &wgpu::Buffer;
    /// The bind group of `voxels/<kind>/irradiance.wgsl`, `@group(3)` of the gather: the
    /// record of the leaf at a voxel coordinate.
    fn irradiance(&self) -> &wgpu::BindGroup;
    /// An indirect dispatch of one 64-wide workgroup per 64 leaves (2D past 65535 groups:
    /// threads index leaves as `gid.x + gid.y * num_workgroups.x * 64`).
    fn leaf_dispatch(&self) -> (&wgpu::Buffer, u64);
    /// Records a debug view into the HDR target, replacing the lit image.
    fn record_debug(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        targets: &FrameTargets,
        view: DebugView,
        timer: &mut GpuTimer,
    );
}

/// How a structure filters its levels above the finest.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Filtering {
    /// Six directional values per voxel above the finest level (true) or one.
    pub anisotropic: bool,
    /// The first directional level weighs each leaf per direction by its normal distribution
    /// (`RendererOptions::ndf_mips`; `cpu::ndf_weight`). Only with `anisotropic`.
    pub ndf: bool,
}

/// Words of `VoxelStructure::pool_counter` read back after each build.
pub const POOL_COUNTERS: usize = 4;

impl VoxelKind {
    /// The layout of @group(1), the structure's sampling resources.
    pub fn sampling_layout(self, device: &wgpu::Device) -> wgpu::BindGroupLayout {
        match self {
            VoxelKind::Dense => dense::DenseVolume::sampling_layout(device),
            VoxelKind::Octree => octree::OctreeVolume::sampling_layout(device),
        }
    }

    /// The layout of @group(2) of the lighting passes, the structure's leaves.
    pub fn leaves_layout(self, device: &wgpu::Device) -> wgpu::BindGroupLayout {
        match self {
            VoxelKind::Dense => dense::DenseVolume::leaves_layout(device),
            VoxelKind::Octree => octree::OctreeVolume::leaves_layout(device),
        }
    }

    /// The layout of @group(3) of the passes that store leaf radiance.
    pub fn leaf_store_layout(self, device: &wgpu::Device) -> wgpu::BindGroupLayout {
        match self {
            VoxelKind::Dense => dense::DenseVolume::leaf_store_layout(device),
            VoxelKind::Octree => octree::OctreeVolume::leaf_store_layout(device),
        }
    }

    /// The layout of @group(3) of the gather, the structure's irradiance lookup.
    pub fn irradiance_layout(self, device: &wgpu::Device) -> wgpu::BindGroupLayout {
        match self {
            VoxelKind::Dense => dense::DenseVolume::irradiance_layout(device),
            VoxelKind::Octree => octree::OctreeVolume::irradiance_layout(device),
        }
    }

    /// Values for the `override` constants of the structure's sample.wgsl.
    pub fn sampling_constants(self, anisotropic: bool, axes: u32) -> [(&'static str, f64); 2] {
        match self {
            VoxelKind::Dense => dense::DenseVolume::sampling_constants(anisotropic, axes),
            VoxelKind::Octree => octree::OctreeVolume::sampling_constants(anisotropic, axes),
        }
    }
}

/// The renderer's voxel structure, whichever kind it is.
pub enum Voxels {
    /// The dense volume.
    Dense(dense::DenseVolume),
    /// The sparse voxel octree.
    Octree(octree::OctreeVolume),
}

impl Voxels {
    /// The structure, for the passes (which know it only through the trait).
    pub fn get(&self) -> &dyn VoxelStructure {
        match self {
            Voxels::Dense(v) => v,
            Voxels::Octree(v) => v,
        }
    }

    /// The structure, mutably (to grow it).
    pub fn get_mut(&mut self) -> &mut dyn VoxelStructure {
        match self {
            Voxels::Dense(v) => v,
            Voxels::Octree(v) => v,
        }
    }

    /// The dense volume, if that is the kind.
    pub fn dense(&self) -> Option<&dense::DenseVolume> {
        match self {
            Voxels::Dense(v) => Some(v),
            Voxels::Octree(_) => None,
        }
    }

    /// The octree, if that is the kind.
    pub fn octree(&self) -> Option<&octree::OctreeVolume> {
        match self {
            Voxels::Octree(v) => Some(v),
            Voxels::Dense(_) => None,
        }
    }
}

/// Mirrors `Volume` in shaders/shared/volume.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuVolume {
    /// World position of the volume's minimum corner, metres.
    pub origin: [f32; 3],
    /// Voxels per side at the finest level.
    pub resolution: u32,
    /// Edge length of a finest voxel, metres.
    pub voxel_size: f32,
    /// Mip levels including the finest.
    pub levels: u32,
    /// 1: six directional values per voxel above the finest level, 0: one.
    pub anisotropic: u32,
    /// Padding to 32 bytes; zero.
    pub _pad: u32,
}

/// Bytes of a 3D texture with `mips` levels.
pub fn texture_bytes(res: u32, bytes_per_texel: u64, mips: u32) -> u64 {
    (0..mips)
        .map(|m| ((res >> m).max(1) as u64).pow(3) * bytes_per_texel)
        .sum()
}
