//! The renderer's knobs with their documented defaults and range checks: creation-time
//! options apart from per-frame parameters.

pub use crate::voxel::VoxelKind;
use crate::voxel::VoxelView;
use crate::{Error, Result};
use voxgi_scene::Camera;

/// Names of the directional chains (`FrameParams::debug_direction`), in the order the
/// anisotropic filters store them.
pub const DIRECTIONS: [&str; 6] = ["+x", "-x", "+y", "-y", "+z", "-z"];

/// A set of diffuse cones around the normal.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ConeSet {
    /// Six cones of 60° aperture: one along the normal, five tilted 60° (Crassin et al.).
    #[default]
    Six60,
    /// Seven cones of 45°: one along the normal, six tilted 45° (the 3D-texture paper).
    Seven45,
    /// Nine cones of 45°: one along the normal, eight tilted 50°.
    Nine45,
}

impl ConeSet {
    /// Every set, in the order settings list them.
    pub const ALL: [ConeSet; 3] = [ConeSet::Six60, ConeSet::Seven45, ConeSet::Nine45];

    /// The set's name as settings and the command line spell it: "6x60", "7x45" or "9x45".
    pub fn name(&self) -> &'static str {
        match self {
            ConeSet::Six60 => "6x60",
            ConeSet::Seven45 => "7x45",
            ConeSet::Nine45 => "9x45",
        }
    }

    /// The set named `s` (as `name` spells it), or `None`.
    pub fn parse(s: &str) -> Option<Self> {
        [ConeSet::Six60, ConeSet::Seven45, ConeSet::Nine45]
            .into_iter()
            .find(|c| c.name() == s)
    }
}

/// The curve that maps exposed linear radiance to display values.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Tonemap {
    /// Narkowicz's fit of ACES: filmic toe and shoulder, desaturates very bright colours.
    #[default]
    Aces,
    /// Khronos PBR Neutral: base colours stay exact up to 0.76, highlights roll off.
    Neutral,
    /// No curve: clamp to [0, 1]. For measurements.
    Clamp,
}

/// What the output shows.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ViewMode {
    /// The lit image.
    #[default]
    Final,
    /// Surface albedo (the G-buffer).
    Albedo,
    /// World-space normals mapped to colour.
    Normal,
    /// Direct light only, without emission.
    Direct,
    /// Ambient occlusion from the diffuse cones (white: open, black: occluded).
    Ao,
    /// Indirect light only.
    Indirect,
    /// The voxel volume ray-marched at `FrameParams::debug_level`: the finest albedo under the
    /// first voxel with opacity > 0.5.
    VoxelAlbedo,
    /// The opacity of the first voxel with opacity > 0.5 at `debug_level`, as grey.
    VoxelOpacity,
    /// The radiance (un-premultiplied) of the first voxel with opacity > 0.5 at `debug_level`.
    VoxelRadiance,
    /// The structure's occupied cells at `debug_level`: the octree's nodes of that level that
    /// have children (at level 0 its occupied leaves), the dense volume's cells with any
    /// opacity; coloured by level, shaded by face, edges darkened.
    VoxelNodes,
    /// Motion vectors: red and green the screen motion since the last frame in pixels (x
    /// right, y down), blue the surface's distance from the last frame's camera in metres.
    /// Raw values: read them from an EXR.
    Motion,
}

impl Tonemap {
    /// Every curve, in the order of their ids.
    pub const ALL: [Tonemap; 3] = [Tonemap::Aces, Tonemap::Neutral, Tonemap::Clamp];

    /// The name scene files and the CLI use.
    pub fn name(self) -> &'static str {
        match self {
            Tonemap::Aces => "aces",
            Tonemap::Neutral => "neutral",
            Tonemap::Clamp => "clamp",
        }
    }

    /// The id the shaders switch on (`Frame.tonemap`; `TONEMAP_*` in shaders/shared/scene.wgsl).
    pub fn id(self) -> u32 {
        self as u32
    }

    /// A curve by name.
    pub fn parse(s: &str) -> Result<Self> {
        Self::ALL
            .into_iter()
            .find(|t| t.name() == s)
            .ok_or_else(|| Error::Setting(format!("tone map '{s}' is not aces, neutral or clamp")))
    }
}

