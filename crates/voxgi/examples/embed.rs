//! voxgi inside an application that owns its device: open an adapter and a device, make a
//! texture, render the built-in Cornell box into it, read it back and write `embed.png`.
//! It renders one frame with the default options: the first frame of a temporal history,
//! which is the unjittered single frame (`voxgi render --accumulate 1`). An application that
//! keeps rendering gets the accumulated image from the second frame on.
//!
//! ```sh
//! cargo run --release -p voxgi --example embed -- [WIDTHxHEIGHT] [OUT.png]
//! ```

use voxgi::wgpu;

/// The format the application renders in. An 8-bit texture without an sRGB view gets voxgi's
/// own sRGB curve, the same bits `voxgi render` writes; a swapchain would use
/// `Bgra8UnormSrgb` and the GPU's encoder (equal to within one step of 255).
pub const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// Renders the Cornell box from its own camera at `width` x `height` into a texture of this
/// application's and returns its RGBA8 pixels, row-major from the top-left.
pub fn render_cornell(width: u32, height: u32) -> Result<Vec<u8>, Box<dyn std::error::Error>> {
    // The application's device: any adapter will do; voxgi says what to request from it.
    let instance =
        wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
        power_preference: wgpu::PowerPreference::HighPerformance,
        ..Default::default()
    }))?;
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        label: Some("embed"),
        required_features: voxgi::required_features(&adapter),
        required_limits: voxgi::required_limits(&adapter),
        ..Default::default()
    }))?;

    // The application's texture: voxgi needs RENDER_ATTACHMENT; COPY_SRC is for the readback.
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("embed target"),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: FORMAT,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    let view = texture.create_view(&Default::default());

    let scene = voxgi::scene::builtin::cornell_box();
    let mut renderer =
        voxgi::Renderer::new(&device, &queue, &scene, &voxgi::RendererOptions::default())?;
    let params = voxgi::FrameParams::new(renderer.default_camera().clone());
    let target = voxgi::Target::new(&view, FORMAT, width, height);

    // An application's frame loop. The first frames build the voxels; a build whose pools
    // overflowed is redone in a later frame, so render until the renderer has settled.
    // (This example waits for each frame only because it wants the settled image.)
    let mut settled = false;
    for _ in 0..4 {
        let mut encoder = device.create_command_encoder(&Default::default());
        renderer.render(&mut encoder, &target, &params)?;
        queue.submit([encoder.finish()]);
        device.poll(wgpu::PollType::wait_indefinitely())?;
        if !renderer.receive_feedback()? {
            settled = true;
            break;
        }
    }
    if !settled {
        return Err("the voxels did not settle in four frames".into());
    }

    // Read the texture back (rows padded to wgpu's copy alignment).
    let row = width * 4;
    let padded =
        row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("embed readback"),
        size: (padded * height) as u64,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    encoder.copy_texture_to_buffer(
        texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(padded),
                rows_per_image: Some(height),
            },
        },
        texture.size(),
    );
    queue.submit([encoder.finish()]);
    buffer.slice(..).map_async(wgpu::MapMode::Read, |_| {});
    device.poll(wgpu::PollType::wait_indefinitely())?;
    let data = buffer.slice(..).get_mapped_range()?;
    let mut pixels = Vec::with_capacity((row * height) as usize);
    for y in 0..height as usize {
        let start = y * padded as usize;
        pixels.extend_from_slice(&data[start..start + row as usize]);
    }
    Ok(pixels)
}

#[allow(dead_code)] // The tests include this file for `render_cornell` alone.
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let (width, height) = match args.next() {
        Some(size) => {
            let (w, h) = size.split_once('x').ok_or("size must be WIDTHxHEIGHT")?;
            (w.parse()?, h.parse()?)
        }
        None => (512, 512),
    };
    let out = args.next().unwrap_or_else(|| "embed.png".into());
    let pixels = render_cornell(width, height)?;
    image::save_buffer(
        &out,
        &pixels,
        width,
        height,
        image::ExtendedColorType::Rgba8,
    )?;
    println!("wrote {out} ({width}x{height})");
    Ok(())
}
