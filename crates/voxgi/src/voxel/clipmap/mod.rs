//! Clipmap cascades: levels of `resolution`³ voxels centred on the camera, level k's voxels
//! 2^k times the finest, so each level spans twice the one inside it (VXGI's 3D clipmaps; the
//! large-world answer of every real-time voxel GI). A large world keeps fine voxels near the
//! camera and coarse ones far away, in memory that does not grow with the world.
//!
//! Built on the dense volume: the levels are the windows of one `DenseVolume` (cubes stacked
//! along z in every texture and buffer), each voxelized from its own fragments (the renderer
//! makes a grid's fragments per level: `fragment_grids`), lit and bounced as leaves of their
//! level's size, and filtered into its own directional mips. Cone tracing reads the finest
//! level that holds a sample wholly and hands over to the next coarser across a band
//! (shaders/voxels/clipmap/sample.wgsl).
//!
//! The windows follow the camera by steps of an eighth of themselves (a window moves when its
//! place for the camera lies two steps or more from where it is, so a camera that wavers does
//! not move it to and fro), on a lattice of their own voxels that starts at the window centred
//! on the scene's bounds, so a voxel of a level covers the same place wherever its window is,
//! and each level's voxels are whole groups of the finer level's (its mips can be the finer
//! level's where they overlap: nest.rs). A window stays inside the scene's bounds on each
//! axis where it can (reaching just past a bound it meets), and is centred on them on an axis
//! where it is wider (a town 30 m tall: every level holds all of its height, none of the
//! ground below it; a level wider than the scene on every axis is the dense volume there), so
//! no voxels are spent on the void past the world's edge.
//! A window that moves is voxelized and lit again alone: each window owns a part of the
//! volume's slots (voxels/dense/slots.wgsl), so the others keep their leaves, and their light
//! (their bounces gather in `bounce_slices` turns); its own leaves where it overlaps its old
//! place keep the light of the leaves that held their voxels (a copy of its occupancy is made
//! before its build: voxels/clipmap/carry.wgsl), the others start from the coarser level's.
//! A frame moves at most `RendererOptions::clipmap_budget` windows; the others wait at their
//! old places, valid, until their turn (scrolling only the slabs newly inside a window is not
//! built).

mod nest;

use super::dense::{self, DenseVolume};
use super::registry::{KindInfo, StructureDesc};
use super::{
    DebugView, FrameChanges, GpuVolume, Grid, POOL_COUNTERS, Region, StructureBindings,
    VoxelStructure, VoxelWork, dynamic_region,
};
use crate::fragments::Fragments;
use crate::frame::targets::FrameTargets;
use crate::gpu::layout;
use crate::gpu::shader::StructureShaders;
use crate::gpu::timer::GpuTimer;
use crate::{Error, Result};
use bytemuck::{Pod, Zeroable};
use glam::{IVec3, Vec3};
use nest::{Nest, NestPass};
use std::sync::Arc;
use wgpu::util::DeviceExt;

/// Most levels (`MAX_CLIP_LEVELS` in shaders/voxels/clipmap/levels.wgsl).
pub const MAX_LEVELS: u32 = 8;

/// With `voxel_size` auto, the coarsest level spans this many times the scene's cube.
const AUTO_SPAN: f32 = 4.0;

/// Voxels a sample's filter needs inside a window beyond its diameter (`MARGIN` in
/// shaders/voxels/clipmap/sample.wgsl).
const MARGIN: f32 = 1.5;
/// Voxels over which a level hands over to the next coarser (`BAND` there).
const BAND: f32 = 4.0;

/// Fragment coordinates hold 10 bits a axis: the stacked windows' depth, levels × resolution,
/// is at most this.
const MAX_STACK: u32 = 1024;

/// Mirrors `ClipLevels` in shaders/voxels/clipmap/levels.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuClipLevels {
    /// Per level: its window's minimum corner (xyz), metres, and its voxel edge (w).
    pub levels: [[f32; 4]; MAX_LEVELS as usize],
    /// The scene's cube, lowest corner (xyz; w unused).
    pub scene_lo: [f32; 4],
    /// Its highest corner.
    pub scene_hi: [f32; 4],
    /// The scene's bounds, lowest corner (xyz; w unused): windows' faces past them need no
    /// margin.
    pub bounds_lo: [f32; 4],
    /// Their highest corner.
    pub bounds_hi: [f32; 4],
    /// Levels in use.
    pub count: u32,
    /// Voxels per side of every window.
    pub resolution: u32,
    /// A bit per level the last voxel work rebuilt alone (its leaves are all new).
    pub rebuilt: u32,
    /// The rebuilt level whose window's occupancy before the build is kept, or `MAX_LEVELS`.
    pub kept: u32,
    /// Where its voxels lay before against where they lie now: old = new + `kept_by` (xyz; w
    /// unused).
    pub kept_by: [i32; 4],
}

