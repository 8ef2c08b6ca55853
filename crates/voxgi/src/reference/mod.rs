//! The ground truth: a GPU path tracer over the same scene, materials and lights as the
//! rasterizer, and an ambient-occlusion reference.
//!
//! All mesh instances are flattened into world-space triangles and all point clouds into the
//! oriented discs the rasterizer draws for them (the discs showing an area light are that
//! light's surface within its shape only, like its emitter triangles), a BVH is built on the CPU (obvhs' PLOC
//! builder) and flattened into a node array the compute shader
//! (`shaders/reference.wgsl`) walks with a stack. Samples accumulate in an f32 buffer, a batch
//! per submit, so long renders report progress and never hold the GPU for long.

use crate::gpu::timer::GpuTimer;
use crate::gpu::{checked, layout, readback, shader};
use crate::gpu_scene::{
    GpuLight, GpuScene, LIGHT_DISC, LIGHT_RECT, NO_INDEX, check_light, gpu_light, view_sphere,
};
use crate::options::{FrameParams, RendererOptions};
use crate::output::{RenderOutput, tonemap};
use crate::view::lit_scene;
use crate::{Error, Result};
use bytemuck::{Pod, Zeroable};
use glam::{Mat3, Vec3};
use voxgi_scene::{Light, Scene};
use wgpu::util::DeviceExt;

pub mod probe;
pub(crate) mod progressive;
pub use progressive::{Accumulation, Region};

/// How many indirect bounces the reference simulates (as the cone tracer counts them).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Bounces {
    /// Direct light from the lights (with visibility) plus emission seen directly: what the
    /// rasterizer computes.
    DirectOnly,
    /// Direct light plus one indirect bounce.
    One,
    /// Full global illumination: paths end by Russian roulette from depth 3 on, or at
    /// [`MAX_BOUNCES`].
    #[default]
    Unlimited,
    /// Exactly this many indirect bounces (no Russian roulette).
    Exactly(u32),
}

impl Bounces {
    /// The bounces the renderer computes with `RendererOptions::bounces` = `n`, so the two
    /// images compare like with like.
    pub fn matching(n: u32) -> Bounces {
        match n {
            0 => Bounces::DirectOnly,
            1 => Bounces::One,
            crate::options::UNLIMITED_BOUNCES => Bounces::Unlimited,
            n => Bounces::Exactly(n),
        }
    }
}

/// Path-length cap for [`Bounces::Unlimited`].
pub const MAX_BOUNCES: u32 = 64;

/// The shader's bounce count and Russian-roulette depth for `bounces`.
fn bounce_limits(bounces: Bounces) -> (u32, u32) {
    match bounces {
        Bounces::DirectOnly => (0, u32::MAX),
        Bounces::One => (1, u32::MAX),
        Bounces::Unlimited => (MAX_BOUNCES - 1, 3),
        Bounces::Exactly(n) => (n.min(MAX_BOUNCES - 1), u32::MAX),
    }
}

/// What the reference computes.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum ReferenceMode {
    /// Radiance (the path tracer).
    #[default]
    Radiance,
    /// Ambient occlusion: the fraction of cosine-weighted rays from the first hit that travel
    /// `radius` metres without hitting anything, as grey radiance in [0, 1] (pixels that see
    /// nothing are 1). Its LDR output is that value, without exposure or tone curve.
    Ao {
        /// How far the rays reach, metres (positive and finite).
        radius: f32,
    },
}

/// Options of one reference render.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReferenceOptions {
    /// Samples per pixel.
    pub spp: u32,
    /// How many indirect bounces paths take (radiance mode only).
    pub bounces: Bounces,
    /// Radiance or ambient occlusion.
    pub mode: ReferenceMode,
    /// The same seed gives the same image.
    pub seed: u32,
}

impl Default for ReferenceOptions {
    fn default() -> Self {
        ReferenceOptions {
            spp: 256,
            bounces: Bounces::Unlimited,
            mode: ReferenceMode::Radiance,
            seed: 0,
        }
    }
}

