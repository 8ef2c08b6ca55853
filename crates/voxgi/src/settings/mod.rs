//! The one table of settings (DESIGN.md, seam 8). Each setting is declared once, in `SETTINGS`:
//! its key, a label, its help, its domain (type and range or choices), what changing it makes
//! out of date, and where it lives in `RendererOptions` or `FrameParams`. From the table come
//! a scene file's `[settings]` parsing (`SceneSettings`), the command line's flags (named as
//! the keys), the help's defaults, the viewer panel's widgets, the range checks of
//! `RendererOptions::validate` and `FrameParams::validate`, and what `Renderer::set_options`
//! redoes after a change (`changes_between`).

mod table;

pub use table::SETTINGS;

use crate::options::{
    DIRECTIONS, FrameParams, MAX_BOUNCES, RendererOptions, UNLIMITED_BOUNCES, VoxelKind,
};
use crate::{Error, Result};
use voxgi_scene::Camera;

/// One setting: a key of a scene file's `[settings]`, a command-line flag (`--` and the key
/// with dashes), a widget of the viewer.
pub struct Setting {
    /// The key (`voxel_resolution`); the flag is `--voxel-resolution`.
    pub key: &'static str,
    /// A short name for panels ("voxels per side").
    pub label: &'static str,
    /// One or two sentences for help texts.
    pub help: &'static str,
    /// Its type and the values it takes.
    pub domain: Domain,
    /// What changing it makes out of date.
    pub changes: Changes,
    access: Access,
}

/// Where a setting lives.
#[derive(Clone, Copy)]
enum Access {
    /// A creation-time option.
    Options {
        get: fn(&RendererOptions) -> Value,
        set: fn(&mut RendererOptions, Value),
    },
    /// A per-frame parameter.
    Frame {
        get: fn(&FrameParams) -> Value,
        set: fn(&mut FrameParams, Value),
    },
}

/// A setting's type and the values it takes.
#[derive(Clone, Copy, Debug)]
pub enum Domain {
    /// true or false.
    Bool,
    /// An integer in `min..=max`.
    Int {
        /// The least value.
        min: u32,
        /// The largest value.
        max: u32,
    },
    /// A power of two from `min` to the voxel structure's largest resolution.
    Resolution {
        /// The least value.
        min: u32,
    },
    /// A number in `min..=max`.
    Float {
        /// The least value.
        min: f32,
        /// The largest value.
        max: f32,
    },
    /// A positive number, or "auto": the renderer's choice from the volume's size.
    Auto,
    /// One of these names.
    Choice(fn() -> Vec<&'static str>),
    /// 0..=`MAX_BOUNCES`, "direct" (0) or "unlimited".
    Bounces,
    /// Linear RGB, each non-negative.
    Rgb,
}

/// What changing a setting makes out of date, from least to most.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Changes {
    /// Only the frames from the next on (per-frame parameters, the update interval).
    Frame,
    /// Pipelines or targets are made anew; the voxels and their light stay.
    Pipelines,
    /// The light in the voxels is computed again (injection, filtering, bounces); the voxels
    /// stay.
    Lighting,
    /// The voxel structure or the shadow maps are made anew: everything is voxelized and lit
    /// again.
    Voxels,
    /// The uploaded scene: a new `Renderer` is needed.
    Scene,
}

/// A setting's value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Value {
    /// `Domain::Bool`.
    Bool(bool),
    /// `Domain::Int`, `Domain::Resolution`, `Domain::Bounces` (`UNLIMITED_BOUNCES`: unlimited).
    Int(u32),
    /// `Domain::Float`.
    Float(f32),
    /// `Domain::Auto`: `None` is "auto".
    Auto(Option<f32>),
    /// `Domain::Choice`: one of its names.
    Name(&'static str),
    /// `Domain::Rgb`.
    Rgb([f32; 3]),
}