/// The clipmap in the registry of kinds.
pub const KIND: KindInfo = KindInfo {
    name: "clipmap",
    summary: "clipmap cascades: levels that follow the camera, fine near it and coarse far \
              away, for worlds larger than one volume",
    // Each level is a dense window; 256 × 4 levels fill the fragments' 10-bit coordinates.
    max_resolution: 256,
    // Its passes are the dense volume's.
    build_passes: &["dense_build", "dense_update"],
    filter_passes: &["filter", "nest"],
    shaders: StructureShaders {
        name: "clipmap",
        sources: crate::wgsl![
            "voxels/clipmap/levels.wgsl",
            "voxels/clipmap/sample.wgsl",
            "voxels/clipmap/placement.wgsl",
            "voxels/clipmap/irradiance.wgsl",
            "voxels/clipmap/carry.wgsl",
            "voxels/clipmap/nest.wgsl",
        ],
        passes: &["voxels/clipmap/nest.wgsl"],
        base: Some(&dense::KIND.shaders),
    },
    sampling_layout: Clipmap::sampling_layout,
    leaves_layout: Clipmap::leaves_layout,
    leaf_store_layout: DenseVolume::leaf_store_layout,
    irradiance_layout: DenseVolume::irradiance_layout,
    carry_layout: Clipmap::carry_layout,
    sampling_constants: super::sampling_constants,
    create,
};

/// A clipmap for `desc`: `desc.levels` windows of `desc.grid.resolution`³ voxels, the finest
/// `desc.voxel_size` (default: the coarsest level spans `AUTO_SPAN` times `desc.grid`, the
/// scene's cube), placed
/// around the scene's centre until the first frame's camera places them.
fn create(
    device: &wgpu::Device,
    desc: &StructureDesc,
    previous: Option<&dyn VoxelStructure>,
) -> Result<Box<dyn VoxelStructure>> {
    let res = desc.grid.resolution;
    let count = desc.levels;
    if !(2..=MAX_LEVELS).contains(&count) {
        return Err(Error::Setting(format!(
            "clipmap_levels {count} is outside 2..={MAX_LEVELS}"
        )));
    }
    if count * res > MAX_STACK {
        return Err(Error::Setting(format!(
            "a clipmap of {count} levels of {res}³ voxels stacks {} voxels deep, past the {MAX_STACK} \
             voxel coordinates hold: use at most {} levels at this resolution, or a lower \
             voxel_resolution",
            count * res,
            MAX_STACK / res
        )));
    }
    let finest = match desc.voxel_size {
        Some(s) if s.is_finite() && s > 0.0 => s,
        Some(s) => {
            return Err(Error::Setting(format!(
                "voxel_size {s} must be a positive number of metres"
            )));
        }
        // The camera may stand anywhere near the scene: from within a scene's size of it,
        // the coarsest level still holds all of it.
        None => AUTO_SPAN * desc.grid.extent() / (res as f32 * (1u32 << (count - 1)) as f32),
    };
    log::info!(
        "clipmap: {count} levels of {res}³ voxels, the finest {finest} m (level 0 spans {} m, \
         level {} {} m)",
        finest * res as f32,
        count - 1,
        finest * res as f32 * (1u32 << (count - 1)) as f32
    );
    let base = Grid {
        origin: Vec3::ZERO,
        voxel_size: finest,
        resolution: res,
    };
    let previous_clipmap = previous.and_then(|p| p.as_any().downcast_ref::<Clipmap>());
    let previous = previous_clipmap
        .map(Clipmap::volume)
        .or_else(|| previous.and_then(|p| p.as_any().downcast_ref::<DenseVolume>()));
    // Every level holds about as many surface voxels as the scene's cube at this resolution.
    let leaves = (desc.leaves * count as u64).min((res as u64).pow(3) * count as u64);
    let inner = DenseVolume::create(device, base, count, desc, leaves, previous)?;
    let scene = (desc.grid.origin, desc.grid.origin + desc.grid.extent());
    // An empty scene's bounds are inverted: the grid's cube stands in for them.
    let bounds = match desc.bounds {
        b if b.min.cmple(b.max).all() => (b.min, b.max),
        _ => scene,
    };
    let centre = (bounds.0 + bounds.1) * 0.5;
    let levels = (0..count)
        .map(|k| {
            let s = finest * (1u32 << k) as f32;
            let mut g = Grid {
                origin: Vec3::ZERO,
                voxel_size: s,
                resolution: res,
            };
            g.origin = placed_origin(&g, bounds, centre);
            g
        })
        .collect();
    let nest_pass = match previous_clipmap {
        Some(p) => p.nest_pass.clone(),
        None => Arc::new(NestPass::new(device, inner.filter().0.layout())),
    };
    Ok(Box::new(Clipmap::new(
        device, inner, nest_pass, levels, scene, bounds,
    )))
}

