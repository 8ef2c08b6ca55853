//! nest: each coarser level's mips filtered from the finer level where they overlap
//! (shaders/voxels/clipmap/nest.wgsl says why and how). Runs after every filter of the
//! levels, finest window first.

use super::super::Grid;
use super::super::dense::{DenseVolume, mip_view};
use crate::gpu::layout;
use crate::gpu::shader::module_for;
use crate::gpu::timer::GpuTimer;
use bytemuck::{Pod, Zeroable};
use glam::IVec3;
use std::sync::atomic::{AtomicBool, Ordering};
use wgpu::util::DeviceExt;

/// Bytes between steps' parameters (the dynamic offset's alignment).
const STRIDE: u64 = 256;

/// One step's parameters. Mirrors `NestParams` in shaders/voxels/clipmap/nest.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Pod, Zeroable)]
pub struct NestParams {
    pub lo: [i32; 3],
    pub window: u32,
    pub size: [u32; 3],
    pub _pad0: u32,
    pub copy_lo: [i32; 3],
    pub _pad1: u32,
    pub copy_hi: [i32; 3],
    pub _pad2: u32,
    pub finer_lo: [i32; 3],
    pub _pad3: u32,
}

/// One dispatch of the nest: a box of one chain level of one window.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NestStep {
    pub chain: u32,
    pub params: NestParams,
}

impl NestStep {
    /// Whether every texel of its box is copied (none filtered).
    fn copies_only(&self) -> bool {
        let p = &self.params;
        p.size.iter().all(|&v| v > 0)
            && p.copy_lo == p.lo
            && (0..3).all(|i| p.copy_hi[i] == p.lo[i] + p.size[i] as i32)
    }

    /// The same box filtered again from its children, nothing copied.
    fn restoring(mut self) -> Self {
        self.params.copy_lo = [0; 3];
        self.params.copy_hi = [0; 3];
        self
    }
}

/// The steps that nest levels `levels` (windows of `resolution`³ voxels, each twice the
/// voxel of the one before) whose chains have `chain_levels` levels, window by window from
/// the second, chain level by chain level: where the finer window overlaps it on a lattice of
/// its voxels, the texels that overlap it (copied where wholly inside and on the finer
/// window's lattice, filtered again from their children otherwise). A window whose voxels do
/// not meet the finer window's lattice (only windows of fewer than 16 voxels, whose steps are
/// single voxels) keeps its own.
pub fn nest_steps(levels: &[Grid], chain_levels: u32) -> Vec<NestStep> {
    let mut steps = Vec::new();
    for k in 1..levels.len() {
        let (finer, g) = (&levels[k - 1], &levels[k]);
        let n = g.resolution as i32;
        let at = (finer.origin - g.origin) / g.voxel_size;
        // Placed on their lattices the windows lie whole voxels apart; a quarter of a voxel
        // allows the rounding of origins far from the world's origin.
        if (at - at.round()).abs().max_element() > 0.25 {
            continue;
        }
        // The finer window's corner and its overlap with this one, in this one's voxels.
        let o = at.round().as_ivec3();
        let lo = o.max(IVec3::ZERO);
        let hi = (o + IVec3::splat(n / 2)).min(IVec3::splat(n));
        if lo.cmpge(hi).any() {
            continue;
        }
        for c in 0..chain_levels {
            let q = 2i32 << c;
            let (box_lo, box_hi) = (floor_div(lo, q), ceil_div(hi, q));
            // Wholly inside the finer window, on its lattice, which has a level above.
            let lattice = o.x % q == 0 && o.y % q == 0 && o.z % q == 0;
            let (copy_lo, copy_hi) = if lattice && c + 1 < chain_levels {
                (ceil_div(lo, q), floor_div(hi, q))
            } else {
                (IVec3::ZERO, IVec3::ZERO)
            };
            steps.push(NestStep {
                chain: c,
                params: NestParams {
                    lo: box_lo.to_array(),
                    window: k as u32,
                    size: (box_hi - box_lo).as_uvec3().to_array(),
                    copy_lo: copy_lo.to_array(),
                    copy_hi: copy_hi.to_array(),
                    finer_lo: floor_div(o, q).to_array(),
                    ..NestParams::zeroed()
                },
            });
        }
    }
    steps
}

