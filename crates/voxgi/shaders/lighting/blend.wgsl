// blend: moves every leaf's shown radiance (what the structure holds for the cones) a step
// towards the light the last voxel update computed for it, so that bounced light changes over
// a few frames instead of at once. Runs after the update, before the filter.

//!include shared/volume.wgsl
//!include voxels/leaf_store.wgsl

struct Blend {
    // The share of the remaining way this step goes: 1 / (steps left, this one included).
    weight: f32,
    // 1: every leaf starts at its new light (a rebuild: slots hold other leaves now).
    restart: u32,
    // 1: the update's light is the last bounce's (`leaf_next`); 0: the direct light.
    from_bounce: u32,
    // 1: every leaf is stored; 0: only those whose shown light moves (nothing else wrote the
    // structure since the last step, so it holds the rest already, and the filter after
    // redoes only around what moved).
    store_all: u32,
}

@group(0) @binding(0) var<uniform> blend: Blend;
// Per leaf slot: the radiance the structure shows (premultiplied rgb, opacity).
@group(0) @binding(1) var<storage, read_write> shown: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let s = leaf_slot(dispatch_index(gid, nwg));
    if s == NO_LEAF {
        return;
    }
    var goal = leaf_direct[direct_index(s)];
    if blend.from_bounce != 0u {
        goal = leaf_next[s];
    }
    // A leaf the last update made (a moved instance's) has no light of its own to come from.
    var now = goal;
    if blend.restart == 0u && !leaf_is_new(s) {
        // The last step lands on the update's light to the bit: mix(a, b, 1) need not be b
        // (a + 1 * (b - a) with a fused multiply-add on NVIDIA rounds in b - a).
        now = select(mix(shown[s], goal, blend.weight), goal, blend.weight >= 1.0);
    }
    let was = shown[s];
    shown[s] = now;
    if blend.store_all != 0u || blend.restart != 0u || any(now != was) {
        store_leaf_radiance(s, now);
    }
}
