//! The pass order: every pass a frame runs, called in one fixed order from here. This is where
//! a reader learns the pipeline (docs/ARCHITECTURE.md draws it):
//!
//! ```text
//! shadow → [moments] → [voxelize (static) → splat (static) → <kind>_build]
//!        → [voxelize (dynamic) → splat (dynamic) → <kind>_update]
//!        → inject → filter → (bounce → filter) × (bounces − 1) → [bounce (records)] → [blend → filter]
//!        → gbuffer → gather → upsample → composite → [debug] → [temporal] → tonemap
//! ```
//!
//! The voxel passes (up to the last `filter` or `bounce`) run only for what changed since the
//! last voxel update (`updates::Pending`), every `voxel_update_interval` frames; a rebuild
//! never waits. With progressive bounces one bounce runs per frame until the light converges.
//! With the fast shading (`IndirectShading::Leaves`) one more bounce keeps every leaf's
//! irradiance and is neither stored nor filtered. With temporal accumulation `blend` moves the
//! light the structure shows towards the update's over a few frames (every frame, whatever
//! the update interval). `debug` runs only for the voxel views and
//! replaces the composite's output; `temporal` (with temporal accumulation on) accumulates it
//! into the history; `tonemap` writes the caller's target. Passes depend on
//! shared resources (the GPU scene, the shadow atlas, the fragments, the structure, the
//! frame's targets), never on each other. Nothing here waits for the GPU.

use super::Renderer;
use super::temporal::FrameHistory;
use crate::Result;
use crate::fragments::Geometry;
use crate::fragments::splat::SplatBind;
use crate::frame::globals::{self, GlobalsSources};
use crate::frame::sequence;
use crate::frame::targets::{FrameTargets, Target};
use crate::frame::uniforms::GpuFrame;
use crate::frame::uniforms::HISTORY_NONE;
use crate::gpu::checked;
use crate::gpu::timer::GpuTimer;
use crate::lighting::atlas::ViewDirt;
use crate::lighting::blend::{GpuBlend, VOXEL_BLEND_FRAMES};
use crate::lighting::bounce::BounceSteps;
use crate::lighting::bounces;
use crate::lighting::inject::InjectPass;
use crate::options::{FrameParams, IndirectShading, ShadowFilter, validate_size};
use crate::view::camera_view_proj;
use crate::voxel::{DebugView, FrameChanges, POOL_COUNTERS, VoxelWork};
use glam::{Mat4, Vec3};

/// What `Renderer::prepare` did, for the frame it prepared.
#[derive(Clone, Copy, Debug)]
pub(super) struct Prepared {
    /// It rebuilt the voxels: the frame starts a new history.
    rebuild: bool,
    /// What the leaves' light did (`record_voxels`), for the frame's blend step.
    relit: Option<bool>,
}

/// A piece of a frame's voxel work recorded ahead (`Renderer::prepare`), to be submitted on
/// its own.
pub struct PreparedStep {
    /// The pass it records (`voxelize`, `build`, `inject`, `filter`, `bounce`, ...): its
    /// timing scope's name.
    pub pass: &'static str,
    /// Its commands, for `Queue::submit`.
    pub commands: wgpu::CommandBuffer,
}

