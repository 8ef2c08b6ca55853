//! Turning emissive quads from mesh files, and flat rectangular patches of emissive points,
//! into area lights.
//!
//! OBJ and PLY have no lights; scenes such as the Cornell box model their lamp as an emissive
//! quad, and point-sampled scenes as emissive samples (seed 004 §4.2). The renderer's direct
//! lighting only sees [`Light`]s, so a quad that is exactly a parallelogram, or a flat, filled
//! rectangle of points that emit alike, becomes a rectangular area light whose visible surface
//! is the original geometry (`Instance::light`, `PointCloud::light`). Anything else that emits
//! stays emissive geometry, which lights the scene only through indirect (voxel) light.

use crate::{AreaShape, Light, LightKind, PointCloud, Scene};
use glam::{DVec2, Vec3};

/// Relative tolerance for edge lengths and areas (float noise in files written with ~6 digits).
const REL_TOL: f32 = 1e-3;
/// Welding distance relative to the mesh's bounding-box diagonal.
const WELD_TOL: f32 = 1e-5;

/// Promotes every emissive parallelogram instance to an area light; see the module docs. A
/// static instance whose emissive mesh is a few flat faces (a box-shaped lamp) is split: each
/// face that is a parallelogram becomes a light of its own, the rest stays geometry.
pub fn promote_emissive_quads(scene: &mut Scene) {
    let mut not_quads = 0usize;
    for ii in 0..scene.instances.len() {
        let inst = &scene.instances[ii];
        if inst.light.is_some() {
            continue;
        }
        let Some(mesh) = scene.meshes.get(inst.mesh) else {
            continue;
        };
        let Some(mat) = scene.materials.get(mesh.material) else {
            continue;
        };
        // A textured emitter does not emit uniformly, so it cannot be one constant-radiance light.
        if !mat.is_emissive() || mat.emissive_texture.is_some() {
            not_quads += mat.is_emissive() as usize;
            continue;
        }
        let world: Vec<Vec3> = mesh
            .indices
            .iter()
            .map(|&i| inst.transform.transform_point3(mesh.positions[i as usize]))
            .collect();
        if let Some(q) = parallelogram(&world) {
            let light = quad_light(inst.name.clone(), q, mat.emissive);
            scene.lights.push(light);
            scene.instances[ii].light = Some(scene.lights.len() - 1);
            continue;
        }
        // Splitting adds instances that an animation of this one would not move.
        let faces = if inst.dynamic {
            Vec::new()
        } else {
            parallelogram_faces(&world)
        };
        if faces.is_empty() {
            not_quads += 1;
            continue;
        }
        split_into_lights(scene, ii, &faces);
    }
    if not_quads > 0 {
        log::info!(
            "{}: {not_quads} emissive mesh(es) are neither quads nor boxes of quads; they light \
             the scene only through indirect light",
            scene.name
        );
    }
}

fn quad_light(name: String, q: Parallelogram, emissive: [f32; 3]) -> Light {
    Light {
        name,
        kind: LightKind::Area {
            shape: AreaShape::Rect { u: q.u, v: q.v },
        },
        color: emissive,
        intensity: 1.0,
        position: q.center,
        direction: q.normal,
        range: None,
        cast_shadows: true,
    }
}

/// The flat faces of a triangle soup (three world-space points per triangle) that are
/// parallelograms: each face's triangles (indices into the soup's triangles) and its shape.
/// Empty when the soup has more than `MAX_FACES` planes (a curved surface).
fn parallelogram_faces(tri_points: &[Vec3]) -> Vec<(Vec<usize>, Parallelogram)> {
    let tol = REL_TOL * diagonal(tri_points);
    // Each triangle's plane: its normal and offset (degenerate triangles have none).
    let planes = tri_points.chunks_exact(3).enumerate().filter_map(|(t, c)| {
        let n = (c[1] - c[0]).cross(c[2] - c[0]).try_normalize()?;
        Some((t, (n, n.dot(c[0]))))
    });
    let Some(planes) = group_alike(planes, |a: &(Vec3, f32), b| {
        a.0.dot(b.0) >= FACE_COS && (a.1 - b.1).abs() <= tol
    }) else {
        return Vec::new();
    };
    planes
        .into_iter()
        .filter_map(|(_, tris)| {
            let pts: Vec<Vec3> = tris
                .iter()
                .flat_map(|&t| tri_points[3 * t..3 * t + 3].iter().copied())
                .collect();
            parallelogram(&pts).map(|q| (tris, q))
        })
        .collect()
}

