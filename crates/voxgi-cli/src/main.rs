//! The `voxgi` command.

use anyhow::{Context, Result, bail};
use clap::{Args, Parser, Subcommand, ValueEnum};
use std::path::PathBuf;
use std::time::Instant;
use voxgi::compare::{self, Image};
use voxgi::scene::glam::Vec3;
use voxgi::scene::{Camera, LightKind, Projection, Scene, builtin, io};
use voxgi::{
    Bounces, GpuContext, PathTracer, ReferenceMode, ReferenceOptions, Renderer, Settings, Tonemap,
    ViewMode,
};

#[derive(Parser)]
#[command(
    name = "voxgi",
    version,
    about = "Real-time global illumination by voxel cone tracing",
    long_about = "voxgi renders meshes and point clouds with direct light, shadows and \
                  voxel-cone-traced indirect light (ambient occlusion, diffuse bounces, glossy \
                  reflections, cone-traced soft shadows), headless, on any Vulkan, Metal or DX12 device \
                  — including Mesa's CPU Vulkan driver on machines without a GPU.\n\n\
                  Scenes: glTF (.gltf/.glb), OBJ (+MTL), PLY (meshes or points), .cloud point \
                  files, and .toml scene files that place other files and add lights and a camera.",
    after_help = "Examples:\n  \
                  voxgi render --builtin cornell-box -o cornell.png --size 512x512\n  \
                  voxgi render scene.toml -o out.exr --size 1920x1080 --exposure 1\n  \
                  voxgi render model.obj -o model.png --eye 0,1,5 --target 0,1,0 --fov 40\n  \
                  voxgi info ../shared/scenes/sponza_dabrovic_geometry_only/sponza.obj\n\n\
                  GPU selection: WGPU_BACKEND=vulkan|metal|dx12|gl, WGPU_ADAPTER_NAME=<part of name>.\n\
                  Logging: RUST_LOG=info for details."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene to a PNG (tone-mapped, sRGB) or EXR (linear HDR radiance).
    Render(RenderArgs),
    /// Print what a scene contains: counts, bounds, materials, lights, cameras.
    Info(SceneArg),
    /// Time every pass with GPU timestamps over many frames; print a table, write JSON.
    Bench(BenchArgs),
    /// Compare a test image with a reference: mean FLIP (LDR-FLIP for PNG, HDR-FLIP for EXR),
    /// RMSE and relative MSE on linear values, printed as one JSON line.
    Compare(CompareArgs),
}

#[derive(Args)]
struct CompareArgs {
    /// The reference image (.png or .exr).
    reference: PathBuf,
    /// The image to judge (same size and kind as the reference).
    test: PathBuf,
    /// Also write the per-pixel FLIP error as a PNG (magma colour map).
    #[arg(long, value_name = "FILE.png")]
    error_map: Option<PathBuf>,
}

#[derive(Args)]
struct SceneArg {
    /// Scene file: .gltf, .glb, .obj, .ply, .cloud or .toml.
    #[arg(required_unless_present = "builtin", conflicts_with = "builtin")]
    scene: Option<PathBuf>,
    /// A built-in scene instead of a file: cornell-box, open-plane, closed-box, two-rooms.
    #[arg(long, value_name = "NAME")]
    builtin: Option<String>,
}

#[derive(Args)]
struct RenderArgs {
    #[command(flatten)]
    scene: SceneArg,
    /// Output image; the extension picks the format (.png or .exr).
    #[arg(short, long, value_name = "FILE")]
    output: PathBuf,
    /// Image size in pixels.
    #[arg(long, value_name = "WxH", default_value = "512x512", value_parser = parse_size)]
    size: (u32, u32),
    #[command(flatten)]
    settings: SettingsArgs,
    /// Camera position, overriding the scene's camera (metres).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    eye: Option<Vec3>,
    /// Point the camera looks at.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    target: Option<Vec3>,
    /// Vertical field of view in degrees.
    #[arg(long, value_name = "DEGREES")]
    fov: Option<f32>,
    /// Which of the scene's cameras to use (by index, see `voxgi info`).
    #[arg(long, value_name = "N")]
    camera: Option<usize>,
    /// Renderer: the real-time rasterizer, the reference path tracer, or the AO reference.
    #[arg(long, value_enum, default_value_t = ModeArg::Raster)]
    mode: ModeArg,
    /// Reference modes: samples per pixel.
    #[arg(long, value_name = "N", default_value_t = 256)]
    spp: u32,
    /// Reference modes: random seed (the same seed gives the same image).
    #[arg(long, value_name = "N", default_value_t = 0)]
    seed: u32,
}

