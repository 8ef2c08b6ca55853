//! Voxel fragments, the one interface between geometry and voxel structures (DESIGN.md, seam
//! 1): a pass that turns geometry into fragments (`voxelize` for meshes) writes them here and
//! nothing else, and a structure is built from them and nothing else. The buffer's length is
//! its capacity; the count runs past it when a build overflowed, and the renderer grows the
//! buffer a frame later.

pub mod grid;
pub mod splat;
pub mod voxelize;

pub use grid::{GpuRegion, Grid, Region};

use crate::gpu_scene::GpuScene;
use crate::{Error, Result};
use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

/// Bytes per fragment (`Fragment` in shaders/shared/fragment.wgsl).
pub const FRAGMENT_BYTES: u64 = 20;

/// Mirrors `FragmentGrid` in shaders/shared/fragment.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuFragmentGrid {
    /// World position of the grid's minimum corner, metres.
    pub origin: [f32; 3],
    /// Voxels per side.
    pub resolution: u32,
    /// Edge length of a voxel, metres.
    pub voxel_size: f32,
    /// `1 / voxel_size`.
    pub inv_voxel_size: f32,
    /// Added to a fragment's z: window `z_offset / resolution` of a structure with several.
    pub z_offset: u32,
    /// Padding to the WGSL struct's 32 bytes; zero.
    pub _pad: u32,
}

impl GpuFragmentGrid {
    /// Window `window` of a structure whose windows are `grid`-sized cubes stacked along z.
    pub fn of(grid: &Grid, window: u32) -> Self {
        GpuFragmentGrid {
            origin: grid.origin.to_array(),
            resolution: grid.resolution,
            voxel_size: grid.voxel_size,
            inv_voxel_size: 1.0 / grid.voxel_size,
            z_offset: window * grid.resolution,
            _pad: 0,
        }
    }
}

/// The fragment buffer of a structure's grids, and its count.
pub struct Fragments {
    /// The grids the fragments lie on (the finest voxels): one, or a camera-following
    /// structure's windows (`VoxelStructure::fragment_grids`), whose fragments are stacked
    /// along z (window k's at z + k · resolution).
    pub grids: Vec<Grid>,
    /// Per grid: where its fragments lie (`FragmentGrid`) and where they are made
    /// (`FragmentRegion`: the static geometry's and the points' at offset 0, the dynamic
    /// geometry's at `REGION_STRIDE`; `set_regions`).
    pub windows: Vec<FragmentWindow>,
    /// The fragments; its length is the capacity.
    pub buffer: wgpu::Buffer,
    /// `[0]`: fragments made by the last build, counted past the capacity.
    pub count: wgpu::Buffer,
    /// `[0]`: the count when the static geometry was done (`record_mark`): fragments from
    /// there on are the dynamic geometry's, redone every frame it moves.
    pub mark: wgpu::Buffer,
    /// Fragments `buffer` holds; a build that makes more counts them and drops the rest.
    pub capacity: u32,
}

/// One grid's uniforms in `Fragments`.
pub struct FragmentWindow {
    /// Where its fragments lie (`FragmentGrid`).
    pub grid: wgpu::Buffer,
    /// Where they are made (`FragmentRegion`s, static at 0, dynamic at `REGION_STRIDE`).
    pub regions: wgpu::Buffer,
    /// The triangle table's spans voxelize runs (`TableSpan`s, `REGION_STRIDE` apart): the
    /// dynamic table's at 0, the static table's from `REGION_STRIDE` (`set_spans`).
    pub spans: wgpu::Buffer,
}

/// Where `geometry`'s spans begin in `FragmentWindow::spans`.
fn spans_offset(geometry: Geometry) -> u64 {
    match geometry {
        Geometry::Dynamic => 0,
        Geometry::Static => REGION_STRIDE,
    }
}

/// The most spans of the static triangle table a window's voxelization runs (`draw_spans`
/// merges across the narrowest gaps past this).
pub const MAX_SPANS: usize = 63;

