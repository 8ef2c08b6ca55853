//! octree_build and octree_update: the octree from the fragments, level by level from the
//! root, and the dynamic geometry merged into the static build.

use super::*;
use tree::{ARGS_CLEAR, ARGS_NEW, ARGS_STATIC};

impl OctreeVolume {
    pub(super) fn build_bind_group(
        &self,
        device: &wgpu::Device,
        fragments: &Fragments,
        scratch: &wgpu::Buffer,
    ) -> wgpu::BindGroup {
        let view = |t: &wgpu::Texture| t.create_view(&Default::default());
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("octree_build"),
            layout: &self.pipelines.build_layout,
            entries: &layout::entries(vec![
                self.tree.as_entire_binding(),
                fragments.buffer.as_entire_binding(),
                fragments.count.as_entire_binding(),
                self.nodes.as_entire_binding(),
                self.tiles.as_entire_binding(),
                self.slots.as_entire_binding(),
                wgpu::BindingResource::TextureView(&view(&self.even_atlas)),
                wgpu::BindingResource::TextureView(&view(&self.odd_atlas)),
                wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &self.levels,
                    offset: 0,
                    size: wgpu::BufferSize::new(16),
                }),
                scratch.as_entire_binding(),
                self.top_grid.as_entire_binding(),
                wgpu::BindingResource::TextureView(&view(&self.filter_flags)),
            ]),
        })
    }

    /// Records a build from every fragment in `fragments`, level by level (octree_build.wgsl).
    pub(super) fn build(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        fragments: &Fragments,
        timer: &mut GpuTimer,
    ) {
        // The build's sums live for this build (wgpu keeps them until the GPU is done with
        // them); a dynamic scene keeps sums only for the slots its updates add.
        let bytes = scratch_bytes(self.layout.tiles as u64, self.pools.slots as u64);
        let scratch = storage_buffer(device, "octree build sums", bytes);
        let bind = self.build_bind_group(device, fragments, &scratch);
        let args = &self.args_bind;
        let b = &self.pipelines.build;
        let depth = self.depth();
        let over_nodes = |t: u32| Run::Indirect((6 + 3 * t as u64) * 4);
        let mut steps: Vec<(&wgpu::ComputePipeline, u32, Run)> = vec![(&b.begin, 0, Run::Prepare)];
        for t in 0..depth {
            steps.extend([
                (&b.flag, t, Run::Indirect(0)),
                (&b.dilate, t, over_nodes(t)),
                (&b.mark, t, Run::One),
                (&b.count, t, over_nodes(t)),
                (&b.scan, t, Run::One),
                (&b.allocate, t, over_nodes(t)),
                (&b.finish, t, Run::Prepare),
                (&b.init, t + 1, over_nodes(t + 1)),
            ]);
        }
        steps.extend([
            (&b.flag, depth, Run::Indirect(0)),
            (&b.count, depth, over_nodes(depth)),
            (&b.scan, depth, Run::One),
            (&b.allocate_slots, depth, over_nodes(depth)),
            (&b.accumulate, depth, Run::Indirect(0)),
            (&b.prepare_slots, depth, Run::Prepare),
            (&b.resolve, depth, Run::Indirect(12)),
            (&b.seal, depth, Run::One),
        ]);
        // Positions the previous build filled and this one may not.
        encoder.clear_buffer(&self.top_grid, 0, None);
        self.run_steps(encoder, "octree_build", &bind, args, &steps, timer);
        if let Some(u) = &self.updates {
            encoder.copy_buffer_to_buffer(&self.nodes, 0, &u.header, 0, u.header.size());
        }
    }

    /// Records `steps` in one compute pass timed as `label`: each dispatch reads what the one
    /// before wrote (dispatch sizes, counters, nodes).
    fn run_steps(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        label: &'static str,
        bind: &wgpu::BindGroup,
        args: &wgpu::BindGroup,
        steps: &[(&wgpu::ComputePipeline, u32, Run)],
        timer: &mut GpuTimer,
    ) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(label),
            timestamp_writes: timer.compute(label),
        });
        for (pipeline, t, run) in steps {
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, bind, &[(*t as u64 * LEVEL_STRIDE) as u32]);
            match run {
                Run::Prepare => {
                    pass.set_bind_group(1, args, &[]);
                    pass.dispatch_workgroups(1, 1, 1);
                }
                Run::One => pass.dispatch_workgroups(1, 1, 1),
                Run::Indirect(offset) => pass.dispatch_workgroups_indirect(&self.args, *offset),
            }
        }
    }

    /// Records an update by the dynamic fragments (those after the static build's): the last
    /// update's texels in the static bricks are zeroed and its writes into the static nodes
    /// and leaves undone, the static build's header comes back from its copy, and the dynamic
    /// fragments are merged in depth by depth (octree_update.wgsl). A scene with no dynamic
    /// instances builds instead.
    pub(super) fn update(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        fragments: &Fragments,
        timer: &mut GpuTimer,
    ) {
        let Some(base) = &self.updates else {
            self.build(device, encoder, fragments, timer);
            return;
        };
        let bind = self.fragment_bind.get(fragments, || {
            self.build_bind_group(device, fragments, &base.scratch)
        });
        let args = &self.args_bind;
        let u = &self.pipelines.update;
        let depth = self.depth();
        let over_nodes = |t: u32| Run::Indirect((6 + 3 * t as u64) * 4);
        let over_new = |t: u32| Run::Indirect((ARGS_NEW + 3 * t as u64) * 4);
        let mut clear: Vec<(&wgpu::ComputePipeline, u32, Run)> = vec![
            (&u.begin_clear, 0, Run::Prepare),
            (&u.clear_leaves, 0, Run::Indirect(ARGS_CLEAR * 4)),
        ];
        for t in 1..=depth {
            clear.push((&u.clear_nodes, t, over_new(t)));
        }
        // After every depth's clear: those reach the bricks through the pointers this resets.
        for t in 1..=depth {
            clear.push((&u.restore, t, over_new(t)));
        }
        self.run_steps(encoder, "octree_update", &bind, args, &clear, timer);
        encoder.copy_buffer_to_buffer(&base.header, 0, &self.nodes, 0, base.header.size());
        let mut steps: Vec<(&wgpu::ComputePipeline, u32, Run)> = vec![
            (&u.begin_update, 0, Run::Prepare),
            (&u.bounds, 0, Run::Indirect(0)),
        ];
        for t in 0..depth {
            steps.extend([
                (&u.flag, t, Run::Indirect(0)),
                (&u.mark, t, Run::One),
                (&u.prepare_depth, t, Run::Prepare),
                (&u.count, t, over_nodes(t)),
                (&u.scan, t, Run::One),
                (&u.allocate, t, over_nodes(t)),
                (&u.finish_update, t, Run::Prepare),
                (&u.init, t + 1, over_new(t + 1)),
            ]);
            if t + 1 < depth {
                steps.push((&u.repair, t + 1, over_new(t + 1)));
            }
        }
        steps.extend([
            (&u.flag, depth, Run::Indirect(0)),
            (&u.prepare_depth, depth, Run::Prepare),
            (&u.count, depth, over_nodes(depth)),
            (&u.scan, depth, Run::One),
            (&u.allocate_slots, depth, over_nodes(depth)),
            (&u.accumulate, depth, Run::Indirect(0)),
            (&u.prepare_static, depth, Run::Prepare),
            (&u.accumulate_static, depth, Run::Indirect(ARGS_STATIC * 4)),
            (&u.prepare_slots, depth, Run::Prepare),
            // Over the box's voxels (prepare_depth's size), not every slot.
            (&u.resolve, depth, over_nodes(depth)),
            (&u.end_update, depth, Run::Prepare),
        ]);
        self.run_steps(encoder, "octree_update", &bind, args, &steps, timer);
    }
}

/// How a step of octree_build is dispatched.
pub(super) enum Run {
    /// One thread that writes dispatch sizes (it binds the arguments buffer).
    Prepare,
    /// One thread.
    One,
    /// Sized by the dispatch arguments at this byte offset.
    Indirect(u64),
}
