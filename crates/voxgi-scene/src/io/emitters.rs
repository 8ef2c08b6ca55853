//! Turning emissive quads from mesh files into area lights.
//!
//! OBJ and PLY have no lights; scenes such as the Cornell box model their lamp as an emissive
//! quad. The renderer's direct lighting only sees [`Light`]s, so a quad that is exactly a
//! parallelogram becomes a rectangular area light whose visible surface is the original mesh
//! (`Instance::light`). Anything else that emits stays emissive geometry, which lights the scene
//! only through indirect (voxel) light.

use crate::{AreaShape, Light, LightKind, Scene};
use glam::Vec3;

/// Relative tolerance for edge lengths and areas (float noise in files written with ~6 digits).
const REL_TOL: f32 = 1e-3;
/// Welding distance relative to the mesh's bounding-box diagonal.
const WELD_TOL: f32 = 1e-5;

/// Promotes every emissive parallelogram instance to an area light; see the module docs.
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
        if !mat.is_emissive() {
            continue;
        }
        let world: Vec<Vec3> = mesh
            .indices
            .iter()
            .map(|&i| inst.transform.transform_point3(mesh.positions[i as usize]))
            .collect();
        // A textured emitter does not emit uniformly, so it cannot be one constant-radiance light.
        let quad = if mat.emissive_texture.is_none() {
            parallelogram(&world)
        } else {
            None
        };
        let Some(q) = quad else {
            not_quads += 1;
            continue;
        };
        let light = Light {
            name: inst.name.clone(),
            kind: LightKind::Area {
                shape: AreaShape::Rect { u: q.u, v: q.v },
            },
            color: mat.emissive,
            intensity: 1.0,
            position: q.center,
            direction: q.normal,
            range: None,
            cast_shadows: true,
        };
        scene.lights.push(light);
        scene.instances[ii].light = Some(scene.lights.len() - 1);
    }
    if not_quads > 0 {
        log::info!(
            "{}: {not_quads} emissive mesh(es) are not single quads; they light the scene only through indirect light",
            scene.name
        );
    }
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
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for &p in tri_points {
        lo = lo.min(p);
        hi = hi.max(p);
    }
    let size = (hi - lo).length();
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