impl std::fmt::Display for Value {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Value::Bool(b) => write!(f, "{b}"),
            Value::Int(UNLIMITED_BOUNCES) => f.write_str("unlimited"),
            Value::Int(n) => write!(f, "{n}"),
            Value::Float(x) | Value::Auto(Some(x)) => write!(f, "{x}"),
            Value::Auto(None) => f.write_str("auto"),
            Value::Name(n) => f.write_str(n),
            Value::Rgb([r, g, b]) => write!(f, "{r},{g},{b}"),
        }
    }
}

impl Setting {
    /// The setting with key `key`.
    pub fn get(key: &str) -> Option<&'static Setting> {
        SETTINGS.iter().find(|s| s.key == key)
    }

    /// The command-line flag without its dashes: the key with dashes for underscores.
    pub fn flag(&self) -> String {
        self.key.replace('_', "-")
    }

    /// Whether it is a per-frame parameter (`FrameParams`) rather than a creation-time option.
    pub fn per_frame(&self) -> bool {
        matches!(self.access, Access::Frame { .. })
    }

    /// Its value in `o` and `f`.
    pub fn value(&self, o: &RendererOptions, f: &FrameParams) -> Value {
        match self.access {
            Access::Options { get, .. } => get(o),
            Access::Frame { get, .. } => get(f),
        }
    }

    /// Its value in `o`, for a creation-time option.
    pub fn option_value(&self, o: &RendererOptions) -> Option<Value> {
        match self.access {
            Access::Options { get, .. } => Some(get(o)),
            Access::Frame { .. } => None,
        }
    }

    /// Sets it in `o` or `f`; `v` must be of its domain (as `parse` and `from_toml` make
    /// them). Ranges are checked by `check`.
    pub fn set(&self, o: &mut RendererOptions, f: &mut FrameParams, v: Value) {
        match self.access {
            Access::Options { set, .. } => set(o, v),
            Access::Frame { set, .. } => set(f, v),
        }
    }

    /// Its default, as help texts print it.
    pub fn default_value(&self) -> Value {
        let camera = Camera::look_at(glam::Vec3::Z, glam::Vec3::ZERO, 45.0);
        self.value(&RendererOptions::default(), &FrameParams::new(camera))
    }

    /// The choices of a `Domain::Choice` setting (empty for the others).
    pub fn choices(&self) -> Vec<&'static str> {
        match self.domain {
            Domain::Choice(names) => names(),
            _ => Vec::new(),
        }
    }

    /// What it takes, for help texts and errors: "true or false", "16..=512 (a power of
    /// two)", "one of pcf, vsm-esm", …
    pub fn describe(&self) -> String {
        match self.domain {
            Domain::Bool => "true or false".into(),
            Domain::Int { min, max } => format!("{min}..={max}"),
            Domain::Resolution { min } => format!(
                "a power of two from {min} (up to {} by structure)",
                VoxelKind::ALL
                    .iter()
                    .map(|k| format!("{} {}", k.name(), k.info().max_resolution))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
            Domain::Float { min, max } => format!("{min}..={max}"),
            Domain::Auto => "a positive number or auto".into(),
            Domain::Choice(names) => format!("one of {}", names().join(", ")),
            Domain::Bounces => format!("0..={MAX_BOUNCES}, direct or unlimited"),
            Domain::Rgb => "r,g,b (linear, non-negative)".into(),
        }
    }

    /// Its value from text (a flag's argument, a widget's text). Ranges are checked by
    /// `check`; this checks the form.
    pub fn parse(&self, s: &str) -> Result<Value> {
        let s = s.trim();
        let bad = || Error::Setting(format!("{}: '{s}' is not {}", self.key, self.describe()));
        let number = || s.parse::<f32>().ok().filter(|x| x.is_finite());
        Ok(match self.domain {
            Domain::Bool => Value::Bool(s.parse().map_err(|_| bad())?),
            Domain::Int { .. } | Domain::Resolution { .. } => {
                Value::Int(s.parse().map_err(|_| bad())?)
            }
            Domain::Float { .. } => Value::Float(number().ok_or_else(bad)?),
            Domain::Auto if s == "auto" => Value::Auto(None),
            Domain::Auto => Value::Auto(Some(number().ok_or_else(bad)?)),
            Domain::Choice(names) => Value::Name(
                names()
                    .into_iter()
                    .find(|n| n.eq_ignore_ascii_case(s))
                    .ok_or_else(bad)?,
            ),
            Domain::Bounces => Value::Int(match s {
                "unlimited" | "inf" => UNLIMITED_BOUNCES,
                "direct" => 0,
                _ => s.parse().map_err(|_| bad())?,
            }),
            Domain::Rgb => {
                let c: Vec<f32> = s
                    .split(',')
                    .map(|c| c.trim().parse::<f32>().map_err(|_| bad()))
                    .collect::<Result<_>>()?;
                Value::Rgb(c.try_into().map_err(|_| bad())?)
            }
        })
    }

    /// `v` as a scene file's `[settings]` writes it: what `from_toml` reads back as `v`.
    pub fn to_toml(&self, v: Value) -> toml::Value {
        match v {
            Value::Bool(b) => toml::Value::Boolean(b),
            Value::Int(UNLIMITED_BOUNCES) if matches!(self.domain, Domain::Bounces) => {
                toml::Value::String("unlimited".into())
            }
            Value::Int(n) => toml::Value::Integer(n.into()),
            Value::Float(x) | Value::Auto(Some(x)) => short(x),
            Value::Auto(None) => toml::Value::String("auto".into()),
            Value::Name(n) => toml::Value::String(n.into()),
            Value::Rgb(c) => toml::Value::Array(c.map(short).into()),
        }
    }

    /// Its value from a scene file's TOML value.
    pub fn from_toml(&self, v: &toml::Value) -> Result<Value> {
        let bad = || {
            Error::Setting(format!(
                "[settings] {}: {} is not {}",
                self.key,
                v,
                self.describe()
            ))
        };
        let float = || match v {
            toml::Value::Float(x) => Some(*x as f32),
            toml::Value::Integer(i) => Some(*i as f32),
            _ => None,
        };
        let int = || match v {
            toml::Value::Integer(i) => u32::try_from(*i).ok(),
            _ => None,
        };
        Ok(match (self.domain, v) {
            (Domain::Bool, toml::Value::Boolean(b)) => Value::Bool(*b),
            (Domain::Int { .. } | Domain::Resolution { .. }, _) => {
                Value::Int(int().ok_or_else(bad)?)
            }
            (Domain::Float { .. }, _) => Value::Float(float().ok_or_else(bad)?),
            (Domain::Auto, toml::Value::String(s)) if s == "auto" => Value::Auto(None),
            (Domain::Auto, _) => Value::Auto(Some(float().ok_or_else(bad)?)),
            (Domain::Choice(_) | Domain::Bounces, toml::Value::String(s)) => {
                self.parse(s).map_err(|_| bad())?
            }
            (Domain::Bounces, _) => Value::Int(int().ok_or_else(bad)?),
            (Domain::Rgb, toml::Value::Array(a)) => {
                let c: Vec<f32> = a
                    .iter()
                    .map(|c| match c {
                        toml::Value::Float(x) => Some(*x as f32),
                        toml::Value::Integer(i) => Some(*i as f32),
                        _ => None,
                    })
                    .collect::<Option<_>>()
                    .ok_or_else(bad)?;
                Value::Rgb(c.try_into().map_err(|_| bad())?)
            }
            _ => return Err(bad()),
        })
    }

    /// Checks `v` against the domain's range; `voxels` is the structure (which bounds the
    /// resolution).
    pub fn check(&self, v: Value, voxels: VoxelKind) -> Result<()> {
        let key = self.key;
        let fail = |m: String| Err(Error::Setting(m));
        match (self.domain, v) {
            (Domain::Int { min, max }, Value::Int(n)) if !(min..=max).contains(&n) => {
                fail(format!("{key} {n} is outside {min}..={max}"))
            }
            (Domain::Resolution { min }, Value::Int(n)) => {
                let top = voxels.info().max_resolution;
                if (min..=top).contains(&n) && n.is_power_of_two() {
                    Ok(())
                } else {
                    fail(format!(
                        "{key} {n} is not a power of two in {min}..={top} (the {} structure)",
                        voxels.name()
                    ))
                }
            }
            (Domain::Float { min, max }, Value::Float(x))
                if !(x.is_finite() && (min..=max).contains(&x)) =>
            {
                fail(format!("{key} {x} is outside {min}..={max}"))
            }
            (Domain::Auto, Value::Auto(Some(x))) if !(x.is_finite() && x > 0.0) => {
                fail(format!("{key} {x} must be a positive number (or auto)"))
            }
            (Domain::Bounces, Value::Int(n)) if n > MAX_BOUNCES && n != UNLIMITED_BOUNCES => {
                fail(format!("{n} bounces: use 0..={MAX_BOUNCES} or unlimited"))
            }
            (Domain::Rgb, Value::Rgb(c)) if !c.iter().all(|c| c.is_finite() && *c >= 0.0) => {
                fail(format!("{key} must be finite and non-negative"))
            }
            _ => Ok(()),
        }
    }
}

