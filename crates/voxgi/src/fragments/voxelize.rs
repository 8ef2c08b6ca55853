//! voxelize: every mesh triangle into voxel fragments (conservative, exact overlap). It writes
//! the fragments and their count, nothing else.

use crate::fragments::{Fragments, Geometry, REGION_STRIDE, TableSpan, TriangleTable};
use crate::gpu::layout;
use crate::gpu::timer::GpuTimer;
use crate::gpu_scene::GpuScene;

/// The voxelize compute pass (shaders/fragments/voxelize.wgsl): its pipeline and bind group layout.
pub struct VoxelizePass {
    /// A workgroup per triangle (or share of a large one's columns).
    pipeline: wgpu::ComputePipeline,
    /// A thread per small triangle.
    small: wgpu::ComputePipeline,
    /// For the dynamic geometry: fragments weighted by how much of their voxel is inside.
    dynamic: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
}

impl VoxelizePass {
    /// Compiles the pipeline and creates its bind group layout.
    pub fn new(device: &wgpu::Device) -> Self {
        let c = wgpu::ShaderStages::COMPUTE;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("voxelize"),
            entries: &[
                layout::uniform(0, c, false),
                layout::storage(1, c, true),
                layout::storage(2, c, true),
                layout::storage(3, c, true),
                layout::storage(4, c, true),
                layout::texture(
                    5,
                    c,
                    wgpu::TextureSampleType::Float { filterable: true },
                    wgpu::TextureViewDimension::D2Array,
                ),
                layout::sampler(6, c),
                layout::storage(7, c, true),
                layout::storage(8, c, false),
                layout::storage(9, c, false),
                layout::uniform(10, c, false),
                layout::storage(11, c, true),
                layout::uniform(12, c, true),
            ],
        });
        let layouts = [Some(&layout)];
        let make = |coverage: f64, entry: &str| {
            crate::gpu::shader::grouped_pipeline_entry(
                device,
                "voxelize",
                "fragments/voxelize.wgsl",
                entry,
                &layouts,
                &[
                    ("DYNAMIC_COVERAGE", coverage),
                    ("CHUNK_COLUMNS", crate::fragments::CHUNK_COLUMNS as f64),
                ],
            )
        };
        VoxelizePass {
            pipeline: make(0.0, "main"),
            small: make(0.0, "small"),
            dynamic: make(1.0, "main"),
            layout,
        }
    }

    /// The pass's bind group over `triangles` into `fragments` on their grid `window` (made
    /// once per fragment buffer).
    pub fn bind(
        &self,
        device: &wgpu::Device,
        scene: &GpuScene,
        triangles: &TriangleTable,
        fragments: &Fragments,
        window: usize,
    ) -> wgpu::BindGroup {
        let geometry = if triangles.dynamic {
            Geometry::Dynamic
        } else {
            Geometry::Static
        };
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("voxelize"),
            layout: &self.layout,
            entries: &layout::entries(vec![
                fragments.windows[window].grid.as_entire_binding(),
                scene.vertices.as_entire_binding(),
                scene.indices.as_entire_binding(),
                scene.draws.as_entire_binding(),
                scene.materials.as_entire_binding(),
                wgpu::BindingResource::TextureView(&scene.texture_view),
                wgpu::BindingResource::Sampler(&scene.sampler),
                triangles.buffer.as_entire_binding(),
                fragments.buffer.as_entire_binding(),
                fragments.count.as_entire_binding(),
                fragments.region(window, geometry),
                scene.draw_bounds.as_entire_binding(),
                fragments.spans(window, geometry),
            ]),
        })
    }

    /// Records the pass over `spans` of `triangles` (a thread per small triangle, a workgroup
    /// per other table entry), appending to `fragments` and its count; clear the count first
    /// (`Fragments::record_clear`). `spans` are those `Fragments::set_spans` wrote for the
    /// bind group's window, in order. A dynamic table's fragments carry coverage. Timed as
    /// "voxelize".
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        triangles: &TriangleTable,
        spans: &[TableSpan],
        bind: &wgpu::BindGroup,
        timer: &mut GpuTimer,
    ) {
        if spans.is_empty() {
            return;
        }
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("voxelize"),
            timestamp_writes: timer.compute("voxelize"),
        });
        let large = if triangles.dynamic {
            &self.dynamic
        } else {
            &self.pipeline
        };
        for (k, span) in spans.iter().enumerate() {
            pass.set_bind_group(0, bind, &[k as u32 * REGION_STRIDE as u32]);
            // Only static tables hold small triangles (`triangle_table`).
            if span.small_count > 0 {
                pass.set_pipeline(&self.small);
                let (x, y) = layout::groups_2d(span.small_count, 64);
                pass.dispatch_workgroups(x, y, 1);
            }
            if span.large_count > 0 {
                pass.set_pipeline(large);
                let (x, y) = layout::groups_2d(span.large_count, 1);
                pass.dispatch_workgroups(x, y, 1);
            }
        }
    }
}
