//! The shadow atlas: every shadow view's distance map in one texture array, and where each
//! light's views are. A shared resource: `shadow` renders into it, `inject` and `composite`
//! read it.

use crate::gpu::layout;
use crate::gpu_scene::{
    CONE_SHADOW_LIGHTS, GpuLight, GpuScene, LIGHT_DIRECTIONAL, LIGHT_DISC, LIGHT_POINT, LIGHT_RECT,
    LIGHT_SPOT, NO_INDEX,
};
use crate::options::{RendererOptions, ShadowFilter};
use crate::{Error, Result};
use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec2, Vec3, Vec4};
use wgpu::util::DeviceExt;

/// Mirrors `ShadowView` in shaders/shared/scene.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuShadowView {
    /// World to clip space of the view, column-major.
    pub view_proj: [[f32; 4]; 4],
    /// Clip to world space (the inverse of `view_proj`).
    pub inv_view_proj: [[f32; 4]; 4],
    /// Where distances are measured from (the light, or the start of an orthographic view), metres.
    pub origin: [f32; 3],
    /// `SHADOW_ORTHO` (directional lights) or `SHADOW_PERSPECTIVE` (spot, point and area lights).
    pub kind: u32,
    /// Unit view direction: the light's direction, or a cube face's axis.
    pub dir: [f32; 3],
    /// World size of a texel, metres (orthographic), or its size in tangent units at distance 1
    /// (perspective).
    pub texel: f32,
    /// Near clip distance, metres.
    pub near: f32,
    /// Far clip distance, metres.
    pub far: f32,
    /// The map's width and height in texels.
    pub resolution: f32,
    /// The view's layer in the atlas.
    pub layer: u32,
    /// Emitter plane (xyz normal, w offset): geometry with dot(plane.xyz, x) + plane.w < 0 casts no
    /// shadow. Zero for lights other than area lights.
    pub plane: [f32; 4],
    /// Where the view's texels start in its layer, texels: zero, or the corner of a sample
    /// view's quarter.
    pub offset: [f32; 2],
    /// Padding to a multiple of 16 bytes; zero.
    pub _pad: [f32; 2],
}

pub(crate) const SHADOW_ORTHO: u32 = 0;
pub(crate) const SHADOW_PERSPECTIVE: u32 = 1;
/// Uniform dynamic offsets must be multiples of 256 bytes.
pub(crate) const UNIFORM_STRIDE: u64 = 256;
/// Format of the atlas's distance maps: the nearest occluder's distance per texel, metres.
pub const ATLAS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;
/// Format of the atlas of a scene with metals: the distance, and the specular material of the
/// surface seen there (lighting/shadow.wgsl's `material_code`).
pub const MATERIAL_ATLAS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rg32Float;
/// Format of the prefiltered moments (lighting/moments.wgsl): f32, since the variance is a
/// difference of two close squares.
pub const MOMENTS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

/// The shadow views of a scene's lights and the textures they render into.
pub struct ShadowAtlas {
    /// Every shadow view, in layer order (`GpuLight::shadow_first` indexes it).
    pub views: Vec<GpuShadowView>,
    /// Which light each view belongs to.
    pub view_light: Vec<usize>,
    /// The atlas texture: one square `ATLAS_FORMAT` (or `MATERIAL_ATLAS_FORMAT`) layer per view
    /// (at least one).
    pub texture: wgpu::Texture,
    /// `texture` as a 2D-array view, for the lighting passes.
    pub array_view: wgpu::TextureView,
    /// One view per layer, for rendering into it.
    pub(crate) layer_views: Vec<wgpu::TextureView>,
    /// With `ShadowFilter::VsmEsm`: per map texel, the moments of its 5x5-texel disc
    /// (`MOMENTS_FORMAT`: mean normalised distance, its square, and the exponential map), same
    /// layers as `texture`; otherwise one texel (bound, never read).
    pub moments: wgpu::Texture,
    /// `moments` as a 2D-array view.
    pub moments_view: wgpu::TextureView,
    pub(crate) depth_view: wgpu::TextureView,
    /// `views` as a storage buffer (binding 2 of `lighting_layout`).
    pub views_buffer: wgpu::Buffer,
    /// Each view's `GpuShadowView` at a `UNIFORM_STRIDE` offset (the shadow pass's dynamic
    /// uniform).
    pub(crate) uniforms: wgpu::Buffer,
    /// Whether area lights have sample views (`plan_views`' `samples`).
    pub samples: bool,
    /// Index of the first sample view: they follow all the other views.
    first_sample: usize,
    /// The views' static geometry alone, kept so that a view re-rendered where dynamic
    /// geometry was or is draws only the dynamic geometry (`ShadowPass::record`), when
    /// `keep_static_maps` holds; None otherwise.
    pub(crate) statics: Option<StaticMaps>,
}

