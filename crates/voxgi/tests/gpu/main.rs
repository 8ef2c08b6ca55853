//! GPU tests: one binary sharing one device (see `common::ctx`).

mod common;
mod points;
