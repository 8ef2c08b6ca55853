//! Point-cloud attribute estimation: normals by PCA over nearest neighbours, and disc radii.
//!
//! Both work in the cloud's local (file) coordinates and fill an attribute only when it is
//! empty, so values from the file win. Neighbour queries search a uniform grid of cells ring by
//! ring, with a `kiddo` immutable k-d tree (which, unlike its mutable tree, copes with many
//! identical points) for the few points far from the rest, and run on all cores.

use crate::{Instance, PointCloud, Scene};
use glam::{DVec3, Mat4, Vec3};
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use std::num::NonZero;

/// The nearest neighbours of every point of a cloud, found once (one query per point) and
/// shared by the estimates, each reading the nearest few it needs: normals 16,
/// regions and radii 8, the surface spread 24. Five separate queries took three times as long.
#[derive(Clone, Debug, Default)]
pub struct Neighbours {
    /// Indices per point: `k + 1` (or all the points, when fewer).
    stride: usize,
    /// Each point's neighbours, nearest first (ties by index from the grid; the k-d tree, for
    /// points far from the rest, may take another of equally near points), the point itself
    /// among them.
    idx: Vec<u32>,
}

impl Neighbours {
    /// The `k` nearest neighbours of each of `positions`, on all cores: the points of a cell of
    /// a uniform grid (a few points each) share one candidate list, their cell and its 26
    /// neighbours, which holds the answer unless a point lies near its cell's face in a sparse
    /// spot; those search ring by ring outwards, and a query that runs out after a few rings
    /// (a point far from the rest) asks a k-d tree. The positions are finite (the loaders and
    /// `Renderer::set_points` check it); a point that is not lies farther than every other.
    pub fn find(positions: &[Vec3], k: usize) -> Self {
        let stride = (k + 1).min(positions.len());
        if stride == 0 {
            return Self::default();
        }
        let grid = CellGrid::new(positions);
        let tree = std::sync::OnceLock::new();
        // Rings outwards from ring `first` (`found` holds the points of those inside it), then
        // the tree: into `found`, `stride` of them, nearest first.
        let search = |i: u32, first: i64, found: &mut Vec<u64>| {
            let q = positions[i as usize];
            if grid.nearest(positions, q, stride, first, found) {
                return;
            }
            found.clear();
            let tree = tree.get_or_init(|| {
                let pts: Vec<[f32; 3]> = positions.iter().map(|p| p.to_array()).collect();
                ImmutableKdTree::<f32, 3>::new_from_slice(&pts)
            });
            found.extend(
                tree.nearest_n_within::<SquaredEuclidean>(
                    &q.to_array(),
                    f32::INFINITY,
                    NonZero::new(stride).unwrap(),
                    false,
                )
                .iter()
                .map(|n| {
                    let j = n.item as u32;
                    rank(positions[j as usize].distance_squared(q), j)
                }),
            );
            // A query finds `stride` points (all lie within infinity); the padding only keeps
            // the layout should it not.
            found.resize(stride, rank(f32::INFINITY, i));
            found.sort_unstable();
        };
        // Cell by cell, in the grid's order (neighbouring cells read the same cells).
        let sorted = par_chunks(grid.runs.len(), |cells, out: &mut Vec<u32>| {
            let mut candidates: Vec<(Vec3, u32)> = Vec::new();
            let mut found = Vec::with_capacity(stride * 8);
            for &(start, end) in &grid.runs[cells] {
                let members = &grid.sorted[start as usize..end as usize];
                let c = CellGrid::cell_of(grid.lo, grid.h, positions[members[0] as usize]);
                candidates.clear();
                for dz in -1..=1 {
                    for dy in -1..=1 {
                        for dx in -1..=1 {
                            candidates.extend(
                                grid.cell([c[0] + dx, c[1] + dy, c[2] + dz])
                                    .iter()
                                    .map(|&j| (positions[j as usize], j)),
                            );
                        }
                    }
                }
                // Many points in few cells (repeated points, a dense spot): one by one.
                let shared = candidates.len() >= stride && candidates.len() <= 64 * stride.max(8);
                for &i in members {
                    let q = positions[i as usize];
                    let mut done = false;
                    if shared {
                        found.clear();
                        found.extend(
                            candidates
                                .iter()
                                .map(|&(p, j)| rank(p.distance_squared(q), j)),
                        );
                        let (_, &mut kth, _) = found.select_nth_unstable(stride - 1);
                        // No point outside the 27 cells is nearer than this (a little less,
                        // for rounding).
                        let reach = (grid.h + grid.inside(q, c)) * (1.0 - 1e-5);
                        if distance_of(kth) < reach * reach {
                            found.truncate(stride);
                            found.sort_unstable();
                            done = true;
                        }
                    }
                    if !done {
                        // The 27 cells are rings 0 and 1: the search goes on from ring 2 with
                        // their points (still all in `found`).
                        if !shared {
                            found.clear();
                        }
                        search(i, if shared { 2 } else { 0 }, &mut found);
                    }
                    out.extend(found.iter().map(|&n| n as u32));
                }
            }
        });
        let mut idx = vec![0u32; sorted.len()];
        for (at, &i) in grid.sorted.iter().enumerate() {
            let i = i as usize;
            idx[i * stride..][..stride].copy_from_slice(&sorted[at * stride..][..stride]);
        }
        Self { stride, idx }
    }