/// Splits instance `ii` into one instance per face in `faces` (each showing a new area light)
/// and one for the triangles left over. The first face keeps the instance's index.
fn split_into_lights(scene: &mut Scene, ii: usize, faces: &[(Vec<usize>, Parallelogram)]) {
    let inst = scene.instances[ii].clone();
    let mesh = scene.meshes[inst.mesh].clone();
    let emissive = scene.materials[mesh.material].emissive;
    let mut taken = vec![false; mesh.indices.len() / 3];
    for (k, (tris, q)) in faces.iter().enumerate() {
        let name = format!("{} (emitter {})", inst.name, k + 1);
        scene.meshes.push(sub_mesh(&mesh, tris, &name));
        scene.lights.push(quad_light(name.clone(), *q, emissive));
        let face = crate::Instance {
            name,
            mesh: scene.meshes.len() - 1,
            light: Some(scene.lights.len() - 1),
            ..inst.clone()
        };
        if k == 0 {
            scene.instances[ii] = face;
        } else {
            scene.instances.push(face);
        }
        tris.iter().for_each(|&t| taken[t] = true);
    }
    let rest: Vec<usize> = (0..taken.len()).filter(|&t| !taken[t]).collect();
    if !rest.is_empty() {
        scene.meshes.push(sub_mesh(&mesh, &rest, &mesh.name));
        scene.instances.push(crate::Instance {
            mesh: scene.meshes.len() - 1,
            ..inst
        });
    }
    log::info!(
        "{}: instance '{}' emits from {} flat quads; each is now an area light",
        scene.name,
        scene.instances[ii].name,
        faces.len()
    );
}

/// The triangles `tris` of `mesh`, with only the vertices they use.
fn sub_mesh(mesh: &crate::Mesh, tris: &[usize], name: &str) -> crate::Mesh {
    let mut remap = std::collections::HashMap::new();
    let mut out = crate::Mesh {
        name: name.to_string(),
        material: mesh.material,
        ..Default::default()
    };
    for &t in tris {
        for &i in &mesh.indices[3 * t..3 * t + 3] {
            let next = remap.len() as u32;
            let j = *remap.entry(i).or_insert_with(|| {
                out.positions.push(mesh.positions[i as usize]);
                out.normals.push(mesh.normals[i as usize]);
                if let Some(uv) = mesh.uvs.get(i as usize) {
                    out.uvs.push(*uv);
                }
                next
            });
            out.indices.push(j);
        }
    }
    out
}

/// The most flat faces one emissive cloud is split into: a box's six and a few more. More
/// normal directions than this mean a curved emitter, which stays geometry.
const MAX_FACES: usize = 8;
/// Fewer points than a 4 x 4 grid are too coarse a sampling to say where a rectangle ends.
const MIN_FACE_POINTS: usize = 16;
/// Points whose normals lie within about 2° of each other can be one face's.
const FACE_COS: f32 = 0.9994;
/// A face's convex hull must cover this fraction of its bounding rectangle (a disc covers π/4).
const HULL_FILL: f64 = 0.9;
/// The filled-rectangle test's cells are at least this many point spacings wide, so that even
/// randomly placed samples leave none empty (e^-16 per cell).
const CELL_SPACINGS: f64 = 4.0;

