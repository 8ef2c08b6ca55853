//! Progressive path tracing for a window: samples accumulate into an [`Accumulation`] a few at a
//! time, frame after frame, and `reference_display` draws the running mean into the caller's
//! target, tone-mapped as the tonemap pass does. The accumulation starts over by itself when
//! the view or the options change, so a caller only says how many samples to add and where.

use super::{Bounces, GpuParams, PathTracer, ReferenceMode, ReferenceOptions, bounce_limits};
use crate::frame::targets::Target;
use crate::gpu::{layout, shader};
use crate::options::{FrameParams, Tonemap, validate_size};
use crate::screen::tonemap::output_pipeline;
use crate::view::camera_view_proj;
use crate::{Error, Result};
use bytemuck::{Pod, Zeroable};
use std::ops::Range;

/// What an accumulated image depends on: when any of it changes, the samples so far belong to
/// another image. Exposure and the tone curve are not in it: they only change the display.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Key {
    view_proj: [f32; 16],
    background: [f32; 3],
    bounces: Bounces,
    mode: ReferenceMode,
    seed: u32,
}

/// The pixels a call covers: columns `columns` of rows `rows`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Region {
    /// The columns, left to right.
    pub columns: Range<u32>,
    /// The rows, top to bottom.
    pub rows: Range<u32>,
}

impl Region {
    /// The whole of a `width` x `height` image.
    pub fn all(width: u32, height: u32) -> Self {
        Region {
            columns: 0..width,
            rows: 0..height,
        }
    }

    fn check(&self, width: u32, height: u32) -> Result<()> {
        let (c, r) = (&self.columns, &self.rows);
        if c.start >= c.end || c.end > width || r.start >= r.end || r.end > height {
            return Err(Error::Setting(format!(
                "region columns {}..{}, rows {}..{} is not a non-empty part of the {width}x\
                 {height} image",
                c.start, c.end, r.start, r.end
            )));
        }
        Ok(())
    }
}

/// A path-traced image accumulating over several submits, made by
/// [`PathTracer::accumulation`] and used only with that path tracer.
///
/// Each pixel counts its own samples, so parts of the image can be traced in different frames
/// (a split view whose divider moves, a band of rows a frame on a slow GPU) and every pixel
/// still shows an unbiased mean of its own samples.
pub struct Accumulation {
    width: u32,
    height: u32,
    /// rgb: the sum of the samples; a: their count.
    buffer: wgpu::Buffer,
    params: wgpu::Buffer,
    trace_group: wgpu::BindGroup,
    display_params: wgpu::Buffer,
    display_group: wgpu::BindGroup,
    key: Option<Key>,
    /// The columns `rows` counts samples for.
    columns: Range<u32>,
    /// For each row, the samples every pixel of `columns` in it has at least.
    rows: Vec<u32>,
}

impl Accumulation {
    /// Width of the image, pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height of the image, pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Samples that every pixel of the columns last traced has, at least (over all rows).
    pub fn samples(&self) -> u32 {
        self.rows.iter().copied().min().unwrap_or(0)
    }

    /// Forgets the samples so far: the next `accumulate` starts a new image. Needed when the
    /// scene changed in a way the path tracer cannot see (it was rebuilt from a new scene).
    pub fn reset(&mut self) {
        self.key = None;
    }

    /// The per-pixel sums (rgb) and sample counts (a), four f32 a pixel in rows.
    pub fn buffer(&self) -> &wgpu::Buffer {
        &self.buffer
    }
}

/// Mirrors `Display` in shaders/reference_display.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub(crate) struct GpuDisplay {
    pub(crate) exposure: f32,
    pub(crate) tonemap: u32,
    pub(crate) width: u32,
    pub(crate) _pad: u32,
}

/// The `reference_display` pass: its layouts, and one pipeline per target format seen.
pub(super) struct DisplayPass {
    layout: wgpu::BindGroupLayout,
    pipeline_layout: wgpu::PipelineLayout,
    module: wgpu::ShaderModule,
    pipelines: Vec<(wgpu::TextureFormat, wgpu::RenderPipeline)>,
}