    /// How many neighbours each point has (besides itself).
    pub fn k(&self) -> usize {
        self.stride.saturating_sub(1)
    }

    /// Point `i`'s `k` nearest neighbours and itself (or a point at the same place), nearest
    /// first; fewer when the cloud is smaller or the neighbours were found for a smaller `k`.
    pub fn of(&self, i: usize, k: usize) -> &[u32] {
        &self.idx[i * self.stride..][..(k + 1).min(self.stride)]
    }

    /// `f(i, neighbours_of_i)` for each point, on all cores.
    fn map<T: Send>(&self, k: usize, f: impl Fn(usize, &[u32]) -> T + Sync) -> Vec<T> {
        let n = self.idx.len().checked_div(self.stride).unwrap_or(0);
        par_chunks(n, |range, out| {
            out.extend(range.map(|i| f(i, self.of(i, k))))
        })
    }
}

/// A neighbour `j` at squared distance `d2` as one number that orders neighbours nearest first,
/// ties by index: the distance's bits above the index (a non-negative float's bits order as
/// the float does), so that selecting and sorting compare integers, not pairs. (A squared
/// distance is never -0.0; one from a position that is not finite, infinite or NaN of either
/// sign, orders after every finite one.)
fn rank(d2: f32, j: u32) -> u64 {
    ((d2.to_bits() as u64) << 32) | j as u64
}

/// The squared distance a `rank` holds.
fn distance_of(rank: u64) -> f32 {
    f32::from_bits((rank >> 32) as u32)
}

/// Points sorted into cubic cells of side `h` (a few points each where the points are), found
/// by an open-addressing table from cell to range: the exact k nearest by searching rings of
/// cells outwards until no unsearched cell can hold a nearer point.
struct CellGrid {
    lo: Vec3,
    h: f32,
    /// Point indices, grouped by cell.
    sorted: Vec<u32>,
    /// (cell key, start, end) into `sorted`; `u64::MAX`: empty.
    table: Vec<(u64, u32, u32)>,
    /// Each non-empty cell's (start, end) into `sorted`, in the order of their keys.
    runs: Vec<(u32, u32)>,
    mask: usize,
}

/// Points a non-empty cell aims to hold: the k = 24 nearest then mostly lie in the first ring.
const TARGET: f32 = 8.0;
/// Rings searched before a query goes to the k-d tree (a point far from the others).
const MAX_RINGS: i32 = 4;