/// Splits off every flat, filled rectangle of points emitting alike into its own cloud showing
/// a new rectangular area light; see the module docs. Only points with normals (which say which
/// way a face shines) are considered; the rest of a cloud stays as it was.
pub fn promote_emissive_points(scene: &mut Scene) {
    let mut added = Vec::new();
    for ci in 0..scene.point_clouds.len() {
        let pc = &scene.point_clouds[ci];
        if pc.light.is_some() || pc.emission.is_empty() {
            continue;
        }
        if pc.normals.is_empty() {
            log::info!(
                "point cloud '{}': its emissive points have no normals, so which way they shine \
                 is unknown; they light the scene only through indirect light",
                pc.name
            );
            continue;
        }
        let faces = match emissive_faces(pc) {
            Ok(f) => f,
            Err(why) => {
                log::info!(
                    "point cloud '{}': its emissive points {why}; they light the scene only \
                     through indirect light",
                    pc.name
                );
                continue;
            }
        };
        if faces.is_empty() {
            continue;
        }
        let mut taken = vec![false; pc.positions.len()];
        for (k, face) in faces.iter().enumerate() {
            let mut part = subset(pc, &face.points);
            part.name = if faces.len() == 1 {
                format!("{} (emitter)", pc.name)
            } else {
                format!("{} (emitter {})", pc.name, k + 1)
            };
            // The points become the light's surface: on its plane, facing its way.
            for (p, n) in part.positions.iter_mut().zip(&mut part.normals) {
                *p -= face.normal * (face.normal.dot(*p) - face.offset);
                *n = face.normal;
            }
            face.points.iter().for_each(|&i| taken[i] = true);
            let rect = Parallelogram {
                center: face.center,
                u: face.u,
                v: face.v,
                normal: face.normal,
            };
            let light = quad_light(part.name.clone(), rect, pc.emission[face.points[0]])
                .transformed(pc.transform);
            log::info!(
                "point cloud '{}': {} emissive points form a {:.3} m² rectangle; they are now \
                 area light '{}'",
                pc.name,
                face.points.len(),
                light.area(),
                light.name
            );
            scene.lights.push(light);
            part.light = Some(scene.lights.len() - 1);
            added.push(part);
        }
        let rest: Vec<usize> = (0..taken.len()).filter(|&i| !taken[i]).collect();
        scene.point_clouds[ci] = subset(&scene.point_clouds[ci], &rest);
    }
    scene.point_clouds.retain(|pc| !pc.positions.is_empty());
    scene.point_clouds.extend(added);
}

/// The points `idx` of `pc`, with their attributes.
fn subset(pc: &PointCloud, idx: &[usize]) -> PointCloud {
    fn pick<T: Copy>(v: &[T], idx: &[usize]) -> Vec<T> {
        if v.is_empty() {
            Vec::new()
        } else {
            idx.iter().map(|&i| v[i]).collect()
        }
    }
    PointCloud {
        name: pc.name.clone(),
        positions: pick(&pc.positions, idx),
        colors: pick(&pc.colors, idx),
        normals: pick(&pc.normals, idx),
        radii: pick(&pc.radii, idx),
        regions: pick(&pc.regions, idx),
        emission: pick(&pc.emission, idx),
        transform: pc.transform,
        dynamic: pc.dynamic,
        light: pc.light,
    }
}

/// A flat rectangle of emissive points, in the cloud's local coordinates.
#[derive(Clone, Debug)]
pub struct PointFace {
    /// Indices of its points in the cloud.
    pub points: Vec<usize>,
    /// Unit normal (the way the points face) and the plane's offset: `normal · x = offset`.
    pub normal: Vec3,
    pub offset: f32,
    /// The rectangle: corners at `center ± u ± v`, half a point spacing beyond the outermost
    /// points, so that each point stands for an equal share of it.
    pub center: Vec3,
    pub u: Vec3,
    pub v: Vec3,
}

/// The cloud's emissive points as flat rectangles: grouped by emission, normal and plane, each
/// group tested as a filled rectangle. Groups failing the test are left out (they stay
/// geometry); an error when the points are not a few flat faces at all.
pub fn emissive_faces(pc: &PointCloud) -> Result<Vec<PointFace>, String> {
    let plane_tol = REL_TOL * diagonal(&pc.positions);
    let unit_normal = |i: usize| pc.normals[i].normalize_or_zero();
    // The emitting points with a normal, grouped by emission and direction.
    let emitting = pc.emission.iter().enumerate().filter_map(|(i, &e)| {
        let n = unit_normal(i);
        (e != [0.0; 3] && n != Vec3::ZERO).then_some((i, (e, n)))
    });
    let alike = |a: &([f32; 3], Vec3), b: &([f32; 3], Vec3)| {
        let m = a.0.iter().chain(&b.0).fold(0.0f32, |m, v| m.max(*v));
        (0..3).all(|k| (a.0[k] - b.0[k]).abs() <= REL_TOL * m) && a.1.dot(b.1) >= FACE_COS
    };
    let groups = group_alike(emitting, alike).ok_or_else(|| {
        format!("face more than {MAX_FACES} directions or emit unevenly (not a few flat faces)")
    })?;
    let mut faces = Vec::new();
    for (_, members) in groups {
        let normal = members
            .iter()
            .map(|&i| unit_normal(i))
            .sum::<Vec3>()
            .normalize();
        // Parallel faces (the two lamps of one cloud, one above the other) part by their offset.
        let mut by_offset: Vec<(f32, usize)> = members
            .iter()
            .map(|&i| (normal.dot(pc.positions[i]), i))
            .collect();
        by_offset.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut start = 0;
        for k in 1..=by_offset.len() {
            if k == by_offset.len() || by_offset[k].0 - by_offset[k - 1].0 > plane_tol {
                let part = &by_offset[start..k];
                let spread = part[part.len() - 1].0 - part[0].0;
                if spread <= 2.0 * plane_tol {
                    let idx: Vec<usize> = part.iter().map(|p| p.1).collect();
                    if let Some(f) = rectangle_face(pc, idx, normal) {
                        faces.push(f);
                    }
                }
                start = k;
            }
        }
    }
    Ok(faces)
}

