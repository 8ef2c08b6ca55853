//! `voxgi bench`: GPU timestamps per pass over many frames, a table and JSON.

use crate::args::{SceneArg, SettingsArgs, load_scene_and_settings, parse_size, scene_label};
use anyhow::{Context, Result, bail};
use clap::Args;
use std::io::Write;
use std::path::PathBuf;
use voxgi::headless::{self, GpuContext};
use voxgi::{Target, VoxelCounts, wgpu};

#[derive(Args)]
pub struct BenchArgs {
    #[command(flatten)]
    pub scene: SceneArg,
    /// Image size in pixels.
    #[arg(long, value_name = "WxH", default_value = "1280x720", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Frames timed (after the warm-up). With temporal accumulation a still view stops
    /// rendering after 256 still frames (it has converged): time a still with fewer, or animate.
    #[arg(long, value_name = "N", default_value_t = 20,
          value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    pub frames: u32,
    /// Frames rendered before timing starts.
    #[arg(long, value_name = "N", default_value_t = 2)]
    pub warmup: u32,
    /// Rebuild everything every frame, static geometry included (as if every object moved).
    #[arg(long)]
    pub revoxelize: bool,
    /// Play the scene's animations: each frame advances the scene's time by 1/--fps, and only
    /// what moved is updated; an animated camera flies along.
    #[arg(long)]
    pub animate: bool,
    /// Frames per second of scene time with --animate.
    #[arg(long, value_name = "F", default_value_t = 30.0)]
    pub fps: f32,
    /// Scene time of the first frame, seconds.
    #[arg(long, value_name = "SECONDS", default_value_t = 0.0)]
    pub time: f32,
    /// Write the results as JSON here.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    /// Write the timed frames' pass scopes as a Chrome trace here (open it in chrome://tracing
    /// or ui.perfetto.dev).
    #[arg(long, value_name = "FILE")]
    pub trace: Option<PathBuf>,
    #[command(flatten)]
    pub settings: SettingsArgs,
}

fn percentile(sorted: &[f64], p: f64) -> f64 {
    if sorted.is_empty() {
        return 0.0;
    }
    let i = ((sorted.len() - 1) as f64 * p).round() as usize;
    sorted[i]
}