/// Bytes between the two regions of `Fragments::regions` (the largest uniform offset
/// alignment WebGPU allows a device to ask for).
pub const REGION_STRIDE: u64 = 256;

/// Which geometry a pass makes fragments of: it decides the region the pass binds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Geometry {
    /// The static geometry (meshes and point clouds), for a build.
    Static,
    /// The dynamic geometry (meshes and point clouds), for an update.
    Dynamic,
}

impl Fragments {
    /// Room for `capacity` fragments on `grids` (check it first with `capacity`).
    pub fn new(device: &wgpu::Device, grids: &[Grid], capacity: u32) -> Self {
        let storage = wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_DST
            | wgpu::BufferUsages::COPY_SRC;
        let windows = grids
            .iter()
            .enumerate()
            .map(|(k, grid)| FragmentWindow {
                grid: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("fragment grid"),
                    contents: bytemuck::bytes_of(&GpuFragmentGrid::of(grid, k as u32)),
                    usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                }),
                regions: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("fragment regions"),
                    contents: &regions_bytes(Region::all(grid), Region::all(grid)),
                    usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                }),
                spans: device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("voxelize spans"),
                    size: (1 + MAX_SPANS as u64) * REGION_STRIDE,
                    usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                }),
            })
            .collect();
        Fragments {
            grids: grids.to_vec(),
            windows,
            buffer: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("voxel fragments"),
                size: capacity.max(1) as u64 * FRAGMENT_BYTES,
                usage: storage,
                mapped_at_creation: false,
            }),
            count: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("fragment count"),
                size: 16,
                usage: storage,
                mapped_at_creation: false,
            }),
            mark: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("static fragment count"),
                size: 16,
                usage: storage,
                mapped_at_creation: false,
            }),
            capacity,
        }
    }

    /// Moves the grids (as many as before: a camera-following structure's windows moved).
    pub fn set_grids(&mut self, queue: &wgpu::Queue, grids: &[Grid]) {
        debug_assert_eq!(grids.len(), self.grids.len());
        for (k, (w, grid)) in self.windows.iter().zip(grids).enumerate() {
            if self.grids[k] != *grid {
                queue.write_buffer(
                    &w.grid,
                    0,
                    bytemuck::bytes_of(&GpuFragmentGrid::of(grid, k as u32)),
                );
                self.grids[k] = *grid;
            }
        }
    }

    /// Sets where the next build (`build`, per grid) and update (`update`) make fragments; a
    /// grid without an entry makes none.
    pub fn set_regions(&self, queue: &wgpu::Queue, build: &[Region], update: &[Region]) {
        for (k, w) in self.windows.iter().enumerate() {
            let at = |r: &[Region]| r.get(k).copied().unwrap_or(Region::EMPTY);
            queue.write_buffer(&w.regions, 0, &regions_bytes(at(build), at(update)));
        }
    }

    /// The region a pass making fragments of `geometry` on grid `window` binds.
    pub fn region(&self, window: usize, geometry: Geometry) -> wgpu::BindingResource<'_> {
        let offset = match geometry {
            Geometry::Static => 0,
            Geometry::Dynamic => REGION_STRIDE,
        };
        wgpu::BindingResource::Buffer(wgpu::BufferBinding {
            buffer: &self.windows[window].regions,
            offset,
            size: wgpu::BufferSize::new(size_of::<GpuRegion>() as u64),
        })
    }

    /// Writes the spans of `geometry`'s triangle table that voxelize runs on grid `window` in
    /// the next recording (`TriangleTable::spans`; one for the dynamic table, at most
    /// `MAX_SPANS` for the static one).
    pub fn set_spans(
        &self,
        queue: &wgpu::Queue,
        window: usize,
        geometry: Geometry,
        spans: &[TableSpan],
    ) {
        let most = match geometry {
            Geometry::Dynamic => 1,
            Geometry::Static => MAX_SPANS,
        };
        assert!(spans.len() <= most, "{} voxelize spans", spans.len());
        let mut bytes = vec![0u8; spans.len() * REGION_STRIDE as usize];
        for (chunk, s) in bytes.chunks_mut(REGION_STRIDE as usize).zip(spans) {
            chunk[..16].copy_from_slice(bytemuck::bytes_of(s));
        }
        let at = spans_offset(geometry);
        queue.write_buffer(&self.windows[window].spans, at, &bytes);
    }

    /// The spans a voxelize pass over `geometry`'s table on grid `window` binds (one
    /// `TableSpan`, its dynamic offset choosing which).
    pub fn spans(&self, window: usize, geometry: Geometry) -> wgpu::BindingResource<'_> {
        wgpu::BindingResource::Buffer(wgpu::BufferBinding {
            buffer: &self.windows[window].spans,
            offset: spans_offset(geometry),
            size: wgpu::BufferSize::new(size_of::<TableSpan>() as u64),
        })
    }

    /// Records the start of a build: no fragments yet.
    pub fn record_clear(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.clear_buffer(&self.count, 0, None);
    }

    /// Records the end of the static geometry: the fragments so far are kept, and those
    /// voxelized after this are the dynamic geometry's.
    pub fn record_mark(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.copy_buffer_to_buffer(&self.count, 0, &self.mark, 0, 16);
    }

    /// Records the start of a dynamic update: the dynamic fragments of the last one are
    /// dropped, the static ones kept.
    pub fn record_truncate(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.copy_buffer_to_buffer(&self.mark, 0, &self.count, 0, 16);
    }

    /// GPU memory held, by buffer name, in bytes (the fragment buffer; the small buffers are left
    /// out).
    pub fn memory(&self) -> Vec<(&'static str, u64)> {
        vec![("voxel fragments", self.buffer.size())]
    }
}

