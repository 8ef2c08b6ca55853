//! bounce: one bounce of light in voxel space over the occupied voxels, then `bounce_store`
//! writes the result into the finest level (a separate dispatch: the volume cannot be sampled
//! and written in one).

use crate::gpu::layout;
use crate::gpu::shader::voxel_pipeline;
use crate::gpu::timer::GpuTimer;
use crate::voxel::{VoxelKind, VoxelStructure};

/// The bounce pass (shaders/bounce.wgsl and bounce_store.wgsl): the gather and store pipelines
/// and the layout of their cone uniform.
pub struct BouncePass {
    gather: wgpu::ComputePipeline,
    globals: wgpu::BindGroupLayout,
    store: wgpu::ComputePipeline,
}

impl BouncePass {
    /// Compiles both pipelines for structure `kind`; `anisotropic` must match the structure's
    /// mode (the gather samples all three axes of an anisotropic one).
    pub fn new(device: &wgpu::Device, kind: VoxelKind, anisotropic: bool) -> Self {
        let c = wgpu::ShaderStages::COMPUTE;
        let globals = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("bounce globals"),
            entries: &[layout::uniform(0, c, false)],
        });
        let voxels = kind.sampling_layout(device);
        let leaves = kind.leaves_layout(device);
        let store = kind.leaf_store_layout(device);
        BouncePass {
            gather: voxel_pipeline(
                device,
                "bounce",
                "lighting/bounce.wgsl",
                kind.name(),
                &[Some(&globals), Some(&voxels), Some(&leaves)],
                &kind.sampling_constants(anisotropic, 3),
            ),
            store: voxel_pipeline(
                device,
                "bounce",
                "lighting/bounce_store.wgsl",
                kind.name(),
                &[None, None, Some(&leaves), Some(&store)],
                &[],
            ),
            globals,
        }
    }

    /// Records one bounce over the leaves of `voxels` with the diffuse cones in `cones` (`Cones` in
    /// shared/volume.wgsl), then the store into the finest level, both as indirect dispatches timed
    /// as "bounce". The volume must be filtered again before it is sampled.
    pub fn record(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        voxels: &dyn VoxelStructure,
        cones: &wgpu::Buffer,
        timer: &mut GpuTimer,
    ) {
        let globals = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("bounce globals"),
            layout: &self.globals,
            entries: &layout::entries(vec![cones.as_entire_binding()]),
        });
        let (args, offset) = voxels.leaf_dispatch();
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("bounce"),
            timestamp_writes: timer.compute("bounce"),
        });
        pass.set_pipeline(&self.gather);
        pass.set_bind_group(0, &globals, &[]);
        pass.set_bind_group(1, voxels.sampling(), &[]);
        pass.set_bind_group(2, voxels.leaves(), &[]);
        pass.dispatch_workgroups_indirect(args, offset);
        pass.set_pipeline(&self.store);
        pass.set_bind_group(3, voxels.leaf_store(), &[]);
        pass.dispatch_workgroups_indirect(args, offset);
    }
}
