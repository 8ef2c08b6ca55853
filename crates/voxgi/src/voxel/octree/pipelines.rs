//! The octree's own pipelines (octree_build, octree_update, octree_filter, debug).

use super::*;

/// The octree's pipelines (octree_build, octree_filter, debug): made once per renderer and
/// shared by every octree it makes (one is remade whenever its pools grow).
pub struct OctreePipelines {
    pub(super) build_layout: wgpu::BindGroupLayout,
    pub(super) args_layout: wgpu::BindGroupLayout,
    pub(super) filter_layout: wgpu::BindGroupLayout,
    pub(super) build: BuildPipelines,
    pub(super) update: UpdatePipelines,
    pub(super) filter: wgpu::ComputePipeline,
    pub(super) filter_top: wgpu::ComputePipeline,
    pub(super) debug: DebugPass,
}

/// octree_update's entry points (shaders/voxels/octree/octree_update.wgsl).
pub(super) struct UpdatePipelines {
    pub(super) begin_clear: wgpu::ComputePipeline,
    pub(super) clear_leaves: wgpu::ComputePipeline,
    pub(super) clear_nodes: wgpu::ComputePipeline,
    pub(super) restore: wgpu::ComputePipeline,
    pub(super) begin_update: wgpu::ComputePipeline,
    pub(super) bounds: wgpu::ComputePipeline,
    pub(super) prepare_depth: wgpu::ComputePipeline,
    pub(super) end_update: wgpu::ComputePipeline,
    pub(super) flag: wgpu::ComputePipeline,
    pub(super) mark: wgpu::ComputePipeline,
    pub(super) count: wgpu::ComputePipeline,
    pub(super) scan: wgpu::ComputePipeline,
    pub(super) allocate: wgpu::ComputePipeline,
    pub(super) finish_update: wgpu::ComputePipeline,
    pub(super) init: wgpu::ComputePipeline,
    pub(super) repair: wgpu::ComputePipeline,
    pub(super) allocate_slots: wgpu::ComputePipeline,
    pub(super) accumulate: wgpu::ComputePipeline,
    pub(super) prepare_static: wgpu::ComputePipeline,
    pub(super) accumulate_static: wgpu::ComputePipeline,
    pub(super) prepare_slots: wgpu::ComputePipeline,
    pub(super) resolve: wgpu::ComputePipeline,
}

pub(super) struct BuildPipelines {
    pub(super) begin: wgpu::ComputePipeline,
    pub(super) flag: wgpu::ComputePipeline,
    pub(super) dilate: wgpu::ComputePipeline,
    pub(super) mark: wgpu::ComputePipeline,
    pub(super) count: wgpu::ComputePipeline,
    pub(super) scan: wgpu::ComputePipeline,
    pub(super) allocate: wgpu::ComputePipeline,
    pub(super) finish: wgpu::ComputePipeline,
    pub(super) init: wgpu::ComputePipeline,
    pub(super) allocate_slots: wgpu::ComputePipeline,
    pub(super) accumulate: wgpu::ComputePipeline,
    pub(super) prepare_slots: wgpu::ComputePipeline,
    pub(super) resolve: wgpu::ComputePipeline,
    pub(super) seal: wgpu::ComputePipeline,
}