/// The origin of a window like `g` for a camera at `camera` in a scene whose bounds span
/// `(lo, hi)`: on each axis centred on the camera, on the lattice of its steps (an eighth of
/// the window) from the window centred on the bounds, so that its voxels lie where the level's
/// always lie; where it would poke out of the bounds, moved back to the lattice point that just
/// reaches the bound (so that face counts as closed: past it there is nothing); centred on
/// the bounds on an axis where it is wider than they are. Every level's lattice starts from
/// its centred window, so a finer window lies a whole number of the coarser one's voxels from
/// it (a multiple of eight with steps of an eighth of 128 voxels: nest.rs).
fn placed_origin(g: &Grid, (lo, hi): (Vec3, Vec3), camera: Vec3) -> Vec3 {
    let (w, half, step) = (g.extent(), g.extent() * 0.5, window_step(g));
    let axis = |lo: f32, hi: f32, c: f32| {
        let middle = (lo + hi) * 0.5;
        if w > (hi - lo) * (1.0 + 1e-5) {
            return middle - half;
        }
        let steps = (c - middle) / step;
        let (first, last) = ((lo + half - middle) / step, (hi - half - middle) / step);
        // The lattice point at or past the bound (a thousandth of a step for rounding).
        let j = if steps <= first {
            (first + 1e-3).floor()
        } else if steps >= last {
            (last - 1e-3).ceil()
        } else {
            steps.round()
        };
        middle - half + j * step
    };
    Vec3::new(
        axis(lo.x, hi.x, camera.x),
        axis(lo.y, hi.y, camera.y),
        axis(lo.z, hi.z, camera.z),
    )
}

/// The windows of `levels` that move for a camera at `camera` in a scene whose bounds are
/// `bounds`, a bit each: of those whose place (`placed_origin`) lies more than a step from
/// where they are, at most `budget` (0: all), those that strayed farthest in their own steps
/// first, the finer first among equals.
fn moves(levels: &[Grid], bounds: (Vec3, Vec3), camera: Vec3, budget: u32) -> u32 {
    let mut wanting: Vec<(usize, f32)> = levels
        .iter()
        .enumerate()
        .filter_map(|(k, g)| {
            let origin = placed_origin(g, bounds, camera);
            let stray = (origin - g.origin).abs().max_element() / window_step(g);
            (stray > 1.001).then_some((k, stray))
        })
        .collect();
    wanting.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
    if budget > 0 {
        wanting.truncate(budget as usize);
    }
    wanting.iter().fold(0, |m, (k, _)| m | 1 << k)
}

/// How far a window moves at a time: an eighth of it (at least a voxel).
fn window_step(g: &Grid) -> f32 {
    g.voxel_size * (g.resolution / 8).max(1) as f32
}

/// Clipmap cascades (the module's documentation says how).
pub struct Clipmap {
    /// The levels' voxels, one window each.
    inner: DenseVolume,
    /// Each level's window: where it lies, its voxel edge, its resolution.
    levels: Vec<Grid>,
    /// `GpuClipLevels` of `levels`, for sampling and for the leaves.
    clip: wgpu::Buffer,
    /// Whether `clip` holds `levels` as they are (written at the next build otherwise).
    clip_current: std::sync::atomic::AtomicBool,
    /// A `Volume` uniform placing one level's window, for the debug views.
    debug_placement: wgpu::Buffer,
    /// The scene's cube (its lowest and highest corner): cones stop at it.
    scene: (Vec3, Vec3),
    /// The scene's bounds: the windows stay inside them where they can, and their lattices
    /// start at the windows centred on them.
    bounds: (Vec3, Vec3),
    /// The first frame's camera has placed the windows.
    placed: bool,
    /// A bit per level the build `plan` last asked for rebuilds alone (the others keep their
    /// leaves and light); 0 when it asked for none or for all of them.
    rebuilt_alone: u32,
    /// The finest level `plan` last moved alone and how far (in its voxels, the new corner
    /// minus the old: a voxel's old index is its new one plus this): its build keeps the
    /// voxels of both places (only the others are voxelized: `Region::all_but_kept`), and its
    /// window's occupancy from before, so that its new leaves keep the light of the leaves
    /// that held their voxels (carry.wgsl).
    kept: Option<(u32, IVec3)>,
    sampling: wgpu::BindGroup,
    leaves: wgpu::BindGroup,
    /// What its new leaves' light starts from: the occupancy and the kept one.
    carry: wgpu::BindGroup,
    /// The coarser levels filtered from the finer ones where they overlap, after each filter.
    nest: Nest,
    nest_pass: Arc<NestPass>,
}

