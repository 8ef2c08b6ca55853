//! Shader composition, pipelines, layouts, readback, timing, and what voxgi asks of a device.

pub mod feedback;
pub mod layout;
pub mod readback;
pub mod requirements;
pub mod shader;
pub mod timer;

use crate::{Error, Result};

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
