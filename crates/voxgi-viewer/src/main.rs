//! `voxgi-viewer`: a window onto a voxgi scene. Orbit or fly, change settings and lights, play
//! animations, watch per-pass GPU times. Built on voxgi's public API only: the viewer owns the
//! device, the window and the frame, as any application would.

mod camera;
mod ground_truth;
mod jobs;
mod settings;
mod viewer;

use anyhow::{Context, Result, bail};
use clap::Parser;
use std::path::PathBuf;
use voxgi::scene::{Scene, builtin, io};

/// An interactive window onto a voxgi scene.
#[derive(Parser, Debug, Clone)]
#[command(name = "voxgi-viewer", version)]
pub struct Args {
    /// Scene file: .gltf, .glb, .obj, .ply, .pcd, .cloud or .toml (or drop one onto the window).
    #[arg(conflicts_with = "builtin")]
    pub scene: Option<PathBuf>,
    /// A built-in scene instead: cornell-box, open-plane, closed-box, two-rooms, cube,
    /// point-cave. Default cornell-box when no file is given.
    #[arg(long, value_name = "NAME")]
    pub builtin: Option<String>,
    /// Window size in pixels. Default 1280x720 on a GPU, 960x480 on a CPU driver (the 3D view
    /// is what the settings panel leaves of it).
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// Write the frame to this PNG after --after-frames frames and exit (for tests and
    /// reproducible shots; the window is real).
    #[arg(long, value_name = "FILE")]
    pub screenshot: Option<PathBuf>,
    /// Frames to render before --screenshot.
    #[arg(long, value_name = "N", default_value_t = 3, requires = "screenshot")]
    pub after_frames: u32,
    /// --screenshot shows the settings panel too (as the window does); without it, only the
    /// rendered scene.
    #[arg(long, requires = "screenshot")]
    pub with_ui: bool,
    /// Draw the ground grid in --screenshot's image too (the window shows it; K toggles it).
    #[arg(long, requires = "screenshot")]
    pub grid: bool,
    /// Present without waiting for the display's refresh.
    #[arg(long)]
    pub no_vsync: bool,
    /// What the window shows: cone tracing, voxgi's path tracer, or both split by a divider
    /// (G cycles through them).
    #[arg(long, value_enum, default_value_t = ground_truth::Display::ConeTraced)]
    pub display: ground_truth::Display,
    /// Paths the path tracer traces a frame (a band of rows when fewer than the image has).
    /// Default: adapted so that tracing takes about 10 ms of GPU time a frame, or on a CPU
    /// driver so that a still view's frames take about 100 ms (input is answered that often).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1024..=1 << 26))]
    pub paths_per_frame: Option<u32>,
    /// Turn the orbit camera by this many degrees each frame: a turntable, for demos and for
    /// measuring the frame rate of a moving view.
    #[arg(
        long,
        value_name = "DEG",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    pub turntable: f32,
    /// Where the split view's divider starts, as a fraction of the 3D view's width (right of
    /// the panel).
    #[arg(long, value_name = "F", default_value_t = 0.5, value_parser = parse_fraction)]
    pub divider: f32,
}

fn parse_fraction(s: &str) -> Result<f32, String> {
    let f: f32 = s
        .trim()
        .parse()
        .map_err(|_| format!("'{s}' is not a number"))?;
    if !(0.0..=1.0).contains(&f) {
        return Err(format!("{f} is not within 0..=1"));
    }
    Ok(f)
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("'{s}' is not WIDTHxHEIGHT (e.g. 960x540)"))?;
    let w: u32 = w.trim().parse().map_err(|_| format!("bad width '{w}'"))?;
    let h: u32 = h.trim().parse().map_err(|_| format!("bad height '{h}'"))?;
    if !(64..=8192).contains(&w) || !(64..=8192).contains(&h) {
        return Err(format!("{w}x{h}: width and height must be 64..=8192"));
    }
    Ok((w, h))
}

/// A scene and its file's `[settings]` table, if it has one.
pub fn load(
    path: Option<&std::path::Path>,
    builtin_name: Option<&str>,
) -> Result<(Scene, Option<voxgi::SceneSettings>)> {
    match (path, builtin_name) {
        (Some(p), _) => {
            let is_toml = p
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("toml"));
            if is_toml {
                let (scene, table) = io::scene_file::load_with_settings(p)?;
                scene.validate().map_err(|e| e.in_file(p))?;
                let settings = table
                    .as_ref()
                    .map(voxgi::SceneSettings::from_table)
                    .transpose()
                    .with_context(|| p.display().to_string())?;
                Ok((scene, settings))
            } else {
                Ok((io::load(p)?, None))
            }
        }
        (None, name) => Ok((builtin::by_name(name.unwrap_or("cornell-box"))?, None)),
    }
}

fn main() {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    if let Err(e) = run(Args::parse()) {
        eprintln!("voxgi-viewer: error: {e:#}");
        std::process::exit(1);
    }
}

fn run(args: Args) -> Result<()> {
    // Fail on a bad scene before any window opens.
    let loaded = load(args.scene.as_deref(), args.builtin.as_deref())?;
    if let Some(p) = &args.screenshot
        && p.extension().is_none_or(|e| !e.eq_ignore_ascii_case("png"))
    {
        bail!("{}: --screenshot writes a .png", p.display());
    }
    let event_loop = winit::event_loop::EventLoop::new()
        .context("cannot open a window (is there a display? try xvfb-run)")?;
    let mut app = viewer::App::new(args, loaded);
    event_loop.run_app(&mut app)?;
    app.finish()
}
