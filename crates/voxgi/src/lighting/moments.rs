//! moments: prefilters the shadow maps for the VSM/ESM shadow filter (`ShadowFilter::VsmEsm`):
//! the moments of a 5x5-texel disc around each texel of every re-rendered part of a map, into
//! the atlas's moments texture (shaders/lighting/moments.wgsl).

use crate::gpu::layout;
use crate::gpu::shader::grouped_pipeline;
use crate::gpu::timer::GpuTimer;
use crate::lighting::atlas::{MOMENTS_FORMAT, ShadowAtlas, ViewDirt, behind_emitter};
use bytemuck::{Pod, Zeroable};

/// How far the prefilter's disc reaches from its centre, in texels (`MOMENT_RADIUS` in
/// shaders/shared/lights.wgsl).
pub const MOMENT_RADIUS: u32 = 2;
/// Dynamic uniform offsets must be multiples of this.
const STRIDE: u64 = 256;

/// `MomentRect` in moments.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub(crate) struct GpuMomentRect {
    pub(crate) min: [u32; 2],
    pub(crate) max: [u32; 2],
    pub(crate) layer: u32,
    pub(crate) far: f32,
    pub(crate) _pad: [u32; 2],
}

/// The moments compute pass: its pipeline and layout.
pub struct MomentsPass {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
}

impl MomentsPass {
    /// Compiles the pipeline.
    pub fn new(device: &wgpu::Device) -> Self {
        let c = wgpu::ShaderStages::COMPUTE;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("moments"),
            entries: &[
                layout::texture(
                    0,
                    c,
                    wgpu::TextureSampleType::Float { filterable: false },
                    wgpu::TextureViewDimension::D2Array,
                ),
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: c,
                    ty: wgpu::BindingType::StorageTexture {
                        access: wgpu::StorageTextureAccess::WriteOnly,
                        format: MOMENTS_FORMAT,
                        view_dimension: wgpu::TextureViewDimension::D2Array,
                    },
                    count: None,
                },
                layout::uniform(2, c, true),
            ],
        });
        let pipeline = grouped_pipeline(
            device,
            "moments",
            "lighting/moments.wgsl",
            &[Some(&layout)],
            &[],
        );
        MomentsPass { pipeline, layout }
    }

    /// The pass's bind group over `atlas`, with room for a rectangle per view (made once per
    /// atlas).
    pub fn bind(&self, device: &wgpu::Device, atlas: &ShadowAtlas) -> MomentsBind {
        let rects = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("moments rects"),
            size: atlas.views.len().max(1) as u64 * STRIDE,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("moments"),
            layout: &self.layout,
            entries: &layout::entries(vec![
                wgpu::BindingResource::TextureView(&atlas.array_view),
                wgpu::BindingResource::TextureView(&atlas.moments_view),
                wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &rects,
                    offset: 0,
                    size: wgpu::BufferSize::new(size_of::<GpuMomentRect>() as u64),
                }),
            ]),
        });
        MomentsBind { rects, bind }
    }

    /// Records the moments of every part of `atlas`'s maps that `views` marks re-rendered
    /// (grown by the disc's radius: texels there average changed ones). Timed as "moments".
    pub fn record(
        &self,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        atlas: &ShadowAtlas,
        views: &[ViewDirt],
        bound: &MomentsBind,
        timer: &mut GpuTimer,
    ) {
        let res = atlas.texture.width();
        let mut rects = Vec::new();
        // Sample views are read by single hard taps only.
        let regular = atlas.sample_views().start;
        for (i, view) in atlas.views.iter().enumerate().take(regular) {
            let dirt = views.get(i).copied().unwrap_or(ViewDirt::All);
            let Some((x, y, w, h)) = dirt.scissor(res) else {
                continue;
            };
            if behind_emitter(view) {
                continue;
            }
            let grow = |lo: u32| lo.saturating_sub(MOMENT_RADIUS);
            let rect = GpuMomentRect {
                min: [grow(x), grow(y)],
                max: [
                    (x + w + MOMENT_RADIUS).min(res),
                    (y + h + MOMENT_RADIUS).min(res),
                ],
                layer: view.layer,
                far: view.far,
                _pad: [0; 2],
            };
            rects.push(rect);
        }
        if rects.is_empty() {
            return;
        }
        let mut bytes = vec![0u8; rects.len() * STRIDE as usize];
        for (i, r) in rects.iter().enumerate() {
            let o = i * STRIDE as usize;
            bytes[o..o + size_of::<GpuMomentRect>()].copy_from_slice(bytemuck::bytes_of(r));
        }
        // Written before the submission runs, as the frame's other uniforms are.
        queue.write_buffer(&bound.rects, 0, &bytes);
        let bind = &bound.bind;
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("moments"),
            timestamp_writes: timer.compute("moments"),
        });
        pass.set_pipeline(&self.pipeline);
        for (i, r) in rects.iter().enumerate() {
            pass.set_bind_group(0, bind, &[(i as u64 * STRIDE) as u32]);
            pass.dispatch_workgroups(
                (r.max[0] - r.min[0]).div_ceil(8),
                (r.max[1] - r.min[1]).div_ceil(8),
                1,
            );
        }
    }
}

/// The moments pass's bind group for one atlas, and the rectangles it reads (`MomentsPass::bind`).
pub struct MomentsBind {
    rects: wgpu::Buffer,
    bind: wgpu::BindGroup,
}
