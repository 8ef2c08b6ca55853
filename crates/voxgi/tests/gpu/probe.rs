//! Cone by cone against the path tracer (`voxgi::reference::probe`): the probe's two sides agree
//! where the answer is known, and the diffuse cones' axes, drawn from their cells, integrate
//! the irradiance as their weights assume.

use crate::common::*;
use voxgi::reference::probe::{
    ConeQuery, ConeTruth, TracedCone, hammersley_turns, pixel_ray, trace_diffuse_cones,
};
use voxgi::scene::Scene;
use voxgi::scene::builtin;
use voxgi::scene::glam::Vec3;
use voxgi::{Bounces, FrameParams, PathTracer, RendererOptions, headless};

/// The diffuse cones at `points` for every turn, on `scene`'s lit voxels, with the renderer.
fn traced(
    scene: &Scene,
    options: &RendererOptions,
    points: &[(Vec3, Vec3)],
) -> (voxgi::Renderer, Vec<Vec<Vec<TracedCone>>>) {
    let mut r = renderer(scene, options);
    let params = FrameParams::new(r.default_camera().clone());
    headless::render_still(ctx(), &mut r, &params, 32, 32, 1).expect("render");
    let cones = trace_diffuse_cones(
        &ctx().device,
        &ctx().queue,
        &r,
        points,
        &hammersley_turns(16),
    )
    .expect("probe");
    (r, cones)
}

fn luminance(c: Vec3) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

#[test]
fn cones_in_a_closed_box_see_its_uniform_light() {
    // Inside the furnace every direction sees walls of one radiance: each cone must gather
    // all of it and nothing through, on both sides of the probe.
    let scene = builtin::closed_box(0.5, 0.5);
    let options = RendererOptions {
        voxel_resolution: 32,
        bounces: 2,
        default_light: false,
        ..RendererOptions::default()
    };
    let b = scene.bounds();
    let c = b.center();
    let points = [
        (Vec3::new(c.x, b.min.y, c.z), Vec3::Y),
        (
            Vec3::new(b.max.x, c.y, c.z + 0.2 * (b.max.z - c.z)),
            -Vec3::X,
        ),
    ];
    let (_, cones) = traced(&scene, &options, &points);
    let tracer = PathTracer::new(&ctx().device, &ctx().queue, &scene, &options).expect("tracer");
    for (i, &(p, n)) in points.iter().enumerate() {
        let queries: Vec<ConeQuery> = cones
            .iter()
            .flat_map(|turn| turn[i].iter().map(|c| ConeQuery::of(c, p, n)))
            .collect();
        let truth = tracer
            .probe_cones(&queries, Bounces::matching(options.bounces), 64, 1)
            .expect("path tracer probe");
        let all: Vec<(&TracedCone, &ConeTruth)> = cones
            .iter()
            .flat_map(|turn| turn[i].iter())
            .zip(&truth)
            .collect();
        let vct = all.iter().map(|(c, _)| luminance(c.radiance)).sum::<f32>() / all.len() as f32;
        let pt = all.iter().map(|(_, t)| luminance(t.mean)).sum::<f32>() / all.len() as f32;
        eprintln!("closed box, point {i}: cones {vct:.4}, path tracer {pt:.4}");
        let leak = all.iter().map(|(c, _)| 1.0 - c.opacity).sum::<f32>() / all.len() as f32;
        let most = all.iter().map(|(c, _)| 1.0 - c.opacity).fold(0.0, f32::max);
        eprintln!("closed box, point {i}: cones pass {leak:.4} on average, {most:.4} at most");
        // Nothing escapes a closed box, and no path does. A cone that crosses a wall
        // obliquely weighs the wall's depth by its squared direction cosine along the wall's
        // normal (the three directional blocks), not by the longer path, and a sample astride
        // a corner averages the coverage across it: such cones pass a few per cent at 32³
        // (docs/QUALITY.md has the figures). 3 % on average holds that; a cone that left
        // through a wall would pass most of its light.
        assert!(leak < 0.03, "point {i}: the cones pass {leak} on average");
        assert!(
            truth.iter().all(|t| t.escaped == 0.0),
            "point {i}: a path escaped"
        );
        // The furnace after two bounces is within 2 % of its closed form on both sides
        // (vct.rs, reference.rs); 64 paths per cone over 96 cones leave the path tracer's mean
        // about 1 % noisy. 4 % holds both; a probe that missed a bounce or the emission, or
        // traced the wrong cones, is off by a quarter or more.
        assert!(
            rel(vct, pt) < 0.04,
            "point {i}: cones {vct}, path tracer {pt}"
        );
    }
}

