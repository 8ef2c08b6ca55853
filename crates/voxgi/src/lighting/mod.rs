//! Light into the voxels: the shadow atlas, the shadow pass that fills it and `moments` that
//! prefilters it for the VSM/ESM filter, `inject` (direct
//! light and emission into the structure's leaves) and `bounce` (further bounces in voxel
//! space). A pass's module, WGSL file (`shaders/lighting/`), pipeline label and timing scope
//! share one name; `renderer.rs` calls them in order.

pub mod atlas;
pub mod blend;
pub mod bounce;
pub mod bounces;
pub mod cones;
pub mod inject;
pub mod moments;
pub mod shadow;
