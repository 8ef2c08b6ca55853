//! gather: per-pixel indirect light from the voxels (diffuse cones with AO, glossy cone) and,
//! with `cone_shadows`, the visibility of area lights by a cone, at full or half resolution.

use crate::brdf::BrdfTables;
use crate::gpu::layout;
use crate::gpu::shader::specialized_pipeline;
use crate::gpu::timer::GpuTimer;
use crate::gpu_scene::GpuScene;
use crate::options::RendererOptions;
use crate::targets::FrameTargets;
use crate::voxel::dense::DenseVolume;
use voxgi_scene::Scene;

pub const INDIRECT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// Cone-traced visibility of up to four area lights.
pub const VISIBILITY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
/// The gather pixels' geometry for the upsample's edge weights: normal (rgb) and distance to
/// the camera (a; 0 for background).
pub const GUIDE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// Whether anything on screen can have a specular lobe: a material with specular or metallic
/// reflectance, or a point cloud (surfels shade with half the dielectric specular).
pub fn has_glossy(scene: &Scene, point_count: u32) -> bool {
    point_count > 0
        || scene
            .materials
            .iter()
            .any(|m| m.specular > 0.0 || m.metallic > 0.0)
}

pub struct GatherPass {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
}

impl GatherPass {
    /// `glossy`: whether any surface may have a specular lobe (`has_glossy`).
    pub fn new(device: &wgpu::Device, settings: &RendererOptions, glossy: bool) -> Self {
        let c = wgpu::ShaderStages::COMPUTE;
        let mut entries = vec![
            layout::uniform(0, c, false),
            layout::uniform(1, c, false),
            layout::uniform(2, c, false),
        ];
        entries.extend(DenseVolume::sampling_layout(3, c));
        entries.extend(FrameTargets::gbuffer_layout(6, c));
        entries.extend([
            layout::storage_texture(10, INDIRECT_FORMAT),
            layout::storage(11, c, true),
            layout::storage_texture(12, VISIBILITY_FORMAT),
            layout::storage_texture(13, GUIDE_FORMAT),
            layout::texture(
                14,
                c,
                wgpu::TextureSampleType::Float { filterable: true },
                wgpu::TextureViewDimension::D2,
            ),
        ]);
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("gather"),
            entries: &entries,
        });
        let [iso, axes] =
            DenseVolume::sampling_constants(settings.anisotropic, settings.gather_axes);
        let constants = [iso, axes, ("GLOSSY", f64::from(u8::from(glossy)))];
        GatherPass {
            pipeline: specialized_pipeline(device, "gather", "gather.wgsl", &layout, &constants),
            layout,
        }
    }

    // The pass reads what the frame and the volume hold; a struct for it would only rename.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        t: &FrameTargets,
        scene: &GpuScene,
        vol: &DenseVolume,
        cones: &wgpu::Buffer,
        tables: &BrdfTables,
        timer: &mut GpuTimer,
    ) {
        let views = vol.sampling_views();
        let mut res = vec![
            t.frame.as_entire_binding(),
            vol.volume.as_entire_binding(),
            cones.as_entire_binding(),
        ];
        res.extend(views.iter().map(wgpu::BindingResource::TextureView));
        res.push(wgpu::BindingResource::Sampler(&vol.sampler));
        res.extend(t.gbuffer_resources());
        res.extend([
            wgpu::BindingResource::TextureView(&t.indirect_low),
            scene.lights.as_entire_binding(),
            wgpu::BindingResource::TextureView(&t.visibility_low),
            wgpu::BindingResource::TextureView(&t.guide_low),
            wgpu::BindingResource::TextureView(&tables.specular_albedo),
        ]);
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("gather"),
            layout: &self.layout,
            entries: &layout::entries(res),
        });
        let (w, h) = t.gather_size();
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("gather"),
            timestamp_writes: timer.compute("gather"),
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &bind, &[]);
        pass.dispatch_workgroups(w.div_ceil(8), h.div_ceil(8), 1);
    }
}
