//! filter: the volume's mip levels above the finest, isotropic or six-directional.

use super::{RADIANCE_FORMAT, mip_view};
use crate::gpu::layout;
use crate::gpu::shader::module_for;
use crate::gpu::timer::GpuTimer;
use crate::voxel::{Filtering, Grid};
use wgpu::util::DeviceExt;

const STRIDE: u64 = 256;

/// The filter compute pass (shaders/voxels/dense/filter.wgsl): after a build every level
/// whole (`whole`); after a change, per level, `prepare` sizes a dispatch of `listed` over the
/// voxels whose children changed, and `done` empties the lists.
pub struct FilterPass {
    whole: wgpu::ComputePipeline,
    listed: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    prepare: wgpu::ComputePipeline,
    done: wgpu::ComputePipeline,
    prepare_layout: wgpu::BindGroupLayout,
}

/// One dispatch: read mip `src` of the chains (None: the finest level), write mip `dst` of
/// the chains' blocks.
struct Step {
    src: Option<u32>,
    dst: u32,
    params: [u32; 8],
}

impl FilterPass {
    /// Compiles the pipelines (one module, four entry points) and creates their layouts.
    pub fn new(device: &wgpu::Device) -> Self {
        let c = wgpu::ShaderStages::COMPUTE;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("filter"),
            entries: &[
                layout::uniform(0, c, true),
                layout::texture_3d_load(1, c),
                layout::storage_texture_3d(2, RADIANCE_FORMAT),
                layout::texture_3d_load(3, c),
                // The occupancy and the leaves' direct light (their specular lobes).
                layout::storage(4, c, true),
                layout::storage(5, c, true),
                // The volume's counters: the levels' bits and lists (changed.wgsl).
                layout::storage(6, c, false),
            ],
        });
        // `prepare` writes the dispatch sizes the levels are dispatched by, so they bind apart.
        let prepare_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("filter prepare"),
            entries: &[
                layout::uniform(0, c, true),
                layout::storage(6, c, false),
                layout::storage(7, c, false),
            ],
        });
        let module = module_for(device, "voxels/dense/filter.wgsl", &super::KIND.shaders);
        let pipeline = |entry: &str, layout: &wgpu::BindGroupLayout| {
            let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("filter"),
                bind_group_layouts: &[Some(layout)],
                immediate_size: 0,
            });
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("filter"),
                layout: Some(&pipeline_layout),
                module: &module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        FilterPass {
            whole: pipeline("whole", &layout),
            listed: pipeline("listed", &layout),
            prepare: pipeline("prepare", &prepare_layout),
            done: pipeline("done", &prepare_layout),
            layout,
            prepare_layout,
        }
    }

    fn steps(grid: Grid, windows: u32, filtering: Filtering) -> Vec<Step> {
        let res = grid.resolution;
        let levels = grid.levels();
        let mode = if filtering.anisotropic { 1 } else { 0 };
        (1..levels)
            .map(|level| {
                // Level 1 reads the finest (isotropic) level, one block; later ones their own
                // blocks.
                let src = (level > 1).then(|| level - 2);
                let ndf = filtering.ndf && filtering.anisotropic && src.is_none();
                Step {
                    src,
                    dst: level - 1,
                    params: [
                        mode,
                        res >> level,
                        src.is_some() as u32,
                        ndf as u32,
                        level - 1,
                        windows,
                        (filtering.lobes && filtering.anisotropic) as u32,
                        0,
                    ],
                }
            })
            .collect()
    }

    /// The bind groups of every level's step for a volume on `grid` (`windows` cubes of it
    /// stacked along z) with these textures (the finest level's `radiance` and `normal`, the
    /// `chains` above), its lists of changed voxels (in `counters`), and its `occupancy` and
    /// slots' `direct` light, whose specular lobes the first level takes in, with their
    /// parameters: made once per volume (they bind only its own resources).
    #[allow(clippy::too_many_arguments)]
    pub fn bind(
        &self,
        device: &wgpu::Device,
        grid: Grid,
        windows: u32,
        filtering: Filtering,
        [radiance, chains, normal]: [&wgpu::Texture; 3],
        [counters, occupancy, direct]: [&wgpu::Buffer; 3],
    ) -> FilterBinds {
        let steps = Self::steps(grid, windows, filtering);
        let mut bytes = vec![0u8; steps.len() * STRIDE as usize];
        for (i, s) in steps.iter().enumerate() {
            bytes[i * STRIDE as usize..i * STRIDE as usize + 32]
                .copy_from_slice(bytemuck::cast_slice(&s.params));
        }
        let n = steps.len().max(1) as u64;
        let args = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("filter dispatch sizes"),
            size: n * 12,
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::INDIRECT
                | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let params = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("filter params"),
            contents: &bytes,
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let params_binding = wgpu::BindingResource::Buffer(wgpu::BufferBinding {
            buffer: &params,
            offset: 0,
            size: wgpu::BufferSize::new(32),
        });
        let prepare = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("filter prepare"),
            layout: &self.prepare_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: params_binding.clone(),
                },
                wgpu::BindGroupEntry {
                    binding: 6,
                    resource: counters.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 7,
                    resource: args.as_entire_binding(),
                },
            ],
        });
        let binds: Vec<wgpu::BindGroup> = steps
            .iter()
            .map(|s| {
                let src = match s.src {
                    None => mip_view(radiance, 0),
                    Some(m) => mip_view(chains, m),
                };
                let dst = mip_view(chains, s.dst);
                let normals = mip_view(normal, 0);
                let mut entries = layout::entries(vec![
                    params_binding.clone(),
                    wgpu::BindingResource::TextureView(&src),
                    wgpu::BindingResource::TextureView(&dst),
                    wgpu::BindingResource::TextureView(&normals),
                    occupancy.as_entire_binding(),
                    direct.as_entire_binding(),
                ]);
                entries.push(wgpu::BindGroupEntry {
                    binding: 6,
                    resource: counters.as_entire_binding(),
                });
                device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("filter"),
                    layout: &self.layout,
                    entries: &entries,
                })
            })
            .collect();
        let blocks = filtering.blocks();
        let whole = steps
            .iter()
            .map(|s| {
                [
                    s.params[1].div_ceil(4),
                    (s.params[1] * blocks * windows).div_ceil(4),
                ]
            })
            .collect();
        FilterBinds {
            _params: params,
            binds,
            whole,
            prepare,
            args,
            counters: counters.clone(),
            bits_end: counter_words_before_lists(grid, windows) * 4,
        }
    }

    /// The layout of the steps' bind group (`FilterBinds::step`), for passes that run
    /// filter.wgsl's code on a volume's levels (the clipmap's nest).
    pub fn layout(&self) -> &wgpu::BindGroupLayout {
        &self.layout
    }

    /// Records the filtering of the levels above the finest, coarsest last, each level
    /// reading the one below it (the finest level's `radiance` for the first) and writing
    /// every block of `chains` (`binds`, from `bind`): with `all` (after a build) every voxel,
    /// then the lists emptied; else per level only the voxels listed as having a changed
    /// child, each listing its parent for the next. Timed as "filter" (summed over the steps).
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        binds: &FilterBinds,
        all: bool,
        timer: &mut GpuTimer,
    ) {
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("filter"),
                timestamp_writes: timer.compute("filter"),
            });
            for (i, b) in binds.binds.iter().enumerate() {
                let offset = [(i as u64 * STRIDE) as u32];
                if all {
                    pass.set_pipeline(&self.whole);
                    pass.set_bind_group(0, b, &offset);
                    let [n, depth] = binds.whole[i];
                    pass.dispatch_workgroups(n, n, depth);
                } else {
                    pass.set_pipeline(&self.prepare);
                    pass.set_bind_group(0, &binds.prepare, &offset);
                    pass.dispatch_workgroups(1, 1, 1);
                    pass.set_pipeline(&self.listed);
                    pass.set_bind_group(0, b, &offset);
                    pass.dispatch_workgroups_indirect(&binds.args, i as u64 * 12);
                }
            }
            if !all {
                pass.set_pipeline(&self.done);
                pass.set_bind_group(0, &binds.prepare, &[0]);
                pass.dispatch_workgroups(1, 1, 1);
            }
        }
        if all {
            // The build's writes listed voxels a whole filter has redone: the redone count
            // (word 6) and the levels' counts, and every level's bits (not the windows' slot
            // counts between them, nor the rebuild word 7, which the next build sets).
            encoder.clear_buffer(&binds.counters, 24, Some(4));
            encoder.clear_buffer(&binds.counters, 32, Some(WINDOW_WORDS * 4 - 32));
            let bits = (WINDOW_WORDS + WINDOW_COUNTER_WORDS) * 4;
            encoder.clear_buffer(&binds.counters, bits, Some(binds.bits_end - bits));
        }
    }
}

