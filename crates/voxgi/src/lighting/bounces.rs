//! How many bounces run in voxel space, and how many of them store their light, for the
//! options' bounce count and indirect shading.

use crate::options::{IndirectShading, RendererOptions, UNLIMITED_BOUNCES};

/// Whether the pixels read the leaves' irradiance (the fast shading).
pub fn leaves(options: &RendererOptions) -> bool {
    options.indirect == IndirectShading::Leaves
}

/// Of `voxel_bounces` per update, those that store their light into the structure: all of them
/// with cones or progressive bounces, all but the last (which keeps the leaves' records) with
/// leaves.
pub fn stored_bounces(options: &RendererOptions, voxel_bounces: u32) -> u32 {
    if leaves(options) && !options.progressive {
        voxel_bounces.saturating_sub(1)
    } else {
        voxel_bounces
    }
}

/// Voxel-space bounces for a total of `options.bounces` indirect bounces: with cones the
/// per-pixel gather adds one; with leaves every bounce runs in voxel space, and at least one
/// runs (with no indirect light, for the occlusion it keeps).
pub fn voxel_bounce_count(max_albedo: f32, options: &RendererOptions) -> u32 {
    let in_voxels = |cones: u32| {
        if leaves(options) { cones + 1 } else { cones }
    };
    let bounces = options.bounces;
    if bounces != UNLIMITED_BOUNCES {
        return in_voxels(bounces.saturating_sub(1));
    }
    // Until the energy left, max albedo^k, is below 0.1 %.
    let rho = max_albedo.clamp(0.0, 0.99);
    if rho <= 0.0 {
        return in_voxels(0);
    }
    in_voxels(((1e-3f32.ln() / rho.ln()).ceil() as u32).clamp(1, 64))
}
