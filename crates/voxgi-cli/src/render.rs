//! `voxgi render`: one image of a scene, by the real-time renderer or the path tracer.

use crate::args::{
    Progress, SceneArg, SettingsArgs, load_scene_and_settings, parse_size, parse_vec3, scene_label,
};
use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};
use std::path::{Path, PathBuf};
use std::time::Instant;
use voxgi::headless::{self, GpuContext};
use voxgi::scene::glam::Vec3;
use voxgi::scene::{Camera, Projection, Scene};
use voxgi::{Bounces, PathTracer, ReferenceMode, ReferenceOptions};

#[derive(Args)]
pub struct RenderArgs {
    #[command(flatten)]
    pub scene: SceneArg,
    /// Output image; the extension picks the format (.png or .exr). With --frames, a pattern
    /// with the frame number as %d or %04d (e.g. out_%04d.png).
    #[arg(short, long, value_name = "FILE")]
    pub output: PathBuf,
    /// Image size in pixels.
    #[arg(long, value_name = "WxH", default_value = "512x512", value_parser = parse_size)]
    pub size: (u32, u32),
    #[command(flatten)]
    pub settings: SettingsArgs,
    /// Camera position, overriding the scene's camera (metres).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub eye: Option<Vec3>,
    /// Point the camera looks at.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub target: Option<Vec3>,
    /// Vertical field of view in degrees.
    #[arg(long, value_name = "DEGREES")]
    pub fov: Option<f32>,
    /// Which of the scene's cameras to use (by index, see `voxgi info`).
    #[arg(long, value_name = "N")]
    pub camera: Option<usize>,
    /// Renderer: the real-time rasterizer, the reference path tracer, or the AO reference.
    #[arg(long, value_enum, default_value_t = ModeArg::Raster)]
    pub mode: ModeArg,
    /// Reference modes: samples per pixel.
    #[arg(long, value_name = "N", default_value_t = 256)]
    pub spp: u32,
    /// Reference modes: random seed (the same seed gives the same image).
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub seed: u32,
    /// The scene's animations at this time, in seconds (default 0: the rest pose); with
    /// --frames, the first frame's time.
    #[arg(long, value_name = "SECONDS", default_value_t = 0.0)]
    pub time: f32,
    /// Render an image sequence of N frames, one renderer updated from frame to frame (only
    /// what moved is re-voxelized); an animated camera flies along.
    #[arg(long, value_name = "N")]
    pub frames: Option<u32>,
    /// Frames per second of scene time in a sequence.
    #[arg(long, value_name = "F", default_value_t = 30.0, requires = "frames")]
    pub fps: f32,
    /// With temporal accumulation (the default): the still is the mean of N frames of the
    /// same instant, jittered within the pixel, with the cones turned and new points on area
    /// lights (default 64, at most 256). 1 renders a single frame. A sequence (--frames)
    /// instead renders one frame per step, the history carried from frame to frame as in the
    /// viewer.
    #[arg(long, value_name = "N", conflicts_with = "frames")]
    pub accumulate: Option<u32>,
}

