// temporal: each pixel's radiance accumulated over frames. The history is reprojected by the
// G-buffer's motion vectors, kept only where the same surface was seen last frame (distance
// and normal), and clipped to this frame's neighbourhood while anything moves; in a still
// frame it is averaged with this frame as it is, so a still converges to the mean of its
// jittered, cone-turned frames. Writes the new history, which tonemap reads.

//!include shared/globals.wgsl

// Group 2, the pass's own:
@group(2) @binding(0) var current: texture_2d<f32>;
// xy: screen motion since the last frame (pixels), z: distance from the last frame's camera,
// w: 1 on geometry, 0 on background.
@group(2) @binding(1) var motion: texture_2d<f32>;
@group(2) @binding(2) var gb_normal: texture_2d<f32>;
@group(2) @binding(3) var gb_depth: texture_depth_2d;
// rgb: accumulated radiance, a: frames it holds.
@group(2) @binding(4) var history_in: texture_2d<f32>;
// rgb: normal, a: camera distance (0: background) of the pixels history_in holds.
@group(2) @binding(5) var geometry_in: texture_2d<f32>;
@group(2) @binding(6) var history_out: texture_storage_2d<rgba32float, write>;
@group(2) @binding(7) var geometry_out: texture_storage_2d<rgba16float, write>;

// While anything moves the history weighs at most 1 - 1/MOVING_FRAMES: enough frames to
// smooth the jitter and the turned cones, few enough that clipped history follows changes.
const MOVING_FRAMES: f32 = 12.0;
// A still keeps averaging: the mean of this many frames is as good as a mean gets.
const STILL_FRAMES: f32 = 4096.0;
// The disocclusion test: the surface's distance from the last camera may differ from the
// history's by this fraction (half floats, and a jittered sample lands elsewhere on a slanted
// surface), and the normals by at most this angle's cosine.
const SAME_DISTANCE: f32 = 0.03;
const SAME_NORMAL: f32 = 0.8;

fn world_position(px: vec2<u32>, depth: f32) -> vec3<f32> {
    let uv = (vec2<f32>(px) + 0.5) * frame.inv_size;
    let ndc = vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, depth, 1.0);
    let w = frame.inv_view_proj * ndc;
    return w.xyz / w.w;
}

// The screen motion of the background at px: a direction, which only the camera's turn moves.
fn background_motion(px: vec2<u32>) -> vec2<f32> {
    let dir = world_position(px, 1.0) - frame.camera_pos;
    let now = frame.view_proj_unjittered * vec4<f32>(dir, 0.0);
    let then = frame.prev_view_proj * vec4<f32>(dir, 0.0);
    let ndc = now.xy / now.w - then.xy / then.w;
    return ndc * vec2<f32>(0.5, -0.5) * frame.size;
}

fn ycocg(c: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(
        0.25 * c.r + 0.5 * c.g + 0.25 * c.b,
        0.5 * c.r - 0.5 * c.b,
        -0.25 * c.r + 0.5 * c.g - 0.25 * c.b,
    );
}

fn rgb(c: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(c.x + c.y - c.z, c.x + c.z, c.x - c.y - c.z);
}

fn load_clamped(t: texture_2d<f32>, p: vec2<i32>) -> vec4<f32> {
    let size = vec2<i32>(textureDimensions(t));
    return textureLoad(t, clamp(p, vec2<i32>(0), size - 1), 0);
}

