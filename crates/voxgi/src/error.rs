use std::path::PathBuf;

/// Everything that can go wrong in voxgi, with a message a user can act on.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    #[error(
        "no GPU adapter found{details}. voxgi needs a Vulkan, Metal or DX12 device; on a machine \
         without a GPU install Mesa's CPU Vulkan driver (Debian/Ubuntu: `apt-get install \
         mesa-vulkan-drivers`)"
    )]
    NoAdapter { details: String },
    #[error("could not open the GPU device '{adapter}': {reason}")]
    Device { adapter: String, reason: String },
    #[error(
        "the GPU device lacks what voxgi needs: {0}. Open it with voxgi::required_limits(&adapter)"
    )]
    DeviceLimits(String),
    #[error("GPU error in {context}: {reason}")]
    Gpu { context: String, reason: String },
    #[error(transparent)]
    Scene(#[from] voxgi_scene::SceneError),
    #[error("invalid setting: {0}")]
    Setting(String),
    #[error("the scene is empty: it has no triangles and no points to render")]
    EmptyScene,
    #[error("{}: {reason}", path.display())]
    Output { path: PathBuf, reason: String },
}

pub type Result<T, E = Error> = std::result::Result<T, E>;