/// The filled rectangle the points `idx` (on one plane with unit `normal`) cover, if they do.
fn rectangle_face(pc: &PointCloud, idx: Vec<usize>, normal: Vec3) -> Option<PointFace> {
    if idx.len() < MIN_FACE_POINTS {
        return None;
    }
    let n = normal.as_dvec3();
    let (t, b) = n.any_orthonormal_pair();
    let origin = pc.positions[idx[0]].as_dvec3();
    let flat: Vec<DVec2> = idx
        .iter()
        .map(|&i| {
            let d = pc.positions[i].as_dvec3() - origin;
            DVec2::new(d.dot(t), d.dot(b))
        })
        .collect();
    let hull = convex_hull(&flat);
    if hull.len() < 3 {
        return None;
    }
    let hull_area = polygon_area(&hull);
    // The smallest rectangle around a convex polygon has a side along one of its edges.
    let mut best: Option<(f64, DVec2, DVec2, DVec2)> = None; // (area, axis, lo, hi)
    for k in 0..hull.len() {
        let axis = (hull[(k + 1) % hull.len()] - hull[k]).normalize_or_zero();
        if axis == DVec2::ZERO {
            continue;
        }
        let perp = axis.perp();
        let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
        for &p in &hull {
            let q = DVec2::new(p.dot(axis), p.dot(perp));
            lo = lo.min(q);
            hi = hi.max(q);
        }
        let area = (hi - lo).x * (hi - lo).y;
        if best.is_none_or(|b| area < b.0) {
            best = Some((area, axis, lo, hi));
        }
    }
    let (area, axis, lo, hi) = best?;
    if area.is_nan() || area <= 0.0 || hull_area < HULL_FILL * area {
        return None;
    }
    // The spacing s for which the m points each stand for s² of the rectangle grown by s/2 on
    // every side: (w + s)(h + s) = m s², exact for a grid of m points.
    let (w, h, m) = ((hi - lo).x, (hi - lo).y, idx.len() as f64);
    let s = ((w + h) + ((w + h).powi(2) + 4.0 * (m - 1.0) * w * h).sqrt()) / (2.0 * (m - 1.0));
    let (lo, hi) = (lo - DVec2::splat(0.5 * s), hi + DVec2::splat(0.5 * s));
    // Filled: no cell of a coarse grid over the rectangle is empty.
    let size = hi - lo;
    let cells = (size / (CELL_SPACINGS * s)).floor().max(DVec2::ONE);
    let (cu, cv) = (cells.x as usize, cells.y as usize);
    if cu.saturating_mul(cv) > 1 << 20 {
        return None;
    }
    let mut seen = vec![false; cu * cv];
    let perp = axis.perp();
    for &p in &flat {
        let q = (DVec2::new(p.dot(axis), p.dot(perp)) - lo) / size * cells;
        let (x, y) = (q.x as usize, q.y as usize);
        seen[y.min(cv - 1) * cu + x.min(cu - 1)] = true;
    }
    if seen.iter().any(|s| !s) {
        return None;
    }
    let offset = idx
        .iter()
        .map(|&i| n.dot(pc.positions[i].as_dvec3()))
        .sum::<f64>()
        / m;
    let c2 = 0.5 * (lo + hi);
    let (axis3, perp3) = (t * axis.x + b * axis.y, t * perp.x + b * perp.y);
    let at = |q: DVec2| origin + axis3 * q.x + perp3 * q.y;
    let center = at(c2);
    // Onto the plane through the points' mean offset.
    let center = center - n * (n.dot(center) - offset);
    Some(PointFace {
        points: idx,
        normal,
        offset: offset as f32,
        center: center.as_vec3(),
        u: (axis3 * 0.5 * size.x).as_vec3(),
        v: (perp3 * 0.5 * size.y).as_vec3(),
    })
}