impl Renderer {
    /// Records one frame into `encoder` and writes the tone-mapped image into `target` (its
    /// whole extent). Submit the encoder before the next call: the frame's uniforms are written
    /// through the queue, so two frames in one submission would share the last one's; and a
    /// frame that records the voxel update counts on that encoder being submitted (dropped,
    /// the update is lost until the next `invalidate`).
    ///
    /// The target's texture needs `TextureUsages::RENDER_ATTACHMENT` (nothing else), in a
    /// renderable colour format: `Bgra8UnormSrgb` or `Rgba8UnormSrgb` (a swapchain's; the GPU
    /// encodes sRGB), `Rgba8Unorm` or `Bgra8Unorm` (voxgi applies the sRGB curve), or a float
    /// format such as `Rgba16Float` (tone-mapped linear values). Its previous contents are
    /// overwritten. The first frame in a new format creates that format's pipeline.
    ///
    /// On the first frame (and after `invalidate`, a pool's growth or a voxel option's change)
    /// this also records the voxel update. Nothing here waits for the GPU.
    pub fn render(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        target: &Target,
        params: &FrameParams,
    ) -> Result<()> {
        let (width, height) = (target.width, target.height);
        validate_size(width, height)?;
        self.timer.begin_frame();
        params.validate(self.options.voxel_levels())?;
        self.receive_feedback()?;
        self.passes.tonemap.prepare(&self.device, target.format)?;
        let half = self.options.half_resolution;
        let temporal = self.options.temporal;
        if self.targets.as_ref().is_none_or(|t| {
            t.width != width || t.height != height || t.half != half || {
                t.history.is_some() != temporal
            }
        }) {
            // Out of memory for large sizes is an error here, not the device's handler's.
            self.targets = Some(checked(&self.device, "render targets", || {
                FrameTargets::new(&self.device, width, height, half, temporal)
            })?);
            self.binds = None;
            self.temporal.reset();
        }
        // This frame's voxel work, or some of it, recorded ahead by `prepare`.
        let prepared = self.prepared.take();
        // A new scene or structure: what the history holds is of another.
        if self.pending.rebuild || prepared.is_some_and(|p| p.rebuild) {
            self.temporal.reset();
        }
        // Whether the light or the geometry may differ from the last frame's.
        let changed = self.voxel_work_pending()
            | prepared.is_some()
            | self.scene.advance_motion(&self.queue)
            | self.advance_cloud_motion();
        let view_proj = camera_view_proj(&params.camera, width, height, self.view.0, self.view.1);
        self.drawn_view_proj = view_proj;
        let history = self.temporal.begin(temporal, params, view_proj, changed);
        // Area lights' sample views move to this frame's points on their lights: every frame
        // that accumulates (not the first of a history, which shows PCSS, nor a held one).
        let sampling = self.atlas.samples && history.mode != HISTORY_NONE && !history.hold;
        if sampling {
            self.atlas.move_samples(
                &self.queue,
                &self.scene.gpu_lights,
                sequence::light_points(history.sample),
                self.center,
                self.radius,
            );
        }
        self.record_shadows(encoder, sampling);
        let interval = self.options.voxel_update_interval.max(1) as u64;
        // A rebuild (the first frame among them) never waits for its turn.
        // After `prepare`, only what changed since (its work was this frame's, a progressive
        // bounce included).
        let due = if prepared.is_some() {
            let p = &self.pending;
            p.rebuild || p.geometry || p.lights
        } else {
            self.voxel_work_pending()
                && (self.pending.rebuild || self.frame_index.is_multiple_of(interval))
        };
        let moved = due && (self.pending.rebuild || self.pending.geometry);
        // The structure's per-frame step: it may ask for voxels of its own (a camera-following
        // structure) even when nothing changed.
        let dynamic_now = self.facts.dynamic.then(|| self.state.dynamic_bounds());
        let work = self.volume.plan(&FrameChanges {
            camera: params.camera.position,
            rebuild: due && self.pending.rebuild,
            dynamic: dynamic_now.filter(|_| moved),
            dynamic_now,
            budget: self.options.clipmap_budget,
        });
        let relit = if due || !work.is_empty() {
            self.record_voxels(encoder, work, &mut |_, _| {})
        } else {
            None
        };
        let relit = match (relit, prepared.and_then(|p| p.relit)) {
            (Some(a), Some(b)) => Some(a || b),
            (a, b) => a.or(b),
        };
        self.record_blend(encoder, relit);
        self.frame_index += 1;
        let frame = self.frame_uniforms(params, width, height, view_proj, &history);
        let t = self.targets.as_ref().expect("targets were just created");
        self.queue
            .write_buffer(&t.frame, 0, bytemuck::bytes_of(&frame));
        // Made again only when a resource they bind was replaced (new targets, a new atlas, a
        // pass made anew by `set_options`).
        let p = &self.passes;
        let b = self.binds.get_or_insert_with(|| FrameBinds {
            globals: globals::bind_group(
                &self.device,
                &self.globals_layout,
                &GlobalsSources {
                    frame: &t.frame,
                    cones: &self.cones,
                    lighting: self.atlas.lighting_resources(&self.scene),
                    tables: &self.brdf_tables,
                },
            ),
            gbuffer: p.gbuffer.bind(&self.device, t, &self.scene),
            gather: p.gather.bind(&self.device, t),
            upsample: p.upsample.bind(&self.device, t),
            composite: p.composite.bind(&self.device, t),
            temporal: p.temporal.bind(&self.device, t),
            tonemap: p.tonemap.bind(&self.device, t),
        });
        let globals = &b.globals;
        let timer = &mut self.timer;
        // A converged still: the last accumulated image again, nothing rendered.
        if history.hold {
            let shown = &b.tonemap[1 + self.temporal.written()];
            p.tonemap.record(encoder, globals, target, shown, timer);
            timer.resolve(encoder);
            return Ok(());
        }
        p.gbuffer.record(encoder, t, &self.scene, &b.gbuffer, timer);
        p.gather
            .record(encoder, t, globals, &*self.volume, &b.gather, timer);
        p.upsample.record(encoder, t, globals, &b.upsample, timer);
        p.composite.record(encoder, t, globals, &b.composite, timer);
        // Only for the voxel views: replaces the composite's output.
        if let Some(mode) = params.view.voxel_view() {
            self.volume.record_debug(
                &self.device,
                encoder,
                t,
                DebugView {
                    mode,
                    level: params.debug_level,
                    direction: params.debug_direction,
                },
                timer,
            );
        }
        // The tone-mapped image: the HDR target's, or the history the temporal pass wrote.
        let shown = match &b.temporal {
            Some(pair) => {
                p.temporal
                    .record(encoder, t, globals, &pair[history.read], timer);
                &b.tonemap[2 - history.read]
            }
            None => &b.tonemap[0],
        };
        p.tonemap.record(encoder, globals, target, shown, timer);
        timer.resolve(encoder);
        Ok(())
    }

