// Interleaved sampling (Keller and Heidrich) over 4x4 pixel blocks, shared by the gather and
// its reconstruction (upsample).

// The 4x4 Bayer rank of a pixel, 0..15: the 2x2 Bayer matrix [[0, 2], [3, 1]] of the pixel's
// low bits, refined by that of its next bits. Arithmetic rather than a table: an indexed
// constant array is copied into memory on every call by CPU drivers.
fn bayer2(x: u32, y: u32) -> u32 {
    return ((x ^ y) << 1u) | y;
}

fn bayer4(p: vec2<u32>) -> u32 {
    return 4u * bayer2(p.x & 1u, p.y & 1u) + bayer2((p.x >> 1u) & 1u, (p.y >> 1u) & 1u);
}

// The position in the 4x4 block whose Bayer rank is k (0..15): bayer4's inverse.
fn bayer4_position(k: u32) -> vec2<u32> {
    let hi = vec2<u32>(((k >> 3u) ^ (k >> 2u)) & 1u, (k >> 2u) & 1u);
    let lo = vec2<u32>(((k >> 1u) ^ k) & 1u, k & 1u);
    return hi + 2u * lo;
}

// A pixel's rank in frame `sample` of the temporal sequence: the 4x4 pattern moves each frame
// by the position of the frame's own rank, so over sixteen frames every pixel takes every
// rank (alternating parities). Each rank draws its cones from one stratum of their cells,
// one half of the ring and fixed quarters: with the pattern held still a pixel converged to
// its rank's share of the cones, and only the upsample's window made up the rest from its
// neighbours, which see other light where it changes across the window. Frame 0, and every
// frame without temporal accumulation, keeps the pattern in place.
fn pixel_rank(p: vec2<u32>, sample: u32) -> u32 {
    return bayer4(p + bayer4_position(sample & 15u));
}

// Which half of the cone ring a pixel's gather traced in frame `sample`: the parity of its
// rank.
fn cone_half(p: vec2<u32>, sample: u32) -> u32 {
    return pixel_rank(p, sample) & 1u;
}
