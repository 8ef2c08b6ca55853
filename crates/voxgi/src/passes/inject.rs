//! inject: direct light and emission into the finest voxels.

use crate::gpu::layout;
use crate::gpu::shader::compute_pipeline;
use crate::gpu::timer::GpuTimer;
use crate::gpu_scene::GpuScene;
use crate::passes::shadow::ShadowAtlas;
use crate::voxel::dense::{DenseVolume, RADIANCE_FORMAT};
use wgpu::util::DeviceExt;

pub struct InjectPass {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    light_count: wgpu::Buffer,
}

impl InjectPass {
    pub fn new(device: &wgpu::Device, light_count: u32) -> Self {
        let c = wgpu::ShaderStages::COMPUTE;
        let mut entries = vec![layout::uniform(0, c, false)];
        entries.extend(ShadowAtlas::lighting_layout(c));
        entries.extend([
            layout::texture_3d_load(4, c),
            layout::texture_3d_load(5, c),
            layout::texture_3d_load(6, c),
            layout::storage(7, c, true),
            layout::storage(8, c, true),
            layout::storage(9, c, false),
            layout::storage_texture_3d(10, RADIANCE_FORMAT),
            layout::uniform(11, c, false),
        ]);
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("inject"),
            entries: &entries,
        });
        InjectPass {
            pipeline: compute_pipeline(device, "inject", "inject.wgsl", &layout),
            layout,
            light_count: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("inject light count"),
                contents: bytemuck::cast_slice(&[light_count, 0, 0, 0]),
                usage: wgpu::BufferUsages::UNIFORM,
            }),
        }
    }

    pub fn record(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        atlas: &ShadowAtlas,
        vol: &DenseVolume,
        timer: &mut GpuTimer,
    ) {
        let v = |t: &wgpu::Texture| t.create_view(&Default::default());
        let (a, n, e, r) = (
            v(&vol.albedo),
            v(&vol.normal),
            v(&vol.emission),
            v(&vol.radiance),
        );
        let mut resources = vec![vol.volume.as_entire_binding()];
        resources.extend(atlas.lighting_resources(scene));
        resources.extend([
            wgpu::BindingResource::TextureView(&a),
            wgpu::BindingResource::TextureView(&n),
            wgpu::BindingResource::TextureView(&e),
            vol.slot_voxel.as_entire_binding(),
            vol.counters.as_entire_binding(),
            vol.slot_direct.as_entire_binding(),
            wgpu::BindingResource::TextureView(&r),
            self.light_count.as_entire_binding(),
        ]);
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("inject"),
            layout: &self.layout,
            entries: &layout::entries(resources),
        });
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("inject"),
            timestamp_writes: timer.compute("inject"),
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &bind, &[]);
        pass.dispatch_workgroups_indirect(&vol.args, 0);
    }
}
