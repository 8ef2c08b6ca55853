//! What voxgi asks of a device, so an application can open one voxgi accepts, and the check
//! that names what is missing when it cannot.

use crate::{Error, Result};

/// The features to request for voxgi: none are required; timestamp queries are asked for
/// when the adapter has them, for per-pass timing (`Renderer::enable_timing`), and between
/// passes too where it allows (copies that belong to a pass's scope).
pub fn required_features(adapter: &wgpu::Adapter) -> wgpu::Features {
    let timing = adapter.features() & wgpu::Features::TIMESTAMP_QUERY;
    if timing.is_empty() {
        return timing;
    }
    timing | (adapter.features() & wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS)
}

/// The limits to request: wgpu's defaults, with buffer and texture sizes raised to what the
/// adapter allows, because a scene's voxel pools and fragment buffers grow with the scene and
/// the voxel resolution (both are checked against the device's limits when a renderer is made).
pub fn required_limits(adapter: &wgpu::Adapter) -> wgpu::Limits {
    let al = adapter.limits();
    let min = minimum_limits();
    wgpu::Limits {
        max_storage_buffer_binding_size: al
            .max_storage_buffer_binding_size
            .max(min.max_storage_buffer_binding_size),
        max_buffer_size: al.max_buffer_size.max(min.max_buffer_size),
        max_texture_array_layers: al.max_texture_array_layers,
        max_texture_dimension_2d: al.max_texture_dimension_2d,
        max_texture_dimension_3d: al.max_texture_dimension_3d,
        ..min
    }
}

/// The least a device must offer: wgpu's default limits (every pipeline fits them; larger
/// scenes need the larger buffers `required_limits` asks for).
pub fn minimum_limits() -> wgpu::Limits {
    wgpu::Limits::default()
}

/// Checks a device against `minimum_limits`, naming every limit it falls short of.
pub fn check_device(device: &wgpu::Device) -> Result<()> {
    let have = device.limits();
    let mut missing = Vec::new();
    // `a.check_limits_with_fail_fn(b)` reports every limit of `a` that `b` does not allow.
    minimum_limits().check_limits_with_fail_fn(&have, false, |name, need, have| {
        missing.push(format!("{name} is {have}, voxgi needs {need}"));
    });
    if missing.is_empty() {
        Ok(())
    } else {
        Err(Error::DeviceLimits(missing.join("; ")))
    }
}