    /// Records the voxel work the next `render` would record (all of it after the renderer was
    /// made, `invalidate` or a voxel option's change; what changed otherwise), ahead of that
    /// frame and in pieces of one pass each, in order. Submitting each in a submission of its
    /// own, the caller can keep drawing meanwhile (another renderer's frames, a progress
    /// frame): on a CPU driver a new renderer's first frame is otherwise seconds of GPU work
    /// that no frame can come between. Submit every piece, in order, before the next `render`,
    /// which then records none of this work; dropped, the work is lost until the next
    /// `invalidate`. Empty when no voxel work is pending. The pieces are not timed.
    pub fn prepare(&mut self, params: &FrameParams) -> Result<Vec<PreparedStep>> {
        params.validate(self.options.voxel_levels())?;
        self.receive_feedback()?;
        if !self.voxel_work_pending() {
            return Ok(Vec::new());
        }
        let timed = std::mem::replace(&mut self.timer, GpuTimer::disabled(&self.queue));
        let device = self.device.clone();
        let new = || {
            device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("prepare"),
            })
        };
        let mut pieces = Vec::new();
        let mut cut = |encoder: &mut wgpu::CommandEncoder, pass: &'static str| {
            let done = std::mem::replace(encoder, new());
            pieces.push(PreparedStep {
                pass,
                commands: done.finish(),
            });
        };
        let mut encoder = new();
        // The shadow maps injection reads: all of them after a rebuild. Not the area lights'
        // sample views, which only an accumulating frame reads (that frame draws them).
        self.record_shadows(&mut encoder, false);
        cut(&mut encoder, "shadow");
        let moved = self.pending.rebuild || self.pending.geometry;
        let dynamic_now = self.facts.dynamic.then(|| self.state.dynamic_bounds());
        let work = self.volume.plan(&FrameChanges {
            camera: params.camera.position,
            rebuild: self.pending.rebuild,
            dynamic: dynamic_now.filter(|_| moved),
            dynamic_now,
            budget: self.options.clipmap_budget,
        });
        let rebuild = self.pending.rebuild;
        let relit = self.record_voxels(&mut encoder, work, &mut cut);
        self.timer = timed;
        // The blend step and the history's restart belong to the frame (with what an earlier
        // `prepare` for it did).
        let relit = match (relit, self.prepared.and_then(|p| p.relit)) {
            (Some(a), Some(b)) => Some(a || b),
            (a, b) => a.or(b),
        };
        let rebuild = rebuild || self.prepared.is_some_and(|p| p.rebuild);
        self.prepared = Some(Prepared { rebuild, relit });
        Ok(pieces)
    }

    /// Writes the last frame's image into `target` again, tone-mapped as it was, without
    /// rendering a frame: with temporal accumulation another frame would add to the history
    /// and show a different image (a screenshot of what a window shows, say). When there is
    /// no last frame of `target`'s size, renders one with `params`. A redraw is not timed: it
    /// may be recorded into the encoder that holds this frame's timed passes (a window's
    /// frame and its screenshot), where ending the timer's frame before that encoder is
    /// submitted made wgpu refuse the submission ("Query Read Buffer is still mapped").
    pub fn redraw(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        target: &Target,
        params: &FrameParams,
    ) -> Result<()> {
        let same = self
            .targets
            .as_ref()
            .is_some_and(|t| (t.width, t.height) == (target.width, target.height));
        let Some(b) = self.binds.as_ref().filter(|_| same) else {
            return self.render(encoder, target, params);
        };
        self.passes.tonemap.prepare(&self.device, target.format)?;
        let shown = match &b.temporal {
            Some(_) => &b.tonemap[1 + self.temporal.written()],
            None => &b.tonemap[0],
        };
        let mut untimed = GpuTimer::disabled(&self.queue);
        self.passes
            .tonemap
            .record(encoder, &b.globals, target, shown, &mut untimed);
        Ok(())
    }

    /// The frame uniform for a `width` x `height` frame of `p` seen through `unjittered`, with
    /// `history`'s jitter, cone turn and previous view.
    fn frame_uniforms(
        &self,
        p: &FrameParams,
        width: u32,
        height: u32,
        unjittered: Mat4,
        history: &FrameHistory,
    ) -> GpuFrame {
        let [jx, jy] = history.jitter;
        // The jitter moves the image by (jx, jy) pixels: a translation in normalised device
        // coordinates (y up there, down in pixels). None at all for frame 0, so that frame is
        // the unjittered still to the bit.
        let view_proj = if history.jitter == [0.0; 2] {
            unjittered
        } else {
            let ndc = Vec3::new(2.0 * jx / width as f32, -2.0 * jy / height as f32, 0.0);
            Mat4::from_translation(ndc) * unjittered
        };
        GpuFrame {
            view_proj: view_proj.to_cols_array_2d(),
            inv_view_proj: view_proj.inverse().to_cols_array_2d(),
            camera_pos: p.camera.position.to_array(),
            light_count: self.scene.light_count,
            size: [width as f32, height as f32],
            inv_size: [1.0 / width as f32, 1.0 / height as f32],
            exposure: 2f32.powf(p.exposure),
            tonemap: p.tonemap.id(),
            shadow_softness: p.shadow_softness,
            // The debug pass draws the voxel views; composite writes the lit image underneath.
            view_mode: p.view.id(),
            background: [p.background[0], p.background[1], p.background[2], 1.0],
            cone_shadows: self.options.cone_shadows as u32,
            geometry_points: self.scene.geometry_points,
            jitter: history.jitter,
            prev_view_proj: history.prev_view_proj.to_cols_array_2d(),
            view_proj_unjittered: unjittered.to_cols_array_2d(),
            prev_camera_pos: history.prev_camera.to_array(),
            history: history.mode,
            cone_turn: history.cone_turn,
            light_sample: history.sample,
            _pad: 0,
        }
    }

    /// Records the shadow views that must be re-rendered (all after a rebuild), and with
    /// `sampling` the sample views (not otherwise: a frame that does not sample does not read
    /// them).
    fn record_shadows(&mut self, encoder: &mut wgpu::CommandEncoder, sampling: bool) {
        let mut views = std::mem::take(&mut self.pending.views);
        let dirt = if sampling {
            ViewDirt::All
        } else {
            ViewDirt::Clean
        };
        if let Some(samples) = views.get_mut(self.atlas.sample_views()) {
            samples.fill(dirt);
        }
        if views.iter().any(|&v| v != ViewDirt::Clean) {
            let p = &self.passes;
            let vsm = self.options.shadow_filter == ShadowFilter::VsmEsm;
            // Made once per atlas (cleared where the atlas is made anew).
            let b = self.shadow_binds.get_or_insert_with(|| ShadowBinds {
                shadow: p.shadow.bind(&self.device, &self.atlas, &self.scene),
                moments: vsm.then(|| p.moments.bind(&self.device, &self.atlas)),
            });
            p.shadow.record(
                encoder,
                &mut self.atlas,
                &self.scene,
                &views,
                &b.shadow,
                &mut self.timer,
            );
            if let Some(m) = &b.moments {
                p.moments.record(
                    &self.queue,
                    encoder,
                    &self.atlas,
                    &views,
                    m,
                    &mut self.timer,
                );
            }
        }
        self.pending.views = vec![ViewDirt::Clean; self.atlas.views.len()];
    }

    /// Whether the next voxel update has work: something changed, or progressive bounces
    /// have not converged.
    pub(super) fn voxel_work_pending(&self) -> bool {
        let p = &self.pending;
        p.rebuild
            || p.geometry
            || p.lights
            || self.progressive_left > 0
            || self.slices_left > 0
            || self.blend_left > 0
    }

    /// Records what the changes since the last voxel update need, in the fixed order:
    /// voxelize the static geometry and build (after a rebuild), voxelize the dynamic geometry
    /// and update (after it moved), inject, then filter and bounce; with progressive bounces,
    /// one bounce per update until converged.
    ///
    /// `cut` is called after each piece of work (its pass named) that may be submitted on its
    /// own (`prepare`); a frame's recording does nothing there.
    ///
    /// Returns what the leaves' light did: `Some(rebuilt)` when it was computed anew (every
    /// leaf new with `rebuilt`), `None` when it stayed.
    fn record_voxels(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        work: VoxelWork,
        cut: &mut dyn FnMut(&mut wgpu::CommandEncoder, &'static str),
    ) -> Option<bool> {
        let pending = std::mem::take(&mut self.pending);
        let geometry = !work.is_empty();
        // A build replaces every leaf: everything is lit anew, as after a rebuild. Not one of
        // some windows (a camera-following structure's that moved), whose new leaves are
        // what the lighting passes find new.
        let rebuilt = pending.rebuild || (work.build.is_some() && !work.partial);
        self.volume.record_plan(&self.device, encoder);
        // Where the structure's windows are now (`plan` may have moved them). A build done
        // while the renderer was made (`Sizing`) holds the windows of then: moved, it is done
        // again.
        let grids = self.volume.fragment_grids();
        let windows_moved = grids != self.fragments.grids;
        self.fragments.set_grids(&self.queue, &grids);
        // With bounce slices, the updates after a change that gather the slices still due:
        // the direct light is stored again (bounces overwrote it), filtered, and bounced.
        let follow_up = !(geometry || pending.lights) && self.slices_left > 0;
        let relight = geometry || pending.lights || follow_up;
        let relit = relight.then_some(rebuilt);
        self.fragments.set_regions(
            &self.queue,
            work.build.as_deref().unwrap_or_default(),
            work.update.as_deref().unwrap_or_default(),
        );
        if relight {
            self.passes.inject.prepare(
                &self.device,
                &self.queue,
                &self.scene,
                &self.atlas,
                &*self.volume,
                rebuilt || pending.lights,
                // Stored bounces overwrite the radiance: it must start from the direct light
                // again.
                bounces::stored_bounces(&self.options, self.voxel_bounces) > 0,
                pending.moved,
                &pending.inject_views,
                self.atlas.texture.width(),
            );
        }
        let timer = &mut self.timer;
        let p = &self.passes;
        // Made once per fragment buffer (cleared where the fragments are made anew).
        let fb = self.fragment_binds.get_or_insert_with(|| {
            let (device, scene, fragments) = (&self.device, &self.scene, &self.fragments);
            (0..fragments.grids.len())
                .map(|k| FragmentBinds {
                    voxelize_static: p.voxelize.bind(
                        device,
                        scene,
                        &self.static_triangles,
                        fragments,
                        k,
                    ),
                    voxelize_dynamic: p.voxelize.bind(
                        device,
                        scene,
                        &self.dynamic_triangles,
                        fragments,
                        k,
                    ),
                    splat_static: (scene.static_points > 0)
                        .then(|| p.splat.bind(device, scene, fragments, k, Geometry::Static)),
                    splat_dynamic: (scene.geometry_points > scene.static_points)
                        .then(|| p.splat.bind(device, scene, fragments, k, Geometry::Dynamic)),
                })
                .collect()
        });
        if work.build.is_some() && (!pending.built || windows_moved) {
            self.fragments.record_clear(encoder);
            // Each grid's fragments in turn (one for most structures; a clipmap's windows),
            // where the build has a region.
            let regions = work.build.as_deref().unwrap_or_default();
            let built = |k: usize| regions.get(k).is_some_and(|r| !r.is_empty());
            for (k, b) in fb.iter().enumerate().filter(|(k, _)| built(*k)) {
                // The table's entries of the draws near the region only.
                let spans = self.static_triangles.spans(&grids[k], &regions[k]);
                self.fragments
                    .set_spans(&self.queue, k, Geometry::Static, &spans);
                let (table, bind) = (&self.static_triangles, &b.voxelize_static);
                p.voxelize.record(encoder, table, &spans, bind, timer);
                p.splat.record(encoder, b.splat_static.as_ref(), timer);
            }
            self.fragments.record_mark(encoder);
            cut(encoder, "voxelize");
            self.volume
                .record_build(&self.device, encoder, &self.fragments, timer);
            cut(encoder, "build");
        }
        if work.update.is_some() {
            self.fragments.record_truncate(encoder);
            let spans = [self.dynamic_triangles.whole()];
            for (k, b) in fb.iter().enumerate() {
                self.fragments
                    .set_spans(&self.queue, k, Geometry::Dynamic, &spans);
                let (table, bind) = (&self.dynamic_triangles, &b.voxelize_dynamic);
                p.voxelize.record(encoder, table, &spans, bind, timer);
                p.splat.record(encoder, b.splat_dynamic.as_ref(), timer);
            }
            self.volume
                .record_update(&self.device, encoder, &self.fragments, timer);
            cut(encoder, "update");
        }
        if geometry {
            // The kernels never write past their buffers, they only count: the counts come
            // back a frame or more later and grow the pools then (`receive_feedback`).
            if !self.counters.request(
                &self.device,
                encoder,
                &[
                    (&self.fragments.count, 1),
                    (self.volume.pool_counter(), POOL_COUNTERS),
                ],
                self.pools,
            ) {
                log::warn!(
                    "voxel counters: too many readbacks in flight; is the encoder submitted?"
                );
            }
        }
        let progressive = self.options.progressive;
        let slices = self.options.bounce_slices.max(1);
        // Made once per structure, set of passes and options (cleared where any is made anew).
        // Progressive bounces keep one irradiance per leaf: each builds on the last.
        let levels = if progressive { 1 } else { self.voxel_bounces };
        let bounce_globals = self.bounce_globals.get_or_insert_with(|| {
            p.bounce
                .bind(&self.device, &*self.volume, &self.cones, slices, levels)
        });
        // This update's bounces gather at one slice of the leaves (all of them after a rebuild:
        // the slots hold other leaves).
        let bounces_run = if progressive {
            self.progressive_left > 0 || relight
        } else {
            relight && self.voxel_bounces > 0
        };
        if bounces_run {
            // Leaves near moved geometry gather at once, whatever their turn.
            let tan = self.options.cones.half_angle_tan();
            let near = pending
                .moved
                .map(|m| crate::lighting::bounce::near_change(m, tan));
            // Leaves whose irradiance the pixels read cannot start from another's light.
            let carry = !bounces::leaves(&self.options);
            // A build of some windows: their new leaves may lie where leaves lay before.
            let kept = work.partial && work.build.is_some();
            bounce_globals.prepare(&self.queue, self.bounce_turn, rebuilt, near, carry, kept);
            self.bounce_turn = self.bounce_turn.wrapping_add(1);
        }
        let bounce_globals = &*bounce_globals;
        // One bounce (the update's `i`th), and the filtering its stored light needs.
        let bounce =
            |encoder: &mut wgpu::CommandEncoder,
             timer: &mut GpuTimer,
             i: u32,
             steps: BounceSteps,
             cut: &mut dyn FnMut(&mut wgpu::CommandEncoder, &'static str)| {
                let volume = &*self.volume;
                p.bounce
                    .record(encoder, volume, bounce_globals, i, steps, timer);
                cut(encoder, "bounce");
                if steps.store {
                    volume.record_filter(encoder, timer);
                    cut(encoder, "filter");
                }
            };
        if relight {
            let inject = if progressive {
                InjectPass::record_direct_only
            } else {
                InjectPass::record
            };
            inject(&p.inject, encoder, &*self.volume, timer);
            cut(encoder, "inject");
            if progressive {
                // One bounce per update from the previous update's light; after a change
                // this many updates make every leaf's light converge again (the first from
                // a cleared volume only reproduces the direct light), each slice of leaves
                // gathering once in `slices` updates.
                self.progressive_left = (self.voxel_bounces + 1) * slices;
            } else {
                self.volume.record_filter(encoder, timer);
                cut(encoder, "filter");
                let n = self.voxel_bounces;
                for i in 0..n {
                    // With leaves the last bounce's light is what the pixels read: it keeps
                    // the irradiance and need not be stored or filtered (the glossy cones
                    // then see the same light as with cones).
                    let last = bounces::leaves(&self.options) && i + 1 == n;
                    let steps = BounceSteps {
                        irradiance: last,
                        store: !last,
                    };
                    bounce(encoder, timer, i, steps, cut);
                }
                // After a change, every leaf gathers its first bounce within `slices` updates,
                // its second within the `slices` after those (from first bounces all made
                // after the change), and so on: then the light equals a full update's.
                self.slices_left = if follow_up {
                    self.slices_left - 1
                } else if slices > 1 && n > 0 {
                    n * slices - 1
                } else {
                    0
                };
            }
        }
        if progressive && self.progressive_left > 0 {
            // Every step is stored (the next builds on it) and, with leaves, keeps the records
            // too, so pixels follow the light as it converges. Its bundles are then turned by
            // the records' layout and it traces occlusion at every step; the converged light
            // is the same as without (the last bounces add less than 0.1 %), not bit for bit.
            let steps = BounceSteps {
                irradiance: bounces::leaves(&self.options),
                store: true,
            };
            bounce(encoder, timer, 0, steps, cut);
            self.progressive_left -= 1;
        }
        // The shadow views were consumed by `record_shadows` this frame; injection's start over.
        self.pending.views = pending.views;
        self.pending.inject_views = vec![ViewDirt::Clean; self.atlas.views.len()];
        relit
    }

    /// Records a step of `blend` (and the filter after it) when the leaves' light changed
    /// this frame (`relit`, from `record_voxels`) or is still moving towards the last change.
    /// Only with temporal accumulation and the per-pixel cones from stored bounces (progressive
    /// bounces converge over frames already; the fast shading's last bounce is not stored);
    /// turned off mid-way, one last step lands on the light.
    fn record_blend(&mut self, encoder: &mut wgpu::CommandEncoder, relit: Option<bool>) {
        let o = &self.options;
        let on = o.temporal && !o.progressive && o.indirect == IndirectShading::Cones;
        if !on && self.blend_left == 0 {
            // What the structure shows is the update's light: the next blend starts afresh.
            self.blend = None;
            return;
        }
        if relit.is_some() {
            self.blend_left = if on { VOXEL_BLEND_FRAMES } else { 1 };
        } else if !on {
            self.blend_left = 1;
        }
        if self.blend_left == 0 {
            return;
        }
        // Shown light made now (or dropped by `set_options`, or of a structure that grew)
        // holds nothing to blend from: this step shows the update's light.
        let capacity = self.volume.leaf_capacity().max(1);
        let fresh = self.blend.as_ref().is_none_or(|b| b.capacity != capacity);
        if fresh {
            self.blend = Some(self.passes.blend.state(&self.device, &*self.volume));
        }
        let restart = fresh || relit == Some(true);
        let step = GpuBlend {
            weight: if restart {
                1.0
            } else {
                1.0 / self.blend_left as f32
            },
            restart: restart as u32,
            from_bounce: (bounces::stored_bounces(o, self.voxel_bounces) > 0) as u32,
            // This frame's voxel update wrote the structure: all of it is shown anew.
            store_all: relit.is_some() as u32,
        };
        let state = self.blend.as_ref().expect("made above");
        self.passes.blend.record(
            &self.queue,
            encoder,
            &*self.volume,
            state,
            step,
            &mut self.timer,
        );
        self.volume.record_filter(encoder, &mut self.timer);
        self.blend_left = if restart { 0 } else { self.blend_left - 1 };
    }
}

