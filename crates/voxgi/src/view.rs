//! The camera's projection and the default-light rule: shared by the renderer and the path
//! tracer, so both see exactly the same view of exactly the same scene.

use glam::{Mat4, Vec3};
use std::borrow::Cow;
use voxgi_scene::{Camera, Projection, Scene};

/// The camera's view-projection matrix for a `width` x `height` image of a scene with bounding
/// sphere (`center`, `radius`): right-handed, depth 0..1, the far plane just past the scene.
/// The rasterizer and the path tracer both use it, so they see exactly the same view.
pub(crate) fn camera_view_proj(
    camera: &Camera,
    width: u32,
    height: u32,
    center: Vec3,
    radius: f32,
) -> Mat4 {
    let aspect = width as f32 / height as f32;
    let dist = (camera.position - center).length();
    let zfar = camera
        .zfar
        .unwrap_or(dist + radius * 1.05)
        .max(camera.znear * 2.0);
    let view = Mat4::look_to_rh(camera.position, camera.forward, camera.up);
    let proj = match camera.projection {
        Projection::Perspective { yfov } => Mat4::perspective_rh(yfov, aspect, camera.znear, zfar),
        Projection::Orthographic { ymag, .. } => Mat4::orthographic_rh(
            -ymag * aspect,
            ymag * aspect,
            -ymag,
            ymag,
            camera.znear,
            zfar,
        ),
    };
    proj * view
}

/// The scene as rendered: with a default sun added when it has no light at all and
/// `default_light` is set, so it does not render black.
pub(crate) fn lit_scene(scene: &Scene, default_light: bool) -> Cow<'_, Scene> {
    if scene.is_unlit() && default_light {
        log::warn!("the scene has no lights and nothing emissive: adding a default sun");
        let mut lit = scene.clone();
        lit.lights.push(Scene::default_sun());
        Cow::Owned(lit)
    } else {
        Cow::Borrowed(scene)
    }
}
