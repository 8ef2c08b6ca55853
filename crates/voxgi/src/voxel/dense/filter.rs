//! filter: the volume's mip levels above the finest, isotropic or six-directional.

use super::{DenseVolume, RADIANCE_FORMAT, mip_view};
use crate::gpu::layout;
use crate::gpu::shader::voxel_pipeline;
use crate::gpu::timer::GpuTimer;
use crate::voxel::{Filtering, Grid};
use wgpu::util::DeviceExt;

const STRIDE: u64 = 256;

/// The filter compute pass (shaders/voxels/dense/filter.wgsl): its pipeline and bind group layout.
pub struct FilterPass {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
}

/// One dispatch: read mip `src` of the chains (None: the finest level), write mip `dst` of
/// every block of the chains.
struct Step {
    src: Option<u32>,
    dst: u32,
    params: [u32; 4],
}

impl FilterPass {
    /// Compiles the pipeline and creates its bind group layout.
    pub fn new(device: &wgpu::Device) -> Self {
        let c = wgpu::ShaderStages::COMPUTE;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("filter"),
            entries: &[
                layout::uniform(0, c, true),
                layout::texture_3d_load(1, c),
                layout::storage_texture_3d(2, RADIANCE_FORMAT),
                layout::texture_3d_load(3, c),
            ],
        });
        FilterPass {
            pipeline: voxel_pipeline(
                device,
                "filter",
                "voxels/dense/filter.wgsl",
                &super::KIND.shaders,
                &[Some(&layout)],
                &[],
            ),
            layout,
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
                    params: [mode, res >> level, src.is_some() as u32, ndf as u32],
                }
            })
            .collect()
    }

    /// The bind groups of every level's step for a volume on `grid` with these textures (the
    /// finest level's `radiance` and `normal`, the `chains` above), with their parameters:
    /// made once per volume (they bind only its own textures).
    pub fn bind(
        &self,
        device: &wgpu::Device,
        grid: Grid,
        filtering: Filtering,
        [radiance, chains, normal]: [&wgpu::Texture; 3],
    ) -> FilterBinds {
        let steps = Self::steps(grid, filtering);
        let mut bytes = vec![0u8; steps.len() * STRIDE as usize];
        for (i, s) in steps.iter().enumerate() {
            bytes[i * STRIDE as usize..i * STRIDE as usize + 16]
                .copy_from_slice(bytemuck::cast_slice(&s.params));
        }
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
                            size: wgpu::BufferSize::new(16),
                        }),
                        wgpu::BindingResource::TextureView(&src),
                        wgpu::BindingResource::TextureView(&dst),
                        wgpu::BindingResource::TextureView(&normals),
                    ]),
                })
            })
            .collect();
        FilterBinds {
            _params: params,
            binds,
            steps,
        }
    }

    /// Records the filtering of every level above the finest, coarsest last: one dispatch per
    /// level, each reading the level below it (the finest level's `radiance` for the first) and
    /// writing every block of `chains` (`binds`, from `bind`). Timed as "filter" (summed over
    /// the levels).
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        vol: &DenseVolume,
        binds: &FilterBinds,
        timer: &mut GpuTimer,
    ) {
        let (steps, binds) = (&binds.steps, &binds.binds);
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("filter"),
            timestamp_writes: timer.compute("filter"),
        });
        pass.set_pipeline(&self.pipeline);
        for (i, (s, b)) in steps.iter().zip(binds).enumerate() {
            pass.set_bind_group(0, b, &[(i as u64 * STRIDE) as u32]);
            let n = s.params[1].div_ceil(4);
            let depth = (s.params[1] * vol.chain_blocks()).div_ceil(4);
            pass.dispatch_workgroups(n, n, depth);
        }
    }
}

/// The dense filter's bind groups for one volume (`FilterPass::bind`).
pub struct FilterBinds {
    /// Every step's parameters at its dynamic offset; bound by `binds`.
    _params: wgpu::Buffer,
    binds: Vec<wgpu::BindGroup>,
    steps: Vec<Step>,
}