impl ViewMode {
    /// Every view, in the order of their ids.
    pub const ALL: [ViewMode; 11] = [
        ViewMode::Final,
        ViewMode::Albedo,
        ViewMode::Normal,
        ViewMode::Direct,
        ViewMode::Ao,
        ViewMode::Indirect,
        ViewMode::VoxelAlbedo,
        ViewMode::VoxelOpacity,
        ViewMode::VoxelRadiance,
        ViewMode::VoxelNodes,
        ViewMode::Motion,
    ];

    /// The name scene files and the CLI use.
    pub fn name(self) -> &'static str {
        match self {
            ViewMode::Final => "final",
            ViewMode::Albedo => "albedo",
            ViewMode::Normal => "normal",
            ViewMode::Direct => "direct",
            ViewMode::Ao => "ao",
            ViewMode::Indirect => "indirect",
            ViewMode::VoxelAlbedo => "voxel-albedo",
            ViewMode::VoxelOpacity => "voxel-opacity",
            ViewMode::VoxelRadiance => "voxel-radiance",
            ViewMode::VoxelNodes => "voxel-nodes",
            ViewMode::Motion => "motion",
        }
    }

    /// The id the shaders switch on (`Frame.view_mode`; `VIEW_*` in shaders/shared/scene.wgsl).
    pub fn id(self) -> u32 {
        self as u32
    }

    /// A view by name.
    pub fn parse(s: &str) -> Result<Self> {
        Self::ALL
            .into_iter()
            .find(|v| v.name() == s)
            .ok_or_else(|| {
                let names: Vec<&str> = Self::ALL.iter().map(|v| v.name()).collect();
                Error::Setting(format!("view '{s}' is not one of {}", names.join(", ")))
            })
    }

    /// What the `debug` pass draws for a voxel view; `None` for the others.
    pub fn voxel_view(&self) -> Option<VoxelView> {
        match self {
            ViewMode::VoxelAlbedo => Some(VoxelView::Albedo),
            ViewMode::VoxelOpacity => Some(VoxelView::Opacity),
            ViewMode::VoxelRadiance => Some(VoxelView::Radiance),
            ViewMode::VoxelNodes => Some(VoxelView::Nodes),
            _ => None,
        }
    }

    /// The views the `debug` pass draws by ray-marching the voxel volume.
    pub fn is_voxel(&self) -> bool {
        matches!(
            self,
            ViewMode::VoxelAlbedo
                | ViewMode::VoxelOpacity
                | ViewMode::VoxelRadiance
                | ViewMode::VoxelNodes
        )
    }
}

/// How each pixel gets its diffuse indirect light and ambient occlusion.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum IndirectShading {
    /// A bundle of diffuse cones traced from every pixel (the per-pixel gather of Crassin et
    /// al.): sharp contact occlusion, costs cones per pixel every frame.
    #[default]
    Cones,
    /// The thesis' fast shading (Salm, §4.6): the last voxel bounce keeps every leaf's
    /// irradiance and occlusion, and each pixel interpolates those of the leaves around it
    /// (weighted by how well their normals agree with its own). No per-pixel diffuse cones:
    /// the frame's cost no longer grows with the cone count, the voxel update costs one more
    /// bounce, and light leaks along edges where a leaf holds two surfaces
    /// (docs/QUALITY.md). Glossy cones are still traced per pixel.
    Leaves,
}

impl IndirectShading {
    /// Both, in the order of their names.
    pub const ALL: [IndirectShading; 2] = [IndirectShading::Cones, IndirectShading::Leaves];

    /// The name scene files and the CLI use.
    pub fn name(self) -> &'static str {
        match self {
            IndirectShading::Cones => "cones",
            IndirectShading::Leaves => "leaves",
        }
    }

    /// A shading by name.
    pub fn parse(s: &str) -> Result<Self> {
        Self::ALL
            .into_iter()
            .find(|t| t.name() == s)
            .ok_or_else(|| Error::Setting(format!("indirect shading '{s}' is not cones or leaves")))
    }
}