/// Renderer settings shared by `render` and `bench`. Each flag overrides the scene file's
/// `[settings]` table, which overrides the defaults.
#[derive(Args)]
struct SettingsArgs {
    /// Exposure in stops (EV): the image is scaled by 2^EV before tone mapping. Default 0.
    #[arg(long, value_name = "EV", allow_hyphen_values = true)]
    exposure: Option<f32>,
    /// Tone-mapping curve for PNG output. Default aces.
    #[arg(long, value_enum)]
    tonemap: Option<TonemapArg>,
    /// What to show. Default final.
    #[arg(long, value_enum)]
    view: Option<ViewArg>,
    /// Shadow map resolution per view, in texels. Default 1024.
    #[arg(long, value_name = "N")]
    shadow_map_size: Option<u32>,
    /// Voxels per side of the volume (power of two, 16..=512). Default 128.
    #[arg(long, value_name = "N")]
    voxel_resolution: Option<u32>,
    /// Indirect bounces: 0 ("direct": direct light only) to 8, or "unlimited". Default 2.
    #[arg(long, value_name = "N", value_parser = parse_bounces)]
    bounces: Option<u32>,
    /// Diffuse cone set: 6x60, 7x45 or 9x45. Default 6x60.
    #[arg(long, value_name = "SET", value_parser = parse_cones)]
    cones: Option<voxgi::ConeSet>,
    /// One radiance value per voxel above the finest level instead of six directional ones.
    #[arg(long)]
    isotropic: bool,
    /// Directional blocks per cone sample in the per-pixel gather: 3 (default) or 2 (faster).
    #[arg(long, value_name = "N")]
    gather_axes: Option<u32>,
    /// Gather indirect light at half resolution with an edge-aware upsample.
    #[arg(long)]
    half_res: bool,
    /// Shadows of area lights by a cone traced through the voxels instead of the shadow map.
    #[arg(long)]
    cone_shadows: bool,
    /// Ambient-occlusion radius in metres. Default: a quarter of the volume.
    #[arg(long, value_name = "M")]
    ao_radius: Option<f32>,
    /// Ambient-occlusion falloff lambda in 1/(1 + lambda r), per metre. Default 0.
    #[arg(long, value_name = "L")]
    ao_lambda: Option<f32>,
    /// Cone step as a fraction of the cone diameter. Default 0.5.
    #[arg(long, value_name = "F")]
    step_factor: Option<f32>,
    /// Mip level the voxel views show (0 = finest).
    #[arg(long, value_name = "N")]
    voxel_level: Option<u32>,
    /// Directional chain the voxel views read above the finest level: +x, -x, +y, -y, +z, -z.
    #[arg(long, value_name = "DIR", value_parser = parse_voxel_dir, allow_hyphen_values = true)]
    voxel_dir: Option<u32>,
}

