//! tonemap: exposure, the tone curve and the output encoding, from the HDR target into the
//! caller's texture. It is the frame's last pass and the only one that touches the caller's
//! target, so it is where the output format is adapted: one pipeline per target format, made
//! the first time that format is seen.

use crate::frame::targets::{FrameTargets, Target};
use crate::gpu::layout;
use crate::gpu::timer::GpuTimer;
use crate::gpu::{checked, shader};
use crate::{Error, Result};

/// The tonemap render pass (shaders/tonemap.wgsl): a full-screen draw from the HDR target into
/// the caller's texture, with one pipeline per target format.
pub struct TonemapPass {
    layout: wgpu::BindGroupLayout,
    pipeline_layout: wgpu::PipelineLayout,
    module: wgpu::ShaderModule,
    /// One pipeline per target format seen so far (a handful at most).
    pipelines: Vec<(wgpu::TextureFormat, wgpu::RenderPipeline)>,
}

/// Whether the shader applies the sRGB curve itself: fixed-point targets without an sRGB view
/// (`Rgba8Unorm`, `Bgra8Unorm`, `Rgb10a2Unorm`…), which a display reads as sRGB-encoded. sRGB
/// formats encode in hardware; float formats (HDR targets) take the tone-mapped linear values.
fn encodes_srgb(format: wgpu::TextureFormat) -> bool {
    use wgpu::TextureFormat as F;
    let float = matches!(
        format,
        F::R16Float
            | F::Rg16Float
            | F::Rgba16Float
            | F::R32Float
            | F::Rg32Float
            | F::Rgba32Float
            | F::Rg11b10Ufloat
    );
    !format.is_srgb() && !float
}

impl TonemapPass {
    /// Compiles the shader and creates the layouts; pipelines are made per format by `prepare`.
    pub fn new(device: &wgpu::Device) -> Self {
        let f = wgpu::ShaderStages::FRAGMENT;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("tonemap"),
            entries: &[layout::texture_2d_load(0, f)],
        });
        let globals = crate::frame::globals::layout(device);
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("tonemap"),
            bind_group_layouts: &[Some(&globals), None, Some(&layout)],
            immediate_size: 0,
        });
        TonemapPass {
            module: shader::module(device, "screen/tonemap.wgsl"),
            layout,
            pipeline_layout,
            pipelines: Vec::new(),
        }
    }

    /// Makes the pipeline for `format` if there is none yet; an error (and nothing kept) when
    /// the format cannot be rendered to this way.
    pub fn prepare(&mut self, device: &wgpu::Device, format: wgpu::TextureFormat) -> Result<()> {
        if self.pipelines.iter().any(|(f, _)| *f == format) {
            return Ok(());
        }
        let pipeline = output_pipeline(
            device,
            "tonemap",
            &self.pipeline_layout,
            &self.module,
            format,
        )?;
        self.pipelines.push((format, pipeline));
        Ok(())
    }

    /// The pass's own bind groups for these targets (made once per targets): the first reads
    /// the HDR target, the others each history (the temporal pass's output, when there is one).
    pub fn bind(&self, device: &wgpu::Device, t: &FrameTargets) -> Vec<wgpu::BindGroup> {
        let read = |view: &wgpu::TextureView| {
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("tonemap"),
                layout: &self.layout,
                entries: &layout::entries(vec![wgpu::BindingResource::TextureView(view)]),
            })
        };
        let mut binds = vec![read(&t.hdr)];
        if let Some(h) = &t.history {
            binds.extend(h.color_views.iter().map(read));
        }
        binds
    }

    /// Draws into `target`, whose format `prepare` has seen.
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        globals: &wgpu::BindGroup,
        target: &Target,
        bind: &wgpu::BindGroup,
        timer: &mut GpuTimer,
    ) {
        let format = target.format;
        let Some((_, pipeline)) = self.pipelines.iter().find(|(f, _)| *f == format) else {
            debug_assert!(false, "tonemap: no pipeline prepared for {format:?}");
            return;
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("tonemap"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target.view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: timer.render("tonemap"),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, globals, &[]);
        pass.set_bind_group(2, bind, &[]);
        pass.draw(0..3, 0..1);
    }
}

/// A full-screen pipeline (`vs_main`, `fs_main`) drawing into the caller's `format`: the
/// tonemap pass's and the path tracer's display, which both end in the caller's target and
/// adapt to its format alike (`ENCODE_SRGB`). An error when the format cannot be rendered to.
pub(crate) fn output_pipeline(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    format: wgpu::TextureFormat,
) -> Result<wgpu::RenderPipeline> {
    let renderable = format
        .guaranteed_format_features(device.features())
        .allowed_usages
        .contains(wgpu::TextureUsages::RENDER_ATTACHMENT)
        && format
            .sample_type(None, None)
            .is_some_and(|t| matches!(t, wgpu::TextureSampleType::Float { .. }))
        && !format.is_depth_stencil_format();
    if !renderable {
        return Err(Error::Setting(format!(
            "the target format {format:?} is not a colour format voxgi can render to (use an \
             8-bit UNORM or sRGB format, Rgb10a2Unorm, or a float format)"
        )));
    }
    let constants = [("ENCODE_SRGB", encodes_srgb(format) as u32 as f64)];
    checked(device, &format!("{label} pipeline"), || {
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(label),
            layout: Some(layout),
            vertex: wgpu::VertexState {
                module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: Default::default(),
            depth_stencil: None,
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module,
                entry_point: Some("fs_main"),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants: &constants,
                    ..Default::default()
                },
                targets: &[Some(format.into())],
            }),
            multiview_mask: None,
            cache: None,
        })
    })
}
