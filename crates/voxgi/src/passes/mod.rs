//! One module per pass. Each owns its pipelines and layouts; `renderer.rs` calls them in order.
//! The fragment passes live in `fragments/`, a structure's own passes with it in `voxel/<kind>/`.
//! A pass's module, WGSL file, pipeline label and timing scope share one name.

pub mod bounce;
pub mod composite;
pub mod gather;
pub mod gbuffer;
pub mod inject;
pub mod shadow;
pub mod tonemap;
pub mod upsample;