impl DisplayPass {
    pub(super) fn new(device: &wgpu::Device) -> Self {
        let f = wgpu::ShaderStages::FRAGMENT;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("reference_display"),
            entries: &[layout::uniform(0, f, false), layout::storage(1, f, true)],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("reference_display"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        DisplayPass {
            module: shader::module(device, "reference_display.wgsl"),
            layout,
            pipeline_layout,
            pipelines: Vec::new(),
        }
    }

    fn pipeline(
        &mut self,
        device: &wgpu::Device,
        format: wgpu::TextureFormat,
    ) -> Result<&wgpu::RenderPipeline> {
        let i = match self.pipelines.iter().position(|(f, _)| *f == format) {
            Some(i) => i,
            None => {
                let p = output_pipeline(
                    device,
                    "reference_display",
                    &self.pipeline_layout,
                    &self.module,
                    format,
                )?;
                self.pipelines.push((format, p));
                self.pipelines.len() - 1
            }
        };
        Ok(&self.pipelines[i].1)
    }
}

impl PathTracer {
    fn key(&self, acc: &Accumulation, frame: &FrameParams, opts: &ReferenceOptions) -> Key {
        let view_proj = camera_view_proj(
            &frame.camera,
            acc.width,
            acc.height,
            self.center,
            self.radius,
        );
        Key {
            view_proj: view_proj.to_cols_array(),
            background: frame.background,
            bounces: opts.bounces,
            mode: opts.mode,
            seed: opts.seed,
        }
    }

    /// Whether `acc` holds samples of this view with these options (other than `spp`): what
    /// `accumulate` would add to rather than start over.
    pub fn shows(&self, acc: &Accumulation, frame: &FrameParams, opts: &ReferenceOptions) -> bool {
        acc.key == Some(self.key(acc, frame, opts))
    }

    /// An empty accumulation image of `width` x `height` pixels.
    pub fn accumulation(&self, width: u32, height: u32) -> Result<Accumulation> {
        validate_size(width, height)?;
        let pixels = width as u64 * height as u64;
        let buffer = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("reference accumulation"),
            size: pixels * 16,
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_SRC
                | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let uniform = |label: &str, size: usize| {
            self.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: size as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let params = uniform("reference params", size_of::<GpuParams>());
        let display_params = uniform("reference_display", size_of::<GpuDisplay>());
        let trace_group = self.trace_group(&params, &buffer, &self.no_queries);
        let display_group = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("reference_display"),
            layout: &self.display.layout,
            entries: &layout::entries(vec![
                display_params.as_entire_binding(),
                buffer.as_entire_binding(),
            ]),
        });
        Ok(Accumulation {
            width,
            height,
            buffer,
            params,
            trace_group,
            display_params,
            display_group,
            key: None,
            columns: 0..0,
            rows: vec![0; height as usize],
        })
    }