/// Sorts `items` (index, key) into groups whose first key each later key is `alike` to, in
/// order; `None` when that needs more than `MAX_FACES` groups.
fn group_alike<K>(
    items: impl Iterator<Item = (usize, K)>,
    alike: impl Fn(&K, &K) -> bool,
) -> Option<Vec<(K, Vec<usize>)>> {
    let mut groups: Vec<(K, Vec<usize>)> = Vec::new();
    for (i, key) in items {
        match groups.iter().position(|g| alike(&g.0, &key)) {
            Some(g) => groups[g].1.push(i),
            None if groups.len() < MAX_FACES => groups.push((key, vec![i])),
            None => return None,
        }
    }
    Some(groups)
}

/// The length of the diagonal of the points' bounds (infinite when there are none).
fn diagonal(points: &[Vec3]) -> f32 {
    let mut b = crate::Aabb::EMPTY;
    points.iter().for_each(|&p| b.grow(p));
    b.size().length()
}

/// Convex hull, counter-clockwise, without collinear points (Andrew's monotone chain).
fn convex_hull(points: &[DVec2]) -> Vec<DVec2> {
    let mut p = points.to_vec();
    p.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    p.dedup();
    if p.len() < 3 {
        return p;
    }
    let cross = |o: DVec2, a: DVec2, b: DVec2| (a - o).perp_dot(b - o);
    let mut hull: Vec<DVec2> = Vec::with_capacity(2 * p.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &DVec2>> = if pass == 0 {
            Box::new(p.iter())
        } else {
            Box::new(p.iter().rev())
        };
        for &q in iter {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], q) <= 0.0
            {
                hull.pop();
            }
            hull.push(q);
        }
        hull.pop();
    }
    hull
}

/// Area of a simple polygon (shoelace).
fn polygon_area(poly: &[DVec2]) -> f64 {
    let n = poly.len();
    0.5 * (0..n)
        .map(|k| poly[k].perp_dot(poly[(k + 1) % n]))
        .sum::<f64>()
        .abs()
}

/// A parallelogram found in a triangle soup: corners at `center ± u ± v`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Parallelogram {
    pub center: Vec3,
    pub u: Vec3,
    pub v: Vec3,
    /// Unit geometric normal of the (counter-clockwise) triangles.
    pub normal: Vec3,
}

