//! Headless rendering for tools and tests: a device opened from the environment (Vulkan
//! first) and frames rendered to images in memory, built on the public API only
//! (`Renderer::new`, `Renderer::render`). Applications that own a device do not need it.

use crate::gpu::readback;
use crate::gpu::requirements::{required_features, required_limits};
use crate::options::FrameParams;
use crate::output::RenderOutput;
use crate::{Error, Renderer, Result, Target};

/// A wgpu device and queue voxgi opened itself, plus what it learned about the adapter.
pub struct GpuContext {
    /// The device, opened with `required_features` and `required_limits`.
    pub device: wgpu::Device,
    /// The device's queue.
    pub queue: wgpu::Queue,
    /// The adapter's name, backend and type.
    pub info: wgpu::AdapterInfo,
    /// Timestamp queries inside passes are available (for `voxgi bench`).
    pub timestamps: bool,
    /// GPU errors no error scope caught. wgpu's default is to panic; on its own device voxgi
    /// collects them here and turns them into an `Error` at the end of the frame.
    pub errors: std::sync::Arc<std::sync::Mutex<Vec<String>>>,
    /// Whether the device was lost: every call below then answers `Error::DeviceLost`.
    pub watch: crate::gpu::lost::DeviceWatch,
}

impl GpuContext {
    /// Opens a device chosen from the environment:
    /// - `WGPU_BACKEND` (e.g. `vulkan`, `metal`, `dx12`, `gl`) restricts the backends tried;
    /// - `WGPU_ADAPTER_NAME` picks the first adapter whose name contains it (case-insensitive).
    ///
    /// Otherwise the best adapter wins: Vulkan before other backends, then discrete GPU,
    /// integrated GPU, virtual GPU, CPU.
    pub fn from_env() -> Result<Self> {
        pollster::block_on(Self::from_env_async())
    }

    async fn from_env_async() -> Result<Self> {
        let backends = wgpu::Backends::from_env().unwrap_or(wgpu::Backends::PRIMARY);
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
        desc.backends = backends;
        let instance = wgpu::Instance::new(desc);
        let adapters = instance.enumerate_adapters(backends).await;
        let wanted = std::env::var("WGPU_ADAPTER_NAME")
            .ok()
            .map(|s| s.to_lowercase());
        let names: Vec<String> = adapters
            .iter()
            .map(|a| {
                let i = a.get_info();
                format!("{} ({:?})", i.name, i.backend)
            })
            .collect();
        let rank = |info: &wgpu::AdapterInfo| {
            let backend = if info.backend == wgpu::Backend::Vulkan {
                0
            } else {
                1
            };
            let kind = match info.device_type {
                wgpu::DeviceType::DiscreteGpu => 0,
                wgpu::DeviceType::IntegratedGpu => 1,
                wgpu::DeviceType::VirtualGpu => 2,
                wgpu::DeviceType::Cpu => 3,
                wgpu::DeviceType::Other => 4,
            };
            (backend, kind)
        };
        let adapter = adapters
            .into_iter()
            .filter(|a| {
                wanted
                    .as_ref()
                    .is_none_or(|w| a.get_info().name.to_lowercase().contains(w))
            })
            .min_by_key(|a| rank(&a.get_info()));
        let Some(adapter) = adapter else {
            let details = match (&wanted, names.is_empty()) {
                (Some(w), false) => format!(
                    " matching WGPU_ADAPTER_NAME='{w}' (available: {})",
                    names.join(", ")
                ),
                (_, _) => format!(" for backends {backends:?}"),
            };
            return Err(Error::NoAdapter { details });
        };
        let info = adapter.get_info();
        let required_features = required_features(&adapter);
        let timestamps = required_features.contains(wgpu::Features::TIMESTAMP_QUERY);
        let required_limits = required_limits(&adapter);
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("voxgi"),
                required_features,
                required_limits,
                experimental_features: wgpu::ExperimentalFeatures::disabled(),
                memory_hints: wgpu::MemoryHints::Performance,
                trace: wgpu::Trace::Off,
            })
            .await
            .map_err(|e| Error::Device {
                adapter: info.name.clone(),
                reason: e.to_string(),
            })?;
        log::info!(
            "GPU: {} ({:?}, {:?})",
            info.name,
            info.backend,
            info.device_type
        );
        let errors = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
        let sink = errors.clone();
        device.on_uncaptured_error(std::sync::Arc::new(move |e: wgpu::Error| {
            log::error!("GPU error: {e}");
            if let Ok(mut v) = sink.lock() {
                v.push(e.to_string());
            }
        }));
        let watch = crate::gpu::lost::DeviceWatch::new(&device);
        Ok(GpuContext {
            device,
            queue,
            info,
            timestamps,
            errors,
            watch,
        })
    }

    /// Takes the errors collected since the last call, as one `Error`.
    pub fn take_error(&self, context: &str) -> Result<()> {
        self.watch.check()?;
        let mut v = self.errors.lock().map_err(|_| Error::Gpu {
            context: context.into(),
            reason: "error log poisoned".into(),
        })?;
        if v.is_empty() {
            return Ok(());
        }
        let reason = v.join("; ");
        v.clear();
        Err(Error::Gpu {
            context: context.into(),
            reason,
        })
    }

    /// A renderer on this device.
    pub fn renderer(
        &self,
        scene: &voxgi_scene::Scene,
        options: &crate::RendererOptions,
    ) -> Result<Renderer> {
        // On a lost device wgpu's helpers panic (a buffer made mapped cannot be mapped).
        self.watch.check()?;
        let r = self
            .watch
            .explain(Renderer::new(&self.device, &self.queue, scene, options));
        self.take_error("renderer creation")?;
        r
    }
}

