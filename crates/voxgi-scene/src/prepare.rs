//! Point preparation: the attributes a point cloud needs for rendering (normals, regions of
//! influence, disc radii), estimated where the file gave none.

use crate::pointcloud::{self, Neighbours};
use crate::{Aabb, PointCloud, Scene};
use glam::{Mat4, Vec3};
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
    /// The surface spread (`pointcloud::surface_spread`, 24 neighbours) of `PointsAhead`,
    /// ahead or, where a degenerate neighbourhood's normal waited for the viewpoint, in
    /// `finish`; at upload the renderer computes it as it writes the surfels.
    pub spread: Duration,
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
    if !needs_preparation(pc) {
        return PointPreparation::default();
    }
    let start = Instant::now();
    let what = missing(pc);
    let unoriented = pc.normals.is_empty();
    let mut timing = estimate_unoriented(pc, nb);
    let t = Instant::now();
    let facing = if unoriented {
        orient(pc, camera)
    } else {
        "the file's"
    };
    timing.normals += t.elapsed();
    log::info!(
        "point cloud '{}': estimated {what} of {} points in {:.2} s (normals facing {facing})",
        pc.name,
        pc.positions.len(),
        start.elapsed().as_secs_f64(),
    );
    timing
}

/// A cloud's attributes estimated ahead of the frame that shows it, on any thread (the
/// renderer's point sequences do it on the thread that reads the file): everything but the
/// normals' orientation, which depends on where the cloud will be (`PointsAhead::finish`).
/// Its parts are read, not written: the neighbours belong to these points.
#[derive(Clone, Debug, Default)]
pub struct PointsAhead {
    /// The points, their missing attributes filled; estimated normals with either sign.
    points: PointCloud,
    /// Their `pointcloud::SPREAD_NEIGHBOURS` nearest neighbours.
    neighbours: Neighbours,
    /// Their surface spread (`pointcloud::surface_spread`, in the cloud's units), which does
    /// not depend on which way the normals face; empty without normals, `None` where a
    /// normal is still to be made (a degenerate neighbourhood's, which faces the viewpoint).
    spread: Option<Vec<f32>>,
    /// What the estimation took.
    timing: PointPreparation,
    /// The normals were estimated and still face either way.
    unoriented: bool,
}

impl PointsAhead {
    /// Finds `points`' neighbours and estimates the attributes they lack, as
    /// `prepare_cloud` does, except the normals' orientation.
    pub fn new(mut points: PointCloud) -> Self {
        // `Renderer::set_points` names a point that is not finite; nothing to estimate.
        if !points.positions.iter().all(|p| p.is_finite()) {
            return Self::unestimated(points);
        }
        let t = Instant::now();
        let neighbours = Neighbours::find(&points.positions, pointcloud::SPREAD_NEIGHBOURS);
        let found = t.elapsed();
        let unoriented = !points.positions.is_empty() && points.normals.is_empty();
        let mut timing = if needs_preparation(&points) {
            estimate_unoriented(&mut points, &neighbours)
        } else {
            PointPreparation::default()
        };
        timing.neighbours = found;
        let t = Instant::now();
        // A degenerate neighbourhood's estimate is zero until `finish` turns it to the
        // viewpoint; a file's normals stay as they are.
        let waits = unoriented && points.normals.contains(&Vec3::ZERO);
        let spread = (!waits).then(|| {
            pointcloud::surface_spread_from(&points, &neighbours, pointcloud::SPREAD_NEIGHBOURS)
        });
        timing.spread = t.elapsed();
        PointsAhead {
            points,
            neighbours,
            spread,
            timing,
            unoriented,
        }
    }

    /// `points` as they are, estimation skipped (a frame nobody will show, or points that are
    /// not all finite).
    pub(crate) fn unestimated(points: PointCloud) -> Self {
        PointsAhead {
            points,
            ..Default::default()
        }
    }

    /// The points, their missing attributes filled (estimated normals with either sign).
    pub fn points(&self) -> &PointCloud {
        &self.points
    }

    /// What the estimation took.
    pub fn timing(&self) -> PointPreparation {
        self.timing
    }

    /// The points' `pointcloud::SPREAD_NEIGHBOURS` nearest neighbours.
    pub fn neighbours(&self) -> &Neighbours {
        &self.neighbours
    }

    /// Turns the estimated normals as `prepare_cloud` would for the cloud placed by
    /// `transform` (`camera`: the scene's default camera's position), and returns the
    /// points, their surface spread and the estimation's times (the orientation's among the
    /// normals').
    pub fn finish(
        mut self,
        transform: Mat4,
        camera: Vec3,
    ) -> (PointCloud, Vec<f32>, PointPreparation) {
        self.points.transform = transform;
        if self.unoriented {
            let t = Instant::now();
            orient(&mut self.points, camera);
            self.timing.normals += t.elapsed();
        }
        let spread = self.spread.unwrap_or_else(|| {
            let t = Instant::now();
            let spread = pointcloud::surface_spread_from(
                &self.points,
                &self.neighbours,
                pointcloud::SPREAD_NEIGHBOURS,
            );
            self.timing.spread += t.elapsed();
            spread
        });
        (self.points, spread, self.timing)
    }
}

/// The attributes `pc` lacks, named for the log.
fn missing(pc: &PointCloud) -> String {
    let what: Vec<&str> = [
        (pc.normals.is_empty(), "normals"),
        (pc.radii.is_empty(), "radii"),
        (pc.regions.is_empty(), "regions of influence"),
    ]
    .into_iter()
    .filter_map(|(missing, name)| missing.then_some(name))
    .collect();
    what.join(", ")
}

