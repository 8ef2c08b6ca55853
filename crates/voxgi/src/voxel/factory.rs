//! Making a structure of the kind the options name: its pipelines (made once per kind and
//! shared by every structure made after, as a structure is remade when it grows), its pools
//! sized from the scene's estimate and checked against the device's limits.

use super::dense::{DensePipelines, DenseVolume, SLOT_BYTES};
use super::octree::{OctreePipelines, OctreePools, OctreeVolume};
use super::{Filtering, Grid, VoxelKind, Voxels};
use crate::gpu::checked;
use crate::options::RendererOptions;
use crate::{Error, Result};
use std::sync::Arc;

/// The structures' own pipelines, each made when a structure of its kind is first made and
/// shared by every one made after it (a structure is remade whenever it grows).
#[derive(Default)]
pub struct StructurePipelines {
    dense: Option<Arc<DensePipelines>>,
    octree: Option<Arc<OctreePipelines>>,
}

/// The structure `options.voxels` names on `grid`, with pools for as many occupied voxels as
/// the options say, or else a quarter of `fragments` (the scene's fragment estimate on
/// `grid`); `dynamic`: whether the scene has dynamic instances (their updates need the static
/// build kept aside).
pub fn new_volume(
    device: &wgpu::Device,
    pipelines: &mut StructurePipelines,
    options: &RendererOptions,
    grid: Grid,
    fragments: u64,
    dynamic: bool,
) -> Result<Voxels> {
    // Slots: at most one per voxel, usually far fewer than fragments, and the fragment
    // estimate is itself an upper bound. Start at a quarter; the first build's counters grow
    // the pools to the exact count if that is short.
    let wanted = options
        .voxel_capacity
        .unwrap_or(fragments / 4)
        .min((grid.resolution as u64).pow(3));
    match options.voxels {
        VoxelKind::Dense => {
            check_volume_fits(device, &grid)?;
            let slots = slot_capacity(
                device,
                wanted.min(crate::gpu::max_entries(device, SLOT_BYTES)),
            )?;
            let p = match &pipelines.dense {
                Some(p) => p.clone(),
                None => checked(device, "pipeline creation", || DensePipelines::new(device))?,
            };
            pipelines.dense = Some(p.clone());
            let v = checked(device, "voxel volume", || {
                DenseVolume::new(device, &p, grid, filtering(options), slots, dynamic)
            })?;
            Ok(Voxels::Dense(v))
        }
        VoxelKind::Octree => {
            let p = match &pipelines.octree {
                Some(p) => p.clone(),
                None => checked(device, "pipeline creation", || OctreePipelines::new(device))?,
            };
            pipelines.octree = Some(p.clone());
            let l = device.limits();
            let pools = OctreePools::for_leaves(wanted)
                .within(l.max_storage_buffer_binding_size.min(l.max_buffer_size));
            let v = checked(device, "voxel octree", || {
                OctreeVolume::new(device, &p, grid, filtering(options), pools, dynamic)
            })??;
            Ok(Voxels::Octree(v))
        }
    }
}

/// Checks a slot capacity (occupied voxels) against the device's storage-buffer limit.
fn slot_capacity(device: &wgpu::Device, wanted: u64) -> Result<u32> {
    crate::gpu::pool_capacity(device, wanted, SLOT_BYTES, "occupied voxels")
}

/// Checks that the volume's per-voxel buffers fit the device's limits.
fn check_volume_fits(device: &wgpu::Device, grid: &Grid) -> Result<()> {
    let l = device.limits();
    let occupancy = (grid.resolution as u64).pow(3) * 4;
    if occupancy > l.max_storage_buffer_binding_size {
        return Err(Error::Setting(format!(
            "a {r}³ volume needs a {} MiB occupancy buffer, more than this GPU's {} MiB \
             storage-buffer limit; use a voxel resolution of at most {}",
            occupancy >> 20,
            l.max_storage_buffer_binding_size >> 20,
            ((l.max_storage_buffer_binding_size / 4) as f64)
                .cbrt()
                .log2()
                .floor()
                .exp2() as u32,
            r = grid.resolution
        )));
    }
    if grid.resolution > l.max_texture_dimension_3d {
        return Err(Error::Setting(format!(
            "a {}³ volume exceeds this GPU's 3D texture limit of {}",
            grid.resolution, l.max_texture_dimension_3d
        )));
    }
    Ok(())
}

/// How the structure filters its levels.
fn filtering(options: &RendererOptions) -> Filtering {
    Filtering {
        anisotropic: options.anisotropic,
        ndf: options.ndf_mips,
    }
}
