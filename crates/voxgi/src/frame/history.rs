//! What a frame keeps for the next (DESIGN.md, seam 9): the accumulated HDR image and the
//! geometry it was accumulated on, twice over. Each frame the temporal pass reads one pair and
//! writes the other; the renderer flips which is which.

use super::formats::{HISTORY_FORMAT, HISTORY_GEOMETRY_FORMAT, STORAGE_TARGET, texture_2d};

/// The history's two pairs of textures, at the output size.
pub struct History {
    /// Accumulated radiance and its frame count (`HISTORY_FORMAT`), the pass's output too:
    /// `tonemap` reads the one written last.
    pub color: [wgpu::Texture; 2],
    /// Views of `color`.
    pub color_views: [wgpu::TextureView; 2],
    /// Normal and camera distance of the pixels `color` was accumulated on
    /// (`HISTORY_GEOMETRY_FORMAT`).
    pub geometry: [wgpu::TextureView; 2],
}

impl History {
    /// Bytes per pixel of both pairs.
    pub const BYTES_PER_PIXEL: u64 = 2 * (16 + 8);

    /// Textures for a `width` x `height` output.
    pub fn new(device: &wgpu::Device, width: u32, height: u32) -> Self {
        let make = |label: &str, format| {
            texture_2d(device, label, format, STORAGE_TARGET, (width, height))
        };
        let color = [
            make("history 0", HISTORY_FORMAT),
            make("history 1", HISTORY_FORMAT),
        ];
        let view = |t: &wgpu::Texture| t.create_view(&Default::default());
        History {
            color_views: [view(&color[0]), view(&color[1])],
            geometry: [
                view(&make("history geometry 0", HISTORY_GEOMETRY_FORMAT)),
                view(&make("history geometry 1", HISTORY_GEOMETRY_FORMAT)),
            ],
            color,
        }
    }
}
