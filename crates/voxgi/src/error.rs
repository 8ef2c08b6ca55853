use std::path::PathBuf;

/// Everything that can go wrong in voxgi, with a message a user can act on.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// No adapter was found on the searched backends, or none whose name matches
    /// `WGPU_ADAPTER_NAME` (opening a headless device).
    #[error(
        "no GPU adapter found{details}. voxgi needs a Vulkan, Metal or DX12 device; on a machine \
         without a GPU install Mesa's CPU Vulkan driver (Debian/Ubuntu: `apt-get install \
         mesa-vulkan-drivers`)"
    )]
    NoAdapter {
        /// What was looked for (the `WGPU_ADAPTER_NAME` filter and the adapters available, or
        /// the backends searched), appended to the message after "found".
        details: String,
    },
    /// The chosen adapter refused to open a device (`request_device` failed).
    #[error("could not open the GPU device '{adapter}': {reason}")]
    Device {
        /// The adapter's name, as wgpu reports it.
        adapter: String,
        /// wgpu's message.
        reason: String,
    },
    /// The device falls short of `minimum_limits` (checked when a renderer is made); the
    /// message names every limit it lacks, with what it has and what voxgi needs.
    #[error(
        "the GPU device lacks what voxgi needs: {0}. Open it with voxgi::required_limits(&adapter)"
    )]
    DeviceLimits(String),
    /// The GPU or wgpu reported a failure: a validation or out-of-memory error caught in an
    /// error scope or by the device's handler, a failed poll or buffer mapping, an unreadable
    /// texture format, non-finite timestamps, or voxel pools that kept overflowing.
    #[error("GPU error in {context}: {reason}")]
    Gpu {
        /// What voxgi was doing (a pass, "readback", "frame", ...), for the message.
        context: String,
        /// wgpu's message, or what was missing.
        reason: String,
    },
    /// The GPU device was lost (a driver reset, a removed GPU, `Device::destroy`): nothing
    /// more can be rendered on it. Seen through a `gpu::lost::DeviceWatch`.
    #[error(
        "the GPU device was lost ({reason}); nothing more can be drawn on it: open a new device \
         (restart voxgi), and if it happens again update the GPU driver or lower the voxel \
         resolution and image size (a driver may reset a GPU that works too long on one frame)"
    )]
    DeviceLost {
        /// What the lost callback said.
        reason: String,
    },
    /// The scene failed to load or failed `Scene::validate` (voxgi-scene's error, unchanged).
    #[error(transparent)]
    Scene(#[from] voxgi_scene::SceneError),
    /// The scene at this voxel resolution needs more than the device's limits hold: the
    /// message names the limit and what it would take. A lower voxel resolution fits
    /// (applications may lower it and try again, as the web page does).
    #[error("{0}")]
    TooLarge(String),
    /// An option, setting, argument or input is out of range or malformed (a settings file, a
    /// renderer option, a scene too large for the device whatever the voxel resolution, images
    /// of different sizes to compare).
    #[error("invalid setting: {0}")]
    Setting(String),
    /// The scene has nothing to render: a renderer got no triangles and no points, the
    /// reference path tracer (which traces triangles only) no triangles.
    #[error("the scene is empty: it has no triangles and no points to render")]
    EmptyScene,
    /// An image could not be written or read (unknown extension, missing file, encoder or
    /// decoder error).
    #[error("{}: {reason}", path.display())]
    Output {
        /// The image file.
        path: PathBuf,
        /// What went wrong.
        reason: String,
    },
}

/// `std::result::Result` with voxgi's `Error` as the default error type.
pub type Result<T, E = Error> = std::result::Result<T, E>;
