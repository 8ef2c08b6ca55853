//! Plain Rust versions of the voxel kernels, for testing the GPU against (exact for occupancy,
//! epsilon for filtering).

use super::Grid;
use glam::{UVec3, Vec3, Vec4};
use std::collections::BTreeSet;

fn separated(a: Vec3, v0: Vec3, v1: Vec3, v2: Vec3, h: f32) -> bool {
    let (p0, p1, p2) = (v0.dot(a), v1.dot(a), v2.dot(a));
    let r = h * (a.x.abs() + a.y.abs() + a.z.abs());
    p0.min(p1).min(p2) > r || p0.max(p1).max(p2) < -r
}

/// Triangle / box overlap by the 13 separating axes, as `voxelize.wgsl` does it.
pub fn tri_box_overlap(center: Vec3, h: f32, a: Vec3, b: Vec3, c: Vec3) -> bool {
    let (v0, v1, v2) = (a - center, b - center, c - center);
    let edges = [v1 - v0, v2 - v1, v0 - v2];
    for axis in [Vec3::X, Vec3::Y, Vec3::Z] {
        if separated(axis, v0, v1, v2, h) {
            return false;
        }
        for e in edges {
            let ax = axis.cross(e);
            if ax.length_squared() > 1e-20 && separated(ax, v0, v1, v2, h) {
                return false;
            }
        }
    }
    !separated(edges[0].cross(edges[1]), v0, v1, v2, h)
}

/// The voxels a set of world-space triangles touches.
pub fn voxelize(triangles: &[[Vec3; 3]], grid: &Grid) -> BTreeSet<[u32; 3]> {
    let mut out = BTreeSet::new();
    let res = grid.resolution as i32;
    for t in triangles {
        let [a, b, c] = t.map(|p| (p - grid.origin) / grid.voxel_size);
        if (b - a).cross(c - a).length() < 1e-12 {
            continue;
        }
        let lo = a.min(b).min(c).floor().as_ivec3().max(glam::IVec3::ZERO);
        let hi = a
            .max(b)
            .max(c)
            .floor()
            .as_ivec3()
            .min(glam::IVec3::splat(res - 1));
        for z in lo.z..=hi.z {
            for y in lo.y..=hi.y {
                for x in lo.x..=hi.x {
                    let center = Vec3::new(x as f32, y as f32, z as f32) + 0.5;
                    if tri_box_overlap(center, 0.5, a, b, c) {
                        out.insert([x as u32, y as u32, z as u32]);
                    }
                }
            }
        }
    }
    out
}

/// Largest opacity a radiance texel stores (`MAX_OPACITY` in shaders/shared/volume.wgsl).
pub const MAX_OPACITY: f32 = 0.999;

/// Premultiplied (L alpha, alpha) to the stored (L sigma, sigma), as `to_depth` in volume.wgsl.
pub fn to_depth(v: Vec4) -> Vec4 {
    let a = v.w.clamp(0.0, MAX_OPACITY);
    let sigma = -(1.0 - a).ln();
    (v.truncate() * (sigma / a.max(1e-6))).extend(sigma)
}

/// Stored (L sigma, sigma) to premultiplied (L alpha, alpha), as `from_depth` in volume.wgsl.
pub fn from_depth(v: Vec4) -> Vec4 {
    let sigma = v.w.max(0.0);
    let a = 1.0 - (-sigma).exp();
    (v.truncate() * (a / sigma.max(1e-6))).extend(a)
}

/// One filtering step for one parent voxel, as `filter.wgsl` does it, on premultiplied
/// values (the textures store optical depth: convert with `from_depth` and `to_depth`). `children[i]` is the
/// child at offset (i & 1, (i >> 1) & 1, i >> 2); `dir` is None for the isotropic mean or
/// Some(0..6) for +X, -X, +Y, -Y, +Z, -Z.
pub fn filter_parent(children: &[Vec4; 8], dir: Option<u32>) -> Vec4 {
    let Some(dir) = dir else {
        return children.iter().copied().sum::<Vec4>() * 0.125;
    };
    let axis = (dir / 2) as usize;
    let positive = dir % 2 == 0;
    let at = |o: UVec3| children[(o.x + 2 * o.y + 4 * o.z) as usize];
    let mut sum = Vec4::ZERO;
    for i in 0..4u32 {
        let mut front = UVec3::ZERO;
        front[(axis + 1) % 3] = i & 1;
        front[(axis + 2) % 3] = i >> 1;
        let mut back = front;
        front[axis] = if positive { 0 } else { 1 };
        back[axis] = if positive { 1 } else { 0 };
        let (f, b) = (at(front), at(back));
        sum += f + (1.0 - f.w) * b;
    }
    sum * 0.25
}