/// Words of a volume's counters on `grid` (`windows` cubes of it) before its lists: the
/// counters, each level's count (voxels/dense/changed.wgsl's `COUNTS`, ten levels), the
/// windows' slot counts, and each level's bits (a bit per voxel of each level above the
/// finest).
fn counter_words_before_lists(grid: Grid, windows: u32) -> u64 {
    let res = grid.resolution as u64;
    let top = grid.levels() as u64 - 1;
    // changed.wgsl counts ten levels above the finest (a 1024³ volume's).
    debug_assert!(top <= 10, "{top} levels above the finest");
    let bits: u64 = (1..=top)
        .map(|l| ((res >> l).pow(3) * windows as u64).div_ceil(32))
        .sum();
    WINDOW_WORDS + WINDOW_COUNTER_WORDS + bits
}

/// Where the windows' slot counts begin in a volume's counters (`WINDOW_WORDS` in
/// voxels/dense/slots.wgsl), after the fixed words and ten levels' counts.
pub(crate) const WINDOW_WORDS: u64 = 18;
/// The most windows a volume's slots are parted into (`MAX_WINDOWS` there).
pub(crate) const MAX_WINDOWS: u64 = 8;
/// Words per window (`WINDOW_STRIDE` there).
pub(crate) const WINDOW_STRIDE: u64 = 4;
/// A window's word counting the slots its last build kept from before a move (`W_KEPT`
/// there), the last of its words.
pub(crate) const W_KEPT: u64 = 3;
/// The windows' words.
const WINDOW_COUNTER_WORDS: u64 = MAX_WINDOWS * WINDOW_STRIDE;