/// The steps after a move from `old` to `new` (`nest_steps`; `old` may hold several moves'
/// steps): window by window, chain level by chain level, the box around the old boxes filtered
/// again from its children (the texels the finer window left hold its copies), then the new
/// box, for each window whose boxes changed. At most one restoring step a window and level.
fn restore_then(old: &[NestStep], new: &[NestStep]) -> Vec<NestStep> {
    let of = |steps: &[NestStep], w: u32| -> Vec<NestStep> {
        steps
            .iter()
            .filter(|s| s.params.window == w)
            .copied()
            .collect()
    };
    let windows = old
        .iter()
        .chain(new)
        .map(|s| s.params.window)
        .max()
        .unwrap_or(0);
    let mut out = Vec::new();
    for w in 1..=windows {
        let (was, now) = (of(old, w), of(new, w));
        let chains = was
            .iter()
            .chain(&now)
            .map(|s| s.chain + 1)
            .max()
            .unwrap_or(0);
        for c in 0..chains {
            let boxes: Vec<&NestStep> = was.iter().filter(|s| s.chain == c).collect();
            if let (true, Some(first)) = (was != now, boxes.first()) {
                let lo = boxes
                    .iter()
                    .map(|s| IVec3::from(s.params.lo))
                    .fold(IVec3::MAX, IVec3::min);
                let hi = boxes
                    .iter()
                    .map(|s| {
                        IVec3::from(s.params.lo)
                            + IVec3::from_array(s.params.size.map(|v| v as i32))
                    })
                    .fold(IVec3::MIN, IVec3::max);
                let mut restore = first.restoring();
                restore.params.lo = lo.to_array();
                restore.params.size = (hi - lo).as_uvec3().to_array();
                out.push(restore);
            }
            out.extend(now.iter().filter(|s| s.chain == c));
        }
    }
    out
}

fn floor_div(v: IVec3, q: i32) -> IVec3 {
    IVec3::new(v.x.div_euclid(q), v.y.div_euclid(q), v.z.div_euclid(q))
}

fn ceil_div(v: IVec3, q: i32) -> IVec3 {
    -floor_div(-v, q)
}

/// The nest pass's pipeline (nest.wgsl over the dense filter's code).
pub struct NestPass {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
}

impl NestPass {
    /// Compiles the pipeline; group 0 is the dense filter's (`filter`, its steps' layout).
    pub fn new(device: &wgpu::Device, filter: &wgpu::BindGroupLayout) -> Self {
        let c = wgpu::ShaderStages::COMPUTE;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("nest"),
            entries: &[layout::texture_3d_load(0, c), layout::uniform(1, c, true)],
        });
        let module = module_for(device, "voxels/clipmap/nest.wgsl", &super::KIND.shaders);
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("nest"),
            bind_group_layouts: &[Some(filter), Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("nest"),
            layout: Some(&pipeline_layout),
            module: &module,
            entry_point: Some("main"),
            compilation_options: Default::default(),
            cache: None,
        });
        NestPass { pipeline, layout }
    }
}

/// A clipmap's nest: its steps, their parameters and the bind groups over its volume.
pub struct Nest {
    /// The steps for the windows as they lie.
    steps: Vec<NestStep>,
    /// After a move, the steps that first restore what the old ones copied, then nest.
    moved: Vec<NestStep>,
    /// The old steps `moved` restores (until it has run: a later move restores them too).
    old: Vec<NestStep>,
    /// Whether the next nest runs `moved` (once, the first after the move).
    restore: AtomicBool,
    params: wgpu::Buffer,
    /// Whether `params` holds the steps (written before the next nest otherwise).
    current: AtomicBool,
    /// Per chain level c, with the finer window's level c + 1 (the top level, which copies
    /// nothing, with its own level below).
    binds: Vec<wgpu::BindGroup>,
}

