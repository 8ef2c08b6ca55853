//! Counting before building: when the scene's fragment estimate (an upper bound) does not fit
//! this device, the static geometry is voxelized and built once while the renderer is made and
//! its counts read back, so that a resolution the device cannot hold is refused then, naming
//! the limit, instead of after a frame's work (half a minute on a CPU driver at 1024³), and a
//! resolution it can hold starts with pools of the counted size instead of growing over
//! several frames. The estimate overshoots (4× on Sponza), so most scenes never count.
//!
//! Native only: it waits for the GPU, which a browser's main thread cannot; there a frame's
//! counters grow the pools a frame later (`Renderer::receive_feedback`) and a count past the
//! limit is the error then.

use crate::fragments::splat::SplatPass;
use crate::fragments::voxelize::VoxelizePass;
use crate::fragments::{
    self, FRAGMENT_BYTES, FragmentEstimate, Fragments, Geometry, TriangleTable,
};
use crate::gpu::readback;
use crate::gpu::timer::GpuTimer;
use crate::gpu_scene::GpuScene;
use crate::voxel::{Grid, POOL_COUNTERS, Region, VoxelStructure};
use crate::{Error, Result};
use voxgi_scene::Aabb;

/// What a counting build needs of the renderer.
pub(super) struct Sizing<'a> {
    pub device: &'a wgpu::Device,
    pub queue: &'a wgpu::Queue,
    pub scene: &'a GpuScene,
    pub triangles: &'a TriangleTable,
    pub voxelize: &'a VoxelizePass,
    pub splat: &'a SplatPass,
}

/// The fragments a scene within `bounds` makes on `grids`: the estimate on each, for a grid
/// narrower than the scene (a clipmap's finer windows) the share of the scene's surface its
/// window can hold, as the square of the ratio of their sides (surfaces grow with area).
pub(super) fn estimate_on(estimate: &FragmentEstimate, bounds: Aabb, grids: &[Grid]) -> u64 {
    let side = bounds.size().max_element().max(1e-6);
    grids
        .iter()
        .map(|g| {
            let share = (g.extent() / side).min(1.0).powi(2) as f64;
            (estimate.at(g) as f64 * share).ceil() as u64
        })
        .sum()
}

/// Whether `estimate` on `volume`'s grids leaves the fragments or its leaves in doubt on this
/// device: the estimate bounds both (a fragment per voxel a triangle or point touches; a leaf
/// per voxel with a fragment), so below both limits nothing can be refused.
pub(super) fn in_doubt(
    device: &wgpu::Device,
    estimate: &FragmentEstimate,
    bounds: Aabb,
    volume: &dyn VoxelStructure,
) -> bool {
    let bound = estimate_on(estimate, bounds, &volume.fragment_grids());
    cfg!(not(target_arch = "wasm32"))
        && (bound > crate::gpu::max_entries(device, FRAGMENT_BYTES)
            || bound > volume.leaf_limit(device))
}

/// Builds that outgrow their pools: each grows them at least by half, so a handful reach
/// any count a device can hold; past it, growth is an error.
const ROUNDS: usize = 8;

