//! debug: the voxel views (`ViewMode::VoxelAlbedo`, `VoxelOpacity`, `VoxelRadiance`). Ray-marches
//! the volume at `FrameParams::debug_level` and overwrites the HDR target; runs after composite and
//! before tonemap, only when such a view is selected.

use super::DenseVolume;
use crate::frame::formats::HDR_FORMAT;
use crate::frame::targets::FrameTargets;
use crate::gpu::layout;
use crate::gpu::shader::voxel_pipeline;
use crate::gpu::timer::GpuTimer;
use crate::voxel::VoxelView;
use wgpu::util::DeviceExt;

/// The voxel debug compute pass (shaders/voxels/dense/debug.wgsl): its pipeline and bind group
/// layout.
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
                layout::texture_3d_load(3, c),
                layout::texture_3d_load(4, c),
                layout::texture_3d_load(5, c),
                layout::storage_texture(6, HDR_FORMAT),
            ],
        });
        DebugPass {
            pipeline: voxel_pipeline(
                device,
                "debug",
                "voxels/dense/debug.wgsl",
                &super::KIND.shaders,
                &[Some(&layout)],
                &[],
            ),
            layout,
        }
    }

    /// Records the view `view` (a voxel view) of mip `level` (0 = finest) of `vol`'s window
    /// `window` (0 for the dense volume), placed by `placement` (a `Volume` uniform), reading
    /// directional chain `direction` (0..6: +X, -X, +Y, -Y, +Z, -Z) above the finest level.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        t: &FrameTargets,
        vol: &DenseVolume,
        (placement, window): (&wgpu::Buffer, u32),
        view: VoxelView,
        level: u32,
        direction: u32,
        timer: &mut GpuTimer,
    ) {
        let mode = view.id();
        let level = level.min(vol.grid.levels() - 1);
        // In isotropic mode the one block serves every direction; the lobe blocks are none.
        let block = direction.min(vol.chain_blocks().min(6) - 1);
        let params = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("debug params"),
            contents: bytemuck::cast_slice(&[mode, level, block, window]),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let chain = vol.chains.create_view(&Default::default());
        let albedo = vol.albedo.create_view(&Default::default());
        let radiance = vol.radiance.create_view(&Default::default());
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("debug"),
            layout: &self.layout,
            entries: &layout::entries(vec![
                t.frame.as_entire_binding(),
                placement.as_entire_binding(),
                params.as_entire_binding(),
                wgpu::BindingResource::TextureView(&albedo),
                wgpu::BindingResource::TextureView(&radiance),
                wgpu::BindingResource::TextureView(&chain),
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
