//! The octree's pools: leaf slots and the three classes of tiles, sized from the scene's
//! estimate and grown (or shrunk) to what a build counted.

use super::*;

/// How many of each pool an octree holds: leaf slots, and tiles of the three classes (leaf
/// voxels, even levels above 0, odd levels).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OctreePools {
    /// Occupied finest voxels.
    pub slots: u32,
    /// Tiles of eight leaf voxels (one level-0 brick each).
    pub leaf_tiles: u32,
    /// Tiles whose parents' bricks hold an even level above 0.
    pub even_tiles: u32,
    /// Tiles whose parents' bricks hold an odd level.
    pub odd_tiles: u32,
    /// Of `slots`, those a dynamic scene's static build fills, as a build counted them (0
    /// before one has): its updates' slots follow them, and only those keep their build sums
    /// between frames (`update_slots`).
    pub static_slots: u32,
}

/// The word of the octree's pool counters (`OctreeVolume::pool_counter`) that holds the static
/// leaves the last update's slots stand in for (`STOOD_IN` in tree.wgsl).
pub const STOOD_IN_COUNTED: usize = 4;
/// The word of the pool counters that holds the static build's slots (`STATIC_SLOTS`).
pub const STATIC_COUNTED: usize = 5;

/// The static build's slots in `counted`, the pool counters (none where they stop before).
fn static_counted(counted: &[u32]) -> u32 {
    counted
        .get(STATIC_COUNTED)
        .map_or(0, |&n| n.min(counted[0]))
}

impl OctreePools {
    /// A first guess for `leaves` occupied voxels: surfaces fill about half of a 2³ group, and
    /// each level above holds about a quarter of the one below; the dilation for the bricks'
    /// borders roughly doubles each. The first build's counters correct it.
    pub fn for_leaves(leaves: u64) -> Self {
        let c = |n: u64| n.clamp(64, u32::MAX as u64 / 8) as u32;
        OctreePools {
            slots: c(leaves),
            leaf_tiles: c(leaves / 2),
            even_tiles: c(leaves / 16),
            odd_tiles: c(leaves / 8),
            static_slots: 0,
        }
    }

    /// The slots a dynamic scene's updates may add after the static build's: the room its
    /// update scratch keeps their sums for.
    pub fn update_slots(&self) -> u32 {
        self.slots - self.static_slots.min(self.slots)
    }

    /// These pools, shrunk where a buffer would exceed `max_binding` bytes: a first guess
    /// must not fail where the scene itself would fit (growth then reports a real excess).
    pub fn within(self, max_binding: u64) -> Self {
        let mut p = self;
        while p.node_bytes() > max_binding && p.leaf_tiles > 64 {
            p.leaf_tiles /= 2;
            p.even_tiles = (p.even_tiles / 2).max(64);
            p.odd_tiles = (p.odd_tiles / 2).max(64);
        }
        // The build's scratch holds the tiles' flags, then the slots' sums.
        let tiles = 1 + p.leaf_tiles as u64 + p.even_tiles as u64 + p.odd_tiles as u64;
        let flags = super::scratch_bytes(tiles, 0);
        p.slots = p.slots.min(
            (max_binding.saturating_sub(flags) / (ACCUM_WORDS * 4)).min(u32::MAX as u64) as u32,
        );
        p
    }

    /// Bytes of the node buffer: `NODE_WORDS` per node above the leaves, one word per leaf.
    pub fn node_bytes(&self) -> u64 {
        let interior = 1 + self.even_tiles as u64 + self.odd_tiles as u64;
        (NODE_HEADER + 8 * interior * NODE_WORDS + 8 * self.leaf_tiles as u64) * 4
    }

    /// Bytes these pools take on the GPU (bricks with six directions above level 0).
    pub fn bytes(&self) -> u64 {
        let brick = 27 * 8;
        self.slots as u64 * SLOT_BYTES
            + self.leaf_tiles as u64 * (brick + 8 * 4 + 8)
            + (self.even_tiles as u64 + self.odd_tiles as u64) * (6 * brick + 8 * 16 + 8)
    }

    /// Pools for what a build counted, and an eighth more where dynamic geometry can add to
    /// it (`room`); a static scene's counts are what every later build of it counts.
    pub fn fitting(counted: &[u32], room: bool) -> Self {
        let need = |n: u32| n.saturating_add(if room { n / 8 } else { 0 }).max(64);
        OctreePools {
            slots: need(counted[0]),
            leaf_tiles: need(counted[1]),
            even_tiles: need(counted[2]),
            odd_tiles: need(counted[3]),
            static_slots: if room { static_counted(counted) } else { 0 },
        }
    }

