//! Cone by cone against the truth: the gather's diffuse cones at chosen surface points
//! (`trace_diffuse_cones`, shaders/cone_probe.wgsl) and the path tracer's light over exactly
//! those cones (`PathTracer::probe_cones`, the probe mode of shaders/reference.wgsl), so that an
//! error in the indirect light can be pinned on a cone and on a term: what a cone gathers
//! against the light inside it, its transmittance against the fraction of its rays that meet
//! nothing, its weight against the cosine-weighted light of its cell.

use super::{GpuParams, PATHS_PER_SUBMIT, PathTracer, bounce_limits};
use crate::frame::sequence::radical_inverse;
use crate::gpu::{checked, layout, readback, shader};
use crate::lighting::cones::cone_uniforms;
use crate::scene::{Camera, Projection};
use crate::{Bounces, Error, Renderer, Result};
use bytemuck::{Pod, Zeroable};
use glam::{Vec2, Vec3, Vec4};
use wgpu::util::DeviceExt;

/// Cone slots per point in the cone probe's results (`Cones::dirs` holds at most 16).
const SLOTS: usize = 16;

/// One diffuse cone of the gather at a surface point, as `trace_cone` gathers it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TracedCone {
    /// The cone's axis, world space (unit).
    pub dir: Vec3,
    /// Its weight: its cell's share of the cosine-weighted hemisphere.
    pub weight: f32,
    /// Tangent of its half-angle.
    pub tan_half: f32,
    /// How far it is traced, metres.
    pub max_distance: f32,
    /// Premultiplied radiance gathered along it: its estimate of the mean radiance arriving
    /// from inside it (W/m²/sr).
    pub radiance: Vec3,
    /// Opacity gathered along it; 1 - opacity is its transmittance.
    pub opacity: f32,
}

/// The ray through the centre of pixel (x, y) of a `size` image seen by `camera`.
pub fn pixel_ray(camera: &Camera, (x, y): (u32, u32), (w, h): (u32, u32)) -> (Vec3, Vec3) {
    let ndc = Vec2::new(
        (x as f32 + 0.5) / w as f32 * 2.0 - 1.0,
        1.0 - (y as f32 + 0.5) / h as f32 * 2.0,
    );
    let right = camera.forward.cross(camera.up).normalize();
    let aspect = w as f32 / h as f32;
    match camera.projection {
        Projection::Perspective { yfov } => {
            let t = (yfov * 0.5).tan();
            let d = camera.forward + right * (ndc.x * t * aspect) + camera.up * (ndc.y * t);
            (camera.position, d.normalize())
        }
        Projection::Orthographic { ymag, .. } => (
            camera.position + right * (ndc.x * ymag * aspect) + camera.up * (ndc.y * ymag),
            camera.forward,
        ),
    }
}

/// `n` turns of the cone bundle spread as the gather's pixels spread theirs: the points of a
/// Hammersley set, each at the centre of its stratum.
pub fn hammersley_turns(n: u32) -> Vec<Vec2> {
    let n = n.max(1);
    (0..n)
        .map(|k| {
            let centre = 0.5 / n as f32;
            Vec2::new(
                k as f32 / n as f32 + centre,
                (radical_inverse(k, 2) + centre).fract(),
            )
        })
        .collect()
}

