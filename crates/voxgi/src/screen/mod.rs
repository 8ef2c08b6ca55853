//! The passes over the screen: `gbuffer`, `gather`, `upsample`, `composite`, `temporal` and
//! `tonemap`
//! (the only one that touches the caller's texture). A pass's module, WGSL file
//! (`shaders/screen/`), pipeline label and timing scope share one name; `renderer.rs` calls
//! them in order.

pub mod composite;
pub mod gather;
pub mod gbuffer;
pub mod temporal;
pub mod tonemap;
pub mod upsample;
