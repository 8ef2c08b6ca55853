//! debug: the octree's voxel views (`ViewMode::VoxelAlbedo`, `VoxelOpacity`, `VoxelRadiance`,
//! `VoxelNodes`). Ray-marches one level and overwrites the HDR target, like the dense
//! volume's debug pass.

use super::OctreeVolume;
use crate::frame::formats::HDR_FORMAT;
use crate::frame::targets::FrameTargets;
use crate::gpu::layout;
use crate::gpu::shader::voxel_pipeline;
use crate::gpu::timer::GpuTimer;
use crate::voxel::DebugView;
use wgpu::util::DeviceExt;

/// The octree's debug compute pass (shaders/voxels/octree/debug.wgsl).
pub struct DebugPass {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
}

impl DebugPass {
    /// Compiles the pipeline and creates its bind group layout.
    pub fn new(device: &wgpu::Device) -> Self {
        let c = wgpu::ShaderStages::COMPUTE;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("debug"),
            entries: &[
                layout::uniform(0, c, false),
                layout::uniform(1, c, false),
                layout::uniform(2, c, false),
                layout::storage(3, c, true),
                layout::storage(4, c, true),
                layout::texture_3d_load(5, c),
                layout::texture_3d_load(6, c),
                layout::storage_texture(7, HDR_FORMAT),
            ],
        });
        DebugPass {
            pipeline: voxel_pipeline(
                device,
                "debug",
                "voxels/octree/debug.wgsl",
                &super::KIND.shaders,
                &[Some(&layout)],
                &[],
            ),
            layout,
        }
    }

    /// Records `view` of the octree into the HDR target.
    pub fn record(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        t: &FrameTargets,
        tree: &OctreeVolume,
        view: DebugView,
        timer: &mut GpuTimer,
    ) {
        let mode = view.mode.id();
        let block = if tree.anisotropic {
            view.direction.min(5)
        } else {
            0
        };
        let params = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("debug params"),
            contents: bytemuck::cast_slice(&[mode, view.level, block, 0u32]),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let v = |x: &wgpu::Texture| x.create_view(&Default::default());
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("debug"),
            layout: &self.layout,
            entries: &layout::entries(vec![
                t.frame.as_entire_binding(),
                tree.tree.as_entire_binding(),
                params.as_entire_binding(),
                tree.nodes.as_entire_binding(),
                tree.slots.as_entire_binding(),
                wgpu::BindingResource::TextureView(&v(&tree.even_atlas)),
                wgpu::BindingResource::TextureView(&v(&tree.odd_atlas)),
                wgpu::BindingResource::TextureView(&t.hdr),
            ]),
        });
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("debug"),
            timestamp_writes: timer.compute("debug"),
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &bind, &[]);
        pass.dispatch_workgroups(t.width.div_ceil(8), t.height.div_ceil(8), 1);
    }
}
