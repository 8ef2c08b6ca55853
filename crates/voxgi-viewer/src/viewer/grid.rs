//! The ground grid (`grid.wgsl`): lines on the plane under the scene, drawn over the cone-traced
//! view and hidden behind the scene by the renderer's depth (`Renderer::depth`).

use super::Viewer;
use bytemuck::{Pod, Zeroable};
use glam::Mat4;
use voxgi::wgpu;

/// The grid's uniforms, as `Grid` in `grid.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct GpuGrid {
    view_proj: [[f32; 4]; 4],
    inv_view_proj: [[f32; 4]; 4],
    /// The plane's height, the minor spacing, the distance the grid fades out by, unused.
    plane: [f32; 4],
    /// The target's size in pixels, and the depth's size over it.
    size: [f32; 4],
}

/// Metres between the grid's lines seen from `above` metres over it, in a scene of `radius`: the
/// power of ten at most that height (0.1 m from the Cornell box's camera, 1 m from a person's
/// eye in Sponza, 10 m from high over it), every tenth line stronger.
pub(super) fn spacing(above: f32, radius: f32) -> f32 {
    10f32.powf(above.abs().max(radius * 1e-3).max(1e-6).log10().floor())
}

/// Height bins of the floor search, metres.
const FLOOR_BIN: f32 = 0.05;

/// The grid's height: the scene's floor, the lowest upward-facing level that holds a tenth of
/// the scene's upward-facing area (its top, with what is up to 10 cm higher, so the grid lies on
/// it, not under it); the lowest
/// point of a scene without one (a point cloud, a single object). Emitters and what may move
/// (dynamic instances) do not count.
pub(super) fn height(scene: &voxgi::scene::Scene) -> f32 {
    // Per 5 cm bin: the area, and the highest vertex of its triangles.
    let mut bins: std::collections::BTreeMap<i64, (f32, f32)> = Default::default();
    let mut total = 0.0;
    for inst in &scene.instances {
        if inst.light.is_some() || inst.dynamic {
            continue;
        }
        let mesh = &scene.meshes[inst.mesh];
        let p: Vec<glam::Vec3> = mesh
            .positions
            .iter()
            .map(|&v| inst.transform.transform_point3(v))
            .collect();
        for t in mesh.indices.chunks_exact(3) {
            let [a, b, c] = [0, 1, 2].map(|k| p[t[k] as usize]);
            let n = (b - a).cross(c - a);
            let area = 0.5 * n.length();
            if area.is_nan() || area <= 0.0 || n.y < 0.95 * n.length() {
                continue;
            }
            total += area;
            let y = (a.y + b.y + c.y) / 3.0;
            let top = a.y.max(b.y).max(c.y);
            let bin = bins
                .entry((y / FLOOR_BIN).floor() as i64)
                .or_insert((0.0, f32::MIN));
            bin.0 += area;
            bin.1 = bin.1.max(top);
        }
    }
    if let Some((&k, _)) = bins.iter().find(|(_, (a, _))| *a >= 0.1 * total) {
        // Its top, over the next two bins too: Sponza's floor is 9 to 13 cm up, and a grid at
        // 10 cm was hidden wherever the floor rose above it.
        return (k..=k + 2)
            .filter_map(|b| bins.get(&b))
            .map(|(_, top)| *top)
            .fold(f32::MIN, f32::max);
    }
    let bounds = scene.swept_bounds();
    if bounds.is_empty() { 0.0 } else { bounds.min.y }
}

/// The grid's pipeline.
pub(super) struct GridPass {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    uniforms: wgpu::Buffer,
}

impl GridPass {
    pub(super) fn new(device: &wgpu::Device, format: wgpu::TextureFormat) -> Self {
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("grid"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Depth,
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
            ],
        });
        let pipeline = super::upscale::overlay_pipeline(
            device,
            "grid",
            include_str!("grid.wgsl"),
            &layout,
            wgpu::ColorTargetState {
                format,
                blend: Some(wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING),
                write_mask: wgpu::ColorWrites::ALL,
            },
        );
        let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("grid"),
            size: size_of::<GpuGrid>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        GridPass {
            pipeline,
            layout,
            uniforms,
        }
    }
}

impl Viewer {
    /// Draws the grid over `target` (`size` pixels), which holds the renderer's last frame,
    /// drawn at `drawn` pixels (its depth's size).
    pub(super) fn draw_grid(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        size: (u32, u32),
        drawn: (u32, u32),
    ) {
        let Some((depth, view_proj)) = self.renderer.depth() else {
            return;
        };
        let grid = &self.grid;
        let u = GpuGrid {
            view_proj: view_proj.to_cols_array_2d(),
            inv_view_proj: view_proj.inverse().to_cols_array_2d(),
            plane: [
                self.scene_floor,
                spacing(
                    self.params.camera.position.y - self.scene_floor,
                    self.scene_radius,
                ),
                self.scene_radius * 4.0,
                0.0,
            ],
            size: [
                size.0 as f32,
                size.1 as f32,
                drawn.0 as f32 / size.0 as f32,
                drawn.1 as f32 / size.1 as f32,
            ],
        };
        if !Mat4::from_cols_array_2d(&u.inv_view_proj).is_finite() {
            return;
        }
        self.queue
            .write_buffer(&grid.uniforms, 0, bytemuck::bytes_of(&u));
        let bind = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("grid"),
            layout: &grid.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: grid.uniforms.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(depth),
                },
            ],
        });
        let mut pass = super::frame::color_pass(encoder, "grid", target, wgpu::LoadOp::Load);
        pass.set_pipeline(&grid.pipeline);
        pass.set_bind_group(0, &bind, &[]);
        pass.draw(0..3, 0..1);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The Cornell box's floor is at 0 (its boxes' tops are higher, and smaller); a floor under
    /// a slab's downward face is still the floor; a scene of one small tilted object has none.
    #[test]
    fn the_grid_lies_on_the_floor() {
        let cornell = voxgi::scene::builtin::cornell_box();
        assert!(height(&cornell).abs() < 1e-4, "{}", height(&cornell));
        let mut open = voxgi::scene::builtin::open_plane(0.5);
        let lifted = glam::Mat4::from_translation(glam::Vec3::new(0.0, 2.5, 0.0));
        for inst in &mut open.instances {
            inst.transform = lifted * inst.transform;
        }
        let floor = height(&open);
        assert!((floor - 2.5).abs() < 0.06, "{floor}");
    }

    #[test]
    fn the_spacing_is_the_power_of_ten_under_the_camera_height() {
        // The Cornell box's camera (0.27 m up), an eye in Sponza (1.7 m), high over it.
        assert_eq!(spacing(0.273, 0.48), 0.1);
        assert!((spacing(1.67, 20.8) - 1.0).abs() < 1e-6);
        assert!((spacing(-40.0, 20.8) - 10.0).abs() < 1e-4);
        // On the plane: a thousandth of the scene, not nothing.
        assert!((spacing(0.0, 20.8) - 0.01).abs() < 1e-6);
    }
}
