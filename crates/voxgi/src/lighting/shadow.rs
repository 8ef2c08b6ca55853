//! shadow: one distance map per shadow view, all in one texture array (the shadow atlas).
//! Directional lights get an orthographic view fitted to the scene, spot lights a perspective
//! one, point and area lights six (a cube around the light).

use crate::gpu::timer::GpuTimer;
use crate::gpu::{layout, shader};
use crate::gpu_scene::GpuScene;
use crate::lighting::atlas::{
    ATLAS_FORMAT, GpuShadowView, ShadowAtlas, UNIFORM_STRIDE, behind_emitter,
};

/// The shadow render pass (shaders/shadow.wgsl): the mesh and surfel pipelines writing distance
/// maps into the shadow atlas, and their bind group layout.
pub struct ShadowPass {
    pipeline: wgpu::RenderPipeline,
    /// Point-cloud surfels: 6 vertices per point, no index buffer.
    points: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
}

impl ShadowPass {
    /// Compiles both pipelines (no culling) and creates their bind group layout.
    pub fn new(device: &wgpu::Device) -> Self {
        let vs = wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shadow"),
            entries: &[
                layout::uniform(0, vs, true),
                layout::storage(1, wgpu::ShaderStages::VERTEX, true),
                layout::storage(2, wgpu::ShaderStages::VERTEX, true),
                layout::storage(3, wgpu::ShaderStages::VERTEX, true),
                layout::storage(4, wgpu::ShaderStages::VERTEX, true),
            ],
        });
        let module = shader::module(device, "lighting/shadow.wgsl");
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("shadow"),
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
                primitive: wgpu::PrimitiveState {
                    cull_mode: None,
                    ..Default::default()
                },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: wgpu::TextureFormat::Depth32Float,
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
                    targets: &[Some(ATLAS_FORMAT.into())],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        ShadowPass {
            pipeline: make("shadow", "vs_main", "fs_main"),
            points: make("shadow points", "vs_points", "fs_points"),
            layout,
        }
    }

    /// Records one render pass per shadow view of `atlas` into its layer (skipping views that only
    /// see the back of their emitter), drawing every mesh except the light's own emitter, and the
    /// points. Only the views `views` marks are rendered (the others keep their maps). Timed as
    /// "shadow" (summed over the views).
    pub fn record(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        atlas: &ShadowAtlas,
        scene: &GpuScene,
        views: &[bool],
        timer: &mut GpuTimer,
    ) {
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("shadow"),
            layout: &self.layout,
            entries: &layout::entries(vec![
                wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &atlas.uniforms,
                    offset: 0,
                    size: wgpu::BufferSize::new(size_of::<GpuShadowView>() as u64),
                }),
                scene.vertices.as_entire_binding(),
                scene.draws.as_entire_binding(),
                scene.points.as_entire_binding(),
                scene.point_spread.as_entire_binding(),
            ]),
        });
        for (i, layer) in atlas.layer_views.iter().enumerate().take(atlas.views.len()) {
            if !views.get(i).copied().unwrap_or(true) || behind_emitter(&atlas.views[i]) {
                continue;
            }
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("shadow"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: layer,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        // Nothing seen: the occluder is infinitely far.
                        load: wgpu::LoadOp::Clear(wgpu::Color {
                            r: 3.0e38,
                            g: 0.0,
                            b: 0.0,
                            a: 0.0,
                        }),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &atlas.depth_view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Discard,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: timer.render("shadow"),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &bind, &[(i as u64 * UNIFORM_STRIDE) as u32]);
            pass.set_index_buffer(scene.indices.slice(..), wgpu::IndexFormat::Uint32);
            let owner = atlas.view_light[i];
            for call in &scene.calls {
                // An emitter does not shadow its own light.
                if call.light == Some(owner) {
                    continue;
                }
                pass.draw_indexed(
                    call.indices.clone(),
                    call.base_vertex,
                    call.draw..call.draw + 1,
                );
            }
            // Points are never an emitter's surface, so they shadow every light.
            if scene.point_count > 0 {
                pass.set_pipeline(&self.points);
                pass.draw(0..scene.point_count * 6, 0..1);
            }
        }
    }
}
