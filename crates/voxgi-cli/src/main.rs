//! The `voxgi` command: one module per subcommand, shared arguments in `args`.

mod args;
mod bench;
mod compare;
mod info;
mod probe;
mod render;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "voxgi",
    version,
    about = "Real-time global illumination by voxel cone tracing",
    long_about = "voxgi renders meshes and point clouds with direct light, shadows and \
                  voxel-cone-traced indirect light (ambient occlusion, diffuse bounces, glossy \
                  reflections, cone-traced soft shadows), headless, on any Vulkan, Metal or DX12 device \
                  — including Mesa's CPU Vulkan driver on machines without a GPU.\n\n\
                  Scenes: glTF (.gltf/.glb), OBJ (+MTL), PLY (meshes or points), .cloud point \
                  files, and .toml scene files that place other files and add lights and a camera.",
    after_help = "Examples:\n  \
                  voxgi render --builtin cornell-box -o cornell.png --size 512x512\n  \
                  voxgi render scene.toml -o out.exr --size 1920x1080 --exposure 1\n  \
                  voxgi render model.obj -o model.png --eye 0,1,5 --target 0,1,0 --fov 40\n  \
                  voxgi info ../shared/scenes/sponza_dabrovic_geometry_only/sponza.obj\n\n\
                  GPU selection: WGPU_BACKEND=vulkan|metal|dx12|gl, WGPU_ADAPTER_NAME=<part of name>.\n\
                  Logging: RUST_LOG=info for details."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene to a PNG (tone-mapped, sRGB) or EXR (linear HDR radiance).
    Render(render::RenderArgs),
    /// Print what a scene contains: counts, bounds, materials, lights, cameras.
    Info(args::SceneArg),
    /// Time every pass with GPU timestamps over many frames; print a table, write JSON.
    Bench(bench::BenchArgs),
    /// Compare a test image with a reference: mean FLIP (LDR-FLIP for PNG, HDR-FLIP for EXR),
    /// RMSE and relative MSE on linear values, printed as one JSON line.
    Compare(compare::CompareArgs),
    /// Trace the diffuse cones at chosen pixels and compare each with the path tracer's light
    /// over the same cone: gathered radiance, transmittance, weights.
    Probe(probe::ProbeArgs),
}

fn main() {
    // Headless: Vulkan's window-system layer complains on stderr when there is no session
    // directory, although nothing here opens a window. Give it an empty one.
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
        // SAFETY: nothing else runs yet; no other thread can read the environment.
        unsafe { std::env::set_var("XDG_RUNTIME_DIR", std::env::temp_dir()) };
    }
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Render(a) => render::run(a),
        Command::Info(a) => info::run(a),
        Command::Bench(a) => bench::run(a),
        Command::Compare(a) => compare::run(a),
        Command::Probe(a) => probe::run(a),
    };
    if let Err(e) = result {
        eprintln!("voxgi: error: {e:#}");
        std::process::exit(1);
    }
}
