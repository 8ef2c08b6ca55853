//! GPU tests: one binary (linking wgpu once), one module per topic, one shared device.
//! They run on whatever adapter the environment picks (`WGPU_BACKEND`, `WGPU_ADAPTER_NAME`);
//! in CI that is Mesa's lavapipe.

mod analytic;
mod clipmap;
mod common;
mod compare;
mod contract;
mod dynamic;
mod embed;
mod errors;
mod fast_shading;
mod golden;
mod layering;
mod ndf_mips;
mod options;
mod point_gi;
mod points;
mod prepare;
mod probe;
mod reference;
mod registry;
mod resize;
mod shaders;
mod shadow_filter;
mod sizing;
mod temporal;
mod vct;
mod voxels;
