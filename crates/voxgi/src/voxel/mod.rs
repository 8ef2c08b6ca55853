//! Voxels: the voxel structures built from fragments.
//!
//! A structure is anything cone tracing can sample (DESIGN.md, seam 2). In Rust it implements
//! `VoxelStructure`; in WGSL it provides `shaders/voxels/<kind>/sample.wgsl`, the contract of
//! names cone tracing uses (`shaders/shared/cone.wgsl`), reading only its own `@group(1)`.
//! Three structures: the dense mip-mapped volume (`dense/`), the sparse voxel octree
//! (`octree/`) and clipmap cascades that follow the camera (`clipmap/`, built on the dense
//! volume's windows); `RendererOptions::voxels` picks one.

pub mod clipmap;
pub mod cpu;
pub mod dense;
pub mod octree;
pub mod registry;

pub use crate::fragments::{Grid, Region};
pub use registry::{KindInfo, StructureDesc, VoxelKind};

use crate::fragments::Fragments;
use crate::frame::targets::FrameTargets;
use crate::gpu::timer::GpuTimer;
use crate::{Error, Result};
use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use voxgi_scene::Aabb;

/// What a voxel debug view shows of the first voxel along each pixel's ray with opacity > 0.5
/// at its level (`ViewMode::voxel_view`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VoxelView {
    /// Its albedo (the finest level's under it).
    Albedo,
    /// Its opacity, as grey.
    Opacity,
    /// Its radiance, un-premultiplied.
    Radiance,
    /// The structure's occupied cells of the level, coloured by level, edges darkened.
    Nodes,
}

impl VoxelView {
    /// The id the debug shaders take (`mode` in voxels/<kind>/debug.wgsl).
    pub fn id(self) -> u32 {
        match self {
            VoxelView::Albedo => 0,
            VoxelView::Opacity => 1,
            VoxelView::Radiance => 2,
            VoxelView::Nodes => 3,
        }
    }
}

/// What a voxel debug view shows: `mode` at mip `level` (0 = finest), along directional chain
/// `direction` (0..6: +X, -X, +Y, -Y, +Z, -Z) where there are chains.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DebugView {
    /// Which voxel property to show.
    pub mode: VoxelView,
    /// Mip level to show, 0 = finest.
    pub level: u32,
    /// Directional chain to show, 0..6 for +X, -X, +Y, -Y, +Z, -Z (ignored where there are no
    /// chains).
    pub direction: u32,
}

/// A voxel structure: built from fragments and nothing else, holding the radiance of its
/// leaves, filtered into coarser levels, sampled by cone tracing through `sampling()` at
/// `@group(1)` of every pipeline that traces cones.
pub trait VoxelStructure: wgpu::WasmNotSendSync {
    /// The per-frame step, asked every frame before any voxel pass: sees the camera and what
    /// changed, and says which regions of its grid it needs voxelized this frame. The default
    /// is the dense volume's and the octree's answer: everything on a rebuild, then the box
    /// of the dynamic instances whenever they moved (a camera-following structure answers
    /// with the slabs newly inside it).
    fn plan(&mut self, changes: &FrameChanges) -> VoxelWork {
        let grid = self.grid();
        VoxelWork {
            build: changes.rebuild.then(|| vec![Region::all(&grid)]),
            update: changes.dynamic.map(|b| vec![dynamic_region(&grid, b)]),
            partial: false,
        }
    }

    /// Records what the lighting passes read of `plan`'s choices before a voxel update's
    /// passes (a camera-following structure: where its windows are now, which it rebuilt
    /// alone). The default, for a structure whose placement never changes, is nothing.
    fn record_plan(&self, device: &wgpu::Device, encoder: &mut wgpu::CommandEncoder) {
        let _ = (device, encoder);
    }

