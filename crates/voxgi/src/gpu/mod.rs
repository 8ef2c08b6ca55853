//! Device setup, shader composition, readback.

mod context;
pub mod layout;
pub mod readback;
pub mod shader;
pub mod timer;

pub use context::GpuContext;
