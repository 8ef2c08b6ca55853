//! Every WGSL file validates with naga (the Rust twins of WGSL structs are checked field by
//! field in the library's own tests, `src/wgsl_twins.rs`, where the private ones are seen).

use voxgi::gpu::shader;

fn parse(name: &str) -> naga::Module {
    parse_for(name, "dense")
}

fn parse_for(name: &str, kind: &str) -> naga::Module {
    let src = voxgi::voxel::compose_for(name, kind).expect("a kind");
    naga::front::wgsl::parse_str(&src)
        .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(&src)))
}

#[test]
fn every_shader_validates() {
    let mut n = 0;
    // Every pass shader for every structure: the shared passes (which reach a structure
    // through `voxels/` includes) with each, and each structure's own with its own includes.
    for &kind in voxgi::VoxelKind::ALL {
        let own = kind.shaders().passes.iter().copied();
        for name in shader::pass_shaders().chain(own) {
            let module = parse_for(name, kind.name());
            naga::valid::Validator::new(
                naga::valid::ValidationFlags::all(),
                naga::valid::Capabilities::all(),
            )
            .validate(&module)
            .unwrap_or_else(|e| panic!("{name} ({kind:?}): {e:?}"));
            n += 1;
        }
    }
    assert!(n >= 4);
}

/// The value of a `u32` constant of a parsed module.
fn wgsl_u32(module: &naga::Module, name: &str) -> u32 {
    let c = module
        .constants
        .iter()
        .find(|(_, c)| c.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("const {name} not found"))
        .1;
    match module.global_expressions[c.init] {
        naga::Expression::Literal(naga::Literal::U32(v)) => v,
        ref e => panic!("const {name} is not a u32 literal: {e:?}"),
    }
}

/// View-mode and tone-map ids are defined once in Rust and once in WGSL: they must agree.
#[test]
fn view_and_tonemap_ids_agree_with_wgsl() {
    let m = parse("screen/composite.wgsl");
    for v in voxgi::ViewMode::ALL {
        let name = format!("VIEW_{}", v.name().replace('-', "_").to_uppercase());
        assert_eq!(wgsl_u32(&m, &name), v.id(), "{name}");
    }
    for t in voxgi::Tonemap::ALL {
        let name = format!("TONEMAP_{}", t.name().to_uppercase());
        assert_eq!(wgsl_u32(&m, &name), t.id(), "{name}");
    }
}