/// The shadow views' maps of the static geometry alone (every view but the sample views,
/// which move every frame): what a view holds before the dynamic geometry is drawn over it.
pub(crate) struct StaticMaps {
    pub texture: wgpu::Texture,
    /// One view per layer, for rendering into it.
    pub layer_views: Vec<wgpu::TextureView>,
    /// `texture` as a 2D-array view, read by the dynamic geometry's fragments.
    pub array_view: wgpu::TextureView,
    /// Per view: its layer holds its static geometry as the view is now.
    pub fresh: Vec<bool>,
}

fn up_for(dir: Vec3) -> Vec3 {
    if dir.y.abs() > 0.99 { Vec3::Z } else { Vec3::Y }
}

/// Points on an area light whose shadows are sampled per frame (temporal accumulation): each
/// a cube of views, the four sharing six layers of the atlas, a quarter of each layer apiece.
pub const SAMPLE_POINTS: usize = 4;

/// Lays out shadow views for every shadow-casting light and records in `lights` where each
/// light's views are. With `samples`, each shadow-casting area light also gets
/// `SAMPLE_POINTS` cubes of sample views (after all the other views), placed at its centre
/// until `sample_views` moves them.
pub fn plan_views(
    lights: &mut [GpuLight],
    casts: &[bool],
    center: Vec3,
    radius: f32,
    res: u32,
    samples: bool,
) -> (Vec<GpuShadowView>, Vec<usize>) {
    let mut views = Vec::new();
    let mut owner = Vec::new();
    let near = (radius * 1e-4).max(1e-5);
    let res_f = res as f32;
    for (li, light) in lights.iter_mut().enumerate() {
        light.sample_first = NO_INDEX;
        if !casts[li] {
            continue;
        }
        let first = views.len() as u32;
        let pos = Vec3::from(light.position);
        let dir = Vec3::from(light.direction).normalize();
        let far_from = |o: Vec3| (o - center).length() + radius * 1.01;
        let plane = if matches!(light.kind, LIGHT_RECT | LIGHT_DISC) {
            [dir.x, dir.y, dir.z, -dir.dot(pos)]
        } else {
            [0.0; 4]
        };
        let mut push = |view: Mat4,
                        proj: Mat4,
                        origin: Vec3,
                        kind: u32,
                        vdir: Vec3,
                        texel: f32,
                        near: f32,
                        far: f32| {
            views.push(GpuShadowView {
                view_proj: (proj * view).to_cols_array_2d(),
                inv_view_proj: (proj * view).inverse().to_cols_array_2d(),
                origin: origin.to_array(),
                kind,
                dir: vdir.to_array(),
                texel,
                near,
                far,
                resolution: res_f,
                layer: 0,
                plane,
                offset: [0.0; 2],
                _pad: [0.0; 2],
            });
            owner.push(li);
        };
        match light.kind {
            LIGHT_DIRECTIONAL => {
                // Fit the scene's bounding sphere; the map starts just outside it.
                let origin = center - dir * radius * 1.05;
                let view = Mat4::look_at_rh(origin, origin + dir, up_for(dir));
                let proj =
                    Mat4::orthographic_rh(-radius, radius, -radius, radius, 0.0, radius * 2.1);
                push(
                    view,
                    proj,
                    origin,
                    SHADOW_ORTHO,
                    dir,
                    2.0 * radius / res_f,
                    0.0,
                    radius * 2.1,
                );
            }
            LIGHT_SPOT => {
                let half = (light.cos_outer.clamp(-1.0, 1.0).acos() + 2f32.to_radians())
                    .min(85f32.to_radians());
                let view = Mat4::look_at_rh(pos, pos + dir, up_for(dir));
                let far = far_from(pos);
                let proj = Mat4::perspective_rh(2.0 * half, 1.0, near, far);
                push(
                    view,
                    proj,
                    pos,
                    SHADOW_PERSPECTIVE,
                    dir,
                    2.0 * half.tan() / res_f,
                    near,
                    far,
                );
            }
            LIGHT_POINT | LIGHT_RECT | LIGHT_DISC => {
                // Area lights look out from just in front of their surface.
                let origin = if light.kind == LIGHT_POINT {
                    pos
                } else {
                    pos + dir * near * 2.0
                };
                for v in cube_views(origin, plane, near, far_from(origin), res_f) {
                    views.push(v);
                    owner.push(li);
                }
            }
            _ => {}
        }
        light.shadow_first = first;
        light.shadow_count = views.len() as u32 - first;
    }
    for (i, v) in views.iter_mut().enumerate() {
        v.layer = i as u32;
    }
    if samples {
        let mut layer = views.len() as u32;
        for (li, light) in lights.iter_mut().enumerate() {
            if !casts[li] || !light.is_area() {
                continue;
            }
            light.sample_first = views.len() as u32;
            let centre = [Vec2::splat(0.5); SAMPLE_POINTS];
            views.extend(sample_views(light, layer, centre, center, radius, res));
            owner.extend([li; 6 * SAMPLE_POINTS]);
            layer += 6;
        }
    }
    (views, owner)
}