impl CellGrid {
    fn new(positions: &[Vec3]) -> Self {
        let (lo, hi) = positions
            .iter()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| {
                (lo.min(p), hi.max(p))
            });
        let extent = (hi - lo).max_element();
        let n = positions.len().max(1) as f32;
        // A first guess as if the points filled their box, then corrected towards `TARGET`
        // points a non-empty cell as if they lay on surfaces (the count grows with h²).
        let mut h = if extent > 0.0 && extent.is_finite() {
            extent / n.cbrt()
        } else {
            1.0
        };
        let mut keys: Vec<(u64, u32)> = Vec::new();
        for attempt in 0..4 {
            keys.clear();
            keys.extend(
                positions
                    .iter()
                    .enumerate()
                    .map(|(i, &p)| (Self::key_of(Self::cell_of(lo, h, p)), i as u32)),
            );
            keys.sort_unstable();
            let cells = 1 + keys.windows(2).filter(|w| w[0].0 != w[1].0).count();
            let mean = n / cells as f32;
            if (TARGET / 2.0..=TARGET * 2.0).contains(&mean) || attempt == 3 || n < 16.0 {
                break;
            }
            h *= (TARGET / mean).sqrt().clamp(0.25, 4.0);
        }
        let cells = 1 + keys.windows(2).filter(|w| w[0].0 != w[1].0).count();
        let size = (cells * 2).next_power_of_two();
        let mut grid = CellGrid {
            lo,
            h,
            sorted: keys.iter().map(|k| k.1).collect(),
            table: vec![(u64::MAX, 0, 0); size],
            runs: Vec::with_capacity(cells),
            mask: size - 1,
        };
        let mut start = 0;
        while start < keys.len() {
            let key = keys[start].0;
            let end = start + keys[start..].iter().take_while(|k| k.0 == key).count();
            let mut slot = Self::hash(key) & grid.mask;
            while grid.table[slot].0 != u64::MAX {
                slot = (slot + 1) & grid.mask;
            }
            grid.table[slot] = (key, start as u32, end as u32);
            grid.runs.push((start as u32, end as u32));
            start = end;
        }
        grid
    }

    /// Cell coordinates of `p` (in double precision, so that a cell's faces lie where the
    /// search's bound assumes), offset so that every neighbour within the rings stays positive.
    fn cell_of(lo: Vec3, h: f32, p: Vec3) -> [i64; 3] {
        let c = Self::cell_space(lo, h, p).floor();
        [c.x as i64, c.y as i64, c.z as i64].map(|v| v.clamp(0, (1 << 20) - 1) + 8)
    }

    fn cell_space(lo: Vec3, h: f32, p: Vec3) -> DVec3 {
        (p.as_dvec3() - lo.as_dvec3()) / h as f64
    }

    fn key_of(c: [i64; 3]) -> u64 {
        (c[0] as u64) | ((c[1] as u64) << 21) | ((c[2] as u64) << 42)
    }

    fn hash(key: u64) -> usize {
        (key.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 32) as usize
    }

    fn cell(&self, c: [i64; 3]) -> &[u32] {
        let key = Self::key_of(c);
        let mut slot = Self::hash(key) & self.mask;
        loop {
            let (k, start, end) = self.table[slot];
            if k == key {
                return &self.sorted[start as usize..end as usize];
            }
            if k == u64::MAX {
                return &[];
            }
            slot = (slot + 1) & self.mask;
        }
    }

    /// How far `q` lies inside its cell `c` from the nearest face: the faces of a cube of
    /// cells searched r rings outwards lie r cells' sides beyond it.
    fn inside(&self, q: Vec3, c: [i64; 3]) -> f32 {
        let f = Self::cell_space(self.lo, self.h, q)
            - DVec3::new((c[0] - 8) as f64, (c[1] - 8) as f64, (c[2] - 8) as f64);
        (f.min(DVec3::ONE - f).min_element().max(0.0) * self.h as f64) as f32
    }

    /// The `count` nearest points to `q` (itself among them), nearest first, ties by index,
    /// into `found`, which holds the points of the rings inside ring `first` (searched
    /// already: none of them held the answer); false when they were not found within
    /// `MAX_RINGS` rings.
    fn nearest(
        &self,
        positions: &[Vec3],
        q: Vec3,
        count: usize,
        first: i64,
        found: &mut Vec<u64>,
    ) -> bool {
        let c = Self::cell_of(self.lo, self.h, q);
        let inside = self.inside(q, c);
        for r in first..=MAX_RINGS as i64 {
            for dz in -r..=r {
                for dy in -r..=r {
                    // Only the ring's shell: the inner cells were searched already.
                    let step = if dz.abs() < r && dy.abs() < r {
                        2 * r
                    } else {
                        1
                    };
                    let mut dx = -r;
                    while dx <= r {
                        found.extend(
                            self.cell([c[0] + dx, c[1] + dy, c[2] + dz])
                                .iter()
                                .map(|&j| rank(positions[j as usize].distance_squared(q), j)),
                        );
                        dx += step;
                    }
                }
            }
            // Many points in few cells (repeated points, a dense spot): the tree's turn.
            if found.len() > 64 * count.max(8) {
                return false;
            }
            if found.len() >= count {
                let (_, &mut kth, _) = found.select_nth_unstable(count - 1);
                // No point in an unsearched cell is nearer than this (a little less, for
                // rounding).
                let reach = (r as f32 * self.h + inside) * (1.0 - 1e-5);
                if distance_of(kth) < reach * reach {
                    found.truncate(count);
                    found.sort_unstable();
                    return true;
                }
            }
        }
        false
    }
}

/// Splits `0..n` into chunks, several per core (`available_parallelism`, 1 where it is
/// unknown), which the cores take in turn as they finish, and concatenates what `f` writes
/// for each chunk, in order. Equal shares per core left one core idle while the other
/// searched the sparse parts of a scan, where queries go ring by ring.
fn par_chunks<T: Send>(n: usize, f: impl Fn(std::ops::Range<usize>, &mut Vec<T>) + Sync) -> Vec<T> {
    let threads = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1)
        .min(16);
    // One core, or a platform without threads (the browser's main thread): all here.
    if threads == 1 || n < 2 {
        let mut out = Vec::new();
        f(0..n, &mut out);
        return out;
    }
    let chunk = n.div_ceil(8 * threads).max(1);
    let next = std::sync::atomic::AtomicUsize::new(0);
    let mut done: Vec<(usize, Vec<T>)> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..threads)
            .map(|_| {
                let (f, next) = (&f, &next);
                s.spawn(move || {
                    let mut done = Vec::new();
                    loop {
                        let start = next.fetch_add(chunk, std::sync::atomic::Ordering::Relaxed);
                        if start >= n {
                            return done;
                        }
                        let mut out = Vec::new();
                        f(start..(start + chunk).min(n), &mut out);
                        done.push((start, out));
                    }
                })
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().expect("neighbour worker panicked"))
            .collect()
    });
    done.sort_unstable_by_key(|(start, _)| *start);
    done.into_iter().flat_map(|(_, out)| out).collect()
}

/// Estimates unit normals where the cloud has none: the direction of least variance of each
/// point's `k` nearest neighbours (PCA), flipped to face `viewpoint` (world space, e.g. the
/// scanner or camera position). Points whose neighbourhood is degenerate (fewer than three
/// distinct points) get the direction towards the viewpoint.
pub fn estimate_normals(pc: &mut PointCloud, k: usize, viewpoint: Vec3) {
    if pc.normals.is_empty() {
        let nb = Neighbours::find(&pc.positions, k.max(3));
        estimate_normals_from(pc, &nb, k, viewpoint);
    }
}

/// `estimate_normals` from neighbours already found (at least `k` of them for the same
/// estimate).
pub fn estimate_normals_from(pc: &mut PointCloud, nb: &Neighbours, k: usize, viewpoint: Vec3) {
    if pc.normals.is_empty() {
        fit_normals_from(pc, nb, k);
        orient_normals(pc, viewpoint);
    }
}

