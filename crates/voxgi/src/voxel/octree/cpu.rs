//! Plain Rust twins of the octree's build and sampling (voxels/octree/*.wgsl), for testing the
//! GPU against: the build's node sets exactly, the sampler to filtering precision.

use super::GpuOctree;
use crate::voxel::cpu::{Texture3d, from_depth, to_depth};
use glam::{UVec3, Vec3, Vec4};
use std::collections::BTreeSet;

/// Node coordinates at one depth (x, y, z at that depth's resolution, 2^t per side).
pub type NodeSet = BTreeSet<[u32; 3]>;

/// What octree_build makes of a set of occupied finest voxels: for each depth t in 0..=D, the
/// nodes that get children. A node of depth t < D is subdivided when it or one of its seven
/// positive neighbours holds an occupied voxel (its brick then holds everything a trilinear
/// fetch at its voxels reads); at depth D the nodes are the occupied voxels themselves.
pub fn subdivided(occupied: &BTreeSet<[u32; 3]>, depth: u32) -> Vec<NodeSet> {
    let mut out = Vec::with_capacity(depth as usize + 1);
    for t in 0..depth {
        let shift = depth - t;
        let content: NodeSet = occupied.iter().map(|c| c.map(|v| v >> shift)).collect();
        let mut set = NodeSet::new();
        for n in &content {
            for o in 0..8u32 {
                let off = [o & 1, (o >> 1) & 1, o >> 2];
                if (0..3).all(|a| n[a] >= off[a]) {
                    set.insert([n[0] - off[0], n[1] - off[1], n[2] - off[2]]);
                }
            }
        }
        out.push(set);
    }
    out.push(occupied.clone());
    out
}

/// The word of node n's child pointer (`child_word` in tree.wgsl).
pub fn child_word(layout: &GpuOctree, n: u32) -> usize {
    let leaves = 8 * layout.base_v as usize;
    let (header, stride) = (super::NODE_HEADER as usize, super::NODE_WORDS as usize);
    let n = n as usize;
    if n >= leaves {
        header + leaves * stride + (n - leaves)
    } else {
        header + n * stride
    }
}

/// The nodes with children at each depth of a GPU node buffer (`OctreeVolume::nodes` read back
/// as u32), found by walking it from the root: the GPU side of `subdivided`.
pub fn walk(nodes: &[u32], layout: &GpuOctree) -> Vec<NodeSet> {
    let child = |n: u32| nodes[child_word(layout, n)];
    let depth = layout.depth;
    let mut out = vec![NodeSet::new(); depth as usize + 1];
    let mut level = vec![(0u32, [0u32; 3])];
    for t in 0..=depth {
        let mut next = Vec::new();
        for &(n, c) in &level {
            let tile = child(n);
            if tile == 0 {
                continue;
            }
            out[t as usize].insert(c);
            if t == depth {
                continue;
            }
            for o in 0..8u32 {
                let cc = [
                    2 * c[0] + (o & 1),
                    2 * c[1] + ((o >> 1) & 1),
                    2 * c[2] + (o >> 2),
                ];
                next.push((tile * 8 + o, cc));
            }
        }
        level = next;
    }
    out
}

/// The octree as voxels/octree/sample.wgsl reads it: its layout, node words and both
/// atlases (one level each: level 0 stored as optical depth per texel, the levels above as
/// premultiplied opacity).
pub struct OctreeSampler<'a> {
    /// The octree uniform.
    pub layout: GpuOctree,
    /// The node buffer, header included.
    pub nodes: &'a [u32],
    /// The even atlas (level 0 and levels 2, 4, …).
    pub even: &'a Texture3d,
    /// The odd atlas.
    pub odd: &'a Texture3d,
}