/// Mirrors `Params` in shaders/reference.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub(crate) struct GpuParams {
    pub(crate) inv_view_proj: [[f32; 4]; 4],
    pub(crate) background: [f32; 3],
    pub(crate) light_count: u32,
    pub(crate) width: u32,
    pub(crate) height: u32,
    pub(crate) x0: u32,
    pub(crate) sample_count: u32,
    pub(crate) seed: u32,
    pub(crate) bounces: u32,
    pub(crate) mode: u32,
    pub(crate) ao_radius: f32,
    pub(crate) rr_depth: u32,
    pub(crate) x1: u32,
    pub(crate) y0: u32,
    pub(crate) y1: u32,
}

/// Mirrors `Node` in shaders/reference.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuNode {
    /// World-space box minimum, metres.
    pub lo: [f32; 3],
    /// Inner node (`count` 0): index of the first of its two adjacent children. Leaf: index of its
    /// first triangle.
    pub first: u32,
    /// World-space box maximum, metres.
    pub hi: [f32; 3],
    /// Triangles in a leaf (`first .. first + count`); 0 for an inner node.
    pub count: u32,
}

/// Mirrors `Tri` in shaders/reference.wgsl: a triangle, or a point's disc (`kind`
/// `PRIM_DISC`: `p0` its centre, `p1` its unit normal, `p2.x` its radius; its albedo and
/// emission in `GpuTriShading::n1` and `n2`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuTri {
    /// First vertex, world space, metres.
    pub p0: [f32; 3],
    /// Index into the scene's materials.
    pub material: u32,
    /// Second vertex, world space, metres.
    pub p1: [f32; 3],
    /// The area light this triangle shows, or `NO_INDEX`.
    pub light: u32,
    /// Third vertex, world space, metres.
    pub p2: [f32; 3],
    /// `PRIM_TRIANGLE` or `PRIM_DISC`.
    pub kind: u32,
}

/// `GpuTri::kind` of a triangle.
pub const PRIM_TRIANGLE: u32 = 0;
/// `GpuTri::kind` of a point's disc.
pub const PRIM_DISC: u32 = 1;

/// Mirrors `TriShading` in shaders/reference.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuTriShading {
    /// World-space unit normal of the first vertex; w is its u.
    pub n0: [f32; 4],
    /// World-space unit normal of the second vertex; w is the first vertex's v.
    pub n1: [f32; 4],
    /// World-space unit normal of the third vertex; w is the second vertex's u.
    pub n2: [f32; 4],
    /// The remaining texture coordinates: (v1, u2, v2, unused).
    pub uv: [f32; 4],
}

/// Pixel-samples per submit: small enough that one submit stays well under a GPU watchdog
/// (a second or so on lavapipe for simple scenes), large enough to keep the GPU busy.
const PATHS_PER_SUBMIT: u64 = 1 << 18;

/// A scene uploaded for path tracing.
pub struct PathTracer {
    device: wgpu::Device,
    queue: wgpu::Queue,
    scene: GpuScene,
    light_count: u32,
    center: Vec3,
    radius: f32,
    primitives: usize,
    nodes: wgpu::Buffer,
    tris: wgpu::Buffer,
    shading: wgpu::Buffer,
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
    /// The probe mode's cone queries, bound where there are none (binding 9 of `layout`).
    no_queries: wgpu::Buffer,
    display: progressive::DisplayPass,
    timer: GpuTimer,
}

/// World-space triangles and discs in BVH order, and the flattened BVH over them.
pub struct FlatScene {
    /// The flattened BVH; node 0 is the root.
    pub nodes: Vec<GpuNode>,
    /// The triangles and discs, in the order the leaves index them.
    pub tris: Vec<GpuTri>,
    /// Shading attributes of `tris`, in the same order.
    pub shading: Vec<GpuTriShading>,
}