    /// The pools to make after a build that counted `counted` (`OctreeVolume::pool_counter`'s
    /// first four words), or None to keep these. A pool that overflowed hides what the levels
    /// below it would have needed, so every pool grows at least by half once one overflows.
    /// Pools more than twice what the build needed (the first guess comes from an upper bound
    /// on the fragments) shrink to the counts, and an eighth with `room` (`fitting`): the
    /// octree's point is its memory.
    /// With `room`, the slots the last update added must fit the update scratch too, and the
    /// first guess's scratch (sized for every slot, before a build counted the static ones)
    /// shrinks to the slots updates may add.
    pub fn resized_for(&self, counted: &[u32], room: bool) -> Option<Self> {
        let have = [self.slots, self.leaf_tiles, self.even_tiles, self.odd_tiles];
        let added = counted[0] - if room { static_counted(counted) } else { 0 };
        if counted.iter().zip(have).all(|(&n, h)| n <= h) && added <= self.update_slots() {
            let fit = Self::fitting(counted, room);
            // Below a few MiB a shrink is not worth a rebuild.
            let oversized = self.bytes() > 2 * fit.bytes() && self.bytes() > 8 << 20;
            // Only the first guess's (made before a build counted its static slots): grown
            // pools keep their room, or a growth would shrink again at once.
            let scratch = self.update_slots() as u64 * ACCUM_WORDS * 4;
            let scratch_oversized = room
                && self.static_slots == 0
                && self.update_slots() > 2 * fit.update_slots()
                && scratch > 8 << 20;
            return (oversized || scratch_oversized).then_some(fit);
        }
        let grow = |n: u32, h: u32| -> u32 {
            let half = h.saturating_add(h / 2);
            n.max(half).max(64)
        };
        Some(OctreePools {
            slots: grow(counted[0], self.slots),
            leaf_tiles: grow(counted[1], self.leaf_tiles),
            even_tiles: grow(counted[2], self.even_tiles),
            odd_tiles: grow(counted[3], self.odd_tiles),
            static_slots: if room { static_counted(counted) } else { 0 },
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pools_grow_to_what_was_counted_and_by_half_at_least() {
        let p = OctreePools {
            slots: 1000,
            leaf_tiles: 100,
            even_tiles: 10,
            odd_tiles: 10,
            static_slots: 0,
        };
        assert_eq!(p.resized_for(&[1000, 100, 10, 10], true), None);
        let g = p.resized_for(&[5000, 100, 10, 11], true).unwrap();
        assert_eq!(
            (g.slots, g.leaf_tiles, g.even_tiles, g.odd_tiles),
            (5000, 150, 64, 64)
        );
    }

    /// The first guess for a town at 512³ was cut to the slots' sums alone, and its build's
    /// scratch (the tiles' flags first) passed lavapipe's 128 MiB binding by 0.7 MiB.
    #[test]
    fn a_guess_within_a_binding_limit_leaves_room_for_the_build_scratch() {
        let limit = 128u64 << 20;
        let p = OctreePools::for_leaves(20_000_000).within(limit);
        let tiles = 1 + p.leaf_tiles as u64 + p.even_tiles as u64 + p.odd_tiles as u64;
        let scratch = super::super::scratch_bytes(tiles, p.slots as u64);
        assert!(scratch <= limit, "{scratch} > {limit}");
        // And no more room than that: one more slot would pass it.
        assert!(scratch + ACCUM_WORDS * 4 > limit, "{scratch}");
        assert!(p.node_bytes() <= limit);
    }

    #[test]
    fn pools_far_larger_than_needed_shrink_to_the_counts() {
        let big = OctreePools::for_leaves(4_000_000);
        let counted = [400_000, 150_000, 6_000, 25_000];
        let fit = big
            .resized_for(&counted, true)
            .expect("a tenth of the pools is used");
        assert_eq!(
            (fit.slots, fit.leaf_tiles, fit.even_tiles, fit.odd_tiles),
            (450_000, 168_750, 6_750, 28_125)
        );
        // Sized so, the next build keeps them.
        assert_eq!(fit.resized_for(&counted, true), None);
        // A static scene's pools hold the counts exactly, and keep them.
        let exact = big.resized_for(&counted, false).expect("shrinks");
        assert_eq!(
            [
                exact.slots,
                exact.leaf_tiles,
                exact.even_tiles,
                exact.odd_tiles
            ],
            counted
        );
        assert_eq!(exact.resized_for(&counted, false), None);
    }

    /// A dynamic scene keeps build sums for the slots its updates add, not for the static
    /// build's: the pool counters' word 5 says how many those are.
    #[test]
    fn a_dynamic_scenes_update_scratch_follows_the_slots_updates_add() {
        let guess = OctreePools::for_leaves(500_000);
        // The counting build before the first frame: static geometry only.
        let built = [400_000, 150_000, 6_000, 25_000, 0, 400_000];
        // The guess is within twice the counts, but its scratch was sized for every slot.
        let fit = guess
            .resized_for(&built, true)
            .expect("the scratch shrinks");
        assert_eq!((fit.slots, fit.static_slots), (450_000, 400_000));
        assert_eq!(fit.update_slots(), 50_000);
        assert_eq!(fit.resized_for(&built, true), None);
        // An update that adds 40,000 slots fits; one that adds 60,000 grows the pool by half.
        let updated = [440_000, 150_000, 6_000, 25_000, 0, 400_000];
        assert_eq!(fit.resized_for(&updated, true), None);
        let over = [460_000, 150_000, 6_000, 25_000, 0, 400_000];
        let grown = fit.resized_for(&over, true).expect("grows");
        assert_eq!((grown.slots, grown.update_slots()), (675_000, 275_000));
        // And keeps that room: the same count does not shrink it again.
        assert_eq!(grown.resized_for(&over, true), None);
        // A static scene keeps no update scratch: its counters' word 5 does not count.
        let exact = guess.resized_for(&built, false);
        assert!(exact.is_none_or(|p| p.static_slots == 0), "{exact:?}");
    }
}
