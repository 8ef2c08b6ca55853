// The light model shared by the rasterizer, the cone tracer and the reference path tracer:
// how much light a punctual or directional light delivers to a point. Area lights are uniform
// one-sided emitters of `radiance` over their rect or disc (see scene.wgsl).

//!include shared/scene.wgsl

// glTF KHR_lights_punctual range window: smooth fall to zero at `range`.
fn range_window(dist: f32, range: f32) -> f32 {
    if range <= 0.0 {
        return 1.0;
    }
    let r = dist / range;
    let w = clamp(1.0 - r * r * r * r, 0.0, 1.0);
    return w * w;
}

// Spot cone: 1 inside the inner angle, 0 outside the outer, and in between the square of the
// linear ramp in cosine (the KHR_lights_punctual reference implementation).
fn spot_falloff(cos_angle: f32, cos_inner: f32, cos_outer: f32) -> f32 {
    let t = clamp((cos_angle - cos_outer) / max(cos_inner - cos_outer, 1e-4), 0.0, 1.0);
    return t * t;
}

// What a directional, point or spot light delivers at p: the unit direction towards the light,
// the distance to it (a huge value for directional lights) and the irradiance on a surface
// facing the light, W/m^2.
struct PunctualSample {
    l: vec3<f32>,
    dist: f32,
    e: vec3<f32>,
}

const FAR_AWAY: f32 = 3.0e38;

fn punctual_light(light: Light, p: vec3<f32>) -> PunctualSample {
    if light.kind == LIGHT_DIRECTIONAL {
        return PunctualSample(-light.direction, FAR_AWAY, light.radiance);
    }
    let to = light.position - p;
    let d2 = max(dot(to, to), 1e-8);
    let d = sqrt(d2);
    let l = to / d;
    var e = light.radiance / d2 * range_window(d, light.range);
    if light.kind == LIGHT_SPOT {
        e *= spot_falloff(dot(-l, light.direction), light.cos_inner, light.cos_outer);
    }
    return PunctualSample(l, d, e);
}