// Catmull-Rom resampling of the history at continuous pixel position `pos` (16 taps): sharper
// than bilinear, whose blur would build up frame after frame while the camera moves.
fn history_at(pos: vec2<f32>) -> vec3<f32> {
    let x = pos - 0.5;
    let i = vec2<i32>(floor(x));
    let f = x - floor(x);
    // Catmull-Rom weights of the taps at -1, 0, 1, 2.
    let w0 = f * (-0.5 + f * (1.0 - 0.5 * f));
    let w1 = 1.0 + f * f * (-2.5 + 1.5 * f);
    let w2 = f * (0.5 + f * (2.0 - 1.5 * f));
    let w3 = f * f * (-0.5 + 0.5 * f);
    var sum = vec3<f32>(0.0);
    for (var y = 0; y < 4; y++) {
        let wy = select(select(select(w3.y, w2.y, y == 2), w1.y, y == 1), w0.y, y == 0);
        for (var xx = 0; xx < 4; xx++) {
            let wx = select(select(select(w3.x, w2.x, xx == 2), w1.x, xx == 1), w0.x, xx == 0);
            sum += wx * wy * load_clamped(history_in, i + vec2<i32>(xx - 1, y - 1)).rgb;
        }
    }
    return max(sum, vec3<f32>(0.0));
}

// Whether a pixel of the history, with geometry g, saw the surface this pixel sees: one at the
// distance `expected` from the last camera (0: the background) with normal n.
fn same_surface(g: vec4<f32>, n: vec3<f32>, expected: f32) -> bool {
    if expected <= 0.0 || g.a <= 0.0 {
        return expected <= 0.0 && g.a <= 0.0;
    }
    return abs(g.a - expected) <= SAME_DISTANCE * expected && dot(g.rgb, n) >= SAME_NORMAL;
}

// The screen motion this frame's pixel p shows (background: the camera's turn).
fn motion_at(p: vec2<i32>) -> vec2<f32> {
    let size = vec2<i32>(frame.size);
    let c = clamp(p, vec2<i32>(0), size - 1);
    let m = textureLoad(motion, c, 0);
    if m.w > 0.0 {
        return m.xy;
    }
    return background_motion(vec2<u32>(c));
}

// Whether this frame's 3x3 neighbourhood moves in more than one way: a moving silhouette,
// where the history on the two sides belongs to different surfaces.
fn at_moving_edge(px: vec2<u32>, moved: vec2<f32>) -> bool {
    var edge = false;
    for (var y = -1; y <= 1; y++) {
        for (var x = -1; x <= 1; x++) {
            let d = motion_at(vec2<i32>(px) + vec2<i32>(x, y)) - moved;
            edge = edge || dot(d, d) > 0.25;
        }
    }
    return edge;
}

// The history at pos from only the texels within `radius` that saw this pixel's surface, with
// tent weights: at a moving silhouette the others hold the surface that moved away.
fn history_of_surface(pos: vec2<f32>, n: vec3<f32>, expected: f32, radius: f32) -> vec4<f32> {
    let q = vec2<i32>(floor(pos));
    let reach = i32(ceil(radius));
    var sum = vec4<f32>(0.0);
    for (var y = -reach; y <= reach; y++) {
        for (var x = -reach; x <= reach; x++) {
            let t = q + vec2<i32>(x, y);
            let d = abs(vec2<f32>(t) + 0.5 - pos) / radius;
            let w = max(1.0 - d.x, 0.0) * max(1.0 - d.y, 0.0);
            if w > 0.0 && same_surface(load_clamped(geometry_in, t), n, expected) {
                sum += w * vec4<f32>(load_clamped(history_in, t).rgb, 1.0);
            }
        }
    }
    return sum;
}

