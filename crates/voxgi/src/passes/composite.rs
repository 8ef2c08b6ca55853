//! composite: deferred shading of direct light and emission into the HDR target, with the
//! indirect light and cone-traced visibility upsampled from the gather's resolution.

use crate::brdf::BrdfTables;
use crate::gpu::layout;
use crate::gpu::shader::specialized_pipeline;
use crate::gpu::timer::GpuTimer;
use crate::gpu_scene::GpuScene;
use crate::shadow_atlas::ShadowAtlas;
use crate::targets::FrameTargets;

const FILTERABLE: wgpu::TextureSampleType = wgpu::TextureSampleType::Float { filterable: true };

/// Format of the HDR target the composite writes: linear radiance, RGBA f32 (read back by
/// headless rendering and tone mapped to the output).
pub const HDR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

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
    pub fn new(device: &wgpu::Device, shadow_maps: bool, specular: bool) -> Self {
        let c = wgpu::ShaderStages::COMPUTE;
        let mut entries = vec![layout::uniform(0, c, false)];
        entries.extend(ShadowAtlas::lighting_layout(c));
        entries.extend(FrameTargets::gbuffer_layout(4, c));
        entries.extend([
            layout::storage_texture(8, HDR_FORMAT),
            layout::texture_2d_load(9, c),
            layout::texture_2d_load(10, c),
            layout::texture_2d_load(11, c),
            layout::texture_2d_load(12, c),
            layout::texture(13, c, FILTERABLE, wgpu::TextureViewDimension::D2),
            layout::sampler(14, c),
        ]);
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("composite"),
            entries: &entries,
        });
        let constants = [
            ("SHADOW_MAPS", f64::from(u8::from(shadow_maps))),
            ("SPECULAR", f64::from(u8::from(specular))),
        ];
        let pipeline =
            specialized_pipeline(device, "composite", "composite.wgsl", &layout, &constants);
        CompositePass { pipeline, layout }
    }

    // The pass reads everything the frame has made so far; a struct for it would only rename.
    /// Records the composite over the whole frame (8x8-pixel workgroups) into `t.hdr`, reading the
    /// G-buffer, the upsampled gather results, the shadow atlas and the BRDF tables. Timed as
    /// "composite".
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        t: &FrameTargets,
        scene: &GpuScene,
        atlas: &ShadowAtlas,
        tables: &BrdfTables,
        timer: &mut GpuTimer,
    ) {
        let mut resources = vec![t.frame.as_entire_binding()];
        resources.extend(atlas.lighting_resources(scene));
        resources.extend(t.gbuffer_resources());
        resources.extend([
            wgpu::BindingResource::TextureView(&t.hdr),
            wgpu::BindingResource::TextureView(&t.indirect),
            wgpu::BindingResource::TextureView(&t.visibility_low),
            wgpu::BindingResource::TextureView(&t.guide_low),
            wgpu::BindingResource::TextureView(&tables.ltc),
            wgpu::BindingResource::TextureView(&tables.specular_albedo),
            wgpu::BindingResource::Sampler(&tables.sampler),
        ]);
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("composite"),
            layout: &self.layout,
            entries: &layout::entries(resources),
        });
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("composite"),
            timestamp_writes: timer.compute("composite"),
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &bind, &[]);
        pass.dispatch_workgroups(t.width.div_ceil(8), t.height.div_ceil(8), 1);
    }
}