/// Flattens every mesh instance into world-space triangles and every point into the disc the
/// rasterizer draws for it, and builds their BVH.
pub fn flatten(scene: &Scene) -> FlatScene {
    let mut tris = Vec::new();
    let mut shading = Vec::new();
    for inst in &scene.instances {
        let mesh = &scene.meshes[inst.mesh];
        let m = inst.transform;
        let nm = {
            let n = Mat3::from_mat4(m).inverse().transpose();
            if n.is_finite() { n } else { Mat3::IDENTITY }
        };
        let light = inst.light.map_or(NO_INDEX, |l| l as u32);
        for t in mesh.indices.chunks_exact(3) {
            let idx = [t[0] as usize, t[1] as usize, t[2] as usize];
            let p = idx.map(|i| m.transform_point3(mesh.positions[i]));
            let n = idx.map(|i| {
                let n = nm * mesh.normals[i];
                n.normalize_or_zero()
            });
            let uv = idx.map(|i| mesh.uvs.get(i).copied().unwrap_or_default());
            tris.push(GpuTri {
                p0: p[0].to_array(),
                material: mesh.material as u32,
                p1: p[1].to_array(),
                light,
                p2: p[2].to_array(),
                kind: PRIM_TRIANGLE,
            });
            shading.push(GpuTriShading {
                n0: n[0].extend(uv[0].x).to_array(),
                n1: n[1].extend(uv[0].y).to_array(),
                n2: n[2].extend(uv[1].x).to_array(),
                uv: [uv[1].y, uv[2].x, uv[2].y, 0.0],
            });
        }
    }
    // The discs the rasterizer draws: the same points, normals, radii and colours.
    let mut faceless = 0usize;
    let points = crate::gpu_scene::gpu_points(scene, false);
    let mut light_of = vec![NO_INDEX; points.points.len()];
    for (range, l) in &points.emitters {
        light_of[range.clone()].fill(*l as u32);
    }
    for (p, light) in points.points.into_iter().zip(light_of) {
        let n = p.normal();
        if n == Vec3::ZERO || p.radius.is_nan() || p.radius <= 0.0 {
            // Not drawn (radius 0) or drawn facing the viewer, which a ray cannot know.
            faceless += 1;
            continue;
        }
        tris.push(GpuTri {
            p0: p.position,
            material: 0,
            p1: n.to_array(),
            light,
            p2: [p.radius, 0.0, 0.0],
            kind: PRIM_DISC,
        });
        let [r, g, b] = p.albedo();
        let [er, eg, eb] = p.emission();
        shading.push(GpuTriShading {
            n0: [n.x, n.y, n.z, 0.0],
            n1: [r, g, b, 0.0],
            n2: [er, eg, eb, 0.0],
            uv: [0.0; 4],
        });
    }
    if faceless > 0 {
        log::warn!("reference: {faceless} points without a normal or a radius are left out");
    }
    let v = |a: [f32; 3]| glam_obvhs::Vec3A::from_array(a);
    let bounds: Vec<obvhs::aabb::Aabb> = tris
        .iter()
        .map(|t| {
            if t.kind == PRIM_DISC {
                // A disc of radius r and unit normal n spans r sqrt(1 - n_i²) along axis i.
                let (c, n) = (Vec3::from(t.p0), Vec3::from(t.p1));
                let e = (Vec3::ONE - n * n).max(Vec3::ZERO).map(f32::sqrt) * t.p2[0];
                obvhs::aabb::Aabb::new(v((c - e).to_array()), v((c + e).to_array()))
            } else {
                let mut b = obvhs::aabb::Aabb::new(v(t.p0), v(t.p0));
                b.extend(v(t.p1));
                b.extend(v(t.p2));
                b
            }
        })
        .collect();
    let bvh = build_bvh2(&bounds, obvhs::BvhBuildParams::medium_build());
    let nodes: Vec<GpuNode> = bvh
        .nodes
        .iter()
        .map(|n| GpuNode {
            lo: n.aabb.min.to_array(),
            first: n.first_index,
            hi: n.aabb.max.to_array(),
            count: n.prim_count,
        })
        .collect();
    // Leaves index `primitive_indices`: store the triangles in that order so a leaf is a range.
    let order = &bvh.primitive_indices;
    FlatScene {
        nodes,
        tris: order.iter().map(|&i| tris[i as usize]).collect(),
        shading: order.iter().map(|&i| shading[i as usize]).collect(),
    }
}