/// The six perspective views of a cube around `origin` (a point or area light's shadow
/// views), each `res` texels square with its layer and offset left zero.
fn cube_views(origin: Vec3, plane: [f32; 4], near: f32, far: f32, res: f32) -> Vec<GpuShadowView> {
    // A guard band of a few texels lets filter taps near a face's edge stay inside it.
    let tan_half = 1.0 + 4.0 / res;
    let proj = Mat4::perspective_rh(2.0 * tan_half.atan(), 1.0, near, far);
    [
        Vec3::X,
        Vec3::NEG_X,
        Vec3::Y,
        Vec3::NEG_Y,
        Vec3::Z,
        Vec3::NEG_Z,
    ]
    .into_iter()
    .map(|axis| {
        let view_proj = proj * Mat4::look_at_rh(origin, origin + axis, up_for(axis));
        GpuShadowView {
            view_proj: view_proj.to_cols_array_2d(),
            inv_view_proj: view_proj.inverse().to_cols_array_2d(),
            origin: origin.to_array(),
            kind: SHADOW_PERSPECTIVE,
            dir: axis.to_array(),
            texel: 2.0 * tan_half / res,
            near,
            far,
            resolution: res,
            layer: 0,
            plane,
            offset: [0.0; 2],
            _pad: [0.0; 2],
        }
    })
    .collect()
}

/// The point of an area light at `u` in the unit square: a rectangle's point at those
/// fractions of its edges, or a disc's at radius fraction sqrt(u.x) and angle 2 pi u.y (equal
/// areas to equal squares).
pub fn light_point(light: &GpuLight, u: Vec2) -> Vec3 {
    let (c, a, b) = (
        Vec3::from(light.position),
        Vec3::from(light.axis_u),
        Vec3::from(light.axis_v),
    );
    if light.kind == LIGHT_RECT {
        return c + (2.0 * u.x - 1.0) * a + (2.0 * u.y - 1.0) * b;
    }
    let (r, t) = (u.x.sqrt(), std::f32::consts::TAU * u.y);
    c + r * (t.cos() * a + t.sin() * b)
}

/// The `SAMPLE_POINTS` cubes of an area light's sample views, one at each of `points` (unit
/// square coordinates, `light_point`), in layers `layer..layer + 6` (face by face) of an
/// atlas of `res`-texel layers: point i in the quarter (i % 2, i / 2) of each.
pub fn sample_views(
    light: &GpuLight,
    layer: u32,
    points: [Vec2; SAMPLE_POINTS],
    center: Vec3,
    radius: f32,
    res: u32,
) -> Vec<GpuShadowView> {
    let near = (radius * 1e-4).max(1e-5);
    let dir = Vec3::from(light.direction).normalize();
    let plane = [dir.x, dir.y, dir.z, -dir.dot(Vec3::from(light.position))];
    let half = (res / 2) as f32;
    let mut out = Vec::with_capacity(6 * SAMPLE_POINTS);
    for (i, u) in points.iter().enumerate() {
        let origin = light_point(light, *u) + dir * near * 2.0;
        let far = (origin - center).length() + radius * 1.01;
        for (face, mut v) in cube_views(origin, plane, near, far, half)
            .into_iter()
            .enumerate()
        {
            v.layer = layer + face as u32;
            v.offset = [(i % 2) as f32 * half, (i / 2) as f32 * half];
            out.push(v);
        }
    }
    out
}

/// What of a shadow view's map is out of date.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ViewDirt {
    /// Nothing: the map is current.
    Clean,
    /// All of it (its light changed, or a rebuild).
    All,
    /// The texels within this rectangle of texture coordinates (0..1, v down), where
    /// something moved.
    Rect {
        /// Lower corner.
        min: Vec2,
        /// Upper corner.
        max: Vec2,
    },
}

impl ViewDirt {
    /// What is out of date after both `self` and `other`.
    pub fn merge(self, other: ViewDirt) -> ViewDirt {
        match (self, other) {
            (ViewDirt::Clean, d) | (d, ViewDirt::Clean) => d,
            (ViewDirt::All, _) | (_, ViewDirt::All) => ViewDirt::All,
            (ViewDirt::Rect { min: a, max: b }, ViewDirt::Rect { min: c, max: d }) => {
                ViewDirt::Rect {
                    min: a.min(c),
                    max: b.max(d),
                }
            }
        }
    }

