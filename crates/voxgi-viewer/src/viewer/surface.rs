//! The device and the window's surface: opening the window, the adapter and the device, the
//! surface's configuration (format, usages, present mode), resizing, and taking each frame's
//! surface texture.

use super::Viewer;
use crate::Args;
use anyhow::{Context, Result, anyhow};
use std::sync::Arc;
use voxgi::wgpu;
use winit::event_loop::ActiveEventLoop;
use winit::window::Window;

/// The window, the device and the surface configured for it, as `Viewer::new` opens them.
pub(super) struct Gpu {
    pub(super) window: Arc<Window>,
    pub(super) surface: wgpu::Surface<'static>,
    pub(super) config: wgpu::SurfaceConfiguration,
    pub(super) device: wgpu::Device,
    pub(super) queue: wgpu::Queue,
    pub(super) info: wgpu::AdapterInfo,
    /// The adapter is a CPU driver (lavapipe, WARP).
    pub(super) cpu: bool,
    /// The device has timestamp queries: GPU times per pass.
    pub(super) timestamps: bool,
    /// The surface can be copied into: a still view is drawn once and copied after that.
    pub(super) keeps_image: bool,
    /// Whether the device was lost.
    pub(super) watch: voxgi::gpu::lost::DeviceWatch,
}

/// Opens the window titled after `scene_name`, a device that can draw into it, and the
/// surface, configured at the size `args` asks for.
pub(super) fn open_window(
    event_loop: &ActiveEventLoop,
    args: &Args,
    scene_name: &str,
) -> Result<Gpu> {
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_with_display_handle_from_env(
        Box::new(event_loop.owned_display_handle()),
    ));
    // Open small first: the size depends on whether the adapter is a CPU.
    let attrs = Window::default_attributes()
        .with_title(format!("voxgi — {scene_name}"))
        .with_inner_size(winit::dpi::PhysicalSize::new(640, 360));
    let window = Arc::new(
        event_loop
            .create_window(attrs)
            .context("cannot open a window")?,
    );
    let surface = instance
        .create_surface(window.clone())
        .context("cannot draw into the window")?;
    let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
        power_preference: wgpu::PowerPreference::HighPerformance,
        force_fallback_adapter: false,
        compatible_surface: Some(&surface),
        apply_limit_buckets: false,
    }))
    .map_err(|e| anyhow!("no GPU adapter can draw into this window: {e}"))?;
    let info = adapter.get_info();
    let cpu = info.device_type == wgpu::DeviceType::Cpu;
    let features = voxgi::required_features(&adapter);
    let timestamps = features.contains(wgpu::Features::TIMESTAMP_QUERY);
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        label: Some("voxgi-viewer"),
        required_features: features,
        required_limits: voxgi::required_limits(&adapter),
        ..Default::default()
    }))
    .with_context(|| format!("cannot open {}", info.name))?;
    let requested = args
        .size
        .unwrap_or(if cpu { (960, 480) } else { (1280, 720) });
    let monitor = window
        .current_monitor()
        .map(|m| (m.size().width, m.size().height));
    let (w, h) = fit_window(requested, monitor, device.limits().max_texture_dimension_2d)?;
    let _ = window.request_inner_size(winit::dpi::PhysicalSize::new(w, h));
    let size = window.inner_size();
    let caps = surface.get_capabilities(&adapter);
    let format = voxgi::surface_format(&caps.formats)
        .ok_or_else(|| anyhow!("the window offers no surface format"))?;
    let mut config = surface
        .get_default_config(&adapter, size.width.max(1), size.height.max(1))
        .ok_or_else(|| anyhow!("{} cannot draw into this window", info.name))?;
    config.usage = wgpu::TextureUsages::RENDER_ATTACHMENT;
    // A still view is drawn once into an image and copied into each frame after that.
    let keeps_image = caps.usages.contains(wgpu::TextureUsages::COPY_DST);
    if keeps_image {
        config.usage |= wgpu::TextureUsages::COPY_DST;
    }
    config.format = format;
    config.present_mode = if args.no_vsync {
        wgpu::PresentMode::AutoNoVsync
    } else {
        wgpu::PresentMode::AutoVsync
    };
    surface.configure(&device, &config);
    let watch = voxgi::gpu::lost::DeviceWatch::new(&device);
    Ok(Gpu {
        window,
        surface,
        config,
        device,
        queue,
        info,
        cpu,
        timestamps,
        keeps_image,
        watch,
    })
}