// The history clipped towards the box of this frame's 3x3 neighbourhood (mean +- one standard
// deviation, in YCoCg): colours the neighbourhood cannot make are history that no longer holds.
fn clip_to_neighbourhood(px: vec2<u32>, history: vec3<f32>) -> vec3<f32> {
    var m1 = vec3<f32>(0.0);
    var m2 = vec3<f32>(0.0);
    for (var y = -1; y <= 1; y++) {
        for (var x = -1; x <= 1; x++) {
            let c = ycocg(load_clamped(current, vec2<i32>(px) + vec2<i32>(x, y)).rgb);
            m1 += c;
            m2 += c * c;
        }
    }
    let mean = m1 / 9.0;
    let sigma = sqrt(max(m2 / 9.0 - mean * mean, vec3<f32>(0.0)));
    let h = ycocg(history);
    let d = h - mean;
    // How far outside the box the history lies along its offset from the mean.
    let extent = max(sigma, vec3<f32>(1e-6));
    let outside = max(abs(d.x) / extent.x, max(abs(d.y) / extent.y, abs(d.z) / extent.z));
    if outside <= 1.0 {
        return history;
    }
    return rgb(mean + d / outside);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<u32>(frame.size);
    if any(id.xy >= size) {
        return;
    }
    let px = id.xy;
    let now = textureLoad(current, px, 0).rgb;
    let depth = textureLoad(gb_depth, px, 0);
    let m = textureLoad(motion, px, 0);
    var n = vec3<f32>(0.0);
    var dist = 0.0;
    var moved = m.xy;
    var expected = m.z;
    if depth >= 1.0 {
        moved = background_motion(px);
        expected = 0.0;
    } else {
        n = normalize(textureLoad(gb_normal, px, 0).xyz);
        dist = length(frame.camera_pos - world_position(px, depth));
    }
    textureStore(geometry_out, px, vec4<f32>(n, dist));

    // The history's radiance and frame count at this pixel's surface; none where it was not seen.
    var history = vec4<f32>(0.0);
    if frame.history == HISTORY_STILL {
        // Nothing moved: the same pixel, the same surface (its jittered samples wander over
        // the pixel, the geometry test would throw away its edges).
        history = textureLoad(history_in, px, 0);
    } else if frame.history == HISTORY_MOVING {
        let pos = vec2<f32>(px) + 0.5 - moved;
        if all(pos >= vec2<f32>(0.0)) && all(pos < frame.size) {
            // Any of the 3x3 history pixels around may have seen it: at a silhouette the
            // nearest one often sampled the other side.
            let q = vec2<i32>(floor(pos));
            var seen = false;
            for (var y = -1; y <= 1; y++) {
                for (var x = -1; x <= 1; x++) {
                    seen = seen || same_surface(load_clamped(geometry_in, q + vec2<i32>(x, y)), n, expected);
                }
            }
            if seen {
                var h = history_at(pos);
                if at_moving_edge(px, moved) {
                    var s = history_of_surface(pos, n, expected, 1.0);
                    if s.w <= 0.0 {
                        s = history_of_surface(pos, n, expected, 2.0);
                    }
                    h = s.rgb / max(s.w, 1e-6);
                }
                history = vec4<f32>(h, load_clamped(history_in, q).a);
                history = vec4<f32>(clip_to_neighbourhood(px, history.rgb), history.a);
            }
        }
    }
    let cap = select(MOVING_FRAMES, STILL_FRAMES, frame.history == HISTORY_STILL);
    // A history's first frame counts as one: the still a single frame shows (PCSS for area
    // shadows rather than a sample of the light). Dropping it instead made the next frame a
    // single frame's four light samples, visibly noisy, and left the converged stills as they
    // were (within 0.001 of HDR-FLIP after 16 frames).
    let count = select(min(history.a + 1.0, cap), 1.0, frame.history == HISTORY_NONE);
    // Without history the frame itself, exactly.
    var out = now;
    if count > 1.0 {
        var w = 1.0 / count;
        if frame.history == HISTORY_MOVING {
            // While things move, a sample far from the pixel's centre counts less (a Gaussian
            // fit of the Blackman-Harris window): an edge's pixel then swings less with the
            // jitter (docs/QUALITY.md, in motion). A still's mean stays the plain average
            // over the pixel.
            w *= exp(-2.29 * dot(frame.jitter, frame.jitter));
        }
        out = history.rgb + (now - history.rgb) * w;
    }
    textureStore(history_out, px, vec4<f32>(out, count));
}