impl Clipmap {
    fn new(
        device: &wgpu::Device,
        inner: DenseVolume,
        nest_pass: Arc<NestPass>,
        levels: Vec<Grid>,
        scene: (Vec3, Vec3),
        bounds: (Vec3, Vec3),
    ) -> Self {
        let clip = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("clipmap levels"),
            contents: bytemuck::bytes_of(&clip_levels(&levels, scene, bounds, 0, None)),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        });
        let debug_placement = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("clipmap debug placement"),
            size: size_of::<GpuVolume>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let (sampling, leaves, carry) = Self::bind_groups(device, &inner, &clip);
        let mut nest = Nest::new(device, &nest_pass, &inner);
        nest.place(&levels);
        Clipmap {
            nest,
            nest_pass,
            inner,
            levels,
            clip,
            clip_current: true.into(),
            debug_placement,
            scene,
            bounds,
            placed: false,
            rebuilt_alone: 0,
            kept: None,
            sampling,
            leaves,
            carry,
        }
    }

    /// The bind groups over a volume made again (its pools resized).
    fn rebind(&mut self, device: &wgpu::Device) {
        (self.sampling, self.leaves, self.carry) =
            Self::bind_groups(device, &self.inner, &self.clip);
        self.nest = Nest::new(device, &self.nest_pass, &self.inner);
        self.nest.place(&self.levels);
    }

    /// The sampling group (the dense volume's with the levels), the leaves' group and the
    /// carry group (the occupancy now and the kept one).
    fn bind_groups(
        device: &wgpu::Device,
        inner: &DenseVolume,
        clip: &wgpu::Buffer,
    ) -> (wgpu::BindGroup, wgpu::BindGroup, wgpu::BindGroup) {
        let view = |t: &wgpu::Texture| t.create_view(&Default::default());
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("voxels"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            ..Default::default()
        });
        let radiance = [view(&inner.radiance), view(&inner.chains)];
        let mut resources = DenseVolume::sampling_resources(&inner.volume, &radiance, &sampler);
        resources.push(clip.as_entire_binding());
        let sampling = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("clipmap sampling"),
            layout: &Self::sampling_layout(device),
            entries: &layout::entries(resources),
        });
        let surface = [
            view(&inner.albedo),
            view(&inner.normal),
            view(&inner.emission),
        ];
        let slots = [
            &inner.slot_voxel,
            &inner.counters,
            &inner.slot_direct,
            &inner.slot_next,
        ];
        let mut resources = DenseVolume::leaves_resources(&inner.volume, &surface, slots);
        resources.push(clip.as_entire_binding());
        let leaves = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("clipmap leaves"),
            layout: &Self::leaves_layout(device),
            entries: &layout::entries(resources),
        });
        let carry = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("clipmap carry"),
            layout: &Self::carry_layout(device),
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: inner.occupancy.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: inner.kept_occupancy(),
                },
            ],
        });
        (sampling, leaves, carry)
    }

    /// The layout of @group(3) of the bounce's `stash` and `mark`, twin of
    /// shaders/voxels/clipmap/carry.wgsl: the occupancy (binding 0) and a moved window's
    /// occupancy before its build (binding 2).
    pub fn carry_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
        let c = wgpu::ShaderStages::COMPUTE;
        device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("clipmap carry"),
            entries: &[layout::storage(0, c, true), layout::storage(2, c, true)],
        })
    }

    /// The layout of @group(1), twin of shaders/voxels/clipmap/sample.wgsl: the dense volume's
    /// and the levels at binding 4.
    pub fn sampling_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
        let mut entries = DenseVolume::sampling_entries();
        entries.push(layout::uniform(4, wgpu::ShaderStages::COMPUTE, false));
        device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("clipmap sampling"),
            entries: &entries,
        })
    }

    /// The layout of @group(2) of the lighting passes, twin of voxels/dense/leaves.wgsl with
    /// shaders/voxels/clipmap/placement.wgsl: the dense volume's and the levels at binding 8.
    pub fn leaves_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
        let mut entries = DenseVolume::leaves_entries();
        entries.push(layout::uniform(8, wgpu::ShaderStages::COMPUTE, false));
        device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("clipmap leaves"),
            entries: &entries,
        })
    }

    /// Each level's window: where it lies, its voxel edge, its resolution.
    pub fn levels(&self) -> &[Grid] {
        &self.levels
    }

    /// The levels' voxels: the dense volume whose windows they are.
    pub fn volume(&self) -> &DenseVolume {
        &self.inner
    }

    /// The level a sample of `diameter` at `p` reads (sample.wgsl's `sample_depth`): the
    /// finest whose reach (past the room it needs, and at most `BAND` voxels of the next
    /// coarser past that one's) is positive, and its weight against the next coarser (1 past
    /// the hand-over band).
    pub fn level_at(&self, p: Vec3, diameter: f32) -> (usize, f32) {
        let (k, r) = self.finest_reaching(p, diameter, MARGIN, |r| r > 0.0);
        (k, (r / (BAND * self.levels[k].voxel_size)).clamp(0.0, 1.0))
    }

    /// The finest level whose reach (`room` voxels), each level's counted at most `BAND` of
    /// the next coarser's voxels past that one's, is taken by `take` (the coarsest when none
    /// is), with that reach.
    fn finest_reaching(
        &self,
        p: Vec3,
        diameter: f32,
        room: f32,
        take: impl Fn(f32) -> bool,
    ) -> (usize, f32) {
        let last = self.levels.len() - 1;
        let mut r = self.reach(p, diameter, room, last);
        let (mut k, mut kr) = (last, r);
        for j in (0..last).rev() {
            r = self
                .reach(p, diameter, room, j)
                .min(r - BAND * self.levels[j + 1].voxel_size);
            if take(r) {
                (k, kr) = (j, r);
            }
        }
        (k, kr)
    }

    /// sample.wgsl's `level_reach`: how far past `room` voxels plus `diameter` level `k`'s
    /// window holds `p`, in metres.
    fn reach(&self, p: Vec3, diameter: f32, room: f32, k: usize) -> f32 {
        let g = &self.levels[k];
        (inside_by(g, self.bounds, p) - (room + diameter / g.voxel_size)) * g.voxel_size
    }

    /// sample.wgsl's `level_holding`: the finest level whose reach (`room` voxels), carried as
    /// `level_at` carries it, is not negative.
    fn level_holding(&self, p: Vec3, diameter: f32, room: f32) -> usize {
        self.finest_reaching(p, diameter, room, |r| r >= 0.0).0
    }

    /// The CPU twin of shaders/voxels/clipmap/sample.wgsl's `sample_voxels` over `voxels`,
    /// the levels' textures read back (a `DenseSampler` of `volume()`): the finest level that
    /// holds the sample with room, handing over to the next across `BAND` voxels.
    pub fn sample_voxels_cpu(
        &self,
        voxels: &super::cpu::DenseSampler,
        p: Vec3,
        diameter: f32,
        dir: Vec3,
    ) -> glam::Vec4 {
        let (k, w) = self.level_at(p, diameter);
        let last = self.levels.len() - 1;
        let depth = |k: usize| {
            let g = &self.levels[k];
            let top = voxels.grid.levels() as f32 - 1.0;
            let lod = (diameter / g.voxel_size).max(1.0).log2().clamp(0.0, top);
            let uvw = ((p - g.origin) / g.extent()).clamp(Vec3::ZERO, Vec3::ONE);
            voxels.window_depth(uvw, lod, dir, k as u32)
                * crate::voxel::cpu::border_weight(uvw, lod, g.resolution)
        };
        let fine = depth(k);
        let outer = if k == last {
            glam::Vec4::ZERO
        } else {
            depth(k + 1)
        };
        super::cpu::from_depth(outer.lerp(fine, w))
    }

    /// Plans the windows' moves for the camera at `camera`: each window whose place for it
    /// (`placed_origin`) lies more than a step from where it is (two steps or more) wants to
    /// move; at most `budget` of them move this frame (0: all), those that strayed farthest
    /// (in their own steps) first, the finer first among equals; the others wait where they
    /// are, still valid. Every window is placed the first time and when `everything` is to
    /// be rebuilt. Returns a bit per level that moved, and whether that is all of them
    /// anyway.
    fn follow(&mut self, camera: Vec3, budget: u32, everything: bool) -> (u32, bool) {
        let all = (1u32 << self.levels.len()) - 1;
        if everything || !self.placed {
            for g in &mut self.levels {
                g.origin = placed_origin(g, self.bounds, camera);
            }
            self.placed = true;
            self.nest.place(&self.levels);
            return (all, true);
        }
        let moved = moves(&self.levels, self.bounds, camera, budget);
        for (k, g) in self.levels.iter_mut().enumerate() {
            if moved & (1 << k) != 0 {
                g.origin = placed_origin(g, self.bounds, camera);
            }
        }
        self.nest.place(&self.levels);
        (moved, false)
    }

    /// Records the levels' placement into `clip` (and the nest's steps into its parameters)
    /// when it changed since the last time.
    fn record_placement(&self, device: &wgpu::Device, encoder: &mut wgpu::CommandEncoder) {
        self.nest.record_params(device, encoder);
        if self
            .clip_current
            .swap(true, std::sync::atomic::Ordering::Relaxed)
        {
            return;
        }
        let staging = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("clipmap levels (staging)"),
            contents: bytemuck::bytes_of(&clip_levels(
                &self.levels,
                self.scene,
                self.bounds,
                self.rebuilt_alone,
                self.kept,
            )),
            usage: wgpu::BufferUsages::COPY_SRC,
        });
        encoder.copy_buffer_to_buffer(&staging, 0, &self.clip, 0, staging.size());
    }
}