    /// The texels a `res`-texel map re-renders for this (`scissor`), as `vec4(x0, y0, x1, y1)`
    /// (x1, y1 exclusive) for the shaders; an empty rectangle when clean.
    pub fn to_gpu(self, res: u32) -> [f32; 4] {
        match self.scissor(res) {
            None => [1.0, 1.0, 0.0, 0.0],
            Some((x, y, w, h)) => [x as f32, y as f32, (x + w) as f32, (y + h) as f32],
        }
    }

    /// The texels of a `res`-texel map to re-render, as a scissor rectangle (x, y, width,
    /// height), with a texel of margin for the rasterizer's rounding; `None` when clean.
    pub fn scissor(self, res: u32) -> Option<(u32, u32, u32, u32)> {
        match self {
            ViewDirt::Clean => None,
            ViewDirt::All => Some((0, 0, res, res)),
            ViewDirt::Rect { min, max } => {
                let r = res as f32;
                let lo = |v: f32| ((v * r).floor() - 1.0).clamp(0.0, r) as u32;
                let hi = |v: f32| ((v * r).ceil() + 1.0).clamp(0.0, r) as u32;
                let (x0, y0, x1, y1) = (lo(min.x), lo(min.y), hi(max.x), hi(max.y));
                (x1 > x0 && y1 > y0).then_some((x0, y0, x1 - x0, y1 - y0))
            }
        }
    }
}

/// Where the box `min..max` can show in `view`'s map: `Clean` when all eight corners lie
/// outside one of the view's clip planes, `All` when the box reaches behind a perspective
/// view's origin, else the rectangle around the corners' projections, clamped to the map.
pub fn box_dirt(view: &GpuShadowView, min: Vec3, max: Vec3) -> ViewDirt {
    let m = Mat4::from_cols_array_2d(&view.view_proj);
    let corners: Vec<Vec4> = (0..8)
        .map(|i| {
            let p = Vec3::new(
                if i & 1 == 0 { min.x } else { max.x },
                if i & 2 == 0 { min.y } else { max.y },
                if i & 4 == 0 { min.z } else { max.z },
            );
            m * p.extend(1.0)
        })
        .collect();
    // wgpu clip space: -w <= x, y <= w and 0 <= z <= w.
    let planes: [fn(Vec4) -> f32; 6] = [
        |c| c.w + c.x,
        |c| c.w - c.x,
        |c| c.w + c.y,
        |c| c.w - c.y,
        |c| c.z,
        |c| c.w - c.z,
    ];
    if planes
        .iter()
        .any(|plane| corners.iter().all(|&c| plane(c) < 0.0))
    {
        return ViewDirt::Clean;
    }
    if corners.iter().any(|c| c.w <= 1e-6) {
        return ViewDirt::All;
    }
    let (mut lo, mut hi) = (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY));
    for c in &corners {
        let uv = Vec2::new(c.x / c.w * 0.5 + 0.5, 0.5 - c.y / c.w * 0.5);
        lo = lo.min(uv);
        hi = hi.max(uv);
    }
    ViewDirt::Rect {
        min: lo.clamp(Vec2::ZERO, Vec2::ONE),
        max: hi.clamp(Vec2::ZERO, Vec2::ONE),
    }
}

/// Whether a cube face of an area light sees only what lies behind the emitter's plane, which
/// the light cannot reach and so nobody looks up (the face opposite a one-sided emitter's
/// direction): such a face is not rendered.
pub fn behind_emitter(view: &GpuShadowView) -> bool {
    let n = Vec3::new(view.plane[0], view.plane[1], view.plane[2]);
    if view.kind != SHADOW_PERSPECTIVE || n == Vec3::ZERO {
        return false;
    }
    // The face's frustum spans its axis a plus up to tan_half times the two other (coordinate)
    // axes; its highest point over the plane is a.n + tan_half (|n|_1 - |a.n|).
    let a = Vec3::from(view.dir);
    let tan_half = 0.5 * view.texel * view.resolution;
    let reach = a.dot(n) + tan_half * (n.abs().element_sum() - a.dot(n).abs());
    reach <= 0.0
}

/// Shadow-map size: the setting, or, when every light's visibility on screen is cone-traced
/// and the maps serve only the voxel injection, four texels per voxel of the volume (the
/// injection reads them at voxel centres; finer maps only cost rendering time).
pub fn atlas_resolution(settings: &RendererOptions, lights: &[GpuLight]) -> u32 {
    if composite_reads_shadow_maps(lights, settings.cone_shadows) {
        settings.shadow_map_size
    } else {
        settings
            .shadow_map_size
            .min((4 * settings.voxel_resolution).max(256))
    }
}

