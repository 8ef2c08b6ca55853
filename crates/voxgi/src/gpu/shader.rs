//! WGSL composition: a shader names the shared files it needs with `//!include shared/NAME.wgsl`
//! lines, which are replaced by those files (each at most once). `//!include voxels/NAME.wgsl`
//! picks the voxel structure's own file, `voxels/<kind>/NAME.wgsl` (or its base kind's, when
//! it has none of that name): that is how cone tracing, written once, meets a structure.
//! `//!include voxels/OTHER/NAME.wgsl` names another kind's file itself. Tiny on purpose:
//! WGSL has no modules yet, and this is all voxgi needs.

/// `&[(path, source)]` of WGSL files by path relative to `crates/voxgi/shaders`, their
/// sources built in.
#[macro_export]
#[doc(hidden)]
macro_rules! wgsl {
    ($($path:literal),* $(,)?) => {
        &[$(($path, include_str!(concat!(env!("CARGO_MANIFEST_DIR"), "/shaders/", $path)))),*]
    };
}

/// A voxel structure's WGSL files (`shaders/voxels/<name>/`): the contract files that shared
/// shaders include as `//!include voxels/FILE.wgsl`, and its own passes.
#[derive(Clone, Copy, Debug)]
pub struct StructureShaders {
    /// The structure's name: its folder under `shaders/voxels/`.
    pub name: &'static str,
    /// Every file of the folder, by path relative to `crates/voxgi/shaders`.
    pub sources: &'static [(&'static str, &'static str)],
    /// Of those, the shaders with entry points of the structure's own passes (validated on
    /// their own by the tests).
    pub passes: &'static [&'static str],
    /// A structure built on another (the clipmap on the dense volume's windows): the files
    /// this one does not have are that one's.
    pub base: Option<&'static StructureShaders>,
}

/// Every WGSL file outside the structures' folders, by path relative to `crates/voxgi/shaders`.
const SOURCES: &[(&str, &str)] = wgsl![
    "shared/scene.wgsl",
    "shared/tone_curves.wgsl",
    "shared/fullscreen.wgsl",
    "shared/globals.wgsl",
    "shared/brdf.wgsl",
    "shared/light_model.wgsl",
    "shared/lights.wgsl",
    "shared/volume.wgsl",
    "shared/half.wgsl",
    "shared/fragment.wgsl",
    "shared/voxel_debug.wgsl",
    "shared/cone.wgsl",
    "shared/irradiance_record.wgsl",
    "shared/leaf_irradiance.wgsl",
    "shared/surfel.wgsl",
    "shared/interleave.wgsl",
    "shared/upsample.wgsl",
    "shared/specular_lobe.wgsl",
    "lighting/shadow.wgsl",
    "lighting/moments.wgsl",
    "screen/gbuffer.wgsl",
    "fragments/voxelize.wgsl",
    "fragments/splat.wgsl",
    "lighting/inject.wgsl",
    "lighting/bounce.wgsl",
    "lighting/bounce_store.wgsl",
    "lighting/blend.wgsl",
    "screen/gather.wgsl",
    "screen/upsample.wgsl",
    "screen/composite.wgsl",
    "screen/temporal.wgsl",
    "screen/tonemap.wgsl",
    "reference.wgsl",
    "reference_display.wgsl",
    "cone_probe.wgsl",
];

/// Shader development: with `VOXGI_SHADER_DIR` set, WGSL is read from that directory (laid out
/// like `crates/voxgi/shaders`) at pipeline creation, so a shader change needs no rebuild. A
/// file missing there falls back to the built-in copy.
const SHADER_DIR_VAR: &str = "VOXGI_SHADER_DIR";

fn raw(name: &str, kind: Option<&StructureShaders>) -> std::borrow::Cow<'static, str> {
    if let Some(dir) = std::env::var_os(SHADER_DIR_VAR) {
        let dir = std::path::Path::new(&dir);
        if let Ok(text) = std::fs::read_to_string(dir.join(name)) {
            log::info!("shader {name} read from {}", dir.display());
            return text.into();
        }
        if !dir.is_dir() {
            static WARNED: std::sync::Once = std::sync::Once::new();
            WARNED.call_once(|| {
                log::warn!(
                    "{SHADER_DIR_VAR}={} is not a directory: using the built-in shaders",
                    dir.display()
                )
            });
        }
    }
    SOURCES
        .iter()
        .chain(kind.map_or(&[][..], |k| k.sources))
        .chain(kind.and_then(|k| k.base).map_or(&[][..], |b| b.sources))
        .find(|(n, _)| *n == name)
        .map(|(_, s)| (*s).into())
        // The sources are built in: a missing one is a bug in voxgi, found by its tests.
        .unwrap_or_else(|| panic!("unknown shader file {name}"))
}

/// The full WGSL of shader `name` with its includes expanded, for a shader that reaches no
/// voxel structure.
pub fn compose(name: &str) -> String {
    compose_with(name, None)
}

/// The full WGSL of shader `name` with `voxels/` includes taken from structure `kind`.
pub fn compose_with(name: &str, kind: Option<&StructureShaders>) -> String {
    let mut out = String::new();
    let mut seen = Vec::new();
    expand(name, kind, &mut out, &mut seen);
    out
}

/// `name`, or the base kind's file of that name when it is a structure's file the structure
/// does not have.
fn resolve(name: &str, kind: Option<&StructureShaders>) -> String {
    let Some(k) = kind else {
        return name.to_string();
    };
    let own = format!("voxels/{}/", k.name);
    match (name.strip_prefix(&own), k.base) {
        (Some(file), Some(b)) if !k.sources.iter().any(|(n, _)| *n == name) => {
            format!("voxels/{}/{file}", b.name)
        }
        _ => name.to_string(),
    }
}