#[test]
fn diffuse_cones_sample_their_cells_as_the_weights_assume() {
    // The cones are far narrower than their aperture near their surface (cone_sample_size),
    // so each measures the light about its axis. Drawn from their cells, cosine-weighted, over
    // the sixteen turns of a block, their weighted sum must be the irradiance: here with the
    // path tracer's light in cones as narrow as the cone tracer's samples, against its own
    // irradiance over the whole hemisphere, at two points of the Cornell box where the light
    // differs across the cells (the ceiling beside the open front, the back wall facing it).
    let scene = builtin::cornell_box();
    let options = RendererOptions {
        voxel_resolution: 64,
        ..RendererOptions::default()
    };
    let b = scene.bounds();
    let points = [
        (Vec3::new(0.277, b.max.y, 0.04), -Vec3::Y),
        (Vec3::new(0.277, 0.416, b.max.z), -Vec3::Z),
    ];
    let (_, cones) = traced(&scene, &options, &points);
    let tracer = PathTracer::new(&ctx().device, &ctx().queue, &scene, &options).expect("tracer");
    for (i, &(p, n)) in points.iter().enumerate() {
        let mut queries: Vec<ConeQuery> = cones
            .iter()
            .flat_map(|turn| {
                turn[i].iter().map(|c| ConeQuery {
                    // A sample near its surface is a third of its height wide
                    // (SELF_CLEARANCE): half-angle tangent cos / 6.
                    tan_half: c.dir.dot(n).max(0.05) / 6.0,
                    ..ConeQuery::of(c, p, n)
                })
            })
            .collect();
        let cells = queries.len();
        queries.extend((0..16).map(|_| ConeQuery::hemisphere(p, n, 10.0)));
        let truth = tracer
            .probe_cones(&queries, Bounces::matching(options.bounces), 256, 2)
            .expect("path tracer probe");
        let weights = cones
            .iter()
            .flat_map(|turn| turn[i].iter().map(|c| c.weight));
        let sum = weights
            .zip(&truth[..cells])
            .map(|(w, t)| w * luminance(t.mean))
            .sum::<f32>()
            / 16.0;
        let irradiance = truth[cells..]
            .iter()
            .map(|t| luminance(t.cos_mean))
            .sum::<f32>()
            / 16.0;
        eprintln!(
            "point {i}: the cones' axes by their weights {sum:.4}, irradiance / pi {irradiance:.4} \
             (ratio {:.3})",
            sum / irradiance
        );
        // Measured 0.957 and 0.994. Traced along fixed axes (the ring at 60 degrees, before
        // the axes were drawn from the cells) the same sum read 1.21 and 0.85 (`voxgi probe`
        // at 128³). 6 % holds the sixteen turns' quadrature error and 256 paths' noise.
        assert!(
            rel(sum, irradiance) < 0.06,
            "point {i}: cones {sum}, irradiance {irradiance}"
        );
    }
}

#[test]
fn quarter_cones_pass_the_light_a_block_lets_by() {
    // At the Cornell box's back wall, behind the tall block, the normal's cone passes the
    // block's top edge: its samples are partly covered by the block's back face and then by
    // its front face. Whole-footprint samples composite each coverage as if independent of
    // the last and stop the same rays twice; one quarter of the footprint a cone (the
    // renderer's default) follows its rays closer. The path tracer's rays in cones as narrow
    // as the samples near the wall (half-angle tangent cos / 6, as `voxgi probe --narrow`)
    // give the truth.
    let scene = builtin::cornell_box();
    let point = [(Vec3::new(0.115, 0.360, 0.559), -Vec3::Z)];
    let pass = |quarters: bool| {
        let options = RendererOptions {
            voxel_resolution: 64,
            bounces: 1,
            cone_quarters: quarters,
            ..RendererOptions::default()
        };
        let (_, cones) = traced(&scene, &options, &point);
        // The normal's cone (index 0) at the sixteen turns.
        let normal: Vec<TracedCone> = cones.iter().map(|turn| turn[0][0]).collect();
        let t = normal.iter().map(|c| 1.0 - c.opacity).sum::<f32>() / normal.len() as f32;
        (t, normal, options)
    };
    let (quarters, normal, options) = pass(true);
    let (whole, _, _) = pass(false);
    let (p, n) = point[0];
    let queries: Vec<ConeQuery> = normal
        .iter()
        .map(|c| ConeQuery {
            tan_half: c.dir.dot(n).max(0.05) / 6.0,
            ..ConeQuery::of(c, p, n)
        })
        .collect();
    let tracer = PathTracer::new(&ctx().device, &ctx().queue, &scene, &options).expect("tracer");
    let truth = tracer
        .probe_cones(&queries, Bounces::matching(options.bounces), 256, 3)
        .expect("path tracer probe");
    let escaped = truth.iter().map(|t| t.escaped).sum::<f32>() / truth.len() as f32;
    eprintln!(
        "back wall's normal cone passes: quarters {quarters:.3}, whole footprint {whole:.3}, \
         path tracer's rays escape {escaped:.3}"
    );
    // A quarter still composites its own partial coverage, so it passes less than the rays;
    // 0.7 to 1.05 of them holds it with room for the 256 paths' noise (docs/QUALITY.md has
    // the figures). Whole footprints pass well under what the quarters pass: the double count
    // the quarters exist for (and the proof that `cone_quarters: false` reaches the shader).
    let ratio = quarters / escaped;
    assert!(
        (0.7..1.05).contains(&ratio),
        "quarters pass {quarters}, the path tracer's rays escape {escaped}"
    );
    assert!(
        whole < 0.8 * quarters,
        "whole footprints pass {whole}, quarters {quarters}, the path tracer's rays escape {escaped}"
    );
}