/// How shadow maps are filtered for point, spot and directional lights (area lights use PCSS
/// or cone shadows whatever this says).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ShadowFilter {
    /// Percentage-closer filtering: twelve comparisons in a disc of `FrameParams::shadow_softness`
    /// texels against the receiver plane.
    #[default]
    Pcf,
    /// The thesis' shadows (Salm, §2.3 and §4.2): variance and exponential shadow maps
    /// prefiltered with a 5x5-texel disc, one lookup each, the smaller of the two visibilities.
    /// Soft-edged, one lookup per pixel instead of twelve, more GPU memory (16 bytes per map
    /// texel); light leaks where occluders and receivers meet (docs/QUALITY.md).
    VsmEsm,
}

impl ShadowFilter {
    /// Both, in the order of their names.
    pub const ALL: [ShadowFilter; 2] = [ShadowFilter::Pcf, ShadowFilter::VsmEsm];

    /// The name scene files and the CLI use.
    pub fn name(self) -> &'static str {
        match self {
            ShadowFilter::Pcf => "pcf",
            ShadowFilter::VsmEsm => "vsm-esm",
        }
    }

    /// A filter by name.
    pub fn parse(s: &str) -> Result<Self> {
        Self::ALL
            .into_iter()
            .find(|t| t.name() == s)
            .ok_or_else(|| Error::Setting(format!("shadow filter '{s}' is not pcf or vsm-esm")))
    }
}

/// `RendererOptions::bounces` value for "until converged": voxel bounces are repeated until the
/// energy left (the largest albedo to the power of the bounce count) is below 0.1 %.
pub const UNLIMITED_BOUNCES: u32 = u32::MAX;
/// Most bounces a finite setting may ask for.
pub const MAX_BOUNCES: u32 = 8;

