//! A scene file's `[settings]` table: parsed here so that every front end (the CLI, a viewer,
//! an application) shares one parser and one list of keys.

use crate::options::{
    ConeSet, DIRECTIONS, FrameParams, IndirectShading, MAX_BOUNCES, RendererOptions, ShadowFilter,
    Tonemap, UNLIMITED_BOUNCES, ViewMode, VoxelKind,
};
use crate::{Error, Result};
use serde::Deserialize;

/// The `[settings]` keys of a scene file. Every key is optional; a key that is present
/// overrides the default (and is overridden in turn by a front end's own flags). Unknown keys
/// are an error that names them.
#[derive(Clone, Debug, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneSettings {
    /// `RendererOptions::shadow_map_size`.
    pub shadow_map_size: Option<u32>,
    /// `RendererOptions::max_texture_size`.
    pub max_texture_size: Option<u32>,
    /// `RendererOptions::default_light`.
    pub default_light: Option<bool>,
    /// `RendererOptions::voxels`: "dense" or "octree".
    pub voxels: Option<String>,
    /// `RendererOptions::voxel_resolution`.
    pub voxel_resolution: Option<u32>,
    /// `RendererOptions::anisotropic`.
    pub anisotropic: Option<bool>,
    /// `RendererOptions::gather_axes`.
    pub gather_axes: Option<u32>,
    /// `RendererOptions::cones`: "6x60", "7x45" or "9x45".
    pub cones: Option<String>,
    /// `RendererOptions::ndf_mips`.
    pub ndf_mips: Option<bool>,
    /// `RendererOptions::shadow_filter`: "pcf" or "vsm-esm".
    pub shadow_filter: Option<String>,
    /// `RendererOptions::indirect`: "cones" or "leaves".
    pub indirect: Option<String>,
    /// `RendererOptions::bounces`: a number, "direct" (0) or "unlimited".
    pub bounces: Option<BouncesValue>,
    /// `RendererOptions::ao_radius`, metres.
    pub ao_radius: Option<f32>,
    /// `RendererOptions::ao_lambda`.
    pub ao_lambda: Option<f32>,
    /// `RendererOptions::step_factor`.
    pub step_factor: Option<f32>,
    /// `RendererOptions::origin_offset`, voxels.
    pub origin_offset: Option<f32>,
    /// `RendererOptions::max_distance`, metres.
    pub max_distance: Option<f32>,
    /// `RendererOptions::half_resolution`.
    pub half_resolution: Option<bool>,
    /// `RendererOptions::cone_shadows`.
    pub cone_shadows: Option<bool>,
    /// `RendererOptions::progressive` (and with it `bounces = "unlimited"`).
    pub progressive: Option<bool>,
    /// `RendererOptions::voxel_update_interval`, frames.
    pub voxel_update_interval: Option<u32>,
    /// `FrameParams::exposure`, stops.
    pub exposure: Option<f32>,
    /// `FrameParams::tonemap`: "aces", "neutral" or "clamp".
    pub tonemap: Option<String>,
    /// `FrameParams::view`: "final", "albedo", "normal", "direct", "ao", "indirect",
    /// "voxel-albedo", "voxel-opacity", "voxel-radiance" or "voxel-nodes".
    pub view: Option<String>,
    /// `FrameParams::background`, linear radiance.
    pub background: Option<[f32; 3]>,
    /// `FrameParams::shadow_softness`, texels.
    pub shadow_softness: Option<f32>,
    /// `FrameParams::debug_level`.
    pub voxel_level: Option<u32>,
    /// `FrameParams::debug_direction`: "+x", "-x", "+y", "-y", "+z" or "-z".
    pub voxel_dir: Option<String>,
}

/// A bounce count as a scene file writes it.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(untagged)]
pub enum BouncesValue {
    /// 0..=8.
    Count(u32),
    /// "direct" or "unlimited".
    Word(String),
}

impl SceneSettings {
    /// Parses a `[settings]` table; errors name the key.
    pub fn from_table(table: &toml::Table) -> Result<Self> {
        let parse = |t: toml::Table| t.try_into::<SceneSettings>();
        parse(table.clone()).map_err(|e| {
            // serde names unknown keys but not the key of a wrongly typed value: find it.
            let key = table.iter().find(|(k, v)| {
                let mut one = toml::Table::new();
                one.insert((*k).clone(), (*v).clone());
                parse(one).is_err()
            });
            match key {
                Some((k, _)) if !e.message().contains("unknown field") => {
                    Error::Setting(format!("[settings] {k}: {}", e.message()))
                }
                _ => Error::Setting(format!("[settings]: {}", e.message())),
            }
        })
    }