/// The bind groups of the screen passes that stay the same from frame to frame: made on the
/// first frame after the targets, the shadow atlas or a screen pass were made anew.
pub(super) struct FrameBinds {
    globals: wgpu::BindGroup,
    gbuffer: wgpu::BindGroup,
    gather: wgpu::BindGroup,
    upsample: wgpu::BindGroup,
    composite: wgpu::BindGroup,
    /// With temporal accumulation: `[i]` reads history `i` and writes the other.
    temporal: Option<[wgpu::BindGroup; 2]>,
    /// Reading the HDR target, then each history.
    tonemap: Vec<wgpu::BindGroup>,
}

/// The bind groups of the passes that make fragments on one of the fragments' grids: made on
/// the first voxel update after the fragment buffer was made anew.
pub(super) struct FragmentBinds {
    voxelize_static: wgpu::BindGroup,
    voxelize_dynamic: wgpu::BindGroup,
    /// The static and the dynamic geometry points' (None without such points: the pass
    /// then records an empty scope).
    splat_static: Option<SplatBind>,
    splat_dynamic: Option<SplatBind>,
}

/// The shadow pass's bind groups and the moments pass's (with VSM/ESM): made on the first
/// shadow render after the atlas was made anew.
pub(super) struct ShadowBinds {
    shadow: crate::lighting::shadow::ShadowBind,
    moments: Option<crate::lighting::moments::MomentsBind>,
}