/// The two regions at their offsets in `Fragments::regions`.
fn regions_bytes(build: Region, update: Region) -> Vec<u8> {
    let mut bytes = vec![0u8; (REGION_STRIDE as usize) + size_of::<GpuRegion>()];
    bytes[..size_of::<GpuRegion>()].copy_from_slice(bytemuck::bytes_of(&build.to_gpu()));
    bytes[REGION_STRIDE as usize..].copy_from_slice(bytemuck::bytes_of(&update.to_gpu()));
    bytes
}

/// Checks a fragment capacity against the device's storage-buffer limit (at least 1024).
pub fn capacity(device: &wgpu::Device, wanted: u64) -> Result<u32> {
    crate::gpu::pool_capacity(device, wanted, FRAGMENT_BYTES, "voxel fragments")
}

/// How many fragments a scene makes on a grid, to size the first fragment buffer (a short one
/// grows a frame later): per triangle, an upper bound, the columns its
/// dominant-axis projection can touch times the three voxels a column can hold; per point, the
/// voxels its region of influence overlaps on average ((1 + e)³ for an edge of e voxels, at
/// most 8). Kept as sums over the triangles and points in metres, so it can be evaluated for
/// any grid without the scene.
#[derive(Clone, Copy, Debug, Default)]
pub struct FragmentEstimate {
    /// Sum of the triangles' dominant-axis projected areas, m².
    area: f64,
    /// Sum of their perimeters, m.
    perimeter: f64,
    triangles: u64,
    points: u64,
    /// Sums of the points' region edges, their squares and cubes (m, m², m³).
    edges: [f64; 3],
}

