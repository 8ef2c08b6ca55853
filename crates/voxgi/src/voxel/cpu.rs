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
/// values (the chains store them; the finest level stores optical depth: convert it with
/// `from_depth`). `children[i]` is the
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

/// How much of a leaf the first directional level counts along direction `dir` (0..6: +X, -X,
/// +Y, -Y, +Z, -Z, the way a cone travels), from its mean normal (xyz) and how well its
/// fragments' normals agree (w, Toksvig's length of the mean normal): all of it where the cone
/// meets its face head-on or edge-on, falling to nothing as it comes from behind (1 + cos),
/// blended towards 1 as the normals disagree. Seen from behind a face neither lights nor
/// stops a cone: behind it lies the front of the solid it bounds, or the cone's own surface
/// (the far side of a ledge its cone clears). Salm (§4.4.2) falls off from 1 head-on to 1/2
/// edge-on too; edge-on leaves at half then let cones out of closed rooms through their edges
/// and corners, and through a block's sides along them (docs/QUALITY.md, "Normal
/// distributions by default"). `ndf_weight` in shared/volume.wgsl.
pub fn ndf_weight(normal: Vec4, dir: u32) -> f32 {
    let n = normal.truncate();
    let len = n.length();
    if len < 1e-4 {
        return 1.0;
    }
    let axis = (dir / 2) as usize;
    let sign = if dir.is_multiple_of(2) { 1.0 } else { -1.0 };
    // The face a cone travelling along +axis meets has its normal along -axis.
    let facing = -sign * n[axis] / len;
    let directional = (1.0 + facing).min(1.0);
    1.0 + normal.w.clamp(0.0, 1.0) * (directional - 1.0)
}

/// A 3D texture's mip chain on the CPU: texels (x fastest) and size per level.
pub struct Texture3d {
    /// Per mip level, finest first: the texels (x fastest, then y, then z) and the size in texels.
    pub levels: Vec<(Vec<Vec4>, UVec3)>,
}

impl Texture3d {
    fn texel(&self, level: usize, c: [i64; 3]) -> Vec4 {
        let (texels, size) = &self.levels[level];
        let [x, y, z] = [0, 1, 2].map(|a| c[a].clamp(0, size[a] as i64 - 1) as u32);
        texels[(x + size.x * (y + size.y * z)) as usize]
    }

    /// `textureSampleLevel` with a trilinear, clamp-to-edge sampler at one level.
    fn sample_at(&self, level: usize, uvw: Vec3) -> Vec4 {
        let size = self.levels[level].1.as_vec3();
        let t = uvw * size - 0.5;
        let base = t.floor();
        let f = t - base;
        let b = [base.x as i64, base.y as i64, base.z as i64];
        let mut out = Vec4::ZERO;
        for i in 0..8 {
            let o = [i & 1, (i >> 1) & 1, i >> 2];
            let w = (0..3)
                .map(|a| if o[a] == 1 { f[a] } else { 1.0 - f[a] })
                .product::<f32>();
            out += w * self.texel(level, [b[0] + o[0], b[1] + o[1], b[2] + o[2]]);
        }
        out
    }

    /// `textureSampleLevel` with linear filtering between levels.
    pub fn sample(&self, uvw: Vec3, lod: f32) -> Vec4 {
        let top = self.levels.len() - 1;
        let lod = lod.clamp(0.0, top as f32);
        let lo = lod.floor() as usize;
        let hi = (lo + 1).min(top);
        self.sample_at(lo, uvw)
            .lerp(self.sample_at(hi, uvw), lod - lo as f32)
    }
}

/// The dense volume as `voxels/dense/sample.wgsl` reads it: placement, the finest level and
/// the directional chains (six blocks stacked along z, or one).
pub struct DenseSampler<'a> {
    /// The volume's placement (origin, voxel size, finest resolution).
    pub grid: Grid,
    /// Whether `chains` holds six directional blocks (stacked along z) rather than one.
    pub anisotropic: bool,
    /// Cubes of `grid.resolution` voxels stacked along z in both textures (`Volume::windows`:
    /// 1, or a clipmap's levels).
    pub windows: u32,
    /// The finest level: stored (L sigma, sigma) per voxel.
    pub radiance0: &'a Texture3d,
    /// The levels above the finest, from half the resolution down: stored premultiplied
    /// (L alpha, alpha).
    pub chains: &'a Texture3d,
}