/// Depth of the flattened BVH (a single leaf has depth 1).
pub fn bvh_depth(nodes: &[GpuNode]) -> u32 {
    let mut max = 0;
    let mut stack = vec![(0usize, 1u32)];
    while let Some((i, d)) = stack.pop() {
        max = max.max(d);
        let n = &nodes[i];
        if n.count == 0 {
            stack.push((n.first as usize, d + 1));
            stack.push((n.first as usize + 1, d + 1));
        }
    }
    max
}

/// Entries of the shader's traversal stack (`STACK_SIZE` in reference.wgsl): a BVH up to this
/// deep is always traversed exactly.
pub const MAX_BVH_DEPTH: u32 = 64;

impl PathTracer {
    /// Uploads `scene` (the same data the rasterizer gets, plus triangles and their BVH). Like
    /// the rasterizer, an unlit scene gets a default sun when `options.default_light`.
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &Scene,
        options: &RendererOptions,
    ) -> Result<Self> {
        options.validate()?;
        scene.validate()?;
        if scene.triangle_count() == 0 && scene.point_count() == 0 {
            return Err(Error::EmptyScene);
        }
        let mut scene = lit_scene(scene, options.default_light);
        voxgi_scene::prepare::complete_point_attributes(&mut scene);
        let scene = scene.as_ref();
        let device = device.clone();
        let queue = queue.clone();
        let (center, radius) = view_sphere(scene);
        let flat = flatten(scene);
        let depth = bvh_depth(&flat.nodes);
        if depth > MAX_BVH_DEPTH {
            return Err(Error::Setting(format!(
                "the path tracer's BVH is {depth} levels deep, more than its traversal stack's \
                 {MAX_BVH_DEPTH}"
            )));
        }
        log::info!(
            "reference: {} triangles and discs, BVH of {} nodes, depth {depth}",
            flat.tris.len(),
            flat.nodes.len()
        );
        let (gpu_scene, buffers) = checked(&device, "reference scene upload", || -> Result<_> {
            let gpu_scene = GpuScene::new(&device, &queue, scene, options)?;
            let storage = |label: &str, bytes: &[u8]| {
                device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(label),
                    contents: bytes,
                    usage: wgpu::BufferUsages::STORAGE,
                })
            };
            Ok((
                gpu_scene,
                (
                    storage("reference bvh", bytemuck::cast_slice(&flat.nodes)),
                    storage("reference triangles", bytemuck::cast_slice(&flat.tris)),
                    storage("reference shading", bytemuck::cast_slice(&flat.shading)),
                    storage(
                        "reference no cone queries",
                        bytemuck::bytes_of(&probe::ConeQuery::zeroed()),
                    ),
                ),
            ))
        })??;
        let (layout, pipeline) = checked(&device, "reference pipeline creation", || {
            use wgpu::ShaderStages as S;
            let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("reference"),
                entries: &[
                    layout::uniform(0, S::COMPUTE, false),
                    layout::storage(1, S::COMPUTE, true),
                    layout::storage(2, S::COMPUTE, true),
                    layout::storage(3, S::COMPUTE, true),
                    layout::storage(4, S::COMPUTE, true),
                    layout::storage(5, S::COMPUTE, true),
                    layout::texture(
                        6,
                        S::COMPUTE,
                        wgpu::TextureSampleType::Float { filterable: true },
                        wgpu::TextureViewDimension::D2Array,
                    ),
                    layout::sampler(7, S::COMPUTE),
                    layout::storage(8, S::COMPUTE, false),
                    layout::storage(9, S::COMPUTE, true),
                ],
            });
            let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("reference"),
                bind_group_layouts: &[Some(&layout)],
                immediate_size: 0,
            });
            let module = shader::module(&device, "reference.wgsl");
            let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("reference"),
                layout: Some(&pl),
                module: &module,
                entry_point: Some("main"),
                compilation_options: Default::default(),
                cache: None,
            });
            (layout, pipeline)
        })?;
        Ok(PathTracer {
            display: progressive::DisplayPass::new(&device),
            timer: GpuTimer::disabled(&queue),
            device,
            queue,
            light_count: gpu_scene.light_count,
            scene: gpu_scene,
            center,
            radius,
            primitives: flat.tris.len(),
            nodes: buffers.0,
            tris: buffers.1,
            shading: buffers.2,
            layout,
            pipeline,
            no_queries: buffers.3,
        })
    }

    /// The tracing pass's bind group: `params`, the scene, the sums `accum` and the probe
    /// mode's cone `queries` (`probe::ConeQuery`).
    fn trace_group(
        &self,
        params: &wgpu::Buffer,
        accum: &wgpu::Buffer,
        queries: &wgpu::Buffer,
    ) -> wgpu::BindGroup {
        self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("reference"),
            layout: &self.layout,
            entries: &layout::entries(vec![
                params.as_entire_binding(),
                self.nodes.as_entire_binding(),
                self.tris.as_entire_binding(),
                self.shading.as_entire_binding(),
                self.scene.materials.as_entire_binding(),
                self.scene.lights.as_entire_binding(),
                wgpu::BindingResource::TextureView(&self.scene.texture_view),
                wgpu::BindingResource::Sampler(&self.scene.sampler),
                accum.as_entire_binding(),
                queries.as_entire_binding(),
            ]),
        })
    }

    /// Turns GPU timing of `accumulate` ("reference") and `display` ("reference_display") on
    /// or off (when the device has `TIMESTAMP_QUERY`).
    pub fn enable_timing(&mut self, on: bool) {
        self.timer = GpuTimer::new(&self.device, &self.queue, on);
    }

    /// Milliseconds per pass recorded since the last call, once submitted (this waits for the
    /// GPU); empty without timing.
    pub fn pass_times(&mut self) -> Result<Vec<(&'static str, f64)>> {
        self.timer.read(&self.device)
    }

    /// Changes light `index` (as `Renderer::lights` numbers them: the scene's, and the default
    /// sun when one was added) to `light`, as `Renderer::set_light` does: everything but its
    /// kind, and but an area light's place and shape (its emitter's triangles are built into
    /// the BVH: an error, make a new PathTracer), so this is exactly a path tracer built afresh
    /// with the new light. Accumulations made before show the old light: `Accumulation::reset`
    /// them.
    pub fn set_light(&mut self, index: usize, light: &Light) -> Result<()> {
        let count = self.scene.gpu_lights.len();
        let was = *self.scene.gpu_lights.get(index).ok_or_else(|| {
            Error::Setting(format!(
                "light {index} does not exist (the path tracer has {count})"
            ))
        })?;
        check_light(light)?;
        let g = gpu_light(light);
        if g.kind != was.kind {
            return Err(Error::Setting(format!(
                "light '{}': its kind is fixed once uploaded; make a new PathTracer to change it",
                light.name
            )));
        }
        let placed = |l: &GpuLight| (l.position, l.direction, l.axis_u, l.axis_v);
        if matches!(g.kind, LIGHT_RECT | LIGHT_DISC) && placed(&g) != placed(&was) {
            // Its emitter's triangles are in the BVH where the light was.
            return Err(Error::Setting(format!(
                "area light '{}': its emitter is built into the path tracer's triangles; make a \
                 new PathTracer to move or reshape it",
                light.name
            )));
        }
        self.scene.gpu_lights[index] = g;
        self.queue.write_buffer(
            &self.scene.lights,
            (index * size_of::<GpuLight>()) as u64,
            bytemuck::bytes_of(&g),
        );
        Ok(())
    }

    /// Number of primitives traced: world-space triangles and points' discs.
    pub fn primitive_count(&self) -> usize {
        self.primitives
    }

    /// Renders `opts.spp` samples per pixel, calling `progress(done, total)` after each batch.
    /// The HDR output is the mean radiance (or AO); the LDR output is tone mapped on the CPU
    /// with the frame parameters' exposure and curve, as the rasterizer's tonemap pass does.
    pub fn render(
        &mut self,
        frame: &FrameParams,
        width: u32,
        height: u32,
        opts: &ReferenceOptions,
        progress: &mut dyn FnMut(u32, u32),
    ) -> Result<RenderOutput> {
        if opts.spp == 0 {
            return Err(Error::Setting("spp must be at least 1".into()));
        }
        let mut acc = self.accumulation(width, height)?;
        let pixels = width as u64 * height as u64;
        let batch = (PATHS_PER_SUBMIT / pixels).clamp(1, 64) as u32;
        let mut done = 0u32;
        while done < opts.spp {
            let count = batch.min(opts.spp - done);
            let mut enc = self
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some("reference"),
                });
            let batch_opts = ReferenceOptions {
                spp: count,
                ..*opts
            };
            self.accumulate(
                &mut enc,
                &mut acc,
                frame,
                &batch_opts,
                Region::all(width, height),
            )?;
            self.queue.submit([enc.finish()]);
            self.device
                .poll(wgpu::PollType::wait_indefinitely())
                .map_err(|e| Error::Gpu {
                    context: "reference".into(),
                    reason: e.to_string(),
                })?;
            done += count;
            progress(done, opts.spp);
        }
        let staging = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("reference readback"),
            size: pixels * 16,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let mut enc = self.device.create_command_encoder(&Default::default());
        enc.copy_buffer_to_buffer(acc.buffer(), 0, &staging, 0, pixels * 16);
        self.queue.submit([enc.finish()]);
        let bytes = readback::read_buffer(&self.device, &staging)?;
        let inv = 1.0 / opts.spp as f32;
        let hdr: Vec<f32> = bytemuck::cast_slice::<u8, [f32; 4]>(&bytes)
            .iter()
            .flat_map(|p| [p[0] * inv, p[1] * inv, p[2] * inv, 1.0])
            .collect();
        let ldr = match opts.mode {
            // AO is a fraction in [0, 1]: shown as is.
            ReferenceMode::Ao { .. } => tonemap(&hdr, 0.0, crate::Tonemap::Clamp),
            ReferenceMode::Radiance => tonemap(&hdr, frame.exposure, frame.tonemap),
        };
        Ok(RenderOutput {
            width,
            height,
            hdr,
            ldr,
        })
    }
}

/// obvhs's `build_bvh2`, step for step, without its build timer: `std::time::Instant` panics
/// on wasm32 (the web page's path tracer).
fn build_bvh2(bounds: &[obvhs::aabb::Aabb], config: obvhs::BvhBuildParams) -> obvhs::bvh2::Bvh2 {
    use obvhs::bvh2::{leaf_collapser::collapse, reinsertion::ReinsertionOptimizer};
    let mut bvh = obvhs::ploc::PlocBuilder::with_capacity(bounds.len()).build(
        config.ploc_search_distance,
        bounds,
        (0..bounds.len() as u32).collect::<Vec<_>>(),
        config.sort_precision,
        config.search_depth_threshold,
    );
    let mut reinsertion = ReinsertionOptimizer::default();
    reinsertion.run(&mut bvh, config.reinsertion_batch_ratio, None);
    collapse(
        &mut bvh,
        config.max_prims_per_leaf.clamp(1, 255),
        config.collapse_traversal_cost,
    );
    reinsertion.run(
        &mut bvh,
        config.reinsertion_batch_ratio * config.post_collapse_reinsertion_batch_ratio_multiplier,
        None,
    );
    bvh
}
