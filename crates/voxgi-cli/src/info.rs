//! `voxgi info`: what a scene contains.

use crate::args::{SceneArg, load_scene, scene_label};
use anyhow::Result;
use voxgi::scene::animation::AnimationTarget;
use voxgi::scene::{LightKind, Projection, Scene};

pub fn run(arg: &SceneArg) -> Result<()> {
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
    let _ = writeln!(o, "animations  {}", s.animations.len());
    for (i, a) in s.animations.iter().enumerate() {
        let target = match &a.target {
            AnimationTarget::Instances { instances, .. } => {
                format!("{} instance(s)", instances.len())
            }
            AnimationTarget::Light { light, .. } => format!(
                "light '{}'",
                s.lights.get(*light).map_or("?", |l| l.name.as_str())
            ),
            AnimationTarget::Camera { camera, .. } => format!(
                "camera [{camera}] '{}'",
                s.cameras.get(*camera).map_or("?", |c| c.name.as_str())
            ),
        };
        let _ = writeln!(
            o,
            "  [{i}] {:<20} {target:<18} {:.3} s",
            a.name,
            a.duration()
        );
    }
    let _ = writeln!(o, "point sequences  {}", s.sequences.len());
    for (i, q) in s.sequences.iter().enumerate() {
        let _ = writeln!(
            o,
            "  [{i}] {:<20} {} frames at {} fps ({:?}), up to {} points, {:.3} s",
            s.point_clouds.get(q.cloud).map_or("?", |c| c.name.as_str()),
            q.files.len(),
            q.fps,
            q.repeat,
            q.capacity,
            q.duration()
        );
    }
    o
}
