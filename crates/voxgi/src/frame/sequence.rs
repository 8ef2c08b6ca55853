//! The per-frame sample sequence of temporal accumulation: where in its pixel each frame's
//! camera samples (jitter) and how far each frame turns the diffuse cone bundle. Frame 0 of a
//! history samples the pixel centre with the unturned bundle, so a single frame (or a renderer
//! with temporal accumulation off) is the still it always was.

/// The radical inverse of `i` in `base` (the Halton sequence's coordinate): 0, 1/2, 1/4, 3/4…
/// for base 2. Low-discrepancy: any run of consecutive indices covers [0, 1) evenly.
pub fn radical_inverse(mut i: u32, base: u32) -> f32 {
    let inv = 1.0 / base as f64;
    let mut f = inv;
    let mut r = 0.0f64;
    while i > 0 {
        r += f * (i % base) as f64;
        i /= base;
        f *= inv;
    }
    r as f32
}

/// Frames after which the sequence repeats: the jitter's Halton points and the cone turns are
/// those of a 2-3 Halton set of this many points, which covers the pixel finely enough that
/// longer runs add nothing an average of them does not already hold.
pub const PERIOD: u32 = 1024;

/// Sub-pixel offset of frame `k`'s camera, in pixels, in [-0.5, 0.5)²: the Halton (2, 3)
/// point k, shifted by half a pixel modulo one so that point 0 is the pixel centre. A shift
/// modulo 1 keeps the set's low discrepancy.
pub fn jitter(k: u32) -> [f32; 2] {
    let k = k % PERIOD;
    let wrap = |x: f32| (x + 0.5).fract() - 0.5;
    [wrap(radical_inverse(k, 2)), wrap(radical_inverse(k, 3))]
}

/// How far frame `k` turns the diffuse cones (`shaders/shared/cone.wgsl`, `diffuse_cone`;
/// the gather wraps them round): about the normal and in zenith, each as a fraction of a
/// cone's cell, so that the frames sweep the whole cells. The base-5 and base-7 radical
/// inverses, bases prime to the jitter's so that the turn and the sample position do not
/// repeat together.
pub fn cone_turn(k: u32) -> [f32; 2] {
    [
        radical_inverse(k % PERIOD, 5),
        radical_inverse(k % PERIOD, 7),
    ]
}

/// Frame `k`'s points on an area light, in the unit square (`lighting::atlas::light_point`):
/// points 4k to 4k + 3 of the R2 sequence (the additive recurrence on the plastic number's
/// powers), low-discrepancy in two dimensions at every length and unrelated to the jitter's
/// Halton points, so that where a pixel samples and which light point it sees do not repeat
/// together.
pub fn light_points(k: u32) -> [glam::Vec2; 4] {
    // The plastic number g (g^3 = g + 1) and the recurrence's steps 1/g, 1/g^2.
    const G: f64 = 1.324_717_957_244_746;
    std::array::from_fn(|i| {
        let n = (k % PERIOD) as f64 * 4.0 + i as f64;
        let f = |a: f64| (0.5 + n * a).fract() as f32;
        glam::Vec2::new(f(1.0 / G), f(1.0 / (G * G)))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_zero_is_the_still() {
        assert_eq!(jitter(0), [0.0, 0.0]);
        assert_eq!(cone_turn(0), [0.0, 0.0]);
    }

    #[test]
    fn jitter_stays_inside_the_pixel_and_covers_it() {
        // 16 points of a (0,2)-style set: every quarter of the pixel holds 4 of them (within
        // one: Halton's 2-3 points are stratified by 2^a 3^b boxes, not exactly by quarters).
        let mut quarters = [0u32; 4];
        for k in 0..16 {
            let [x, y] = jitter(k);
            assert!(
                (-0.5..0.5).contains(&x) && (-0.5..0.5).contains(&y),
                "{k}: {x} {y}"
            );
            quarters[(x >= 0.0) as usize + 2 * (y >= 0.0) as usize] += 1;
        }
        for q in quarters {
            assert!((3..=5).contains(&q), "{quarters:?}");
        }
        // The mean offset of a long run is the pixel centre (the image is not shifted).
        let n = 1024;
        let (mut sx, mut sy) = (0.0f64, 0.0f64);
        for k in 0..n {
            let [x, y] = jitter(k);
            sx += x as f64;
            sy += y as f64;
        }
        assert!((sx / n as f64).abs() < 2e-3 && (sy / n as f64).abs() < 2e-3);
    }

    #[test]
    fn cone_turns_spread_over_the_cell() {
        // 25 = 5² and 49 = 7²: the base-5 radical inverse of 0..25 is exactly the multiples
        // of 1/25, the base-7 one of 0..49 those of 1/49.
        for (axis, n) in [(0, 25), (1, 49)] {
            let mut t: Vec<f32> = (0..n).map(|k| cone_turn(k)[axis]).collect();
            t.sort_by(f32::total_cmp);
            for (i, v) in t.iter().enumerate() {
                assert!((v - i as f32 / n as f32).abs() < 1e-6, "{t:?}");
            }
        }
    }

    #[test]
    fn light_points_cover_the_light_evenly() {
        // 64 frames, 256 points: each cell of an 8x8 grid over the unit square expects 4. The
        // R2 sequence's discrepancy keeps every cell within 4 ± 3 (random points would leave
        // about one cell in ten empty).
        let mut cells = [0u32; 64];
        for k in 0..64 {
            for p in light_points(k) {
                assert!(
                    (0.0..1.0).contains(&p.x) && (0.0..1.0).contains(&p.y),
                    "{p}"
                );
                cells[(p.y * 8.0) as usize * 8 + (p.x * 8.0) as usize] += 1;
            }
        }
        assert!(cells.iter().all(|&c| (1..=7).contains(&c)), "{cells:?}");
        // Each frame's four points are four different points of the light.
        let f = light_points(5);
        for i in 0..4 {
            for j in i + 1..4 {
                assert!(f[i].distance(f[j]) > 0.05, "{f:?}");
            }
        }
    }
}