impl FragmentEstimate {
    /// Sums the projected areas, perimeters and count of every instance's triangles, in world
    /// space.
    pub fn of(scene: &voxgi_scene::Scene) -> Self {
        let mut e = FragmentEstimate::default();
        // Area-light emitters make no fragments (`triangle_table`); dynamic geometry makes
        // two per voxel it crosses (voxelize.wgsl's coverage).
        for inst in scene.instances.iter().filter(|i| i.light.is_none()) {
            let m = &scene.meshes[inst.mesh];
            let k = if inst.dynamic { 2.0 } else { 1.0 };
            for t in m.indices.chunks_exact(3) {
                let [a, b, c] = [t[0], t[1], t[2]]
                    .map(|i| inst.transform.transform_point3(m.positions[i as usize]));
                let n = (b - a).cross(c - a);
                e.area += k * 0.5 * n.abs().max_element() as f64;
                e.perimeter += k * ((b - a).length() + (c - b).length() + (a - c).length()) as f64;
                e.triangles += k as u64;
            }
        }
        for (c, pc) in scene.point_clouds.iter().enumerate() {
            if pc.light.is_some() {
                continue;
            }
            let scale = pc.transform.determinant().abs().cbrt() as f64;
            // A point sequence's largest frame, as so many points like these.
            let room = scene.cloud_capacity(c);
            let grow = room as f64 / pc.positions.len().max(1) as f64;
            e.points += room as u64;
            for &r in &pc.regions {
                let r = r as f64 * scale;
                if r.is_finite() {
                    e.edges[0] += grow * r;
                    e.edges[1] += grow * r * r;
                    e.edges[2] += grow * r * r * r;
                }
            }
        }
        e
    }

    /// The bound on `grid`.
    pub fn at(&self, grid: &Grid) -> u64 {
        let inv = 1.0 / grid.voxel_size as f64;
        let triangles =
            3.0 * (self.area * inv * inv + self.perimeter * inv + 2.0 * self.triangles as f64);
        // Regions wider than a voxel are clipped to one, so the sum can overshoot: cap it.
        let [e1, e2, e3] = self.edges;
        let points =
            (self.points as f64 + 3.0 * e1 * inv + 3.0 * e2 * inv * inv + e3 * inv * inv * inv)
                .min(8.0 * self.points as f64);
        (triangles + points).ceil() as u64
    }
}

/// The triangles voxelize reads: per workgroup, a triangle's draw, first index and base
/// vertex, and which share of its voxel columns the workgroup takes (`chunk | chunks << 16`).
pub struct TriangleTable {
    /// `[u32; 4]` per entry: a header (the small entries' count), the small triangles, then
    /// the workgroups' entries (shaders/fragments/voxelize.wgsl).
    pub buffer: wgpu::Buffer,
    /// Small triangles, one thread each.
    pub small: u32,
    /// Workgroup entries: larger triangles, or shares of a large one's columns.
    pub count: u32,
    /// The dynamic instances' triangles (their fragments carry coverage), or the static ones'.
    pub dynamic: bool,
    /// Per draw of a static table, in the table's order: its world box and its entries (the
    /// small ones' and the workgroups', each a range of their list). Empty for a dynamic one.
    draws: Vec<DrawEntries>,
}

/// A static draw's world box and its entries in the triangle table.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DrawEntries {
    /// Its world box's lowest corner.
    pub lo: glam::Vec3,
    /// Its world box's highest corner.
    pub hi: glam::Vec3,
    /// Its small entries: `[first, end)` of that list.
    pub small: [u32; 2],
    /// Its workgroup entries: `[first, end)` of that list.
    pub large: [u32; 2],
}

/// What one dispatch pair of voxelize runs (`TableSpan` in shaders/fragments/voxelize.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct TableSpan {
    /// The first small entry, within the small entries.
    pub small_first: u32,
    /// How many small entries.
    pub small_count: u32,
    /// The first workgroup entry, within the workgroup entries.
    pub large_first: u32,
    /// How many workgroup entries.
    pub large_count: u32,
}

impl TriangleTable {
    /// Every entry in one span.
    pub fn whole(&self) -> TableSpan {
        TableSpan {
            small_first: 0,
            small_count: self.small,
            large_first: 0,
            large_count: self.count,
        }
    }