/// The first half of `estimate_normals_from`, which needs no viewpoint (so it can run ahead,
/// on another thread): each point's axis of least variance with either sign, zero where the
/// neighbourhood is degenerate. Nothing when the cloud has normals.
pub fn fit_normals_from(pc: &mut PointCloud, nb: &Neighbours, k: usize) {
    if !pc.normals.is_empty() || pc.positions.is_empty() {
        return;
    }
    let positions = &pc.positions;
    pc.normals = nb.map(k.max(3), |i, nb| {
        let p = positions[i];
        if nb.len() < 3 {
            return Vec3::ZERO;
        }
        // Covariance about the mean, in f64 relative to the point to avoid cancellation far
        // from the origin.
        let rel = |j: u32| (positions[j as usize] - p).as_dvec3();
        let mean = nb.iter().map(|&j| rel(j)).sum::<DVec3>() / nb.len() as f64;
        let mut c = [[0f64; 3]; 3];
        for &j in nb {
            let d = (rel(j) - mean).to_array();
            for (r, row) in c.iter_mut().enumerate() {
                for (col, v) in row.iter_mut().enumerate() {
                    *v += d[r] * d[col];
                }
            }
        }
        let (vals, vecs) = symmetric_eigen3(c);
        // Degenerate: all neighbours on a line or a point; the smallest axis is meaningless.
        if vals[1].is_nan() || vals[1] <= 1e-12 * vals[2].max(f64::MIN_POSITIVE) {
            return Vec3::ZERO;
        }
        DVec3::new(vecs[0][0], vecs[1][0], vecs[2][0])
            .as_vec3()
            .normalize_or_zero()
    });
}

/// The second half of `estimate_normals_from`: every normal turned to face `viewpoint` (world
/// space), and zero normals (a degenerate neighbourhood) made the direction towards it.
pub fn orient_normals(pc: &mut PointCloud, viewpoint: Vec3) {
    let view = pc.transform.inverse().transform_point3(viewpoint);
    for (n, &p) in pc.normals.iter_mut().zip(&pc.positions) {
        let towards = (view - p).normalize_or(Vec3::Y);
        if *n == Vec3::ZERO {
            *n = towards;
        } else if n.dot(view - p) < 0.0 {
            *n = -*n;
        }
    }
}

/// How much larger than the equal-area radius the discs are. Each point owns on average the
/// area `π d_k² / k` (k neighbours within distance d_k), whose equal-area disc has radius
/// `d_k / sqrt(k)`. Equal-area discs leave gaps: covering the plane needs discs 1.0996× larger
/// on a hexagonal lattice (covering density 1.2092) and 1.2533× (sqrt(π/2)) on a square grid, the
/// common layout of scans and depth images. But for small k the k-th neighbour lies on a discrete
/// ring, so `π d_k² / k` underestimates the area per point: on a square grid of spacing s, k = 8
/// gives d_8 = s·√2 and `d_k / sqrt(k)` = s / 2, while covering needs s / √2 (√2× more). 1.45
/// covers square grids for k = 4, 8 and 16 (0.725 s, 0.725 s, 0.81 s), which removed a lattice of
/// pixel holes from renders of the Kinect office scan at 1.25; hexagonal lattices get more
/// overlap than they need, which splatting tolerates.
pub const RADIUS_COVER_FACTOR: f32 = 1.45;

/// Fills one disc radius per point where the cloud has none:
/// `RADIUS_COVER_FACTOR × d_k / sqrt(k)`, with `d_k` the distance to the k-th nearest neighbour
/// (not counting the point itself). Clouds of one point get radius 0.
pub fn estimate_radii(pc: &mut PointCloud, k: usize) {
    if pc.radii.is_empty() {
        let nb = Neighbours::find(&pc.positions, k.max(1));
        estimate_radii_from(pc, &nb, k);
    }
}

/// `estimate_radii` from neighbours already found.
pub fn estimate_radii_from(pc: &mut PointCloud, nb: &Neighbours, k: usize) {
    if !pc.radii.is_empty() || pc.positions.is_empty() {
        return;
    }
    let positions = &pc.positions;
    pc.radii = nb.map(k.max(1), |i, nb| {
        let p = positions[i];
        // Neighbours other than the point itself (duplicates count as neighbours at 0).
        let others = nb.len().saturating_sub(1);
        if others == 0 {
            return 0.0;
        }
        let dk = nb
            .iter()
            .map(|&j| positions[j as usize].distance(p))
            .fold(0.0f32, f32::max);
        RADIUS_COVER_FACTOR * dk / (others as f32).sqrt()
    });
}

/// Fills the edge of each point's cubic region of influence where the cloud has none (seed 004
/// §4.3.4): from the file's disc radius when it has one (the square of the disc's area,
/// `sqrt(π) r`), else the larger of two spacings. One is the thesis's: the Chebyshev
/// (maximum-norm) distance to the nearest other point, which tiles a regular grid exactly. The
/// other is the side of the square with the area each point owns by a k-nearest-neighbour
/// density estimate (`π d_k² / (k + 1)`): on irregular samplings (a mesh's vertices, a noisy
/// scan) the nearest pair lies much closer than the typical spacing, and the Stanford bunny's
/// vertices came out with regions of a third of their area, too transparent in the voxels. The
/// Chebyshev nearest point is looked for among the `k` Euclidean nearest (it is within √3 of the
/// Euclidean nearest distance, so a few are enough); points at the same position do not count
/// as neighbours. A point without neighbours gets 0, which the voxels read as "one voxel". Call
/// before `estimate_radii`, so that only radii from the file are used.
pub fn estimate_regions(pc: &mut PointCloud, k: usize) {
    if pc.regions.is_empty() {
        let nb = if pc.radii.len() == pc.positions.len() {
            Neighbours::default()
        } else {
            Neighbours::find(&pc.positions, k.max(1))
        };
        estimate_regions_from(pc, &nb, k);
    }
}

