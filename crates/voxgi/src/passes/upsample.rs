//! upsample, stage one of two: the gather's interleaved samples filtered at the gather's own
//! resolution (full or half), edge-aware, so each holds every rotation of the cone bundle. The
//! composite finishes the upsample with an edge-aware 2x2 filter at full resolution (joint
//! bilateral upsampling): the wide window runs on a quarter of the pixels at half resolution.

use crate::gpu::layout;
use crate::gpu::shader::compute_pipeline;
use crate::gpu::timer::GpuTimer;
use crate::passes::gather::INDIRECT_FORMAT;
use crate::targets::FrameTargets;

pub struct UpsamplePass {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
}

impl UpsamplePass {
    pub fn new(device: &wgpu::Device) -> Self {
        let c = wgpu::ShaderStages::COMPUTE;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("upsample"),
            entries: &[
                layout::uniform(0, c, false),
                layout::texture_2d_load(1, c),
                layout::texture_2d_load(2, c),
                layout::storage_texture(3, INDIRECT_FORMAT),
            ],
        });
        UpsamplePass {
            pipeline: compute_pipeline(device, "upsample", "upsample.wgsl", &layout),
            layout,
        }
    }

    pub fn record(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        t: &FrameTargets,
        timer: &mut GpuTimer,
    ) {
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("upsample"),
            layout: &self.layout,
            entries: &layout::entries(vec![
                t.frame.as_entire_binding(),
                wgpu::BindingResource::TextureView(&t.indirect_low),
                wgpu::BindingResource::TextureView(&t.guide_low),
                wgpu::BindingResource::TextureView(&t.indirect),
            ]),
        });
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("upsample"),
            timestamp_writes: timer.compute("upsample"),
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &bind, &[]);
        let (w, h) = t.gather_size();
        pass.dispatch_workgroups(w.div_ceil(8), h.div_ceil(8), 1);
    }
}