pub fn run(args: &BenchArgs) -> Result<()> {
    let label = scene_label(&args.scene);
    let (mut scene, table) = load_scene_and_settings(&args.scene)?;
    if !(args.fps.is_finite() && args.fps > 0.0 && args.time.is_finite()) {
        bail!("--fps must be positive and --time finite");
    }
    if args.animate && scene.animations.is_empty() && scene.sequences.is_empty() {
        bail!("{label} has no animations or point sequences to play (--animate)");
    }
    scene.set_time(args.time);
    scene
        .load_frames_at(args.time)
        .with_context(|| label.clone())?;
    let camera = scene.default_camera();
    let (settings, mut frame) = args
        .settings
        .resolve(table.as_ref(), camera)
        .with_context(|| label.clone())?;
    let ctx = GpuContext::from_env()?;
    if !ctx.timestamps {
        bail!(
            "{} does not support GPU timestamp queries; voxgi bench needs them",
            ctx.info.name
        );
    }
    // The CPU's share of a point cloud, timed apart: its attributes, then the upload (which
    // includes each point's surface spread).
    let points = (scene.point_count() > 0).then(|| {
        eprintln!(
            "bench: estimating the attributes of {} points …",
            scene.point_count()
        );
        voxgi::prepare_points(&mut scene)
    });
    let upload = std::time::Instant::now();
    let mut renderer = ctx
        .renderer(&scene, &settings)
        .with_context(|| label.clone())?;
    let upload = upload.elapsed().as_secs_f64() * 1e3;
    renderer.enable_timing(true);
    let (w, h) = args.size;
    let texture = ctx.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("bench output"),
        size: wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: headless::OUTPUT_FORMAT,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
        view_formats: &[],
    });
    let view = texture.create_view(&Default::default());
    let target = Target::new(&view, headless::OUTPUT_FORMAT, w, h);
    eprintln!(
        "bench: {label}, {w}x{h}, {} voxels {}³, {} frames after {} warm-up, on {} ({:?})",
        settings.voxels.name(),
        settings.voxel_resolution,
        args.frames,
        args.warmup,
        ctx.info.name,
        ctx.info.backend
    );
    let mut per_pass: Vec<(&'static str, Vec<f64>)> = Vec::new();
    let mut totals = Vec::new();
    let (mut voxel_sums, mut screen_sums, mut gi_sums) = (Vec::new(), Vec::new(), Vec::new());
    // The indirect light's passes: the voxel update, the blend of its light and the per-pixel
    // gather with its upsample (not the G-buffer, the composite, accumulation or tone mapping).
    let gi_passes: Vec<&str> = voxgi::voxel_passes()
        .iter()
        .copied()
        .chain(["blend", "gather", "upsample"])
        .collect();
    let mut walls = Vec::new();
    let mut sequence_frames: Vec<voxgi::SequenceFrame> = Vec::new();
    let mut first_frame: Vec<(&'static str, f64)> = Vec::new();
    let voxel_passes = voxgi::voxel_passes();
    let flies = scene.camera_is_animated(0);
    for i in 0..args.warmup + args.frames {
        if i == args.warmup && args.trace.is_some() {
            renderer.keep_pass_trace();
        }
        // Wall time from recording to the timestamps' readback: the whole frame, CPU included,
        // whatever a driver's timestamps miss (lavapipe's read about 0 for some passes).
        let start = std::time::Instant::now();
        if args.revoxelize {
            renderer.invalidate();
        }
        if args.animate {
            let t = args.time + i as f32 / args.fps;
            let frames = renderer.set_time(t)?;
            if i >= args.warmup {
                sequence_frames.extend(frames);
            }
            // A flight: the scene's camera where its animation puts it.
            if let Some(c) = scene.camera_at(0, t).filter(|_| flies) {
                frame.camera = c;
            }
        }
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        renderer.render(&mut encoder, &target, &frame)?;
        ctx.queue.submit([encoder.finish()]);
        let times = renderer.pass_times()?;
        ctx.take_error("frame")?;
        let wall = start.elapsed().as_secs_f64() * 1e3;
        if i == 0 {
            first_frame = times.clone();
        }
        if i < args.warmup {
            continue;
        }
        totals.push(times.iter().map(|(_, ms)| ms).sum::<f64>());
        let voxel: f64 = times
            .iter()
            .filter(|(n, _)| voxel_passes.contains(n))
            .map(|(_, ms)| ms)
            .sum();
        voxel_sums.push(voxel);
        gi_sums.push(
            times
                .iter()
                .filter(|(n, _)| gi_passes.contains(n))
                .map(|(_, ms)| ms)
                .sum::<f64>(),
        );
        screen_sums.push(totals[totals.len() - 1] - voxel);
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
    if let Some(path) = &args.trace {
        renderer
            .write_pass_trace(path)
            .with_context(|| format!("writing the trace {}", path.display()))?;
        eprintln!("bench: pass trace in {}", path.display());
    }
    let VoxelCounts {
        fragments,
        occupied,
    } = renderer.voxel_counts()?;
    let mut rows = Vec::new();
    println!(
        "{:<14} {:>10} {:>10} {:>8}",
        "pass", "median ms", "p95 ms", "frames"
    );
    // Voxel passes first, in the order they run; a pass that ran in only some frames says in
    // how many (its median is over those).
    per_pass.sort_by_key(|(n, _)| {
        voxel_passes
            .iter()
            .position(|v| v == n)
            .unwrap_or(voxel_passes.len())
    });
    for (name, v) in &mut per_pass {
        v.sort_by(f64::total_cmp);
        let (med, p95) = (percentile(v, 0.5), percentile(v, 0.95));
        println!("{name:<14} {med:>10.3} {p95:>10.3} {:>8}", v.len());
        rows.push(
            serde_json::json!({"name": name, "median_ms": med, "p95_ms": p95, "frames": v.len()}),
        );
    }
    let mut sums = Vec::new();
    for (name, v) in [
        ("voxel update", &mut voxel_sums),
        ("screen", &mut screen_sums),
        ("GI", &mut gi_sums),
    ] {
        v.sort_by(f64::total_cmp);
        let (med, p95) = (percentile(v, 0.5), percentile(v, 0.95));
        println!("{name:<14} {med:>10.3} {p95:>10.3} {:>8}", v.len());
        sums.push(serde_json::json!({"name": name, "median_ms": med, "p95_ms": p95}));
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
    println!("scene upload (CPU and GPU): {upload:.0} ms");
    if let Some(p) = &points {
        println!(
            "points: {} estimated; neighbours {:.0} ms, normals {:.0} ms, regions {:.0} ms, radii \
             {:.0} ms (CPU, {} threads)",
            p.points,
            p.neighbours.as_secs_f64() * 1e3,
            p.normals.as_secs_f64() * 1e3,
            p.regions.as_secs_f64() * 1e3,
            p.radii.as_secs_f64() * 1e3,
            std::thread::available_parallelism().map_or(1, |n| n.get())
        );
    }
    let sequences = sequence_summary(&sequence_frames);
    if let Some(path) = &args.json {
        let json = serde_json::json!({
            "adapter": ctx.info.name,
            "backend": format!("{:?}", ctx.info.backend),
            "device_type": format!("{:?}", ctx.info.device_type),
            "driver": ctx.info.driver,
            "scene": label,
            "size": [w, h],
            "frames": args.frames,
            "settings": settings_json(&settings, &frame, args),
            "passes": rows,
            "sums": sums,
            "first_frame_ms": first_frame.iter().map(|(n, ms)| serde_json::json!({"name": n, "ms": ms})).collect::<Vec<_>>(),
            "frame_ms": {"median": fmed, "p95": fp95},
            "wall_ms": {"median": wmed, "p95": wp95},
            "memory_bytes": memory.iter().map(|(n, b)| serde_json::json!({"name": n, "bytes": b})).collect::<Vec<_>>(),
            "voxels": {"fragments": fragments, "occupied": occupied},
            "upload_ms": upload,
            "points": points.map(|p| serde_json::json!({
                "estimated": p.points,
                "neighbours_ms": p.neighbours.as_secs_f64() * 1e3,
                "normals_ms": p.normals.as_secs_f64() * 1e3,
                "regions_ms": p.regions.as_secs_f64() * 1e3,
                "radii_ms": p.radii.as_secs_f64() * 1e3,
            })),
            "sequence_frames": sequences,
        });
        let text = serde_json::to_string_pretty(&json)? + "\n";
        voxgi::scene::io::atomic::replace_with(path, |w| w.write_all(text.as_bytes()))
            .with_context(|| format!("writing {}", path.display()))?;
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}

/// The point sequences' frames the measured frames loaded (`Renderer::set_time`): printed as
/// medians per new frame, and returned for the JSON (null when none changed).
fn sequence_summary(frames: &[voxgi::SequenceFrame]) -> serde_json::Value {
    if frames.is_empty() {
        return serde_json::Value::Null;
    }
    let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
    let median = |f: &dyn Fn(&voxgi::SequenceFrame) -> f64| {
        let mut v: Vec<f64> = frames.iter().map(f).collect();
        v.sort_by(f64::total_cmp);
        percentile(&v, 0.5)
    };
    let points = median(&|f| f.points as f64);
    let waited = median(&|f| ms(f.waited));
    let neighbours = median(&|f| ms(f.prepared.neighbours));
    let normals = median(&|f| ms(f.prepared.normals));
    let regions = median(&|f| ms(f.prepared.regions));
    let radii = median(&|f| ms(f.prepared.radii));
    let spread = median(&|f| ms(f.prepared.spread));
    let set = median(&|f| ms(f.set));
    println!(
        "point sequences: {} new frames of {points:.0} points (medians, CPU): waiting for the \
         file {waited:.1} ms; set_points {set:.1} ms; estimated ahead (on the reading thread): \
         neighbours {neighbours:.0}, normals {normals:.0}, regions {regions:.0}, radii \
         {radii:.0}, spread {spread:.0}",
        frames.len()
    );
    serde_json::json!({
        "count": frames.len(),
        "points": points,
        "waited_ms": waited,
        "set_points_ms": set,
        "neighbours_ms": neighbours,
        "normals_ms": normals,
        "regions_ms": regions,
        "radii_ms": radii,
        "spread_ms": spread,
    })
}

/// Every setting of the table with its value in this run (as the scene file writes it), and
/// the bench's own choices.
fn settings_json(
    o: &voxgi::RendererOptions,
    f: &voxgi::FrameParams,
    args: &BenchArgs,
) -> serde_json::Value {
    use voxgi::settings::{SETTINGS, Value};
    let mut m = serde_json::Map::new();
    for s in SETTINGS {
        let v = match s.value(o, f) {
            Value::Bool(b) => serde_json::json!(b),
            Value::Int(voxgi::UNLIMITED_BOUNCES) => serde_json::json!("unlimited"),
            Value::Int(n) => serde_json::json!(n),
            Value::Float(x) | Value::Auto(Some(x)) => serde_json::json!(x),
            Value::Auto(None) => serde_json::json!("auto"),
            Value::Name(n) => serde_json::json!(n),
            Value::Rgb(c) => serde_json::json!(c),
        };
        m.insert(s.key.into(), v);
    }
    m.insert("revoxelize_every_frame".into(), args.revoxelize.into());
    m.insert("animate".into(), args.animate.into());
    m.insert("fps".into(), args.fps.into());
    serde_json::Value::Object(m)
}