/// `estimate_regions` from neighbours already found (none needed when the cloud has radii).
pub fn estimate_regions_from(pc: &mut PointCloud, nb: &Neighbours, k: usize) {
    if !pc.regions.is_empty() || pc.positions.is_empty() {
        return;
    }
    if pc.radii.len() == pc.positions.len() {
        let s = std::f32::consts::PI.sqrt();
        pc.regions = pc.radii.iter().map(|&r| (s * r).max(0.0)).collect();
        return;
    }
    let positions = &pc.positions;
    pc.regions = nb.map(k.max(1), |i, nb| {
        let p = positions[i];
        // One pass over the neighbours at another place: how many, the nearest by the
        // maximum norm, the farthest.
        let (mut others, mut chebyshev, mut dk) = (0usize, f32::INFINITY, 0.0f32);
        for &j in nb {
            let d = positions[j as usize] - p;
            if d != Vec3::ZERO {
                others += 1;
                chebyshev = chebyshev.min(d.abs().max_element());
                dk = dk.max(d.length());
            }
        }
        if others == 0 {
            return 0.0;
        }
        let density = (std::f32::consts::PI / (others + 1) as f32).sqrt() * dk;
        chebyshev.max(density)
    });
}

/// Neighbours the surface spread reads: 24 (then dilated over 24 more) span a few point
/// spacings each way.
pub const SPREAD_NEIGHBOURS: usize = 24;

/// How far the surface around each point strays from flat: the largest `|dot(q - p, n)|` and
/// `|dot(q - p, n_q)|` over the `k` nearest neighbours `q` (normal `n_q`) of a point `p` with
/// normal `n`, then the largest of those over
/// the point's `k` nearest neighbours (so that the whole terrace next to a step knows the step's
/// height, not just the points at its edge). In the cloud's local units; zero on flat clean
/// surfaces. On scans it measures depth noise and quantisation steps (a Kinect's depth comes in
/// steps of about 5 cm at 4 m), which the renderer needs so that noisy points do not shadow
/// their neighbours. Empty when the cloud has no normals.
pub fn surface_spread(pc: &PointCloud, k: usize) -> Vec<f32> {
    if pc.normals.len() != pc.positions.len() || pc.positions.is_empty() {
        return Vec::new();
    }
    surface_spread_from(pc, &Neighbours::find(&pc.positions, k.max(1)), k)
}

/// `surface_spread` from neighbours already found.
pub fn surface_spread_from(pc: &PointCloud, nb: &Neighbours, k: usize) -> Vec<f32> {
    if pc.normals.len() != pc.positions.len() || pc.positions.is_empty() {
        return Vec::new();
    }
    let positions = &pc.positions;
    let normals = &pc.normals;
    let k = k.max(1);
    let raw = nb.map(k, |i, nb| {
        let (p, n) = (positions[i], normals[i]);
        // Distances both ways, to this point's plane and to each neighbour's: a point whose
        // neighbours lie on a line (a row of a depth image) has an arbitrary normal, and its
        // neighbours' planes still see the step it sits on.
        nb.iter()
            .map(|&j| {
                let d = positions[j as usize] - p;
                d.dot(n).abs().max(d.dot(normals[j as usize]).abs())
            })
            .fold(0.0f32, f32::max)
    });
    nb.map(k, |_, nb| {
        nb.iter().map(|&j| raw[j as usize]).fold(0.0f32, f32::max)
    })
}