/// The path of frame `k` of an output pattern: its one `%d` or `%0Nd` replaced by `k`.
pub fn frame_path(pattern: &Path, k: u32) -> Result<PathBuf> {
    let text = pattern.to_string_lossy();
    let Some(start) = text.find('%') else {
        bail!(
            "{}: an image sequence needs the frame number in the name, as %d or %04d \
             (e.g. out_%04d.png)",
            pattern.display()
        );
    };
    let rest = &text[start + 1..];
    let digits: String = rest.chars().take_while(|c| c.is_ascii_digit()).collect();
    if !rest[digits.len()..].starts_with('d') {
        bail!(
            "{}: the frame number must be written %d or %0Nd",
            pattern.display()
        );
    }
    if text[start + 2 + digits.len()..].contains('%') {
        bail!("{}: only one % is allowed", pattern.display());
    }
    let width: usize = digits.parse().unwrap_or(0);
    Ok(PathBuf::from(format!(
        "{}{k:0width$}{}",
        &text[..start],
        &text[start + 2 + digits.len()..]
    )))
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ModeArg {
    Raster,
    Reference,
    AoReference,
}

pub fn run(args: &RenderArgs) -> Result<()> {
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
    let times: Vec<f32> = match args.frames {
        None => vec![args.time],
        Some(0) => bail!("--frames 0: nothing to render"),
        Some(n) => {
            if !(args.fps.is_finite() && args.fps > 0.0) {
                bail!("--fps {} must be a positive number", args.fps);
            }
            (0..n).map(|k| args.time + k as f32 / args.fps).collect()
        }
    };
    let first = if args.frames.is_some() {
        frame_path(&args.output, 0)?
    } else {
        args.output.clone()
    };
    check_writable(&first)?;
    let label = scene_label(&args.scene);
    let (scene, table) = p.stage(&format!("loading {label}"), || {
        load_scene_and_settings(&args.scene)
    })?;
    if args.accumulate == Some(0) {
        bail!("--accumulate 0: a still needs at least one frame");
    }
    if let Some(n) = args
        .accumulate
        .filter(|&n| n > voxgi::TEMPORAL_STILL_FRAMES)
    {
        bail!(
            "--accumulate {n}: at most {} (a still has converged there)",
            voxgi::TEMPORAL_STILL_FRAMES
        );
    }
    if !args.time.is_finite() {
        bail!("--time {} is not a finite number of seconds", args.time);
    }
    let mut scene = scene;
    scene.set_time(times[0]);
    scene
        .load_frames_at(times[0])
        .with_context(|| label.clone())?;
    let camera = pick_camera(&scene, args, times[0])?;
    let (options, frame) = args
        .settings
        .resolve(table.as_ref(), camera)
        .with_context(|| label.clone())?;
    let ctx = p.stage("opening GPU", GpuContext::from_env)?;
    eprintln!("GPU: {} ({:?})", ctx.info.name, ctx.info.backend);
    let (w, h) = args.size;
    if args.frames.is_some() {
        return render_sequence(args, &ctx, &mut scene, &options, &frame, &times, &p);
    }
    let out = if args.mode == ModeArg::Raster {
        let mut renderer = p
            .stage("uploading scene", || ctx.renderer(&scene, &options))
            .with_context(|| label.clone())?;
        let accumulate = args.accumulate.unwrap_or(headless::DEFAULT_ACCUMULATE);
        let what = if options.temporal && accumulate > 1 {
            format!("rendering {w}x{h}, {accumulate} frames accumulated")
        } else {
            format!("rendering {w}x{h}")
        };
        // One image of a still scene: progressive bounces run to convergence (a sequence
        // shows them building up frame by frame instead, as an application would).
        p.stage(&what, || {
            headless::render_still(&ctx, &mut renderer, &frame, w, h, accumulate)
        })?
    } else {
        let opts = reference_options(args, &scene, &options);
        let mut tracer = p
            .stage("uploading scene and building the BVH", || {
                ctx.watch.check()?;
                ctx.watch
                    .explain(PathTracer::new(&ctx.device, &ctx.queue, &scene, &options))
            })
            .with_context(|| label.clone())?;
        eprintln!(
            "path tracing {w}x{h}, {} spp, {} triangles and discs",
            opts.spp,
            tracer.primitive_count()
        );
        let t = Instant::now();
        let mut last = 0.0;
        let out = ctx
            .watch
            .explain(tracer.render(&frame, w, h, &opts, &mut |done, total| {
                let el = t.elapsed().as_secs_f64();
                if el - last >= 1.0 || done == total {
                    last = el;
                    let eta = el / done as f64 * (total - done) as f64;
                    eprint!("\r  {done}/{total} spp  {el:.1} s elapsed  ETA {eta:.1} s   ");
                }
            }))?;
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

fn reference_options(
    args: &RenderArgs,
    scene: &Scene,
    options: &voxgi::RendererOptions,
) -> ReferenceOptions {
    ReferenceOptions {
        spp: args.spp,
        bounces: Bounces::matching(options.bounces),
        mode: if args.mode == ModeArg::AoReference {
            ReferenceMode::Ao {
                // The cone tracer's AO radius, so the two are comparable.
                radius: options.ao_radius.unwrap_or_else(|| {
                    let b = scene.swept_bounds();
                    voxgi::voxel::Grid::around(b.min, b.max, options.voxel_resolution).extent()
                        * 0.25
                }),
            }
        } else {
            ReferenceMode::Radiance
        },
        seed: args.seed,
    }
}

/// An image sequence: one renderer, moved to each frame's time (`Renderer::set_time`), or one
/// path-traced image per frame. A line of progress with the ETA.
fn render_sequence(
    args: &RenderArgs,
    ctx: &GpuContext,
    scene: &mut Scene,
    options: &voxgi::RendererOptions,
    frame: &voxgi::FrameParams,
    times: &[f32],
    p: &Progress,
) -> Result<()> {
    let (w, h) = args.size;
    let label = scene_label(&args.scene);
    let mut renderer = if args.mode == ModeArg::Raster {
        Some(
            p.stage("uploading scene", || ctx.renderer(scene, options))
                .with_context(|| label.clone())?,
        )
    } else {
        None
    };
    let n = times.len();
    eprintln!(
        "rendering {n} frames of {w}x{h} at {} frames/s, t = {:.3} .. {:.3} s",
        args.fps,
        times[0],
        times[n - 1]
    );
    let start = Instant::now();
    let mut frame = frame.clone();
    for (k, &t) in times.iter().enumerate() {
        // A camera that flies takes its place at this frame's time.
        frame.camera = pick_camera(scene, args, t)?;
        let frame = &frame;
        let out = match &mut renderer {
            Some(r) => {
                r.set_time(t)?;
                headless::render(ctx, r, frame, w, h)?
            }
            None => {
                scene.set_time(t);
                scene.load_frames_at(t)?;
                ctx.watch.check()?;
                let mut tracer =
                    ctx.watch
                        .explain(PathTracer::new(&ctx.device, &ctx.queue, scene, options))?;
                let opts = reference_options(args, scene, options);
                ctx.watch
                    .explain(tracer.render(frame, w, h, &opts, &mut |_, _| {}))?
            }
        };
        let path = frame_path(&args.output, k as u32)?;
        out.save(&path)?;
        let el = start.elapsed().as_secs_f64();
        let done = k + 1;
        let eta = el / done as f64 * (n - done) as f64;
        eprint!("\r  frame {done}/{n}  t = {t:.3} s  {el:.1} s elapsed  ETA {eta:.1} s   ");
    }
    eprintln!(
        "\nwrote {} .. {} in {:.2} s",
        frame_path(&args.output, 0)?.display(),
        frame_path(&args.output, n as u32 - 1)?.display(),
        p.start.elapsed().as_secs_f64()
    );
    Ok(())
}

/// The camera of the frame at time `t`: the chosen camera of the scene (`--camera`, else its
/// default) where its animation puts it then, with `--eye`, `--target` and `--fov` applied.
fn pick_camera(scene: &Scene, args: &RenderArgs, t: f32) -> Result<Camera> {
    let mut cam = match args.camera {
        Some(i) => scene.camera_at(i, t).with_context(|| {
            format!(
                "camera {i} does not exist (the scene has {})",
                scene.cameras.len()
            )
        })?,
        None => scene
            .camera_at(0, t)
            .unwrap_or_else(|| scene.default_camera()),
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

/// Fails before any rendering when `path` cannot be written: its folder is missing or
/// read-only, or it names a folder.
fn check_writable(path: &Path) -> Result<()> {
    if path.is_dir() {
        bail!("{}: is a directory, not an image file", path.display());
    }
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    if !dir.is_dir() {
        bail!(
            "{}: the folder {} does not exist",
            path.display(),
            dir.display()
        );
    }
    let existed = path.exists();
    std::fs::OpenOptions::new()
        .append(true)
        .create(true)
        .open(path)
        .with_context(|| format!("{}: cannot write here", path.display()))?;
    if !existed {
        // Leave no empty file behind if the render then fails.
        let _ = std::fs::remove_file(path);
    }
    Ok(())
}
