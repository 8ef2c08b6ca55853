//! Helpers shared by the GPU tests.

use std::sync::OnceLock;

/// The one GPU context all tests in this binary share.
pub fn ctx() -> &'static voxgi::GpuContext {
    static CTX: OnceLock<voxgi::GpuContext> = OnceLock::new();
    CTX.get_or_init(|| voxgi::GpuContext::from_env().expect("no GPU device for the tests"))
}