    /// The grids its fragments lie on, the finest voxels: its own grid, or a camera-following
    /// structure's windows (as `plan` last placed them), whose fragments are stacked along z
    /// (window k's at z + k · resolution). Their number never changes.
    fn fragment_grids(&self) -> Vec<Grid> {
        vec![self.grid()]
    }
    /// The structure's kind (its name is also its WGSL folder: `shaders/voxels/<kind>/`).
    fn kind(&self) -> VoxelKind;
    /// The structure itself, for code that knows its kind (its own tests, its `create`
    /// taking over a previous structure's pipelines).
    fn as_any(&self) -> &dyn std::any::Any;
    /// The grid of its finest voxels (the fragments' grid).
    fn grid(&self) -> Grid;
    /// The finest voxel edge it holds about `p` (the CPU side of `voxels_voxel_size_at`):
    /// its grid's, unless its voxels coarsen away from the camera.
    fn voxel_size_at(&self, p: Vec3) -> f32 {
        let _ = p;
        self.grid().voxel_size
    }
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
    /// Makes the bind groups of its build and update over `fragments`, which the renderer
    /// hands it whenever the fragments or the structure are made anew; `record_build` and
    /// `record_update` given other fragments make theirs on the spot.
    fn bind_fragments(&mut self, device: &wgpu::Device, fragments: &Fragments);
    /// Records the filtering of the leaves' radiance into every coarser level.
    fn record_filter(&self, encoder: &mut wgpu::CommandEncoder, timer: &mut GpuTimer);
    /// A buffer whose first `POOL_COUNTERS` u32 count what the last build asked of each of the
    /// structure's pools, past their capacity (read back asynchronously to grow them). Word 0
    /// is always the leaves (occupied finest voxels); the others are the structure's own (zero
    /// where it has fewer pools).
    fn pool_counter(&self) -> &wgpu::Buffer;
    /// Leaves the pools hold.
    fn leaf_capacity(&self) -> u64;
    /// The most leaves its pools can hold on `device` (its storage-buffer limit).
    fn leaf_limit(&self, device: &wgpu::Device) -> u64;
    /// The occupied finest voxels among what a build counted (`pool_counter`'s words): the
    /// leaves, unless the structure holds some voxels twice.
    fn occupied(&self, counted: &[u32; POOL_COUNTERS]) -> u64 {
        counted[0] as u64
    }
    /// Whether a build that counted `counted` (`pool_counter`'s words) overflowed a pool.
    fn needs_growth(&self, counted: &[u32; POOL_COUNTERS]) -> bool;
    /// Makes room for what a build counted; the contents are lost (the next build refills
    /// them). On an error (out of memory, a device limit) the structure is left as it was.
    fn grow(&mut self, device: &wgpu::Device, counted: &[u32; POOL_COUNTERS]) -> crate::Result<()>;
    /// Gives back room far beyond what a build counted (`counted`, `pool_counter`'s words),
    /// keeping some headroom; whether it did (the contents are then lost). Asked only after
    /// the counting build before the first frame, whose first guess may be the device's limit;
    /// a structure whose pools follow their counts on their own (`needs_growth`) keeps the
    /// default, which does nothing.
    fn shrink(
        &mut self,
        device: &wgpu::Device,
        counted: &[u32; POOL_COUNTERS],
    ) -> crate::Result<bool> {
        let _ = (device, counted);
        Ok(false)
    }
    /// Bytes per GPU resource.
    fn memory(&self) -> Vec<(&'static str, u64)>;
    /// What the passes bind of the structure: its sampling group, its leaves, their radiance
    /// store, the irradiance lookup, the leaves' records and the leaves' dispatch size.
    fn bindings(&self) -> StructureBindings<'_>;
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

/// What changed since the structure's last update, as its per-frame step sees it.
#[derive(Clone, Copy, Debug)]
pub struct FrameChanges {
    /// The camera's position this frame.
    pub camera: Vec3,
    /// Everything is out of date (the first frame, `invalidate`, grown pools, new options).
    pub rebuild: bool,
    /// Dynamic geometry is to be voxelized again: where every dynamic instance is now (world
    /// space). `None` when nothing moved or the scene has no dynamic instances.
    pub dynamic: Option<Aabb>,
    /// Where every dynamic instance is now, moved or not (for a structure that rebuilds on
    /// its own, and must merge them again). `None` without dynamic instances.
    pub dynamic_now: Option<Aabb>,
    /// Windows a camera-following structure may rebuild this frame, at most
    /// (`RendererOptions::clipmap_budget`; 0: no limit).
    pub budget: u32,
}

/// The regions a structure needs voxelized this frame (`VoxelStructure::plan`), one per grid
/// of `VoxelStructure::fragment_grids` (a grid without one makes no fragments).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct VoxelWork {
    /// Build from the static geometry and the points in these regions (`record_build`).
    pub build: Option<Vec<Region>>,
    /// Merge the dynamic geometry in these regions (`record_update`; it runs even when they
    /// are empty, to take out the last update).
    pub update: Option<Vec<Region>>,
    /// The build rebuilds only the grids whose region is not empty, and the other grids'
    /// leaves keep their slots and light (a camera-following structure's windows that moved):
    /// for the lighting passes not a rebuild, only the rebuilt grids' leaves are new
    /// (`leaf_is_new`).
    pub partial: bool,
}

/// Where the dynamic geometry inside world box `b` makes fragments on `grid`. Two voxels of
/// margin: a dynamic fragment's voxel holds a vertex, or lies one voxel behind one (the
/// solid's inner voxel), and the GPU's transform of a vertex may round across a voxel face
/// the CPU's box does not.
pub fn dynamic_region(grid: &Grid, b: Aabb) -> Region {
    Region::around(grid, b.min, b.max, 2)
}

impl VoxelWork {
    /// Whether there is nothing to voxelize.
    pub fn is_empty(&self) -> bool {
        self.build.is_none() && self.update.is_none()
    }
}

/// The registry: every kind voxgi has, in the order settings list them, with names for the two
/// that code names.
impl VoxelKind {
    /// The dense mip-mapped volume: every voxel stored, fastest to sample and to update.
    pub const DENSE: VoxelKind = VoxelKind::new(&dense::KIND);
    /// The sparse voxel octree: memory in proportion to the occupied voxels.
    pub const OCTREE: VoxelKind = VoxelKind::new(&octree::KIND);
    /// Clipmap cascades: levels that follow the camera, for large worlds.
    pub const CLIPMAP: VoxelKind = VoxelKind::new(&clipmap::KIND);

