//! One module per pass. Each owns its pipelines and layouts; `frame.rs` calls them in order.
//! A pass's module, WGSL file, pipeline label and timing scope share one name.

pub mod bounce;
pub mod composite;
pub mod debug;
pub mod filter;
pub mod gather;
pub mod gbuffer;
pub mod inject;
pub mod shadow;
pub mod tonemap;
pub mod upsample;
pub mod voxelize;
