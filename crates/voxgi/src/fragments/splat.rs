//! splat: every point-cloud sample into voxel fragments through its region of influence (seed
//! 004 §4.3.4). It writes the fragments and their count, nothing else.

use crate::fragments::{Fragments, Geometry};
use crate::gpu::layout;
use crate::gpu::timer::GpuTimer;
use crate::gpu_scene::GpuScene;

/// The splat compute pass (shaders/fragments/splat.wgsl): its pipeline and bind group layout.
pub struct SplatPass {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
}

impl SplatPass {
    /// Compiles the pipeline and creates its bind group layout.
    pub fn new(device: &wgpu::Device) -> Self {
        let c = wgpu::ShaderStages::COMPUTE;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("splat"),
            entries: &[
                layout::uniform(0, c, false),
                layout::storage(1, c, true),
                layout::storage(2, c, true),
                layout::storage(3, c, false),
                layout::storage(4, c, false),
                layout::uniform(5, c, false),
            ],
        });
        let pipeline = crate::gpu::shader::grouped_pipeline(
            device,
            "splat",
            "fragments/splat.wgsl",
            &[Some(&layout)],
            &[],
        );
        SplatPass { pipeline, layout }
    }

    /// The pass's bind group over `scene`'s geometry points into `fragments` (made once per
    /// fragment buffer).
    pub fn bind(
        &self,
        device: &wgpu::Device,
        scene: &GpuScene,
        fragments: &Fragments,
    ) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("splat"),
            layout: &self.layout,
            entries: &layout::entries(vec![
                fragments.grid_uniform.as_entire_binding(),
                scene.points.as_entire_binding(),
                // The shader's point count is this binding's length.
                wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &scene.point_regions,
                    offset: 0,
                    size: wgpu::BufferSize::new(scene.geometry_points as u64 * 4),
                }),
                fragments.buffer.as_entire_binding(),
                fragments.count.as_entire_binding(),
                fragments.region(Geometry::Static),
            ]),
        })
    }

    /// Records the pass over every point of `scene`, one thread per point, appending to
    /// `fragments` and its count (after `voxelize`, into the same build). Timed as "splat".
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        bind: Option<&wgpu::BindGroup>,
        timer: &mut GpuTimer,
    ) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("splat"),
            timestamp_writes: timer.compute("splat"),
        });
        // Area lights' surfaces are not voxelized (see `triangle_table`); they follow the
        // geometry's points.
        let (Some(bind), true) = (bind, scene.geometry_points > 0) else {
            return;
        };
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, bind, &[]);
        let (x, y) = layout::groups_2d(scene.geometry_points, 64);
        pass.dispatch_workgroups(x, y, 1);
    }
}
