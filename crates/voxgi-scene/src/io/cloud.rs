//! `.cloud`: the binary surface-sample format of Salm's thesis (section 5.2).
//!
//! Layout, little-endian, no padding:
//!
//! ```text
//! i32 count
//! count × { f32 position[3]; f32 ndf[3]; u8 albedo_srgb[3] }   // 27 bytes per record
//! ```
//!
//! Positions and NDFs are right-handed, +Y up. The NDF vector's direction is the mean normal; we
//! keep only its direction (a zero NDF has none and is an error). Albedo is sRGB-encoded and is
//! decoded to linear on load and re-encoded on write.

use crate::{PointCloud, Result, Scene, SceneError, limits, srgb_to_linear};
use glam::{Mat4, Vec3};
use std::path::Path;

/// Bytes per record: 6 floats and 3 bytes.
pub const RECORD_SIZE: usize = 27;

pub fn load(path: &Path) -> Result<Scene> {
    let bytes = super::source::read(path).map_err(|e| SceneError::load(path, e))?;
    let pc = parse(&bytes).map_err(|reason| SceneError::load(path, reason))?;
    let mut pc = pc;
    pc.name = stem(path);
    Ok(Scene {
        name: stem(path),
        point_clouds: vec![pc],
        ..Default::default()
    })
}

fn stem(path: &Path) -> String {
    path.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "cloud".into())
}

/// Parses the bytes of a `.cloud` file; the error says what is wrong (without the file name).
pub fn parse(bytes: &[u8]) -> std::result::Result<PointCloud, String> {
    if bytes.len() < 4 {
        return Err(format!(
            "file is {} bytes, too short for the 4-byte sample count",
            bytes.len()
        ));
    }
    let count = i32::from_le_bytes(bytes[0..4].try_into().unwrap());
    if count < 0 {
        return Err(format!("negative sample count {count}"));
    }
    let count = count as usize;
    if count > limits::MAX_ELEMENTS {
        return Err(format!(
            "sample count {count} exceeds the limit of {}",
            limits::MAX_ELEMENTS
        ));
    }
    let expected = 4 + RECORD_SIZE as u64 * count as u64;
    if bytes.len() as u64 != expected {
        return Err(format!(
            "size mismatch: expected {expected} bytes for {count} samples (4 + 27 × {count}), file has {} bytes",
            bytes.len()
        ));
    }
    let f = |b: &[u8], i: usize| f32::from_le_bytes(b[i * 4..i * 4 + 4].try_into().unwrap());
    let mut pc = PointCloud {
        positions: Vec::with_capacity(count),
        colors: Vec::with_capacity(count),
        normals: Vec::with_capacity(count),
        transform: Mat4::IDENTITY,
        ..Default::default()
    };
    for (i, rec) in bytes[4..].chunks_exact(RECORD_SIZE).enumerate() {
        let p = Vec3::new(f(rec, 0), f(rec, 1), f(rec, 2));
        let ndf = Vec3::new(f(rec, 3), f(rec, 4), f(rec, 5));
        if !p.is_finite() {
            return Err(format!("record {i}: non-finite position {p}"));
        }
        let Some(n) = ndf.is_finite().then(|| ndf.try_normalize()).flatten() else {
            return Err(format!(
                "record {i}: NDF {ndf} has no direction (zero or non-finite)"
            ));
        };
        pc.positions.push(p);
        pc.normals.push(n);
        pc.colors
            .push([rec[24], rec[25], rec[26]].map(|c| srgb_to_linear(c as f32 / 255.0)));
    }
    Ok(pc)
}

/// Writes a point cloud as `.cloud`. Normals become the NDF (+Y where the cloud has none), colours
/// are sRGB-encoded and rounded to 8 bits. The cloud's transform is not stored.
pub fn write(path: &Path, pc: &PointCloud) -> Result<()> {
    let n = pc.positions.len();
    let count = i32::try_from(n)
        .map_err(|_| SceneError::load(path, format!("{n} points do not fit a .cloud file")))?;
    let mut out = Vec::with_capacity(4 + RECORD_SIZE * n);
    out.extend_from_slice(&count.to_le_bytes());
    for i in 0..n {
        let nrm = pc.normals.get(i).copied().unwrap_or(Vec3::Y);
        let c = pc.colors.get(i).copied().unwrap_or([0.8; 3]);
        for v in pc.positions[i].to_array().into_iter().chain(nrm.to_array()) {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out.extend(c.map(linear_to_srgb8));
    }
    super::atomic::replace_with(path, |w| std::io::Write::write_all(w, &out))
        .map_err(|e| SceneError::load(path, e))
}

/// Inverse of [`srgb_to_linear`], quantised to 8 bits.
pub fn linear_to_srgb8(c: f32) -> u8 {
    let c = c.clamp(0.0, 1.0);
    let s = if c <= 0.003_130_8 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0).round() as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb8_round_trips_every_byte() {
        for b in 0..=255u8 {
            assert_eq!(linear_to_srgb8(srgb_to_linear(b as f32 / 255.0)), b);
        }
    }
}
