//! Shader composition, pipelines, layouts, readback, timing, and what voxgi asks of a device.

pub mod feedback;
pub mod layout;
pub mod readback;
pub mod requirements;
pub mod shader;
pub mod timer;

use crate::{Error, Result};

/// The most entries of `entry_bytes` one storage binding can hold on this device.
pub fn max_entries(device: &wgpu::Device, entry_bytes: u64) -> u64 {
    device.limits().max_storage_buffer_binding_size / entry_bytes
}

/// A pool capacity of at least 1024 `what` (entries of `entry_bytes`, as in "voxel
/// fragments"), checked against the device's storage-binding limit.
pub fn pool_capacity(
    device: &wgpu::Device,
    wanted: u64,
    entry_bytes: u64,
    what: &str,
) -> Result<u32> {
    let limit = max_entries(device, entry_bytes);
    let cap = wanted.max(1024);
    if cap > limit.min(u32::MAX as u64) {
        return Err(Error::Setting(format!(
            "the scene needs about {cap} {what} at this resolution, more than this GPU's \
             storage-buffer limit allows ({limit}); lower the voxel resolution"
        )));
    }
    Ok(cap as u32)
}

/// Runs `f` inside validation and out-of-memory error scopes of its own, turning what it
/// triggers into an `Error` naming `context` instead of reaching the device's handler. Popping
/// a scope does not wait for the GPU: wgpu validates on the CPU as commands are made.
pub fn checked<T>(device: &wgpu::Device, context: &str, f: impl FnOnce() -> T) -> Result<T> {
    let scope_oom = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
    let scope_val = device.push_error_scope(wgpu::ErrorFilter::Validation);
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
