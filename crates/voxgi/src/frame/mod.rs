//! The frame: the formats of its targets, the targets of one output size, the frame uniform
//! and the globals every screen pass binds at `@group(0)`. It sits below every pass: passes
//! import it, it imports no pass. The order the passes run in is `renderer/order.rs`.

pub mod formats;
pub mod globals;
pub mod history;
pub mod sequence;
pub mod targets;
pub mod uniforms;
