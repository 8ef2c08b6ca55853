//! Copying textures back to the CPU.

use crate::{Error, Result};

/// Reads a whole 2D texture (mip 0, layer 0) into tightly packed bytes.
pub fn read_texture(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
) -> Result<Vec<u8>> {
    let (w, h) = (texture.width(), texture.height());
    let bpp = texture
        .format()
        .block_copy_size(None)
        .ok_or_else(|| Error::Gpu {
            context: "readback".into(),
            reason: format!("cannot read back format {:?}", texture.format()),
        })?;
    let row = w * bpp;
    let padded =
        row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: (padded * h) as u64,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut enc = device.create_command_encoder(&Default::default());
    enc.copy_texture_to_buffer(
        texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(padded),
                rows_per_image: Some(h),
            },
        },
        wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        },
    );
    queue.submit([enc.finish()]);
    read_buffer(device, &buffer).map(|bytes| {
        let mut out = Vec::with_capacity((row * h) as usize);
        for y in 0..h as usize {
            let start = y * padded as usize;
            out.extend_from_slice(&bytes[start..start + row as usize]);
        }
        out
    })
}

/// Reads one mip level of a 3D texture, or of every layer of a 2D array texture, into tightly
/// packed bytes (x fastest, then y, then z or the layer).
pub fn read_texture_3d(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    mip: u32,
) -> Result<Vec<u8>> {
    let fail = |reason: String| Error::Gpu {
        context: "readback".into(),
        reason,
    };
    if texture.dimension() == wgpu::TextureDimension::D1 || mip >= texture.mip_level_count() {
        return Err(fail(format!(
            "mip {mip} of a {:?} texture with {} levels",
            texture.dimension(),
            texture.mip_level_count()
        )));
    }
    let size = texture.size().mip_level_size(mip, texture.dimension());
    let (w, h, d) = (size.width, size.height, size.depth_or_array_layers);
    let bpp = texture
        .format()
        .block_copy_size(None)
        .ok_or_else(|| fail(format!("cannot read back format {:?}", texture.format())))?;
    let row = w * bpp;
    let padded =
        row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback 3d"),
        size: (padded * h * d) as u64,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut enc = device.create_command_encoder(&Default::default());
    enc.copy_texture_to_buffer(
        wgpu::TexelCopyTextureInfo {
            texture,
            mip_level: mip,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(padded),
                rows_per_image: Some(h),
            },
        },
        size,
    );
    queue.submit([enc.finish()]);
    read_buffer(device, &buffer).map(|bytes| {
        let mut out = Vec::with_capacity((row * h * d) as usize);
        for y in 0..(h * d) as usize {
            let start = y * padded as usize;
            out.extend_from_slice(&bytes[start..start + row as usize]);
        }
        out
    })
}

/// Reads a whole buffer (which needs COPY_SRC) into bytes.
pub fn read_buffer_copy(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    source: &wgpu::Buffer,
) -> Result<Vec<u8>> {
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback buffer"),
        size: source.size(),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut enc = device.create_command_encoder(&Default::default());
    enc.copy_buffer_to_buffer(source, 0, &buffer, 0, source.size());
    queue.submit([enc.finish()]);
    read_buffer(device, &buffer)
}

/// An IEEE binary16 value (as read back from an rgba16float texture) as f32.
pub fn f16_to_f32(h: u16) -> f32 {
    half::f16::from_bits(h).to_f32()
}

/// Maps a MAP_READ buffer and copies its contents out, waiting for the GPU.
pub fn read_buffer(device: &wgpu::Device, buffer: &wgpu::Buffer) -> Result<Vec<u8>> {
    let (tx, rx) = std::sync::mpsc::channel();
    buffer.map_async(wgpu::MapMode::Read, .., move |r| {
        let _ = tx.send(r);
    });
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| Error::Gpu {
            context: "readback".into(),
            reason: e.to_string(),
        })?;
    let mapped = rx.recv().map_err(|e| Error::Gpu {
        context: "readback".into(),
        reason: e.to_string(),
    })?;
    mapped.map_err(|e| Error::Gpu {
        context: "readback".into(),
        reason: e.to_string(),
    })?;
    let data = buffer
        .get_mapped_range(..)
        .map_err(|e| Error::Gpu {
            context: "readback".into(),
            reason: e.to_string(),
        })?
        .to_vec();
    buffer.unmap();
    Ok(data)
}
