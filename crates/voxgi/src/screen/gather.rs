//! gather: per-pixel indirect light from the voxels (diffuse cones with AO, or with
//! `IndirectShading::Leaves` the leaves' interpolated irradiance; glossy cone) and, with
//! `cone_shadows`, the visibility of area lights by a cone, at full or half resolution.
//! Bind groups: 0 the frame's globals, 1 the voxel structure's sampling group, 2 its own, 3 the
//! structure's irradiance lookup.

use crate::frame::formats::{GUIDE_FORMAT, INDIRECT_FORMAT, VISIBILITY_FORMAT};
use crate::frame::targets::FrameTargets;
use crate::gpu::layout;
use crate::gpu::shader::voxel_pipeline;
use crate::gpu::timer::GpuTimer;
use crate::options::{IndirectShading, RendererOptions};
use crate::voxel::VoxelStructure;
use voxgi_scene::Scene;

/// Whether anything on screen can have a specular lobe: a material with specular or metallic
/// reflectance, or a point cloud (surfels shade with half the dielectric specular).
pub fn has_glossy(scene: &Scene, point_count: u32) -> bool {
    point_count > 0
        || scene
            .materials
            .iter()
            .any(|m| m.specular > 0.0 || m.metallic > 0.0)
}

/// The gather compute pass (shaders/gather.wgsl): its pipeline and the layouts of its globals
/// (group 0) and its own targets (group 2).
pub struct GatherPass {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
}

impl GatherPass {
    /// `glossy`: whether any surface may have a specular lobe (`has_glossy`); `lobes`: whether
    /// the voxels keep specular lobes.
    pub fn new(
        device: &wgpu::Device,
        settings: &RendererOptions,
        glossy: bool,
        lobes: bool,
    ) -> Self {
        let c = wgpu::ShaderStages::COMPUTE;
        let globals = crate::frame::globals::layout(device);
        let mut entries = FrameTargets::gbuffer_layout(0, c).to_vec();
        entries.extend([
            layout::storage_texture(4, INDIRECT_FORMAT),
            layout::storage_texture(5, VISIBILITY_FORMAT),
            layout::storage_texture(6, GUIDE_FORMAT),
        ]);
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("gather"),
            entries: &entries,
        });
        let kind = settings.voxels;
        let leaves = settings.indirect == IndirectShading::Leaves;
        let mut constants =
            kind.sampling_constants(settings.anisotropic, lobes, settings.gather_axes);
        constants.extend([
            ("GLOSSY", f64::from(u8::from(glossy))),
            ("LEAVES", f64::from(u8::from(leaves))),
        ]);
        let voxels = kind.sampling_layout(device);
        let irradiance = kind.irradiance_layout(device);
        GatherPass {
            pipeline: voxel_pipeline(
                device,
                "gather",
                "screen/gather.wgsl",
                kind.shaders(),
                &[
                    Some(&globals),
                    Some(&voxels),
                    Some(&layout),
                    Some(&irradiance),
                ],
                &constants,
            ),
            layout,
        }
    }

    /// The pass's own bind group for these targets (made once per targets).
    pub fn bind(&self, device: &wgpu::Device, t: &FrameTargets) -> wgpu::BindGroup {
        let mut res = t.gbuffer_resources().to_vec();
        res.extend([
            wgpu::BindingResource::TextureView(&t.indirect_low),
            wgpu::BindingResource::TextureView(&t.visibility_low),
            wgpu::BindingResource::TextureView(&t.guide_low),
        ]);
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("gather"),
            layout: &self.layout,
            entries: &layout::entries(res),
        })
    }

    /// Records the gather at `t.gather_size()` (8x8-pixel workgroups) into the low-resolution
    /// indirect, visibility and guide targets, sampling `voxels` with the cones of the frame's
    /// `globals`. Timed as "gather".
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        t: &FrameTargets,
        globals: &wgpu::BindGroup,
        voxels: &dyn VoxelStructure,
        own: &wgpu::BindGroup,
        timer: &mut GpuTimer,
    ) {
        let bound = voxels.bindings();
        let (w, h) = t.gather_size();
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("gather"),
            timestamp_writes: timer.compute("gather"),
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, globals, &[]);
        pass.set_bind_group(1, bound.sampling, &[]);
        pass.set_bind_group(2, own, &[]);
        pass.set_bind_group(3, bound.irradiance, &[]);
        pass.dispatch_workgroups(w.div_ceil(8), h.div_ceil(8), 1);
    }
}
