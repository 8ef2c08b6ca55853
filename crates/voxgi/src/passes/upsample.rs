//! upsample: the gather's interleaved samples (full or half resolution) to full-resolution
//! indirect light and area-light visibility, edge-aware.

use crate::frame::FrameTargets;
use crate::gpu::layout;
use crate::gpu::shader::compute_pipeline;
use crate::gpu::timer::GpuTimer;
use crate::passes::gather::{INDIRECT_FORMAT, VISIBILITY_FORMAT};

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
                layout::texture(
                    3,
                    c,
                    wgpu::TextureSampleType::Depth,
                    wgpu::TextureViewDimension::D2,
                ),
                layout::storage_texture(4, INDIRECT_FORMAT),
                layout::texture_2d_load(5, c),
                layout::storage_texture(6, VISIBILITY_FORMAT),
                layout::texture_2d_load(7, c),
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
        let low = &t.indirect_low;
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("upsample"),
            layout: &self.layout,
            entries: &layout::entries(vec![
                t.frame.as_entire_binding(),
                wgpu::BindingResource::TextureView(low),
                wgpu::BindingResource::TextureView(&t.normal),
                wgpu::BindingResource::TextureView(&t.depth),
                wgpu::BindingResource::TextureView(&t.indirect),
                wgpu::BindingResource::TextureView(&t.visibility_low),
                wgpu::BindingResource::TextureView(&t.visibility),
                wgpu::BindingResource::TextureView(&t.guide_low),
            ]),
        });
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("upsample"),
            timestamp_writes: timer.compute("upsample"),
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &bind, &[]);
        pass.dispatch_workgroups(t.width.div_ceil(8), t.height.div_ceil(8), 1);
    }
}