/// `corners` holds three points per triangle (world space). Returns the parallelogram the
/// triangles cover exactly, or `None`.
pub fn parallelogram(tri_points: &[Vec3]) -> Option<Parallelogram> {
    if tri_points.len() < 6 || !tri_points.len().is_multiple_of(3) {
        return None;
    }
    let size = diagonal(tri_points);
    if !(size > 0.0 && size.is_finite()) {
        return None;
    }
    let weld = WELD_TOL * size;
    let mut corners: Vec<Vec3> = Vec::with_capacity(4);
    for &p in tri_points {
        if !corners.iter().any(|c| c.distance(p) <= weld) {
            if corners.len() == 4 {
                return None;
            }
            corners.push(p);
        }
    }
    if corners.len() != 4 {
        return None;
    }
    // Common normal: sum of the triangles' area vectors; every triangle must agree with it.
    let mut sum = Vec3::ZERO;
    let mut area = 0.0;
    let crosses: Vec<Vec3> = tri_points
        .chunks_exact(3)
        .map(|t| (t[1] - t[0]).cross(t[2] - t[0]))
        .collect();
    for c in &crosses {
        sum += *c;
        area += 0.5 * c.length();
    }
    let normal = sum.try_normalize()?;
    for c in &crosses {
        let len = c.length();
        // Degenerate slivers have no direction; others must face the same way.
        if len > REL_TOL * size * size && c.dot(normal) < len * (1.0 - REL_TOL) {
            return None;
        }
    }
    // Find the corner opposite corners[0]: then a, b, c, d go around the parallelogram.
    let a = corners[0];
    for opp in 1..4 {
        let others: Vec<usize> = (1..4).filter(|&k| k != opp).collect();
        let (b, c, d) = (corners[others[0]], corners[opp], corners[others[1]]);
        let (ab, dc, ad, bc) = (b - a, c - d, d - a, c - b);
        let edges_equal = (ab - dc).length() <= REL_TOL * ab.length()
            && (ad - bc).length() <= REL_TOL * ad.length();
        if !edges_equal {
            continue;
        }
        let para_area = ab.cross(ad).length();
        let coplanar = ab.cross(ad).normalize_or_zero().dot(normal).abs() >= 1.0 - REL_TOL;
        if para_area > 0.0 && coplanar && (area - para_area).abs() <= REL_TOL * para_area {
            return Some(Parallelogram {
                center: (a + b + c + d) * 0.25,
                u: ab * 0.5,
                v: ad * 0.5,
                normal,
            });
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Material, Mesh, compute_normals};
    use glam::Mat4;

    fn quad_scene(indices: Vec<u32>, positions: Vec<Vec3>) -> Scene {
        let mut s = Scene::default();
        let mesh = Mesh {
            name: "lamp".into(),
            normals: compute_normals(&positions, &indices),
            positions,
            indices,
            ..Default::default()
        };
        let mut m = Material::diffuse("lamp", [0.5; 3]);
        m.emissive = [17.0, 12.0, 4.0];
        s.add_mesh(mesh, m, Mat4::from_translation(Vec3::new(0.0, 2.0, 0.0)));
        s
    }

    fn square() -> Vec<Vec3> {
        vec![
            Vec3::new(-0.5, 0.0, -0.25),
            Vec3::new(0.5, 0.0, -0.25),
            Vec3::new(0.5, 0.0, 0.25),
            Vec3::new(-0.5, 0.0, 0.25),
        ]
    }

    #[test]
    fn ccw_from_below_faces_down() {
        // Seen from below (-Y), 0,1,2 run counter-clockwise: (1-0) x (2-0) = X x Z-ish = -Y.
        let mut s = quad_scene(vec![0, 1, 2, 0, 2, 3], square());
        promote_emissive_quads(&mut s);
        assert_eq!(s.lights.len(), 1);
        assert_eq!(s.instances[0].light, Some(0));
        let l = &s.lights[0];
        assert!((l.direction - Vec3::NEG_Y).length() < 1e-6);
        assert!((l.position - Vec3::new(0.0, 2.0, 0.0)).length() < 1e-6);
        assert!(
            (l.area() - 0.5).abs() < 1e-6,
            "1 m x 0.5 m, area {}",
            l.area()
        );
        assert_eq!(l.color, [17.0, 12.0, 4.0]);
        assert!(s.validate().is_ok());
    }

    #[test]
    fn opposite_winding_faces_up() {
        let mut s = quad_scene(vec![0, 2, 1, 0, 3, 2], square());
        promote_emissive_quads(&mut s);
        assert_eq!(s.lights.len(), 1);
        assert!((s.lights[0].direction - Vec3::Y).length() < 1e-6);
    }

    #[test]
    fn an_emissive_box_becomes_six_quad_lights() {
        let mut cube = crate::builtin::cube([0.5; 3]);
        cube.materials[0].emissive = [3.0; 3];
        cube.instances[0].transform = Mat4::from_scale(Vec3::new(0.5, 0.04, 0.5));
        let mut moving = cube.clone();
        promote_emissive_quads(&mut cube);
        assert_eq!(cube.lights.len(), 6);
        assert_eq!(cube.instances.len(), 6, "no triangles are left over");
        let mut areas: Vec<f32> = cube.lights.iter().map(Light::area).collect();
        areas.sort_by(f32::total_cmp);
        // Four 0.5 x 0.04 sides, then the 0.5 x 0.5 top and bottom.
        for (a, want) in areas.iter().zip([0.02, 0.02, 0.02, 0.02, 0.25, 0.25]) {
            assert!((a - want).abs() < 1e-5, "{areas:?}");
        }
        for inst in &cube.instances {
            let l = &cube.lights[inst.light.expect("every face is a light")];
            // Outwards: the face's centre lies along its normal from the box's centre.
            assert!(l.direction.dot(l.position) > 0.0);
            assert_eq!(cube.meshes[inst.mesh].indices.len(), 6);
        }
        assert!(cube.validate().is_ok());
        // An animated (dynamic) box is not split: the animation moves one instance.
        moving.instances[0].dynamic = true;
        promote_emissive_quads(&mut moving);
        assert!(moving.lights.is_empty());
    }

    /// A grid of `nx` x `nz` points, `h` apart, in the plane y = 0 around the origin, facing
    /// `normal`, all emitting `e`.
    fn point_panel(nx: usize, nz: usize, h: f32, normal: Vec3, e: [f32; 3]) -> PointCloud {
        let mut pc = PointCloud {
            name: "panel".into(),
            transform: Mat4::IDENTITY,
            ..Default::default()
        };
        for i in 0..nx {
            for k in 0..nz {
                let x = (i as f32 - 0.5 * (nx - 1) as f32) * h;
                let z = (k as f32 - 0.5 * (nz - 1) as f32) * h;
                pc.positions.push(Vec3::new(x, 0.0, z));
                pc.normals.push(normal);
                pc.colors.push([0.5; 3]);
                pc.emission.push(e);
            }
        }
        pc
    }

    fn scene_of(clouds: Vec<PointCloud>) -> Scene {
        Scene {
            point_clouds: clouds,
            ..Default::default()
        }
    }

    #[test]
    fn a_grid_of_emissive_points_becomes_the_rectangle_it_samples() {
        // 20 x 10 points 5 cm apart each stand for a 5 cm square: a 1 m x 0.5 m panel, placed
        // 2 m up by the cloud's transform.
        let mut pc = point_panel(20, 10, 0.05, Vec3::NEG_Y, [4.0, 3.0, 2.0]);
        pc.transform = Mat4::from_translation(Vec3::new(0.0, 2.0, 0.0));
        let mut s = scene_of(vec![pc]);
        promote_emissive_points(&mut s);
        assert_eq!(s.lights.len(), 1);
        assert_eq!(s.point_clouds.len(), 1);
        assert_eq!(s.point_clouds[0].light, Some(0));
        assert_eq!(s.point_clouds[0].positions.len(), 200);
        let l = &s.lights[0];
        // The spacing is solved exactly for a grid; f64 arithmetic on f32 positions.
        assert!((l.area() - 0.5).abs() < 1e-5, "area {}", l.area());
        assert!((l.position - Vec3::new(0.0, 2.0, 0.0)).length() < 1e-5);
        assert!((l.direction - Vec3::NEG_Y).length() < 1e-6);
        assert_eq!(l.color, [4.0, 3.0, 2.0]);
        let LightKind::Area {
            shape: AreaShape::Rect { u, v },
        } = l.kind
        else {
            panic!("not a rectangle");
        };
        let mut edges = [2.0 * u.length(), 2.0 * v.length()];
        edges.sort_by(f32::total_cmp);
        assert!((edges[0] - 0.5).abs() < 1e-5 && (edges[1] - 1.0).abs() < 1e-5);
        assert!(s.validate().is_ok());
    }

    #[test]
    fn only_the_emissive_points_of_a_cloud_become_a_light() {
        let mut pc = point_panel(8, 8, 0.1, Vec3::Y, [2.0; 3]);
        let dark = point_panel(5, 5, 0.1, Vec3::Y, [0.0; 3]);
        for (i, p) in dark.positions.iter().enumerate() {
            pc.positions.push(*p + Vec3::new(3.0, 1.0, 0.0));
            pc.normals.push(dark.normals[i]);
            pc.colors.push([0.2; 3]);
            pc.emission.push([0.0; 3]);
        }
        let mut s = scene_of(vec![pc]);
        promote_emissive_points(&mut s);
        assert_eq!(s.lights.len(), 1);
        let (geometry, lamp) = (&s.point_clouds[0], &s.point_clouds[1]);
        assert_eq!((geometry.light, geometry.positions.len()), (None, 25));
        assert!(geometry.emission.iter().all(|e| *e == [0.0; 3]));
        assert_eq!((lamp.light, lamp.positions.len()), (Some(0), 64));
        assert!((s.lights[0].area() - 0.64).abs() < 1e-5);
    }

    #[test]
    fn an_emissive_box_of_points_becomes_six_lights_covering_its_faces() {
        let mut cube = crate::builtin::cube([0.5; 3]);
        cube.materials[0].emissive = [3.0; 3];
        // A 1 m cube sampled every 5 cm: 20 x 20 points a face, each standing for 25 cm².
        let mut s = crate::pointcloud::sample_surfaces(&cube, 0.05);
        promote_emissive_points(&mut s);
        assert_eq!(s.lights.len(), 6);
        assert_eq!(s.point_clouds.len(), 6);
        for (pc, l) in s.point_clouds.iter().zip(&s.lights) {
            let li = pc.light.expect("every face is a light");
            assert!((s.lights[li].area() - 1.0).abs() < 1e-3, "{}", l.area());
            // Each face shines outwards: away from the cube's centre.
            assert!(s.lights[li].direction.dot(s.lights[li].position) > 0.49);
        }
    }

    #[test]
    fn randomly_placed_emissive_points_fill_their_rectangle() {
        // 4000 points uniformly at random in a 2 m x 1 m rectangle. The hull reaches nearly to
        // the edges, and the padding that makes each point stand for an equal share adds about
        // half a spacing (sqrt(2 m² / 4000) = 2.2 cm) on each side.
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        let mut pc = point_panel(1, 1, 1.0, Vec3::Y, [1.0; 3]);
        pc.positions.clear();
        pc.normals.clear();
        pc.colors.clear();
        pc.emission.clear();
        for _ in 0..4000 {
            pc.positions
                .push(Vec3::new(2.0 * next() - 1.0, 0.0, next() - 0.5));
            pc.normals.push(Vec3::Y);
            pc.colors.push([0.5; 3]);
            pc.emission.push([1.0; 3]);
        }
        let mut s = scene_of(vec![pc]);
        promote_emissive_points(&mut s);
        assert_eq!(s.lights.len(), 1);
        let h = (2.0f32 / 4000.0).sqrt();
        let area = s.lights[0].area();
        // Gaps at the edges shrink the hull by about an edge / 4000 (0.05 %): 0.5 % below.
        assert!(
            area > 0.995 * 2.0 && area < 1.01 * (2.0 + h) * (1.0 + h),
            "{area}"
        );
    }

    #[test]
    fn emissive_points_that_are_no_filled_rectangle_stay_geometry() {
        let e = [1.0; 3];
        // A disc, an L, two panels side by side, a panel with a hole, a bent panel of more
        // directions than a box has, and a panel without normals.
        let keep = |pc: &PointCloud, f: &dyn Fn(Vec3) -> bool| {
            let mut out = pc.clone();
            let idx: Vec<usize> = (0..pc.positions.len())
                .filter(|&i| f(pc.positions[i]))
                .collect();
            out = subset(&out, &idx);
            out
        };
        let big = point_panel(40, 40, 0.05, Vec3::Y, e);
        let disc = keep(&big, &|p| p.length() < 1.0);
        let ell = keep(&big, &|p| p.x < 0.0 || p.z < 0.0);
        let two = keep(&big, &|p| p.x.abs() > 0.4);
        let holed = keep(&big, &|p| p.x.abs() > 0.3 || p.z.abs() > 0.3);
        let mut bent = big.clone();
        for (p, n) in bent.positions.iter_mut().zip(&mut bent.normals) {
            let a = p.x * 0.8;
            *p = Vec3::new(a.sin(), 1.0 - a.cos(), p.z);
            *n = Vec3::new(-a.sin(), a.cos(), 0.0);
        }
        let mut bare = big.clone();
        bare.normals.clear();
        for pc in [disc, ell, two, holed, bent, bare] {
            let n = pc.positions.len();
            let mut s = scene_of(vec![pc]);
            promote_emissive_points(&mut s);
            assert!(s.lights.is_empty());
            assert_eq!(s.point_clouds.len(), 1);
            assert_eq!(s.point_clouds[0].positions.len(), n);
            assert_eq!(s.point_clouds[0].light, None);
        }
    }

    #[test]
    fn non_quads_stay_geometry() {
        // A single triangle, a quad missing a triangle's worth of area (overlapping triangles),
        // and a trapezoid.
        let tri = quad_scene(vec![0, 1, 2], square());
        let overlap = quad_scene(vec![0, 1, 2, 0, 1, 2, 0, 2, 3], square());
        let mut trap = square();
        trap[2].x = 0.3;
        let trap = quad_scene(vec![0, 1, 2, 0, 2, 3], trap);
        for mut s in [tri, overlap, trap] {
            promote_emissive_quads(&mut s);
            assert!(s.lights.is_empty());
            assert_eq!(s.instances[0].light, None);
        }
    }
}