impl Viewer {
    /// The window's new size: the surface follows it.
    pub(super) fn resize(&mut self, size: winit::dpi::PhysicalSize<u32>) {
        self.config.width = size.width.max(1);
        self.config.height = size.height.max(1);
        self.surface.configure(&self.device, &self.config);
    }

    /// The surface texture to draw this frame into, or `None` when there is none this time
    /// (the surface is configured again when it went out of date).
    pub(super) fn surface_texture(&mut self) -> Result<Option<wgpu::SurfaceTexture>> {
        match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t)
            | wgpu::CurrentSurfaceTexture::Suboptimal(t) => Ok(Some(t)),
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                self.surface.configure(&self.device, &self.config);
                Ok(None)
            }
            // Minimised or slow to hand out a frame: try again on the next redraw.
            wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => {
                Ok(None)
            }
            other => Err(anyhow!("the window's surface: {other:?}")),
        }
    }

    /// Configures the surface again when the panel's vsync box changed.
    pub(super) fn follow_vsync(&mut self) {
        let present_mode = if self.vsync {
            wgpu::PresentMode::AutoVsync
        } else {
            wgpu::PresentMode::AutoNoVsync
        };
        if present_mode != self.config.present_mode {
            self.config.present_mode = present_mode;
            self.surface.configure(&self.device, &self.config);
        }
    }
}

/// The window size for `requested`: refused beyond what the device's textures hold (the frame
/// is drawn into them), brought within the monitor's size (a window the screen cannot show
/// is still drawn at full size every frame, minutes a frame on a CPU driver), kept otherwise.
fn fit_window(
    requested: (u32, u32),
    monitor: Option<(u32, u32)>,
    device_max: u32,
) -> Result<(u32, u32)> {
    let (w, h) = requested;
    if w > device_max || h > device_max {
        return Err(anyhow!(
            "--size {w}x{h}: larger than this GPU's largest texture, {device_max}x{device_max}"
        ));
    }
    match monitor {
        Some((mw, mh)) if mw > 0 && mh > 0 && (w > mw || h > mh) => {
            // Keep the aspect ratio.
            let s = (mw as f64 / w as f64).min(mh as f64 / h as f64);
            let fit = (
                ((w as f64 * s) as u32).max(1),
                ((h as f64 * s) as u32).max(1),
            );
            log::warn!(
                "--size {w}x{h} is larger than the screen ({mw}x{mh}): opening {}x{} (render \
                 larger images with `voxgi render`)",
                fit.0,
                fit.1
            );
            Ok(fit)
        }
        _ => Ok((w, h)),
    }
}

#[cfg(test)]
mod tests {
    use super::fit_window;

    #[test]
    fn the_window_fits_the_device_and_the_screen() {
        assert_eq!(
            fit_window((800, 600), Some((1920, 1080)), 8192).unwrap(),
            (800, 600)
        );
        // 8192x8192 on a 1280x1024 screen: the largest square it shows.
        assert_eq!(
            fit_window((8192, 8192), Some((1280, 1024)), 16384).unwrap(),
            (1024, 1024)
        );
        assert_eq!(
            fit_window((4000, 1000), Some((2000, 2000)), 8192).unwrap(),
            (2000, 500)
        );
        // No monitor known (some Wayland compositors): as asked, within the device.
        assert_eq!(fit_window((3000, 2000), None, 8192).unwrap(), (3000, 2000));
        let e = fit_window((20000, 100), Some((1920, 1080)), 16384).unwrap_err();
        assert!(
            e.to_string().contains("largest texture, 16384x16384"),
            "{e}"
        );
    }
}
