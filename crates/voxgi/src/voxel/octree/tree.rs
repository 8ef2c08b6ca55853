//! The octree's GPU layout, described once in shaders/voxels/octree/tree.wgsl: the sizes and
//! strides the Rust side shares with it, the `Octree` uniform and the brick atlases' shapes.

use bytemuck::{Pod, Zeroable};

/// Format of both atlases: level 0 (the leaves) optical depth (L sigma, sigma), the levels
/// above premultiplied opacity (L alpha, alpha), as the dense volume's finest level and chains.
pub const ATLAS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// u32 per node above the leaves: child pointer and the -x, -y, -z neighbours (`NODE_STRIDE`;
/// a leaf voxel keeps its child word only).
pub const NODE_WORDS: u64 = 4;
/// u32 per leaf slot (`SLOT_STRIDE` in tree.wgsl): what the leaf is.
pub const SLOT_WORDS: u64 = 6;
/// u32 per leaf slot of the build's sums and the static slot an update's slot stands in for
/// (`ACCUM_STRIDE` in tree.wgsl), in the scratch buffer only builds and updates bind.
pub const ACCUM_WORDS: u64 = 14;
/// Bytes per leaf slot across the slot, direct-light and bounce buffers.
pub const SLOT_BYTES: u64 = SLOT_WORDS * 4 + 32;
/// Words of counters before the nodes in the node buffer (`NODE_HEADER` in tree.wgsl).
pub(super) const NODE_HEADER: u64 = 64;
/// Dispatch sizes (u32): fragments, leaves, the nodes of each depth, the new nodes of each
/// depth, the last update's leaves, the static fragments (`ARGS_NEW`, `ARGS_CLEAR`,
/// `ARGS_STATIC` in octree_update.wgsl).
pub(super) const ARGS_WORDS: u64 = 78;
pub(super) const ARGS_NEW: u64 = 39;
pub(super) const ARGS_CLEAR: u64 = 72;
pub(super) const ARGS_STATIC: u64 = 75;
/// u32 per tile in the tile buffer (`TILE_WORDS` in tree.wgsl).
pub(super) const TILE_WORDS: u64 = 2;
/// Deepest depth of the top grid (`GRID_DEPTH` in tree.wgsl).
pub(super) const GRID_DEPTH: u32 = 6;
/// Stride of the per-depth uniforms (the minimum dynamic-offset alignment).
pub(super) const LEVEL_STRIDE: u64 = 256;
/// Texels per brick side.
pub(super) const BRICK: u32 = 3;
/// The filter's flags: one r32uint texel per node above the leaves, `1 << FLAG_SHIFT` a row
/// (`FLAG_SHIFT` in tree.wgsl).
pub(super) const FLAG_SHIFT: u32 = 12;
pub(super) const FLAG_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;

/// The constants above that octree_update.wgsl (and tree.wgsl, which it includes) defines
/// too, by their WGSL names: a test holds the two sides equal.
#[cfg(test)]
pub(crate) const SHARED_CONSTANTS: &[(&str, u64)] = &[
    ("NODE_STRIDE", NODE_WORDS),
    ("SLOT_STRIDE", SLOT_WORDS),
    ("ACCUM_STRIDE", ACCUM_WORDS),
    ("NODE_HEADER", NODE_HEADER),
    ("TILE_WORDS", TILE_WORDS),
    ("GRID_DEPTH", GRID_DEPTH as u64),
    ("ARGS_NEW", ARGS_NEW),
    ("ARGS_CLEAR", ARGS_CLEAR),
    ("ARGS_STATIC", ARGS_STATIC),
    ("STOOD_IN", super::STOOD_IN_COUNTED as u64),
    ("STATIC_SLOTS", super::STATIC_COUNTED as u64),
    ("FLAG_SHIFT", FLAG_SHIFT as u64),
];

