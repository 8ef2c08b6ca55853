//! voxgi: real-time global illumination by voxel cone tracing, on wgpu.
//!
//! The application owns the device; voxgi records into its encoder and writes into its
//! texture:
//!
//! ```no_run
//! # async fn run(adapter: wgpu::Adapter, view: wgpu::TextureView) -> Result<(), Box<dyn std::error::Error>> {
//! use voxgi::wgpu;
//! let (device, queue) = adapter
//!     .request_device(&wgpu::DeviceDescriptor {
//!         required_features: voxgi::required_features(&adapter),
//!         required_limits: voxgi::required_limits(&adapter),
//!         ..Default::default()
//!     })
//!     .await?;
//! let scene = voxgi::scene::builtin::cornell_box();
//! let mut renderer =
//!     voxgi::Renderer::new(&device, &queue, &scene, &voxgi::RendererOptions::default())?;
//! let params = voxgi::FrameParams::new(renderer.default_camera().clone());
//! let mut encoder = device.create_command_encoder(&Default::default());
//! let target = voxgi::Target::new(&view, wgpu::TextureFormat::Rgba8UnormSrgb, 512, 512);
//! renderer.render(&mut encoder, &target, &params)?;
//! queue.submit([encoder.finish()]);
//! # Ok(())
//! # }
//! ```
//!
//! Cargo features: `headless` (a device from the environment and rendering to images in
//! memory, for tools and tests), `image-io` (PNG and EXR writing), `compare` (FLIP and error
//! metrics between images), `reference` (the ground-truth path tracer). The `voxgi` command
//! turns them all on; an application embedding the renderer needs none.

#![warn(missing_docs)]

pub mod brdf;
#[cfg(feature = "compare")]
pub mod compare;
mod error;
pub mod fragments;
pub mod frame;
pub mod gpu;
pub mod gpu_scene;
#[cfg(feature = "headless")]
pub mod headless;
pub mod lighting;
mod options;
pub mod output;
#[cfg(feature = "reference")]
pub mod reference;
mod renderer;
mod scene_state;
pub mod screen;
pub mod settings;
mod view;
pub mod voxel;
#[cfg(all(test, feature = "reference"))]
mod wgsl_twins;

pub use error::{Error, Result};
pub use frame::targets::{FrameTargets, Target, surface_format};
pub use gpu::requirements::{check_device, minimum_limits, required_features, required_limits};
pub use options::{
    ConeSet, DIRECTIONS, FrameParams, IndirectShading, MAX_BOUNCES, MAX_IMAGE_SIZE,
    RendererOptions, ShadowFilter, Tonemap, UNLIMITED_BOUNCES, ViewMode, validate_size,
};
pub use output::RenderOutput;
#[cfg(feature = "reference")]
pub use reference::{Bounces, PathTracer, ReferenceMode, ReferenceOptions};
pub use renderer::{PreparedStep, Renderer, SequenceFrame, TEMPORAL_STILL_FRAMES, VoxelCounts};
pub use settings::{SceneSettings, Setting, parse_bounces};
pub use voxel::{VoxelKind, voxel_passes};
/// The scene model and loaders (re-exported from `voxgi-scene`).
pub use voxgi_scene as scene;
pub use voxgi_scene::prepare::{PointPreparation, PointsAhead, prepare_points};
/// The wgpu voxgi is built on: use it to create the device and textures you hand to voxgi.
pub use wgpu;
