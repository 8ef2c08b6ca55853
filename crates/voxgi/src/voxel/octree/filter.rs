//! octree_filter: the levels above the leaves, finest first.

use super::*;

impl OctreeVolume {
    /// Records the filtering of the levels above the leaves, finest first: one dispatch per
    /// depth (octree_filter.wgsl), timed as "octree_filter". Only the nodes flagged since the
    /// last filter, and their ancestors, are redone.
    pub(super) fn filter(&self, encoder: &mut wgpu::CommandEncoder, timer: &mut GpuTimer) {
        let depth = self.depth();
        encoder.clear_buffer(&self.filter_redone, 0, None);
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("octree_filter"),
            timestamp_writes: timer.compute("octree_filter"),
        });
        pass.set_pipeline(&self.pipelines.filter);
        // Depth t's dispatch runs over the nodes of depth t + 1 and writes level depth - 1 - t.
        for t in (0..depth - 1).rev() {
            let level = depth - 1 - t;
            let group = &self.filter[(level & 1) as usize];
            pass.set_bind_group(0, group, &[(t as u64 * LEVEL_STRIDE) as u32]);
            pass.dispatch_workgroups_indirect(&self.args, (6 + 3 * (t as u64 + 1)) * 4);
        }
        // Level D, the whole volume as one voxel, from the root's brick.
        pass.set_pipeline(&self.pipelines.filter_top);
        pass.set_bind_group(0, &self.filter[(depth & 1) as usize], &[0]);
        pass.dispatch_workgroups(1, 1, 1);
    }

    /// Flags every node, so that the next filter redoes the whole tree (what a region filter
    /// must equal).
    pub fn flag_all_for_filter(&self, queue: &wgpu::Queue) {
        let size = self.filter_flags.size();
        let ones = vec![1u32; size.width as usize * size.height as usize];
        queue.write_texture(
            self.filter_flags.as_image_copy(),
            bytemuck::cast_slice(&ones),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(size.width * 4),
                rows_per_image: None,
            },
            size,
        );
    }
}
