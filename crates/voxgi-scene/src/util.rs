use glam::Vec3;

/// Area-weighted vertex normals for a triangle list. Vertices no triangle touches get +Y.
pub fn compute_normals(positions: &[Vec3], indices: &[u32]) -> Vec<Vec3> {
    let mut n = vec![Vec3::ZERO; positions.len()];
    for t in indices.chunks_exact(3) {
        let [a, b, c] = [t[0] as usize, t[1] as usize, t[2] as usize];
        if a >= positions.len() || b >= positions.len() || c >= positions.len() {
            continue;
        }
        // The cross product's length is twice the area, which gives the weighting for free.
        let f = (positions[b] - positions[a]).cross(positions[c] - positions[a]);
        n[a] += f;
        n[b] += f;
        n[c] += f;
    }
    n.into_iter()
        .map(|v| v.try_normalize().unwrap_or(Vec3::Y))
        .collect()
}

/// The sRGB electro-optical transfer function (IEC 61966-2-1), per channel.
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normals_of_a_ccw_triangle_face_the_viewer() {
        let p = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let n = compute_normals(&p, &[0, 1, 2]);
        assert!(n.iter().all(|v| (*v - Vec3::Z).length() < 1e-6));
    }

    #[test]
    fn srgb_decode_matches_the_standard_at_known_points() {
        assert!((srgb_to_linear(0.0)).abs() < 1e-7);
        assert!((srgb_to_linear(1.0) - 1.0).abs() < 1e-6);
        // 0.5 sRGB is 0.21404 linear (the spec's formula).
        assert!((srgb_to_linear(0.5) - 0.21404).abs() < 1e-4);
    }
}
