//! What a frame keeps for the next (DESIGN.md, seam 9): the accumulated HDR image and the
//! geometry it was accumulated on, twice over. Each frame the temporal pass reads one pair and
//! writes the other; the renderer flips which is which.

use super::formats::{HISTORY_FORMAT, HISTORY_GEOMETRY_FORMAT};

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
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d {
                    width,
                    height,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage: wgpu::TextureUsages::STORAGE_BINDING
                    | wgpu::TextureUsages::TEXTURE_BINDING
                    | wgpu::TextureUsages::COPY_SRC,
                view_formats: &[],
            })
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