/// A converged still's diffuse light at every pixel is its own cones' integral there: over the
/// frames each pixel takes every rank of the 4x4 interleaving (shaders/shared/interleave.wgsl,
/// `pixel_rank`) and the turns sweep the cones' whole cells. Before, a pixel kept its rank and
/// the turns moved within a sixteenth of each cell, so a block traced the same sixteen small
/// patches of every cell in every frame: on the open Cornell box's ceiling, where the light
/// changes sharply across the cells (the open front, the lit room), the converged gather read
/// 0.90 to 1.09 of its cones' integral. 128x128 at 64³, 64 frames, the indirect view.
#[test]
fn a_converged_still_gathers_its_cones_integral_at_every_pixel() {
    let scene = builtin::cornell_box();
    let options = RendererOptions {
        voxel_resolution: 64,
        ..RendererOptions::default()
    };
    let (w, h) = (128u32, 128u32);
    let mut r = renderer(&scene, &options);
    let cam = r.default_camera().clone();
    let params = FrameParams {
        view: voxgi::ViewMode::Indirect,
        ..FrameParams::new(cam.clone())
    };
    let still = headless::render_still(ctx(), &mut r, &params, w, h, 64).expect("still");
    let ceiling = scene.bounds().max.y;
    let albedo = Vec3::from(builtin::CORNELL_WHITE);
    // Two 4x4 blocks across and one down each, on the ceiling: beside the open front at the
    // right and in the middle, and right of the lamp, nearer the back wall.
    for (x0, y0) in [(88, 3), (56, 3), (80, 19)] {
        let pixels: Vec<(u32, u32)> = (y0..y0 + 4)
            .flat_map(|y| (x0..x0 + 8).map(move |x| (x, y)))
            .collect();
        let points: Vec<(Vec3, Vec3)> = pixels
            .iter()
            .map(|&px| {
                let (o, d) = pixel_ray(&cam, px, (w, h));
                (o + d * ((ceiling - o.y) / d.y), -Vec3::Y)
            })
            .collect();
        let turns = hammersley_turns(64);
        let cones =
            trace_diffuse_cones(&ctx().device, &ctx().queue, &r, &points, &turns).expect("probe");
        let mut integral = 0.0;
        let mut gathered = 0.0;
        for (i, &(x, y)) in pixels.iter().enumerate() {
            let mean: Vec3 = cones
                .iter()
                .map(|turn| turn[i].iter().map(|c| c.weight * c.radiance).sum::<Vec3>())
                .sum::<Vec3>()
                / turns.len() as f32;
            integral += luminance(albedo * mean);
            gathered += luminance(Vec3::from(still.radiance(x, y)));
        }
        let ratio = gathered / integral;
        eprintln!(
            "ceiling pixels {x0}..{}, {y0}..{}: gathered / cones {ratio:.4}",
            x0 + 8,
            y0 + 4
        );
        // Measured on lavapipe: 1.002, 1.014 and 1.000 (1.095 in the first before). 3 % holds
        // the residue of 64 frames' turns, of the jitter, which moves the pixels' points about
        // the ones probed here, and of the upsample's window, which leans back from the
        // image's edge in the first rows.
        assert!(
            rel(ratio, 1.0) < 0.03,
            "ceiling pixels at ({x0}, {y0}): the gather reads {ratio} of its cones' integral"
        );
    }
}
