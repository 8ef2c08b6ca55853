//! gbuffer: rasterizes all mesh instances into the G-buffer (motion vectors included), then every point-cloud sample as a
//! surfel (an oriented disc) into the same targets, depth-tested against the meshes.

use crate::frame::formats::{
    ALBEDO_FORMAT, DEPTH_FORMAT, EMISSION_FORMAT, MOTION_FORMAT, NORMAL_FORMAT,
};
use crate::frame::targets::FrameTargets;
use crate::gpu::timer::GpuTimer;
use crate::gpu::{layout, shader};
use crate::gpu_scene::GpuScene;

/// The G-buffer render pass (shaders/gbuffer.wgsl): the mesh and surfel pipelines and their
/// shared bind group layout.
pub struct GbufferPass {
    pipeline: wgpu::RenderPipeline,
    /// Surfels: 6 vertices per point, no index buffer.
    points: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
}

impl GbufferPass {
    /// Compiles both pipelines (no culling) and creates their bind group layout.
    pub fn new(device: &wgpu::Device) -> Self {
        let vf = wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("gbuffer"),
            entries: &[
                layout::uniform(0, vf, false),
                layout::storage(1, wgpu::ShaderStages::VERTEX, true),
                layout::storage(2, vf, true),
                layout::storage(3, wgpu::ShaderStages::FRAGMENT, true),
                layout::texture(
                    4,
                    wgpu::ShaderStages::FRAGMENT,
                    wgpu::TextureSampleType::Float { filterable: true },
                    wgpu::TextureViewDimension::D2Array,
                ),
                layout::sampler(5, wgpu::ShaderStages::FRAGMENT),
                layout::storage(6, wgpu::ShaderStages::VERTEX, true),
                layout::storage(7, wgpu::ShaderStages::VERTEX, true),
                layout::storage(8, wgpu::ShaderStages::VERTEX, true),
                layout::storage(9, wgpu::ShaderStages::VERTEX, true),
            ],
        });
        let module = shader::module(device, "screen/gbuffer.wgsl");
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("gbuffer"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let make = |label: &str, vs: &str, fs: &str| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(&pipeline_layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some(vs),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                // No culling: OBJ and PLY files often mix windings; back faces flip their normal.
                primitive: wgpu::PrimitiveState {
                    cull_mode: None,
                    ..Default::default()
                },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: DEPTH_FORMAT,
                    depth_write_enabled: Some(true),
                    depth_compare: Some(wgpu::CompareFunction::Less),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some(fs),
                    compilation_options: Default::default(),
                    targets: &[
                        Some(ALBEDO_FORMAT.into()),
                        Some(NORMAL_FORMAT.into()),
                        Some(EMISSION_FORMAT.into()),
                        Some(MOTION_FORMAT.into()),
                    ],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        GbufferPass {
            pipeline: make("gbuffer", "vs_main", "fs_main"),
            points: make("gbuffer points", "vs_points", "fs_points"),
            layout,
        }
    }

    /// The pass's bind group for these targets and this scene (made once per targets).
    pub fn bind(
        &self,
        device: &wgpu::Device,
        t: &FrameTargets,
        scene: &GpuScene,
    ) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("gbuffer"),
            layout: &self.layout,
            entries: &layout::entries(vec![
                t.frame.as_entire_binding(),
                scene.vertices.as_entire_binding(),
                scene.draws.as_entire_binding(),
                scene.materials.as_entire_binding(),
                wgpu::BindingResource::TextureView(&scene.texture_view),
                wgpu::BindingResource::Sampler(&scene.sampler),
                scene.points.as_entire_binding(),
                scene.point_spread.as_entire_binding(),
                scene.prev_models.as_entire_binding(),
                scene.point_motion.as_entire_binding(),
            ]),
        })
    }

    /// Records the pass: clears the G-buffer targets of `t`, draws every mesh draw call of `scene`,
    /// then its points as surfels. Timed as "gbuffer".
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        t: &FrameTargets,
        scene: &GpuScene,
        bind: &wgpu::BindGroup,
        timer: &mut GpuTimer,
    ) {
        let clear = |view| {
            Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                    store: wgpu::StoreOp::Store,
                },
            })
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("gbuffer"),
            color_attachments: &[
                clear(&t.albedo),
                clear(&t.normal),
                clear(&t.emission),
                clear(&t.motion),
            ],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &t.depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: timer.render("gbuffer"),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, bind, &[]);
        pass.set_index_buffer(scene.indices.slice(..), wgpu::IndexFormat::Uint32);
        for call in &scene.calls {
            pass.draw_indexed(
                call.indices.clone(),
                call.base_vertex,
                call.draw..call.draw + 1,
            );
        }
        if scene.point_count > 0 {
            pass.set_pipeline(&self.points);
            pass.draw(0..scene.point_count * 6, 0..1);
        }
    }
}
