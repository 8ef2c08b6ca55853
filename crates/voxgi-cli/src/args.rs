//! Arguments shared by several commands: the scene, the renderer's settings, sizes and vectors;
//! loading a scene with its `[settings]` table; progress lines.

use anyhow::{Result, bail};
use clap::Args;
use std::path::PathBuf;
use std::time::Instant;
use voxgi::scene::glam::Vec3;
use voxgi::scene::{Camera, Scene, builtin, io};
use voxgi::settings::{Domain, SETTINGS};
use voxgi::{FrameParams, RendererOptions, SceneSettings};

#[derive(Args)]
pub struct SceneArg {
    /// Scene file: .gltf, .glb, .obj, .ply, .pcd, .cloud or .toml.
    #[arg(required_unless_present = "builtin", conflicts_with = "builtin")]
    pub scene: Option<PathBuf>,
    /// A built-in scene instead of a file: cornell-box, open-plane, closed-box, two-rooms,
    /// cube, point-cave.
    #[arg(long, value_name = "NAME")]
    pub builtin: Option<String>,
}

/// Renderer settings shared by `render` and `bench`: one flag per setting of the library's
/// table (`voxgi::settings::SETTINGS`), named as its key with dashes. Each flag overrides the
/// scene file's `[settings]` table, which overrides the defaults.
pub struct SettingsArgs {
    /// The flags given, as (key, text), checked against their setting's form.
    given: Vec<(&'static str, String)>,
}

impl clap::FromArgMatches for SettingsArgs {
    fn from_arg_matches(m: &clap::ArgMatches) -> Result<Self, clap::Error> {
        let given = SETTINGS
            .iter()
            .filter_map(|s| m.get_one::<String>(s.key).map(|v| (s.key, v.clone())))
            .collect();
        Ok(SettingsArgs { given })
    }

    fn update_from_arg_matches(&mut self, m: &clap::ArgMatches) -> Result<(), clap::Error> {
        *self = Self::from_arg_matches(m)?;
        Ok(())
    }
}

impl clap::Args for SettingsArgs {
    fn augment_args(cmd: clap::Command) -> clap::Command {
        SETTINGS.iter().fold(cmd, |cmd, s| {
            let mut arg = clap::Arg::new(s.key)
                .long(s.flag())
                .help(match s.domain {
                    // clap lists the choices itself.
                    Domain::Choice(_) => format!("{} (default {})", s.help, s.default_value()),
                    _ => format!(
                        "{} ({}; default {})",
                        s.help,
                        s.describe(),
                        s.default_value()
                    ),
                })
                .value_parser(move |v: &str| s.parse(v).map(|_| v.to_string()))
                .help_heading(if s.per_frame() {
                    "Frame settings"
                } else {
                    "Renderer settings"
                });
            arg = match s.domain {
                // `--half-resolution` alone is true; `--anisotropic=false` turns one off.
                Domain::Bool => arg
                    .num_args(0..=1)
                    .require_equals(true)
                    .default_missing_value("true")
                    .value_name("BOOL"),
                Domain::Choice(names) => arg
                    .value_name("NAME")
                    .allow_hyphen_values(true)
                    .ignore_case(true)
                    .value_parser(clap::builder::PossibleValuesParser::new(names())),
                _ => arg.value_name("VALUE").allow_hyphen_values(true),
            };
            cmd.arg(arg)
        })
    }

    fn augment_args_for_update(cmd: clap::Command) -> clap::Command {
        Self::augment_args(cmd)
    }
}

impl SettingsArgs {
    /// Defaults, then the scene file's `[settings]`, then these flags; `camera` is the view.
    pub fn resolve(
        &self,
        file: Option<&toml::Table>,
        camera: Camera,
    ) -> Result<(RendererOptions, FrameParams)> {
        let mut o = RendererOptions::default();
        let mut f = FrameParams::new(camera);
        if let Some(t) = file {
            SceneSettings::from_table(t)?.apply(&mut o, &mut f)?;
        }
        SceneSettings::from_pairs(self.given.iter().map(|(k, v)| (*k, v.as_str())))?
            .apply(&mut o, &mut f)?;
        o.validate()?;
        f.validate(o.voxel_levels())?;
        Ok((o, f))
    }
}

pub fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("'{s}' is not WIDTHxHEIGHT (e.g. 512x512)"))?;
    let w: u32 = w.trim().parse().map_err(|_| format!("bad width '{w}'"))?;
    let h: u32 = h.trim().parse().map_err(|_| format!("bad height '{h}'"))?;
    voxgi::validate_size(w, h).map_err(|e| e.to_string())?;
    Ok((w, h))
}

pub fn parse_vec3(s: &str) -> Result<Vec3, String> {
    let v: Vec<f32> = s
        .split(',')
        .map(|c| {
            c.trim()
                .parse::<f32>()
                .map_err(|_| format!("'{c}' is not a number"))
        })
        .collect::<Result<_, _>>()?;
    match v.as_slice() {
        [x, y, z] if x.is_finite() && y.is_finite() && z.is_finite() => Ok(Vec3::new(*x, *y, *z)),
        _ => Err(format!("'{s}' is not three finite numbers X,Y,Z")),
    }
}

/// Prints a stage and how long it took, so long work is never silent.
pub struct Progress {
    pub start: Instant,
}

impl Progress {
    pub fn stage<T>(&self, what: &str, f: impl FnOnce() -> T) -> T {
        eprint!("{what} … ");
        let t = Instant::now();
        let out = f();
        eprintln!("{:.2} s", t.elapsed().as_secs_f64());
        out
    }
}

pub fn load_scene(arg: &SceneArg) -> Result<Scene> {
    Ok(load_scene_and_settings(arg)?.0)
}

/// The scene, and the `[settings]` table when it is a scene file that has one.
pub fn load_scene_and_settings(arg: &SceneArg) -> Result<(Scene, Option<toml::Table>)> {
    match (&arg.scene, &arg.builtin) {
        (_, Some(name)) => Ok((builtin::by_name(name)?, None)),
        (Some(path), None) => {
            let is_toml = path
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("toml"));
            if is_toml {
                let (scene, table) = io::scene_file::load_with_settings(path)?;
                scene.validate().map_err(|e| e.in_file(path))?;
                Ok((scene, table))
            } else {
                Ok((io::load(path)?, None))
            }
        }
        (None, None) => bail!("give a scene file or --builtin NAME"),
    }
}

pub fn scene_label(arg: &SceneArg) -> String {
    match (&arg.scene, &arg.builtin) {
        (_, Some(name)) => format!("built-in scene '{name}'"),
        (Some(path), None) => path.display().to_string(),
        _ => String::new(),
    }
}