impl Nest {
    /// The nest of `volume`'s windows (its levels' textures), placed later by `place`.
    pub fn new(device: &wgpu::Device, pass: &NestPass, volume: &DenseVolume) -> Self {
        let chain_levels = volume.grid.levels() - 1;
        // The top level's `finer` is the level below it: a different mip from its own.
        debug_assert!(
            chain_levels >= 2,
            "a clipmap of {}³ voxels",
            volume.grid.resolution
        );
        // `moved` (restoring and nesting every window's chain levels), then the steps.
        let most = 3 * (volume.windows as u64 - 1) * chain_levels as u64;
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("nest params"),
            size: most.max(1) * STRIDE,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let binds = (0..chain_levels)
            .map(|c| {
                let finer = mip_view(
                    &volume.chains,
                    if c + 1 < chain_levels {
                        c + 1
                    } else {
                        c.saturating_sub(1)
                    },
                );
                device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("nest"),
                    layout: &pass.layout,
                    entries: &layout::entries(vec![
                        wgpu::BindingResource::TextureView(&finer),
                        wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                            buffer: &params,
                            offset: 0,
                            size: wgpu::BufferSize::new(size_of::<NestParams>() as u64),
                        }),
                    ]),
                })
            })
            .collect();
        Nest {
            steps: Vec::new(),
            moved: Vec::new(),
            old: Vec::new(),
            restore: false.into(),
            params,
            current: true.into(),
            binds,
        }
    }

    /// Places the steps for windows `levels` (`nest_steps`); the next nest first restores
    /// what the old steps copied.
    pub fn place(&mut self, levels: &[Grid]) {
        // A bind group per chain level.
        let steps = nest_steps(levels, self.binds.len() as u32);
        if steps != self.steps {
            let mut old = std::mem::take(&mut self.steps);
            if self.restore.load(Ordering::Relaxed) {
                old.extend(&self.old);
            }
            self.moved = restore_then(&old, &steps);
            self.old = old;
            self.steps = steps;
            self.restore.store(true, Ordering::Relaxed);
            self.current.store(false, Ordering::Relaxed);
        }
    }

    /// GPU memory it holds.
    pub fn memory(&self) -> u64 {
        self.params.size()
    }

    /// Records the steps' parameters (`moved`'s, then the steps') when they changed since the
    /// last time (before the frame's filters).
    pub fn record_params(&self, device: &wgpu::Device, encoder: &mut wgpu::CommandEncoder) {
        if self.current.swap(true, Ordering::Relaxed) {
            return;
        }
        let all: Vec<&NestStep> = self.moved.iter().chain(&self.steps).collect();
        if all.is_empty() {
            return;
        }
        let mut bytes = vec![0u8; all.len() * STRIDE as usize];
        for (i, s) in all.iter().enumerate() {
            let at = i * STRIDE as usize;
            bytes[at..at + size_of::<NestParams>()].copy_from_slice(bytemuck::bytes_of(&s.params));
        }
        let staging = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("nest params (staging)"),
            contents: &bytes,
            usage: wgpu::BufferUsages::COPY_SRC,
        });
        encoder.copy_buffer_to_buffer(&staging, 0, &self.params, 0, staging.size());
    }

    /// Records the nest of `volume`'s windows after its filter: the first time after a move
    /// `moved`, later the steps. Timed as "nest".
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        pass: &NestPass,
        volume: &DenseVolume,
        timer: &mut GpuTimer,
    ) {
        let (steps, first) = if self.restore.swap(false, Ordering::Relaxed) {
            (&self.moved, 0)
        } else {
            (&self.steps, self.moved.len())
        };
        if steps.is_empty() {
            return;
        }
        let (_, filter) = volume.filter();
        let blocks = volume.chain_blocks();
        // A step that only copies (its box wholly inside the finer window and on its lattice:
        // every step of the chain levels whose texels are at most the windows' offset, all
        // the texels but a few hundred) is a texture copy, a block at a time; the others filter
        // and copy in the pass. Steps run in order: each reads what the steps before wrote.
        let mut at = 0;
        while at < steps.len() {
            let copies = steps[at..].iter().take_while(|s| s.copies_only()).count();
            if copies > 0 {
                timer.encoder("nest", encoder, |encoder| {
                    for s in &steps[at..at + copies] {
                        copy_step(encoder, volume, s, blocks);
                    }
                });
            }
            at += copies;
            let filters = steps[at..].iter().take_while(|s| !s.copies_only()).count();
            if filters == 0 {
                continue;
            }
            let mut cpass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("nest"),
                timestamp_writes: timer.compute("nest"),
            });
            cpass.set_pipeline(&pass.pipeline);
            for (i, s) in steps[at..at + filters].iter().enumerate() {
                let (group, offset) = filter.step(s.chain);
                cpass.set_bind_group(0, group, &[offset]);
                let param = ((first + at + i) as u64 * STRIDE) as u32;
                cpass.set_bind_group(1, &self.binds[s.chain as usize], &[param]);
                let size = s.params.size;
                cpass.dispatch_workgroups(
                    size[0].div_ceil(4),
                    size[1].div_ceil(4),
                    (size[2] * blocks).div_ceil(4),
                );
            }
            at += filters;
        }
    }
}

