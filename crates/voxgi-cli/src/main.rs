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
    long_about = "voxgi renders meshes and point clouds with direct light, shadows and (soon) \
                  voxel-cone-traced indirect light, headless, on any Vulkan, Metal or DX12 device \
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
    /// Exposure in stops (EV): the image is scaled by 2^EV before tone mapping.
    #[arg(
        long,
        value_name = "EV",
        default_value_t = 0.0,
        allow_hyphen_values = true
    )]
    exposure: f32,
    /// Tone-mapping curve for PNG output.
    #[arg(long, value_enum, default_value_t = TonemapArg::Aces)]
    tonemap: TonemapArg,
    /// What to show.
    #[arg(long, value_enum, default_value_t = ViewArg::Final)]
    view: ViewArg,
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
    /// Shadow map resolution per view, in texels.
    #[arg(long, value_name = "N", default_value_t = Settings::default().shadow_map_size)]
    shadow_map_size: u32,
    /// Renderer: the real-time rasterizer, the reference path tracer, or the AO reference.
    #[arg(long, value_enum, default_value_t = ModeArg::Raster)]
    mode: ModeArg,
    /// Reference modes: samples per pixel.
    #[arg(long, value_name = "N", default_value_t = 256)]
    spp: u32,
    /// Reference mode: indirect bounces (direct = what the rasterizer computes).
    #[arg(long, value_enum, default_value_t = BouncesArg::Unlimited)]
    bounces: BouncesArg,
    /// AO reference: how far (metres) a ray must travel unblocked to count as unoccluded.
    #[arg(long, value_name = "METRES", default_value_t = 1.0)]
    ao_radius: f32,
    /// Reference modes: random seed (the same seed gives the same image).
    #[arg(long, value_name = "N", default_value_t = 0)]
    seed: u32,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum ModeArg {
    Raster,
    Reference,
    AoReference,
}

#[derive(Clone, Copy, ValueEnum)]
enum BouncesArg {
    Direct,
    #[value(name = "1")]
    One,
    Unlimited,
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
    match (&arg.scene, &arg.builtin) {
        (_, Some(name)) => Ok(builtin::by_name(name)?),
        (Some(path), None) => Ok(io::load(path)?),
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
    let scene = p.stage(&format!("loading {label}"), || load_scene(&args.scene))?;
    let settings = Settings {
        exposure: args.exposure,
        shadow_map_size: args.shadow_map_size,
        tonemap: match args.tonemap {
            TonemapArg::Aces => Tonemap::Aces,
            TonemapArg::Neutral => Tonemap::Neutral,
            TonemapArg::Clamp => Tonemap::Clamp,
        },
        view: match args.view {
            ViewArg::Final => ViewMode::Final,
            ViewArg::Albedo => ViewMode::Albedo,
            ViewArg::Normal => ViewMode::Normal,
            ViewArg::Direct => ViewMode::Direct,
        },
        ..Settings::default()
    };
    settings.validate()?;
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
            bounces: match args.bounces {
                BouncesArg::Direct => Bounces::DirectOnly,
                BouncesArg::One => Bounces::One,
                BouncesArg::Unlimited => Bounces::Unlimited,
            },
            mode: if args.mode == ModeArg::AoReference {
                ReferenceMode::Ao {
                    radius: args.ao_radius,
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
        let near = cam.znear;
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
        Command::Compare(a) => compare_images(a),
    };
    if let Err(e) = result {
        eprintln!("voxgi: error: {e:#}");
        std::process::exit(1);
    }
}
