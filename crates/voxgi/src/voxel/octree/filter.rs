//! octree_filter: the levels above the leaves, finest first.

use super::*;

impl OctreeVolume {
    /// Records the filtering of every level above the leaves, finest first: one dispatch per
    /// depth (octree_filter.wgsl), timed as "octree_filter".
    pub(super) fn filter(&self, encoder: &mut wgpu::CommandEncoder, timer: &mut GpuTimer) {
        let depth = self.depth();
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
}