/// Whether the composite looks up shadow maps: not when every light is an area light whose
/// visibility the gather cone-traces (the first `CONE_SHADOW_LIGHTS` area lights).
pub fn composite_reads_shadow_maps(lights: &[GpuLight], cone_shadows: bool) -> bool {
    let cone_traced =
        cone_shadows && lights.len() <= CONE_SHADOW_LIGHTS && lights.iter().all(GpuLight::is_area);
    !cone_traced
}

/// Refuses an atlas the device cannot make, naming the count and the limit, before anything
/// is made: more layers than its texture arrays hold, or more bytes than one allocation may
/// take (wgpu's own error names neither; its largest buffer stands for the largest
/// allocation, which is what Vulkan drivers derive it from).
fn check_atlas(
    views: &[GpuShadowView],
    casts: &[bool],
    res: u32,
    moments: bool,
    materials: bool,
    limits: &wgpu::Limits,
) -> Result<()> {
    let layers = views.iter().map(|v| v.layer + 1).max().unwrap_or(1);
    // The distance maps (R32Float, Rg32Float with materials), and with VSM/ESM filtering their
    // moments (Rgba32Float), a texture of the same layers of its own.
    let texel = if moments {
        16
    } else if materials {
        8
    } else {
        4
    };
    let bytes = res as u64 * res as u64 * layers as u64 * texel;
    let lights = casts.iter().filter(|&&c| c).count();
    let cause = if layers > limits.max_texture_array_layers {
        format!(
            "more than this GPU's limit of {} texture array layers",
            limits.max_texture_array_layers
        )
    } else if bytes > limits.max_buffer_size {
        format!(
            "{} MiB at {res}² texels a map, more than the {} MiB this GPU allocates at once",
            bytes >> 20,
            limits.max_buffer_size >> 20
        )
    } else {
        return Ok(());
    };
    Err(Error::Setting(format!(
        "{lights} shadow-casting lights need {layers} shadow-map layers, {cause} (a point or \
         area light takes 6 layers, an area light 6 more for its sampled shadows with temporal \
         accumulation, a spot or directional light 1): lower shadow_map_size, choose a \
         shadow_filter other than vsm-esm, or set cast_shadows = false on some lights"
    )))
}

