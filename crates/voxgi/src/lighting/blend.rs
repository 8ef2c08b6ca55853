//! blend: the voxels' light follows a change over `VOXEL_BLEND_FRAMES` frames instead of at
//! once (with temporal accumulation). Each leaf keeps the radiance it shows; after every voxel
//! update, and on the frames after it, a step moves what it shows a share of the remaining way
//! towards the light the update computed, landing on it exactly at the last step: bounced light
//! changes smoothly, and never lags by more than those frames. A leaf of moved geometry (its
//! slot held another leaf) shows its new light at once, as does every leaf after a rebuild.

use crate::gpu::layout;
use crate::gpu::shader::voxel_pipeline;
use crate::gpu::timer::GpuTimer;
use crate::voxel::{VoxelKind, VoxelStructure};
use bytemuck::{Pod, Zeroable};

/// Frames over which a voxel update's light replaces the light shown before: a step of a
/// quarter of the change a frame at 60 Hz is 67 ms of lag at most.
pub const VOXEL_BLEND_FRAMES: u32 = 4;

/// Mirrors `Blend` in shaders/lighting/blend.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuBlend {
    /// The share of the remaining way this step goes.
    pub weight: f32,
    /// 1: every leaf starts at its new light.
    pub restart: u32,
    /// 1: the update's light is the last bounce's; 0: the direct light.
    pub from_bounce: u32,
    /// 1: every leaf is stored; 0: only those whose shown light moves (the structure holds
    /// the others since the last step: nothing else wrote it).
    pub store_all: u32,
}

/// The blend pass's pipeline and layout.
pub struct BlendPass {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
}

/// What the pass keeps for one structure: the leaves' shown radiance and the step's uniform.
pub struct BlendState {
    /// Per leaf slot, vec4 f32.
    shown: wgpu::Buffer,
    uniform: wgpu::Buffer,
    bind: wgpu::BindGroup,
    /// Leaf slots `shown` holds.
    pub capacity: u64,
}

impl BlendPass {
    /// Compiles the pass for structure `kind`.
    pub fn new(device: &wgpu::Device, kind: VoxelKind) -> Self {
        let c = wgpu::ShaderStages::COMPUTE;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("blend"),
            entries: &[layout::uniform(0, c, false), layout::storage(1, c, false)],
        });
        let leaves = kind.leaves_layout(device);
        let store = kind.leaf_store_layout(device);
        let pipeline = voxel_pipeline(
            device,
            "blend",
            "lighting/blend.wgsl",
            kind.shaders(),
            &[Some(&layout), None, Some(&leaves), Some(&store)],
            &[],
        );
        BlendPass { pipeline, layout }
    }

    /// The shown radiance of `voxels`'s leaf slots (contents undefined until a restart).
    pub fn state(&self, device: &wgpu::Device, voxels: &dyn VoxelStructure) -> BlendState {
        let capacity = voxels.leaf_capacity().max(1);
        let shown = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("blend shown"),
            size: capacity * 16,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        let uniform = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("blend"),
            size: size_of::<GpuBlend>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("blend"),
            layout: &self.layout,
            entries: &layout::entries(vec![uniform.as_entire_binding(), shown.as_entire_binding()]),
        });
        BlendState {
            shown,
            uniform,
            bind,
            capacity,
        }
    }

    /// Records one step over the leaves of `voxels` (an indirect dispatch timed as "blend"):
    /// `step` is the uniform, written through `queue`. The structure must be filtered after.
    pub fn record(
        &self,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        voxels: &dyn VoxelStructure,
        state: &BlendState,
        step: GpuBlend,
        timer: &mut GpuTimer,
    ) {
        queue.write_buffer(&state.uniform, 0, bytemuck::bytes_of(&step));
        let bound = voxels.bindings();
        let (args, offset) = bound.leaf_dispatch;
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("blend"),
            timestamp_writes: timer.compute("blend"),
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &state.bind, &[]);
        pass.set_bind_group(2, bound.leaves, &[]);
        pass.set_bind_group(3, bound.leaf_store, &[]);
        pass.dispatch_workgroups_indirect(args, offset);
    }
}

impl BlendState {
    /// GPU memory of the shown radiance, bytes.
    pub fn bytes(&self) -> u64 {
        self.shown.size()
    }
}
