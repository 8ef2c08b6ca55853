// The frame's globals: @group(0) of the screen passes (gather, upsample, composite, tonemap),
// one bind group per frame. Twin: src/globals.rs.

//!include shared/scene.wgsl
//!include shared/volume.wgsl

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var<uniform> cones: Cones;
@group(0) @binding(2) var<storage, read> lights: array<Light>;
@group(0) @binding(3) var<storage, read> shadow_views: array<ShadowView>;
@group(0) @binding(4) var shadow_maps: texture_2d_array<f32>;
// The maps' prefiltered moments (lighting/moments.wgsl), with the VSM/ESM shadow filter.
@group(0) @binding(5) var shadow_moments: texture_2d_array<f32>;
// The specular lobe's directional albedo: (a, b) over (n.v, roughness).
@group(0) @binding(6) var specular_table: texture_2d<f32>;
// The LTC fit's inverse matrices, f32 (interpolated by hand: f32 need not be filterable).
@group(0) @binding(7) var ltc_table: texture_2d<f32>;
// Bilinear, clamp to edge: the BRDF tables' own sampler.
@group(0) @binding(8) var table_sampler: sampler;
