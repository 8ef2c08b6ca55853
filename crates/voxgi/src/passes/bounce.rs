//! bounce: one bounce of light in voxel space over the occupied voxels, then `bounce_store`
//! writes the result into the finest level (a separate dispatch: the volume cannot be sampled
//! and written in one).

use crate::gpu::layout;
use crate::gpu::shader::{compute_pipeline, grouped_pipeline};
use crate::gpu::timer::GpuTimer;
use crate::voxel::VoxelStructure;
use crate::voxel::dense::{DenseVolume, RADIANCE_FORMAT};

pub struct BouncePass {
    gather: wgpu::ComputePipeline,
    globals: wgpu::BindGroupLayout,
    gather_layout: wgpu::BindGroupLayout,
    store: wgpu::ComputePipeline,
    store_layout: wgpu::BindGroupLayout,
}

impl BouncePass {
    pub fn new(device: &wgpu::Device, anisotropic: bool) -> Self {
        let c = wgpu::ShaderStages::COMPUTE;
        let globals = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("bounce globals"),
            entries: &[layout::uniform(0, c, false)],
        });
        let gather_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("bounce"),
            entries: &[
                layout::texture_3d_load(0, c),
                layout::texture_3d_load(1, c),
                layout::storage(2, c, true),
                layout::storage(3, c, true),
                layout::storage(4, c, true),
                layout::storage(5, c, false),
            ],
        });
        let store_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("bounce_store"),
            entries: &[
                layout::uniform(0, c, false),
                layout::storage(1, c, true),
                layout::storage(2, c, true),
                layout::storage(3, c, true),
                layout::storage_texture_3d(4, RADIANCE_FORMAT),
            ],
        });
        let voxels = DenseVolume::sampling_layout(device);
        BouncePass {
            gather: grouped_pipeline(
                device,
                "bounce",
                "bounce.wgsl",
                &[&globals, &voxels, &gather_layout],
                &DenseVolume::sampling_constants(anisotropic, 3),
            ),
            store: compute_pipeline(device, "bounce", "bounce_store.wgsl", &store_layout),
            globals,
            gather_layout,
            store_layout,
        }
    }

    pub fn record(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        vol: &DenseVolume,
        cones: &wgpu::Buffer,
        timer: &mut GpuTimer,
    ) {
        let v = |t: &wgpu::Texture| t.create_view(&Default::default());
        let (albedo, normal) = (v(&vol.albedo), v(&vol.normal));
        let globals = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("bounce globals"),
            layout: &self.globals,
            entries: &layout::entries(vec![cones.as_entire_binding()]),
        });
        let gather_bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("bounce"),
            layout: &self.gather_layout,
            entries: &layout::entries(vec![
                wgpu::BindingResource::TextureView(&albedo),
                wgpu::BindingResource::TextureView(&normal),
                vol.slot_voxel.as_entire_binding(),
                vol.counters.as_entire_binding(),
                vol.slot_direct.as_entire_binding(),
                vol.slot_next.as_entire_binding(),
            ]),
        });
        let radiance = v(&vol.radiance);
        let store_bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("bounce_store"),
            layout: &self.store_layout,
            entries: &layout::entries(vec![
                vol.volume.as_entire_binding(),
                vol.slot_voxel.as_entire_binding(),
                vol.counters.as_entire_binding(),
                vol.slot_next.as_entire_binding(),
                wgpu::BindingResource::TextureView(&radiance),
            ]),
        });
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("bounce"),
            timestamp_writes: timer.compute("bounce"),
        });
        pass.set_pipeline(&self.gather);
        pass.set_bind_group(0, &globals, &[]);
        pass.set_bind_group(1, vol.sampling(), &[]);
        pass.set_bind_group(2, &gather_bind, &[]);
        pass.dispatch_workgroups_indirect(&vol.args, 0);
        pass.set_pipeline(&self.store);
        pass.set_bind_group(0, &store_bind, &[]);
        pass.dispatch_workgroups_indirect(&vol.args, 0);
    }
}
