//! The grid fragments lie on and structures are built over: a cube of `resolution`³ voxels.

use bytemuck::{Pod, Zeroable};
use glam::{IVec3, UVec3, Vec3};

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

/// A box of a grid's voxels, bounds included, where fragments are made: a pass that makes
/// fragments makes none outside it, nor inside its `kept` box. Empty when `hi` lies below `lo`
/// on some axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Region {
    /// The first voxel inside, per axis.
    pub lo: UVec3,
    /// The last voxel inside, per axis.
    pub hi: UVec3,
    /// A box of voxels, bounds included, left out after all (none when its `.1` lies below
    /// its `.0` on some axis): those a moved clipmap window keeps from its old place.
    pub kept: (UVec3, UVec3),
}

/// No voxels left out of a region.
const NONE_KEPT: (UVec3, UVec3) = (UVec3::ONE, UVec3::ZERO);

impl Region {
    /// Every voxel of `grid`.
    pub fn all(grid: &Grid) -> Self {
        Region {
            lo: UVec3::ZERO,
            hi: UVec3::splat(grid.resolution - 1),
            kept: NONE_KEPT,
        }
    }

    /// Every voxel of `grid` but those it keeps from where it lay before it moved by `moved`
    /// voxels (its new corner minus the old; the voxels of both places, where a voxel's old
    /// index is its new one plus `moved`).
    pub fn all_but_kept(grid: &Grid, moved: IVec3) -> Self {
        let r = grid.resolution as i32;
        let (lo, hi) = (
            (-moved).max(IVec3::ZERO),
            (r - 1 - moved).min(IVec3::splat(r - 1)),
        );
        Region {
            kept: if lo.cmple(hi).all() {
                (lo.as_uvec3(), hi.as_uvec3())
            } else {
                NONE_KEPT
            },
            ..Region::all(grid)
        }
    }

    /// No voxel.
    pub const EMPTY: Region = Region {
        lo: UVec3::ONE,
        hi: UVec3::ZERO,
        kept: NONE_KEPT,
    };

    /// The voxels of `grid` that the world box `min..max` touches, grown by `margin` voxels
    /// on every side and clipped to the grid (empty when the box lies outside).
    pub fn around(grid: &Grid, min: Vec3, max: Vec3, margin: u32) -> Self {
        let top = grid.resolution as f32 - 1.0;
        let voxel = |p: Vec3| (p - grid.origin) / grid.voxel_size;
        let (lo, hi) = (
            voxel(min).floor() - margin as f32,
            voxel(max).floor() + margin as f32,
        );
        if min.cmpgt(max).any()
            || !lo.is_finite()
            || !hi.is_finite()
            || lo.cmpgt(Vec3::splat(top)).any()
            || hi.cmplt(Vec3::ZERO).any()
        {
            return Region::EMPTY;
        }
        Region {
            lo: lo.max(Vec3::ZERO).as_uvec3(),
            hi: hi.min(Vec3::splat(top)).as_uvec3(),
            kept: NONE_KEPT,
        }
    }

    /// Whether it holds no voxel.
    pub fn is_empty(&self) -> bool {
        self.hi.cmplt(self.lo).any()
    }

    /// As `FragmentRegion` in shaders/shared/fragment.wgsl.
    pub fn to_gpu(self) -> GpuRegion {
        GpuRegion {
            lo: self.lo.to_array(),
            _pad0: 0,
            hi: self.hi.to_array(),
            _pad1: 0,
            kept_lo: self.kept.0.to_array(),
            _pad2: 0,
            kept_hi: self.kept.1.to_array(),
            _pad3: 0,
        }
    }
}

/// Mirrors `FragmentRegion` in shaders/shared/fragment.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuRegion {
    /// `Region::lo`.
    pub lo: [u32; 3],
    /// Padding; zero.
    pub _pad0: u32,
    /// `Region::hi`.
    pub hi: [u32; 3],
    /// Padding; zero.
    pub _pad1: u32,
    /// `Region::kept.0`.
    pub kept_lo: [u32; 3],
    /// Padding; zero.
    pub _pad2: u32,
    /// `Region::kept.1`.
    pub kept_hi: [u32; 3],
    /// Padding; zero.
    pub _pad3: u32,
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

    #[test]
    fn a_moved_window_keeps_the_voxels_of_both_places() {
        let g = Grid::around(Vec3::ZERO, Vec3::splat(1.0), 16);
        // Moved 4 voxels up x and 2 down z: new x 0..=11 were old 4..=15, new z 2..=15 old 0..=13.
        let r = Region::all_but_kept(&g, IVec3::new(4, 0, -2));
        assert_eq!(r.kept, (UVec3::new(0, 0, 2), UVec3::new(11, 15, 15)));
        assert_eq!((r.lo, r.hi), (Region::all(&g).lo, Region::all(&g).hi));
        // Moved a whole window: nothing kept.
        assert_eq!(
            Region::all_but_kept(&g, IVec3::new(0, 16, 0)),
            Region::all(&g)
        );
    }

    #[test]
    fn regions_cover_the_box_and_clip_to_the_grid() {
        let g = Grid::around(Vec3::ZERO, Vec3::splat(1.0), 16);
        assert_eq!(
            Region::around(&g, g.origin, g.origin + g.extent(), 0).hi,
            UVec3::splat(15)
        );
        let r = Region::around(&g, Vec3::splat(0.5), Vec3::splat(0.5), 1);
        let c = ((Vec3::splat(0.5) - g.origin) / g.voxel_size)
            .floor()
            .as_uvec3();
        assert_eq!((r.lo, r.hi), (c - 1, c + 1));
        assert!(Region::around(&g, Vec3::splat(5.0), Vec3::splat(6.0), 2).is_empty());
        assert!(!Region::all(&g).is_empty());
        assert!(Region::EMPTY.is_empty());
    }
}
