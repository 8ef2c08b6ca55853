//! The structure seam: a kind declared outside the library, registered by its `KindInfo`
//! alone, renders through every pass; its per-frame step sees every frame's camera.

use crate::common::{clamped, ctx, frame, renderer};
use std::any::Any;
use std::sync::Mutex;
use voxgi::fragments::Fragments;
use voxgi::frame::targets::FrameTargets;
use voxgi::gpu::timer::GpuTimer;
use voxgi::scene::builtin;
use voxgi::scene::glam::Vec3;
use voxgi::voxel::dense::{self, DenseVolume};
use voxgi::voxel::{
    DebugView, FrameChanges, Grid, KindInfo, POOL_COUNTERS, StructureBindings, StructureDesc,
    VoxelKind, VoxelStructure, VoxelWork,
};
use voxgi::{RendererOptions, Result};

/// A third kind: the dense volume behind a wrapper of the test's own, with a per-frame step
/// that records what it was shown. Its WGSL and layouts are the dense volume's; its name,
/// creation and Rust type are its own.
static STAND_IN: KindInfo = KindInfo {
    name: "stand-in",
    summary: "the dense volume, wrapped by a test",
    max_resolution: 64,
    build_passes: dense::KIND.build_passes,
    filter_passes: dense::KIND.filter_passes,
    shaders: dense::KIND.shaders,
    sampling_layout: dense::KIND.sampling_layout,
    leaves_layout: dense::KIND.leaves_layout,
    leaf_store_layout: dense::KIND.leaf_store_layout,
    irradiance_layout: dense::KIND.irradiance_layout,
    carry_layout: dense::KIND.carry_layout,
    sampling_constants: dense::KIND.sampling_constants,
    create: stand_in,
};

/// What the stand-in's per-frame step was shown, frame by frame: the camera, whether the
/// frame rebuilt, whether it asked for a build. One test uses it.
static SEEN: Mutex<Vec<(Vec3, bool, bool)>> = Mutex::new(Vec::new());

struct StandIn {
    inner: Box<dyn VoxelStructure>,
}

fn stand_in(
    device: &voxgi::wgpu::Device,
    desc: &StructureDesc,
    previous: Option<&dyn VoxelStructure>,
) -> Result<Box<dyn VoxelStructure>> {
    let previous = previous
        .and_then(|p| p.as_any().downcast_ref::<StandIn>())
        .map(|p| p.inner.as_ref());
    Ok(Box::new(StandIn {
        inner: (dense::KIND.create)(device, desc, previous)?,
    }))
}

impl VoxelStructure for StandIn {
    fn plan(&mut self, changes: &FrameChanges) -> VoxelWork {
        let work = self.inner.plan(changes);
        SEEN.lock()
            .unwrap()
            .push((changes.camera, changes.rebuild, work.build.is_some()));
        work
    }
    fn kind(&self) -> VoxelKind {
        VoxelKind::new(&STAND_IN)
    }
    fn as_any(&self) -> &dyn Any {
        self
    }
    fn grid(&self) -> Grid {
        self.inner.grid()
    }
    fn record_build(
        &self,
        d: &voxgi::wgpu::Device,
        e: &mut voxgi::wgpu::CommandEncoder,
        f: &Fragments,
        t: &mut GpuTimer,
    ) {
        self.inner.record_build(d, e, f, t)
    }
    fn record_update(
        &self,
        d: &voxgi::wgpu::Device,
        e: &mut voxgi::wgpu::CommandEncoder,
        f: &Fragments,
        t: &mut GpuTimer,
    ) {
        self.inner.record_update(d, e, f, t)
    }
    fn bind_fragments(&mut self, d: &voxgi::wgpu::Device, f: &Fragments) {
        self.inner.bind_fragments(d, f)
    }
    fn record_filter(&self, e: &mut voxgi::wgpu::CommandEncoder, t: &mut GpuTimer) {
        self.inner.record_filter(e, t)
    }
    fn pool_counter(&self) -> &voxgi::wgpu::Buffer {
        self.inner.pool_counter()
    }
    fn leaf_capacity(&self) -> u64 {
        self.inner.leaf_capacity()
    }
    fn leaf_limit(&self, d: &voxgi::wgpu::Device) -> u64 {
        self.inner.leaf_limit(d)
    }
    fn needs_growth(&self, counted: &[u32; POOL_COUNTERS]) -> bool {
        self.inner.needs_growth(counted)
    }
    fn grow(&mut self, d: &voxgi::wgpu::Device, counted: &[u32; POOL_COUNTERS]) -> Result<()> {
        self.inner.grow(d, counted)
    }
    fn memory(&self) -> Vec<(&'static str, u64)> {
        self.inner.memory()
    }
    fn bindings(&self) -> StructureBindings<'_> {
        self.inner.bindings()
    }
    fn record_debug(
        &self,
        d: &voxgi::wgpu::Device,
        e: &mut voxgi::wgpu::CommandEncoder,
        targets: &FrameTargets,
        view: DebugView,
        t: &mut GpuTimer,
    ) {
        self.inner.record_debug(d, e, targets, view, t)
    }
}

#[test]
fn a_kind_outside_the_registry_renders_as_the_structure_it_wraps() {
    let _ = ctx();
    let scene = builtin::cornell_box();
    let options = |voxels| RendererOptions {
        voxels,
        voxel_resolution: 32,
        ..RendererOptions::default()
    };
    let mut dense = renderer(&scene, &options(VoxelKind::DENSE));
    let mut stand_in = renderer(&scene, &options(VoxelKind::new(&STAND_IN)));
    assert_eq!(stand_in.volume().kind().name(), "stand-in");
    assert!(stand_in.structure::<StandIn>().is_some());
    assert!(stand_in.structure::<DenseVolume>().is_none());
    SEEN.lock().unwrap().clear();
    let mut params = clamped(dense.default_camera());
    let mut cameras = Vec::new();
    for k in 0..3 {
        params.camera.position += Vec3::new(0.01 * k as f32, 0.0, 0.0);
        cameras.push(params.camera.position);
        let want = frame(&mut dense, &params, 48, 48);
        let got = frame(&mut stand_in, &params, 48, 48);
        // The same passes over the same voxels: the same image, to the bit.
        assert_eq!(got.hdr, want.hdr, "frame {k}");
    }
    let seen = SEEN.lock().unwrap().clone();
    // A step every frame, with the frame's camera. The first frame builds, and so does one
    // after the first build's counters grew the pools (`headless::render` renders until they
    // are back); the default step builds exactly when the renderer rebuilds.
    assert!(seen.len() >= 3, "{seen:?}");
    assert!(seen[0].1, "{seen:?}");
    assert!(seen.iter().all(|s| s.1 == s.2), "{seen:?}");
    for c in cameras {
        assert!(
            seen.iter().any(|s| s.0 == c),
            "no step saw the camera at {c}"
        );
    }
    // Settings know only the registry.
    assert!(VoxelKind::parse("stand-in").is_err());
    let bad = RendererOptions {
        voxel_resolution: 128,
        ..options(VoxelKind::new(&STAND_IN))
    };
    let e = bad.validate().unwrap_err().to_string();
    assert!(e.contains("16..=64") && e.contains("stand-in"), "{e}");
}
