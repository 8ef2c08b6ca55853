//! The diffuse cone sets' geometry and weights, and the cone uniform (`Cones` in
//! shaders/shared/volume.wgsl) the gather and the bounce read.

use crate::fragments::Grid;
use crate::options::{ConeSet, RendererOptions};
use bytemuck::{Pod, Zeroable};
use glam::Vec3;

/// Mirrors `Cones` in shaders/shared/volume.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuCones {
    /// Per cone: tangent-space axis (xyz, z = normal) and weight (w; the cone's share of the
    /// cosine-weighted hemisphere, summing to 1 over the cones). Entries past `count` are zero.
    pub dirs: [[f32; 4]; 16],
    /// Number of cones used in `dirs` (at most 16).
    pub count: u32,
    /// Tangent of the diffuse cones' half-angle.
    pub diffuse_tan: f32,
    /// Sample step as a fraction of the cone diameter.
    pub step_factor: f32,
    /// Cones stop after this distance, metres.
    pub max_distance: f32,
    /// Ambient occlusion falloff lambda in 1/(1 + lambda r), per metre.
    pub ao_lambda: f32,
    /// Ambient occlusion rays stop at this distance, metres.
    pub ao_radius: f32,
    /// Offset of the cone origin along the normal, in finest voxels.
    pub origin_offset: f32,
    /// 1: the per-pixel gather adds indirect light, 0: it does not (bounces = 0).
    pub indirect: u32,
    /// 1: each diffuse cone traces one quarter of its footprint; 0: the whole footprint.
    pub quarters: u32,
    /// Padding to a multiple of 16 bytes; zero.
    pub _pad: [u32; 3],
}

impl ConeSet {
    /// Full aperture angle of each cone in radians.
    pub fn aperture(&self) -> f32 {
        match self {
            ConeSet::Six60 => 60f32.to_radians(),
            _ => 45f32.to_radians(),
        }
    }

    /// Tangent of each cone's half-angle.
    pub fn half_angle_tan(&self) -> f32 {
        (self.aperture() * 0.5).tan()
    }

    /// Tangent-space axes (z = normal).
    pub fn axes(&self) -> Vec<Vec3> {
        let (ring, tilt) = match self {
            ConeSet::Six60 => (5, 60f32),
            ConeSet::Seven45 => (6, 45f32),
            ConeSet::Nine45 => (8, 50f32),
        };
        let mut v = vec![Vec3::Z];
        let t = tilt.to_radians();
        for i in 0..ring {
            let phi = i as f32 / ring as f32 * std::f32::consts::TAU;
            v.push(Vec3::new(t.sin() * phi.cos(), t.sin() * phi.sin(), t.cos()));
        }
        v
    }

    /// Each cone's weight: the cosine-weighted solid angle of the part of the hemisphere whose
    /// directions are nearest its axis, as a fraction of the whole (pi). The cones stand for
    /// their cells, so the weights sum to exactly 1 and no empirical factor is needed.
    pub fn weights(&self) -> Vec<f32> {
        cell_weights(&self.axes())
    }
}

/// Cosine-weighted hemisphere fractions of the nearest-axis cells, by midpoint quadrature in
/// (cos²θ, φ), where the cosine-weighted measure is uniform.
pub fn cell_weights(axes: &[Vec3]) -> Vec<f32> {
    let (nu, nphi) = (256, 1024);
    let mut w = vec![0f64; axes.len()];
    for i in 0..nu {
        // u = sin²θ is uniform under the cosine-weighted measure.
        let u = (i as f32 + 0.5) / nu as f32;
        let (s, c) = (u.sqrt(), (1.0 - u).sqrt());
        for j in 0..nphi {
            let phi = (j as f32 + 0.5) / nphi as f32 * std::f32::consts::TAU;
            let d = Vec3::new(s * phi.cos(), s * phi.sin(), c);
            let best = axes
                .iter()
                .enumerate()
                .max_by(|a, b| a.1.dot(d).total_cmp(&b.1.dot(d)))
                .map(|(k, _)| k)
                .unwrap_or(0);
            w[best] += 1.0;
        }
    }
    let total: f64 = w.iter().sum();
    w.into_iter().map(|x| (x / total) as f32).collect()
}

/// The cone uniforms from the options and the volume.
pub fn cone_uniforms(options: &RendererOptions, grid: &Grid) -> GpuCones {
    let axes = options.cones.axes();
    let weights = options.cones.weights();
    let mut dirs = [[0f32; 4]; 16];
    for (i, (a, w)) in axes.iter().zip(&weights).enumerate().take(16) {
        dirs[i] = [a.x, a.y, a.z, *w];
    }
    GpuCones {
        dirs,
        count: axes.len().min(16) as u32,
        diffuse_tan: options.cones.half_angle_tan(),
        step_factor: options.step_factor,
        max_distance: options.max_distance.unwrap_or(grid.extent() * 3f32.sqrt()),
        ao_lambda: options.ao_lambda,
        ao_radius: options.ao_radius.unwrap_or(grid.extent() * 0.25),
        origin_offset: options.origin_offset,
        indirect: (options.bounces > 0) as u32,
        quarters: options.cone_quarters as u32,
        _pad: [0; 3],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cone_weights_partition_the_cosine_hemisphere() {
        for set in [ConeSet::Six60, ConeSet::Seven45, ConeSet::Nine45] {
            let w = set.weights();
            assert_eq!(w.len(), set.axes().len());
            // Quadrature of a partition: the fractions sum to 1 up to float rounding.
            assert!((w.iter().sum::<f32>() - 1.0).abs() < 1e-5, "{set:?}: {w:?}");
            // The ring cones are symmetric, so they get equal weights (to quadrature error).
            for &x in &w[2..] {
                assert!((x - w[1]).abs() < 2e-3, "{set:?}: {w:?}");
            }
        }
    }
}