impl ShadowAtlas {
    /// Makes the atlas for `views` (owned by the lights in `view_light`), each map `res` texels
    /// square, with its depth buffer and view buffers, and with `moments` the prefiltered
    /// moments of every map, and with `materials` the surfaces' specular materials beside the
    /// distances (`MATERIAL_ATLAS_FORMAT`).
    #[allow(clippy::too_many_arguments)] // the atlas's shape, one argument each
    pub fn new(
        device: &wgpu::Device,
        views: Vec<GpuShadowView>,
        view_light: Vec<usize>,
        res: u32,
        moments: bool,
        samples: bool,
        dynamic: bool,
        materials: bool,
    ) -> Self {
        let format = if materials {
            MATERIAL_ATLAS_FORMAT
        } else {
            ATLAS_FORMAT
        };
        let layers = views.iter().map(|v| v.layer + 1).max().unwrap_or(1);
        // Sample views are the quarter-size ones, after all the others (`plan_views`).
        let first_sample = views
            .iter()
            .position(|v| v.resolution as u32 != res)
            .unwrap_or(views.len());
        let (mres, mlayers) = if moments { (res, layers) } else { (1, 1) };
        let moments = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("shadow moments"),
            size: wgpu::Extent3d {
                width: mres,
                height: mres,
                depth_or_array_layers: mlayers,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: MOMENTS_FORMAT,
            usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let moments_view = moments.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        // Distance maps, one square layer a view.
        let maps = |label: &str, layers: u32, usage: wgpu::TextureUsages| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d {
                    width: res,
                    height: res,
                    depth_or_array_layers: layers,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage: usage
                    | wgpu::TextureUsages::RENDER_ATTACHMENT
                    | wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            })
        };
        let texture = maps(
            "shadow atlas",
            layers,
            wgpu::TextureUsages::COPY_DST | wgpu::TextureUsages::COPY_SRC,
        );
        let layer_views = |texture: &wgpu::Texture, layers: u32| {
            (0..layers)
                .map(|l| {
                    texture.create_view(&wgpu::TextureViewDescriptor {
                        label: Some("shadow layer"),
                        dimension: Some(wgpu::TextureViewDimension::D2),
                        base_array_layer: l,
                        array_layer_count: Some(1),
                        ..Default::default()
                    })
                })
                .collect()
        };
        let array_of = |texture: &wgpu::Texture| {
            texture.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2Array),
                ..Default::default()
            })
        };
        // The sample views move every frame: their layers (after the others') keep nothing.
        let static_layers = views[..first_sample]
            .iter()
            .map(|v| v.layer + 1)
            .max()
            .unwrap_or(1);
        let statics = dynamic.then(|| {
            let texture = maps(
                "shadow atlas, static geometry",
                static_layers,
                wgpu::TextureUsages::COPY_SRC,
            );
            StaticMaps {
                layer_views: layer_views(&texture, static_layers),
                array_view: array_of(&texture),
                fresh: vec![false; views.len()],
                texture,
            }
        });
        let array_view = array_of(&texture);
        let layer_views = layer_views(&texture, layers);
        let depth = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("shadow depth"),
            size: wgpu::Extent3d {
                width: res,
                height: res,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Depth32Float,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        });
        let mut uniform_bytes = vec![0u8; UNIFORM_STRIDE as usize * views.len().max(1)];
        for (i, v) in views.iter().enumerate() {
            let o = i * UNIFORM_STRIDE as usize;
            uniform_bytes[o..o + size_of::<GpuShadowView>()].copy_from_slice(bytemuck::bytes_of(v));
        }
        let mut view_bytes = bytemuck::cast_slice::<_, u8>(&views).to_vec();
        view_bytes.resize(view_bytes.len().max(size_of::<GpuShadowView>()), 0);
        ShadowAtlas {
            uniforms: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("shadow view uniforms"),
                contents: &uniform_bytes,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            }),
            views_buffer: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("shadow views"),
                contents: &view_bytes,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            }),
            views,
            view_light,
            texture,
            array_view,
            layer_views,
            moments,
            moments_view,
            depth_view: depth.create_view(&Default::default()),
            samples,
            first_sample,
            statics,
        }
    }

    /// The indices of the area lights' sample views (empty without them).
    pub fn sample_views(&self) -> std::ops::Range<usize> {
        self.first_sample..self.views.len()
    }

    /// Moves the sample views of every area light that has them to `points` (unit square
    /// coordinates on the light, `light_point`), writing them where the passes read them.
    pub fn move_samples(
        &mut self,
        queue: &wgpu::Queue,
        lights: &[GpuLight],
        points: [Vec2; SAMPLE_POINTS],
        center: Vec3,
        radius: f32,
    ) {
        let res = self.texture.width();
        for light in lights.iter().filter(|l| l.sample_first != NO_INDEX) {
            let first = light.sample_first as usize;
            let layer = self.views[first].layer;
            let views = sample_views(light, layer, points, center, radius, res);
            for (i, v) in views.iter().enumerate() {
                queue.write_buffer(
                    &self.uniforms,
                    (first + i) as u64 * UNIFORM_STRIDE,
                    bytemuck::bytes_of(v),
                );
            }
            queue.write_buffer(
                &self.views_buffer,
                (first * size_of::<GpuShadowView>()) as u64,
                bytemuck::cast_slice(&views),
            );
            self.views[first..first + views.len()].copy_from_slice(&views);
        }
    }

    /// Replaces the views by `views` (re-planned after lights moved: the same number, owned by
    /// the same lights), writing them where the passes read them. The maps are not re-rendered
    /// here.
    pub fn update_views(&mut self, queue: &wgpu::Queue, views: Vec<GpuShadowView>) {
        debug_assert_eq!(views.len(), self.views.len());
        for (i, v) in views.iter().enumerate() {
            queue.write_buffer(
                &self.uniforms,
                i as u64 * UNIFORM_STRIDE,
                bytemuck::bytes_of(v),
            );
        }
        if !views.is_empty() {
            queue.write_buffer(&self.views_buffer, 0, bytemuck::cast_slice(&views));
        }
        if let Some(s) = &mut self.statics {
            for (i, (new, old)) in views.iter().zip(&self.views).enumerate() {
                if bytemuck::bytes_of(new) != bytemuck::bytes_of(old) {
                    s.fresh[i] = false;
                }
            }
        }
        self.views = views;
    }

    /// Forgets the static geometry's maps (the next render of each view draws them anew).
    pub fn forget_statics(&mut self) {
        if let Some(s) = &mut self.statics {
            s.fresh.fill(false);
        }
    }

    /// Bindings 1 to 4 of every shader that includes `shared/lights.wgsl`: the lights, the
    /// shadow views, this atlas's maps and their moments.
    pub fn lighting_layout(c: wgpu::ShaderStages) -> [wgpu::BindGroupLayoutEntry; 4] {
        let array = |binding| {
            layout::texture(
                binding,
                c,
                wgpu::TextureSampleType::Float { filterable: false },
                wgpu::TextureViewDimension::D2Array,
            )
        };
        [
            layout::storage(1, c, true),
            layout::storage(2, c, true),
            array(3),
            array(4),
        ]
    }

    /// The resources for `lighting_layout`, in its order.
    pub fn lighting_resources<'a>(&'a self, scene: &'a GpuScene) -> [wgpu::BindingResource<'a>; 4] {
        [
            scene.lights.as_entire_binding(),
            self.views_buffer.as_entire_binding(),
            wgpu::BindingResource::TextureView(&self.array_view),
            wgpu::BindingResource::TextureView(&self.moments_view),
        ]
    }

    /// GPU memory of the atlas in bytes, counted as the distance (and material) texel plus
    /// 4 bytes of Depth32 depth per texel of every layer (the depth texture has one layer, so
    /// this is an upper bound), plus the moments and the static geometry's maps.
    pub fn bytes(&self) -> u64 {
        let texels = |t: &wgpu::Texture| {
            t.width() as u64 * t.height() as u64 * t.depth_or_array_layers() as u64
        };
        let texel = self.texture.format().block_copy_size(None).unwrap_or(4) as u64;
        let statics = self
            .statics
            .as_ref()
            .map_or(0, |s| texels(&s.texture) * texel);
        texels(&self.texture) * (texel + 4) + texels(&self.moments) * 16 + statics
    }
}