/// Mirrors `Octree` in shaders/voxels/octree/tree.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuOctree {
    /// World position of the volume's minimum corner, metres.
    pub origin: [f32; 3],
    /// Finest voxels per side.
    pub resolution: u32,
    /// Edge of a finest voxel, metres.
    pub voxel_size: f32,
    /// log2(resolution).
    pub depth: u32,
    /// 1: six directional values above the finest level.
    pub anisotropic: u32,
    /// Atlas slots per brick above level 0.
    pub dirs: u32,
    /// First tile of class V (leaf voxels).
    pub base_v: u32,
    /// First tile of class E (bricks of even levels above 0).
    pub base_e: u32,
    /// First tile of class O (bricks of odd levels).
    pub base_o: u32,
    /// Tiles in the pool.
    pub tiles: u32,
    /// Leaf slots.
    pub slots: u32,
    /// 1: the first directional level weighs the leaves by their normals (`Filtering::ndf`).
    pub ndf: u32,
    /// 1: the leaves keep specular lobes after their direct light, and the levels above them
    /// the lobes' moments in two more blocks (`Filtering::lobes`).
    pub lobes: u32,
    /// Padding; zero.
    pub _pad: u32,
    /// The even atlas's region of level 0.
    pub leaf_atlas: GpuAtlasShape,
    /// The even atlas's region of levels 2, 4, …
    pub even_atlas: GpuAtlasShape,
    /// The odd atlas (levels 1, 3, …).
    pub odd_atlas: GpuAtlasShape,
}

/// Mirrors `AtlasShape` in shaders/voxels/octree/tree.wgsl: where a region of an atlas keeps
/// its bricks.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct GpuAtlasShape {
    /// log2 of the bricks per row and per layer.
    pub shift: [u32; 2],
    /// Texels of one direction block along z.
    pub block: u32,
    /// The region's first texel along z.
    pub z0: u32,
    /// 1 / the atlas size in texels; w unused.
    pub inv_size: [f32; 4],
}

impl GpuAtlasShape {
    /// The regions of one atlas texture within `max_dim` texels a side, each `(bricks, blocks)`
    /// (bricks in `blocks` direction blocks), one after another along z. Each block rounds its
    /// bricks up to whole layers of `2^k` bricks (rows of `2^ceil(k/2)`). The layers start as
    /// large as a cube of the bricks asks and shrink until the rounding wastes at most a
    /// sixteenth of the bricks (or 4096, which small atlases may waste to stay near a cube: a
    /// long texture costs precision in CPU drivers' f32 filtering), as far as the texture's
    /// depth allows.
    pub fn regions<const N: usize>(regions: [(u64, u32); N], max_dim: u32) -> Option<[Self; N]> {
        let max_shift = (max_dim / BRICK).max(1).ilog2();
        let used: u64 = regions.iter().map(|(b, k)| b.max(&1) * *k as u64).sum();
        // Each block's first texel along z and its texels along z, with layers of 2^k bricks;
        // and the texture's depth.
        let layout = |k: u32| -> (Vec<(u64, u64)>, u64) {
            let mut z0 = 0u64;
            let at = regions
                .iter()
                .map(|&(bricks, blocks)| {
                    let block = bricks.max(1).div_ceil(1 << k) * BRICK as u64;
                    let at = (z0, block);
                    z0 += block * blocks as u64;
                    at
                })
                .collect();
            (at, z0)
        };
        let fits = |k: u32| layout(k).1 <= max_dim as u64;
        let wasted = |k: u32| ((layout(k).1 / BRICK as u64) << k) - used;
        let cube = ((used as f64).cbrt().ceil() as u64)
            .next_power_of_two()
            .ilog2()
            .min(max_shift)
            * 2;
        let k = (0..=cube)
            .rev()
            .find(|&k| fits(k) && wasted(k) <= (used / 16).max(4096))
            .or_else(|| (0..=2 * max_shift).find(|&k| fits(k)))?;
        let (at, depth) = layout(k);
        let shift = [k.div_ceil(2), k / 2];
        let size = [BRICK << shift[0], BRICK << shift[1], depth as u32];
        let inv_size = [
            1.0 / size[0] as f32,
            1.0 / size[1] as f32,
            1.0 / size[2] as f32,
            0.0,
        ];
        let mut out = [GpuAtlasShape::zeroed(); N];
        for (o, &(z0, block)) in out.iter_mut().zip(&at) {
            *o = GpuAtlasShape {
                shift,
                block: block as u32,
                z0: z0 as u32,
                inv_size,
            };
        }
        Some(out)
    }