/// Bytes of a volume's counters on `grid` (`windows` cubes of it; the twin of
/// voxels/dense/changed.wgsl's layout): the counters and bits
/// (`counter_words_before_lists`), then each level's list of changed voxels (room for all of
/// them).
pub fn counter_bytes(grid: Grid, windows: u32) -> u64 {
    let res = grid.resolution as u64;
    let top = grid.levels() as u64 - 1;
    let lists: u64 = (1..=top).map(|l| (res >> l).pow(3) * windows as u64).sum();
    (counter_words_before_lists(grid, windows) + lists) * 4
}

impl FilterBinds {
    /// The bind group of the step writing chain level `c` (reading the one below, or the
    /// finest level for 0), and its dynamic offset.
    pub fn step(&self, c: u32) -> (&wgpu::BindGroup, u32) {
        (&self.binds[c as usize], (c as u64 * STRIDE) as u32)
    }
}

/// The dense filter's bind groups for one volume (`FilterPass::bind`).
pub struct FilterBinds {
    /// Every step's parameters at its dynamic offset; bound by `binds` and `prepare`.
    _params: wgpu::Buffer,
    binds: Vec<wgpu::BindGroup>,
    /// Each level's workgroups when it is filtered whole: across, and along z (every block).
    whole: Vec<[u32; 2]>,
    /// `prepare`'s and `done`'s bind group.
    prepare: wgpu::BindGroup,
    /// Each listed level's dispatch size, written by `prepare`.
    pub(super) args: wgpu::Buffer,
    /// The volume's counters (a handle), cleared after a whole filter.
    counters: wgpu::Buffer,
    /// Bytes of the counters before the lists.
    bits_end: u64,
}
