//! The grid fragments lie on and structures are built over: a cube of `resolution`³ voxels.

use glam::Vec3;

/// A cubic grid over the scene: `resolution` voxels per side from `origin`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    /// World position of the grid's minimum corner, metres.
    pub origin: Vec3,
    /// Edge length of a voxel, metres.
    pub voxel_size: f32,
    /// Voxels per side (a power of two).
    pub resolution: u32,
}

impl Grid {
    /// The cube around the scene bounds with one empty voxel of margin on every side, so walls
    /// on the bounds (the Cornell box's) lie inside the volume, not on its edge.
    pub fn around(min: Vec3, max: Vec3, resolution: u32) -> Self {
        let (min, max) = if min.x > max.x {
            (Vec3::splat(-0.5), Vec3::splat(0.5))
        } else {
            (min, max)
        };
        let extent = (max - min).max_element().max(1e-3);
        let side = extent * resolution as f32 / (resolution as f32 - 2.0);
        let center = (min + max) * 0.5;
        Grid {
            origin: center - Vec3::splat(side * 0.5),
            voxel_size: side / resolution as f32,
            resolution,
        }
    }

    /// Edge length of the whole grid, metres.
    pub fn extent(&self) -> f32 {
        self.voxel_size * self.resolution as f32
    }

    /// Mip levels including the finest (down to 1 voxel).
    pub fn levels(&self) -> u32 {
        self.resolution.ilog2() + 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_has_a_margin_voxel() {
        let g = Grid::around(Vec3::ZERO, Vec3::new(2.0, 1.0, 1.0), 64);
        assert!((g.extent() - 2.0 * 64.0 / 62.0).abs() < 1e-5);
        assert!((g.origin.x + g.voxel_size).abs() < 1e-5);
        assert_eq!(g.levels(), 7);
    }
}
