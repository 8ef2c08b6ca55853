//! voxgi: real-time global illumination by voxel cone tracing, on wgpu.
//!
//! ```no_run
//! let ctx = voxgi::GpuContext::from_env()?;
//! let scene = voxgi::scene::builtin::cornell_box();
//! let mut renderer = voxgi::Renderer::new(&ctx, &scene, voxgi::Settings::default())?;
//! let camera = renderer.default_camera().clone();
//! renderer.render(&camera, 512, 512)?.save("cornell.png".as_ref())?;
//! # Ok::<(), voxgi::Error>(())
//! ```

pub mod brdf;
pub mod compare;
mod error;
mod frame;
pub mod gpu;
pub mod gpu_scene;
pub mod output;
pub mod passes;
pub mod reference;
mod settings;
pub mod voxel;

pub use error::{Error, Result};
pub use frame::{FrameTargets, Renderer};
pub use gpu::GpuContext;
pub use output::RenderOutput;
pub use reference::{Bounces, PathTracer, ReferenceMode, ReferenceOptions};
pub use settings::{
    MAX_BOUNCES, MAX_IMAGE_SIZE, Settings, Tonemap, UNLIMITED_BOUNCES, ViewMode, validate_size,
};
pub use voxel::ConeSet;
/// The scene model and loaders (re-exported from `voxgi-scene`).
pub use voxgi_scene as scene;
