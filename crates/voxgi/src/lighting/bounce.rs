//! bounce: one bounce of light in voxel space over the occupied voxels, then `bounce_store`
//! writes the result into the finest level (a separate dispatch: the volume cannot be sampled
//! and written in one). For the fast shading the gather also keeps every leaf's irradiance.

use crate::gpu::layout;
use crate::gpu::shader::{voxel_pipeline, voxel_pipeline_entry};
use crate::gpu::timer::GpuTimer;
use crate::voxel::{VoxelKind, VoxelStructure};
use bytemuck::{Pod, Zeroable};

/// What one bounce records.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BounceSteps {
    /// Keep every leaf's irradiance and occlusion (`VoxelStructure::leaf_irradiance`) for the
    /// fast shading.
    pub irradiance: bool,
    /// Write the bounced radiance into the finest level (the volume must then be filtered).
    pub store: bool,
}

/// Mirrors `Slices` in shaders/lighting/bounce.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuSlices {
    /// Slices of the leaves, one gathered per update (1: every leaf every update).
    pub count: u32,
    /// The slice that gathers this update.
    pub turn: u32,
    /// 1: every leaf gathers (nothing kept yet, or the slots hold other leaves now).
    pub all: u32,
    /// Leaf slots of the structure (where the list begins in the kept words).
    pub capacity: u32,
    /// The lowest corner of the world box whose leaves gather at once, whatever their slice
    /// (`near_change`); the box is empty (min above max) when no geometry moved.
    pub near_min: [f32; 4],
    /// The box's highest corner.
    pub near_max: [f32; 4],
    /// 1: a new leaf may start from the kept light its structure names
    /// (`leaf_carry_source`); 0: it gathers at once (its irradiance record is read).
    pub carry: u32,
    /// Padding; zero.
    pub _pad: [u32; 3],
}

/// Where leaves gather at once after dynamic geometry moved within `moved` (world space), with
/// diffuse cones of half-angle tangent `diffuse_tan`: within `s / diffuse_tan` of the box, `s`
/// its largest side. A diffuse cone is `2 d tan` wide at distance `d`, so there the box spans
/// at least half a cone's width and its change enters a gather at no less than a quarter of
/// a cone's cross-section; farther, it is diluted more, and the slices amortise it.
pub fn near_change(moved: voxgi_scene::Aabb, diffuse_tan: f32) -> voxgi_scene::Aabb {
    let size = moved.max - moved.min;
    let reach = size.max_element() / diffuse_tan.max(1e-3);
    voxgi_scene::Aabb {
        min: moved.min - glam::Vec3::splat(reach),
        max: moved.max + glam::Vec3::splat(reach),
    }
}

/// The bounce pass's `@group(0)` for one structure (`BouncePass::bind`): per bounce of an
/// update, the gather's bind group and `mark`'s, each with its range of the kept irradiance.
pub struct BounceGlobals {
    levels: Vec<(wgpu::BindGroup, wgpu::BindGroup)>,
    uniform: wgpu::Buffer,
    gathered: Vec<wgpu::Buffer>,
    /// `mark`'s count and the gather's dispatch size.
    listing: wgpu::Buffer,
    capacity: u32,
    /// `bounce_slices` it was made for (at least 1).
    slices: u32,
    /// Nothing is kept yet: the next update's bounces gather at every leaf.
    fresh: bool,
    /// The next update's bounces gather at a list of leaves (`prepare`).
    listed: bool,
    /// The next update's new leaves may keep the light of the leaves that held their voxels
    /// before a build of part of the structure (`prepare`'s `kept`).
    stash: bool,
}

impl BounceGlobals {
    /// Sets which leaves gather in the next update's bounces: those of slice `turn` and those
    /// inside `near` (`near_change`), or all of them when nothing is kept yet or `all`; new
    /// leaves too, unless `carry` lets them start from the kept light their structure names
    /// (not when the bounce keeps irradiance records for the pixels: a carried leaf would
    /// show its slot's previous record); with `carry` and `kept` (a build of part of the
    /// structure, whose new leaves may lie where leaves lay before) first from the light of
    /// the leaf that held their voxel (`leaf_kept_self`).
    pub fn prepare(
        &mut self,
        queue: &wgpu::Queue,
        turn: u32,
        all: bool,
        near: Option<voxgi_scene::Aabb>,
        carry: bool,
        kept: bool,
    ) {
        let count = self.slices;
        let all = all || self.fresh;
        let (near_min, near_max) = near.map_or(([1.0; 4], [-1.0; 4]), |b| {
            (b.min.extend(0.0).to_array(), b.max.extend(0.0).to_array())
        });
        let s = GpuSlices {
            count,
            turn: turn % count,
            all: all as u32,
            capacity: self.capacity,
            near_min,
            near_max,
            carry: carry as u32,
            _pad: [0; 3],
        };
        queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&s));
        self.fresh = false;
        self.listed = count > 1 && !all;
        self.stash = self.listed && carry && kept;
    }

    /// Bytes of the kept irradiance and the lists (none with one slice).
    pub fn memory(&self) -> u64 {
        if self.slices > 1 {
            self.gathered.iter().map(|b| b.size()).sum()
        } else {
            0
        }
    }
}