    /// Every kind, in the order settings list them. A new kind is one entry here.
    pub const ALL: &'static [VoxelKind] =
        &[VoxelKind::DENSE, VoxelKind::OCTREE, VoxelKind::CLIPMAP];

    /// Every kind's name, in the registry's order.
    pub fn names() -> Vec<&'static str> {
        Self::ALL.iter().map(|k| k.name()).collect()
    }

    /// The kind named `s`.
    pub fn parse(s: &str) -> Result<Self> {
        Self::ALL
            .iter()
            .copied()
            .find(|k| k.name() == s)
            .ok_or_else(|| {
                Error::Setting(format!(
                    "voxel structure '{s}' is not one of {}",
                    Self::names().join(", ")
                ))
            })
    }
}

impl Default for VoxelKind {
    fn default() -> Self {
        VoxelKind::DENSE
    }
}

/// The timing scopes of the voxel update (what depends on the scene and its lights, not on
/// the camera), in the order they run, with every kind's own passes; every other scope is the
/// screen's.
pub fn voxel_passes() -> Vec<&'static str> {
    let mut v = vec!["shadow", "moments", "voxelize", "splat"];
    let add = |v: &mut Vec<&'static str>, names: &[&'static str]| {
        // A kind built on another runs that one's passes: each scope once.
        v.extend(names.iter().filter(|n| !v.contains(n)).collect::<Vec<_>>());
    };
    for k in VoxelKind::ALL {
        add(&mut v, k.info().build_passes);
    }
    v.push("inject");
    for k in VoxelKind::ALL {
        add(&mut v, k.info().filter_passes);
    }
    v.push("bounce");
    v
}

/// The full WGSL of shader `name` with `voxels/` includes taken from the kind named `kind`
/// (for tests and tools that name kinds by string).
pub fn compose_for(name: &str, kind: &str) -> Result<String> {
    Ok(crate::gpu::shader::compose_with(
        name,
        Some(VoxelKind::parse(kind)?.shaders()),
    ))
}

/// What the passes bind of a structure (`VoxelStructure::bindings`), by owner: group 1 of
/// every pipeline that traces cones, and the groups of the lighting passes and the gather.
#[derive(Clone, Copy)]
pub struct StructureBindings<'a> {
    /// The WGSL contract's resources (`voxels/<kind>/sample.wgsl`), `@group(1)`.
    pub sampling: &'a wgpu::BindGroup,
    /// The leaves (`voxels/<kind>/leaves.wgsl`), `@group(2)` of the lighting passes: what each
    /// leaf is, and its direct and bounced light.
    pub leaves: &'a wgpu::BindGroup,
    /// The leaves' radiance for writing (`voxels/<kind>/leaf_store.wgsl`), `@group(3)`.
    pub leaf_store: &'a wgpu::BindGroup,
    /// The irradiance lookup (`voxels/<kind>/irradiance.wgsl`), `@group(3)` of the gather:
    /// the record of the leaf at a voxel coordinate.
    pub irradiance: &'a wgpu::BindGroup,
    /// What a new leaf's light may start from (`voxels/<kind>/carry.wgsl`), `@group(3)` of
    /// the bounce's `stash` and `mark`.
    pub carry: &'a wgpu::BindGroup,
    /// Per leaf slot, what the last bounce kept for the fast shading
    /// (`IndirectShading::Leaves`): a `vec4<u32>` record of irradiance, occlusion and normal
    /// (shaders/lighting/bounce.wgsl).
    pub leaf_irradiance: &'a wgpu::Buffer,
    /// An indirect dispatch of one 64-wide workgroup per 64 leaves (2D past 65535 groups:
    /// threads index leaves as `gid.x + gid.y * num_workgroups.x * 64`): the buffer and the
    /// byte offset.
    pub leaf_dispatch: (&'a wgpu::Buffer, u64),
}