/// sample.wgsl's `inside_by`: how far inside window `g` the point `p` lies, in its voxels,
/// counting only the faces inside the scene's bounds `(lo, hi)` (negative outside the window).
fn inside_by(g: &Grid, (lo, hi): (Vec3, Vec3), p: Vec3) -> f32 {
    let n = g.resolution as f32;
    let q = (p - g.origin) / g.voxel_size;
    if q.cmplt(Vec3::ZERO).any() || q.cmpgt(Vec3::splat(n)).any() {
        return -1.0;
    }
    let half = 0.5 * g.voxel_size;
    let open_lo = g.origin.cmpgt(lo + half);
    let open_hi = (g.origin + n * g.voxel_size).cmplt(hi - half);
    let far = Vec3::splat(1e9);
    Vec3::select(open_lo, q, far)
        .min(Vec3::select(open_hi, Vec3::splat(n) - q, far))
        .min_element()
}

/// The levels in the scene's cube `scene` and bounds `bounds` as the shaders read them, with
/// `rebuilt` the levels the last voxel work rebuilt alone and `kept` the one whose old
/// occupancy is kept (`Clipmap::kept`).
fn clip_levels(
    levels: &[Grid],
    (lo, hi): (Vec3, Vec3),
    bounds: (Vec3, Vec3),
    rebuilt: u32,
    kept: Option<(u32, IVec3)>,
) -> GpuClipLevels {
    let mut l = GpuClipLevels {
        levels: [[0.0; 4]; MAX_LEVELS as usize],
        scene_lo: lo.extend(0.0).to_array(),
        scene_hi: hi.extend(0.0).to_array(),
        bounds_lo: bounds.0.extend(0.0).to_array(),
        bounds_hi: bounds.1.extend(0.0).to_array(),
        count: levels.len() as u32,
        resolution: levels[0].resolution,
        rebuilt,
        kept: kept.map_or(MAX_LEVELS, |(k, _)| k),
        kept_by: kept.map_or([0; 4], |(_, by)| by.extend(0).to_array()),
    };
    for (k, g) in levels.iter().enumerate() {
        l.levels[k] = [g.origin.x, g.origin.y, g.origin.z, g.voxel_size];
    }
    l
}