/// The bounce pass (shaders/bounce.wgsl and bounce_store.wgsl): the gather and store pipelines
/// and the layout of their cone uniform and irradiance records.
pub struct BouncePass {
    gather: wgpu::ComputePipeline,
    /// Made for the fast shading only.
    gather_irradiance: Option<wgpu::ComputePipeline>,
    globals: wgpu::BindGroupLayout,
    store: wgpu::ComputePipeline,
    /// `stash`, `mark` and `list` (bounce slices) and their `@group(0)`.
    stash: wgpu::ComputePipeline,
    mark: wgpu::ComputePipeline,
    list: wgpu::ComputePipeline,
    mark_globals: wgpu::BindGroupLayout,
}

impl BouncePass {
    /// Compiles the pipelines for structure `kind`; `anisotropic` and `lobes` must match the
    /// structure's mode (the gather samples all three axes of an anisotropic one, and the lobe
    /// blocks of one with specular lobes); `irradiance`: also the gather that keeps
    /// the leaves' irradiance (`BounceSteps::irradiance`).
    pub fn new(
        device: &wgpu::Device,
        kind: VoxelKind,
        anisotropic: bool,
        lobes: bool,
        irradiance: bool,
    ) -> Self {
        let c = wgpu::ShaderStages::COMPUTE;
        let globals = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("bounce globals"),
            entries: &[
                layout::uniform(0, c, false),
                layout::storage(1, c, false),
                layout::uniform(2, c, false),
                layout::storage(3, c, false),
            ],
        });
        let mark_globals = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("bounce mark"),
            entries: &[
                layout::uniform(2, c, false),
                layout::storage(3, c, false),
                layout::storage(4, c, false),
            ],
        });
        let voxels = kind.sampling_layout(device);
        let leaves = kind.leaves_layout(device);
        let store = kind.leaf_store_layout(device);
        let carry = kind.carry_layout(device);
        let mark = |entry| {
            voxel_pipeline_entry(
                device,
                "bounce",
                "lighting/bounce.wgsl",
                kind.shaders(),
                entry,
                // What the structure's carry functions read.
                &[Some(&mark_globals), None, Some(&leaves), Some(&carry)],
            )
        };
        let gather = |irradiance: bool| {
            let mut constants = kind.sampling_constants(anisotropic, lobes, 3);
            constants.push(("IRRADIANCE", f64::from(u8::from(irradiance))));
            voxel_pipeline(
                device,
                "bounce",
                "lighting/bounce.wgsl",
                kind.shaders(),
                &[Some(&globals), Some(&voxels), Some(&leaves)],
                &constants,
            )
        };
        BouncePass {
            gather: gather(false),
            gather_irradiance: irradiance.then(|| gather(true)),
            store: voxel_pipeline(
                device,
                "bounce",
                "lighting/bounce_store.wgsl",
                kind.shaders(),
                &[None, None, Some(&leaves), Some(&store)],
                &[],
            ),
            mark: mark("mark"),
            stash: mark("stash"),
            list: voxel_pipeline_entry(
                device,
                "bounce",
                "lighting/bounce.wgsl",
                kind.shaders(),
                "list",
                &[Some(&mark_globals)],
            ),
            globals,
            mark_globals,
        }
    }

    /// The pass's `@group(0)` for `voxels`, made once per structure: the diffuse cones in
    /// `cones` (`Cones` in shared/volume.wgsl), the leaves' records, and with `slices` > 1 the
    /// irradiance each leaf last gathered in each of `bounces` bounces of an update.
    pub fn bind(
        &self,
        device: &wgpu::Device,
        voxels: &dyn VoxelStructure,
        cones: &wgpu::Buffer,
        slices: u32,
        bounces: u32,
    ) -> BounceGlobals {
        let buffer = |label, size, usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage,
                mapped_at_creation: false,
            })
        };
        let uniform = buffer(
            "bounce slices",
            std::mem::size_of::<GpuSlices>() as u64,
            wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        );
        let listing = buffer(
            "bounce listing",
            16,
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::INDIRECT,
        );
        let capacity = voxels.leaf_capacity().max(1);
        // Per bounce (a buffer each: many bounces of a large structure would pass the largest
        // buffer a device makes): four words a slot, the count, a word a slot.
        let (levels, size) = if slices > 1 {
            (bounces.max(1), (5 * capacity + 1) * 4)
        } else {
            (1, 16)
        };
        let gathered: Vec<wgpu::Buffer> = (0..levels)
            .map(|_| buffer("bounce gathered", size, wgpu::BufferUsages::STORAGE))
            .collect();
        let levels = gathered
            .iter()
            .map(|part| {
                let part = || part.as_entire_binding();
                let entry = |binding, resource| wgpu::BindGroupEntry { binding, resource };
                let gather = device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("bounce globals"),
                    layout: &self.globals,
                    entries: &[
                        entry(0, cones.as_entire_binding()),
                        entry(1, voxels.bindings().leaf_irradiance.as_entire_binding()),
                        entry(2, uniform.as_entire_binding()),
                        entry(3, part()),
                    ],
                });
                let mark = device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("bounce mark"),
                    layout: &self.mark_globals,
                    entries: &[
                        entry(2, uniform.as_entire_binding()),
                        entry(3, part()),
                        entry(4, listing.as_entire_binding()),
                    ],
                });
                (gather, mark)
            })
            .collect();
        BounceGlobals {
            levels,
            uniform,
            gathered,
            listing,
            capacity: u32::try_from(capacity).unwrap_or(u32::MAX),
            slices: slices.max(1),
            fresh: true,
            listed: false,
            stash: false,
        }
    }

    /// Records one bounce over the leaves of `voxels` with the cones `globals` binds (`bind`),
    /// then, with `steps.store`, the store into the finest level, both as
    /// indirect dispatches timed as "bounce". After a store the volume must be filtered again
    /// before it is sampled.
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        voxels: &dyn VoxelStructure,
        globals: &BounceGlobals,
        bounce: u32,
        steps: BounceSteps,
        timer: &mut GpuTimer,
    ) {
        let bound = voxels.bindings();
        let (args, offset) = bound.leaf_dispatch;
        let (gather_globals, mark_globals) =
            &globals.levels[(bounce as usize).min(globals.levels.len() - 1)];
        let gather = match (&self.gather_irradiance, steps.irradiance) {
            (Some(p), true) => p,
            (None, true) => panic!("BouncePass::new was not asked for the irradiance gather"),
            (_, false) => &self.gather,
        };
        fn pass<'a>(
            encoder: &'a mut wgpu::CommandEncoder,
            timer: &mut GpuTimer,
        ) -> wgpu::ComputePass<'a> {
            encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("bounce"),
                timestamp_writes: timer.compute("bounce"),
            })
        }
        // With slices: `mark` lists the leaves that gather and re-emits the others' kept
        // light, `list` sizes the gather to the list; each step reads what the last wrote.
        if globals.listed {
            {
                let mut pass = pass(encoder, timer);
                pass.set_bind_group(0, mark_globals, &[]);
                pass.set_bind_group(2, bound.leaves, &[]);
                pass.set_bind_group(3, bound.carry, &[]);
                // `stash` reads the kept light of old leaves before `mark` writes new ones'.
                if globals.stash {
                    pass.set_pipeline(&self.stash);
                    pass.dispatch_workgroups_indirect(args, offset);
                }
                pass.set_pipeline(&self.mark);
                pass.dispatch_workgroups_indirect(args, offset);
            }
            let mut pass = pass(encoder, timer);
            pass.set_pipeline(&self.list);
            pass.set_bind_group(0, mark_globals, &[]);
            pass.dispatch_workgroups(1, 1, 1);
        }
        let mut pass = pass(encoder, timer);
        pass.set_pipeline(gather);
        pass.set_bind_group(0, gather_globals, &[]);
        pass.set_bind_group(1, bound.sampling, &[]);
        pass.set_bind_group(2, bound.leaves, &[]);
        if globals.listed {
            pass.dispatch_workgroups_indirect(&globals.listing, 4);
        } else {
            pass.dispatch_workgroups_indirect(args, offset);
        }
        if !steps.store {
            return;
        }
        pass.set_pipeline(&self.store);
        pass.set_bind_group(3, bound.leaf_store, &[]);
        pass.dispatch_workgroups_indirect(args, offset);
    }
}