fn expand(name: &str, kind: Option<&StructureShaders>, out: &mut String, seen: &mut Vec<String>) {
    let name = &resolve(name, kind);
    if seen.iter().any(|s| s == name) {
        return;
    }
    seen.push(name.to_string());
    for line in raw(name, kind).lines() {
        if let Some(inc) = line.trim().strip_prefix("//!include ") {
            let inc = inc.trim();
            match (inc.strip_prefix("voxels/"), kind) {
                (Some(file), Some(k)) => {
                    // A structure's files name each other (and a base kind's) by their full
                    // path; a bare name is the kind's own file, or else its base's.
                    let path = if file.contains('/') {
                        inc.to_string()
                    } else {
                        format!("voxels/{}/{file}", k.name)
                    };
                    expand(&path, kind, out, seen)
                }
                (Some(_), None) => {
                    panic!("shader {name} includes {inc}: compose it for a voxel structure")
                }
                (None, _) => expand(inc, kind, out, seen),
            }
        } else {
            out.push_str(line);
            out.push('\n');
        }
    }
}

/// Compiles shader `name`; the label is the shader's name so pipelines and timings agree.
pub fn module(device: &wgpu::Device, name: &str) -> wgpu::ShaderModule {
    module_with(device, name, None)
}

/// Compiles shader `name` for voxel structure `kind` (its `voxels/` includes).
pub fn module_for(
    device: &wgpu::Device,
    name: &str,
    kind: &StructureShaders,
) -> wgpu::ShaderModule {
    module_with(device, name, Some(kind))
}

fn module_with(
    device: &wgpu::Device,
    name: &str,
    kind: Option<&StructureShaders>,
) -> wgpu::ShaderModule {
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(name),
        source: wgpu::ShaderSource::Wgsl(compose_with(name, kind).into()),
    })
}

/// A compute pipeline whose label is the pass name, from the WGSL file's `main`.
pub fn compute_pipeline(
    device: &wgpu::Device,
    label: &str,
    file: &str,
    layout: &wgpu::BindGroupLayout,
) -> wgpu::ComputePipeline {
    specialized_pipeline(device, label, file, layout, &[])
}

/// `compute_pipeline` with values for the shader's `override` constants.
pub fn specialized_pipeline(
    device: &wgpu::Device,
    label: &str,
    file: &str,
    layout: &wgpu::BindGroupLayout,
    constants: &[(&str, f64)],
) -> wgpu::ComputePipeline {
    grouped_pipeline(device, label, file, &[Some(layout)], constants)
}

/// `specialized_pipeline` with one layout per bind group, by owner as rerun's re_renderer
/// keeps them: 0 the frame's globals, 1 the voxel structure's sampling, 2 the structure's
/// leaves or the pass's own resources, 3 the leaves' radiance for writing. `None`: a group
/// the shader does not use.
pub fn grouped_pipeline(
    device: &wgpu::Device,
    label: &str,
    file: &str,
    layouts: &[Option<&wgpu::BindGroupLayout>],
    constants: &[(&str, f64)],
) -> wgpu::ComputePipeline {
    pipeline_with(device, label, file, None, "main", layouts, constants)
}

/// `grouped_pipeline` of entry point `entry` (a pass of several steps in one file).
pub fn grouped_pipeline_entry(
    device: &wgpu::Device,
    label: &str,
    file: &str,
    entry: &str,
    layouts: &[Option<&wgpu::BindGroupLayout>],
    constants: &[(&str, f64)],
) -> wgpu::ComputePipeline {
    pipeline_with(device, label, file, None, entry, layouts, constants)
}

/// `grouped_pipeline` for a shader that reaches voxel structure `kind` (`voxels/` includes).
pub fn voxel_pipeline(
    device: &wgpu::Device,
    label: &str,
    file: &str,
    kind: &StructureShaders,
    layouts: &[Option<&wgpu::BindGroupLayout>],
    constants: &[(&str, f64)],
) -> wgpu::ComputePipeline {
    pipeline_with(device, label, file, Some(kind), "main", layouts, constants)
}

/// `voxel_pipeline` of entry point `entry` (a pass of several steps in one file).
pub fn voxel_pipeline_entry(
    device: &wgpu::Device,
    label: &str,
    file: &str,
    kind: &StructureShaders,
    entry: &str,
    layouts: &[Option<&wgpu::BindGroupLayout>],
) -> wgpu::ComputePipeline {
    pipeline_with(device, label, file, Some(kind), entry, layouts, &[])
}

fn pipeline_with(
    device: &wgpu::Device,
    label: &str,
    file: &str,
    kind: Option<&StructureShaders>,
    entry: &str,
    layouts: &[Option<&wgpu::BindGroupLayout>],
    constants: &[(&str, f64)],
) -> wgpu::ComputePipeline {
    let module = module_with(device, file, kind);
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: layouts,
        immediate_size: 0,
    });
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(label),
        layout: Some(&pipeline_layout),
        module: &module,
        entry_point: Some(entry),
        compilation_options: wgpu::PipelineCompilationOptions {
            constants,
            ..Default::default()
        },
        cache: None,
    })
}

/// The names of the pass shaders outside the structures' folders (for tests that validate
/// every one, composed for each structure; each structure lists its own in
/// `StructureShaders::passes`).
pub fn pass_shaders() -> impl Iterator<Item = &'static str> {
    SOURCES
        .iter()
        .map(|(n, _)| *n)
        .filter(|n| !n.starts_with("shared/"))
}