/// A scene's mesh surfaces as points, as a scanner would see them: every instance becomes a
/// point cloud with a point wherever a lattice of `spacing` metres, laid in each triangle's
/// dominant-axis plane, falls inside the triangle (so axis-aligned surfaces get a regular
/// square grid, and slanted ones up to √3 times sparser). Each point takes its triangle's
/// normal (oriented like the mesh's shading normals), its material's base colour (textures are
/// not read) and emission. Area lights' emitters stay meshes: they are lights, not geometry.
/// Lights, cameras and materials are kept. For comparing points with the meshes they sample.
pub fn sample_surfaces(scene: &Scene, spacing: f32) -> Scene {
    let mut out = without_geometry(scene);
    let spacing = spacing.max(1e-6) as f64;
    for inst in geometry(scene) {
        let mesh = &scene.meshes[inst.mesh];
        let material = &scene.materials[mesh.material];
        let normal_matrix = inst.transform.inverse().transpose();
        let mut pc = PointCloud {
            name: format!("{} (points)", inst.name),
            transform: Mat4::IDENTITY,
            ..Default::default()
        };
        for (t, [a, b, c]) in mesh
            .indices
            .chunks_exact(3)
            .zip(world_triangles(scene, inst))
        {
            let mut n = (b - a).cross(c - a);
            if n.length_squared() < 1e-30 {
                continue;
            }
            n = n.normalize();
            let shading: Vec3 = [t[0], t[1], t[2]]
                .iter()
                .filter_map(|&i| mesh.normals.get(i as usize))
                .map(|&s| normal_matrix.transform_vector3(s))
                .sum();
            if n.dot(shading.as_dvec3()) < 0.0 {
                n = -n;
            }
            let w = n.abs().max_position();
            let (u, v) = ((w + 1) % 3, (w + 2) % 3);
            let lo = a.min(b).min(c);
            let hi = a.max(b).max(c);
            // Offsets that differ per axis keep lattice points off the diagonal a quad's two
            // triangles share, where both or neither might take them.
            let (du, dv) = (0.5, 0.5 + 0.123_456_7);
            let i0 = (lo[u] / spacing - du).ceil() as i64;
            let i1 = (hi[u] / spacing - du).floor() as i64;
            let j0 = (lo[v] / spacing - dv).ceil() as i64;
            let j1 = (hi[v] / spacing - dv).floor() as i64;
            // Edge functions in the (u, v) plane, signed so the inside is positive.
            let edge = |p: DVec3, q: DVec3, x: f64, y: f64| {
                (q[u] - p[u]) * (y - p[v]) - (q[v] - p[v]) * (x - p[u])
            };
            let sign = edge(a, b, c[u], c[v]).signum();
            for i in i0..=i1 {
                for j in j0..=j1 {
                    let (x, y) = ((i as f64 + du) * spacing, (j as f64 + dv) * spacing);
                    if sign * edge(a, b, x, y) < 0.0
                        || sign * edge(b, c, x, y) < 0.0
                        || sign * edge(c, a, x, y) < 0.0
                    {
                        continue;
                    }
                    let mut p = DVec3::ZERO;
                    p[u] = x;
                    p[v] = y;
                    p[w] = a[w] - (n[u] * (x - a[u]) + n[v] * (y - a[v])) / n[w];
                    pc.positions.push(p.as_vec3());
                    pc.normals.push(n.as_vec3());
                    let [r, g, bl, _] = material.base_color;
                    pc.colors.push([r, g, bl]);
                    pc.emission.push(material.emissive);
                }
            }
        }
        if pc.emission.iter().all(|e| *e == [0.0; 3]) {
            pc.emission.clear();
        }
        if !pc.positions.is_empty() {
            out.point_clouds.push(pc);
        }
    }
    out
}

/// The world-space area of the triangles `sample_surfaces` samples, m².
pub fn surface_area(scene: &Scene) -> f64 {
    geometry(scene)
        .flat_map(|inst| world_triangles(scene, inst))
        .map(|[a, b, c]| 0.5 * (b - a).cross(c - a).length())
        .sum()
}

/// A scene's meshes as point clouds of their vertices (a scan that kept a mesh's vertices, as
/// the Stanford models' PLY files do): each instance becomes a cloud of its vertices in world
/// space with the mesh's normals, its material's base colour and emission. Area lights'
/// emitters stay meshes; lights, cameras and materials are kept.
pub fn mesh_vertices(scene: &Scene) -> Scene {
    let mut out = without_geometry(scene);
    for inst in geometry(scene) {
        let mesh = &scene.meshes[inst.mesh];
        let material = &scene.materials[mesh.material];
        let normal_matrix = inst.transform.inverse().transpose();
        let n = mesh.positions.len();
        let [r, g, b, _] = material.base_color;
        let pc = PointCloud {
            name: format!("{} (vertices)", inst.name),
            positions: mesh
                .positions
                .iter()
                .map(|&p| inst.transform.transform_point3(p))
                .collect(),
            normals: mesh
                .normals
                .iter()
                .map(|&v| normal_matrix.transform_vector3(v).normalize_or_zero())
                .collect(),
            colors: vec![[r, g, b]; n],
            emission: if material.emissive == [0.0; 3] {
                Vec::new()
            } else {
                vec![material.emissive; n]
            },
            transform: Mat4::IDENTITY,
            ..Default::default()
        };
        if n > 0 {
            out.point_clouds.push(pc);
        }
    }
    out
}

/// The instances `sample_surfaces` and `mesh_vertices` turn into points: all but area lights'
/// emitters.
fn geometry(scene: &Scene) -> impl Iterator<Item = &Instance> {
    scene.instances.iter().filter(|i| i.light.is_none())
}

/// `scene` without the instances `geometry` lists (and without animations, which name
/// instances by index): what the points are added to.
fn without_geometry(scene: &Scene) -> Scene {
    let mut out = scene.clone();
    out.instances.retain(|i| i.light.is_some());
    out.animations.clear();
    out
}

/// The world-space corners of `inst`'s triangles, in f64.
fn world_triangles<'a>(
    scene: &'a Scene,
    inst: &'a Instance,
) -> impl Iterator<Item = [DVec3; 3]> + 'a {
    let mesh = &scene.meshes[inst.mesh];
    mesh.indices.chunks_exact(3).map(move |t| {
        [t[0], t[1], t[2]].map(|i| {
            inst.transform
                .transform_point3(mesh.positions[i as usize])
                .as_dvec3()
        })
    })
}