/// The most any changed creation-time option makes out of date between `old` and `new`;
/// `None` when no setting differs. Options outside the table (the pools' first capacities)
/// size pools made anew and change nothing in use.
pub fn changes_between(old: &RendererOptions, new: &RendererOptions) -> Option<Changes> {
    SETTINGS
        .iter()
        .filter(|s| s.option_value(old) != s.option_value(new))
        .map(|s| s.changes)
        .max()
}

impl RendererOptions {
    /// Checks every option against its setting's range, and the options that depend on each
    /// other.
    pub fn validate(&self) -> Result<()> {
        for s in SETTINGS {
            if let Some(v) = s.option_value(self) {
                s.check(v, self.voxels)?;
            }
        }
        if self.specular_bounces && !self.anisotropic {
            return Err(Error::Setting(
                "specular_bounces keeps the lobes beside six directional values: it needs the \
                 anisotropic volume"
                    .into(),
            ));
        }
        if self.progressive && self.bounces != UNLIMITED_BOUNCES {
            return Err(Error::Setting(format!(
                "progressive bounces converge to unlimited bounces: set bounces to unlimited \
                 (not {})",
                self.bounces
            )));
        }
        Ok(())
    }
}

impl FrameParams {
    /// Checks every parameter against its setting's range and the camera; `levels` is the
    /// volume's mip count (the voxel views' levels).
    pub fn validate(&self, levels: u32) -> Result<()> {
        let c = &self.camera;
        if !(c.position.is_finite() && c.forward.is_finite() && c.up.is_finite()) {
            return Err(Error::Setting(
                "camera position and direction must be finite".into(),
            ));
        }
        for s in SETTINGS.iter().filter(|s| s.per_frame()) {
            s.check(
                s.value(&RendererOptions::default(), self),
                VoxelKind::default(),
            )?;
        }
        if self.debug_level >= levels {
            return Err(Error::Setting(format!(
                "voxel_level {} is outside 0..{levels}",
                self.debug_level
            )));
        }
        if self.debug_direction as usize >= DIRECTIONS.len() {
            return Err(Error::Setting(format!(
                "voxel_dir {} is outside 0..6 (+X, -X, +Y, -Y, +Z, -Z)",
                self.debug_direction
            )));
        }
        Ok(())
    }
}

