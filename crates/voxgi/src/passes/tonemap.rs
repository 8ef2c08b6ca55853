//! tonemap: exposure, filmic curve and sRGB encoding into the 8-bit output.

use crate::frame::FrameTargets;
use crate::gpu::layout;
use crate::gpu::shader::compute_pipeline;
use crate::gpu::timer::GpuTimer;

pub const LDR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

pub struct TonemapPass {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
}

impl TonemapPass {
    pub fn new(device: &wgpu::Device) -> Self {
        let c = wgpu::ShaderStages::COMPUTE;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("tonemap"),
            entries: &[
                layout::uniform(0, c, false),
                layout::texture_2d_load(1, c),
                layout::storage_texture(2, LDR_FORMAT),
            ],
        });
        let pipeline = compute_pipeline(device, "tonemap", "tonemap.wgsl", &layout);
        TonemapPass { pipeline, layout }
    }

    pub fn record(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        t: &FrameTargets,
        timer: &mut GpuTimer,
    ) {
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("tonemap"),
            layout: &self.layout,
            entries: &layout::entries(vec![
                t.frame.as_entire_binding(),
                wgpu::BindingResource::TextureView(&t.hdr),
                wgpu::BindingResource::TextureView(&t.ldr),
            ]),
        });
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("tonemap"),
            timestamp_writes: timer.compute("tonemap"),
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &bind, &[]);
        pass.dispatch_workgroups(t.width.div_ceil(8), t.height.div_ceil(8), 1);
    }
}
