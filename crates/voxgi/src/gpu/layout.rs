//! Short constructors for bind group layout entries, so each pass's layout reads as a list.

use wgpu::{BindGroupLayoutEntry as Entry, BindingType, ShaderStages};

/// A uniform buffer at `binding`, with a dynamic offset if `dynamic`.
pub fn uniform(binding: u32, visibility: ShaderStages, dynamic: bool) -> Entry {
    Entry {
        binding,
        visibility,
        ty: BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: dynamic,
            min_binding_size: None,
        },
        count: None,
    }
}

/// A storage buffer at `binding`, read-only or read-write.
pub fn storage(binding: u32, visibility: ShaderStages, read_only: bool) -> Entry {
    Entry {
        binding,
        visibility,
        ty: BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// A single-sampled texture at `binding` of the given sample type and view dimension.
pub fn texture(
    binding: u32,
    visibility: ShaderStages,
    sample_type: wgpu::TextureSampleType,
    view_dimension: wgpu::TextureViewDimension,
) -> Entry {
    Entry {
        binding,
        visibility,
        ty: BindingType::Texture {
            sample_type,
            view_dimension,
            multisampled: false,
        },
        count: None,
    }
}

/// A 2D float texture read with textureLoad only (no filtering needed).
pub fn texture_2d_load(binding: u32, visibility: ShaderStages) -> Entry {
    texture(
        binding,
        visibility,
        wgpu::TextureSampleType::Float { filterable: false },
        wgpu::TextureViewDimension::D2,
    )
}

/// A write-only 2D storage texture of `format` at `binding`, for compute shaders.
pub fn storage_texture(binding: u32, format: wgpu::TextureFormat) -> Entry {
    Entry {
        binding,
        visibility: ShaderStages::COMPUTE,
        ty: BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::WriteOnly,
            format,
            view_dimension: wgpu::TextureViewDimension::D2,
        },
        count: None,
    }
}

/// A filtering sampler at `binding`.
pub fn sampler(binding: u32, visibility: ShaderStages) -> Entry {
    Entry {
        binding,
        visibility,
        ty: BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
        count: None,
    }
}

/// Bind group entries from (binding, resource) pairs.
pub fn entries<'a>(resources: Vec<wgpu::BindingResource<'a>>) -> Vec<wgpu::BindGroupEntry<'a>> {
    resources
        .into_iter()
        .enumerate()
        .map(|(i, resource)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource,
        })
        .collect()
}

/// A write-only 3D storage texture of `format` at `binding`, for compute shaders.
pub fn storage_texture_3d(binding: u32, format: wgpu::TextureFormat) -> Entry {
    Entry {
        binding,
        visibility: ShaderStages::COMPUTE,
        ty: BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::WriteOnly,
            format,
            view_dimension: wgpu::TextureViewDimension::D3,
        },
        count: None,
    }
}

/// A 3D float texture read with textureLoad only.
pub fn texture_3d_load(binding: u32, visibility: ShaderStages) -> Entry {
    texture(
        binding,
        visibility,
        wgpu::TextureSampleType::Float { filterable: false },
        wgpu::TextureViewDimension::D3,
    )
}

/// Workgroup counts for `n` threads of `group` lanes in a 2D grid (65535 per dimension).
pub fn groups_2d(n: u32, group: u32) -> (u32, u32) {
    let g = n.div_ceil(group).max(1);
    let x = g.min(65535);
    (x, g.div_ceil(x))
}
