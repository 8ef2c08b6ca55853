//! Point preparation: the attributes a point cloud needs for rendering (normals, regions of
//! influence, disc radii), estimated where the file gave none.

use crate::pointcloud::{self, Neighbours};
use crate::{Aabb, PointCloud, Scene};
use glam::Vec3;
use std::borrow::Cow;
use web_time::{Duration, Instant};

/// `prepare_points` when a point cloud lacks any attribute, on a copy of the scene (borrowed
/// scenes that need nothing are not copied). voxgi's renderer and path tracer both call it, so
/// both see the same points.
pub fn complete_point_attributes(scene: &mut Cow<'_, Scene>) {
    if scene.point_clouds.iter().any(needs_preparation) {
        prepare_points(scene.to_mut());
    }
}

/// How long `prepare_points` took for each attribute, summed over the clouds.
#[derive(Clone, Copy, Debug, Default)]
pub struct PointPreparation {
    /// Points whose attributes were estimated.
    pub points: usize,
    /// Finding each point's nearest neighbours (once for all the attributes).
    pub neighbours: Duration,
    /// Normal estimation (PCA over 16 neighbours).
    pub normals: Duration,
    /// Regions of influence (8 neighbours).
    pub regions: Duration,
    /// Disc radii (8 neighbours).
    pub radii: Duration,
}

/// Fills in normals (k = 16), regions of influence and disc radii (k = 8) of point clouds that
/// lack them, as voxgi's `Renderer::new` does (call it first to time it, or to keep the result for
/// several renderers). Normals face the cloud's local origin when that lies outside the
/// cloud's bounds (scanners put the sensor there), else the default camera.
pub fn prepare_points(scene: &mut Scene) -> PointPreparation {
    let mut timing = PointPreparation::default();
    let camera = scene.default_camera().position;
    for pc in &mut scene.point_clouds {
        let t = prepare_cloud(pc, camera);
        timing.points += t.points;
        timing.neighbours += t.neighbours;
        timing.normals += t.normals;
        timing.regions += t.regions;
        timing.radii += t.radii;
    }
    timing
}

/// Neighbours each estimate reads: normals by PCA over 16, regions and radii from 8.
pub const NORMAL_NEIGHBOURS: usize = 16;
pub const REGION_NEIGHBOURS: usize = 8;
pub const RADIUS_NEIGHBOURS: usize = 8;

/// Whether `prepare_cloud` has anything to estimate.
pub fn needs_preparation(pc: &PointCloud) -> bool {
    !pc.positions.is_empty()
        && (pc.normals.is_empty() || pc.radii.is_empty() || pc.regions.is_empty())
}

/// `prepare_points` for one cloud, `camera` the scene's default camera's position (where
/// normals face when the cloud's origin lies inside it): nothing when it has every attribute.
pub fn prepare_cloud(pc: &mut PointCloud, camera: Vec3) -> PointPreparation {
    if !needs_preparation(pc) {
        return PointPreparation::default();
    }
    // As many as the renderer's surface spread reads, so that a cloud prepared here and one
    // given to `Renderer::set_points` (one search for both) take the same neighbours when
    // several lie at the same distance (points on a grid).
    let t = Instant::now();
    let nb = Neighbours::find(&pc.positions, pointcloud::SPREAD_NEIGHBOURS);
    let neighbours = t.elapsed();
    let mut timing = prepare_cloud_with(pc, camera, &nb);
    timing.neighbours = neighbours;
    timing
}

/// `prepare_cloud` from neighbours already found (`pointcloud::SPREAD_NEIGHBOURS` of them,
/// as `prepare_cloud` finds).
pub fn prepare_cloud_with(pc: &mut PointCloud, camera: Vec3, nb: &Neighbours) -> PointPreparation {
    let mut timing = PointPreparation::default();
    if !needs_preparation(pc) {
        return timing;
    }
    let start = Instant::now();
    let mut local = Aabb::EMPTY;
    for &p in &pc.positions {
        local.grow(p);
    }
    let origin_outside = (0..3).any(|a| local.min[a] > 0.0 || local.max[a] < 0.0);
    // `estimate_normals` takes the viewpoint in world space.
    let viewpoint = if origin_outside {
        pc.transform.transform_point3(Vec3::ZERO)
    } else {
        camera
    };
    let what: Vec<&str> = [
        (pc.normals.is_empty(), "normals"),
        (pc.radii.is_empty(), "radii"),
        (pc.regions.is_empty(), "regions of influence"),
    ]
    .into_iter()
    .filter_map(|(missing, name)| missing.then_some(name))
    .collect();
    let what = what.join(", ");
    timing.points += pc.positions.len();
    let t = Instant::now();
    pointcloud::estimate_normals_from(pc, nb, NORMAL_NEIGHBOURS, viewpoint);
    timing.normals += t.elapsed();
    // Regions first: they take the file's radii, not estimated ones.
    let t = Instant::now();
    pointcloud::estimate_regions_from(pc, nb, REGION_NEIGHBOURS);
    timing.regions += t.elapsed();
    let t = Instant::now();
    pointcloud::estimate_radii_from(pc, nb, RADIUS_NEIGHBOURS);
    timing.radii += t.elapsed();
    log::info!(
        "point cloud '{}': estimated {what} of {} points in {:.2} s (normals facing {})",
        pc.name,
        pc.positions.len(),
        start.elapsed().as_secs_f64(),
        if origin_outside {
            "the cloud's origin"
        } else {
            "the default camera"
        }
    );
    timing
}
