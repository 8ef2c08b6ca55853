//! The frame's globals, bound at `@group(0)` by the screen passes (gather, upsample,
//! composite, tonemap): the frame uniform, the cone parameters, the lights and the shadow
//! atlas, the BRDF tables and their sampler. One bind group, made again only when one of
//! those resources is replaced (new targets, a new atlas); each pass binds it and
//! adds its own resources at group 2. Twin: shaders/shared/globals.wgsl.

use crate::brdf::BrdfTables;
use crate::gpu::layout;

/// The layout of the frame's globals.
pub fn layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let v = wgpu::ShaderStages::COMPUTE | wgpu::ShaderStages::FRAGMENT;
    let texture = |binding, filterable, dimension| {
        layout::texture(
            binding,
            v,
            wgpu::TextureSampleType::Float { filterable },
            dimension,
        )
    };
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("globals"),
        entries: &[
            layout::uniform(0, v, false),
            layout::uniform(1, v, false),
            layout::storage(2, v, true),
            layout::storage(3, v, true),
            texture(4, false, wgpu::TextureViewDimension::D2Array),
            texture(5, false, wgpu::TextureViewDimension::D2Array),
            texture(6, true, wgpu::TextureViewDimension::D2),
            texture(7, false, wgpu::TextureViewDimension::D2),
            layout::sampler(8, v),
        ],
    })
}

/// What the frame's globals are made of. Resources, not their owners: the frame sits below
/// the scene and the lighting.
pub struct GlobalsSources<'a> {
    /// The `GpuFrame` uniform (`FrameTargets::frame`).
    pub frame: &'a wgpu::Buffer,
    /// `GpuCones`.
    pub cones: &'a wgpu::Buffer,
    /// The lights, the shadow views, the shadow maps and their moments
    /// (`ShadowAtlas::lighting_resources`).
    pub lighting: [wgpu::BindingResource<'a>; 4],
    /// The BRDF tables and their sampler.
    pub tables: &'a BrdfTables,
}

/// The frame's globals for `layout`.
pub fn bind_group(
    device: &wgpu::Device,
    bgl: &wgpu::BindGroupLayout,
    s: &GlobalsSources,
) -> wgpu::BindGroup {
    let mut entries = vec![s.frame.as_entire_binding(), s.cones.as_entire_binding()];
    entries.extend(s.lighting.iter().cloned());
    entries.extend([
        wgpu::BindingResource::TextureView(&s.tables.specular_albedo),
        wgpu::BindingResource::TextureView(&s.tables.ltc),
        wgpu::BindingResource::Sampler(&s.tables.sampler),
    ]);
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("globals"),
        layout: bgl,
        entries: &layout::entries(entries),
    })
}