/// Creation-time options: what the renderer's pipelines, resources and voxel work depend on.
/// `Renderer::new` takes them; `Renderer::set_options` rebuilds only what a change touches.
#[derive(Clone, Debug, PartialEq)]
pub struct RendererOptions {
    /// Width and height of each shadow map in texels (64..=8192). Default 1024.
    pub shadow_map_size: u32,
    /// How the shadow maps of point, spot and directional lights are filtered. Default PCF.
    pub shadow_filter: ShadowFilter,
    /// Largest material texture size; bigger textures are downsampled (1..=8192). Default 1024.
    pub max_texture_size: u32,
    /// Add a sun when the scene has no light and nothing emissive, instead of rendering black.
    /// Default true.
    pub default_light: bool,
    /// The voxel structure: the dense volume (default) or the sparse voxel octree.
    pub voxels: VoxelKind,
    /// Voxels per side of the volume at the finest level: a power of two in 16..=512 (the
    /// octree: 16..=1024; the clipmap: each level's, 16..=256). Default 128.
    pub voxel_resolution: u32,
    /// The clipmap's levels (2..=8), each twice the extent of the one inside it. Default 5.
    pub clipmap_levels: u32,
    /// The most clipmap windows rebuilt in one frame (0: every window that moved). A window
    /// whose turn has not come stays where it was, valid, and cones read the coarser levels
    /// past it. Default 1.
    pub clipmap_budget: u32,
    /// The clipmap's finest voxel edge, metres: `None` (default) makes its coarsest level
    /// span four times the scene's cube (the camera may stand anywhere near it).
    pub voxel_size: Option<f32>,
    /// Six directional values per voxel above the finest level (true, default) or one.
    pub anisotropic: bool,
    /// The first directional level weighs each leaf's radiance and opacity along each of the six
    /// directions by its normal distribution (after Salm, §4.4.2): whole face-on and edge-on,
    /// falling to nothing from behind, blended towards isotropic as its fragments' normals
    /// disagree (Toksvig's length of the mean normal; `voxel::cpu::ndf_weight`). Default true:
    /// a column's lit face is not seen from its shadowed side, nor a ledge's face by the cones
    /// clearing its top (docs/QUALITY.md, "Normal distributions by default"). Isotropic volumes
    /// have no directions to weigh: there it does nothing.
    pub ndf_mips: bool,
    /// Metals' specular reflections of the lights in the bounces: each lit metal leaf keeps a
    /// lobe of what it reflects, which every structure keeps up its levels in two more blocks
    /// beside the six directions, evaluated towards each cone (docs/QUALITY.md, "Specular
    /// light in the bounces"). Needs `anisotropic`. In a scene without a metal it keeps nothing
    /// and costs nothing. Default false: a wall facing a metal's reflection is lit at under
    /// half its strength, and the lobes cost a scene with metals half as much gather time
    /// again.
    pub specular_bounces: bool,
    /// Directional blocks each cone sample of the per-pixel gather reads in an anisotropic
    /// volume: 3, every axis by its weight (the paper's filtering), or 2, the two axes of
    /// largest weight renormalised (faster; docs/QUALITY.md has the cost in accuracy).
    /// Default 3.
    pub gather_axes: u32,
    /// Diffuse cone set. Default: six cones of 60°.
    pub cones: ConeSet,
    /// Indirect bounces: 0 (direct light only) to 8, or `UNLIMITED_BOUNCES`. With cones the last
    /// bounce is the per-pixel gather and the others run in voxel space; with leaves all run in
    /// voxel space. Default 2.
    pub bounces: u32,
    /// Where pixels get diffuse indirect light: cones per pixel (default) or the leaves'
    /// stored irradiance.
    pub indirect: IndirectShading,
    /// Ambient occlusion radius in metres; `None`: a quarter of the volume's extent.
    pub ao_radius: Option<f32>,
    /// Ambient occlusion falloff lambda in 1/(1 + lambda r), per metre (>= 0). Default 0:
    /// plain cosine-weighted visibility within the radius, what the AO reference computes.
    pub ao_lambda: f32,
    /// Cone sample step as a fraction of the cone's diameter (0.05..=2). Default 0.5.
    pub step_factor: f32,
    /// Each diffuse cone (per pixel and in the voxel bounces) traces one quarter of its
    /// footprint, a different one from pixel to pixel, voxel to voxel and frame to frame:
    /// nearer the path tracer wherever surfaces partly cover the cones (docs/QUALITY.md). False
    /// traces the whole footprint, at about half the gather's cost. Default true.
    pub cone_quarters: bool,
    /// Cone origin offset along the normal, in finest voxels (0..=8): keeps a cone from seeing
    /// its own surface's voxels. Default 1.5.
    pub origin_offset: f32,
    /// Longest cone in metres; `None`: the volume's diagonal.
    pub max_distance: Option<f32>,
    /// Gather indirect light at half resolution and upsample it edge-aware. Default false.
    pub half_resolution: bool,
    /// Shadows of area lights by a cone traced through the voxels towards the light (aperture:
    /// the light's size) instead of PCSS on the shadow map. Default false.
    pub cone_shadows: bool,
    /// Voxel fragments the first build has room for (at least 1024); `None`: an upper bound
    /// estimated from the scene. Too few is not an error: the build counts what did not fit
    /// and the pool grows a frame later. Set it to avoid that frame in a known scene.
    pub fragment_capacity: Option<u64>,
    /// Occupied voxels the first build has room for (at least 1024); `None`: a quarter of the
    /// fragment estimate. Grows like `fragment_capacity`.
    pub voxel_capacity: Option<u64>,
    /// Progressive bounces: each voxel update adds one bounce, gathered from the previous
    /// update's voxel radiance, so a still scene converges to the `UNLIMITED_BOUNCES` result
    /// and a changing one costs one bounce per update (its light lags behind by a few
    /// updates). Needs `bounces` = `UNLIMITED_BOUNCES`. Default false.
    pub progressive: bool,
    /// Voxel work (dynamic geometry, injection, filtering, bounces) runs on every k-th frame
    /// only (1..=64); the frames between reuse the voxels, which then trail the meshes by up
    /// to k - 1 frames. Shadow maps follow every frame. Default 1.
    pub voxel_update_interval: u32,
    /// Voxel bounces gather at one leaf in k per update (1..=16), the leaves taking turns by a
    /// hash of their voxel; the others re-emit the irradiance they last gathered on top of
    /// their direct light of now. Leaves near moved geometry gather at once
    /// (`lighting::bounce::near_change`). After a change stops, the light equals a full bounce's
    /// within k updates per voxel bounce. A moving light or object then costs a k-th of the
    /// bounces, and the bounced light lags by up to k - 1 updates. Default 1 (every leaf).
    pub bounce_slices: u32,
    /// Temporal accumulation: each frame's camera is jittered within the pixel and its cone
    /// bundle turned, and the frames are accumulated into a history reprojected by motion
    /// vectors (anti-aliased edges, many more cone directions than one frame traces; a still
    /// converges over frames). Off, every frame is a still of its own, the same from frame to
    /// frame. Default true.
    pub temporal: bool,
}

