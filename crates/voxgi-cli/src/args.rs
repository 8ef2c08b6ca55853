//! Arguments shared by several commands: the scene, the renderer's settings, sizes and vectors;
//! loading a scene with its `[settings]` table; progress lines.

use anyhow::{Result, bail};
use clap::Args;
use std::path::PathBuf;
use std::time::Instant;
use voxgi::scene::glam::Vec3;
use voxgi::scene::{Camera, Scene, builtin, io};
use voxgi::{FrameParams, RendererOptions, SceneSettings, Tonemap, ViewMode};

#[derive(Args)]
pub struct SceneArg {
    /// Scene file: .gltf, .glb, .obj, .ply, .cloud or .toml.
    #[arg(required_unless_present = "builtin", conflicts_with = "builtin")]
    pub scene: Option<PathBuf>,
    /// A built-in scene instead of a file: cornell-box, open-plane, closed-box, two-rooms,
    /// cube.
    #[arg(long, value_name = "NAME")]
    pub builtin: Option<String>,
}

/// Renderer settings shared by `render` and `bench`. Each flag overrides the scene file's
/// `[settings]` table, which overrides the defaults.
#[derive(Args)]
pub struct SettingsArgs {
    /// Exposure in stops (EV): the image is scaled by 2^EV before tone mapping. Default 0.
    #[arg(long, value_name = "EV", allow_hyphen_values = true)]
    pub exposure: Option<f32>,
    /// Tone-mapping curve for PNG output. Default aces.
    #[arg(long, value_parser = names(Tonemap::ALL.map(Tonemap::name)))]
    pub tonemap: Option<String>,
    /// What to show; the voxel views ray-march the volume at --voxel-level and show the first
    /// voxel with opacity > 0.5. Default final.
    #[arg(long, value_parser = names(ViewMode::ALL.map(ViewMode::name)))]
    pub view: Option<String>,
    /// Shadow filter of point, spot and directional lights: pcf, or vsm-esm (the thesis'
    /// prefiltered variance and exponential maps, the smaller visibility). Default pcf.
    #[arg(long, value_parser = names(voxgi::ShadowFilter::ALL.map(voxgi::ShadowFilter::name)))]
    pub shadow_filter: Option<String>,
    /// Shadow map resolution per view, in texels. Default 1024.
    #[arg(long, value_name = "N")]
    pub shadow_map_size: Option<u32>,
    /// Voxel structure: dense (the mip-mapped volume) or octree (the sparse voxel octree,
    /// memory in proportion to the occupied voxels). Default dense.
    #[arg(long, value_parser = names(voxgi::VoxelKind::names()))]
    pub voxels: Option<String>,
    /// Voxels per side of the volume (power of two, 16..=512; the octree 16..=1024). Default 128.
    #[arg(long, value_name = "N")]
    pub voxel_resolution: Option<u32>,
    /// Indirect bounces: 0 ("direct": direct light only) to 8, or "unlimited". Default 2.
    #[arg(long, value_name = "N", value_parser = lib(voxgi::parse_bounces))]
    pub bounces: Option<u32>,
    /// Diffuse cone set: 6x60, 7x45 or 9x45. Default 6x60.
    #[arg(long, value_name = "SET", value_parser = lib(voxgi::parse_cones))]
    pub cones: Option<voxgi::ConeSet>,
    /// Diffuse indirect light per pixel: cones (a cone bundle per pixel) or leaves (the
    /// thesis' fast shading: the leaves' stored irradiance, interpolated). Default cones.
    #[arg(long, value_parser = names(voxgi::IndirectShading::ALL.map(voxgi::IndirectShading::name)))]
    pub indirect: Option<String>,
    /// Weigh each leaf's radiance and opacity per direction by its normals in the first
    /// directional level (the point-cloud thesis' NDF), instead of counting leaves isotropic.
    #[arg(long)]
    pub ndf_mips: bool,
    /// One radiance value per voxel above the finest level instead of six directional ones.
    #[arg(long)]
    pub isotropic: bool,
    /// Directional blocks per cone sample in the per-pixel gather: 3 (default) or 2 (faster).
    #[arg(long, value_name = "N")]
    pub gather_axes: Option<u32>,
    /// Gather indirect light at half resolution with an edge-aware upsample.
    #[arg(long)]
    pub half_res: bool,
    /// Shadows of area lights by a cone traced through the voxels instead of the shadow map.
    #[arg(long)]
    pub cone_shadows: bool,
    /// Ambient-occlusion radius in metres. Default: a quarter of the volume.
    #[arg(long, value_name = "M")]
    pub ao_radius: Option<f32>,
    /// Ambient-occlusion falloff lambda in 1/(1 + lambda r), per metre. Default 0.
    #[arg(long, value_name = "L")]
    pub ao_lambda: Option<f32>,
    /// Cone step as a fraction of the cone diameter. Default 0.5.
    #[arg(long, value_name = "F")]
    pub step_factor: Option<f32>,
    /// Mip level the voxel views show (0 = finest).
    #[arg(long, value_name = "N")]
    pub voxel_level: Option<u32>,
    /// Directional chain the voxel views read above the finest level: +x, -x, +y, -y, +z, -z.
    #[arg(long, value_name = "DIR", value_parser = lib(voxgi::parse_direction), allow_hyphen_values = true)]
    pub voxel_dir: Option<u32>,
    /// Progressive bounces: one voxel bounce per frame on top of the last frame's light,
    /// converging to unlimited bounces (sets --bounces unlimited).
    #[arg(long)]
    pub progressive: bool,
    /// Voxel work on every K-th frame only (the voxels then trail moving meshes). Default 1.
    #[arg(long, value_name = "K")]
    pub update_interval: Option<u32>,
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
        macro_rules! set {
            ($dst:expr, $src:expr) => {
                if let Some(v) = $src {
                    $dst = v;
                }
            };
        }
        set!(f.exposure, self.exposure);
        if let Some(t) = &self.tonemap {
            f.tonemap = Tonemap::parse(t)?;
        }
        if let Some(v) = &self.view {
            f.view = ViewMode::parse(v)?;
        }
        set!(o.shadow_map_size, self.shadow_map_size);
        if let Some(f) = &self.shadow_filter {
            o.shadow_filter = voxgi::ShadowFilter::parse(f)?;
        }
        if let Some(v) = &self.voxels {
            o.voxels = voxgi::VoxelKind::parse(v)?;
        }
        set!(o.voxel_resolution, self.voxel_resolution);
        set!(o.bounces, self.bounces);
        set!(o.cones, self.cones);
        if let Some(i) = &self.indirect {
            o.indirect = voxgi::IndirectShading::parse(i)?;
        }
        if self.isotropic {
            o.anisotropic = false;
        }
        o.ndf_mips |= self.ndf_mips;
        set!(o.gather_axes, self.gather_axes);
        o.half_resolution |= self.half_res;
        o.cone_shadows |= self.cone_shadows;
        if self.ao_radius.is_some() {
            o.ao_radius = self.ao_radius;
        }
        set!(o.ao_lambda, self.ao_lambda);
        set!(o.step_factor, self.step_factor);
        set!(f.debug_level, self.voxel_level);
        set!(f.debug_direction, self.voxel_dir);
        if self.progressive {
            o.progressive = true;
            o.bounces = voxgi::UNLIMITED_BOUNCES;
        }
        set!(o.voxel_update_interval, self.update_interval);
        o.validate()?;
        f.validate(o.voxel_levels())?;
        Ok((o, f))
    }
}

/// The view when the scene gives none: as the renderer's (`Renderer::default_camera`), around
/// everything the scene's animations sweep, so it is the same at every time.
pub fn default_camera(scene: &Scene) -> Camera {
    scene
        .cameras
        .first()
        .cloned()
        .unwrap_or_else(|| Camera::viewing(voxgi::swept_bounds(scene)))
}

/// A clap parser for one of the library's names.
fn names(names: impl IntoIterator<Item = &'static str>) -> clap::builder::PossibleValuesParser {
    clap::builder::PossibleValuesParser::new(names)
}

/// A clap parser from one of the library's parsers, so the CLI and scene files agree.
fn lib<T: Clone + Send + Sync + 'static>(
    f: fn(&str) -> voxgi::Result<T>,
) -> impl Fn(&str) -> Result<T, String> + Clone {
    move |s| f(s).map_err(|e| e.to_string())
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