/// Fills the attributes `pc` lacks from its neighbours, the normals with either sign.
fn estimate_unoriented(pc: &mut PointCloud, nb: &Neighbours) -> PointPreparation {
    let mut timing = PointPreparation {
        points: pc.positions.len(),
        ..Default::default()
    };
    let t = Instant::now();
    pointcloud::fit_normals_from(pc, nb, NORMAL_NEIGHBOURS);
    timing.normals += t.elapsed();
    // Regions first: they take the file's radii, not estimated ones.
    let t = Instant::now();
    pointcloud::estimate_regions_from(pc, nb, REGION_NEIGHBOURS);
    timing.regions += t.elapsed();
    let t = Instant::now();
    pointcloud::estimate_radii_from(pc, nb, RADIUS_NEIGHBOURS);
    timing.radii += t.elapsed();
    timing
}

/// Turns estimated normals to face the cloud's local origin when that lies outside the
/// cloud's bounds (scanners put the sensor there), else `camera`; says which.
fn orient(pc: &mut PointCloud, camera: Vec3) -> &'static str {
    let mut local = Aabb::EMPTY;
    for &p in &pc.positions {
        local.grow(p);
    }
    let origin_outside = (0..3).any(|a| local.min[a] > 0.0 || local.max[a] < 0.0);
    // `orient_normals` takes the viewpoint in world space.
    if origin_outside {
        let origin = pc.transform.transform_point3(Vec3::ZERO);
        pointcloud::orient_normals(pc, origin);
        "the cloud's origin"
    } else {
        pointcloud::orient_normals(pc, camera);
        "the default camera"
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A wavy sheet of points with a row of collinear points beside it (degenerate
    /// neighbourhoods, whose normals face the viewpoint), moved by `offset`.
    fn sheet(offset: Vec3) -> PointCloud {
        let mut positions = Vec::new();
        for i in 0..40 {
            for j in 0..30 {
                let (x, z) = (i as f32 * 0.05, j as f32 * 0.05);
                positions.push(Vec3::new(x, (x * 2.0).sin() * 0.2 + z * 0.1, z) + offset);
            }
        }
        positions.extend((0..20).map(|i| Vec3::new(5.0 + i as f32 * 0.01, 0.0, 0.0) + offset));
        PointCloud {
            positions,
            ..Default::default()
        }
    }

    /// Estimating ahead and finishing later gives what the whole estimation gives (the surface
    /// spread too), to the bit, whichever way the normals turn: to the camera (the cloud's
    /// origin inside its bounds) or to its origin (outside), under a transform that turns the
    /// cloud about; with the sheet's row of collinear points (degenerate neighbourhoods, whose
    /// spread waits for the viewpoint) and without it (the spread computed ahead).
    #[test]
    fn estimating_ahead_equals_estimating_at_once() {
        let transform =
            Mat4::from_rotation_x(2.5) * Mat4::from_translation(Vec3::new(0.3, 1.0, -2.0));
        let camera = Vec3::new(0.5, 4.0, 3.0);
        let offsets = [Vec3::new(-1.0, -0.1, -0.7), Vec3::new(2.0, 1.0, 1.0)];
        for (offset, row) in offsets.into_iter().flat_map(|o| [(o, true), (o, false)]) {
            // The sheet's 40 × 30 points, and its row of 20 after them or not.
            let cloud = || {
                let mut pc = sheet(offset);
                pc.positions.truncate(if row { 1220 } else { 1200 });
                pc
            };
            let mut whole = cloud();
            whole.transform = transform;
            let nb = Neighbours::find(&whole.positions, pointcloud::SPREAD_NEIGHBOURS);
            prepare_cloud_with(&mut whole, camera, &nb);
            let ahead = PointsAhead::new(cloud());
            assert_eq!(
                ahead.spread.is_none(),
                row,
                "the spread waits for the row's normals"
            );
            let ahead_nb = ahead.neighbours().clone();
            let (ahead, spread, timing) = ahead.finish(transform, camera);
            assert_eq!(timing.points, whole.positions.len());
            assert_eq!(ahead.transform, transform);
            assert_eq!(ahead.normals, whole.normals, "offset {offset}, row {row}");
            assert_eq!(ahead.radii, whole.radii);
            assert_eq!(ahead.regions, whole.regions);
            let n = whole.positions.len();
            assert!((0..n).all(|i| ahead_nb.of(i, 24) == nb.of(i, 24)));
            // The spread ahead, from normals facing either way, is the oriented normals'.
            let want = pointcloud::surface_spread_from(&whole, &nb, pointcloud::SPREAD_NEIGHBOURS);
            assert_eq!(spread.len(), n);
            assert_eq!(spread, want, "offset {offset}, row {row}");
            // Every normal faces the viewpoint: the camera while the origin lies inside the
            // cloud's bounds, else the origin.
            let view = if offset.x < 0.0 {
                transform.inverse().transform_point3(camera)
            } else {
                Vec3::ZERO
            };
            for (p, v) in whole.positions.iter().zip(&whole.normals) {
                assert!((v.length() - 1.0).abs() < 1e-5 && v.dot(view - *p) >= 0.0);
            }
        }
    }

    /// A cloud with a point that is not finite is left for `Renderer::set_points` to name.
    #[test]
    fn points_that_are_not_finite_are_not_estimated() {
        let mut pc = sheet(Vec3::ZERO);
        pc.positions[7].y = f32::NAN;
        let ahead = PointsAhead::new(pc);
        assert!(ahead.points.normals.is_empty() && ahead.points.radii.is_empty());
    }
}