impl SettingsArgs {
    /// Defaults, then the scene file's `[settings]`, then these flags.
    fn to_settings(&self, file: Option<&toml::Table>) -> Result<Settings> {
        let mut s = Settings::default();
        if let Some(t) = file {
            apply_table(&mut s, t)?;
        }
        if let Some(v) = self.exposure {
            s.exposure = v;
        }
        if let Some(v) = self.tonemap {
            s.tonemap = match v {
                TonemapArg::Aces => Tonemap::Aces,
                TonemapArg::Neutral => Tonemap::Neutral,
                TonemapArg::Clamp => Tonemap::Clamp,
            };
        }
        if let Some(v) = self.view {
            s.view = match v {
                ViewArg::Final => ViewMode::Final,
                ViewArg::Albedo => ViewMode::Albedo,
                ViewArg::Normal => ViewMode::Normal,
                ViewArg::Direct => ViewMode::Direct,
                ViewArg::Ao => ViewMode::Ao,
                ViewArg::Indirect => ViewMode::Indirect,
                ViewArg::VoxelAlbedo => ViewMode::VoxelAlbedo,
                ViewArg::VoxelOpacity => ViewMode::VoxelOpacity,
                ViewArg::VoxelRadiance => ViewMode::VoxelRadiance,
            };
        }
        if let Some(v) = self.shadow_map_size {
            s.shadow_map_size = v;
        }
        if let Some(v) = self.voxel_resolution {
            s.voxel_resolution = v;
        }
        if let Some(v) = self.bounces {
            s.bounces = v;
        }
        if let Some(v) = self.cones {
            s.cones = v;
        }
        if self.isotropic {
            s.anisotropic = false;
        }
        if let Some(v) = self.gather_axes {
            s.gather_axes = v;
        }
        if self.half_res {
            s.half_resolution = true;
        }
        if self.cone_shadows {
            s.cone_shadows = true;
        }
        if self.ao_radius.is_some() {
            s.ao_radius = self.ao_radius;
        }
        if let Some(v) = self.ao_lambda {
            s.ao_lambda = v;
        }
        if let Some(v) = self.step_factor {
            s.step_factor = v;
        }
        if let Some(v) = self.voxel_level {
            s.debug_level = v;
        }
        if let Some(v) = self.voxel_dir {
            s.debug_direction = v;
        }
        s.validate()?;
        Ok(s)
    }
}

/// Applies a scene file's `[settings]` table; unknown keys and wrong types are errors.
fn apply_table(s: &mut Settings, t: &toml::Table) -> Result<()> {
    for (key, value) in t {
        let num = || {
            value
                .as_float()
                .or_else(|| value.as_integer().map(|i| i as f64))
                .with_context(|| format!("[settings] {key}: expected a number, got {value}"))
        };
        let int = || {
            value
                .as_integer()
                .and_then(|i| u32::try_from(i).ok())
                .with_context(|| {
                    format!("[settings] {key}: expected a non-negative integer, got {value}")
                })
        };
        let boolean = || {
            value
                .as_bool()
                .with_context(|| format!("[settings] {key}: expected true or false, got {value}"))
        };
        let string = || {
            value
                .as_str()
                .with_context(|| format!("[settings] {key}: expected a string, got {value}"))
        };
        match key.as_str() {
            "exposure" => s.exposure = num()? as f32,
            "shadow_map_size" => s.shadow_map_size = int()?,
            "voxel_resolution" => s.voxel_resolution = int()?,
            "bounces" => {
                s.bounces = match value.as_str() {
                    Some(v) => parse_bounces(v).map_err(anyhow::Error::msg)?,
                    None => int()?,
                }
            }
            "cones" => s.cones = parse_cones(string()?).map_err(anyhow::Error::msg)?,
            "anisotropic" => s.anisotropic = boolean()?,
            "gather_axes" => s.gather_axes = int()?,
            "half_resolution" => s.half_resolution = boolean()?,
            "cone_shadows" => s.cone_shadows = boolean()?,
            "ao_radius" => s.ao_radius = Some(num()? as f32),
            "ao_lambda" => s.ao_lambda = num()? as f32,
            "step_factor" => s.step_factor = num()? as f32,
            "voxel_level" => s.debug_level = int()?,
            "tonemap" => {
                s.tonemap = match string()? {
                    "aces" => Tonemap::Aces,
                    "neutral" => Tonemap::Neutral,
                    "clamp" => Tonemap::Clamp,
                    other => bail!("[settings] tonemap: '{other}' is not aces, neutral or clamp"),
                }
            }
            other => bail!(
                "[settings] unknown key '{other}' (known: exposure, shadow_map_size, \
                 voxel_resolution, bounces, cones, anisotropic, gather_axes, half_resolution, \
                 cone_shadows, ao_radius, ao_lambda, step_factor, voxel_level, tonemap)"
            ),
        }
    }
    Ok(())
}