impl VoxelStructure for Clipmap {
    /// Follows the camera within the frame's budget (`follow`): the windows that move are
    /// voxelized and lit again, alone (the others keep their leaves and light), with the
    /// dynamic geometry where it is now; a rebuild places and builds every window.
    fn plan(&mut self, changes: &FrameChanges) -> VoxelWork {
        let before = self.levels.clone();
        let (moved, everything) = self.follow(changes.camera, changes.budget, changes.rebuild);
        let was_kept = self.kept;
        // The finest level moved alone keeps its old occupancy for its leaves' light.
        self.kept = (moved != 0 && !everything).then(|| {
            let k = moved.trailing_zeros();
            let (old, new) = (&before[k as usize], &self.levels[k as usize]);
            (
                k,
                ((new.origin - old.origin) / new.voxel_size)
                    .round()
                    .as_ivec3(),
            )
        });
        let around = |levels: &[Grid], b| {
            levels
                .iter()
                .map(|g| dynamic_region(g, b))
                .collect::<Vec<_>>()
        };
        let was = self.rebuilt_alone;
        let work = if moved != 0 {
            let build = self
                .levels
                .iter()
                .enumerate()
                .map(|(k, g)| match self.kept {
                    Some((kept, by)) if kept as usize == k => Region::all_but_kept(g, by),
                    _ if moved & (1 << k) != 0 => Region::all(g),
                    _ => Region::EMPTY,
                })
                .collect();
            self.rebuilt_alone = if everything { 0 } else { moved };
            VoxelWork {
                build: Some(build),
                update: changes
                    .dynamic
                    .or(changes.dynamic_now)
                    .map(|b| around(&self.levels, b)),
                partial: !everything,
            }
        } else {
            self.rebuilt_alone = 0;
            VoxelWork {
                build: None,
                update: changes.dynamic.map(|b| around(&self.levels, b)),
                partial: false,
            }
        };
        if moved != 0 || was != self.rebuilt_alone || was_kept != self.kept {
            self.clip_current
                .store(false, std::sync::atomic::Ordering::Relaxed);
        }
        work
    }

    fn record_plan(&self, device: &wgpu::Device, encoder: &mut wgpu::CommandEncoder) {
        self.record_placement(device, encoder);
    }

    fn fragment_grids(&self) -> Vec<Grid> {
        self.levels.clone()
    }

    fn kind(&self) -> super::VoxelKind {
        super::VoxelKind::CLIPMAP
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }

    fn grid(&self) -> Grid {
        self.levels[0]
    }

    fn voxel_size_at(&self, p: Vec3) -> f32 {
        // sample.wgsl's voxels_voxel_size_at: the level a sample there reads, with MARGIN +
        // BAND + 1 voxels of its window around p.
        self.levels[self.level_holding(p, 0.0, MARGIN + BAND + 1.0)].voxel_size
    }

    fn record_build(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        fragments: &Fragments,
        timer: &mut GpuTimer,
    ) {
        self.record_placement(device, encoder);
        // Every level on a rebuild, and for the build that counts the pools (no plan yet).
        let rebuild = match self.rebuilt_alone {
            0 => self.inner.every_window(),
            some => some,
        };
        let kept = self.kept.filter(|_| self.rebuilt_alone != 0);
        self.inner
            .build_windows(device, encoder, fragments, rebuild, kept, timer);
    }

    fn record_update(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        fragments: &Fragments,
        timer: &mut GpuTimer,
    ) {
        self.record_placement(device, encoder);
        self.inner.record_update(device, encoder, fragments, timer);
    }

