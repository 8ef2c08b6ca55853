// sample_voxels for the dense mip-mapped volume: premultiplied radiance and opacity of the
// volume filtered to `diameter` around `pos`, as seen travelling along `dir`. The including
// shader declares `vol`, `radiance0` (finest level, isotropic), `aniso_*` (six directional mip
// chains starting one level above the finest) and `voxel_sampler` (trilinear, clamp to zero).

fn sample_aniso(uvw: vec3<f32>, lod: f32, dir: vec3<f32>) -> vec4<f32> {
    // Three fetches, one per axis, weighted by the squared direction cosines (they sum to 1).
    let w = dir * dir;
    var x: vec4<f32>;
    var y: vec4<f32>;
    var z: vec4<f32>;
    if dir.x >= 0.0 {
        x = textureSampleLevel(aniso_px, voxel_sampler, uvw, lod);
    } else {
        x = textureSampleLevel(aniso_nx, voxel_sampler, uvw, lod);
    }
    if dir.y >= 0.0 {
        y = textureSampleLevel(aniso_py, voxel_sampler, uvw, lod);
    } else {
        y = textureSampleLevel(aniso_ny, voxel_sampler, uvw, lod);
    }
    if dir.z >= 0.0 {
        z = textureSampleLevel(aniso_pz, voxel_sampler, uvw, lod);
    } else {
        z = textureSampleLevel(aniso_nz, voxel_sampler, uvw, lod);
    }
    return w.x * x + w.y * y + w.z * z;
}

fn sample_voxels(pos: vec3<f32>, diameter: f32, dir: vec3<f32>) -> vec4<f32> {
    let extent = vol.voxel_size * f32(vol.resolution);
    let uvw = (pos - vol.origin) / extent;
    // Outside the volume there is nothing (no clamp-to-border sampler in core WebGPU).
    if any(uvw < vec3<f32>(0.0)) || any(uvw > vec3<f32>(1.0)) {
        return vec4<f32>(0.0);
    }
    let lod = clamp(log2(max(diameter / vol.voxel_size, 1.0)), 0.0, f32(vol.levels - 1u));
    if lod <= 0.0 {
        return textureSampleLevel(radiance0, voxel_sampler, uvw, 0.0);
    }
    // Levels above the finest live in the directional (or, in isotropic mode, the +X) chain,
    // whose level 0 is the volume's level 1.
    var coarse: vec4<f32>;
    if vol.anisotropic != 0u {
        coarse = sample_aniso(uvw, max(lod - 1.0, 0.0), dir);
    } else {
        coarse = textureSampleLevel(aniso_px, voxel_sampler, uvw, max(lod - 1.0, 0.0));
    }
    if lod < 1.0 {
        // Only between the finest level and the first coarse one is the finest level read.
        return mix(textureSampleLevel(radiance0, voxel_sampler, uvw, 0.0), coarse, lod);
    }
    return coarse;
}
