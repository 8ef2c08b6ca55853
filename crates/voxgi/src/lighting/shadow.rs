//! shadow: one distance map per shadow view, all in one texture array (the shadow atlas).
//! Directional lights get an orthographic view fitted to the scene, spot lights a perspective
//! one, point and area lights six (a cube around the light).

use crate::gpu::timer::GpuTimer;
use crate::gpu::{layout, shader};
use crate::gpu_scene::GpuScene;
use crate::lighting::atlas::{
    ATLAS_FORMAT, GpuShadowView, ShadowAtlas, UNIFORM_STRIDE, ViewDirt, behind_emitter,
};

/// The shadow render pass (shaders/shadow.wgsl): the mesh and surfel pipelines writing distance
/// maps into the shadow atlas, and their bind group layout.
pub struct ShadowPass {
    pipeline: wgpu::RenderPipeline,
    /// Point-cloud surfels: 6 vertices per point, no index buffer.
    points: wgpu::RenderPipeline,
    /// Resets the scissored part of a view that is re-rendered only in part.
    clear: wgpu::RenderPipeline,
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
        let make = |label: &str, vs: &str, fs: &str, depth: bool| {
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
                    depth_write_enabled: Some(depth),
                    depth_compare: Some(if depth {
                        wgpu::CompareFunction::Less
                    } else {
                        wgpu::CompareFunction::Always
                    }),
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
            pipeline: make("shadow", "vs_main", "fs_main", true),
            points: make("shadow points", "vs_points", "fs_points", true),
            clear: make("shadow clear", "vs_clear", "fs_clear", false),
            layout,
        }
    }

    /// The pass's bind group over `atlas`'s views and `scene`'s geometry (made once per atlas).
    pub fn bind(
        &self,
        device: &wgpu::Device,
        atlas: &ShadowAtlas,
        scene: &GpuScene,
    ) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
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
        })
    }

    /// Records one render pass per shadow view of `atlas` into its layer (skipping views that only
    /// see the back of their emitter), drawing every mesh except the light's own emitter, and the
    /// points. Only what `views` marks out of date is rendered: a whole view, or a rectangle of
    /// it (scissored: the rest keeps its texels, which are what a full render would give since
    /// nothing there changed). A view that fills only part of its layer (a sample view's
    /// quarter) is rendered through a viewport onto that part. Timed as "shadow" (summed over
    /// the views), and the area lights' sample views as "shadow_samples".
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        atlas: &ShadowAtlas,
        scene: &GpuScene,
        views: &[ViewDirt],
        bind: &wgpu::BindGroup,
        timer: &mut GpuTimer,
    ) {
        for (i, view) in atlas.views.iter().enumerate() {
            let dirt = views.get(i).copied().unwrap_or(ViewDirt::All);
            let res = view.resolution as u32;
            let Some(scissor) = dirt.scissor(res) else {
                continue;
            };
            if behind_emitter(view) {
                continue;
            }
            let layer = &atlas.layer_views[view.layer as usize];
            let [ox, oy] = view.offset;
            // A part of a layer is never cleared whole: the rest belongs to other views.
            let part = view.offset != [0.0; 2] || res != atlas.texture.width();
            let whole = dirt == ViewDirt::All && !part;
            let label = if atlas.sample_views().contains(&i) {
                "shadow_samples"
            } else {
                "shadow"
            };
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some(label),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: layer,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        // Nothing seen: the occluder is infinitely far.
                        load: if whole {
                            wgpu::LoadOp::Clear(wgpu::Color {
                                r: 3.0e38,
                                g: 0.0,
                                b: 0.0,
                                a: 0.0,
                            })
                        } else {
                            wgpu::LoadOp::Load
                        },
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
                timestamp_writes: timer.render(label),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_bind_group(0, bind, &[(i as u64 * UNIFORM_STRIDE) as u32]);
            if part {
                pass.set_viewport(ox, oy, res as f32, res as f32, 0.0, 1.0);
            }
            if !whole {
                let (x, y, w, h) = scissor;
                pass.set_scissor_rect(x + ox as u32, y + oy as u32, w, h);
                pass.set_pipeline(&self.clear);
                pass.draw(0..3, 0..1);
            }
            pass.set_pipeline(&self.pipeline);
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
            if scene.point_count > 0 {
                pass.set_pipeline(&self.points);
                pass.draw(0..scene.geometry_points * 6, 0..1);
                for (range, light) in &scene.emitter_points {
                    if *light != owner {
                        pass.draw(range.start * 6..range.end * 6, 0..1);
                    }
                }
            }
        }
    }
}
