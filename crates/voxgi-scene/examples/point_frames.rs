//! Writes a point sequence (one PLY file per frame, positions and colours, no normals) from one
//! point file or mesh, for trying and measuring point sequences (`file = "…_%04d.ply"` in a
//! scene file): each frame a fresh random subset of the input's points (a sensor scanning
//! again), optionally twisted about the vertical axis through its centre by an angle that
//! swings over the frames (a deforming object).
//!
//!   cargo run --release -p voxgi-scene --example point_frames -- \
//!       ../shared/scenes/stanford_dragon_100k/dragon.ply target/frames/dragon \
//!       --frames 24 --twist 40
//!
//! Options: `--frames N` (default 16), `--points N` (per frame; default all the input's),
//! `--twist DEGREES` (the largest twist, top against bottom; default 0).

use std::io::Write;
use std::path::PathBuf;
use voxgi_scene::glam::{Mat4, Vec3};

fn main() {
    if let Err(e) = run() {
        eprintln!("point_frames: {e}");
        std::process::exit(1);
    }
}

fn run() -> Result<(), String> {
    let mut args = std::env::args().skip(1);
    let (input, out) = match (args.next(), args.next()) {
        (Some(i), Some(o)) => (PathBuf::from(i), PathBuf::from(o)),
        _ => {
            return Err(
                "usage: point_frames INPUT OUT_DIR [--frames N] [--points N] [--twist DEG]".into(),
            );
        }
    };
    let (mut frames, mut per_frame, mut twist) = (16usize, None, 0.0f32);
    while let Some(flag) = args.next() {
        let value = args.next().ok_or(format!("{flag} needs a value"))?;
        let bad = || format!("{flag} {value}: not a number");
        match flag.as_str() {
            "--frames" => frames = value.parse().map_err(|_| bad())?,
            "--points" => per_frame = Some(value.parse::<usize>().map_err(|_| bad())?),
            "--twist" => twist = value.parse().map_err(|_| bad())?,
            _ => return Err(format!("unknown option {flag}")),
        }
    }
    if frames == 0 || frames > 100_000 || !twist.is_finite() {
        return Err("--frames must be 1 to 100000 and --twist finite".into());
    }
    let mut scene = voxgi_scene::io::load(&input).map_err(|e| e.to_string())?;
    if scene.point_clouds.is_empty() {
        scene = voxgi_scene::pointcloud::mesh_vertices(&scene);
    }
    let (mut points, mut colors) = (Vec::new(), Vec::new());
    for pc in &scene.point_clouds {
        points.extend(
            pc.positions
                .iter()
                .map(|&p| pc.transform.transform_point3(p)),
        );
        colors.extend(pc.colors.iter().copied());
    }
    if points.is_empty() {
        return Err(format!("{} holds no points or vertices", input.display()));
    }
    let n = per_frame.unwrap_or(points.len()).min(points.len());
    let (lo, hi) = points.iter().fold((Vec3::MAX, Vec3::MIN), |(lo, hi), &p| {
        (lo.min(p), hi.max(p))
    });
    let centre = (lo + hi) * 0.5;
    let height = (hi.y - lo.y).max(1e-6);
    std::fs::create_dir_all(&out).map_err(|e| format!("{}: {e}", out.display()))?;
    let mut order: Vec<usize> = (0..points.len()).collect();
    for f in 0..frames {
        // A partial Fisher-Yates shuffle per frame, seeded by the frame: reproducible subsets.
        let mut state =
            0x9E37_79B9_7F4A_7C15u64 ^ (f as u64 + 1).wrapping_mul(0xD1B5_4A32_D192_ED03);
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        if n < points.len() {
            for i in 0..n {
                let j = i + (next() % (points.len() - i) as u64) as usize;
                order.swap(i, j);
            }
        }
        let swing = (f as f32 / frames as f32 * std::f32::consts::TAU).sin();
        let path = out.join(format!("frame_{f:04}.ply"));
        let file = std::fs::File::create(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        let mut w = std::io::BufWriter::new(file);
        let header = format!(
            "ply\nformat binary_little_endian 1.0\ncomment point_frames frame {f} of {}\n\
             element vertex {n}\nproperty float x\nproperty float y\nproperty float z\n\
             property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n",
            input.display()
        );
        let mut bytes = header.into_bytes();
        for &i in &order[..n] {
            let p = points[i];
            // The twist grows from the bottom (none) to the top (the full angle).
            let angle = (twist * swing * (p.y - lo.y) / height).to_radians();
            let m = Mat4::from_translation(centre)
                * Mat4::from_rotation_y(angle)
                * Mat4::from_translation(-centre);
            let p = m.transform_point3(p);
            for v in p.to_array() {
                bytes.extend_from_slice(&v.to_le_bytes());
            }
            let c = colors.get(i).copied().unwrap_or([0.8; 3]);
            bytes.extend(c.map(|v| (linear_to_srgb(v) * 255.0).round() as u8));
        }
        w.write_all(&bytes)
            .and_then(|_| w.flush())
            .map_err(|e| format!("{}: {e}", path.display()))?;
    }
    eprintln!(
        "point_frames: {frames} frames of {n} points in {}",
        out.join("frame_%04d.ply").display()
    );
    Ok(())
}

fn linear_to_srgb(v: f32) -> f32 {
    let v = v.clamp(0.0, 1.0);
    if v <= 0.003_130_8 {
        v * 12.92
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}
