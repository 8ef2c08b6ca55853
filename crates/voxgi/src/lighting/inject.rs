//! inject: direct light and emission into the voxel structure's leaves.

use crate::gpu::layout;
use crate::gpu::timer::GpuTimer;
use crate::gpu_scene::GpuScene;
use crate::lighting::atlas::{MATERIAL_ATLAS_FORMAT, ShadowAtlas, ViewDirt};
use crate::options::ShadowFilter;
use crate::voxel::{VoxelKind, VoxelStructure};
use wgpu::util::DeviceExt;

/// The inject compute pass (shaders/inject.wgsl): its pipeline, the layout of its globals, and
/// what changed since the last injection (`prepare`).
pub struct InjectPass {
    /// `mark` and `main`, storing the leaves' radiance, and the same without (progressive
    /// bounces); `prepare` between them.
    pipelines: [(wgpu::ComputePipeline, wgpu::ComputePipeline); 2],
    prepare: wgpu::ComputePipeline,
    globals: wgpu::BindGroupLayout,
    /// `main`'s dispatch size (written by `prepare`).
    args: wgpu::Buffer,
    /// The leaves to recompute (`todo` in the WGSL), grown by `prepare` to the structure's
    /// leaves.
    todo: wgpu::Buffer,
    light_count: u32,
    /// `globals` bound: the params, the lights and the shadow atlas, the views' dirt and the
    /// list; made by `prepare` when first needed and again when the atlas or the list is new
    /// (the atlas it was made for is kept to tell).
    bound: Option<(wgpu::Texture, wgpu::BindGroup)>,
    /// `args_layout` bound to `args`.
    args_bind: wgpu::BindGroup,
    /// `InjectParams`: the light count, whether every leaf is recomputed, where geometry moved.
    params: wgpu::Buffer,
    /// Per shadow view, the rectangle of its map that changed.
    dirt: wgpu::Buffer,
}

/// Mirrors `InjectParams` in shaders/lighting/inject.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct GpuInjectParams {
    pub(crate) light_count: u32,
    pub(crate) all: u32,
    pub(crate) store_all: u32,
    /// 1: the shadow maps hold the surfaces' specular materials (`MATERIAL_ATLAS_FORMAT`).
    pub(crate) materials: u32,
    pub(crate) moved_min: [f32; 4],
    pub(crate) moved_max: [f32; 4],
}

