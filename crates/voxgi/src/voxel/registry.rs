//! What a kind of voxel structure declares of itself (`KindInfo`: name, limits, timing
//! scopes, WGSL files, layouts, sampling constants, creation), and `VoxelKind`, a handle to
//! one. Everything the renderer, the command line, the viewer and the tests know about a kind
//! comes from here. The registry itself, `VoxelKind::ALL`, is in `voxel/mod.rs`, beside the
//! kinds' modules: a new kind is a folder under `voxel/` and `shaders/voxels/` that defines a
//! `KindInfo`, plus its `mod` line and one entry in `VoxelKind::ALL`.

use super::{Filtering, Grid, VoxelStructure};
use crate::Result;
use crate::gpu::shader::StructureShaders;

/// What a structure is made from: where it lies and how it filters, the room its pools start
/// with, and whether dynamic geometry will be merged into it.
#[derive(Clone, Copy, Debug)]
pub struct StructureDesc {
    /// The grid of its finest voxels (the fragments' grid).
    pub grid: Grid,
    /// The scene's bounds, which `grid` is around (a camera-following structure keeps its
    /// windows within them).
    pub bounds: voxgi_scene::Aabb,
    /// How it filters its levels.
    pub filtering: Filtering,
    /// Occupied voxels its pools start with room for (they grow when a build counts more).
    pub leaves: u64,
    /// Whether the scene has dynamic instances (their updates need the static build kept).
    pub dynamic: bool,
    /// A camera-following structure's levels (`RendererOptions::clipmap_levels`).
    pub levels: u32,
    /// A camera-following structure's finest voxel edge, metres (`None`: its own choice).
    pub voxel_size: Option<f32>,
}

/// A kind of voxel structure, as its own module declares it.
pub struct KindInfo {
    /// The name scene files, the command line and the viewer use; also its folders
    /// `src/voxel/<name>/` and `shaders/voxels/<name>/`.
    pub name: &'static str,
    /// One line for help texts and the viewer.
    pub summary: &'static str,
    /// The largest voxel resolution it takes (a power of two).
    pub max_resolution: u32,
    /// Timing scopes of its own passes that build and update it from fragments, in the order
    /// they run (they run before inject).
    pub build_passes: &'static [&'static str],
    /// Timing scopes of its own passes that filter its levels (after inject and each bounce).
    pub filter_passes: &'static [&'static str],
    /// Its WGSL files.
    pub shaders: StructureShaders,
    /// The layout of `@group(1)`, its sampling resources (`VoxelStructure::sampling`).
    pub sampling_layout: fn(&wgpu::Device) -> wgpu::BindGroupLayout,
    /// The layout of `@group(2)` of the lighting passes, its leaves.
    pub leaves_layout: fn(&wgpu::Device) -> wgpu::BindGroupLayout,
    /// The layout of `@group(3)` of the passes that store leaf radiance.
    pub leaf_store_layout: fn(&wgpu::Device) -> wgpu::BindGroupLayout,
    /// The layout of `@group(3)` of the gather, its irradiance lookup.
    pub irradiance_layout: fn(&wgpu::Device) -> wgpu::BindGroupLayout,
    /// The layout of `@group(3)` of the bounce's `stash` and `mark`, what its carry.wgsl reads
    /// (where a new leaf's light may start from).
    pub carry_layout: fn(&wgpu::Device) -> wgpu::BindGroupLayout,
    /// Values for the `override` constants of its sample.wgsl: (anisotropic, specular lobes,
    /// gather axes).
    pub sampling_constants: fn(bool, bool, u32) -> Vec<(&'static str, f64)>,
    /// Makes one. `previous`, the structure it replaces (of any kind), lends its pipelines
    /// when it is of this kind. Errors name what does not fit the device.
    pub create: CreateFn,
}

/// `KindInfo::create`.
pub type CreateFn = fn(
    &wgpu::Device,
    &StructureDesc,
    Option<&dyn VoxelStructure>,
) -> Result<Box<dyn VoxelStructure>>;

/// Which voxel structure a renderer builds: a handle to a kind in the registry.
#[derive(Clone, Copy)]
pub struct VoxelKind(&'static KindInfo);

impl VoxelKind {
    /// A kind from its own declaration: how a kind outside the registry (an application's
    /// own structure, a test's stand-in) is handed to `RendererOptions::voxels`. Settings and
    /// the command line know only the registry's kinds.
    pub const fn new(info: &'static KindInfo) -> Self {
        VoxelKind(info)
    }

    /// The name settings and the command line use, also the WGSL folder `shaders/voxels/<name>/`.
    pub fn name(self) -> &'static str {
        self.0.name
    }

    /// What the kind declares of itself.
    pub fn info(self) -> &'static KindInfo {
        self.0
    }

    /// The layout of @group(1), the structure's sampling resources.
    pub fn sampling_layout(self, device: &wgpu::Device) -> wgpu::BindGroupLayout {
        (self.0.sampling_layout)(device)
    }

    /// The layout of @group(2) of the lighting passes, the structure's leaves.
    pub fn leaves_layout(self, device: &wgpu::Device) -> wgpu::BindGroupLayout {
        (self.0.leaves_layout)(device)
    }

    /// The layout of @group(3) of the passes that store leaf radiance.
    pub fn leaf_store_layout(self, device: &wgpu::Device) -> wgpu::BindGroupLayout {
        (self.0.leaf_store_layout)(device)
    }

    /// The layout of @group(3) of the gather, the structure's irradiance lookup.
    pub fn irradiance_layout(self, device: &wgpu::Device) -> wgpu::BindGroupLayout {
        (self.0.irradiance_layout)(device)
    }

    /// The layout of @group(3) of the bounce's `stash` and `mark`, the structure's carry.
    pub fn carry_layout(self, device: &wgpu::Device) -> wgpu::BindGroupLayout {
        (self.0.carry_layout)(device)
    }

    /// Values for the `override` constants of the structure's sample.wgsl.
    pub fn sampling_constants(
        self,
        anisotropic: bool,
        lobes: bool,
        axes: u32,
    ) -> Vec<(&'static str, f64)> {
        (self.0.sampling_constants)(anisotropic, lobes, axes)
    }

    /// Its WGSL files, for the shader composer.
    pub fn shaders(self) -> &'static StructureShaders {
        &self.0.shaders
    }
}

impl PartialEq for VoxelKind {
    fn eq(&self, other: &Self) -> bool {
        self.name() == other.name()
    }
}

impl Eq for VoxelKind {}

impl std::fmt::Debug for VoxelKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}
