//! glTF, JSON or binary (by the GLB magic), through `voxgi_scene::io::load`: errors are fine,
//! panics and hangs are not.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let ext = if data.starts_with(b"glTF") { "glb" } else { "gltf" };
    let _ = voxgi_scene::io::fuzz::load_as(ext, data);
});
