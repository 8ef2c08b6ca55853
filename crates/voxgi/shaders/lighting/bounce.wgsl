// bounce: one more bounce of light in voxel space. Each occupied voxel gathers irradiance with
// the diffuse cones from the filtered volume and re-emits albedo/pi of it on top of its direct
// light; `store` then writes the results into the finest level for re-filtering. For the
// fast shading (IRRADIANCE) it also keeps each leaf's irradiance and occlusion, which the
// gather then interpolates instead of tracing cones per pixel.

//!include shared/scene.wgsl
//!include shared/volume.wgsl
//!include shared/cone.wgsl
//!include voxels/leaves.wgsl
//!include shared/irradiance_record.wgsl
//!include voxels/carry.wgsl

// Which leaves gather this update (`bounce_slices`). With `count` > 1 and not `all`, `mark`
// lists those whose slice is `turn` (and those near moved geometry, and the new ones, unless
// their structure names a leaf whose kept light they start from: voxels/<kind>/carry.wgsl) and
// re-emits, at every other leaf, the irradiance it last gathered in this bounce of an update
// on top of its direct light of now; `list` sizes the gather's dispatch to the list, and
// `main` gathers at the listed leaves only.
// Listing them keeps a SIMD group's lanes on one kind of work: with the slices mixed in a
// group, nearly every group would pay for a whole gather.
struct Slices {
    count: u32,
    turn: u32,
    all: u32,
    // Leaf slots of the structure: where the list begins in `gathered`.
    capacity: u32,
    // Leaves inside this world box gather whatever their slice (`near_change` in
    // lighting/bounce.rs: where moved geometry spans half a cone's width or more); empty
    // (min above max) when nothing moved.
    near_min: vec4<f32>,
    near_max: vec4<f32>,
    // 1: a new leaf may start from the kept light `leaf_carry_source` names; 0: it gathers
    // (the pixels read its irradiance record, which only a gather writes).
    carry: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(0) @binding(0) var<uniform> cones: Cones;
// Per leaf slot (shared/irradiance_record.wgsl); written when IRRADIANCE.
@group(0) @binding(1) var<storage, read_write> leaf_irradiance: array<vec4<u32>>;
@group(0) @binding(2) var<uniform> slices: Slices;
// This bounce's (each bounce of an update binds its own range), used when `slices.count` > 1:
// per leaf slot, four words (the irradiance it last gathered, f32 rgb, and one unused); then
// the listed leaves' count and the list.
@group(0) @binding(3) var<storage, read_write> gathered: array<u32>;
// `mark` and `list` only: [0] the leaves listed so far, [1..4) the gather's dispatch size.
@group(0) @binding(4) var<storage, read_write> listing: array<atomic<u32>>;

fn kept(s: u32) -> vec3<f32> {
    return bitcast<vec3<f32>>(vec3<u32>(gathered[4u * s], gathered[4u * s + 1u], gathered[4u * s + 2u]));
}

fn keep(s: u32, e: vec3<f32>) {
    let w = bitcast<vec3<u32>>(e);
    gathered[4u * s] = w.x;
    gathered[4u * s + 1u] = w.y;
    gathered[4u * s + 2u] = w.z;
}

fn list_start() -> u32 {
    return 4u * slices.capacity;
}

// A leaf's slice: a hash of its voxel (not its slot, which atomics hand out in any order, so
// that renders are the same from run to run), spreading a turn's leaves through the scene.
fn slice_of(c: vec3<u32>) -> u32 {
    var h = (c.x * 73856093u) ^ (c.y * 19349663u) ^ (c.z * 83492791u);
    h = (h ^ (h >> 16u)) * 0x45d9f3bu;
    h = (h ^ (h >> 16u)) * 0x45d9f3bu;
    h = h ^ (h >> 16u);
    return h % slices.count;
}

// `leaf_next`'s opacity where `stash` parked a kept light (no leaf's opacity is negative).
const STASHED: f32 = -1.0;

// Before `mark`, after a build of part of the structure: a new leaf whose voxel a leaf held
// before the build (`leaf_kept_self`, voxels/<kind>/carry.wgsl: a clipmap window that moved
// and overlaps its old place) reads that leaf's kept light, before `mark` lets the new leaves
// write theirs over the slots (the old leaves' slots are new leaves' now). It parks it in its
// own `leaf_next`, which `mark` or the gather writes after.
@compute @workgroup_size(64)
fn stash(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let s = leaf_slot(dispatch_index(gid, nwg));
    if s == NO_LEAF || !leaf_is_new(s) {
        return;
    }
    let t = leaf_kept_self(s);
    if t != NO_LEAF {
        leaf_next[s] = vec4<f32>(kept(t), STASHED);
    }
}

@compute @workgroup_size(64)
fn mark(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let s = leaf_slot(dispatch_index(gid, nwg));
    if s == NO_LEAF {
        return;
    }
    let p = leaf_center(s);
    let near = all(p >= slices.near_min.xyz) && all(p <= slices.near_max.xyz);
    var gather = near || slice_of(leaf_coord(s)) == slices.turn;
    // A new leaf has nothing kept: it gathers now, or starts from the light `stash` read of
    // the leaf that held its voxel before, or from the light of the leaf its structure names
    // (reading only leaves that are not new, whose kept light no thread writes here).
    if leaf_is_new(s) && !gather {
        let stashed = leaf_next[s];
        let source = select(NO_LEAF, leaf_carry_source(s), slices.carry != 0u);
        if slices.carry != 0u && stashed.w == STASHED {
            keep(s, stashed.xyz);
        } else if source == NO_LEAF {
            gather = true;
        } else {
            keep(s, kept(source));
        }
    }
    if gather {
        let k = atomicAdd(&listing[0], 1u);
        gathered[list_start() + 1u + k] = s;
    } else {
        leaf_next[s] = re_emit(leaf_direct[direct_index(s)], leaf_albedo(s), kept(s));
    }
}

@compute @workgroup_size(1)
fn list() {
    let n = atomicLoad(&listing[0]);
    gathered[list_start()] = n;
    let groups = (n + 63u) / 64u;
    atomicStore(&listing[1], max(min(groups, 65535u), 1u));
    atomicStore(&listing[2], max((groups + 65534u) / 65535u, 1u));
    atomicStore(&listing[3], 1u);
    // Ready for the next bounce's `mark`.
    atomicStore(&listing[0], 0u);
}

override IRRADIANCE: bool = false;
// Group 1: the voxel structure's sampling, group 2: its leaves.

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    var s = dispatch_index(gid, nwg);
    if slices.count > 1u && slices.all == 0u {
        if s >= gathered[list_start()] {
            return;
        }
        s = gathered[list_start() + 1u + s];
    } else {
        s = leaf_slot(s);
        if s == NO_LEAF {
            return;
        }
    }
    let c = leaf_coord(s);
    let albedo = leaf_albedo(s);
    let nw = leaf_normal(s);
    let center = leaf_center(s);
    var e = vec3<f32>(0.0);
    var ao = 1.0;
    // Records turn their bundles by the layout the pixels' window filter averages
    // (shared/irradiance_record.wgsl).
    let records_turn = leaf_turn(c);
    // Otherwise a fixed turn per voxel, varied between voxels to break up patterns. It
    // follows the voxel's coordinates, not its slot: slots are handed out by atomics in
    // whatever order the GPU runs, and renders must not change from run to run. (Roberts' R3
    // step for the first coordinate, so neighbouring voxels get well spread turns; the second
    // takes the plastic number's powers and sqrt(2) - 1, which no plane of voxels makes a
    // multiple of the first: R3's own powers would tie the two on every plane z = const.)
    let r3 = fract(vec2<f32>(
        dot(vec3<f32>(c), vec3<f32>(0.8191725134, 0.6710436067, 0.5497004779)),
        dot(vec3<f32>(c), vec3<f32>(0.5698402910, 0.7548776662, 0.4142135624)),
    ));
    let turn = select(r3, records_turn, IRRADIANCE);
    // The cones' quarters (shared/cone.wgsl, cone_quarter) by the records' layout too: the
    // voxels of any 4x4 window trace each cone through each quarter equally often.
    let rank = leaf_rank(c);
    // Cones start at the voxels they read there: at a clipmap window's open face the next
    // coarser level's, whose thicker voxels a cone clearing only the leaf's own would read its
    // own surface in (elsewhere, and in the other structures, the leaf's own).
    let vs = max(leaf_size(s), voxels_voxel_size_at(center));
    if nw.w > 0.3 {
        let n = normalize(nw.xyz);
        let g = gather_diffuse(center, n, turn, IRRADIANCE, ALL_CONES, vs, rank, 0u);
        e = g.irradiance;
        ao = g.ao;
    } else {
        // Two-sided voxel: half the light from each side, each side's cones a quarter on.
        let n = vec3<f32>(0.0, 1.0, 0.0);
        let up = gather_diffuse(center, n, turn, IRRADIANCE, ALL_CONES, vs, rank, 0u);
        let down = gather_diffuse(center, -n, turn, IRRADIANCE, ALL_CONES, vs, rank, 1u);
        e = 0.5 * (up.irradiance + down.irradiance);
        ao = 0.5 * (up.ao + down.ao);
    }
    if IRRADIANCE {
        leaf_irradiance[s] = pack_irradiance(e, ao, nw);
    }
    if slices.count > 1u {
        keep(s, e);
    }
    leaf_next[s] = re_emit(leaf_direct[direct_index(s)], albedo, e);
}

// A leaf's light after a bounce: its direct light and albedo/pi of irradiance `e`, premultiplied
// by opacity. One function for gathered and kept irradiance, so both round alike.
fn re_emit(direct: vec4<f32>, albedo: vec4<f32>, e: vec3<f32>) -> vec4<f32> {
    return vec4<f32>(direct.rgb + albedo.rgb / PI * e * direct.a, direct.a);
}