/// Copies step `s`'s box (all of it copied: `NestStep::copies_only`) from the finer window's
/// chain level above, block by block (`blocks` directions stacked along z, each holding the
/// windows stacked along z).
fn copy_step(encoder: &mut wgpu::CommandEncoder, volume: &DenseVolume, s: &NestStep, blocks: u32) {
    let p = &s.params;
    let n = volume.grid.resolution >> (s.chain + 1);
    let (m, w, k) = (n / 2, volume.windows, p.window);
    let lo = IVec3::from(p.copy_lo).as_uvec3();
    let from = (IVec3::from(p.copy_lo) - IVec3::from(p.finer_lo)).as_uvec3();
    for b in 0..blocks {
        encoder.copy_texture_to_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &volume.chains,
                mip_level: s.chain + 1,
                origin: wgpu::Origin3d {
                    x: from.x,
                    y: from.y,
                    z: b * m * w + (k - 1) * m + from.z,
                },
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyTextureInfo {
                texture: &volume.chains,
                mip_level: s.chain,
                origin: wgpu::Origin3d {
                    x: lo.x,
                    y: lo.y,
                    z: b * n * w + k * n + lo.z,
                },
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::Extent3d {
                width: p.size[0],
                height: p.size[1],
                depth_or_array_layers: p.size[2],
            },
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn level(origin: Vec3, voxel_size: f32) -> Grid {
        Grid {
            origin,
            voxel_size,
            resolution: 16,
        }
    }

    #[test]
    fn nested_windows_copy_where_their_lattices_meet_and_filter_astride() {
        // Level 1 (voxels of 2) from 0; level 0 (voxels of 1) 4 of level 1's voxels in, so
        // its 8 level-1 voxels are [4, 12) on each axis.
        let levels = [level(Vec3::splat(8.0), 1.0), level(Vec3::ZERO, 2.0)];
        // The four chain levels above 16³: 8, 4, 2 and 1 texels a side.
        let steps = nest_steps(&levels, 4);
        assert_eq!(steps.len(), 4);
        // Chain 0 (texels of 2 voxels): [2, 6), all copied, from 2 texels in.
        let c0 = steps[0].params;
        assert_eq!((c0.lo, c0.size), ([2; 3], [4; 3]));
        assert_eq!(
            (c0.copy_lo, c0.copy_hi, c0.finer_lo),
            ([2; 3], [6; 3], [2; 3])
        );
        // Boxes wholly copied are texture copies; the others run the pass.
        let copied: Vec<bool> = steps.iter().map(NestStep::copies_only).collect();
        assert_eq!(copied, [true, true, false, false]);
        // Chain 1 (texels of 4): [1, 3), copied.
        let c1 = steps[1].params;
        assert_eq!(
            (c1.lo, c1.size, c1.copy_lo, c1.copy_hi),
            ([1; 3], [2; 3], [1; 3], [3; 3])
        );
        // Chain 2 (texels of 8): [4, 12) lies astride texels 0 and 1: refiltered, none copied.
        let c2 = steps[2].params;
        assert_eq!((c2.lo, c2.size), ([0; 3], [2; 3]));
        assert_eq!(c2.copy_lo, c2.copy_hi);
        // The top level: refiltered.
        assert_eq!(steps[3].params.copy_lo, steps[3].params.copy_hi);
    }

    #[test]
    fn a_window_off_the_finer_lattice_keeps_its_own_and_a_strayed_one_nests_its_overlap() {
        // Half a coarse voxel off: nothing nested.
        let off = [level(Vec3::new(9.0, 8.0, 8.0), 1.0), level(Vec3::ZERO, 2.0)];
        assert!(nest_steps(&off, 4).is_empty());
        // The finer window poking out below along x (a coarser window waiting its turn): only
        // the overlap, voxels [0, 6), is nested. Chain 0: texels [0, 3), from -1 in the finer
        // window's.
        let strayed = [
            level(Vec3::new(-4.0, 8.0, 8.0), 1.0),
            level(Vec3::ZERO, 2.0),
        ];
        let c0 = nest_steps(&strayed, 4)[0].params;
        assert_eq!((c0.lo[0], c0.size[0]), (0, 3));
        assert_eq!((c0.copy_lo[0], c0.copy_hi[0], c0.finer_lo[0]), (0, 3, -1));
    }

    #[test]
    fn after_a_move_the_old_boxes_are_filtered_again_before_the_new_ones_nest() {
        let coarse = level(Vec3::ZERO, 2.0);
        let old = nest_steps(&[level(Vec3::splat(8.0), 1.0), coarse], 4);
        let new = nest_steps(&[level(Vec3::new(12.0, 8.0, 8.0), 1.0), coarse], 4);
        let steps = restore_then(&old, &new);
        // Per chain level, the old box with nothing copied, then the new box.
        assert_eq!(steps.len(), 8);
        for c in 0..4 {
            let (restore, nest) = (steps[2 * c], steps[2 * c + 1]);
            assert_eq!((restore.chain, nest.chain), (c as u32, c as u32));
            assert_eq!(restore.params.lo, old[c].params.lo);
            assert_eq!(restore.params.copy_lo, restore.params.copy_hi, "level {c}");
            assert_eq!(nest, new[c]);
        }
        // Nothing moved: nothing to restore.
        assert_eq!(restore_then(&new, &new), new);
        // Two moves before a nest ran: one box around both old ones a level.
        let both: Vec<NestStep> = old.iter().chain(&new).copied().collect();
        let back = restore_then(&both, &old);
        assert_eq!(back.len(), 8);
        let c0 = back[0].params;
        assert_eq!((c0.lo, c0.size), ([2; 3], [5, 4, 4]));
        assert_eq!(c0.copy_lo, c0.copy_hi);
    }
}