    /// The spans of a static table that voxelizing `region` of `grid` runs: the entries of
    /// the draws whose box may reach it (`draw_spans`). A dynamic table's draws move: all of it.
    pub fn spans(&self, grid: &Grid, region: &Region) -> Vec<TableSpan> {
        if self.dynamic {
            return vec![self.whole()];
        }
        draw_spans(&self.draws, grid, region, MAX_SPANS)
    }
}

/// The spans of `draws`' entries whose draws' boxes may make fragments in `region` of `grid`,
/// neighbours merged, at most `most` (merged across the narrowest gaps, whose draws' entries
/// then run too: voxelize's own box test, `draw_in_region`, skips them). The box test
/// is voxelize's with a voxel more of margin, so the host never leaves out a draw the GPU
/// would voxelize.
pub fn draw_spans(
    draws: &[DrawEntries],
    grid: &Grid,
    region: &Region,
    most: usize,
) -> Vec<TableSpan> {
    if region.is_empty() {
        return Vec::new();
    }
    let reaches = |d: &DrawEntries| {
        let lo = (d.lo - grid.origin) / grid.voxel_size - 3.0;
        let hi = (d.hi - grid.origin) / grid.voxel_size + 3.0;
        // NaN corners fail every comparison: such a draw is run.
        let outside =
            (0..3).any(|a| hi[a] < region.lo[a] as f32 || lo[a] >= (region.hi[a] + 1) as f32);
        let (klo, khi) = region.kept;
        let kept = (0..3).all(|a| lo[a] >= klo[a] as f32 && hi[a] < (khi[a] + 1) as f32);
        !(outside || kept)
    };
    // Runs of draws, by their index in `draws`.
    let mut runs: Vec<(usize, usize)> = Vec::new();
    for (i, _) in draws.iter().enumerate().filter(|(_, d)| reaches(d)) {
        match runs.last_mut() {
            Some((_, end)) if *end == i => *end = i + 1,
            _ => runs.push((i, i + 1)),
        }
    }
    // Too many: keep apart only at the `most - 1` widest gaps, in table entries (what a gap
    // merged over costs: its entries' threads, which voxelize's own box test returns).
    let most = most.max(1);
    if runs.len() > most {
        let entries = |a: usize, b: usize| {
            let (first, last) = (&draws[a], &draws[b - 1]);
            (last.small[1] - first.small[0]) + (last.large[1] - first.large[0])
        };
        let mut gaps: Vec<(u32, usize)> = (1..runs.len())
            .map(|k| (entries(runs[k - 1].1, runs[k].0), k))
            .collect();
        gaps.sort_unstable_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)));
        let mut apart: Vec<usize> = gaps[..most - 1].iter().map(|g| g.1).collect();
        apart.sort_unstable();
        let mut merged = Vec::with_capacity(most);
        let mut start = runs[0].0;
        for &k in &apart {
            merged.push((start, runs[k - 1].1));
            start = runs[k].0;
        }
        merged.push((start, runs[runs.len() - 1].1));
        runs = merged;
    }
    runs.iter()
        .map(|&(a, b)| {
            let (first, last) = (&draws[a], &draws[b - 1]);
            TableSpan {
                small_first: first.small[0],
                small_count: last.small[1] - first.small[0],
                large_first: first.large[0],
                large_count: last.large[1] - first.large[0],
            }
        })
        .filter(|s| s.small_count + s.large_count > 0)
        .collect()
}

/// Voxel columns one voxelize workgroup takes at most (512 per thread). A CPU driver
/// (llvmpipe) ends every loop of an invocation once they have run 65535 iterations in all,
/// silently: one workgroup for a triangle over a 1024³ grid's whole floor made a fifth of its
/// fragments. Larger triangles are split over several workgroups.
pub const CHUNK_COLUMNS: u32 = 64 * 512;

/// A triangle whose longest edge spans at most this many of the finest voxels covers at most
/// 324 columns along its dominant axis ((16 + 2)²): one thread voxelizes it, within the 512
/// columns a thread of a large triangle's workgroup may take (`CHUNK_COLUMNS`, a CPU driver's
/// loop budget).
const SMALL_EDGE: f32 = 16.0;

