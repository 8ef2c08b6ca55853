//! composite: deferred shading of direct light and emission into the HDR target, with the
//! indirect light and cone-traced visibility upsampled from the gather's resolution.

use crate::frame::formats::HDR_FORMAT;
use crate::frame::targets::FrameTargets;
use crate::gpu::layout;
use crate::gpu::shader::grouped_pipeline;
use crate::gpu::timer::GpuTimer;
use crate::options::ShadowFilter;

/// The composite compute pass (shaders/composite.wgsl): its pipeline and bind group layout.
pub struct CompositePass {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
}

impl CompositePass {
    /// `shadow_maps`: whether any light's visibility comes from the shadow maps
    /// (`composite_reads_shadow_maps`); without, the shader is compiled without their lookup.
    /// `specular`: whether any surface has a specular lobe (`gather::has_glossy`); without, the
    /// area lights' specular integral is compiled out.
    /// `filter`: the shadow filter of point, spot and directional lights.
    pub fn new(
        device: &wgpu::Device,
        shadow_maps: bool,
        specular: bool,
        filter: ShadowFilter,
    ) -> Self {
        let c = wgpu::ShaderStages::COMPUTE;
        let mut entries = FrameTargets::gbuffer_layout(0, c).to_vec();
        entries.extend([
            layout::storage_texture(4, HDR_FORMAT),
            layout::texture_2d_load(5, c),
            layout::texture_2d_load(6, c),
            layout::texture_2d_load(7, c),
            layout::texture_2d_load(8, c),
        ]);
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("composite"),
            entries: &entries,
        });
        let constants = [
            ("SHADOW_MAPS", f64::from(u8::from(shadow_maps))),
            ("SPECULAR", f64::from(u8::from(specular))),
            (
                "SHADOW_MOMENTS",
                f64::from(u8::from(filter == ShadowFilter::VsmEsm)),
            ),
        ];
        let globals = crate::frame::globals::layout(device);
        let pipeline = grouped_pipeline(
            device,
            "composite",
            "screen/composite.wgsl",
            &[Some(&globals), None, Some(&layout)],
            &constants,
        );
        CompositePass { pipeline, layout }
    }

    /// The pass's own bind group for these targets (made once per targets).
    pub fn bind(&self, device: &wgpu::Device, t: &FrameTargets) -> wgpu::BindGroup {
        let mut resources = t.gbuffer_resources().to_vec();
        resources.extend([
            wgpu::BindingResource::TextureView(&t.hdr),
            wgpu::BindingResource::TextureView(&t.indirect),
            wgpu::BindingResource::TextureView(&t.visibility_low),
            wgpu::BindingResource::TextureView(&t.guide_low),
            wgpu::BindingResource::TextureView(&t.motion),
        ]);
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("composite"),
            layout: &self.layout,
            entries: &layout::entries(resources),
        })
    }

    /// Records the composite over the whole frame (8x8-pixel workgroups) into `t.hdr`, reading the
    /// G-buffer, the upsampled gather results and the frame's `globals` (lights, shadow atlas,
    /// BRDF tables). Timed as "composite".
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        t: &FrameTargets,
        globals: &wgpu::BindGroup,
        bind: &wgpu::BindGroup,
        timer: &mut GpuTimer,
    ) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("composite"),
            timestamp_writes: timer.compute("composite"),
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, globals, &[]);
        pass.set_bind_group(2, bind, &[]);
        pass.dispatch_workgroups(t.width.div_ceil(8), t.height.div_ceil(8), 1);
    }
}
