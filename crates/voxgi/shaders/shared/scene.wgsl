// Structs shared by every pass. Each has a #[repr(C)] twin in src/gpu_scene.rs; the test
// `wgsl_struct_sizes` checks the two agree.

const PI: f32 = 3.14159265358979;
const NO_INDEX: u32 = 0xffffffffu;

// Frame.view_mode: ViewMode::id() in src/options.rs (a test checks the two agree).
const VIEW_FINAL: u32 = 0u;
const VIEW_ALBEDO: u32 = 1u;
const VIEW_NORMAL: u32 = 2u;
const VIEW_DIRECT: u32 = 3u;
const VIEW_AO: u32 = 4u;
const VIEW_INDIRECT: u32 = 5u;
const VIEW_VOXEL_ALBEDO: u32 = 6u;
const VIEW_VOXEL_OPACITY: u32 = 7u;
const VIEW_VOXEL_RADIANCE: u32 = 8u;
const VIEW_VOXEL_NODES: u32 = 9u;
const VIEW_MOTION: u32 = 10u;

// Frame.tonemap: Tonemap::id() in src/options.rs.
const TONEMAP_ACES: u32 = 0u;
const TONEMAP_NEUTRAL: u32 = 1u;
const TONEMAP_CLAMP: u32 = 2u;

// Per-frame camera and output parameters.
struct Frame {
    view_proj: mat4x4<f32>,
    inv_view_proj: mat4x4<f32>,
    camera_pos: vec3<f32>,
    light_count: u32,
    size: vec2<f32>,
    inv_size: vec2<f32>,
    // 2^EV, applied before tone mapping.
    exposure: f32,
    // TONEMAP_*.
    tonemap: u32,
    // Filter radius of punctual-light shadows, in shadow-map texels.
    shadow_softness: f32,
    // VIEW_*: output selection for debugging.
    view_mode: u32,
    background: vec4<f32>,
    // 1: area lights' shadows by a cone traced through the voxels instead of the shadow map.
    cone_shadows: u32,
    // The points from this index on show area lights (GpuScene::geometry_points).
    geometry_points: u32,
    // This frame's sub-pixel camera offset, pixels (view_proj includes it).
    jitter: vec2<f32>,
    // The previous frame's world-to-clip matrix without its jitter.
    prev_view_proj: mat4x4<f32>,
    // This frame's world-to-clip matrix without the jitter.
    view_proj_unjittered: mat4x4<f32>,
    prev_camera_pos: vec3<f32>,
    // HISTORY_*: what the temporal pass may do with the history.
    history: u32,
    // How far this frame shifts the diffuse cones' turns about the normal and in zenith, in
    // interleaving steps.
    cone_turn: vec2<f32>,
    // Which frame of the area lights' sample points the sample views show.
    light_sample: u32,
    _pad2: u32,
}

const HISTORY_NONE: u32 = 0u;
const HISTORY_MOVING: u32 = 1u;
const HISTORY_STILL: u32 = 2u;

// One vertex, pulled from a storage buffer (no vertex buffers: every pass reads the same data).
struct Vertex {
    position: vec3<f32>,
    u: f32,
    normal: vec3<f32>,
    v: f32,
}

// One mesh instance: a draw call's per-instance data, indexed by instance_index.
struct Draw {
    model: mat4x4<f32>,
    // Inverse transpose of the model matrix, for normals.
    normal_matrix: mat4x4<f32>,
    material: u32,
    // Index of the area light this geometry shows, or NO_INDEX.
    light: u32,
    _pad0: u32,
    _pad1: u32,
}

struct Material {
    base_color: vec4<f32>,
    // Emitted radiance, W/(m^2 sr).
    emissive: vec3<f32>,
    roughness: f32,
    metallic: f32,
    // Scales the dielectric F0 of 0.04 (KHR_materials_specular); 0 makes a pure Lambertian.
    specular: f32,
    // Layers in the texture array, -1 for none.
    base_texture: i32,
    emissive_texture: i32,
    // Texels with alpha below this are cut out; 0 for opaque materials.
    alpha_cutoff: f32,
    double_sided: u32,
    _pad0: u32,
    _pad1: u32,
}

// One point-cloud sample (surfel) in world space: an oriented disc. 32 bytes; unpack with the
// helpers in shared/surfel.wgsl.
struct Point {
    position: vec3<f32>,
    // Disc radius in metres (0: not drawn).
    radius: f32,
    // Unit normal, octahedral-encoded as two snorm16 (unpack2x16snorm); POINT_NO_NORMAL when the
    // point has none and the disc faces the viewer.
    normal: u32,
    // Linear albedo and emitted radiance (W/(m^2 sr)) as f16 pairs (unpack2x16float):
    // (albedo.r, albedo.g), (albedo.b, emission.r), (emission.g, emission.b).
    albedo_rg: u32,
    albedo_b_emission_r: u32,
    emission_gb: u32,
}

const POINT_NO_NORMAL: u32 = 0x80008000u;

const LIGHT_DIRECTIONAL: u32 = 0u;
const LIGHT_POINT: u32 = 1u;
const LIGHT_SPOT: u32 = 2u;
const LIGHT_RECT: u32 = 3u;
const LIGHT_DISC: u32 = 4u;

fn is_area_light(light: Light) -> bool {
    return light.kind == LIGHT_RECT || light.kind == LIGHT_DISC;
}

// Area lights (the first ones, in light order) whose shadows `cone_shadows` traces as cones.
const CONE_SHADOW_LIGHTS: u32 = 4u;

struct Light {
    position: vec3<f32>,
    kind: u32,
    // Where photons travel; for area lights the emitting side's normal.
    direction: vec3<f32>,
    // Point/spot range of influence in metres, 0 for unlimited.
    range: f32,
    // W/m^2 (directional), W/sr (point, spot), W/(m^2 sr) (area).
    radiance: vec3<f32>,
    area: f32,
    // Rect: half-edge vectors. Disc: an orthonormal tangent frame scaled by the radius.
    axis_u: vec3<f32>,
    cos_inner: f32,
    axis_v: vec3<f32>,
    cos_outer: f32,
    // Index of the first shadow view and how many (0 = no shadows, 1, or 6 for a cube).
    shadow_first: u32,
    shadow_count: u32,
    // Radius of a disc with the light's area: sets the penumbra size.
    size: f32,
    // The first of the light's SAMPLE_POINTS cubes of sample views, or NO_INDEX.
    sample_first: u32,
}

const SHADOW_ORTHO: u32 = 0u;
const SHADOW_PERSPECTIVE: u32 = 1u;

// One rendered shadow map (a layer of the shadow atlas). It stores, per texel, the distance of
// the nearest occluder: along `dir` from `origin` for orthographic views, from `origin` for
// perspective ones.
struct ShadowView {
    view_proj: mat4x4<f32>,
    inv_view_proj: mat4x4<f32>,
    origin: vec3<f32>,
    kind: u32,
    dir: vec3<f32>,
    // World size of a texel (orthographic) or its size in tangent units at distance 1
    // (perspective).
    texel: f32,
    near: f32,
    far: f32,
    resolution: f32,
    layer: u32,
    // Geometry behind this plane (dot(plane.xyz, x) + plane.w < 0) casts no shadow: nothing
    // behind a one-sided emitter can block it. Zero for other lights.
    plane: vec4<f32>,
    // Where the view's texels start in its layer (sample views share layers).
    offset: vec2<f32>,
    _pad: vec2<f32>,
}
