//! Voxels: where the volume sits, the cone sets, and the voxel structures built from fragments.
//!
//! A structure is anything cone tracing can sample (DESIGN.md, seam 2). In Rust it implements
//! `VoxelStructure`; in WGSL it provides `shaders/voxels/<kind>/sample.wgsl`, the contract of
//! names cone tracing uses (`shaders/shared/cone.wgsl`), reading only its own `@group(1)`.
//! Two structures: the dense mip-mapped volume (`dense/`) and the sparse voxel octree
//! (`octree/`); `RendererOptions::voxels` picks one.

pub mod cpu;
pub mod dense;
pub mod octree;

use crate::fragments::Fragments;
use crate::gpu::timer::GpuTimer;
use crate::options::ViewMode;
use crate::targets::FrameTargets;
use bytemuck::{Pod, Zeroable};
use glam::Vec3;

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

/// Which voxel structure a renderer builds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum VoxelKind {
    /// The dense mip-mapped volume: every voxel stored, fastest to sample and to update.
    #[default]
    Dense,
    /// The sparse voxel octree: memory in proportion to the occupied voxels.
    Octree,
}

impl VoxelKind {
    /// Both, in the order of their names.
    pub const ALL: [VoxelKind; 2] = [VoxelKind::Dense, VoxelKind::Octree];

    /// The name settings and the command line use, also the WGSL folder `shaders/voxels/<name>/`.
    pub fn name(self) -> &'static str {
        match self {
            VoxelKind::Dense => "dense",
            VoxelKind::Octree => "octree",
        }
    }

    /// The structure named `s`.
    pub fn parse(s: &str) -> crate::Result<Self> {
        Self::ALL
            .into_iter()
            .find(|k| k.name() == s)
            .ok_or_else(|| {
                crate::Error::Setting(format!("voxel structure '{s}' is not dense or octree"))
            })
    }

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

/// Mirrors `Cones` in shaders/shared/volume.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuCones {
    /// Per cone: tangent-space axis (xyz, z = normal) and weight (w; the cone's share of the
    /// cosine-weighted hemisphere, summing to 1 over the cones). Entries past `count` are zero.
    pub dirs: [[f32; 4]; 16],
    /// Number of cones used in `dirs` (at most 16).
    pub count: u32,
    /// Tangent of the diffuse cones' half-angle.
    pub diffuse_tan: f32,
    /// Sample step as a fraction of the cone diameter.
    pub step_factor: f32,
    /// Cones stop after this distance, metres.
    pub max_distance: f32,
    /// Ambient occlusion falloff lambda in 1/(1 + lambda r), per metre.
    pub ao_lambda: f32,
    /// Ambient occlusion rays stop at this distance, metres.
    pub ao_radius: f32,
    /// Offset of the cone origin along the normal, in finest voxels.
    pub origin_offset: f32,
    /// 1: the per-pixel gather adds indirect light, 0: it does not (bounces = 0).
    pub indirect: u32,
}

/// A cubic grid over the scene: `resolution` voxels per side from `origin`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    /// World position of the grid's minimum corner, metres.
    pub origin: Vec3,
    /// Edge length of a voxel, metres.
    pub voxel_size: f32,
    /// Voxels per side (a power of two).
    pub resolution: u32,
}

impl Grid {
    /// The cube around the scene bounds with one empty voxel of margin on every side, so walls
    /// on the bounds (the Cornell box's) lie inside the volume, not on its edge.
    pub fn around(min: Vec3, max: Vec3, resolution: u32) -> Self {
        let (min, max) = if min.x > max.x {
            (Vec3::splat(-0.5), Vec3::splat(0.5))
        } else {
            (min, max)
        };
        let extent = (max - min).max_element().max(1e-3);
        let side = extent * resolution as f32 / (resolution as f32 - 2.0);
        let center = (min + max) * 0.5;
        Grid {
            origin: center - Vec3::splat(side * 0.5),
            voxel_size: side / resolution as f32,
            resolution,
        }
    }

    /// Edge length of the whole grid, metres.
    pub fn extent(&self) -> f32 {
        self.voxel_size * self.resolution as f32
    }

    /// Mip levels including the finest (down to 1 voxel).
    pub fn levels(&self) -> u32 {
        self.resolution.ilog2() + 1
    }
}

/// A set of diffuse cones around the normal.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ConeSet {
    /// Six cones of 60° aperture: one along the normal, five tilted 60° (Crassin et al.).
    #[default]
    Six60,
    /// Seven cones of 45°: one along the normal, six tilted 45° (the 3D-texture paper).
    Seven45,
    /// Nine cones of 45°: one along the normal, eight tilted 50°.
    Nine45,
}

