//! inject: direct light and emission into the voxel structure's leaves.

use crate::gpu::layout;
use crate::gpu::shader::grouped_pipeline;
use crate::gpu::timer::GpuTimer;
use crate::gpu_scene::GpuScene;
use crate::lighting::atlas::ShadowAtlas;
use crate::voxel::VoxelStructure;
use crate::voxel::dense::DenseVolume;
use wgpu::util::DeviceExt;

/// The inject compute pass (shaders/inject.wgsl): its pipeline, the layout of its globals, and
/// the uniform holding the scene's light count.
pub struct InjectPass {
    pipeline: wgpu::ComputePipeline,
    /// The same without storing the radiance (progressive bounces).
    direct_only: wgpu::ComputePipeline,
    globals: wgpu::BindGroupLayout,
    light_count: wgpu::Buffer,
}

impl InjectPass {
    /// Compiles the pipeline for a scene of `light_count` lights (fixed until the pass is rebuilt).
    pub fn new(device: &wgpu::Device, light_count: u32) -> Self {
        let c = wgpu::ShaderStages::COMPUTE;
        let mut entries = vec![layout::uniform(0, c, false)];
        entries.extend(ShadowAtlas::lighting_layout(c));
        let globals = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("inject globals"),
            entries: &entries,
        });
        let leaves = DenseVolume::leaves_layout(device);
        let store = DenseVolume::leaf_store_layout(device);
        let layouts = [Some(&globals), None, Some(&leaves), Some(&store)];
        InjectPass {
            pipeline: grouped_pipeline(device, "inject", "lighting/inject.wgsl", &layouts, &[]),
            direct_only: grouped_pipeline(
                device,
                "inject",
                "lighting/inject.wgsl",
                &layouts,
                &[("STORE_RADIANCE", 0.0)],
            ),
            globals,
            light_count: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("inject light count"),
                contents: bytemuck::cast_slice(&[light_count, 0, 0, 0]),
                usage: wgpu::BufferUsages::UNIFORM,
            }),
        }
    }

    /// Records the injection of direct light (shadowed by `atlas`) and emission into every leaf of
    /// `voxels` as an indirect dispatch: the leaves' direct light and their radiance. Timed as
    /// "inject".
    pub fn record(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        atlas: &ShadowAtlas,
        voxels: &dyn VoxelStructure,
        timer: &mut GpuTimer,
    ) {
        self.record_with(&self.pipeline, device, encoder, scene, atlas, voxels, timer);
    }

    /// `record`, but the leaves' radiance is kept: only their direct light is renewed (for
    /// progressive bounces, which build on the last update's radiance).
    pub fn record_direct_only(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        atlas: &ShadowAtlas,
        voxels: &dyn VoxelStructure,
        timer: &mut GpuTimer,
    ) {
        self.record_with(
            &self.direct_only,
            device,
            encoder,
            scene,
            atlas,
            voxels,
            timer,
        );
    }

    #[allow(clippy::too_many_arguments)]
    fn record_with(
        &self,
        pipeline: &wgpu::ComputePipeline,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        atlas: &ShadowAtlas,
        voxels: &dyn VoxelStructure,
        timer: &mut GpuTimer,
    ) {
        let mut resources = vec![self.light_count.as_entire_binding()];
        resources.extend(atlas.lighting_resources(scene));
        let globals = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("inject globals"),
            layout: &self.globals,
            entries: &layout::entries(resources),
        });
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("inject"),
            timestamp_writes: timer.compute("inject"),
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &globals, &[]);
        pass.set_bind_group(2, voxels.leaves(), &[]);
        pass.set_bind_group(3, voxels.leaf_store(), &[]);
        let (args, offset) = voxels.leaf_dispatch();
        pass.dispatch_workgroups_indirect(args, offset);
    }
}