    fn bind_fragments(&mut self, device: &wgpu::Device, fragments: &Fragments) {
        self.inner.bind_fragments(device, fragments);
    }

    fn record_filter(&self, encoder: &mut wgpu::CommandEncoder, timer: &mut GpuTimer) {
        self.inner.record_filter(encoder, timer);
        self.nest
            .record(encoder, &self.nest_pass, &self.inner, timer);
    }

    fn pool_counter(&self) -> &wgpu::Buffer {
        self.inner.pool_counter()
    }

    fn leaf_capacity(&self) -> u64 {
        self.inner.leaf_capacity()
    }

    fn leaf_limit(&self, device: &wgpu::Device) -> u64 {
        self.inner.leaf_limit(device)
    }

    fn needs_growth(&self, counted: &[u32; POOL_COUNTERS]) -> bool {
        self.inner.needs_growth(counted)
    }

    fn grow(&mut self, device: &wgpu::Device, counted: &[u32; POOL_COUNTERS]) -> Result<()> {
        self.inner.grow(device, counted)?;
        self.rebind(device);
        Ok(())
    }

    fn shrink(&mut self, device: &wgpu::Device, counted: &[u32; POOL_COUNTERS]) -> Result<bool> {
        let shrunk = self.inner.shrink(device, counted)?;
        if shrunk {
            self.rebind(device);
        }
        Ok(shrunk)
    }

    fn memory(&self) -> Vec<(&'static str, u64)> {
        let mut m = self.inner.memory();
        m.push(("clipmap nest", self.nest.memory()));
        m
    }

