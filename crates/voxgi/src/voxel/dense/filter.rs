//! filter: the volume's mip levels above the finest, isotropic or six-directional.

use super::{RADIANCE_FORMAT, mip_view};
use crate::gpu::layout;
use crate::gpu::shader::module_for;
use crate::gpu::timer::GpuTimer;
use crate::voxel::{Filtering, Grid};
use wgpu::util::DeviceExt;

const STRIDE: u64 = 256;
/// Bytes of a level's box (`LevelBox` in filter.wgsl).
const BOX_BYTES: u64 = 32;

/// The filter compute pass (shaders/voxels/dense/filter.wgsl): its pipelines (`region`, then
/// `main` once per level) and bind group layouts.
pub struct FilterPass {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    region: wgpu::ComputePipeline,
    region_layout: wgpu::BindGroupLayout,
}

/// One dispatch: read mip `src` of the chains (None: the finest level), write mip `dst` of
/// the chains' blocks, within the box `region` found for it.
struct Step {
    src: Option<u32>,
    dst: u32,
    params: [u32; 8],
}

impl FilterPass {
    /// Compiles the pipelines (one module, two entry points) and creates their layouts.
    pub fn new(device: &wgpu::Device) -> Self {
        let c = wgpu::ShaderStages::COMPUTE;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("filter"),
            entries: &[
                layout::uniform(0, c, true),
                layout::texture_3d_load(1, c),
                layout::storage_texture_3d(2, RADIANCE_FORMAT),
                layout::texture_3d_load(3, c),
                layout::storage(4, c, true),
            ],
        });
        // `region` binds apart from the levels (filter.wgsl's bindings 5 to 8 of group 0).
        let region_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("filter region"),
            entries: &[
                layout::uniform(5, c, false),
                layout::storage(6, c, false),
                layout::storage(7, c, false),
                layout::storage(8, c, false),
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
            pipeline: pipeline("main", &layout),
            region: pipeline("region", &region_layout),
            layout,
            region_layout,
        }
    }

    fn steps(grid: Grid, filtering: Filtering) -> Vec<Step> {
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
                        0,
                        0,
                        0,
                    ],
                }
            })
            .collect()
    }

    /// The bind groups of every level's step for a volume on `grid` with these textures (the
    /// finest level's `radiance` and `normal`, the `chains` above) and its box of written
    /// voxels (in `counters`), with their parameters: made once per volume (they bind only its
    /// own resources).
    pub fn bind(
        &self,
        device: &wgpu::Device,
        grid: Grid,
        filtering: Filtering,
        [radiance, chains, normal]: [&wgpu::Texture; 3],
        counters: &wgpu::Buffer,
    ) -> FilterBinds {
        let steps = Self::steps(grid, filtering);
        let mut bytes = vec![0u8; steps.len() * STRIDE as usize];
        for (i, s) in steps.iter().enumerate() {
            bytes[i * STRIDE as usize..i * STRIDE as usize + 32]
                .copy_from_slice(bytemuck::cast_slice(&s.params));
        }
        let n = steps.len().max(1) as u64;
        let boxes = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("filter boxes"),
            size: n * BOX_BYTES,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        let args = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("filter dispatch sizes"),
            size: n * 12,
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::INDIRECT
                | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let blocks = super::chain_blocks(filtering.anisotropic);
        let region = |all: bool| {
            let params = [grid.resolution, steps.len() as u32, blocks, all as u32];
            let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("filter region"),
                contents: bytemuck::cast_slice(&params),
                usage: wgpu::BufferUsages::UNIFORM,
            });
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("filter region"),
                layout: &self.region_layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 5,
                        resource: uniform.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 6,
                        resource: counters.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 7,
                        resource: boxes.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 8,
                        resource: args.as_entire_binding(),
                    },
                ],
            })
        };
        let region = [region(false), region(true)];
        let params = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("filter params"),
            contents: &bytes,
            usage: wgpu::BufferUsages::UNIFORM,
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
                device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("filter"),
                    layout: &self.layout,
                    entries: &layout::entries(vec![
                        wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                            buffer: &params,
                            offset: 0,
                            size: wgpu::BufferSize::new(32),
                        }),
                        wgpu::BindingResource::TextureView(&src),
                        wgpu::BindingResource::TextureView(&dst),
                        wgpu::BindingResource::TextureView(&normals),
                        boxes.as_entire_binding(),
                    ]),
                })
            })
            .collect();
        let whole = steps
            .iter()
            .map(|s| [s.params[1].div_ceil(4), (s.params[1] * blocks).div_ceil(4)])
            .collect();
        FilterBinds {
            _params: params,
            binds,
            whole,
            region,
            args,
        }
    }

    /// Records the filtering of the levels above the finest, coarsest last: `region` finds
    /// each level's voxels above the finest ones written since the last filter (every voxel
    /// with `all`, after a build) and empties that box; then one dispatch per level, each
    /// reading the level below it (the finest level's `radiance` for the first) and writing
    /// its box in every block of `chains` (`binds`, from `bind`). Timed as "filter" (summed
    /// over the steps).
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
            pass.set_pipeline(&self.region);
            pass.set_bind_group(0, &binds.region[all as usize], &[]);
            pass.dispatch_workgroups(1, 1, 1);
        }
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("filter"),
            timestamp_writes: timer.compute("filter"),
        });
        pass.set_pipeline(&self.pipeline);
        for (i, b) in binds.binds.iter().enumerate() {
            pass.set_bind_group(0, b, &[(i as u64 * STRIDE) as u32]);
            if all {
                // The whole level, sized here: an indirect dispatch makes a CPU driver wait
                // for `region` before it starts, for nothing.
                let [n, depth] = binds.whole[i];
                pass.dispatch_workgroups(n, n, depth);
            } else {
                pass.dispatch_workgroups_indirect(&binds.args, i as u64 * 12);
            }
        }
    }
}

/// The dense filter's bind groups for one volume (`FilterPass::bind`).
pub struct FilterBinds {
    /// Every step's parameters at its dynamic offset; bound by `binds`.
    _params: wgpu::Buffer,
    binds: Vec<wgpu::BindGroup>,
    /// Each level's workgroups when it is filtered whole: across, and along z (every block).
    whole: Vec<[u32; 2]>,
    /// `region`'s bind group: `[0]` the written box, `[1]` the whole volume.
    region: [wgpu::BindGroup; 2],
    /// Each level's dispatch size, written by `region`.
    pub(super) args: wgpu::Buffer,
}
