//! temporal: accumulates the composite's radiance over frames into the history (reprojected
//! by the G-buffer's motion vectors, disocclusion tested, clipped while anything moves,
//! averaged while nothing does). Runs only with temporal accumulation on; `tonemap` then reads
//! the history it wrote instead of the HDR target.

use crate::frame::formats::{HISTORY_FORMAT, HISTORY_GEOMETRY_FORMAT};
use crate::frame::targets::FrameTargets;
use crate::gpu::layout;
use crate::gpu::shader::grouped_pipeline;
use crate::gpu::timer::GpuTimer;

/// The temporal compute pass (shaders/screen/temporal.wgsl): its pipeline and bind group
/// layout.
pub struct TemporalPass {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
}

impl TemporalPass {
    /// Compiles the pipeline and creates its bind group layout.
    pub fn new(device: &wgpu::Device) -> Self {
        let c = wgpu::ShaderStages::COMPUTE;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("temporal"),
            entries: &[
                layout::texture_2d_load(0, c),
                layout::texture_2d_load(1, c),
                layout::texture_2d_load(2, c),
                layout::texture(
                    3,
                    c,
                    wgpu::TextureSampleType::Depth,
                    wgpu::TextureViewDimension::D2,
                ),
                layout::texture_2d_load(4, c),
                layout::texture_2d_load(5, c),
                layout::storage_texture(6, HISTORY_FORMAT),
                layout::storage_texture(7, HISTORY_GEOMETRY_FORMAT),
            ],
        });
        let globals = crate::frame::globals::layout(device);
        TemporalPass {
            pipeline: grouped_pipeline(
                device,
                "temporal",
                "screen/temporal.wgsl",
                &[Some(&globals), None, Some(&layout)],
                &[],
            ),
            layout,
        }
    }

    /// The pass's two bind groups for these targets: `[i]` reads history `i` and writes the
    /// other. `None` without a history.
    pub fn bind(&self, device: &wgpu::Device, t: &FrameTargets) -> Option<[wgpu::BindGroup; 2]> {
        let h = t.history.as_ref()?;
        let make = |from: usize| {
            let to = 1 - from;
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("temporal"),
                layout: &self.layout,
                entries: &layout::entries(vec![
                    wgpu::BindingResource::TextureView(&t.hdr),
                    wgpu::BindingResource::TextureView(&t.motion),
                    wgpu::BindingResource::TextureView(&t.normal),
                    wgpu::BindingResource::TextureView(&t.depth),
                    wgpu::BindingResource::TextureView(&h.color_views[from]),
                    wgpu::BindingResource::TextureView(&h.geometry[from]),
                    wgpu::BindingResource::TextureView(&h.color_views[to]),
                    wgpu::BindingResource::TextureView(&h.geometry[to]),
                ]),
            })
        };
        Some([make(0), make(1)])
    }

    /// Records the pass over the whole frame (8x8-pixel workgroups) with `bind`, one of
    /// `bind`'s pair. Timed as "temporal".
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        t: &FrameTargets,
        globals: &wgpu::BindGroup,
        bind: &wgpu::BindGroup,
        timer: &mut GpuTimer,
    ) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("temporal"),
            timestamp_writes: timer.compute("temporal"),
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, globals, &[]);
        pass.set_bind_group(2, bind, &[]);
        pass.dispatch_workgroups(t.width.div_ceil(8), t.height.div_ceil(8), 1);
    }
}