impl DenseSampler<'_> {
    fn uvw(&self, p: Vec3) -> Vec3 {
        (p - self.grid.origin) / self.grid.extent()
    }

    fn inside(uvw: Vec3) -> bool {
        uvw.cmpge(Vec3::ZERO).all() && uvw.cmple(Vec3::ONE).all()
    }

    /// `chain_along`: block `b` (counted with its window, of `blocks`) at chain level `c`, seen
    /// along `axis`: the two layers of texels around `uvw` along it, each turned to optical
    /// depth, interpolated.
    fn chain_along(&self, uvw: Vec3, c: usize, b: f32, blocks: f32, axis: usize) -> Vec4 {
        let n = ((self.grid.resolution / 2) as f32 * (-(c as f32)).exp2()).max(1.0);
        let lo = 0.5 / n;
        let p = uvw[axis] * n - 0.5;
        let layer = p.floor();
        let mut q0 = uvw.clamp(Vec3::splat(lo), Vec3::splat(1.0 - lo));
        let mut q1 = q0;
        q0[axis] = ((layer + 0.5) / n).clamp(lo, 1.0 - lo);
        q1[axis] = ((layer + 1.5) / n).clamp(lo, 1.0 - lo);
        let at = |q: Vec3| {
            to_depth(
                self.chains
                    .sample_at(c, Vec3::new(q.x, q.y, (q.z + b) / blocks)),
            )
        };
        at(q0).lerp(at(q1), p - layer)
    }

    /// `sample_chains` of window `win` at chain level `cl` (an integer), with every axis read
    /// (`SAMPLE_AXES` = 3).
    fn chains(&self, uvw: Vec3, cl: usize, dir: Vec3, win: u32) -> Vec4 {
        let (window, windows) = (win as f32, self.windows as f32);
        let w = if self.anisotropic {
            dir * dir
        } else {
            Vec3::AXES[main_axis(dir)]
        };
        // Each direction's block holds every window: block b, window w at b · windows + w.
        let (block, blocks) = if self.anisotropic {
            let block = Vec3::new(
                if dir.x >= 0.0 { 0.0 } else { 1.0 },
                if dir.y >= 0.0 { 2.0 } else { 3.0 },
                if dir.z >= 0.0 { 4.0 } else { 5.0 },
            );
            (block * windows + window, 6.0 * windows)
        } else {
            (Vec3::splat(window), windows)
        };
        (0..3)
            .filter(|&axis| w[axis] > 0.0)
            .map(|axis| w[axis] * self.chain_along(uvw, cl, block[axis], blocks, axis))
            .sum()
    }

    /// `window_depth`: optical depth at `uvw` over window `win`, at the level nearest `lod`
    /// levels above its finest, seen along `dir`.
    pub fn window_depth(&self, uvw: Vec3, lod: f32, dir: Vec3, win: u32) -> Vec4 {
        if lod < 0.5 {
            let n = self.grid.resolution as f32;
            let inside = if self.windows > 1 {
                uvw.z.clamp(0.5 / n, 1.0 - 0.5 / n)
            } else {
                uvw.z
            };
            let z = (win as f32 + inside) / self.windows as f32;
            return self.radiance0.sample(Vec3::new(uvw.x, uvw.y, z), 0.0);
        }
        let top = self.grid.levels() as f32 - 2.0;
        let cl = (lod - 1.0 + 0.5).floor().clamp(0.0, top) as usize;
        self.chains(uvw, cl, dir, win)
    }

    /// `sample_depth`: optical depth per sample diameter, filtered to `diameter`.
    pub fn sample_depth(&self, p: Vec3, diameter: f32, dir: Vec3) -> Vec4 {
        let uvw = self.uvw(p);
        if !Self::inside(uvw) {
            return Vec4::ZERO;
        }
        let vs = self.grid.voxel_size;
        let top = self.grid.levels() as f32 - 1.0;
        let lod = (diameter / vs).max(1.0).log2().clamp(0.0, top);
        self.window_depth(uvw, lod, dir, 0) * border_weight(uvw, lod, self.grid.resolution)
    }

    /// `sample_voxels`: premultiplied radiance and opacity.
    pub fn sample_voxels(&self, p: Vec3, diameter: f32, dir: Vec3) -> Vec4 {
        from_depth(self.sample_depth(p, diameter, dir))
    }
}