    /// The atlas texture's size in texels.
    pub fn size(&self) -> [u32; 3] {
        [
            (1.0 / self.inv_size[0]).round() as u32,
            (1.0 / self.inv_size[1]).round() as u32,
            (1.0 / self.inv_size[2]).round() as u32,
        ]
    }

    /// First texel of direction block `block` of brick `b` (`brick_texel` in tree.wgsl).
    pub fn brick_texel(&self, b: u32, block: u32) -> [u32; 3] {
        let [sx, sy] = self.shift;
        [
            3 * (b & ((1 << sx) - 1)),
            3 * ((b >> sx) & ((1 << sy) - 1)),
            3 * (b >> (sx + sy)) + self.z0 + block * self.block,
        ]
    }
}

pub(super) fn storage_buffer(device: &wgpu::Device, label: &str, size: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size.max(16),
        usage: wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_DST
            | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    })
}

pub(super) fn atlas(device: &wgpu::Device, label: &str, shape: &GpuAtlasShape) -> wgpu::Texture {
    let [width, height, depth] = shape.size();
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: depth,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D3,
        format: ATLAS_FORMAT,
        usage: wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atlases_stay_within_the_texture_limit() {
        let [one] = GpuAtlasShape::regions([(1, 6)], 2048).unwrap();
        assert_eq!(
            (one.shift, one.block, one.z0, one.size()),
            ([1, 1], 3, 0, [6, 6, 18])
        );
        // 215,638 leaf bricks and 8,755 of six blocks (Sponza at 256³): a cube's layers of
        // 128² bricks would leave 6 * (16,384 - 8,755) empty, layers of 64 x 32 bricks leave
        // 1,450 + 6 * 1,485, under a sixteenth.
        let [leaf, even] = GpuAtlasShape::regions([(215_638, 1), (8_755, 6)], 2048).unwrap();
        assert_eq!(leaf.shift, [6, 5]);
        assert_eq!(even.size(), [192, 96, 3 * (106 + 6 * 5)]);
        assert_eq!((leaf.block, even.z0, even.block), (3 * 106, 3 * 106, 3 * 5));
        // 512 bricks of 3 texels a row fit 2048; six blocks of 113 layers do, 114 do not.
        let [big] = GpuAtlasShape::regions([(512 * 512 * 113, 6)], 2048).unwrap();
        assert_eq!(big.size(), [1536, 1536, 6 * 3 * 113]);
        assert_eq!(
            GpuAtlasShape::regions([(512 * 512 * 113 + 1, 6)], 2048),
            None
        );
        for n in [27u64, 1000, 1_000_003] {
            let [a, b] = GpuAtlasShape::regions([(n, 1), (n / 3, 6)], 2048).unwrap();
            assert_eq!(a.size(), b.size(), "one texture");
            let [x, y, z] = a.size();
            // The last brick of each region, in its last block, lies inside and after the
            // region before.
            let ta = a.brick_texel(n as u32 - 1, 0);
            let tb = b.brick_texel((n / 3).max(1) as u32 - 1, 5);
            assert!(ta[2] + 3 <= b.z0, "{n}: {ta:?} reaches into {b:?}");
            assert!(
                ta[0] + 3 <= x && ta[1] + 3 <= y && tb[2] + 3 <= z,
                "{n}: {tb:?}"
            );
        }
    }
}