    fn bindings(&self) -> StructureBindings<'_> {
        let inner = self.inner.bindings();
        StructureBindings {
            sampling: &self.sampling,
            leaves: &self.leaves,
            carry: &self.carry,
            ..inner
        }
    }

    /// The voxel views of level `view.level` (its finest voxels and their directional mips
    /// are the level's own: the view shows the level's window at its finest).
    fn record_debug(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        targets: &FrameTargets,
        view: DebugView,
        timer: &mut GpuTimer,
    ) {
        let k = view.level.min(self.levels.len() as u32 - 1);
        let g = self.levels[k as usize];
        let placement = GpuVolume {
            origin: g.origin.to_array(),
            resolution: g.resolution,
            voxel_size: g.voxel_size,
            levels: g.levels(),
            anisotropic: self.inner.anisotropic as u32,
            windows: self.levels.len() as u32,
        };
        let staging = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("clipmap debug placement (staging)"),
            contents: bytemuck::bytes_of(&placement),
            usage: wgpu::BufferUsages::COPY_SRC,
        });
        encoder.copy_buffer_to_buffer(&staging, 0, &self.debug_placement, 0, staging.size());
        self.inner.debug_pass().record(
            device,
            encoder,
            targets,
            &self.inner,
            (&self.debug_placement, k),
            view.mode,
            0,
            view.direction,
            timer,
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `count` levels of `resolution`³ voxels from `finest` metres, placed for `camera`.
    fn placed_levels(
        count: u32,
        finest: f32,
        resolution: u32,
        bounds: (Vec3, Vec3),
        camera: Vec3,
    ) -> Vec<Grid> {
        (0..count)
            .map(|k| {
                let mut g = Grid {
                    origin: Vec3::ZERO,
                    voxel_size: finest * (1 << k) as f32,
                    resolution,
                };
                g.origin = placed_origin(&g, bounds, camera);
                g
            })
            .collect()
    }

    #[test]
    fn windows_snap_to_their_own_lattice_and_nest() {
        let camera = Vec3::new(3.37, -1.2, 40.05);
        let scene = (
            Vec3::new(-100.31, -50.0, -60.0),
            Vec3::new(99.69, 150.0, 140.0),
        );
        let levels = placed_levels(5, 0.1, 64, scene, camera);
        for (k, g) in levels.iter().enumerate() {
            // On the level's lattice: origins are whole steps (8 voxels) from the window
            // centred on the scene.
            let anchor = (scene.0 + scene.1) * 0.5 - Vec3::splat(g.extent() * 0.5);
            let steps = (g.origin - anchor) / window_step(g);
            assert!(
                (steps - steps.round()).abs().max_element() < 1e-3,
                "level {k}: {steps}"
            );
            // The camera within half a step of the centre.
            let centre = g.origin + Vec3::splat(g.extent() * 0.5);
            assert!((camera - centre).abs().max_element() <= window_step(g) * 0.5 + 1e-4);
            // Inside the next coarser level, a whole number of its voxels in, a multiple of
            // four (the nest copies its mips up to texels of four voxels).
            if let Some(c) = levels.get(k + 1) {
                let o = (g.origin - c.origin) / c.voxel_size;
                assert!(
                    (o / 4.0 - (o / 4.0).round()).abs().max_element() < 1e-3,
                    "level {k} lies {o} voxels into level {}",
                    k + 1
                );
                assert!(g.origin.cmpge(c.origin).all(), "level {k} pokes out below");
                let (hi, chi) = (g.origin + g.extent(), c.origin + c.extent());
                assert!(hi.cmple(chi).all(), "level {k} pokes out above");
            }
        }
    }

    #[test]
    fn windows_stay_inside_the_scene_and_a_wide_one_is_centred_on_it() {
        let scene = (Vec3::ZERO, Vec3::splat(6.4));
        let grid = |s: f32| Grid {
            origin: Vec3::ZERO,
            voxel_size: s,
            resolution: 32,
        };
        // A camera outside the scene: the window holding 3.2 m slides back inside it.
        let camera = Vec3::new(-2.0, 3.1, 8.0);
        let near = |a: Vec3, b: Vec3| a.abs_diff_eq(b, 1e-5);
        let o = placed_origin(&grid(0.1), scene, camera);
        assert!(near(o, Vec3::new(0.0, 1.6, 3.2)), "{o}");
        // The window as wide as the scene is the scene's cube, wherever the camera is.
        let o = placed_origin(&grid(0.2), scene, camera);
        assert!(near(o, Vec3::ZERO), "{o}");
        // Wider: centred on the scene.
        let o = placed_origin(&grid(0.4), scene, camera);
        assert!(near(o, Vec3::splat(-3.2)), "{o}");
    }

    #[test]
    fn at_a_bound_every_window_reaches_it_and_the_finer_ones_stay_inside_the_coarser() {
        // Bounds 6.7 m along x (no whole number of steps); windows of 32 voxels from 0.05 m.
        let bounds = (Vec3::ZERO, Vec3::new(6.7, 6.7, 6.7));
        for camera in [Vec3::new(0.3, 3.0, 3.0), Vec3::new(6.6, 3.0, 3.0)] {
            let levels = placed_levels(3, 0.05, 32, bounds, camera);
            for (k, g) in levels.iter().enumerate() {
                let (o, e) = (g.origin.x, g.origin.x + g.extent());
                // The face at the bound the camera is near lies on or past it (closed), by less
                // than a step.
                let past = if camera.x < 1.0 { -o } else { e - 6.7 };
                assert!(
                    (-1e-4..window_step(g)).contains(&past),
                    "level {k}: [{o}, {e}] for {camera}"
                );
                // Inside the next coarser level, but past the bounds.
                if let Some(c) = levels.get(k + 1) {
                    let (co, ce) = (c.origin.x, c.origin.x + c.extent());
                    assert!(
                        o.max(0.0) >= co - 1e-4 && e.min(6.7) <= ce + 1e-4,
                        "level {k}"
                    );
                }
            }
        }
    }

    #[test]
    fn a_budget_moves_the_farthest_strayed_windows_and_the_others_wait() {
        let bounds = (Vec3::splat(-500.0), Vec3::splat(500.0));
        // Four levels of 32 voxels from 0.25 m: steps of 1, 2, 4 and 8 m.
        let start = Vec3::ZERO;
        let mut levels = placed_levels(4, 0.25, 32, bounds, start);
        // 5 m along x: level 0's place is 5 steps away, level 1's 3 (it rounds to 6 m), level
        // 2's one (within its two: it stays), level 3's none.
        let camera = Vec3::new(5.0, 0.0, 0.0);
        assert_eq!(
            moves(&levels, bounds, camera, 0),
            0b0011,
            "every window that strayed"
        );
        assert_eq!(
            moves(&levels, bounds, camera, 1),
            0b0001,
            "the farthest strayed first"
        );
        assert_eq!(
            moves(&levels, bounds, camera, 8),
            0b0011,
            "no more than strayed"
        );
        // Level 0 moved: level 1's turn, whose stray has not changed.
        levels[0].origin = placed_origin(&levels[0], bounds, camera);
        assert_eq!(moves(&levels, bounds, camera, 1), 0b0010);
        // A camera back at the start: the moved window strays back, the waiting one never
        // left.
        assert_eq!(moves(&levels, bounds, start, 0), 0b0001);
    }

    #[test]
    fn over_a_flat_world_windows_hold_its_whole_height() {
        // A town 64 m wide and 3 m tall; a window of 32 voxels of 0.2 m (6.4 m).
        let bounds = (Vec3::ZERO, Vec3::new(64.0, 3.0, 64.0));
        let g = Grid {
            origin: Vec3::ZERO,
            voxel_size: 0.2,
            resolution: 32,
        };
        for camera in [Vec3::new(20.0, 1.7, 30.1), Vec3::new(20.0, 150.0, 30.1)] {
            let o = placed_origin(&g, bounds, camera);
            // Along y, wider than the town: centred on it, wherever the camera is.
            assert!((o.y - (1.5 - 3.2)).abs() < 1e-5, "{camera}: {o}");
            // Along x and z, the camera within half a 0.8 m step of the centre, on the lattice.
            let xz = glam::Vec2::new(o.x, o.z);
            assert!(xz.abs_diff_eq(glam::Vec2::new(16.8, 27.2), 1e-4), "{o}");
        }
    }
}