#[derive(Args)]
struct BenchArgs {
    #[command(flatten)]
    scene: SceneArg,
    /// Image size in pixels.
    #[arg(long, value_name = "WxH", default_value = "1280x720", value_parser = parse_size)]
    size: (u32, u32),
    /// Frames timed (after the warm-up).
    #[arg(long, value_name = "N", default_value_t = 20)]
    frames: u32,
    /// Frames rendered before timing starts.
    #[arg(long, value_name = "N", default_value_t = 2)]
    warmup: u32,
    /// Voxelize, inject, filter and bounce every frame (a fully dynamic scene).
    #[arg(long)]
    revoxelize: bool,
    /// Write the results as JSON here.
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
    #[command(flatten)]
    settings: SettingsArgs,
}

fn parse_bounces(s: &str) -> Result<u32, String> {
    if s == "unlimited" || s == "inf" {
        return Ok(voxgi::UNLIMITED_BOUNCES);
    }
    if s == "direct" {
        return Ok(0);
    }
    let n: u32 = s
        .parse()
        .map_err(|_| format!("'{s}' is not 0..=8 or 'unlimited'"))?;
    if n > voxgi::MAX_BOUNCES {
        return Err(format!(
            "{n} bounces: use 0..={} or 'unlimited'",
            voxgi::MAX_BOUNCES
        ));
    }
    Ok(n)
}

fn parse_cones(s: &str) -> Result<voxgi::ConeSet, String> {
    voxgi::ConeSet::parse(s).ok_or_else(|| format!("'{s}' is not a cone set (6x60, 7x45, 9x45)"))
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum ModeArg {
    Raster,
    Reference,
    AoReference,
}

#[derive(Clone, Copy, ValueEnum)]
enum TonemapArg {
    Aces,
    Neutral,
    Clamp,
}

#[derive(Clone, Copy, ValueEnum)]
enum ViewArg {
    Final,
    Albedo,
    Normal,
    Direct,
    Ao,
    Indirect,
    /// The voxel volume's albedo (first voxel with opacity > 0.5 at --voxel-level).
    VoxelAlbedo,
    /// The voxel volume's opacity as grey.
    VoxelOpacity,
    /// The voxel volume's radiance (un-premultiplied).
    VoxelRadiance,
}

fn parse_voxel_dir(s: &str) -> Result<u32, String> {
    voxgi::voxel::dense::DIRECTIONS
        .iter()
        .position(|d| d.eq_ignore_ascii_case(s))
        .map(|i| i as u32)
        .ok_or_else(|| format!("'{s}' is not a direction (+x, -x, +y, -y, +z, -z)"))
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("'{s}' is not WIDTHxHEIGHT (e.g. 512x512)"))?;
    let w: u32 = w.trim().parse().map_err(|_| format!("bad width '{w}'"))?;
    let h: u32 = h.trim().parse().map_err(|_| format!("bad height '{h}'"))?;
    voxgi::validate_size(w, h).map_err(|e| e.to_string())?;
    Ok((w, h))
}

