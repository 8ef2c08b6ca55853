//! Counters read back without waiting: the GPU's count is copied into a small mappable buffer
//! in the same encoder as the work that wrote it, the buffer is mapped when that encoder is
//! submitted, and the values are picked up by a later frame once the map has completed. No
//! frame ever blocks on it.

use std::sync::Arc;
use std::sync::atomic::{AtomicU8, Ordering};

const IDLE: u8 = 0;
const IN_FLIGHT: u8 = 1;
const READY: u8 = 2;
const FAILED: u8 = 3;

/// More requests than this in flight means the caller is not submitting what voxgi records
/// (or the GPU is many frames behind); further requests are dropped until some complete.
const MAX_IN_FLIGHT: usize = 8;

struct Slot {
    buffer: wgpu::Buffer,
    state: Arc<AtomicU8>,
    /// The caller's tag for what was read (which pools), returned with the values.
    tag: u64,
}

/// A pool of readback buffers for `count` counter words, taken from the start of a few buffers.
pub struct CounterReadback {
    label: &'static str,
    count: usize,
    slots: Vec<Slot>,
}

impl CounterReadback {
    /// An empty pool for `count` counters; buffers (labelled `label`) are made as requests need
    /// them.
    pub fn new(label: &'static str, count: usize) -> Self {
        CounterReadback {
            label,
            count,
            slots: Vec::new(),
        }
    }

    /// Records a copy of the first `words` u32 of each of `sources` (`count` words in all) and
    /// the map on submission; `tag` comes back with the values, in order. Returns false when
    /// too many reads are still in flight (nothing is recorded).
    pub fn request(
        &mut self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        sources: &[(&wgpu::Buffer, usize)],
        tag: u64,
    ) -> bool {
        debug_assert_eq!(sources.iter().map(|s| s.1).sum::<usize>(), self.count);
        let i = match self
            .slots
            .iter()
            .position(|s| s.state.load(Ordering::Acquire) == IDLE)
        {
            Some(i) => i,
            None if self.slots.len() < MAX_IN_FLIGHT => {
                self.slots.push(Slot {
                    buffer: device.create_buffer(&wgpu::BufferDescriptor {
                        label: Some(self.label),
                        size: 4 * self.count as u64,
                        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                        mapped_at_creation: false,
                    }),
                    state: Arc::new(AtomicU8::new(IDLE)),
                    tag: 0,
                });
                self.slots.len() - 1
            }
            None => return false,
        };
        let slot = &mut self.slots[i];
        slot.tag = tag;
        slot.state.store(IN_FLIGHT, Ordering::Release);
        let mut at = 0;
        for (src, words) in sources {
            encoder.copy_buffer_to_buffer(src, 0, &slot.buffer, at, 4 * *words as u64);
            at += 4 * *words as u64;
        }
        let state = slot.state.clone();
        encoder.map_buffer_on_submit(&slot.buffer, wgpu::MapMode::Read, .., move |r| {
            state.store(if r.is_ok() { READY } else { FAILED }, Ordering::Release);
        });
        true
    }

    /// Whether some read has not been taken yet (in flight, or completed and waiting for
    /// `take_ready`).
    pub fn pending(&self) -> bool {
        self.slots.iter().any(|s| {
            let state = s.state.load(Ordering::Acquire);
            state == IN_FLIGHT || state == READY
        })
    }

    /// Whether some read has been submitted but its map has not completed yet.
    pub fn in_flight(&self) -> bool {
        self.slots
            .iter()
            .any(|s| s.state.load(Ordering::Acquire) == IN_FLIGHT)
    }

    /// Every read completed since the last call, as (tag, u32 words). Call after a
    /// non-blocking `Device::poll` so that completed maps have run their callbacks.
    pub fn take_ready(&mut self) -> Vec<(u64, Vec<u32>)> {
        let mut out = Vec::new();
        for s in &self.slots {
            match s.state.load(Ordering::Acquire) {
                READY => {
                    if let Ok(view) = s.buffer.slice(..).get_mapped_range() {
                        out.push((s.tag, bytemuck::cast_slice(&view).to_vec()));
                    }
                    s.buffer.unmap();
                    s.state.store(IDLE, Ordering::Release);
                }
                FAILED => s.state.store(IDLE, Ordering::Release),
                _ => {}
            }
        }
        out
    }
}