impl RendererOptions {
    /// The defaults for an interactive view (a window, a web page): on a CPU adapter
    /// (lavapipe, SwiftShader) a 64³ volume, the half-resolution gather and whole-footprint
    /// cones (`cone_quarters` off, about half the gather's cost) keep frames to a fraction of a
    /// second; on a GPU, 128³ at full resolution with the cones' quarters.
    pub fn interactive(cpu: bool) -> Self {
        RendererOptions {
            half_resolution: cpu,
            cone_quarters: !cpu,
            voxel_resolution: if cpu { 64 } else { 128 },
            ..RendererOptions::default()
        }
    }
}

impl Default for RendererOptions {
    fn default() -> Self {
        RendererOptions {
            shadow_map_size: 1024,
            shadow_filter: ShadowFilter::Pcf,
            max_texture_size: 1024,
            default_light: true,
            voxels: VoxelKind::DENSE,
            voxel_resolution: 128,
            clipmap_levels: 5,
            clipmap_budget: 1,
            voxel_size: None,
            anisotropic: true,
            ndf_mips: true,
            specular_bounces: false,
            gather_axes: 3,
            cones: ConeSet::Six60,
            bounces: 2,
            indirect: IndirectShading::Cones,
            ao_radius: None,
            ao_lambda: 0.0,
            step_factor: 0.5,
            cone_quarters: true,
            origin_offset: 1.5,
            max_distance: None,
            half_resolution: false,
            cone_shadows: false,
            fragment_capacity: None,
            voxel_capacity: None,
            progressive: false,
            voxel_update_interval: 1,
            bounce_slices: 1,
            temporal: true,
        }
    }
}

impl RendererOptions {
    /// Mip levels of the volume, the finest included.
    pub fn voxel_levels(&self) -> u32 {
        self.voxel_resolution.max(1).ilog2() + 1
    }
}

/// Per-frame parameters: the view and how it is displayed. Changing any of them never
/// rebuilds a pipeline or redoes voxel work.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameParams {
    /// The camera (the scene's own is `Renderer::default_camera`).
    pub camera: Camera,
    /// Exposure in stops: the image is scaled by 2^exposure before tone mapping (-20..=20).
    /// Default 0.
    pub exposure: f32,
    /// Default ACES.
    pub tonemap: Tonemap,
    /// Radiance of pixels that see no geometry. Default black.
    pub background: [f32; 3],
    /// Default `ViewMode::Final`.
    pub view: ViewMode,
    /// Filter radius of point, spot and directional shadows in texels (0..=16). Area lights get
    /// penumbrae from their size instead. Default 1.5.
    pub shadow_softness: f32,
    /// Mip level the voxel views show, 0 = finest (< `RendererOptions::voxel_levels`).
    /// Default 0.
    pub debug_level: u32,
    /// Directional chain the voxel views read above the finest level: 0..6 for +X, -X, +Y, -Y,
    /// +Z, -Z (ignored in an isotropic volume). Default 0.
    pub debug_direction: u32,
}

impl FrameParams {
    /// The defaults, seen from `camera`.
    pub fn new(camera: Camera) -> Self {
        FrameParams {
            camera,
            exposure: 0.0,
            tonemap: Tonemap::Aces,
            background: [0.0; 3],
            view: ViewMode::Final,
            shadow_softness: 1.5,
            debug_level: 0,
            debug_direction: 0,
        }
    }
}

/// Largest image side voxgi renders (memory for the targets grows with its square).
pub const MAX_IMAGE_SIZE: u32 = 8192;

/// Checks an output size.
pub fn validate_size(width: u32, height: u32) -> Result<()> {
    if width == 0 || height == 0 || width > MAX_IMAGE_SIZE || height > MAX_IMAGE_SIZE {
        return Err(Error::Setting(format!(
            "image size {width}x{height} is outside 1x1..={MAX_IMAGE_SIZE}x{MAX_IMAGE_SIZE}"
        )));
    }
    Ok(())
}
