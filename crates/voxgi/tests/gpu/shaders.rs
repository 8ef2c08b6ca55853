//! Every WGSL file validates with naga, and every Rust struct that mirrors a WGSL struct has
//! the size naga computes for it.

use voxgi::gpu::shader;
use voxgi::gpu_scene::{GpuDraw, GpuFrame, GpuLight, GpuMaterial, GpuPoint, GpuVertex};
use voxgi::passes::shadow::GpuShadowView;
use voxgi::voxel::{GpuCones, GpuVolume};

fn parse(name: &str) -> naga::Module {
    let src = shader::compose(name);
    naga::front::wgsl::parse_str(&src)
        .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(&src)))
}

#[test]
fn every_shader_validates() {
    let mut n = 0;
    for name in shader::pass_shaders() {
        let module = parse(name);
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::all(),
        )
        .validate(&module)
        .unwrap_or_else(|e| panic!("{name}: {e:?}"));
        n += 1;
    }
    assert!(n >= 4);
}

#[test]
fn wgsl_struct_sizes() {
    // Between them these include every shared file that defines structs.
    let modules = [parse("composite.wgsl"), parse("gather.wgsl")];
    let size_of_wgsl = |name: &str| -> u32 {
        modules
            .iter()
            .flat_map(|m| m.types.iter())
            .find_map(|(_, t)| match (&t.name, &t.inner) {
                (Some(n), naga::TypeInner::Struct { span, .. }) if n == name => Some(*span),
                _ => None,
            })
            .unwrap_or_else(|| panic!("struct {name} not found"))
    };
    let cases = [
        ("Frame", size_of::<GpuFrame>()),
        ("Vertex", size_of::<GpuVertex>()),
        ("Draw", size_of::<GpuDraw>()),
        ("Material", size_of::<GpuMaterial>()),
        ("Light", size_of::<GpuLight>()),
        ("Volume", size_of::<GpuVolume>()),
        ("Cones", size_of::<GpuCones>()),
        ("ShadowView", size_of::<GpuShadowView>()),
        ("Point", size_of::<GpuPoint>()),
    ];
    for (name, rust) in cases {
        assert_eq!(
            size_of_wgsl(name) as usize,
            rust,
            "{name}: WGSL and Rust sizes differ"
        );
    }
}