/// The axis an isotropic block is read along: `dir`'s largest component, ties to x, then y
/// (`main_axis` in shaders/shared/volume.wgsl).
pub fn main_axis(dir: Vec3) -> usize {
    let a = dir.abs();
    if a.x >= a.y && a.x >= a.z {
        0
    } else if a.y >= a.z {
        1
    } else {
        2
    }
}

/// The share of a sample's trilinear filter at level of detail `lod` that lies inside a volume
/// of `resolution` finest voxels a side: `border_weight` in shared/volume.wgsl, which says why.
pub fn border_weight(uvw: Vec3, lod: f32, resolution: u32) -> f32 {
    let u = uvw.min(Vec3::ONE - uvw) * resolution as f32 * (-lod).exp2();
    let f = (u + 0.5).clamp(Vec3::splat(0.5), Vec3::ONE);
    f.x * f.y * f.z
}

/// Subdivisions of a voxel edge in which `splat` places a region of influence (`SUB` in
/// splat.wgsl).
pub const SPLAT_SUB: u32 = 1024;
/// A voxel face in fragment-weight units (`WEIGHT_ONE` in shared/fragment.wgsl).
pub const WEIGHT_ONE: u32 = 4096;

/// One fragment of a point (`splat`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct PointFragment {
    /// The voxel.
    pub cell: [u32; 3],
    /// The overlap of the point's region with the voxel, in (1/`SPLAT_SUB` voxel)³.
    pub overlap: u32,
    /// The fragment's weight: the share of the point's area in the voxel, in 1/`WEIGHT_ONE`
    /// voxel faces (without the density flag).
    pub weight: u32,
}

/// PCG's output permutation, as `hash` in splat.wgsl.
fn splat_hash(v: u32) -> u32 {
    let state = v.wrapping_mul(747796405).wrapping_add(2891336453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277803737);
    (word >> 22) ^ word
}

/// The region edge `splat` uses, in 1/`SPLAT_SUB` voxel: `region` metres (0: a point alone)
/// clamped to one voxel.
pub fn splat_edge(grid: &Grid, region: f32) -> u32 {
    let e_in = region * (1.0 / grid.voxel_size);
    let e = if e_in > 0.0 { e_in.min(1.0) } else { 1.0 };
    ((e * SPLAT_SUB as f32).round_ties_even() as u32).clamp(1, SPLAT_SUB)
}