/// How many workgroups voxelize a triangle whose longest edge is `edge` metres on `grid`:
/// its projection on the dominant plane fits a square of that side, so it covers at most
/// `(edge / voxel + 2)²` columns. (A dynamic instance scaled up past its uploaded size makes
/// the last workgroup take the rest.)
pub fn chunks(edge: f32, grid: &Grid) -> u32 {
    let side = (edge / grid.voxel_size).min(1e6) as f64 + 2.0;
    ((side * side) / CHUNK_COLUMNS as f64)
        .ceil()
        .clamp(1.0, 65535.0) as u32
}

/// The triangle table of the static (`dynamic` false) or the dynamic instances on `grid`,
/// whose structure's finest voxels are `finest` metres (a clipmap's finest level is finer than
/// the scene's grid: small triangles are small there). An error when the table would not fit
/// one storage binding of this device.
pub fn triangle_table(
    device: &wgpu::Device,
    scene: &GpuScene,
    dynamic: bool,
    grid: &Grid,
    finest: f32,
) -> Result<TriangleTable> {
    let (mut small, mut t): (Vec<[u32; 4]>, Vec<[u32; 4]>) = (Vec::new(), Vec::new());
    let mut draws = Vec::new();
    for call in scene.calls.iter().filter(|c| c.dynamic == dynamic) {
        // The visible surface of an area light is not voxelized, neither as an emitter (its
        // light reaches surfaces as the light's direct term, shaded per pixel and injected per
        // voxel, so it would count twice, and an isotropic voxel would shine sideways from a
        // one-sided flat emitter) nor as an occluder: a free-standing lamp voxelized as an
        // opaque slab moved the image further from the path tracer (docs/QUALITY.md).
        if call.light.is_some() {
            continue;
        }
        let (small_at, large_at) = (small.len() as u32, t.len() as u32);
        for (first, &edge) in call.indices.clone().step_by(3).zip(&call.edges) {
            // A dynamic instance may be scaled up past its uploaded size: its triangles keep
            // the workgroups that share any number of columns.
            if !dynamic && edge <= SMALL_EDGE * finest.min(grid.voxel_size) {
                small.push([call.draw, first, call.base_vertex as u32, 0]);
                continue;
            }
            let n = chunks(edge, grid);
            for chunk in 0..n {
                t.push([call.draw, first, call.base_vertex as u32, chunk | n << 16]);
            }
        }
        if !dynamic {
            let b = scene.draw_box(call.draw);
            draws.push(DrawEntries {
                lo: b.min,
                hi: b.max,
                small: [small_at, small.len() as u32],
                large: [large_at, t.len() as u32],
            });
        }
    }
    let n = t.len() as u32;
    let s = small.len() as u32;
    let t: Vec<[u32; 4]> = std::iter::once([s, 0, 0, 0])
        .chain(small)
        .chain(t)
        .collect();
    let bytes = size_of_val(t.as_slice()) as u64;
    let limit = device.limits().max_storage_buffer_binding_size;
    if bytes > limit {
        return Err(Error::TooLarge(format!(
            "the scene's drawn triangles need a {} MiB voxelization table ({} entries), \
             more than this GPU's storage-buffer limit of {} MiB",
            bytes >> 20,
            t.len(),
            limit >> 20
        )));
    }
    let buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(if dynamic {
            "voxelize triangles (dynamic)"
        } else {
            "voxelize triangles (static)"
        }),
        contents: bytemuck::cast_slice(&t),
        usage: wgpu::BufferUsages::STORAGE,
    });
    Ok(TriangleTable {
        buffer,
        small: s,
        count: n,
        dynamic,
        draws,
    })
}

