//! The device: chosen from the environment, Vulkan first.

use crate::{Error, Result};

/// A wgpu device and queue plus what we learned about the adapter.
pub struct GpuContext {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub info: wgpu::AdapterInfo,
    /// Timestamp queries inside passes are available (for `voxgi bench`).
    pub timestamps: bool,
    /// GPU errors no error scope caught. wgpu's default is to panic; voxgi collects them here
    /// and turns them into an `Error` at the end of the frame.
    pub errors: std::sync::Arc<std::sync::Mutex<Vec<String>>>,
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
        let features = adapter.features();
        let timestamps = features.contains(wgpu::Features::TIMESTAMP_QUERY);
        let mut required_features = wgpu::Features::empty();
        if timestamps {
            required_features |= wgpu::Features::TIMESTAMP_QUERY;
        }
        // Ask for what the adapter offers (within the defaults' spirit): big scenes need large
        // storage buffers, and lavapipe and real GPUs both allow far more than the defaults.
        let al = adapter.limits();
        let required_limits = wgpu::Limits {
            max_storage_buffer_binding_size: al.max_storage_buffer_binding_size,
            max_buffer_size: al.max_buffer_size,
            max_texture_array_layers: al.max_texture_array_layers,
            max_texture_dimension_2d: al.max_texture_dimension_2d,
            max_texture_dimension_3d: al.max_texture_dimension_3d,
            max_storage_textures_per_shader_stage: al.max_storage_textures_per_shader_stage.min(8),
            max_compute_invocations_per_workgroup: al
                .max_compute_invocations_per_workgroup
                .min(1024),
            ..wgpu::Limits::default()
        };
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
        Ok(GpuContext {
            device,
            queue,
            info,
            timestamps,
            errors,
        })
    }

    /// Runs `f`, turning any validation or out-of-memory error it triggers into an `Error`
    /// instead of wgpu's default panic.
    /// Takes the errors collected since the last call, as one `Error`.
    pub fn take_error(errors: &std::sync::Mutex<Vec<String>>, context: &str) -> Result<()> {
        let mut v = errors.lock().map_err(|_| Error::Gpu {
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

    pub fn checked<T>(&self, context: &str, f: impl FnOnce() -> T) -> Result<T> {
        let scope_oom = self.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let scope_val = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let out = f();
        let val = pollster::block_on(scope_val.pop());
        let oom = pollster::block_on(scope_oom.pop());
        if let Some(e) = val.or(oom) {
            return Err(Error::Gpu {
                context: context.into(),
                reason: e.to_string(),
            });
        }
        Ok(out)
    }
}