/// `x` as the shortest decimal that reads back as it (0.1, not 0.10000000149011612).
fn short(x: f32) -> toml::Value {
    toml::Value::Float(x.to_string().parse().unwrap_or(x.into()))
}

/// A scene file's `[settings]` table, parsed: the settings it names with their values, in the
/// table's order. Unknown keys and values of the wrong form are errors that name the key.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SceneSettings {
    values: Vec<(&'static str, Value)>,
}

impl SceneSettings {
    /// Parses a `[settings]` table.
    pub fn from_table(table: &toml::Table) -> Result<Self> {
        for key in table.keys() {
            if Setting::get(key).is_none() {
                return Err(Error::Setting(format!(
                    "[settings]: unknown key '{key}' (the keys: {})",
                    SETTINGS
                        .iter()
                        .map(|s| s.key)
                        .collect::<Vec<_>>()
                        .join(", ")
                )));
            }
        }
        let values = SETTINGS
            .iter()
            .filter_map(|s| table.get(s.key).map(|v| Ok((s.key, s.from_toml(v)?))))
            .collect::<Result<_>>()?;
        Ok(SceneSettings { values })
    }

    /// The settings given as (key, text) pairs, as flags give them.
    pub fn from_pairs<'a>(pairs: impl IntoIterator<Item = (&'a str, &'a str)>) -> Result<Self> {
        let mut values = Vec::new();
        for (key, text) in pairs {
            let s = Setting::get(key)
                .ok_or_else(|| Error::Setting(format!("unknown setting '{key}'")))?;
            values.push((s.key, s.parse(text)?));
        }
        values.sort_by_key(|(k, _)| SETTINGS.iter().position(|s| s.key == *k));
        Ok(SceneSettings { values })
    }

    /// Whether it names no setting.
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// The value given for `key`, if any.
    pub fn value(&self, key: &str) -> Option<Value> {
        self.values.iter().find(|(k, _)| *k == key).map(|(_, v)| *v)
    }

    /// Applies the settings that are present, in the table's order (ranges are checked by
    /// `RendererOptions::validate` and `FrameParams::validate`).
    pub fn apply(&self, o: &mut RendererOptions, f: &mut FrameParams) -> Result<()> {
        for (key, v) in &self.values {
            let s = Setting::get(key).expect("parsed from the table");
            s.set(o, f, *v);
        }
        Ok(())
    }
}

