//! splat: every point-cloud sample into voxel fragments through its region of influence (seed
//! 004 §4.3.4). It writes the fragments and their count, nothing else.

use crate::fragments::{Fragments, Geometry};
use crate::gpu::layout;
use crate::gpu::timer::GpuTimer;
use crate::gpu_scene::GpuScene;
use wgpu::util::DeviceExt;

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
                layout::uniform(6, c, false),
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

    /// The pass's bind group over `scene`'s static geometry points (`Geometry::Static`: the
    /// build's) or its dynamic clouds' (`Geometry::Dynamic`: each update's) into `fragments`
    /// on their grid `window` (made once per fragment buffer).
    pub fn bind(
        &self,
        device: &wgpu::Device,
        scene: &GpuScene,
        fragments: &Fragments,
        window: usize,
        which: Geometry,
    ) -> SplatBind {
        let (first, count) = points_of(scene, which);
        let range = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("splat range"),
            contents: bytemuck::cast_slice(&[first, count, 0, 0]),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("splat"),
            layout: &self.layout,
            entries: &layout::entries(vec![
                fragments.windows[window].grid.as_entire_binding(),
                scene.points.as_entire_binding(),
                scene.point_regions.as_entire_binding(),
                fragments.buffer.as_entire_binding(),
                fragments.count.as_entire_binding(),
                fragments.region(window, which),
                range.as_entire_binding(),
            ]),
        });
        SplatBind { group, count }
    }

    /// Records the pass over the points `bind` took, one thread per point, appending to
    /// `fragments` and its count (after `voxelize`, into the same build or update). Timed as
    /// "splat".
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        bind: Option<&SplatBind>,
        timer: &mut GpuTimer,
    ) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("splat"),
            timestamp_writes: timer.compute("splat"),
        });
        // Area lights' surfaces are not voxelized (see `triangle_table`); they follow the
        // geometry's points.
        let Some(bind) = bind.filter(|b| b.count > 0) else {
            return;
        };
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &bind.group, &[]);
        let (x, y) = layout::groups_2d(bind.count, 64);
        pass.dispatch_workgroups(x, y, 1);
    }
}

/// A splat bind group and how many points it splats.
pub struct SplatBind {
    group: wgpu::BindGroup,
    count: u32,
}

/// The first point and the count of `scene`'s static geometry points or its dynamic ones.
pub fn points_of(scene: &GpuScene, which: Geometry) -> (u32, u32) {
    match which {
        Geometry::Static => (0, scene.static_points),
        Geometry::Dynamic => (
            scene.static_points,
            scene.geometry_points - scene.static_points,
        ),
    }
}