impl ConeSet {
    /// The set's name as settings and the command line spell it: "6x60", "7x45" or "9x45".
    pub fn name(&self) -> &'static str {
        match self {
            ConeSet::Six60 => "6x60",
            ConeSet::Seven45 => "7x45",
            ConeSet::Nine45 => "9x45",
        }
    }

    /// The set named `s` (as `name` spells it), or `None`.
    pub fn parse(s: &str) -> Option<Self> {
        [ConeSet::Six60, ConeSet::Seven45, ConeSet::Nine45]
            .into_iter()
            .find(|c| c.name() == s)
    }

    /// Full aperture angle of each cone in radians.
    pub fn aperture(&self) -> f32 {
        match self {
            ConeSet::Six60 => 60f32.to_radians(),
            _ => 45f32.to_radians(),
        }
    }

    /// Tangent-space axes (z = normal).
    pub fn axes(&self) -> Vec<Vec3> {
        let (ring, tilt) = match self {
            ConeSet::Six60 => (5, 60f32),
            ConeSet::Seven45 => (6, 45f32),
            ConeSet::Nine45 => (8, 50f32),
        };
        let mut v = vec![Vec3::Z];
        let t = tilt.to_radians();
        for i in 0..ring {
            let phi = i as f32 / ring as f32 * std::f32::consts::TAU;
            v.push(Vec3::new(t.sin() * phi.cos(), t.sin() * phi.sin(), t.cos()));
        }
        v
    }

    /// Each cone's weight: the cosine-weighted solid angle of the part of the hemisphere whose
    /// directions are nearest its axis, as a fraction of the whole (pi). The cones stand for
    /// their cells, so the weights sum to exactly 1 and no empirical factor is needed.
    pub fn weights(&self) -> Vec<f32> {
        cell_weights(&self.axes())
    }
}

/// Cosine-weighted hemisphere fractions of the nearest-axis cells, by midpoint quadrature in
/// (cos²θ, φ), where the cosine-weighted measure is uniform.
pub fn cell_weights(axes: &[Vec3]) -> Vec<f32> {
    let (nu, nphi) = (256, 1024);
    let mut w = vec![0f64; axes.len()];
    for i in 0..nu {
        // u = sin²θ is uniform under the cosine-weighted measure.
        let u = (i as f32 + 0.5) / nu as f32;
        let (s, c) = (u.sqrt(), (1.0 - u).sqrt());
        for j in 0..nphi {
            let phi = (j as f32 + 0.5) / nphi as f32 * std::f32::consts::TAU;
            let d = Vec3::new(s * phi.cos(), s * phi.sin(), c);
            let best = axes
                .iter()
                .enumerate()
                .max_by(|a, b| a.1.dot(d).total_cmp(&b.1.dot(d)))
                .map(|(k, _)| k)
                .unwrap_or(0);
            w[best] += 1.0;
        }
    }
    let total: f64 = w.iter().sum();
    w.into_iter().map(|x| (x / total) as f32).collect()
}

/// Bytes of a 3D texture with `mips` levels.
pub fn texture_bytes(res: u32, bytes_per_texel: u64, mips: u32) -> u64 {
    (0..mips)
        .map(|m| ((res >> m).max(1) as u64).pow(3) * bytes_per_texel)
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cone_weights_partition_the_cosine_hemisphere() {
        for set in [ConeSet::Six60, ConeSet::Seven45, ConeSet::Nine45] {
            let w = set.weights();
            assert_eq!(w.len(), set.axes().len());
            // Quadrature of a partition: the fractions sum to 1 up to float rounding.
            assert!((w.iter().sum::<f32>() - 1.0).abs() < 1e-5, "{set:?}: {w:?}");
            // The ring cones are symmetric, so they get equal weights (to quadrature error).
            for &x in &w[2..] {
                assert!((x - w[1]).abs() < 2e-3, "{set:?}: {w:?}");
            }
        }
    }

    #[test]
    fn grid_has_a_margin_voxel() {
        let g = Grid::around(Vec3::ZERO, Vec3::new(2.0, 1.0, 1.0), 64);
        assert!((g.extent() - 2.0 * 64.0 / 62.0).abs() < 1e-5);
        assert!((g.origin.x + g.voxel_size).abs() < 1e-5);
        assert_eq!(g.levels(), 7);
    }
}