impl OctreePipelines {
    /// Compiles the build, filter and debug pipelines.
    pub fn new(device: &wgpu::Device) -> Arc<Self> {
        let c = wgpu::ShaderStages::COMPUTE;
        let build_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("octree_build"),
            entries: &[
                layout::uniform(0, c, false),
                layout::storage(1, c, true),
                layout::storage(2, c, true),
                layout::storage(3, c, false),
                layout::storage(4, c, false),
                layout::storage(5, c, false),
                layout::storage_texture_3d(6, ATLAS_FORMAT),
                layout::storage_texture_3d(7, ATLAS_FORMAT),
                layout::uniform(8, c, true),
                layout::storage(9, c, false),
                layout::storage(10, c, false),
                layout::storage_texture(11, super::tree::FLAG_FORMAT),
            ],
        });
        let args_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("octree_build args"),
            entries: &[layout::storage(0, c, false)],
        });
        let plain = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("octree_build"),
            bind_group_layouts: &[Some(&build_layout)],
            immediate_size: 0,
        });
        let with_args = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("octree_build prepare"),
            bind_group_layouts: &[Some(&build_layout), Some(&args_layout)],
            immediate_size: 0,
        });
        let pipe = |m: &wgpu::ShaderModule, label: &str, entry: &str, args: bool| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(label),
                layout: Some(if args { &with_args } else { &plain }),
                module: m,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        let m = shader::module_for(device, "voxels/octree/octree_build.wgsl", &KIND.shaders);
        let b = |entry: &str, args: bool| pipe(&m, "octree_build", entry, args);
        let build = BuildPipelines {
            begin: b("begin", true),
            flag: b("flag", false),
            dilate: b("dilate", false),
            mark: b("mark", false),
            count: b("count", false),
            scan: b("scan", false),
            allocate: b("allocate", false),
            finish: b("finish", true),
            init: b("init", false),
            allocate_slots: b("allocate_slots", false),
            accumulate: b("accumulate", false),
            prepare_slots: b("prepare_slots", true),
            resolve: b("resolve", false),
            seal: b("seal", false),
        };
        let m = shader::module_for(device, "voxels/octree/octree_update.wgsl", &KIND.shaders);
        let u = |entry: &str, args: bool| pipe(&m, "octree_update", entry, args);
        let update = UpdatePipelines {
            begin_clear: u("begin_clear", true),
            clear_leaves: u("clear_leaves", false),
            clear_nodes: u("clear_nodes", false),
            restore: u("restore", false),
            begin_update: u("begin_update", true),
            bounds: u("bounds", false),
            prepare_depth: u("prepare_depth", true),
            end_update: u("end_update", true),
            flag: u("flag", false),
            mark: u("mark", false),
            count: u("count", false),
            scan: u("scan", false),
            allocate: u("allocate", false),
            finish_update: u("finish_update", true),
            init: u("init", false),
            repair: u("repair", false),
            allocate_slots: u("allocate_slots", false),
            accumulate: u("accumulate", false),
            prepare_static: u("prepare_static", true),
            accumulate_static: u("accumulate_static", false),
            prepare_slots: u("prepare_slots", true),
            resolve: u("resolve", false),
        };
        let filter_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("octree_filter"),
            entries: &[
                layout::uniform(0, c, false),
                layout::storage(1, c, true),
                layout::storage(2, c, true),
                layout::texture_3d_load(3, c),
                layout::storage_texture_3d(4, ATLAS_FORMAT),
                layout::uniform(5, c, true),
                layout::storage(6, c, true),
                wgpu::BindGroupLayoutEntry {
                    binding: 7,
                    visibility: c,
                    ty: wgpu::BindingType::StorageTexture {
                        access: wgpu::StorageTextureAccess::ReadWrite,
                        format: super::tree::FLAG_FORMAT,
                        view_dimension: wgpu::TextureViewDimension::D2,
                    },
                    count: None,
                },
                layout::storage(8, c, false),
                // The leaves' direct light: their specular lobes.
                layout::storage(9, c, true),
            ],
        });
        let filter_module =
            shader::module_for(device, "voxels/octree/octree_filter.wgsl", &KIND.shaders);
        let filter_pipeline_layout =
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("octree_filter"),
                bind_group_layouts: &[Some(&filter_layout)],
                immediate_size: 0,
            });
        let f = |entry: &str| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("octree_filter"),
                layout: Some(&filter_pipeline_layout),
                module: &filter_module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        let (filter, filter_top) = (f("main"), f("top"));
        Arc::new(OctreePipelines {
            build_layout,
            args_layout,
            filter_layout,
            build,
            update,
            filter,
            filter_top,
            debug: DebugPass::new(device),
        })
    }
}