/// A bounce count: "0".."8", "direct" or "unlimited" (also "inf").
pub fn parse_bounces(s: &str) -> Result<u32> {
    let b = Setting::get("bounces").expect("in the table");
    let v = b.parse(s)?;
    b.check(v, VoxelKind::default())?;
    match v {
        Value::Int(n) => Ok(n),
        _ => unreachable!("bounces parse to counts"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::options::{ConeSet, Tonemap, ViewMode};

    fn parse(text: &str) -> Result<(RendererOptions, FrameParams)> {
        let table: toml::Table = toml::from_str(text).expect("valid TOML");
        let mut o = RendererOptions::default();
        let mut f = FrameParams::new(Camera::look_at(glam::Vec3::Z, glam::Vec3::ZERO, 45.0));
        SceneSettings::from_table(&table)?.apply(&mut o, &mut f)?;
        o.validate()?;
        Ok((o, f))
    }

    /// What the viewer saves into a scene file reads back as itself: every setting's default,
    /// and values off it (unlimited bounces, a fixed cone length, a background colour).
    #[test]
    fn every_setting_written_as_toml_reads_back() {
        for s in SETTINGS {
            let v = s.default_value();
            assert_eq!(s.from_toml(&s.to_toml(v)).unwrap(), v, "{}", s.key);
        }
        let cases = [
            ("bounces", Value::Int(UNLIMITED_BOUNCES)),
            ("max_distance", Value::Auto(Some(12.5))),
            ("background", Value::Rgb([0.1, 0.2, 0.3])),
            ("step_factor", Value::Float(0.3)),
        ];
        for (key, v) in cases {
            let s = Setting::get(key).unwrap();
            assert_eq!(s.from_toml(&s.to_toml(v)).unwrap(), v, "{key}");
        }
        let s = Setting::get("step_factor").unwrap();
        assert_eq!(s.to_toml(Value::Float(0.3)).to_string(), "0.3");
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
        assert!(e.contains("filmic") && e.contains("tonemap"), "{e}");
        let e = parse("anisotropic = 3").unwrap_err().to_string();
        assert!(e.contains("anisotropic"), "{e}");
        let e = parse("voxel_resolution = 100").unwrap_err().to_string();
        assert!(e.contains("voxel_resolution 100"), "{e}");
    }

    /// Every setting's default is valid, reads back through its own parser, and every
    /// creation-time option's default is `RendererOptions::default()`'s.
    #[test]
    fn every_default_parses_back_and_validates() {
        for s in SETTINGS {
            let d = s.default_value();
            let text = d.to_string();
            assert_eq!(s.parse(&text).unwrap(), d, "{}: {text}", s.key);
            s.check(d, VoxelKind::default()).unwrap();
            assert!(!s.help.is_empty() && !s.label.is_empty(), "{}", s.key);
        }
        RendererOptions::default().validate().unwrap();
        // Keys are unique.
        for (i, s) in SETTINGS.iter().enumerate() {
            assert!(SETTINGS[..i].iter().all(|t| t.key != s.key), "{}", s.key);
        }
    }

    /// Each setting set to a value other than its default changes what it says, and only that
    /// (the table's get and set agree, and no two settings share a field).
    #[test]
    fn each_setting_owns_its_field() {
        let camera = Camera::look_at(glam::Vec3::Z, glam::Vec3::ZERO, 45.0);
        for s in SETTINGS {
            let (mut o, mut f) = (RendererOptions::default(), FrameParams::new(camera.clone()));
            let other = match (s.domain, s.default_value()) {
                (_, Value::Bool(b)) => Value::Bool(!b),
                (Domain::Bounces, _) => Value::Int(3),
                (Domain::Int { min, max }, Value::Int(n)) => {
                    Value::Int(if n == max { min } else { max })
                }
                (Domain::Resolution { min }, _) => Value::Int(min),
                (Domain::Float { min, max }, Value::Float(x)) => {
                    Value::Float(if x == max { min } else { max })
                }
                (Domain::Auto, _) => Value::Auto(Some(0.25)),
                (Domain::Choice(names), Value::Name(n)) => {
                    Value::Name(names().into_iter().find(|c| *c != n).expect("two choices"))
                }
                (Domain::Rgb, _) => Value::Rgb([0.5, 0.25, 1.0]),
                (d, v) => panic!("{}: {d:?} with {v:?}", s.key),
            };
            s.set(&mut o, &mut f, other);
            assert_eq!(s.value(&o, &f), other, "{}", s.key);
            for t in SETTINGS.iter().filter(|t| t.key != s.key) {
                // Progressive bounces set unlimited bounces with them.
                if (s.key, t.key) == ("progressive", "bounces") {
                    continue;
                }
                assert_eq!(
                    t.value(&o, &f),
                    t.default_value(),
                    "setting {} changed {}",
                    s.key,
                    t.key
                );
            }
        }
    }

    #[test]
    fn lighting_settings_do_not_revoxelize() {
        let base = RendererOptions::default();
        let with = |f: fn(&mut RendererOptions)| {
            let mut o = base.clone();
            f(&mut o);
            changes_between(&base, &o)
        };
        assert_eq!(with(|o| o.bounces = 3), Some(Changes::Lighting));
        assert_eq!(with(|o| o.ao_radius = Some(1.0)), Some(Changes::Lighting));
        assert_eq!(with(|o| o.voxel_resolution = 64), Some(Changes::Voxels));
        assert_eq!(with(|o| o.half_resolution = true), Some(Changes::Pipelines));
        assert_eq!(with(|o| o.fragment_capacity = Some(4096)), None);
        assert_eq!(changes_between(&base, &base), None);
    }
}