/// The format `render` writes the tone-mapped image in: 8-bit without an sRGB view, so the
/// sRGB curve is voxgi's own (exact to the bit on every device) rather than the GPU's encoder,
/// which may round differently by one step.
pub const OUTPUT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// Most frames `render` records before giving up on the voxels settling: the first build; a
/// second when it dropped fragments (its voxel count covers only those it kept); a third when
/// the voxel pool then still overflowed; and one to spare.
const MAX_FRAMES: u32 = 4;

/// Renders one frame of `width` x `height` and reads it back: the tone-mapped image
/// (`OUTPUT_FORMAT`) and the linear HDR radiance. Waits for the GPU, unlike
/// `Renderer::render`. When the frame's voxel build overflowed a pool, the frame is rendered
/// again once the pools have grown, so the image is always that of a renderer sized right.
/// With temporal accumulation this is the next frame of the renderer's stream (the first
/// one is the unjittered still); `render_still` renders a converged still.
pub fn render(
    ctx: &GpuContext,
    renderer: &mut Renderer,
    params: &FrameParams,
    width: u32,
    height: u32,
) -> Result<RenderOutput> {
    ctx.watch.check()?;
    let output = Output::new(ctx, width, height)?;
    ctx.watch.explain(
        output
            .frame(ctx, renderer, params)
            .and_then(|()| output.read(ctx, renderer)),
    )
}

/// Frames `render_still` accumulates unless told otherwise: enough for the area light's
/// sampled shadows to agree with the path tracer's (the Cornell box's direct light, whose
/// error falls only slowly beyond, docs/QUALITY.md); the indirect light has converged long
/// before.
pub const DEFAULT_ACCUMULATE: u32 = 64;