    /// Applies the keys that are present, checking each value's form (ranges are checked by
    /// `RendererOptions::validate` and `FrameParams::validate`).
    pub fn apply(&self, o: &mut RendererOptions, f: &mut FrameParams) -> Result<()> {
        macro_rules! set {
            ($dst:expr, $src:expr) => {
                if let Some(v) = $src {
                    $dst = v;
                }
            };
        }
        set!(o.shadow_map_size, self.shadow_map_size);
        set!(o.max_texture_size, self.max_texture_size);
        set!(o.default_light, self.default_light);
        if let Some(v) = &self.voxels {
            o.voxels = VoxelKind::parse(v)?;
        }
        set!(o.voxel_resolution, self.voxel_resolution);
        set!(o.anisotropic, self.anisotropic);
        set!(o.ndf_mips, self.ndf_mips);
        set!(o.gather_axes, self.gather_axes);
        if let Some(c) = &self.cones {
            o.cones = parse_cones(c)?;
        }
        if let Some(i) = &self.indirect {
            o.indirect = IndirectShading::parse(i)?;
        }
        if let Some(f) = &self.shadow_filter {
            o.shadow_filter = ShadowFilter::parse(f)?;
        }
        if let Some(b) = &self.bounces {
            o.bounces = match b {
                BouncesValue::Count(n) => check_bounces(*n)?,
                BouncesValue::Word(w) => parse_bounces(w)?,
            };
        }
        if self.ao_radius.is_some() {
            o.ao_radius = self.ao_radius;
        }
        set!(o.ao_lambda, self.ao_lambda);
        set!(o.step_factor, self.step_factor);
        set!(o.origin_offset, self.origin_offset);
        if self.max_distance.is_some() {
            o.max_distance = self.max_distance;
        }
        set!(o.half_resolution, self.half_resolution);
        set!(o.cone_shadows, self.cone_shadows);
        if let Some(p) = self.progressive {
            o.progressive = p;
            if p {
                o.bounces = UNLIMITED_BOUNCES;
            }
        }
        set!(o.voxel_update_interval, self.voxel_update_interval);
        set!(f.exposure, self.exposure);
        if let Some(t) = &self.tonemap {
            f.tonemap = Tonemap::parse(t)?;
        }
        if let Some(v) = &self.view {
            f.view = ViewMode::parse(v)?;
        }
        set!(f.background, self.background);
        set!(f.shadow_softness, self.shadow_softness);
        set!(f.debug_level, self.voxel_level);
        if let Some(d) = &self.voxel_dir {
            f.debug_direction = parse_direction(d)?;
        }
        Ok(())
    }
}

/// "6x60", "7x45" or "9x45".
pub fn parse_cones(s: &str) -> Result<ConeSet> {
    ConeSet::parse(s)
        .ok_or_else(|| Error::Setting(format!("'{s}' is not a cone set (6x60, 7x45, 9x45)")))
}

/// A bounce count: "0".."8", "direct" or "unlimited" (also "inf").
pub fn parse_bounces(s: &str) -> Result<u32> {
    match s {
        "unlimited" | "inf" => Ok(UNLIMITED_BOUNCES),
        "direct" => Ok(0),
        _ => check_bounces(s.parse().map_err(|_| {
            Error::Setting(format!("'{s}' is not 0..={MAX_BOUNCES} or 'unlimited'"))
        })?),
    }
}

fn check_bounces(n: u32) -> Result<u32> {
    if n > MAX_BOUNCES {
        return Err(Error::Setting(format!(
            "{n} bounces: use 0..={MAX_BOUNCES} or 'unlimited'"
        )));
    }
    Ok(n)
}

/// "+x", "-x", "+y", "-y", "+z" or "-z" (any case) as a directional-chain index.
pub fn parse_direction(s: &str) -> Result<u32> {
    DIRECTIONS
        .iter()
        .position(|d| d.eq_ignore_ascii_case(s))
        .map(|i| i as u32)
        .ok_or_else(|| Error::Setting(format!("'{s}' is not a direction (+x, -x, +y, -y, +z, -z)")))
}

#[cfg(test)]
mod tests {
    use super::*;
    use voxgi_scene::Camera;

    fn parse(text: &str) -> Result<(RendererOptions, FrameParams)> {
        let table: toml::Table = toml::from_str(text).expect("valid TOML");
        let mut o = RendererOptions::default();
        let mut f = FrameParams::new(Camera::look_at(glam::Vec3::Z, glam::Vec3::ZERO, 45.0));
        SceneSettings::from_table(&table)?.apply(&mut o, &mut f)?;
        Ok((o, f))
    }

    #[test]
    fn keys_reach_options_and_frame_params() {
        let (o, f) = parse(
            "voxel_resolution = 64\nbounces = \"unlimited\"\ncones = \"9x45\"\n\
             half_resolution = true\nexposure = -1.5\ntonemap = \"clamp\"\n\
             view = \"voxel-opacity\"\nvoxel_dir = \"-Z\"\nao_radius = 2",
        )
        .unwrap();
        assert_eq!(o.voxel_resolution, 64);
        assert_eq!(o.bounces, UNLIMITED_BOUNCES);
        assert_eq!(o.cones, ConeSet::Nine45);
        assert!(o.half_resolution);
        assert_eq!(o.ao_radius, Some(2.0));
        assert_eq!(f.exposure, -1.5);
        assert_eq!(f.tonemap, Tonemap::Clamp);
        assert_eq!(f.view, ViewMode::VoxelOpacity);
        assert_eq!(f.debug_direction, 5);
        // Keys left out keep their defaults.
        assert_eq!(
            o.shadow_map_size,
            RendererOptions::default().shadow_map_size
        );
    }

    #[test]
    fn unknown_keys_and_bad_values_are_named() {
        let e = parse("voxel_resolutoin = 64").unwrap_err().to_string();
        assert!(e.contains("voxel_resolutoin"), "{e}");
        let e = parse("bounces = 9").unwrap_err().to_string();
        assert!(e.contains("9 bounces"), "{e}");
        let e = parse("tonemap = \"filmic\"").unwrap_err().to_string();
        assert!(e.contains("filmic"), "{e}");
        let e = parse("anisotropic = 3").unwrap_err().to_string();
        assert!(e.contains("anisotropic"), "{e}");
    }
}
