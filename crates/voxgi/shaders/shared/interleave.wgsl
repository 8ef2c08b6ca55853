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

// Which half of the cone ring a pixel's gather traced: the parity of its Bayer rank.
fn cone_half(p: vec2<u32>) -> u32 {
    return bayer4(p) & 1u;
}