/// A structure's bind group over one fragment buffer (`VoxelStructure::bind_fragments`), kept
/// with the buffer it binds so that it is used for those fragments only.
#[derive(Default)]
pub struct FragmentBind(Option<(wgpu::Buffer, wgpu::BindGroup)>);

impl FragmentBind {
    /// Keeps `bind`, made over `fragments`.
    pub fn set(&mut self, fragments: &Fragments, bind: wgpu::BindGroup) {
        self.0 = Some((fragments.buffer.clone(), bind));
    }

    /// The bind group over `fragments`: the kept one if it binds them, else `make`'s.
    pub fn get(
        &self,
        fragments: &Fragments,
        make: impl FnOnce() -> wgpu::BindGroup,
    ) -> wgpu::BindGroup {
        match &self.0 {
            Some((buffer, bind)) if *buffer == fragments.buffer => bind.clone(),
            _ => make(),
        }
    }
}

/// How a structure filters its levels above the finest.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Filtering {
    /// Six directional values per voxel above the finest level (true) or one.
    pub anisotropic: bool,
    /// The first directional level weighs each leaf per direction by its normal distribution
    /// (`RendererOptions::ndf_mips`; `cpu::ndf_weight`). Only with `anisotropic`.
    pub ndf: bool,
    /// Each leaf keeps a specular lobe beside its direct light, whose moments every level above
    /// the finest keeps in two more directional blocks (shared/specular_lobe.wgsl, "The lobe
    /// chain"; `RendererOptions::specular_bounces` in a scene with a metal). Only with
    /// `anisotropic`.
    pub lobes: bool,
}

impl Filtering {
    /// Blocks each level above the finest holds per voxel: six directions (one isotropic), and
    /// with `lobes` the lobe chain's two after them (shared/specular_lobe.wgsl).
    pub fn blocks(self) -> u32 {
        match (self.anisotropic, self.lobes) {
            (false, _) => 1,
            (true, false) => 6,
            (true, true) => 8,
        }
    }

    /// The most bytes a slot's direct light takes (`direct_bytes` with lobes).
    pub const MOST_DIRECT_BYTES: u64 = 32;

    /// Bytes a leaf slot's direct light takes in its structure's `leaf_direct` (voxels/<kind>/
    /// leaves.wgsl): its radiance and opacity (a vec4 f32), and with `lobes` its specular lobe
    /// after it (shared/specular_lobe.wgsl).
    pub fn direct_bytes(self) -> u64 {
        if self.lobes {
            Self::MOST_DIRECT_BYTES
        } else {
            16
        }
    }
}

/// Values for the `override` constants every structure's sample.wgsl declares, for the
/// pipelines that sample a structure of this mode: `anisotropic` (ISOTROPIC_ONLY: one block
/// read a sample), `lobes` (LOBE_CHAIN: the samples add the specular lobes' light) and `axes`, the
/// directional blocks a sample reads (SAMPLE_AXES).
pub fn sampling_constants(anisotropic: bool, lobes: bool, axes: u32) -> Vec<(&'static str, f64)> {
    vec![
        ("ISOTROPIC_ONLY", if anisotropic { 0.0 } else { 1.0 }),
        ("SAMPLE_AXES", f64::from(axes)),
        ("LOBE_CHAIN", if anisotropic && lobes { 1.0 } else { 0.0 }),
    ]
}

/// Words of `VoxelStructure::pool_counter` read back after each build (the octree's sixth: the
/// slots of its static build, `octree::STATIC_COUNTED`).
pub const POOL_COUNTERS: usize = 6;

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
    /// Cubes of `resolution` voxels stacked along z in every texture and buffer: 1, or a
    /// clipmap's levels.
    pub windows: u32,
}

/// Bytes of a 3D texture with `mips` levels.
pub fn texture_bytes(res: u32, bytes_per_texel: u64, mips: u32) -> u64 {
    (0..mips)
        .map(|m| ((res >> m).max(1) as u64).pow(3) * bytes_per_texel)
        .sum()
}