/// The diffuse cones of `renderer`'s gather at each surface point (position, unit normal),
/// their axes drawn from their cells at each of `turns` in [0, 1)² (about the normal, in
/// zenith: shaders/shared/cone.wgsl, `diffuse_cone`), traced on its current voxels in one
/// dispatch: per turn, per point, its cones. The renderer must have rendered a frame (its
/// voxels lit).
pub fn trace_diffuse_cones(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    renderer: &Renderer,
    points: &[(Vec3, Vec3)],
    turns: &[Vec2],
) -> Result<Vec<Vec<Vec<TracedCone>>>> {
    if points.is_empty() || turns.is_empty() {
        return Ok(vec![Vec::new(); turns.len()]);
    }
    for (p, n) in points {
        if !(p.is_finite() && n.is_finite() && (n.length() - 1.0).abs() < 1e-3) {
            return Err(Error::Setting(format!(
                "probe point {p} with normal {n}: the position must be finite and the normal \
                 a unit vector"
            )));
        }
    }
    let options = renderer.options();
    let volume = renderer.volume();
    let cones = cone_uniforms(options, &volume.grid());
    let input: Vec<[f32; 8]> = turns
        .iter()
        .flat_map(|t| {
            points
                .iter()
                .map(|(p, n)| [p.x, p.y, p.z, t.x, n.x, n.y, n.z, t.y])
        })
        .collect();
    let slots = (input.len() * SLOTS) as u64;
    let (pipeline, bind, output) = checked(device, "cone_probe", || {
        let buffer = |label: &str, contents: &[u8], usage| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage,
            })
        };
        let cones = buffer(
            "cone_probe cones",
            bytemuck::bytes_of(&cones),
            wgpu::BufferUsages::UNIFORM,
        );
        let input = buffer(
            "cone_probe points",
            bytemuck::cast_slice(&input),
            wgpu::BufferUsages::STORAGE,
        );
        let output = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("cone_probe results"),
            size: slots * 32,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let c = wgpu::ShaderStages::COMPUTE;
        let own = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("cone_probe"),
            entries: &[
                layout::uniform(0, c, false),
                layout::storage(1, c, true),
                layout::storage(2, c, false),
            ],
        });
        let kind = options.voxels;
        let sampling = kind.sampling_layout(device);
        let constants =
            kind.sampling_constants(options.anisotropic, renderer.lobes(), options.gather_axes);
        let pipeline = shader::voxel_pipeline(
            device,
            "cone_probe",
            "cone_probe.wgsl",
            kind.shaders(),
            &[Some(&own), Some(&sampling)],
            &constants,
        );
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("cone_probe"),
            layout: &own,
            entries: &layout::entries(vec![
                cones.as_entire_binding(),
                input.as_entire_binding(),
                output.as_entire_binding(),
            ]),
        });
        (pipeline, bind, output)
    })?;
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("cone_probe"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind, &[]);
        pass.set_bind_group(1, volume.bindings().sampling, &[]);
        pass.dispatch_workgroups((slots as u32).div_ceil(64), 1, 1);
    }
    queue.submit([encoder.finish()]);
    let bytes = readback::read_buffer_copy(device, queue, &output)?;
    let v: &[[f32; 4]] = bytemuck::cast_slice(&bytes);
    let cone = |slot: usize| {
        let [c, r] = [v[2 * slot], v[2 * slot + 1]];
        TracedCone {
            dir: Vec3::new(c[0], c[1], c[2]),
            weight: c[3],
            tan_half: cones.diffuse_tan,
            max_distance: cones.max_distance,
            radiance: Vec3::new(r[0], r[1], r[2]),
            opacity: r[3],
        }
    };
    Ok((0..turns.len())
        .map(|t| {
            (0..points.len())
                .map(|p| {
                    let first = (t * points.len() + p) * SLOTS;
                    (first..first + cones.count as usize).map(cone).collect()
                })
                .collect()
        })
        .collect())
}

/// A cone for the path tracer's probe mode. Mirrors `ConeQuery` in shaders/reference.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct ConeQuery {
    /// The surface point the cone leaves, world space.
    pub origin: [f32; 3],
    /// Tangent of the cone's half-angle (at most 1e4: up to the whole hemisphere).
    pub tan_half: f32,
    /// The cone's axis (unit).
    pub dir: [f32; 3],
    /// Hits further than this count as escaped, metres.
    pub max_distance: f32,
    /// The surface's unit normal: directions below its plane carry no light and count as
    /// blocked at distance 0.
    pub normal: [f32; 3],
    /// Padding to 48 bytes; zero.
    pub _pad: f32,
}

impl ConeQuery {
    /// The query for `cone` leaving the surface point `p` with normal `n`.
    pub fn of(cone: &TracedCone, p: Vec3, n: Vec3) -> Self {
        ConeQuery {
            origin: p.to_array(),
            tan_half: cone.tan_half,
            dir: cone.dir.to_array(),
            max_distance: cone.max_distance,
            normal: n.to_array(),
            _pad: 0.0,
        }
    }

    /// The whole hemisphere above `p` (normal `n`): its `ConeTruth::cos_mean` is the
    /// irradiance over pi.
    pub fn hemisphere(p: Vec3, n: Vec3, max_distance: f32) -> Self {
        ConeQuery {
            origin: p.to_array(),
            tan_half: 1e4,
            dir: n.to_array(),
            max_distance,
            normal: n.to_array(),
            _pad: 0.0,
        }
    }
}

/// What the path tracer finds inside one cone: the light arriving at its origin from the
/// directions it covers, with the bounces counted as the cone tracer counts them and without
/// the area lights' emitters (their light is the direct term, not the cones').
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConeTruth {
    /// Mean radiance over the cone's solid angle: what a cone's gathered radiance estimates.
    pub mean: Vec3,
    /// Cosine-weighted mean radiance over the cone (the cosine to the surface normal).
    pub cos_mean: Vec3,
    /// Fraction of its directions that meet nothing within `max_distance`: what a cone's
    /// transmittance estimates.
    pub escaped: f32,
    /// Mean distance to the first hit of the directions that meet something, metres (a
    /// direction below the surface counts as a hit at 0).
    pub mean_hit: f32,
}