/// Renders a still of the scene as it is: frames until the voxels have settled (progressive
/// bounces converged), then, with temporal accumulation on, `accumulate` frames of the same
/// instant into a fresh history (jittered, the cones turned, new points on area lights) and
/// reads back their mean.
/// Without temporal accumulation, or with `accumulate` at most 1, the settled frame itself.
/// More than `TEMPORAL_STILL_FRAMES` is an error: the renderer stops accumulating there.
pub fn render_still(
    ctx: &GpuContext,
    renderer: &mut Renderer,
    params: &FrameParams,
    width: u32,
    height: u32,
    accumulate: u32,
) -> Result<RenderOutput> {
    if accumulate > crate::TEMPORAL_STILL_FRAMES {
        return Err(crate::Error::Setting(format!(
            "{accumulate} frames to accumulate: at most {} (a still has converged there)",
            crate::TEMPORAL_STILL_FRAMES
        )));
    }
    ctx.watch.check()?;
    let output = Output::new(ctx, width, height)?;
    let mut frames = || -> Result<RenderOutput> {
        output.frame(ctx, renderer, params)?;
        while !renderer.voxels_settled() {
            output.frame(ctx, renderer, params)?;
        }
        if renderer.options().temporal && accumulate > 1 {
            renderer.reset_history();
            for _ in 0..accumulate {
                output.frame(ctx, renderer, params)?;
            }
        }
        output.read(ctx, renderer)
    };
    ctx.watch.explain(frames())
}

/// The texture headless frames are written to.
struct Output {
    texture: wgpu::Texture,
    view: wgpu::TextureView,
    width: u32,
    height: u32,
}

impl Output {
    fn new(ctx: &GpuContext, width: u32, height: u32) -> Result<Self> {
        crate::validate_size(width, height)?;
        let texture = crate::frame::formats::texture_2d(
            &ctx.device,
            "headless output",
            OUTPUT_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            (width, height),
        );
        let view = texture.create_view(&Default::default());
        Ok(Output {
            texture,
            view,
            width,
            height,
        })
    }

    /// Renders one frame into the texture and waits for it: again after a voxel build that
    /// overflowed, once the pools have grown.
    fn frame(&self, ctx: &GpuContext, renderer: &mut Renderer, params: &FrameParams) -> Result<()> {
        let target = Target::new(&self.view, OUTPUT_FORMAT, self.width, self.height);
        for frame in 0..MAX_FRAMES {
            let mut encoder = ctx
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some("headless frame"),
                });
            renderer.render(&mut encoder, &target, params)?;
            ctx.queue.submit([encoder.finish()]);
            ctx.device
                .poll(wgpu::PollType::wait_indefinitely())
                .map_err(|e| Error::Gpu {
                    context: "frame".into(),
                    reason: e.to_string(),
                })?;
            ctx.take_error("frame")?;
            // The counters' map callback runs in whichever thread polls the device; on a device
            // shared between threads that may be another one, a moment after this thread's wait
            // returned. Until it has run, a build that overflowed looks finished (a flaky golden
            // test showed such an image: voxels missing from one corner).
            let waiting = std::time::Instant::now();
            while renderer.feedback_in_flight() {
                if waiting.elapsed() > std::time::Duration::from_secs(30) {
                    return Err(Error::Gpu {
                        context: "voxel counters".into(),
                        reason: "their readback did not complete within 30 s".into(),
                    });
                }
                let _ = ctx.device.poll(wgpu::PollType::Poll);
                std::thread::yield_now();
            }
            if !renderer.receive_feedback()? {
                break;
            }
            if frame + 1 == MAX_FRAMES {
                return Err(Error::Gpu {
                    context: "voxelize".into(),
                    reason: "the voxel pools still overflow after growing".into(),
                });
            }
        }
        Ok(())
    }

    /// Reads back the last frame: the tone-mapped image and the HDR radiance it showed.
    fn read(&self, ctx: &GpuContext, renderer: &Renderer) -> Result<RenderOutput> {
        let (width, height, texture) = (self.width, self.height, &self.texture);
        let hdr = renderer.hdr_texture().ok_or_else(|| Error::Gpu {
            context: "frame".into(),
            reason: "no HDR target after rendering".into(),
        })?;
        let hdr_bytes = readback::read_texture(&ctx.device, &ctx.queue, hdr)?;
        let ldr = readback::read_texture(&ctx.device, &ctx.queue, texture)?;
        ctx.take_error("readback")?;
        Ok(RenderOutput {
            width,
            height,
            hdr: bytemuck::cast_slice(&hdr_bytes).to_vec(),
            ldr,
        })
    }
}