/// Plans the shadow views for the options (writing each light's views into `scene`'s
/// lights) and makes the atlas that holds them.
pub fn plan_atlas(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    scene: &mut GpuScene,
    casts: &[bool],
    options: &RendererOptions,
    center: Vec3,
    radius: f32,
) -> Result<ShadowAtlas> {
    let res = atlas_resolution(options, &scene.gpu_lights);
    // Area-light shadows sampled over frames need the frames' accumulation.
    let samples = options.temporal;
    let (views, owners) = plan_views(&mut scene.gpu_lights, casts, center, radius, res, samples);
    let moments = options.shadow_filter == ShadowFilter::VsmEsm;
    // The surfaces' specular materials, for the leaves' lobes.
    let materials = scene.metals && options.specular_bounces;
    check_atlas(&views, casts, res, moments, materials, &device.limits())?;
    crate::gpu::checked(device, "shadow atlas", || {
        queue.write_buffer(&scene.lights, 0, bytemuck::cast_slice(&scene.gpu_lights));
        ShadowAtlas::new(
            device,
            views,
            owners,
            res,
            moments,
            samples,
            keep_static_maps(scene),
            materials,
        )
    })
}

/// How many times the dynamic occluders the static ones must number (triangles and surfels)
/// for an atlas to keep the static geometry's maps: they cost half the atlas again, and pay
/// for it only where redrawing the static geometry under a moving object costs more than
/// drawing that object.
pub const STATIC_MAPS_FROM: u64 = 4;