fn parse_vec3(s: &str) -> Result<Vec3, String> {
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
struct Progress {
    start: Instant,
}

impl Progress {
    fn stage<T>(&self, what: &str, f: impl FnOnce() -> T) -> T {
        eprint!("{what} … ");
        let t = Instant::now();
        let out = f();
        eprintln!("{:.2} s", t.elapsed().as_secs_f64());
        out
    }
}

fn load_scene(arg: &SceneArg) -> Result<Scene> {
    Ok(load_scene_and_settings(arg)?.0)
}

/// The scene, and the `[settings]` table when it is a scene file that has one.
fn load_scene_and_settings(arg: &SceneArg) -> Result<(Scene, Option<toml::Table>)> {
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

fn scene_label(arg: &SceneArg) -> String {
    match (&arg.scene, &arg.builtin) {
        (_, Some(name)) => format!("built-in scene '{name}'"),
        (Some(path), None) => path.display().to_string(),
        _ => String::new(),
    }
}

fn render(args: &RenderArgs) -> Result<()> {
    let p = Progress {
        start: Instant::now(),
    };
    let ext = args
        .output
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    if ext != "png" && ext != "exr" {
        bail!(
            "{}: unknown image type (use .png or .exr)",
            args.output.display()
        );
    }
    let label = scene_label(&args.scene);
    let (scene, table) = p.stage(&format!("loading {label}"), || {
        load_scene_and_settings(&args.scene)
    })?;
    let settings = args
        .settings
        .to_settings(table.as_ref())
        .with_context(|| label.clone())?;
    let ctx = p.stage("opening GPU", GpuContext::from_env)?;
    eprintln!("GPU: {} ({:?})", ctx.info.name, ctx.info.backend);
    let (w, h) = args.size;
    let out = if args.mode == ModeArg::Raster {
        let mut renderer = p
            .stage("uploading scene", || Renderer::new(&ctx, &scene, settings))
            .with_context(|| label.clone())?;
        let camera = pick_camera(&scene, renderer.default_camera(), args)?;
        p.stage(&format!("rendering {w}x{h}"), || {
            renderer.render(&camera, w, h)
        })?
    } else {
        let opts = ReferenceOptions {
            spp: args.spp,
            bounces: match settings.bounces {
                0 => Bounces::DirectOnly,
                1 => Bounces::One,
                voxgi::UNLIMITED_BOUNCES => Bounces::Unlimited,
                n => Bounces::Exactly(n),
            },
            mode: if args.mode == ModeArg::AoReference {
                ReferenceMode::Ao {
                    // The cone tracer's AO radius, so the two are comparable.
                    radius: settings.ao_radius.unwrap_or_else(|| {
                        let b = scene.bounds();
                        voxgi::voxel::Grid::around(b.min, b.max, settings.voxel_resolution).extent()
                            * 0.25
                    }),
                }
            } else {
                ReferenceMode::Radiance
            },
            seed: args.seed,
        };
        let mut tracer = p
            .stage("uploading scene and building the BVH", || {
                PathTracer::new(&ctx, &scene, &settings)
            })
            .with_context(|| label.clone())?;
        let default = scene
            .cameras
            .first()
            .cloned()
            .unwrap_or_else(|| scene.default_camera());
        let camera = pick_camera(&scene, &default, args)?;
        eprintln!(
            "path tracing {w}x{h}, {} spp, {} triangles",
            opts.spp,
            tracer.triangle_count()
        );
        let t = Instant::now();
        let mut last = 0.0;
        let out = tracer.render(&camera, w, h, &opts, &mut |done, total| {
            let el = t.elapsed().as_secs_f64();
            if el - last >= 1.0 || done == total {
                last = el;
                let eta = el / done as f64 * (total - done) as f64;
                eprint!("\r  {done}/{total} spp  {el:.1} s elapsed  ETA {eta:.1} s   ");
            }
        })?;
        eprintln!(
            "\nrendered {} spp in {:.2} s",
            opts.spp,
            t.elapsed().as_secs_f64()
        );
        out
    };
    out.save(&args.output)?;
    eprintln!(
        "wrote {} ({w}x{h}) in {:.2} s",
        args.output.display(),
        p.start.elapsed().as_secs_f64()
    );
    Ok(())
}

fn pick_camera(scene: &Scene, default: &Camera, args: &RenderArgs) -> Result<Camera> {
    let mut cam = match args.camera {
        Some(i) => scene.cameras.get(i).cloned().with_context(|| {
            format!(
                "camera {i} does not exist (the scene has {})",
                scene.cameras.len()
            )
        })?,
        None => default.clone(),
    };
    if args.eye.is_some() || args.target.is_some() {
        let eye = args.eye.unwrap_or(cam.position);
        let target = args.target.unwrap_or(cam.position + cam.forward);
        if (target - eye).length() < 1e-6 {
            bail!("--eye and --target are the same point");
        }
        let fov = match cam.projection {
            Projection::Perspective { yfov } => yfov.to_degrees(),
            _ => 45.0,
        };
        // The default camera's near plane sits just in front of the scene's bounds; a moved eye
        // (perhaps inside the scene) needs one scaled to the scene instead.
        let near = if args.eye.is_some() {
            let b = scene.bounds();
            let radius = if b.is_empty() {
                1.0
            } else {
                b.size().length() * 0.5
            };
            cam.znear.min((radius * 1e-3).max(1e-4))
        } else {
            cam.znear
        };
        cam = Camera::look_at(eye, target, fov);
        cam.znear = near;
    }
    if let Some(fov) = args.fov {
        if !(fov > 0.5 && fov < 179.0) {
            bail!("--fov {fov} is outside (0.5, 179) degrees");
        }
        cam.projection = Projection::Perspective {
            yfov: fov.to_radians(),
        };
    }
    Ok(cam)
}

fn compare_images(args: &CompareArgs) -> Result<()> {
    let reference = Image::load(&args.reference)?;
    let test = Image::load(&args.test)?;
    let (c, map) = compare::compare_with_map(&reference, &test).with_context(|| {
        format!(
            "comparing {} with {}",
            args.test.display(),
            args.reference.display()
        )
    })?;
    if let Some(path) = &args.error_map {
        compare::save_error_map(path, reference.width, reference.height, &map)?;
    }
    println!(
        "{}",
        serde_json::json!({
            "flip_mean": c.flip_mean,
            "rmse": c.rmse,
            "rel_mse": c.rel_mse,
            "reference": args.reference.display().to_string(),
            "test": args.test.display().to_string(),
            "hdr": c.hdr,
        })
    );
    Ok(())
}

fn info(arg: &SceneArg) -> Result<()> {
    let scene = load_scene(arg)?;
    print!("{}", describe(&scene, &scene_label(arg)));
    Ok(())
}

fn describe(s: &Scene, label: &str) -> String {
    use std::fmt::Write;
    let mut o = String::new();
    let b = s.bounds();
    let _ = writeln!(o, "scene       {label}");
    let _ = writeln!(
        o,
        "geometry    {} meshes, {} instances, {} triangles drawn, {} vertices",
        s.meshes.len(),
        s.instances.len(),
        s.triangle_count(),
        s.meshes.iter().map(|m| m.positions.len()).sum::<usize>()
    );
    let _ = writeln!(
        o,
        "points      {} clouds, {} points",
        s.point_clouds.len(),
        s.point_count()
    );
    if b.is_empty() {
        let _ = writeln!(o, "bounds      empty");
    } else {
        let _ = writeln!(
            o,
            "bounds      min {:.4?}  max {:.4?}  size {:.4?}",
            b.min.to_array(),
            b.max.to_array(),
            b.size().to_array()
        );
    }
    let _ = writeln!(
        o,
        "materials   {}   textures {}",
        s.materials.len(),
        s.textures.len()
    );
    for (i, m) in s.materials.iter().enumerate().take(32) {
        let c = m.base_color;
        let _ = write!(
            o,
            "  [{i}] {:<24} base [{:.3}, {:.3}, {:.3}]  rough {:.2}  metal {:.2}",
            m.name, c[0], c[1], c[2], m.roughness, m.metallic
        );
        if m.is_emissive() {
            let _ = write!(o, "  emissive {:?}", m.emissive);
        }
        if m.base_color_texture.is_some() {
            let _ = write!(o, "  textured");
        }
        let _ = writeln!(o);
    }
    if s.materials.len() > 32 {
        let _ = writeln!(o, "  … and {} more", s.materials.len() - 32);
    }
    let _ = writeln!(o, "lights      {}", s.lights.len());
    for (i, l) in s.lights.iter().enumerate() {
        let kind = match l.kind {
            LightKind::Directional => "directional".to_string(),
            LightKind::Point => "point".to_string(),
            LightKind::Spot {
                inner_angle,
                outer_angle,
            } => format!(
                "spot {:.1}°/{:.1}°",
                inner_angle.to_degrees(),
                outer_angle.to_degrees()
            ),
            LightKind::Area { .. } => format!("area {:.4} m²", l.area()),
        };
        let _ = writeln!(
            o,
            "  [{i}] {:<20} {kind:<18} {:?} x {}  at {:.3?}  towards {:.3?}",
            l.name,
            l.color,
            l.intensity,
            l.position.to_array(),
            l.direction.to_array()
        );
    }
    let _ = writeln!(o, "cameras     {}", s.cameras.len());
    for (i, c) in s.cameras.iter().enumerate() {
        let proj = match c.projection {
            Projection::Perspective { yfov } => format!("perspective {:.1}°", yfov.to_degrees()),
            Projection::Orthographic { xmag, ymag } => format!("orthographic {xmag}x{ymag}"),
        };
        let _ = writeln!(
            o,
            "  [{i}] {:<20} {proj}  at {:.3?}  looking {:.3?}",
            c.name,
            c.position.to_array(),
            c.forward.to_array()
        );
    }
    o
}

fn main() {
    // Headless: Vulkan's window-system layer complains on stderr when there is no session
    // directory, although nothing here opens a window. Give it an empty one.
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
        // SAFETY: nothing else runs yet; no other thread can read the environment.
        unsafe { std::env::set_var("XDG_RUNTIME_DIR", std::env::temp_dir()) };
    }
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Render(a) => render(a),
        Command::Info(a) => info(a),
        Command::Bench(a) => bench(a),
        Command::Compare(a) => compare_images(a),
    };
    if let Err(e) = result {
        eprintln!("voxgi: error: {e:#}");
        std::process::exit(1);
    }
}

