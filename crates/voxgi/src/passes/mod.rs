//! One module per pass. Each owns its pipelines and layouts; `frame.rs` calls them in order.
//! A pass's module, WGSL file, pipeline label and timing scope share one name.

pub mod composite;
pub mod gbuffer;
pub mod shadow;
pub mod tonemap;