/// Whether an atlas for `scene` keeps the static geometry's maps (`StaticMaps`): when
/// something moves (meshes or clouds; area lights' emitters move with their lights, but alone
/// are few) and the static occluders number `STATIC_MAPS_FROM` times the dynamic ones.
pub fn keep_static_maps(scene: &GpuScene) -> bool {
    // Triangles and surfels: the static geometry's, the dynamic geometry's, the emitters'.
    let (mut fixed, mut dynamic, mut emitters) = (0u64, 0u64, 0u64);
    for c in &scene.calls {
        let triangles = c.indices.len() as u64 / 3;
        if c.dynamic {
            dynamic += triangles;
        } else if c.light.is_some() {
            emitters += triangles;
        } else {
            fixed += triangles;
        }
    }
    fixed += scene.static_points as u64;
    dynamic += (scene.geometry_points - scene.static_points) as u64;
    emitters += scene
        .emitter_points
        .iter()
        .map(|(r, _)| r.len() as u64)
        .sum::<u64>();
    dynamic > 0 && fixed >= STATIC_MAPS_FROM * (dynamic + emitters)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn light(kind: u32, direction: [f32; 3]) -> GpuLight {
        GpuLight {
            kind,
            position: [0.0, 1.0, 0.0],
            direction,
            ..Default::default()
        }
    }

    #[test]
    fn only_cone_shadowed_area_lights_skip_the_shadow_maps() {
        let rect = light(LIGHT_RECT, [0.0, -1.0, 0.0]);
        let disc = light(LIGHT_DISC, [0.0, -1.0, 0.0]);
        let point = light(LIGHT_POINT, [0.0, -1.0, 0.0]);
        assert!(!composite_reads_shadow_maps(&[rect, disc], true));
        assert!(composite_reads_shadow_maps(&[rect, disc], false));
        // A point light keeps its shadow map beside cone-shadowed area lights.
        assert!(composite_reads_shadow_maps(&[rect, point], true));
        // Only the first CONE_SHADOW_LIGHTS area lights get a cone.
        assert!(composite_reads_shadow_maps(
            &[rect; CONE_SHADOW_LIGHTS + 1],
            true
        ));
        let settings = |cone_shadows| RendererOptions {
            cone_shadows,
            voxel_resolution: 64,
            ..RendererOptions::default()
        };
        assert_eq!(atlas_resolution(&settings(true), &[rect]), 256);
        assert_eq!(atlas_resolution(&settings(false), &[rect]), 1024);
        assert_eq!(atlas_resolution(&settings(true), &[rect, point]), 1024);
    }

    #[test]
    fn a_down_facing_emitter_skips_only_its_upward_cube_face() {
        let mut lights = [light(LIGHT_RECT, [0.0, -1.0, 0.0])];
        let (views, _) = plan_views(&mut lights, &[true], Vec3::ZERO, 2.0, 256, false);
        let skipped: Vec<[f32; 3]> = views
            .iter()
            .filter(|v| behind_emitter(v))
            .map(|v| v.dir)
            .collect();
        assert_eq!(skipped, vec![[0.0, 1.0, 0.0]]);
        // A point light sees all round: no face is skipped.
        let mut lights = [light(LIGHT_POINT, [0.0, -1.0, 0.0])];
        let (views, _) = plan_views(&mut lights, &[true], Vec3::ZERO, 2.0, 256, false);
        assert!(views.iter().all(|v| !behind_emitter(v)));
        // A tilted emitter sees a little of every side face, so none is skipped but the back.
        let d = Vec3::new(0.3, -1.0, 0.2).normalize();
        let mut lights = [light(LIGHT_RECT, d.to_array())];
        let (views, _) = plan_views(&mut lights, &[true], Vec3::ZERO, 2.0, 256, false);
        assert_eq!(views.iter().filter(|v| behind_emitter(v)).count(), 1);
    }

    #[test]
    fn sample_views_follow_the_regular_views_in_quarters_of_six_layers() {
        let mut rect = light(LIGHT_RECT, [0.0, -1.0, 0.0]);
        rect.axis_u = [0.2, 0.0, 0.0];
        rect.axis_v = [0.0, 0.0, 0.1];
        let mut lights = [light(LIGHT_POINT, [0.0, -1.0, 0.0]), rect];
        let (views, owners) = plan_views(&mut lights, &[true, true], Vec3::ZERO, 2.0, 256, true);
        // Two cubes of regular views, then the rectangle's four sample cubes.
        assert_eq!(views.len(), 12 + 6 * SAMPLE_POINTS);
        assert_eq!(lights[0].sample_first, NO_INDEX);
        assert_eq!(lights[1].sample_first, 12);
        assert!(owners[12..].iter().all(|&o| o == 1));
        for (i, v) in views[12..].iter().enumerate() {
            let (point, face) = (i / 6, i % 6);
            assert_eq!(v.layer, 12 + face as u32);
            assert_eq!(v.resolution, 128.0);
            assert_eq!(
                v.offset,
                [(point % 2) as f32 * 128.0, (point / 2) as f32 * 128.0]
            );
        }
        // Without samples, nothing follows the regular views.
        let (views, _) = plan_views(&mut lights, &[true, true], Vec3::ZERO, 2.0, 256, false);
        assert_eq!((views.len(), lights[1].sample_first), (12, NO_INDEX));
    }

    #[test]
    fn light_points_span_the_emitter() {
        let mut rect = light(LIGHT_RECT, [0.0, -1.0, 0.0]);
        rect.axis_u = [0.2, 0.0, 0.0];
        rect.axis_v = [0.0, 0.0, 0.1];
        // The unit square's corners are the rectangle's corners, its centre the light's.
        assert!(light_point(&rect, Vec2::ZERO).distance(Vec3::new(-0.2, 1.0, -0.1)) < 1e-6);
        assert!(light_point(&rect, Vec2::ONE).distance(Vec3::new(0.2, 1.0, 0.1)) < 1e-6);
        assert!(light_point(&rect, Vec2::splat(0.5)).distance(Vec3::Y) < 1e-6);
        // A disc's points lie within its radius, on its plane, the rim at u.x = 1.
        let mut disc = rect;
        disc.kind = LIGHT_DISC;
        disc.axis_u = [0.3, 0.0, 0.0];
        disc.axis_v = [0.0, 0.0, 0.3];
        for (x, y) in [(0.0, 0.0), (0.25, 0.3), (0.99, 0.7), (1.0, 0.5)] {
            let d = light_point(&disc, Vec2::new(x, y)) - Vec3::Y;
            assert!(d.y.abs() < 1e-6 && d.length() <= 0.3 + 1e-6, "{d}");
            assert!((d.length() - 0.3 * x.sqrt()).abs() < 1e-5);
        }
    }
}
