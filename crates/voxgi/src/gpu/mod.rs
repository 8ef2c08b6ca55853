//! Shader composition, pipelines, layouts, readback, timing, and what voxgi asks of a device.

pub mod feedback;
pub mod layout;
pub mod lost;
pub mod readback;
pub mod requirements;
pub mod shader;
pub mod timer;

use crate::{Error, Result};
use std::cell::RefCell;
use std::pin::Pin;
use std::task::{Context, Poll, Waker};

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
        return Err(Error::TooLarge(format!(
            "the scene needs about {cap} {what} at this resolution, more than this GPU's \
             storage-buffer limit allows ({limit}); lower the voxel resolution"
        )));
    }
    Ok(cap as u32)
}

/// Runs `f` inside validation and out-of-memory error scopes of its own, turning what it
/// triggers into an `Error` naming `context` instead of reaching the device's handler.
///
/// Never waits. Native wgpu validates on the CPU as commands are made, so its scopes have
/// answered when `f` returns and an error comes back here. WebGPU answers later: a scope
/// still open is kept, and its error comes back from `late_error` (the renderer asks at the
/// start of every frame, as it reads its counters a frame later).
pub fn checked<T>(device: &wgpu::Device, context: &str, f: impl FnOnce() -> T) -> Result<T> {
    let scope_oom = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
    let scope_val = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let out = f();
    let mut open = Vec::new();
    // The validation scope first: it is the innermost, and its error is the more specific.
    for mut scope in [
        Box::pin(scope_val.pop()) as Scope,
        Box::pin(scope_oom.pop()),
    ] {
        match poll_now(scope.as_mut()) {
            Poll::Ready(Some(e)) => return Err(gpu_error(context, &e)),
            Poll::Ready(None) => {}
            Poll::Pending => open.push(scope),
        }
    }
    if !open.is_empty() {
        LATE.with_borrow_mut(|late| {
            late.push(Late {
                device: device.clone(),
                context: context.into(),
                scopes: open,
            })
        });
    }
    Ok(out)
}

/// The first error that work `checked` on `device` let through before its scopes answered
/// (WebGPU only), once they have; `Ok` while none has.
pub fn late_error(device: &wgpu::Device) -> Result<()> {
    LATE.with_borrow_mut(|late| {
        let mut first = None;
        late.retain_mut(|l| {
            if l.device != *device {
                return true;
            }
            l.scopes.retain_mut(|scope| match poll_now(scope.as_mut()) {
                Poll::Ready(e) => {
                    if let (Some(e), None) = (e, &first) {
                        first = Some(gpu_error(&l.context, &e));
                    }
                    false
                }
                Poll::Pending => true,
            });
            !l.scopes.is_empty()
        });
        first.map_or(Ok(()), Err)
    })
}

/// A popped error scope's answer.
type Scope = Pin<Box<dyn Future<Output = Option<wgpu::Error>>>>;

/// Scopes `checked` left open, with what they were checking.
struct Late {
    device: wgpu::Device,
    context: String,
    scopes: Vec<Scope>,
}

thread_local! {
    // Per thread, as WebGPU's devices are; native wgpu never leaves anything here.
    static LATE: RefCell<Vec<Late>> = const { RefCell::new(Vec::new()) };
}

/// Polls once, without blocking: a scope's answer if it has one.
fn poll_now<F: Future + ?Sized>(f: Pin<&mut F>) -> Poll<F::Output> {
    f.poll(&mut Context::from_waker(Waker::noop()))
}

fn gpu_error(context: &str, e: &wgpu::Error) -> Error {
    Error::Gpu {
        context: context.into(),
        reason: e.to_string(),
    }
}