impl OctreeSampler<'_> {
    fn child(&self, n: u32) -> u32 {
        self.nodes[child_word(&self.layout, n)]
    }

    /// The tile of the brick holding level `lvl` at level voxel `v`, or 0.
    fn brick(&self, v: UVec3, lvl: u32) -> u32 {
        if lvl == self.layout.depth {
            // Level D: the brick of the node above the root (`TOP_NODE` in tree.wgsl).
            return self.child(2);
        }
        let n: UVec3 = v >> 1u32;
        let depth = self.layout.depth - 1 - lvl;
        let mut node = 0;
        for i in 0..depth {
            let tile = self.child(node);
            if tile == 0 {
                return 0;
            }
            let s = depth - 1 - i;
            let o = ((n.x >> s) & 1) | (((n.y >> s) & 1) << 1) | (((n.z >> s) & 1) << 2);
            node = tile * 8 + o;
        }
        self.child(node)
    }

    /// Level `lvl` at uvw, directional block `dir` (0..6) read along `axis` (`fetch_along` in
    /// sample.wgsl), as optical depth: trilinear fetches inside one brick at the centres of the
    /// two layers of texels around the sample along `axis`, each made depth (levels above 0 store
    /// premultiplied opacity), blended by the sample's place between them.
    fn level(&self, uvw: Vec3, lvl: u32, dir: u32, axis: usize) -> Vec4 {
        let l = &self.layout;
        let r = (l.resolution >> lvl) as f32;
        let q = (uvw * r - 0.5).clamp(Vec3::ZERO, Vec3::splat(r - 1.0));
        let v = q.as_uvec3();
        let tile = self.brick(v, lvl);
        if tile == 0 {
            return Vec4::ZERO;
        }
        let (atlas, shape, base) = match lvl {
            0 => (self.even, &l.leaf_atlas, l.base_v),
            _ if lvl.is_multiple_of(2) => (self.even, &l.even_atlas, l.base_e),
            _ => (self.odd, &l.odd_atlas, l.base_o),
        };
        let block = if lvl == 0 || l.dirs == 1 { 0 } else { dir };
        let origin = UVec3::from_array(shape.brick_texel(tile - base, block)).as_vec3();
        // In [0.5, 2.5) per axis: both layers lie inside the brick.
        let local = q - 2.0 * (v >> 1u32).as_vec3() + 0.5;
        let size = atlas.levels[0].1.as_vec3();
        let p = local[axis] - 0.5;
        let l0 = p.floor();
        let layer = |c: f32| {
            let mut at = local;
            at[axis] = c;
            let s = atlas.sample((origin + at) / size, 0.0);
            if lvl == 0 { s } else { to_depth(s) }
        };
        layer(l0 + 0.5).lerp(layer(l0 + 1.5), p - l0)
    }

    /// `sample_depth`: optical depth per sample diameter, filtered to `diameter`, seen along `dir`.
    /// Reads the level nearest to the diameter's (sample.wgsl's `sample_levels`).
    pub fn sample_depth(&self, p: Vec3, diameter: f32, dir: Vec3) -> Vec4 {
        let l = &self.layout;
        let extent = l.voxel_size * l.resolution as f32;
        let uvw = (p - Vec3::from_array(l.origin)) / extent;
        if !(uvw.cmpge(Vec3::ZERO).all() && uvw.cmple(Vec3::ONE).all()) {
            return Vec4::ZERO;
        }
        let top = l.depth as f32;
        let lod = (diameter / l.voxel_size).max(1.0).log2().clamp(0.0, top);
        let lo = (lod as u32).min(l.depth - 1);
        let f = lod - lo as f32;
        let lvl = if f < 0.5 { lo } else { lo + 1 };
        let v = if l.anisotropic == 0 || lvl == 0 {
            // One block: read along dir's largest component alone.
            self.level(uvw, lvl, 0, crate::voxel::cpu::main_axis(dir))
        } else {
            // Each direction's block along its own axis, weighted by the squared cosines.
            let w = dir * dir;
            let b = |neg: bool, pos: u32| if neg { pos + 1 } else { pos };
            w.x * self.level(uvw, lvl, b(dir.x < 0.0, 0), 0)
                + w.y * self.level(uvw, lvl, b(dir.y < 0.0, 2), 1)
                + w.z * self.level(uvw, lvl, b(dir.z < 0.0, 4), 2)
        };
        v * crate::voxel::cpu::border_weight(uvw, lod, l.resolution)
    }

    /// `sample_voxels`: premultiplied radiance and opacity.
    pub fn sample_voxels(&self, p: Vec3, diameter: f32, dir: Vec3) -> Vec4 {
        from_depth(self.sample_depth(p, diameter, dir))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_voxel_subdivides_its_ancestors_and_their_negative_neighbours() {
        let occupied: BTreeSet<[u32; 3]> = [[5, 0, 3]].into_iter().collect();
        let s = subdivided(&occupied, 3);
        // Depth 0: the root. Depth 1: (0,0,0) holds (5,0,3) >> 2 = (1,0,0), and (0,0,0) is
        // its -x neighbour; y and z are 0, so no neighbours there.
        assert_eq!(s[0], [[0, 0, 0]].into_iter().collect());
        assert_eq!(s[1], [[0, 0, 0], [1, 0, 0]].into_iter().collect());
        // Depth 2: (2,0,1) and its negative neighbours along x and z.
        assert_eq!(
            s[2],
            [[1, 0, 0], [1, 0, 1], [2, 0, 0], [2, 0, 1]]
                .into_iter()
                .collect()
        );
        assert_eq!(s[3], occupied);
        // Every subdivided node's parent is subdivided: the structure is a tree.
        for t in 1..3 {
            for n in &s[t] {
                assert!(s[t - 1].contains(&n.map(|v| v >> 1)), "{n:?} at depth {t}");
            }
        }
    }

    #[test]
    fn walking_a_hand_made_node_buffer_finds_its_nodes() {
        // Depth 1 (a 2³ grid): the root (tile 0, node 0) has children in tile 1; of those,
        // node 8 + 5 (octant (1, 0, 1)) is an occupied voxel (slot 0, stored as 1).
        let header = super::super::NODE_HEADER as usize;
        let mut nodes = vec![0u32; header + 8 * 4 + 8];
        nodes[header] = 1;
        nodes[header + 8 * 4 + 5] = 1;
        // No tiles of classes E and O: tile 1 is the first of class V, whose nodes keep one
        // word each after the root tile's records.
        let layout = GpuOctree {
            depth: 1,
            base_e: 1,
            base_o: 1,
            base_v: 1,
            tiles: 2,
            ..bytemuck::Zeroable::zeroed()
        };
        let w = walk(&nodes, &layout);
        assert_eq!(w[0], [[0, 0, 0]].into_iter().collect());
        assert_eq!(w[1], [[1, 0, 1]].into_iter().collect());
    }
}
