//! upsample, stage one of two: the gather's interleaved samples filtered at the gather's own
//! resolution (full or half), edge-aware, so each holds every rotation of the cone bundle. The
//! composite finishes the upsample with an edge-aware 2x2 filter at full resolution (joint
//! bilateral upsampling): the wide window runs on a quarter of the pixels at half resolution.

use crate::frame::formats::INDIRECT_FORMAT;
use crate::frame::targets::FrameTargets;
use crate::gpu::layout;
use crate::gpu::shader::grouped_pipeline;
use crate::gpu::timer::GpuTimer;

/// The upsample compute pass, stage one (shaders/upsample.wgsl): its pipeline and bind group
/// layout.
pub struct UpsamplePass {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
}

impl UpsamplePass {
    /// Compiles the pipeline and creates its bind group layout.
    pub fn new(device: &wgpu::Device) -> Self {
        let c = wgpu::ShaderStages::COMPUTE;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("upsample"),
            entries: &[
                layout::texture_2d_load(0, c),
                layout::texture_2d_load(1, c),
                layout::storage_texture(2, INDIRECT_FORMAT),
            ],
        });
        let globals = crate::frame::globals::layout(device);
        UpsamplePass {
            pipeline: grouped_pipeline(
                device,
                "upsample",
                "screen/upsample.wgsl",
                &[Some(&globals), None, Some(&layout)],
                &[],
            ),
            layout,
        }
    }

    /// The pass's own bind group for these targets (made once per targets).
    pub fn bind(&self, device: &wgpu::Device, t: &FrameTargets) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("upsample"),
            layout: &self.layout,
            entries: &layout::entries(vec![
                wgpu::BindingResource::TextureView(&t.indirect_low),
                wgpu::BindingResource::TextureView(&t.guide_low),
                wgpu::BindingResource::TextureView(&t.indirect),
            ]),
        })
    }

    /// Records the edge-aware 5x5 tent filter of `t.indirect_low` (guided by `t.guide_low`) into
    /// `t.indirect`, at the gather's resolution. Timed as "upsample".
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        t: &FrameTargets,
        globals: &wgpu::BindGroup,
        bind: &wgpu::BindGroup,
        timer: &mut GpuTimer,
    ) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("upsample"),
            timestamp_writes: timer.compute("upsample"),
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, globals, &[]);
        pass.set_bind_group(2, bind, &[]);
        let (w, h) = t.gather_size();
        pass.dispatch_workgroups(w.div_ceil(8), h.div_ceil(8), 1);
    }
}
