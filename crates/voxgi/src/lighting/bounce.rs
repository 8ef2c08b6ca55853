//! bounce: one bounce of light in voxel space over the occupied voxels, then `bounce_store`
//! writes the result into the finest level (a separate dispatch: the volume cannot be sampled
//! and written in one). For the fast shading the gather also keeps every leaf's irradiance.

use crate::gpu::layout;
use crate::gpu::shader::voxel_pipeline;
use crate::gpu::timer::GpuTimer;
use crate::voxel::{VoxelKind, VoxelStructure};

/// What one bounce records.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BounceSteps {
    /// Keep every leaf's irradiance and occlusion (`VoxelStructure::leaf_irradiance`) for the
    /// fast shading.
    pub irradiance: bool,
    /// Write the bounced radiance into the finest level (the volume must then be filtered).
    pub store: bool,
}

/// The bounce pass (shaders/bounce.wgsl and bounce_store.wgsl): the gather and store pipelines
/// and the layout of their cone uniform and irradiance records.
pub struct BouncePass {
    gather: wgpu::ComputePipeline,
    /// Made for the fast shading only.
    gather_irradiance: Option<wgpu::ComputePipeline>,
    globals: wgpu::BindGroupLayout,
    store: wgpu::ComputePipeline,
}

impl BouncePass {
    /// Compiles the pipelines for structure `kind`; `anisotropic` must match the structure's
    /// mode (the gather samples all three axes of an anisotropic one); `irradiance`: also the
    /// gather that keeps the leaves' irradiance (`BounceSteps::irradiance`).
    pub fn new(
        device: &wgpu::Device,
        kind: VoxelKind,
        anisotropic: bool,
        irradiance: bool,
    ) -> Self {
        let c = wgpu::ShaderStages::COMPUTE;
        let globals = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("bounce globals"),
            entries: &[layout::uniform(0, c, false), layout::storage(1, c, false)],
        });
        let voxels = kind.sampling_layout(device);
        let leaves = kind.leaves_layout(device);
        let store = kind.leaf_store_layout(device);
        let [iso, axes] = kind.sampling_constants(anisotropic, 3);
        let gather = |irradiance: bool| {
            voxel_pipeline(
                device,
                "bounce",
                "lighting/bounce.wgsl",
                kind.shaders(),
                &[Some(&globals), Some(&voxels), Some(&leaves)],
                &[iso, axes, ("IRRADIANCE", f64::from(u8::from(irradiance)))],
            )
        };
        BouncePass {
            gather: gather(false),
            gather_irradiance: irradiance.then(|| gather(true)),
            store: voxel_pipeline(
                device,
                "bounce",
                "lighting/bounce_store.wgsl",
                kind.shaders(),
                &[None, None, Some(&leaves), Some(&store)],
                &[],
            ),
            globals,
        }
    }

    /// The pass's `@group(0)`: the diffuse cones in `cones` (`Cones` in shared/volume.wgsl) and
    /// the leaves' records of `voxels`; made once per structure.
    pub fn bind(
        &self,
        device: &wgpu::Device,
        voxels: &dyn VoxelStructure,
        cones: &wgpu::Buffer,
    ) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("bounce globals"),
            layout: &self.globals,
            entries: &layout::entries(vec![
                cones.as_entire_binding(),
                voxels.bindings().leaf_irradiance.as_entire_binding(),
            ]),
        })
    }

    /// Records one bounce over the leaves of `voxels` with the cones `globals` binds (`bind`),
    /// then, with `steps.store`, the store into the finest level, both as
    /// indirect dispatches timed as "bounce". After a store the volume must be filtered again
    /// before it is sampled.
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        voxels: &dyn VoxelStructure,
        globals: &wgpu::BindGroup,
        steps: BounceSteps,
        timer: &mut GpuTimer,
    ) {
        let bound = voxels.bindings();
        let (args, offset) = bound.leaf_dispatch;
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("bounce"),
            timestamp_writes: timer.compute("bounce"),
        });
        let gather = match (&self.gather_irradiance, steps.irradiance) {
            (Some(p), true) => p,
            (None, true) => panic!("BouncePass::new was not asked for the irradiance gather"),
            (_, false) => &self.gather,
        };
        pass.set_pipeline(gather);
        pass.set_bind_group(0, globals, &[]);
        pass.set_bind_group(1, bound.sampling, &[]);
        pass.set_bind_group(2, bound.leaves, &[]);
        pass.dispatch_workgroups_indirect(args, offset);
        if !steps.store {
            return;
        }
        pass.set_pipeline(&self.store);
        pass.set_bind_group(3, bound.leaf_store, &[]);
        pass.dispatch_workgroups_indirect(args, offset);
    }
}