/// Point `index` at world `position` with unit `normal` (as the GPU decodes it; zero for
/// none) and a region of influence of edge `region` metres behind it, split over the voxels of
/// `grid` as splat.wgsl does it, step for step in the same integers:
/// every voxel inside the grid that the region overlaps, with its weight (the GPU emits a
/// fragment where the weight is not 0).
pub fn splat(
    grid: &Grid,
    index: u32,
    position: Vec3,
    normal: Vec3,
    region: f32,
) -> Vec<PointFragment> {
    let inv = 1.0 / grid.voxel_size;
    let p = (position - grid.origin) * inv;
    let eq = splat_edge(grid, region);
    let behind = (normal * (0.5 * eq as f32))
        .map(f32::round_ties_even)
        .as_ivec3();
    let lo =
        (p * SPLAT_SUB as f32).floor().as_ivec3() - glam::IVec3::splat((eq / 2) as i32) - behind;
    let c0: glam::IVec3 = lo >> 10;
    let o0 = ((lo + glam::IVec3::splat(eq as i32)).min((c0 + 1) << 10) - lo).as_uvec3();
    let o1 = UVec3::splat(eq) - o0;
    let den = eq * (SPLAT_SUB * SPLAT_SUB / WEIGHT_ONE);
    let res = grid.resolution as i32;
    let mut out = Vec::new();
    for k in 0..8u32 {
        let b = UVec3::new(k & 1, (k >> 1) & 1, (k >> 2) & 1);
        let o = UVec3::select(b.cmpeq(UVec3::ONE), o1, o0);
        let cell = c0 + b.as_ivec3();
        if o.cmpeq(UVec3::ZERO).any()
            || cell.cmplt(glam::IVec3::ZERO).any()
            || cell.cmpge(glam::IVec3::splat(res)).any()
        {
            continue;
        }
        let overlap = o.x * o.y * o.z;
        let up = (splat_hash(index.wrapping_mul(8).wrapping_add(k)) % den < overlap % den) as u32;
        out.push(PointFragment {
            cell: cell.as_uvec3().to_array(),
            overlap,
            weight: overlap / den + up,
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ndf_weight_counts_faces_by_how_a_cone_meets_them() {
        let floor = Vec4::new(0.0, 1.0, 0.0, 1.0);
        // A cone travelling down (-Y, direction 3) meets the floor head-on; up (+Y) from behind;
        // along x edge-on, where it counts whole.
        assert_eq!(ndf_weight(floor, 3), 1.0);
        assert_eq!(ndf_weight(floor, 2), 0.0);
        assert_eq!(ndf_weight(floor, 0), 1.0);
        assert_eq!(ndf_weight(floor, 5), 1.0);
        // Half way between edge-on and behind: half.
        let tilted = Vec4::new(0.0, 0.5, -(0.75f32.sqrt()), 1.0);
        assert!((ndf_weight(tilted, 2) - 0.5).abs() < 1e-6);
        // Normals that disagree (Toksvig's length 0.4) count 60 % isotropic.
        let rough = Vec4::new(0.0, 0.4, 0.0, 0.4);
        assert!((ndf_weight(rough, 2) - 0.6).abs() < 1e-6);
        // Two-sided (normals cancel) or empty: isotropic.
        assert_eq!(ndf_weight(Vec4::ZERO, 1), 1.0);
    }

    #[test]
    fn a_points_region_overlaps_sum_to_its_volume() {
        // Points anywhere inside a 16³ grid, regions from a thousandth of a voxel to two
        // (clamped to one), normals along the axes and diagonals: the overlaps of each point
        // sum to its region's volume exactly (integers), and its weights to its region's area
        // within the rounding of at most eight fragments.
        let grid = Grid {
            origin: Vec3::new(-1.0, -0.5, 0.25),
            voxel_size: 0.125,
            resolution: 16,
        };
        let mut s = 0x9e37_79b9u32;
        let mut next = move || {
            s ^= s << 13;
            s ^= s >> 17;
            s ^= s << 5;
            s as f32 / u32::MAX as f32
        };
        let normals = [
            Vec3::X,
            Vec3::NEG_Y,
            Vec3::new(1.0, 1.0, -1.0).normalize(),
            Vec3::ZERO,
        ];
        for i in 0..20_000u32 {
            let p = grid.origin
                + Vec3::new(next(), next(), next()) * (grid.voxel_size * 14.0)
                + Vec3::splat(grid.voxel_size);
            let region = grid.voxel_size * 0.001 * 2000f32.powf(next());
            let n = normals[i as usize % normals.len()];
            let f = splat(&grid, i, p, n, region);
            let eq = splat_edge(&grid, region);
            let volume: u64 = f.iter().map(|f| f.overlap as u64).sum();
            assert_eq!(volume, (eq as u64).pow(3), "point {i} at {p}, edge {eq}");
            assert!(f.len() <= 8);
            let weight: u64 = f.iter().map(|f| f.weight as u64).sum();
            // Area in weight units: eq² / SUB² voxel faces times WEIGHT_ONE.
            let area = (eq as f64).powi(2) / (SPLAT_SUB as f64).powi(2) * WEIGHT_ONE as f64;
            assert!(
                (weight as f64 - area).abs() <= f.len() as f64,
                "point {i}: weights {weight} against an area of {area}"
            );
        }
    }

    #[test]
    fn a_region_lies_behind_its_point() {
        // A point on a voxel face with its normal along +x fills the voxel behind it (-x) only;
        // along -x, the one in front.
        let grid = Grid {
            origin: Vec3::ZERO,
            voxel_size: 1.0,
            resolution: 8,
        };
        let p = Vec3::new(4.0, 2.5, 2.5);
        let behind = splat(&grid, 0, p, Vec3::X, 0.5);
        assert_eq!(behind.len(), 1);
        assert_eq!(behind[0].cell, [3, 2, 2]);
        let front = splat(&grid, 0, p, Vec3::NEG_X, 0.5);
        assert_eq!(front[0].cell, [4, 2, 2]);
        // Without a normal the region is centred: half in each.
        let centred = splat(&grid, 0, p, Vec3::ZERO, 0.5);
        assert_eq!(centred.len(), 2);
        assert_eq!(centred[0].overlap, centred[1].overlap);
    }
}