/// The fragment buffer on `grids` with room for `wanted` fragments, or as many as this
/// device's storage-buffer limit allows (a build that overflows it counts, and the pools grow).
pub fn allocate(device: &wgpu::Device, grids: &[Grid], wanted: u64) -> Result<Fragments> {
    let capacity = capacity(
        device,
        wanted.min(crate::gpu::max_entries(device, FRAGMENT_BYTES)),
    )?;
    crate::gpu::checked(device, "voxel fragments", || {
        Fragments::new(device, grids, capacity)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{UVec3, Vec3};

    /// Draws a metre wide along x, 0.5 m apart, each with one small and one large entry.
    fn row(n: u32) -> Vec<DrawEntries> {
        (0..n)
            .map(|i| {
                let x = i as f32 * 1.5;
                DrawEntries {
                    lo: Vec3::new(x, 0.0, 0.0),
                    hi: Vec3::new(x + 1.0, 1.0, 1.0),
                    small: [i, i + 1],
                    large: [i, i + 1],
                }
            })
            .collect()
    }

    fn grid() -> Grid {
        Grid {
            origin: Vec3::ZERO,
            voxel_size: 0.1,
            resolution: 256,
        }
    }

    #[test]
    fn spans_run_the_draws_near_the_region_and_merge_neighbours() {
        let draws = row(10);
        // x from 3.0 to 6.0 m: draws 2 and 3 meet it, draw 4 (from 6.0 m) only by the margin
        // (voxelize's two voxels and the host's third), draw 1 (to 2.5 m) not even so.
        let region = Region {
            lo: UVec3::new(30, 0, 0),
            hi: UVec3::new(59, 9, 9),
            kept: (UVec3::ONE, UVec3::ZERO),
        };
        let spans = draw_spans(&draws, &grid(), &region, MAX_SPANS);
        assert_eq!(
            spans,
            vec![TableSpan {
                small_first: 2,
                small_count: 3,
                large_first: 2,
                large_count: 3,
            }]
        );
        // Draws whose box, grown, lies inside the kept box are left out, splitting the run:
        // with voxels 0..=99 on x kept (up to 10 m, every y and z), draws 0 to 5 (the last
        // ends at 8.5 m) are kept, 6 to 9 run (draw 6 ends at 10 m, its box grown past it).
        let region = Region {
            kept: (UVec3::new(0, 0, 0), UVec3::new(99, 255, 255)),
            ..Region::all(&grid())
        };
        let mut lifted = draws.clone();
        for d in &mut lifted {
            (d.lo.y, d.hi.y, d.lo.z, d.hi.z) = (5.0, 6.0, 5.0, 6.0);
        }
        lifted[0].lo.x = 0.5;
        let spans = draw_spans(&lifted, &grid(), &region, MAX_SPANS);
        let runs: Vec<(u32, u32)> = spans
            .iter()
            .map(|s| (s.small_first, s.small_count))
            .collect();
        assert_eq!(runs, vec![(6, 4)]);
        assert!(draw_spans(&draws, &grid(), &Region::EMPTY, MAX_SPANS).is_empty());
    }

    #[test]
    fn too_many_spans_merge_across_the_smallest_gaps() {
        let mut draws = row(9);
        // Draws 0, 2, 4, 8 reach the region (the others moved far away): 4 runs.
        for i in [1, 3, 5, 6, 7] {
            draws[i].lo += Vec3::splat(100.0);
            draws[i].hi += Vec3::splat(100.0);
        }
        let region = Region::all(&grid());
        let spans = draw_spans(&draws, &grid(), &region, 2);
        // The gaps after 0 and 2 are one draw, after 4 three: 0..=4 merge, 8 stays apart.
        let runs: Vec<(u32, u32)> = spans
            .iter()
            .map(|s| (s.small_first, s.small_count))
            .collect();
        assert_eq!(runs, vec![(0, 5), (8, 1)]);
        // A box of NaNs fails every comparison: run, as voxelize runs it.
        draws[1].lo = Vec3::NAN;
        let spans = draw_spans(&draws, &grid(), &region, MAX_SPANS);
        assert_eq!(spans[0].small_count, 3, "{spans:?}");
    }
}
