//! `voxgi probe`: the gather's diffuse cones at chosen pixels, cone by cone against the path
//! tracer's light over the same cones, to find which term of the cone tracer is wrong.

use crate::args::{
    Progress, SceneArg, SettingsArgs, load_scene_and_settings, parse_size, scene_label,
};
use anyhow::{Context, Result, bail};
use clap::Args;
use std::time::Instant;
use voxgi::reference::probe::{
    ConeQuery, ConeTruth, TracedCone, hammersley_turns, pixel_ray, trace_diffuse_cones,
};
use voxgi::reference::{PRIM_DISC, flatten};
use voxgi::scene::glam::Vec3;
use voxgi::{Bounces, PathTracer, headless};

#[derive(Args)]
pub struct ProbeArgs {
    #[command(flatten)]
    pub scene: SceneArg,
    /// A pixel to probe, X,Y from the top left of an image of --size seen by the scene's
    /// camera (repeat for more).
    #[arg(long = "pixel", value_name = "X,Y", required = true, value_parser = parse_pixel)]
    pub pixels: Vec<(u32, u32)>,
    /// The image size the pixels refer to.
    #[arg(long, value_name = "WxH", default_value = "512x512", value_parser = parse_size)]
    pub size: (u32, u32),
    #[command(flatten)]
    pub settings: SettingsArgs,
    /// Path-traced directions per cone.
    #[arg(long, value_name = "N", default_value_t = 4096,
          value_parser = clap::value_parser!(u32).range(1..=1 << 20))]
    pub spp: u32,
    /// Trace the path tracer's cones as narrow as the cone tracer's samples are near their
    /// surface (a third of their height above it wide: half-angle tangent cos θ / 6), rather
    /// than at the cones' nominal aperture: the diffuse cones measure the light about their
    /// axes, so this is the comparison of their weights.
    #[arg(long)]
    pub narrow: bool,
    /// Print every turn of every cone, not only their means.
    #[arg(long)]
    pub detail: bool,
    /// Turns of the cone bundle: its cones' axes drawn from their cells at the points of a
    /// Hammersley set, as the gather's 4x4 block draws them; the table averages each cone
    /// over them.
    #[arg(long, value_name = "N", default_value_t = 16)]
    pub turns: u32,
}

fn parse_pixel(s: &str) -> Result<(u32, u32), String> {
    let (x, y) = s
        .split_once(',')
        .ok_or_else(|| format!("'{s}' is not X,Y (e.g. 256,40)"))?;
    let x = x.trim().parse().map_err(|_| format!("bad column '{x}'"))?;
    let y = y.trim().parse().map_err(|_| format!("bad row '{y}'"))?;
    Ok((x, y))
}

/// The nearest triangle or point disc hit along the ray: the point and the surface's normal
/// facing the ray.
fn first_hit(tris: &[voxgi::reference::GpuTri], o: Vec3, d: Vec3) -> Option<(Vec3, Vec3)> {
    let mut best: Option<(f32, Vec3)> = None;
    let mut keep = |dist: f32, n: Vec3| {
        if dist > 1e-6 && best.is_none_or(|(bd, _)| dist < bd) {
            best = Some((dist, if n.dot(d) > 0.0 { -n } else { n }));
        }
    };
    for t in tris {
        let [a, b, c] = [t.p0, t.p1, t.p2].map(Vec3::from_array);
        if t.kind == PRIM_DISC {
            // p0 the centre, p1 the unit normal, p2.x the radius.
            let denom = b.dot(d);
            if denom.abs() > 1e-12 {
                let dist = (a - o).dot(b) / denom;
                if (o + d * dist - a).length() <= c.x {
                    keep(dist, b);
                }
            }
            continue;
        }
        let (e1, e2) = (b - a, c - a);
        let p = d.cross(e2);
        let det = e1.dot(p);
        if det.abs() < 1e-12 {
            continue;
        }
        let s = o - a;
        let u = s.dot(p) / det;
        let q = s.cross(e1);
        let v = d.dot(q) / det;
        let dist = e2.dot(q) / det;
        if u < 0.0 || v < 0.0 || u + v > 1.0 {
            continue;
        }
        keep(dist, e1.cross(e2).normalize());
    }
    best.map(|(dist, n)| (o + d * dist, n))
}

fn luminance(c: Vec3) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

fn ratio(a: f32, b: f32) -> String {
    if b.abs() < 1e-9 {
        "-".into()
    } else {
        format!("{:.3}", a / b)
    }
}

