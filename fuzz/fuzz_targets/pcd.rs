//! `.pcd` files through `voxgi_scene::io::load`: errors are fine, panics and hangs are not.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = voxgi_scene::io::fuzz::load_as("pcd", data);
});