impl Sizing<'_> {
    /// Voxelizes the static geometry into `fragments` (or a larger buffer) and builds
    /// `volume` from it, growing either until the build fits. Returns the larger fragment
    /// buffer if one was made, and whether `volume` holds the whole build (false only if it
    /// still overflowed after `ROUNDS` builds). `volume` is left bound to the fragments in use. An
    /// error when a count is past this device's limits: the fragments' or the structure's
    /// own (`VoxelStructure::grow`).
    pub fn fit(
        &self,
        fragments: &Fragments,
        volume: &mut Box<dyn VoxelStructure>,
    ) -> Result<(Option<Fragments>, bool)> {
        let grids = volume.fragment_grids();
        let all: Vec<Region> = grids.iter().map(Region::all).collect();
        fragments.set_regions(self.queue, &all, &[]);
        let mut count = self.voxelize(fragments)?;
        let mut grown = None;
        if count > fragments.capacity as u64 {
            let limit = crate::gpu::max_entries(self.device, FRAGMENT_BYTES);
            if count > limit {
                return Err(Error::TooLarge(format!(
                    "at {r}³ voxels the scene makes {count} voxel fragments, more than this \
                     GPU's storage-buffer limit of {} MiB holds ({limit}); lower the voxel \
                     resolution (each halving divides the fragments by about 4)",
                    self.device.limits().max_storage_buffer_binding_size >> 20,
                    r = grids[0].resolution
                )));
            }
            log::info!("voxels: {count} fragments counted before the first frame");
            let capacity = fragments::capacity(self.device, count)?;
            let f = crate::gpu::checked(self.device, "voxel fragments", || {
                Fragments::new(self.device, &grids, capacity)
            })?;
            f.set_regions(self.queue, &all, &[]);
            count = self.voxelize(&f)?;
            grown = Some(f);
        }
        let f = grown.as_ref().unwrap_or(fragments);
        let mut built = false;
        for _ in 0..ROUNDS {
            volume.bind_fragments(self.device, f);
            let pools = self.build(f, volume.as_ref())?;
            if !volume.needs_growth(&pools) {
                // A first guess far above the count gives the room back (and builds again,
                // so that the counters hold this build's counts).
                if volume.shrink(self.device, &pools)? {
                    log::info!(
                        "voxels: {} occupied voxels counted before the first frame; the pools \
                         shrink to them",
                        pools[0]
                    );
                    continue;
                }
                built = true;
                break;
            }
            log::info!(
                "voxels: {count} fragments and {} occupied voxels counted before the first \
                 frame; sizing the pools",
                pools[0]
            );
            volume.grow(self.device, &pools)?;
        }
        volume.bind_fragments(self.device, f);
        Ok((grown, built))
    }

    /// Voxelizes the static geometry and the static points into `fragments`, waited for: the
    /// fragments made, counted past the capacity.
    fn voxelize(&self, fragments: &Fragments) -> Result<u64> {
        let mut timer = GpuTimer::disabled(self.queue);
        let mut encoder = self.device.create_command_encoder(&Default::default());
        fragments.record_clear(&mut encoder);
        for k in 0..fragments.grids.len() {
            let voxelize =
                self.voxelize
                    .bind(self.device, self.scene, self.triangles, fragments, k);
            let splat = (self.scene.static_points > 0).then(|| {
                self.splat
                    .bind(self.device, self.scene, fragments, k, Geometry::Static)
            });
            let spans = self
                .triangles
                .spans(&fragments.grids[k], &Region::all(&fragments.grids[k]));
            fragments.set_spans(self.queue, k, Geometry::Static, &spans);
            self.voxelize
                .record(&mut encoder, self.triangles, &spans, &voxelize, &mut timer);
            self.splat.record(&mut encoder, splat.as_ref(), &mut timer);
        }
        fragments.record_mark(&mut encoder);
        Ok(self.read(encoder, &[(&fragments.count, 1)])?[0] as u64)
    }

    /// Builds `volume` from `fragments`, waited for: its pool counters.
    fn build(
        &self,
        fragments: &Fragments,
        volume: &dyn VoxelStructure,
    ) -> Result<[u32; POOL_COUNTERS]> {
        let mut timer = GpuTimer::disabled(self.queue);
        let mut encoder = self.device.create_command_encoder(&Default::default());
        volume.record_build(self.device, &mut encoder, fragments, &mut timer);
        let words = self.read(encoder, &[(volume.pool_counter(), POOL_COUNTERS)])?;
        let mut pools = [0u32; POOL_COUNTERS];
        pools.copy_from_slice(&words);
        Ok(pools)
    }

    /// Submits `encoder` with a copy of the first words of each source, and waits for them.
    fn read(
        &self,
        mut encoder: wgpu::CommandEncoder,
        sources: &[(&wgpu::Buffer, usize)],
    ) -> Result<Vec<u32>> {
        let words: usize = sources.iter().map(|s| s.1).sum();
        let read = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("voxel count readback"),
            size: 4 * words as u64,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let mut at = 0;
        for &(buffer, n) in sources {
            encoder.copy_buffer_to_buffer(buffer, 0, &read, at, 4 * n as u64);
            at += 4 * n as u64;
        }
        self.queue.submit([encoder.finish()]);
        let bytes = readback::read_buffer(self.device, &read)?;
        Ok(bytemuck::cast_slice(&bytes).to_vec())
    }
}