impl InjectPass {
    /// Compiles the pipeline for a scene of `light_count` lights with `views` shadow views
    /// (both fixed until the pass is rebuilt), filtered by `filter`.
    pub fn new(
        device: &wgpu::Device,
        kind: VoxelKind,
        light_count: u32,
        views: usize,
        filter: ShadowFilter,
    ) -> Self {
        let moments = f64::from(u8::from(filter == ShadowFilter::VsmEsm));
        let c = wgpu::ShaderStages::COMPUTE;
        let mut entries = vec![layout::uniform(0, c, false)];
        entries.extend(ShadowAtlas::lighting_layout(c));
        entries.push(layout::storage(5, c, true));
        entries.push(layout::storage(6, c, false));
        let globals = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("inject globals"),
            entries: &entries,
        });
        let leaves = kind.leaves_layout(device);
        let store = kind.leaf_store_layout(device);
        let args_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("inject args"),
            entries: &[layout::storage(0, c, false)],
        });
        let module = crate::gpu::shader::module_for(device, "lighting/inject.wgsl", kind.shaders());
        let pipe = |entry: &str, layouts: &[Option<&wgpu::BindGroupLayout>], store: bool| {
            let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("inject"),
                bind_group_layouts: layouts,
                immediate_size: 0,
            });
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("inject"),
                layout: Some(&pipeline_layout),
                module: &module,
                entry_point: Some(entry),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants: &[
                        ("STORE_RADIANCE", if store { 1.0 } else { 0.0 }),
                        ("SHADOW_MOMENTS", moments),
                    ],
                    ..Default::default()
                },
                cache: None,
            })
        };
        let layouts = [Some(&globals), None, Some(&leaves), Some(&store)];
        let both = |store| (pipe("mark", &layouts, store), pipe("main", &layouts, store));
        let args = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("inject dispatch size"),
            size: 12,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::INDIRECT,
            mapped_at_creation: false,
        });
        let args_bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("inject args"),
            layout: &args_layout,
            entries: &layout::entries(vec![args.as_entire_binding()]),
        });
        InjectPass {
            pipelines: [both(true), both(false)],
            prepare: pipe("prepare", &[Some(&globals), Some(&args_layout)], true),
            args,
            args_bind,
            bound: None,
            todo: todo_buffer(device, 4),
            globals,
            light_count,
            params: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("inject params"),
                size: size_of::<GpuInjectParams>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            dirt: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("inject view dirt"),
                contents: &vec![0u8; 16 * views.max(1)],
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            }),
        }
    }

    /// Says what changed since the last injection, for the next `record`: everything (`all`),
    /// or the box dynamic geometry moved through (`moved`) and the changed part of each shadow
    /// view (`views`, one per atlas layer of `res` texels). Leaves whose inputs none of this touches keep
    /// their direct light: what they would compute is the same, to the bit. Their radiance
    /// is stored again only when `store_all` (something else wrote it since: the bounces).
    #[allow(clippy::too_many_arguments)]
    pub fn prepare(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &GpuScene,
        atlas: &ShadowAtlas,
        voxels: &dyn VoxelStructure,
        all: bool,
        store_all: bool,
        moved: Option<voxgi_scene::Aabb>,
        views: &[ViewDirt],
        res: u32,
    ) {
        let (lo, hi) = moved.map_or(([1.0, 1.0, 1.0, 0.0], [-1.0, -1.0, -1.0, 0.0]), |b| {
            (b.min.extend(0.0).to_array(), b.max.extend(0.0).to_array())
        });
        let p = GpuInjectParams {
            light_count: self.light_count,
            all: all as u32,
            store_all: store_all as u32,
            materials: (atlas.texture.format() == MATERIAL_ATLAS_FORMAT) as u32,
            moved_min: lo,
            moved_max: hi,
        };
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&p));
        let needed = todo_bytes(voxels);
        if self.todo.size() < needed {
            self.todo = todo_buffer(device, needed);
            self.bound = None;
        }
        if self.bound.as_ref().is_none_or(|(t, _)| *t != atlas.texture) {
            let mut resources = vec![self.params.as_entire_binding()];
            resources.extend(atlas.lighting_resources(scene));
            resources.push(self.dirt.as_entire_binding());
            resources.push(self.todo.as_entire_binding());
            let globals = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("inject globals"),
                layout: &self.globals,
                entries: &layout::entries(resources),
            });
            self.bound = Some((atlas.texture.clone(), globals));
        }
        let dirt: Vec<[f32; 4]> = views.iter().map(|v| v.to_gpu(res)).collect();
        if !dirt.is_empty() {
            queue.write_buffer(&self.dirt, 0, bytemuck::cast_slice(&dirt));
        }
    }

    /// The list of leaves the last injection recomputed: a count, then their slots.
    pub fn recomputed(&self) -> &wgpu::Buffer {
        &self.todo
    }

    /// Records the injection of direct light (shadowed by `atlas`) and emission into every leaf of
    /// `voxels` as an indirect dispatch: the leaves' direct light and their radiance. Timed as
    /// "inject".
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        voxels: &dyn VoxelStructure,
        timer: &mut GpuTimer,
    ) {
        self.record_with(0, encoder, voxels, timer);
    }

    /// `record`, but the leaves' radiance is kept: only their direct light is renewed (for
    /// progressive bounces, which build on the last update's radiance).
    pub fn record_direct_only(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        voxels: &dyn VoxelStructure,
        timer: &mut GpuTimer,
    ) {
        self.record_with(1, encoder, voxels, timer);
    }

    fn record_with(
        &self,
        which: usize,
        encoder: &mut wgpu::CommandEncoder,
        voxels: &dyn VoxelStructure,
        timer: &mut GpuTimer,
    ) {
        debug_assert!(
            self.todo.size() >= todo_bytes(voxels),
            "inject: `prepare` sizes the list for these leaves"
        );
        let todo = &self.todo;
        encoder.clear_buffer(todo, 0, Some(4));
        let Some((_, globals)) = &self.bound else {
            debug_assert!(false, "inject: `prepare` makes the bind group");
            return;
        };
        let args = &self.args_bind;
        let (mark, main) = &self.pipelines[which];
        let bound = voxels.bindings();
        let (leaf_args, offset) = bound.leaf_dispatch;
        // Three passes: each reads what the one before wrote (the list, its dispatch size).
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("inject"),
                timestamp_writes: timer.compute("inject"),
            });
            pass.set_pipeline(mark);
            pass.set_bind_group(0, globals, &[]);
            pass.set_bind_group(2, bound.leaves, &[]);
            pass.set_bind_group(3, bound.leaf_store, &[]);
            pass.dispatch_workgroups_indirect(leaf_args, offset);
        }
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("inject"),
                timestamp_writes: timer.compute("inject"),
            });
            pass.set_pipeline(&self.prepare);
            pass.set_bind_group(0, globals, &[]);
            pass.set_bind_group(1, args, &[]);
            pass.dispatch_workgroups(1, 1, 1);
        }
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("inject"),
            timestamp_writes: timer.compute("inject"),
        });
        pass.set_pipeline(main);
        pass.set_bind_group(0, globals, &[]);
        pass.set_bind_group(2, bound.leaves, &[]);
        pass.set_bind_group(3, bound.leaf_store, &[]);
        pass.dispatch_workgroups_indirect(&self.args, 0);
    }
}

/// Bytes of the list of leaves to recompute: a count and a slot per leaf.
fn todo_bytes(voxels: &dyn VoxelStructure) -> u64 {
    (voxels.leaf_capacity() + 1) * 4
}

fn todo_buffer(device: &wgpu::Device, size: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("inject todo"),
        size,
        usage: wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_DST
            | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    })
}