/// Eigen-decomposition of a symmetric 3×3 matrix by cyclic Jacobi rotations (robust for
/// repeated and zero eigenvalues). Returns the eigenvalues in ascending order and the matching
/// unit eigenvectors as the columns of the second result (`vecs[row][col]`).
pub fn symmetric_eigen3(m: [[f64; 3]; 3]) -> ([f64; 3], [[f64; 3]; 3]) {
    let mut a = m;
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let scale: f64 = a.iter().flatten().map(|x| x * x).sum::<f64>();
    for _sweep in 0..32 {
        let off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
        if off <= 1e-30 * scale || off == 0.0 {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q] == 0.0 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            for row in a.iter_mut() {
                let (akp, akq) = (row[p], row[q]);
                row[p] = c * akp - s * akq;
                row[q] = s * akp + c * akq;
            }
            let (row_p, row_q) = (a[p], a[q]);
            for col in 0..3 {
                a[p][col] = c * row_p[col] - s * row_q[col];
                a[q][col] = s * row_p[col] + c * row_q[col];
            }
            for row in v.iter_mut() {
                let (vkp, vkq) = (row[p], row[q]);
                row[p] = c * vkp - s * vkq;
                row[q] = s * vkp + c * vkq;
            }
        }
    }
    let mut order = [0usize, 1, 2];
    order.sort_by(|&i, &j| a[i][i].total_cmp(&a[j][j]));
    let vals = order.map(|i| a[i][i]);
    let vecs = [0, 1, 2].map(|r| order.map(|c| v[r][c]));
    (vals, vecs)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{DMat3, Mat4};

    /// Deterministic pseudo-random numbers in [0, 1) (xorshift), so tests need no crate.
    pub(crate) fn rng(seed: u64) -> impl FnMut() -> f32 {
        let mut s = seed.max(1);
        move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 40) as f32 / (1u64 << 24) as f32
        }
    }

    /// The shared neighbour search is an exact k-nearest search: each point's list equals a
    /// brute-force sort by distance (ties by index), also its prefixes, with duplicates, on a
    /// cloud smaller than k, and for clouds spread very unevenly (cells of very different counts).
    #[test]
    fn neighbours_are_the_nearest() {
        let mut r = rng(7);
        let mut pts: Vec<Vec3> = (0..600)
            .map(|i| {
                let p = Vec3::new(r(), r() * 0.01, r());
                // A far cluster and exact duplicates.
                if i % 50 == 0 {
                    p * 1e-3 + Vec3::splat(500.0)
                } else {
                    p
                }
            })
            .collect();
        pts.extend_from_within(..20);
        // A wavy surface of 3000 points: queries that need the second ring of cells.
        let surface: Vec<Vec3> = (0..3000)
            .map(|_| {
                let (x, z) = (r() * 4.0, r() * 2.0);
                Vec3::new(x, (x * 3.0).sin() * 0.3, z)
            })
            .collect();
        // A lattice with some points twice: distances tie everywhere (exact in binary).
        let mut lattice: Vec<Vec3> = (0..300)
            .map(|i| Vec3::new((i % 10) as f32, (i / 10 % 10) as f32, (i / 100) as f32) * 0.25)
            .collect();
        lattice.extend_from_within(40..60);
        for (cloud, k, exact) in [
            (&pts[..], 24, false),
            (&pts[..], 8, false),
            (&pts[..5], 24, false),
            (&surface[..], 24, false),
            (&lattice[..], 24, true),
            (&lattice[..], 8, true),
        ] {
            let nb = Neighbours::find(cloud, k);
            assert_eq!(nb.k(), k.min(cloud.len() - 1));
            for (i, &p) in cloud.iter().enumerate() {
                let mut all: Vec<(f32, u32)> = cloud
                    .iter()
                    .enumerate()
                    .map(|(j, &q)| (q.distance_squared(p), j as u32))
                    .collect();
                all.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
                for kk in [k, 8, 3] {
                    let got = nb.of(i, kk);
                    let want: Vec<u32> = all[..(kk + 1).min(cloud.len())]
                        .iter()
                        .map(|a| a.1)
                        .collect();
                    // The same distances (ties among equal distances may pick other points
                    // where the k-d tree answers: the far cluster's points).
                    let d = |v: &[u32]| {
                        v.iter()
                            .map(|&j| cloud[j as usize].distance_squared(p))
                            .collect::<Vec<f32>>()
                    };
                    assert_eq!(d(got), d(&want), "point {i}, k {kk}");
                    // Ties by index, where the grid answers (a lattice: no query reaches
                    // the tree).
                    if exact {
                        assert_eq!(got, &want[..], "point {i}, k {kk}");
                    }
                }
            }
        }
    }

    fn check_eigen(m: [[f64; 3]; 3]) {
        let (vals, vecs) = symmetric_eigen3(m);
        let mm = DMat3::from_cols_array_2d(&m).transpose();
        let scale = m.iter().flatten().map(|x| x.abs()).fold(1e-300, f64::max);
        assert!(vals[0] <= vals[1] && vals[1] <= vals[2]);
        for c in 0..3 {
            let e = DVec3::new(vecs[0][c], vecs[1][c], vecs[2][c]);
            // Unit length and A e = λ e, to 1e-9 of the matrix scale (f64 round-off after a
            // handful of rotations is ~1e-15; 1e-9 leaves room and still catches any wrong sign
            // or index in the rotation).
            assert!((e.length() - 1.0).abs() < 1e-9);
            assert!((mm * e - vals[c] * e).length() < 1e-9 * scale, "{m:?}");
        }
    }

    #[test]
    #[allow(clippy::needless_range_loop)] // filling a symmetric matrix by (i, j) is clearest
    fn eigen_solver_on_random_and_special_matrices() {
        let mut r = rng(7);
        for _ in 0..1000 {
            let mut m = [[0f64; 3]; 3];
            for i in 0..3 {
                for j in i..3 {
                    let x = (r() as f64 - 0.5) * 10.0;
                    m[i][j] = x;
                    m[j][i] = x;
                }
            }
            check_eigen(m);
        }
        check_eigen([[0.0; 3]; 3]);
        check_eigen([[2.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 2.0]]);
        check_eigen([[3.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 2.0]]);
        // Rank one (points on a line).
        check_eigen([[1.0, 1.0, 1.0], [1.0, 1.0, 1.0], [1.0, 1.0, 1.0]]);
        let (vals, vecs) = symmetric_eigen3([[4.0, 0.0, 0.0], [0.0, 9.0, 0.0], [0.0, 0.0, 1.0]]);
        assert_eq!(vals, [1.0, 4.0, 9.0]);
        assert_eq!(
            [vecs[0][0], vecs[1][0], vecs[2][0]].map(f64::abs),
            [0.0, 0.0, 1.0]
        );
    }

    fn jittered_plane(n: usize, jitter: f32) -> PointCloud {
        let mut r = rng(42);
        let mut pc = PointCloud {
            transform: Mat4::IDENTITY,
            ..Default::default()
        };
        for i in 0..n {
            for j in 0..n {
                let x = i as f32 * 0.01 + (r() - 0.5) * jitter;
                let y = j as f32 * 0.01 + (r() - 0.5) * jitter;
                pc.positions.push(Vec3::new(x, y, 0.0));
            }
        }
        pc.colors = vec![[0.8; 3]; pc.positions.len()];
        pc
    }

    #[test]
    fn normals_of_a_jittered_plane_face_the_viewpoint() {
        for (view, want) in [
            (Vec3::new(0.3, 0.2, 5.0), Vec3::Z),
            (Vec3::new(0.1, 0.1, -2.0), Vec3::NEG_Z),
        ] {
            let mut pc = jittered_plane(60, 0.006);
            estimate_normals(&mut pc, 12, view);
            assert_eq!(pc.normals.len(), pc.positions.len());
            // The points lie exactly in z = 0 (jitter is in-plane), so only rounding separates
            // the estimate from ±Z; 1° is the brief's bound.
            let cos1 = 1f32.to_radians().cos();
            for n in &pc.normals {
                assert!(n.dot(want) > cos1, "{n}");
            }
        }
    }

    #[test]
    fn normals_of_a_noisy_tilted_plane() {
        // Out-of-plane noise of ±0.5 mm on a 1 cm grid tilts local fits by atan(0.05 / ~2) ≈ 1.4°
        // at worst; averaged over 16 neighbours the median error stays well below 1°.
        let mut pc = jittered_plane(50, 0.004);
        let mut r = rng(3);
        let rot = glam::Quat::from_rotation_x(0.7);
        for p in &mut pc.positions {
            p.z = (r() - 0.5) * 0.001;
            *p = rot * *p;
        }
        let want = rot * Vec3::Z;
        estimate_normals(&mut pc, 16, want * 10.0);
        let mut err: Vec<f32> = pc
            .normals
            .iter()
            .map(|n| n.dot(want).clamp(-1.0, 1.0).acos().to_degrees())
            .collect();
        err.sort_by(f32::total_cmp);
        assert!(err[err.len() / 2] < 1.0, "median {}", err[err.len() / 2]);
        assert!(pc.normals.iter().all(|n| n.dot(want) > 0.0));
    }

    #[test]
    fn radii_on_a_1cm_grid() {
        let mut pc = jittered_plane(40, 0.0);
        for k in [4, 8, 16] {
            pc.radii.clear();
            estimate_radii(&mut pc, k);
            // Covering a 1 cm square grid needs 0.707 cm; the brief's bounds are [0.5, 1.0] cm.
            // Only interior points: near the border the k neighbours spread over a half or
            // quarter disc, so d_k (and the radius) grows there by design.
            let mut checked = 0;
            for (p, &r) in pc.positions.iter().zip(&pc.radii) {
                if p.x.min(p.y) >= 0.045 && p.x.max(p.y) <= 0.345 {
                    assert!((0.005..=0.010).contains(&r), "k {k}: {r}");
                    checked += 1;
                }
            }
            assert!(checked > 500);
        }
    }

    #[test]
    fn existing_attributes_are_kept() {
        let mut pc = jittered_plane(5, 0.0);
        pc.normals = vec![Vec3::X; 25];
        pc.radii = vec![7.0; 25];
        estimate_normals(&mut pc, 8, Vec3::Z);
        estimate_radii(&mut pc, 8);
        assert!(pc.normals.iter().all(|n| *n == Vec3::X));
        assert!(pc.radii.iter().all(|r| *r == 7.0));
    }
}
