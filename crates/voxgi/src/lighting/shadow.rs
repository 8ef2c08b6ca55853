//! shadow: one distance map per shadow view, all in one texture array (the shadow atlas).
//! Directional lights get an orthographic view fitted to the scene, spot lights a perspective
//! one, point and area lights six (a cube around the light).

use crate::gpu::timer::GpuTimer;
use crate::gpu::{layout, shader};
use crate::gpu_scene::GpuScene;
use crate::lighting::atlas::{
    ATLAS_FORMAT, GpuShadowView, MATERIAL_ATLAS_FORMAT, ShadowAtlas, UNIFORM_STRIDE, ViewDirt,
    behind_emitter,
};

/// The shadow render pass (shaders/shadow.wgsl): the mesh and surfel pipelines writing distance
/// maps into the shadow atlas (and, in an atlas of two channels, the surfaces' specular
/// materials beside them), and their bind group layout.
pub struct ShadowPass {
    /// For a one-channel atlas (distances).
    distance: Pipelines,
    /// For a two-channel atlas (distances and materials): made by the first `bind` to one.
    with_materials: std::sync::OnceLock<Pipelines>,
    module: wgpu::ShaderModule,
    pipeline_layout: wgpu::PipelineLayout,
    over_layout: wgpu::PipelineLayout,
    layout: wgpu::BindGroupLayout,
    statics_layout: wgpu::BindGroupLayout,
}

/// The pass's pipelines for one atlas format.
struct Pipelines {
    pipeline: wgpu::RenderPipeline,
    /// Point-cloud surfels: 6 vertices per point, no index buffer.
    points: wgpu::RenderPipeline,
    /// Resets the scissored part of a view that is re-rendered only in part.
    clear: wgpu::RenderPipeline,
    /// Meshes and surfels drawn over the static geometry's maps (`StaticMaps`).
    pipeline_over: wgpu::RenderPipeline,
    points_over: wgpu::RenderPipeline,
}