    /// Records `opts.spp` more samples per pixel for the pixels of `region`, starting the image
    /// over first when the camera, the background or `opts` (other than `spp`) changed since
    /// the last call. Returns the samples every pixel of the region's columns (in all rows) now
    /// has, at least. One call per accumulation per submit: the call's parameters are written
    /// to the queue, which a second call before the submit would overwrite.
    pub fn accumulate(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        acc: &mut Accumulation,
        frame: &FrameParams,
        opts: &ReferenceOptions,
        region: Region,
    ) -> Result<u32> {
        let camera = &frame.camera;
        if !(camera.position.is_finite() && camera.forward.is_finite() && camera.up.is_finite()) {
            return Err(Error::Setting(
                "camera position and direction must be finite".into(),
            ));
        }
        if opts.spp == 0 {
            return Err(Error::Setting("spp must be at least 1".into()));
        }
        region.check(acc.width, acc.height)?;
        let (mode, ao_radius) = match opts.mode {
            ReferenceMode::Radiance => (0, 0.0),
            ReferenceMode::Ao { radius } => {
                if !(radius.is_finite() && radius > 0.0) {
                    return Err(Error::Setting(format!(
                        "AO radius {radius} must be positive and finite"
                    )));
                }
                (1, radius)
            }
        };
        let (bounces, rr_depth) = bounce_limits(opts.bounces);
        let key = self.key(acc, frame, opts);
        let view_proj = glam::Mat4::from_cols_array(&key.view_proj);
        let columns = region.columns.clone();
        if acc.key != Some(key) {
            encoder.clear_buffer(&acc.buffer, 0, None);
            acc.key = Some(key);
            acc.rows.fill(0);
        } else if !(acc.columns.start <= columns.start && columns.end <= acc.columns.end) {
            // Columns not traced with the rest so far may have had no sample yet.
            acc.rows.fill(0);
        }
        acc.columns = columns.clone();
        for n in &mut acc.rows[region.rows.start as usize..region.rows.end as usize] {
            *n += opts.spp;
        }
        let params = GpuParams {
            inv_view_proj: view_proj.inverse().to_cols_array_2d(),
            background: frame.background,
            light_count: self.light_count,
            width: acc.width,
            height: acc.height,
            x0: columns.start,
            // One sample a pixel per dispatch, `opts.spp` dispatches: on lavapipe the loops
            // of one invocation share one budget of iterations, past which every loop stops
            // at once (llvmpipe's LP_MAX_TGSI_LOOP_ITERATIONS, 65,535), without an error;
            // many samples in one invocation on a large scene lost their later samples' rays
            // (docs/QUALITY.md, "The ground truth"). Each dispatch reads the count the last
            // one left (a barrier between dispatches on the read-write buffer).
            sample_count: 1,
            seed: opts.seed,
            bounces,
            mode,
            ao_radius,
            rr_depth,
            x1: columns.end,
            y0: region.rows.start,
            y1: region.rows.end,
        };
        self.queue
            .write_buffer(&acc.params, 0, bytemuck::bytes_of(&params));
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("reference"),
                timestamp_writes: self.timer.compute("reference"),
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &acc.trace_group, &[]);
            for _ in 0..opts.spp {
                pass.dispatch_workgroups(
                    (columns.end - columns.start).div_ceil(8),
                    (region.rows.end - region.rows.start).div_ceil(8),
                    1,
                );
            }
        }
        // Resolved after each pass: a caller may trace without displaying, or the reverse.
        self.timer.resolve(encoder);
        Ok(acc.samples())
    }

    /// Records drawing the running mean of `acc` into the pixels of `columns` of `target` (the
    /// others are left as they are), exposed and tone-mapped with `frame`'s exposure and curve
    /// as the renderer's tonemap pass does; an AO image is drawn as is. The target must be the
    /// accumulation's size.
    pub fn display(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        acc: &Accumulation,
        target: &Target,
        frame: &FrameParams,
        columns: Range<u32>,
    ) -> Result<()> {
        if (target.width, target.height) != (acc.width, acc.height) {
            return Err(Error::Setting(format!(
                "the target is {}x{} but the accumulation is {}x{}",
                target.width, target.height, acc.width, acc.height
            )));
        }
        Region {
            columns: columns.clone(),
            rows: 0..acc.height,
        }
        .check(acc.width, acc.height)?;
        let ao = matches!(
            acc.key,
            Some(Key {
                mode: ReferenceMode::Ao { .. },
                ..
            })
        );
        let (exposure, tonemap) = if ao {
            (1.0, Tonemap::Clamp)
        } else {
            (2f32.powf(frame.exposure), frame.tonemap)
        };
        let params = GpuDisplay {
            exposure,
            tonemap: tonemap.id(),
            width: acc.width,
            _pad: 0,
        };
        self.queue
            .write_buffer(&acc.display_params, 0, bytemuck::bytes_of(&params));
        let pipeline = self.display.pipeline(&self.device, target.format)?;
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("reference_display"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target.view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Load,
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: self.timer.render("reference_display"),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &acc.display_group, &[]);
        pass.set_scissor_rect(columns.start, 0, columns.end - columns.start, acc.height);
        pass.draw(0..3, 0..1);
        drop(pass);
        self.timer.resolve(encoder);
        Ok(())
    }
}