fn percentile(sorted: &[f64], p: f64) -> f64 {
    if sorted.is_empty() {
        return 0.0;
    }
    let i = ((sorted.len() - 1) as f64 * p).round() as usize;
    sorted[i]
}

fn bench(args: &BenchArgs) -> Result<()> {
    let label = scene_label(&args.scene);
    let (scene, table) = load_scene_and_settings(&args.scene)?;
    let mut settings = args
        .settings
        .to_settings(table.as_ref())
        .with_context(|| label.clone())?;
    settings.revoxelize_every_frame = args.revoxelize;
    let ctx = GpuContext::from_env()?;
    if !ctx.timestamps {
        bail!(
            "{} does not support GPU timestamp queries; voxgi bench needs them",
            ctx.info.name
        );
    }
    let mut renderer =
        Renderer::new(&ctx, &scene, settings.clone()).with_context(|| label.clone())?;
    renderer.enable_timing(true);
    let camera = renderer.default_camera().clone();
    let (w, h) = args.size;
    eprintln!(
        "bench: {label}, {w}x{h}, voxels {}³, {} frames after {} warm-up, on {} ({:?})",
        settings.voxel_resolution, args.frames, args.warmup, ctx.info.name, ctx.info.backend
    );
    let mut per_pass: Vec<(&'static str, Vec<f64>)> = Vec::new();
    let mut totals = Vec::new();
    let mut walls = Vec::new();
    let mut first_frame: Vec<(&'static str, f64)> = Vec::new();
    for i in 0..args.warmup + args.frames {
        // Wall time from recording to the timestamps' readback: the whole frame, CPU included,
        // whatever a driver's timestamps miss (lavapipe's read about 0 for some passes).
        let start = std::time::Instant::now();
        renderer.render_frame(&camera, w, h)?;
        let times = renderer.pass_times()?;
        let wall = start.elapsed().as_secs_f64() * 1e3;
        if i == 0 {
            first_frame = times.clone();
        }
        if i < args.warmup {
            continue;
        }
        totals.push(times.iter().map(|(_, ms)| ms).sum::<f64>());
        walls.push(wall);
        for (name, ms) in times {
            match per_pass.iter_mut().find(|(n, _)| *n == name) {
                Some(e) => e.1.push(ms),
                None => per_pass.push((name, vec![ms])),
            }
        }
        eprint!("\rframe {}/{}", i + 1 - args.warmup, args.frames);
    }
    eprintln!();
    let (fragments, occupied) = renderer.voxel_counts()?;
    let mut rows = Vec::new();
    println!(
        "{:<14} {:>10} {:>10} {:>8}",
        "pass", "median ms", "p95 ms", "frames"
    );
    for (name, v) in &mut per_pass {
        v.sort_by(f64::total_cmp);
        let (med, p95) = (percentile(v, 0.5), percentile(v, 0.95));
        println!("{name:<14} {med:>10.3} {p95:>10.3} {:>8}", v.len());
        rows.push(
            serde_json::json!({"name": name, "median_ms": med, "p95_ms": p95, "frames": v.len()}),
        );
    }
    totals.sort_by(f64::total_cmp);
    let (fmed, fp95) = (percentile(&totals, 0.5), percentile(&totals, 0.95));
    println!(
        "{:<14} {fmed:>10.3} {fp95:>10.3} {:>8}",
        "frame (GPU)",
        totals.len()
    );
    walls.sort_by(f64::total_cmp);
    let (wmed, wp95) = (percentile(&walls, 0.5), percentile(&walls, 0.95));
    println!(
        "{:<14} {wmed:>10.3} {wp95:>10.3} {:>8}",
        "frame (wall)",
        walls.len()
    );
    let update: Vec<(&'static str, f64)> = first_frame
        .iter()
        .filter(|(n, _)| !per_pass.iter().any(|(p, _)| p == n))
        .copied()
        .collect();
    if !update.is_empty() {
        let sum: f64 = update.iter().map(|(_, ms)| ms).sum();
        println!("scene update, first frame only: {sum:.3} ms");
        for (n, ms) in &update {
            println!("  {n:<12} {ms:>10.3}");
        }
    }
    let memory = renderer.memory();
    let total_bytes: u64 = memory.iter().map(|(_, b)| b).sum();
    println!("memory: {:.1} MiB total", total_bytes as f64 / 1048576.0);
    for (name, bytes) in &memory {
        println!("  {name:<36} {:>10.2} MiB", *bytes as f64 / 1048576.0);
    }
    println!("voxels: {fragments} fragments, {occupied} occupied voxels");
    if let Some(path) = &args.json {
        let json = serde_json::json!({
            "adapter": ctx.info.name,
            "backend": format!("{:?}", ctx.info.backend),
            "device_type": format!("{:?}", ctx.info.device_type),
            "driver": ctx.info.driver,
            "scene": label,
            "size": [w, h],
            "frames": args.frames,
            "settings": {
                "voxel_resolution": settings.voxel_resolution,
                "anisotropic": settings.anisotropic,
                "cones": settings.cones.name(),
                "bounces": settings.bounces,
                "gather_axes": settings.gather_axes,
                "half_resolution": settings.half_resolution,
                "cone_shadows": settings.cone_shadows,
                "revoxelize_every_frame": settings.revoxelize_every_frame,
                "shadow_map_size": settings.shadow_map_size,
                "step_factor": settings.step_factor,
            },
            "passes": rows,
            "first_frame_ms": first_frame.iter().map(|(n, ms)| serde_json::json!({"name": n, "ms": ms})).collect::<Vec<_>>(),
            "frame_ms": {"median": fmed, "p95": fp95},
            "wall_ms": {"median": wmed, "p95": wp95},
            "memory_bytes": memory.iter().map(|(n, b)| serde_json::json!({"name": n, "bytes": b})).collect::<Vec<_>>(),
            "voxels": {"fragments": fragments, "occupied": occupied},
        });
        std::fs::write(path, serde_json::to_string_pretty(&json)? + "\n")
            .with_context(|| format!("{}", path.display()))?;
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}