impl PathTracer {
    /// The light inside each cone of `queries`, from `spp` directions per cone drawn uniformly
    /// over its solid angle, each followed by a path with `bounces` as the cone tracer counts
    /// them (the surface the cone leaves is the path's first vertex, as a camera ray's first
    /// hit is).
    pub fn probe_cones(
        &self,
        queries: &[ConeQuery],
        bounces: Bounces,
        spp: u32,
        seed: u32,
    ) -> Result<Vec<ConeTruth>> {
        // Each cone numbers its paths in an f32 sum, exact up to 2^24.
        if spp == 0 || spp > 1 << 24 {
            return Err(Error::Setting(format!(
                "{spp} paths per cone: between 1 and {}",
                1 << 24
            )));
        }
        if queries.is_empty() {
            return Ok(Vec::new());
        }
        let unit = |v: [f32; 3]| (Vec3::from_array(v).length() - 1.0).abs() < 1e-3;
        for q in queries {
            let ok = unit(q.dir)
                && unit(q.normal)
                && q.origin
                    .iter()
                    .chain(&q.dir)
                    .chain(&q.normal)
                    .all(|x| x.is_finite())
                && q.tan_half > 0.0
                && q.tan_half <= 1e4
                && q.max_distance > 0.0;
            if !ok {
                return Err(Error::Setting(format!(
                    "cone query {q:?}: positions must be finite, directions unit vectors, the \
                     half-angle's tangent in (0, 1e4] and the distance positive"
                )));
            }
        }
        let n = queries.len() as u32;
        let (bounces, rr_depth) = bounce_limits(bounces);
        let device = &self.device;
        let (params, bind, accum) = checked(device, "reference probe", || {
            let params = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("reference probe params"),
                size: size_of::<GpuParams>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let input = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("reference probe cones"),
                contents: bytemuck::cast_slice(queries),
                usage: wgpu::BufferUsages::STORAGE,
            });
            // Three sums per cone (shaders/reference.wgsl, `probe`).
            let accum = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("reference probe sums"),
                size: n as u64 * 3 * 16,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let bind = self.trace_group(&params, &accum, &input);
            (params, bind, accum)
        })?;
        let batch = (PATHS_PER_SUBMIT / n as u64).clamp(1, 256) as u32;
        let mut done = 0;
        while done < spp {
            let count = batch.min(spp - done);
            let p = GpuParams {
                inv_view_proj: glam::Mat4::IDENTITY.to_cols_array_2d(),
                background: [0.0; 3],
                light_count: self.light_count,
                width: n,
                height: 1,
                x0: 0,
                // One path a cone per dispatch, as `accumulate` traces one sample a pixel
                // per dispatch (progressive.rs says why).
                sample_count: 1,
                seed,
                bounces,
                mode: 2,
                ao_radius: 0.0,
                rr_depth,
                x1: n,
                y0: 0,
                y1: 1,
            };
            self.queue.write_buffer(&params, 0, bytemuck::bytes_of(&p));
            let mut enc = device.create_command_encoder(&Default::default());
            {
                let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("reference probe"),
                    timestamp_writes: None,
                });
                pass.set_pipeline(&self.pipeline);
                pass.set_bind_group(0, &bind, &[]);
                for _ in 0..count {
                    pass.dispatch_workgroups(n.div_ceil(8), 1, 1);
                }
            }
            self.queue.submit([enc.finish()]);
            device
                .poll(wgpu::PollType::wait_indefinitely())
                .map_err(|e| Error::Gpu {
                    context: "reference probe".into(),
                    reason: e.to_string(),
                })?;
            done += count;
        }
        let bytes = readback::read_buffer_copy(device, &self.queue, &accum)?;
        let v: Vec<Vec4> = bytemuck::cast_slice::<u8, [f32; 4]>(&bytes)
            .iter()
            .map(|x| Vec4::from_array(*x))
            .collect();
        Ok(v.chunks_exact(3)
            .map(|s| {
                let hits = s[2].z;
                ConeTruth {
                    mean: s[0].truncate() / s[0].w.max(1.0),
                    cos_mean: s[1].truncate() / s[1].w.max(1e-12),
                    escaped: s[2].x / s[2].w.max(1.0),
                    mean_hit: if hits > 0.0 { s[2].y / hits } else { 0.0 },
                }
            })
            .collect())
    }
}