impl Pipelines {
    fn new(
        device: &wgpu::Device,
        module: &wgpu::ShaderModule,
        pipeline_layout: &wgpu::PipelineLayout,
        over_layout: &wgpu::PipelineLayout,
        format: wgpu::TextureFormat,
    ) -> Self {
        let make_with = |pipeline_layout: &wgpu::PipelineLayout,
                         label: &str,
                         vs: &str,
                         fs: &str,
                         depth: bool| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(pipeline_layout),
                vertex: wgpu::VertexState {
                    module,
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
                    module,
                    entry_point: Some(fs),
                    compilation_options: Default::default(),
                    targets: &[Some(format.into())],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let make = |label: &str, vs: &str, fs: &str, depth: bool| {
            make_with(pipeline_layout, label, vs, fs, depth)
        };
        Pipelines {
            pipeline: make("shadow", "vs_main", "fs_main", true),
            points: make("shadow points", "vs_points", "fs_points", true),
            clear: make("shadow clear", "vs_clear", "fs_clear", false),
            pipeline_over: make_with(over_layout, "shadow", "vs_main", "fs_main_over", true),
            points_over: make_with(
                over_layout,
                "shadow points",
                "vs_points",
                "fs_points_over",
                true,
            ),
        }
    }
}

/// The shadow pass's bind groups for one atlas (`ShadowPass::bind`).
pub struct ShadowBind {
    scene: wgpu::BindGroup,
    /// The static geometry's maps, when the atlas keeps them.
    statics: Option<wgpu::BindGroup>,
}

impl ShadowPass {
    /// Compiles the pipelines for a one-channel atlas (no culling) and creates their bind
    /// group layout.
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
                layout::storage(5, wgpu::ShaderStages::FRAGMENT, true),
            ],
        });
        let statics_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shadow statics"),
            entries: &[layout::texture(
                0,
                wgpu::ShaderStages::FRAGMENT,
                wgpu::TextureSampleType::Float { filterable: false },
                wgpu::TextureViewDimension::D2Array,
            )],
        });
        let module = shader::module(device, "lighting/shadow.wgsl");
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("shadow"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let over_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("shadow over statics"),
            bind_group_layouts: &[Some(&layout), Some(&statics_layout)],
            immediate_size: 0,
        });
        ShadowPass {
            distance: Pipelines::new(
                device,
                &module,
                &pipeline_layout,
                &over_layout,
                ATLAS_FORMAT,
            ),
            with_materials: std::sync::OnceLock::new(),
            module,
            pipeline_layout,
            over_layout,
            layout,
            statics_layout,
        }
    }

    /// The pipelines for an atlas of `format` (`bind` made those of a two-channel atlas).
    fn pipelines(&self, format: wgpu::TextureFormat) -> &Pipelines {
        if format == MATERIAL_ATLAS_FORMAT {
            self.with_materials
                .get()
                .expect("ShadowPass::bind comes before record for an atlas")
        } else {
            &self.distance
        }
    }
    /// The pass's bind groups over `atlas`'s views and static maps and `scene`'s geometry
    /// (made once per atlas).
    pub fn bind(&self, device: &wgpu::Device, atlas: &ShadowAtlas, scene: &GpuScene) -> ShadowBind {
        if atlas.texture.format() == MATERIAL_ATLAS_FORMAT {
            self.with_materials.get_or_init(|| {
                Pipelines::new(
                    device,
                    &self.module,
                    &self.pipeline_layout,
                    &self.over_layout,
                    MATERIAL_ATLAS_FORMAT,
                )
            });
        }
        let statics = atlas.statics.as_ref().map(|s| {
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("shadow statics"),
                layout: &self.statics_layout,
                entries: &layout::entries(vec![wgpu::BindingResource::TextureView(&s.array_view)]),
            })
        });
        let scene = device.create_bind_group(&wgpu::BindGroupDescriptor {
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
                scene.materials.as_entire_binding(),
            ]),
        });
        ShadowBind { scene, statics }
    }

    /// Records one render pass per shadow view of `atlas` into its layer (skipping views that only
    /// see the back of their emitter), drawing every mesh except the light's own emitter, and the
    /// points. Only what `views` marks out of date is rendered: a whole view, or a rectangle of
    /// it (scissored: the rest keeps its texels, which are what a full render would give since
    /// nothing there changed). A view that fills only part of its layer (a sample view's
    /// quarter) is rendered through a viewport onto that part. With the static geometry's maps
    /// (`keep_static_maps`) a view other than a sample view is the static
    /// geometry's map (drawn when the view changed), copied, and the dynamic geometry and the
    /// emitters drawn over it: a rectangle costs the dynamic geometry only. Timed as "shadow"
    /// (summed over the views), and the area lights' sample views as "shadow_samples".
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        atlas: &mut ShadowAtlas,
        scene: &GpuScene,
        views: &[ViewDirt],
        bind: &ShadowBind,
        timer: &mut GpuTimer,
    ) {
        let pipelines = self.pipelines(atlas.texture.format());
        for i in 0..atlas.views.len() {
            let view = atlas.views[i];
            let mut dirt = views.get(i).copied().unwrap_or(ViewDirt::All);
            let res = view.resolution as u32;
            if dirt.scissor(res).is_none() || behind_emitter(&view) {
                continue;
            }
            let sample = atlas.sample_views().contains(&i);
            let label = if sample { "shadow_samples" } else { "shadow" };
            let owner = atlas.view_light[i];
            let layer = view.layer as usize;
            let offset = [(i as u64 * UNIFORM_STRIDE) as u32];
            let (Some(maps), Some(statics_bind), false) = (&atlas.statics, &bind.statics, sample)
            else {
                self.record_view(encoder, atlas, scene, i, dirt, &bind.scene, label, timer);
                continue;
            };
            if !maps.fresh[i] {
                // The view changed: its static geometry first, then all of it over that.
                let target = &maps.layer_views[layer];
                let mut pass = begin(encoder, target, true, &atlas.depth_view, label, timer);
                pass.set_bind_group(0, &bind.scene, &offset);
                self.draw(&mut pass, pipelines, scene, owner, Draws::Static, false);
                dirt = ViewDirt::All;
            }
            let Some((x, y, w, h)) = dirt.scissor(res) else {
                continue;
            };
            let texture = |t| wgpu::TexelCopyTextureInfo {
                texture: t,
                mip_level: 0,
                origin: wgpu::Origin3d {
                    x,
                    y,
                    z: view.layer,
                },
                aspect: wgpu::TextureAspect::All,
            };
            encoder.copy_texture_to_texture(
                texture(&maps.texture),
                texture(&atlas.texture),
                wgpu::Extent3d {
                    width: w,
                    height: h,
                    depth_or_array_layers: 1,
                },
            );
            let target = &atlas.layer_views[layer];
            let mut pass = begin(encoder, target, false, &atlas.depth_view, label, timer);
            pass.set_bind_group(0, &bind.scene, &offset);
            pass.set_bind_group(1, statics_bind, &[]);
            pass.set_scissor_rect(x, y, w, h);
            self.draw(&mut pass, pipelines, scene, owner, Draws::Dynamic, true);
            drop(pass);
            if let Some(maps) = &mut atlas.statics {
                maps.fresh[i] = true;
            }
        }
    }

    /// One view drawn whole or in the rectangle `dirt` says, every mesh and point at once.
    #[allow(clippy::too_many_arguments)] // the pass's inputs, one view of them
    fn record_view(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        atlas: &ShadowAtlas,
        scene: &GpuScene,
        i: usize,
        dirt: ViewDirt,
        bind: &wgpu::BindGroup,
        label: &'static str,
        timer: &mut GpuTimer,
    ) {
        let pipelines = self.pipelines(atlas.texture.format());
        let view = &atlas.views[i];
        let res = view.resolution as u32;
        let Some((x, y, w, h)) = dirt.scissor(res) else {
            return;
        };
        let [ox, oy] = view.offset;
        // A part of a layer is never cleared whole: the rest belongs to other views.
        let part = view.offset != [0.0; 2] || res != atlas.texture.width();
        let whole = dirt == ViewDirt::All && !part;
        let layer = &atlas.layer_views[view.layer as usize];
        let mut pass = begin(encoder, layer, whole, &atlas.depth_view, label, timer);
        pass.set_bind_group(0, bind, &[(i as u64 * UNIFORM_STRIDE) as u32]);
        if part {
            pass.set_viewport(ox, oy, res as f32, res as f32, 0.0, 1.0);
        }
        if !whole {
            pass.set_scissor_rect(x + ox as u32, y + oy as u32, w, h);
            pass.set_pipeline(&pipelines.clear);
            pass.draw(0..3, 0..1);
        }
        self.draw(
            &mut pass,
            pipelines,
            scene,
            atlas.view_light[i],
            Draws::All,
            false,
        );
    }

    /// Draws `which` of the scene's meshes and points for a view of light `owner` (never the
    /// light's own emitter), `over` the static geometry's maps or not.
    fn draw(
        &self,
        pass: &mut wgpu::RenderPass,
        pipelines: &Pipelines,
        scene: &GpuScene,
        owner: usize,
        which: Draws,
        over: bool,
    ) {
        let (meshes, points) = if over {
            (&pipelines.pipeline_over, &pipelines.points_over)
        } else {
            (&pipelines.pipeline, &pipelines.points)
        };
        pass.set_pipeline(meshes);
        pass.set_index_buffer(scene.indices.slice(..), wgpu::IndexFormat::Uint32);
        for call in &scene.calls {
            // An emitter does not shadow its own light.
            if call.light == Some(owner) {
                continue;
            }
            // Emitters move with their lights: drawn with the dynamic geometry.
            let dynamic = call.dynamic || call.light.is_some();
            if which.includes(dynamic) {
                pass.draw_indexed(
                    call.indices.clone(),
                    call.base_vertex,
                    call.draw..call.draw + 1,
                );
            }
        }
        if scene.point_count > 0 {
            pass.set_pipeline(points);
            let geometry = match which {
                Draws::All => 0..scene.geometry_points,
                Draws::Static => 0..scene.static_points,
                Draws::Dynamic => scene.static_points..scene.geometry_points,
            };
            if !geometry.is_empty() {
                pass.draw(geometry.start * 6..geometry.end * 6, 0..1);
            }
            if which.includes(true) {
                for (range, light) in &scene.emitter_points {
                    if *light != owner {
                        pass.draw(range.start * 6..range.end * 6, 0..1);
                    }
                }
            }
        }
    }
}

/// Which of the scene's occluders a draw takes.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Draws {
    All,
    /// The geometry that never moves.
    Static,
    /// Dynamic meshes and clouds, and the area lights' emitters.
    Dynamic,
}

impl Draws {
    fn includes(self, dynamic: bool) -> bool {
        match self {
            Draws::All => true,
            Draws::Static => !dynamic,
            Draws::Dynamic => dynamic,
        }
    }
}

/// A render pass into one layer `target` (cleared to "nothing seen" with `clear`), with the
/// atlas's depth buffer `depth` cleared.
fn begin<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    target: &wgpu::TextureView,
    clear: bool,
    depth: &wgpu::TextureView,
    label: &'static str,
    timer: &mut GpuTimer,
) -> wgpu::RenderPass<'e> {
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: target,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                // Nothing seen: the occluder is infinitely far.
                load: if clear {
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
            view: depth,
            depth_ops: Some(wgpu::Operations {
                load: wgpu::LoadOp::Clear(1.0),
                store: wgpu::StoreOp::Discard,
            }),
            stencil_ops: None,
        }),
        timestamp_writes: timer.render(label),
        occlusion_query_set: None,
        multiview_mask: None,
    })
}