pub fn run(args: &ProbeArgs) -> Result<()> {
    let p = Progress {
        start: Instant::now(),
    };
    if args.turns == 0 || args.turns > 256 {
        bail!("--turns {}: between 1 and 256", args.turns);
    }
    let (w, h) = args.size;
    for &(x, y) in &args.pixels {
        if x >= w || y >= h {
            bail!("pixel {x},{y} lies outside the {w}x{h} image");
        }
    }
    let label = scene_label(&args.scene);
    let (scene, table) = p.stage(&format!("loading {label}"), || {
        load_scene_and_settings(&args.scene)
    })?;
    let camera = scene.default_camera();
    let (options, frame) = args
        .settings
        .resolve(table.as_ref(), camera.clone())
        .with_context(|| label.clone())?;
    let tris = flatten(&scene).tris;
    let mut points = Vec::new();
    for &px in &args.pixels {
        let (o, d) = pixel_ray(&camera, px, args.size);
        let (hit, n) = first_hit(&tris, o, d)
            .with_context(|| format!("pixel {},{} sees no surface", px.0, px.1))?;
        points.push((hit, n));
    }
    let ctx = p.stage("opening GPU", headless::GpuContext::from_env)?;
    eprintln!("GPU: {} ({:?})", ctx.info.name, ctx.info.backend);
    let mut renderer = p
        .stage("uploading scene", || ctx.renderer(&scene, &options))
        .with_context(|| label.clone())?;
    p.stage("lighting the voxels", || {
        headless::render_still(&ctx, &mut renderer, &frame, 64, 64, 1)
    })?;
    let count = options.cones.axes().len();
    let turns: Vec<Vec<Vec<TracedCone>>> = p.stage("tracing the cones", || {
        let turns = hammersley_turns(args.turns);
        trace_diffuse_cones(&ctx.device, &ctx.queue, &renderer, &points, &turns)
    })?;
    // Per point: every turn's cones, then the hemisphere.
    let mut queries = Vec::new();
    for (i, &(hit, n)) in points.iter().enumerate() {
        for turn in &turns {
            queries.extend(turn[i].iter().map(|c| {
                let mut q = ConeQuery::of(c, hit, n);
                if args.narrow {
                    q.tan_half = c.dir.dot(n).max(0.05) / 6.0;
                }
                q
            }));
        }
        // The hemisphere gets sixteen times the directions: it is the reference of the sum.
        for _ in 0..16 {
            queries.push(ConeQuery::hemisphere(hit, n, turns[0][i][0].max_distance));
        }
    }
    let tracer = p
        .stage("uploading scene for the path tracer", || {
            PathTracer::new(&ctx.device, &ctx.queue, &scene, &options)
        })
        .with_context(|| label.clone())?;
    let truth: Vec<ConeTruth> = p.stage(
        &format!(
            "path tracing {} cones, {} directions each",
            queries.len(),
            args.spp
        ),
        || tracer.probe_cones(&queries, Bounces::matching(options.bounces), args.spp, 0),
    )?;
    let per_point = args.turns as usize * count + 16;
    for (i, &(hit, n)) in points.iter().enumerate() {
        let truth = &truth[i * per_point..(i + 1) * per_point];
        let hemi = truth[per_point - 16..]
            .iter()
            .fold(Vec3::ZERO, |a, t| a + t.cos_mean / 16.0);
        println!(
            "\npixel {},{}: point {:.3},{:.3},{:.3} normal {:.2},{:.2},{:.2}; luminance, averaged over {} turns",
            args.pixels[i].0, args.pixels[i].1, hit.x, hit.y, hit.z, n.x, n.y, n.z, args.turns
        );
        println!(
            "cone  weight  cones: L     path: L   ratio   cos-mean | cones: T   path: escaped  hit m"
        );
        let (mut e_cone, mut e_true, mut e_cos) = (0.0, 0.0, 0.0);
        for c in 0..count {
            let (mut l, mut t, mut pl, mut pc, mut pe, mut ph) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
            let mut weight = 0.0;
            for (k, turn) in turns.iter().enumerate() {
                let cone = turn[i][c];
                let want = truth[k * count + c];
                if args.detail {
                    println!(
                        "    turn {k}: dir {:.2},{:.2},{:.2} cones L {:.4} T {:.3} | path L {:.4} escaped {:.3} hit {:.2}",
                        cone.dir.x,
                        cone.dir.y,
                        cone.dir.z,
                        luminance(cone.radiance),
                        1.0 - cone.opacity,
                        luminance(want.mean),
                        want.escaped,
                        want.mean_hit
                    );
                }
                weight = cone.weight;
                l += luminance(cone.radiance);
                t += 1.0 - cone.opacity;
                pl += luminance(want.mean);
                pc += luminance(want.cos_mean);
                pe += want.escaped;
                ph += want.mean_hit;
            }
            let k = args.turns as f32;
            let (l, t, pl, pc, pe, ph) = (l / k, t / k, pl / k, pc / k, pe / k, ph / k);
            e_cone += weight * l;
            e_true += weight * pl;
            e_cos += weight * pc;
            println!(
                "{c:>4}  {weight:.3}  {l:>9.4}  {pl:>9.4}  {:>6}  {pc:>9.4} | {t:>8.3}  {pe:>13.3}  {ph:>5.2}",
                ratio(l, pl)
            );
        }
        let hemi_l = luminance(hemi);
        println!(
            "irradiance / pi: cones {e_cone:.4}; path tracer {hemi_l:.4} (the cones' ratio {}); \
             the path tracer's light in the cones, by their weights: {e_true:.4} (uniform in \
             each cone), {e_cos:.4} (cosine-weighted)",
            ratio(e_cone, hemi_l)
        );
    }
    eprintln!("done in {:.1} s", p.start.elapsed().as_secs_f64());
    Ok(())
}
