//! GPU timestamps per pass, for `voxgi bench`. Each pass asks for a scope by its name when it
//! begins; scopes of the same name in a frame (one shadow pass per view, one filter pass per
//! mip level) add up. Without timestamp support every request returns `None` and costs nothing.

use crate::{Error, Result};

const MAX_SCOPES: u32 = 512;

/// Timestamp queries for up to 512 pass scopes a frame, resolved into a buffer and read back
/// after submission. Inert (all `None`) when disabled or when the device lacks `TIMESTAMP_QUERY`.
pub struct GpuTimer {
    query_set: Option<wgpu::QuerySet>,
    resolve: Option<wgpu::Buffer>,
    readback: Option<wgpu::Buffer>,
    labels: Vec<&'static str>,
    period_ns: f32,
}

impl GpuTimer {
    /// A timer that records only if `enabled` and the device supports timestamps.
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue, enabled: bool) -> Self {
        let on = enabled && device.features().contains(wgpu::Features::TIMESTAMP_QUERY);
        let size = MAX_SCOPES as u64 * 2 * 8;
        GpuTimer {
            query_set: on.then(|| {
                device.create_query_set(&wgpu::QuerySetDescriptor {
                    label: Some("pass timestamps"),
                    ty: wgpu::QueryType::Timestamp,
                    count: MAX_SCOPES * 2,
                })
            }),
            resolve: on.then(|| {
                device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("timestamp resolve"),
                    size,
                    usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                    mapped_at_creation: false,
                })
            }),
            readback: on.then(|| {
                device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("timestamp readback"),
                    size,
                    usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                    mapped_at_creation: false,
                })
            }),
            labels: Vec::new(),
            period_ns: queue.get_timestamp_period(),
        }
    }

    /// A timer that never records.
    pub fn disabled(queue: &wgpu::Queue) -> Self {
        GpuTimer {
            query_set: None,
            resolve: None,
            readback: None,
            labels: Vec::new(),
            period_ns: queue.get_timestamp_period(),
        }
    }

    fn next(&mut self, label: &'static str) -> Option<(&wgpu::QuerySet, u32)> {
        let qs = self.query_set.as_ref()?;
        if self.labels.len() as u32 >= MAX_SCOPES {
            return None;
        }
        let i = self.labels.len() as u32;
        self.labels.push(label);
        Some((qs, i * 2))
    }

    /// Timestamp writes for a compute pass named `label`, or `None` when the timer is off or the
    /// frame's scopes are used up.
    pub fn compute(&mut self, label: &'static str) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        self.next(label)
            .map(|(query_set, i)| wgpu::ComputePassTimestampWrites {
                query_set,
                beginning_of_pass_write_index: Some(i),
                end_of_pass_write_index: Some(i + 1),
            })
    }

    /// Timestamp writes for a render pass named `label`, or `None` when the timer is off or the
    /// frame's scopes are used up.
    pub fn render(&mut self, label: &'static str) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        self.next(label)
            .map(|(query_set, i)| wgpu::RenderPassTimestampWrites {
                query_set,
                beginning_of_pass_write_index: Some(i),
                end_of_pass_write_index: Some(i + 1),
            })
    }

    /// Records the resolve of this frame's timestamps; call once after the last pass.
    pub fn resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        let (Some(qs), Some(resolve), Some(readback)) =
            (&self.query_set, &self.resolve, &self.readback)
        else {
            return;
        };
        let n = self.labels.len() as u32 * 2;
        if n == 0 {
            return;
        }
        encoder.resolve_query_set(qs, 0..n, resolve, 0);
        encoder.copy_buffer_to_buffer(resolve, 0, readback, 0, n as u64 * 8);
    }

    /// Milliseconds per pass name, in first-use order, after the frame was submitted; clears
    /// the scopes for the next frame.
    pub fn read(&mut self, device: &wgpu::Device) -> Result<Vec<(&'static str, f64)>> {
        let labels = std::mem::take(&mut self.labels);
        let Some(readback) = &self.readback else {
            return Ok(Vec::new());
        };
        if labels.is_empty() {
            return Ok(Vec::new());
        }
        let bytes = crate::gpu::readback::read_buffer(device, readback)?;
        let ticks: &[u64] = bytemuck::cast_slice(&bytes[..labels.len() * 16]);
        let mut out: Vec<(&'static str, f64)> = Vec::new();
        for (i, label) in labels.iter().enumerate() {
            let (a, b) = (ticks[2 * i], ticks[2 * i + 1]);
            let ms = b.saturating_sub(a) as f64 * self.period_ns as f64 * 1e-6;
            match out.iter_mut().find(|(l, _)| l == label) {
                Some(e) => e.1 += ms,
                None => out.push((label, ms)),
            }
        }
        if out.iter().any(|(_, ms)| !ms.is_finite()) {
            return Err(Error::Gpu {
                context: "timestamps".into(),
                reason: "non-finite pass time".into(),
            });
        }
        Ok(out)
    }
}
