//! Every setting, once. The order is the order help texts and the viewer's panel list them,
//! and the order a scene file's or the command line's values are applied in.

use super::{Access, Changes, Domain, Setting, Value};
use crate::options::{
    ConeSet, DIRECTIONS, IndirectShading, ShadowFilter, Tonemap, UNLIMITED_BOUNCES, ViewMode,
    VoxelKind,
};

/// Reads and writes of one field, by the value kind of its domain.
macro_rules! access {
    (options bool $f:ident) => {
        Access::Options {
            get: |o| Value::Bool(o.$f),
            set: |o, v| {
                if let Value::Bool(b) = v {
                    o.$f = b;
                }
            },
        }
    };
    (options int $f:ident) => {
        Access::Options {
            get: |o| Value::Int(o.$f),
            set: |o, v| {
                if let Value::Int(n) = v {
                    o.$f = n;
                }
            },
        }
    };
    (options float $f:ident) => {
        Access::Options {
            get: |o| Value::Float(o.$f),
            set: |o, v| {
                if let Value::Float(x) = v {
                    o.$f = x;
                }
            },
        }
    };
    (options auto $f:ident) => {
        Access::Options {
            get: |o| Value::Auto(o.$f),
            set: |o, v| {
                if let Value::Auto(x) = v {
                    o.$f = x;
                }
            },
        }
    };
    (options $ty:ident $f:ident) => {
        Access::Options {
            get: |o| Value::Name(o.$f.name()),
            set: |o, v| {
                if let Value::Name(n) = v
                    && let Ok(x) = $ty::parse(n)
                {
                    o.$f = x;
                }
            },
        }
    };
    (frame float $f:ident) => {
        Access::Frame {
            get: |p| Value::Float(p.$f),
            set: |p, v| {
                if let Value::Float(x) = v {
                    p.$f = x;
                }
            },
        }
    };
    (frame $ty:ident $f:ident) => {
        Access::Frame {
            get: |p| Value::Name(p.$f.name()),
            set: |p, v| {
                if let Value::Name(n) = v
                    && let Ok(x) = $ty::parse(n)
                {
                    p.$f = x;
                }
            },
        }
    };
}

/// The settings: creation-time options first, then per-frame parameters.
pub static SETTINGS: &[Setting] = &[
    Setting {
        key: "voxels",
        label: "voxel structure",
        help: "The voxel structure: dense (the mip-mapped volume), octree (the sparse voxel \
               octree, memory in proportion to the occupied voxels) or clipmap (levels that \
               follow the camera, fine near it and coarse far away: large worlds).",
        domain: Domain::Choice(VoxelKind::names),
        changes: Changes::Voxels,
        access: Access::Options {
            get: |o| Value::Name(o.voxels.name()),
            set: |o, v| {
                if let Value::Name(n) = v
                    && let Ok(k) = VoxelKind::parse(n)
                {
                    o.voxels = k;
                }
            },
        },
    },
    Setting {
        key: "voxel_resolution",
        label: "voxels per side",
        help: "Voxels per side of the volume at the finest level.",
        domain: Domain::Resolution { min: 16 },
        changes: Changes::Voxels,
        access: access!(options int voxel_resolution),
    },
    Setting {
        key: "clipmap_levels",
        label: "clipmap levels",
        help: "The clipmap's levels, each twice the extent of the one inside it.",
        domain: Domain::Int { min: 2, max: 8 },
        changes: Changes::Voxels,
        access: access!(options int clipmap_levels),
    },
    Setting {
        key: "clipmap_budget",
        label: "clipmap windows a frame",
        help: "The most clipmap windows voxelized again in one frame as the camera moves (0: \
               every window that moved); the others wait at their places, still valid.",
        domain: Domain::Int { min: 0, max: 8 },
        changes: Changes::Frame,
        access: access!(options int clipmap_budget),
    },
    Setting {
        key: "voxel_size",
        label: "finest voxel (m)",
        help: "The clipmap's finest voxel edge in metres; auto: its coarsest level spans four \
               times the scene.",
        domain: Domain::Auto,
        changes: Changes::Voxels,
        access: access!(options auto voxel_size),
    },
    Setting {
        key: "anisotropic",
        label: "anisotropic voxels",
        help: "Six directional values per voxel above the finest level (false: one).",
        domain: Domain::Bool,
        changes: Changes::Voxels,
        access: access!(options bool anisotropic),
    },
    Setting {
        key: "ndf_mips",
        label: "leaves weighed by their normals (NDF)",
        help: "Weigh each leaf's radiance and opacity per direction by its normals in the first \
               directional level (after the point-cloud thesis' NDF): a face is not seen from \
               behind. Only anisotropic voxels have directions to weigh.",
        domain: Domain::Bool,
        changes: Changes::Voxels,
        access: access!(options bool ndf_mips),
    },
    Setting {
        key: "specular_bounces",
        label: "metals' reflections in the bounces",
        help: "Metals reflect the lights' light specularly into the voxels (a lobe per lit leaf, \
               kept up the voxels' levels beside the six directions): a wall facing a metal's \
               reflection is lit (0.86 of the path tracer's light on examples/metal-floor.toml). \
               Needs anisotropic voxels.",
        domain: Domain::Bool,
        changes: Changes::Voxels,
        access: access!(options bool specular_bounces),
    },
    Setting {
        key: "bounces",
        label: "bounces",
        help: "Indirect bounces: 0 (direct light only) to 8, or unlimited (until the energy \
               left is below 0.1 %).",
        domain: Domain::Bounces,
        changes: Changes::Lighting,
        access: access!(options int bounces),
    },
    Setting {
        key: "progressive",
        label: "progressive (one bounce per frame)",
        help: "One voxel bounce per frame on top of the last frame's light, converging to \
               unlimited bounces (sets bounces to unlimited).",
        domain: Domain::Bool,
        // The series starts from cleared radiance: a relight would build on the last light.
        changes: Changes::Voxels,
        access: Access::Options {
            get: |o| Value::Bool(o.progressive),
            set: |o, v| {
                if let Value::Bool(b) = v {
                    o.progressive = b;
                    if b {
                        o.bounces = UNLIMITED_BOUNCES;
                    }
                }
            },
        },
    },
    Setting {
        key: "cones",
        label: "diffuse cones",
        help: "The diffuse cone set: 6x60 (six cones of 60°), 7x45 or 9x45.",
        domain: Domain::Choice(|| ConeSet::ALL.iter().map(|c| c.name()).collect()),
        changes: Changes::Lighting,
        access: Access::Options {
            get: |o| Value::Name(o.cones.name()),
            set: |o, v| {
                if let Value::Name(n) = v
                    && let Some(c) = ConeSet::parse(n)
                {
                    o.cones = c;
                }
            },
        },
    },
    Setting {
        key: "indirect",
        label: "diffuse indirect",
        help: "Diffuse indirect light per pixel: cones (a cone bundle per pixel) or leaves (the \
               thesis' fast shading: the leaves' stored irradiance, interpolated).",
        domain: Domain::Choice(|| IndirectShading::ALL.map(IndirectShading::name).to_vec()),
        changes: Changes::Lighting,
        access: access!(options IndirectShading indirect),
    },
    Setting {
        key: "gather_axes",
        label: "gather axes",
        help: "Directional blocks per cone sample in the per-pixel gather: 3 (every axis by its \
               weight) or 2 (the two largest, faster).",
        domain: Domain::Int { min: 2, max: 3 },
        changes: Changes::Pipelines,
        access: access!(options int gather_axes),
    },
    Setting {
        key: "half_resolution",
        label: "half-resolution gather",
        help: "Gather indirect light at half resolution with an edge-aware upsample.",
        domain: Domain::Bool,
        changes: Changes::Pipelines,
        access: access!(options bool half_resolution),
    },
    Setting {
        key: "temporal",
        label: "temporal accumulation",
        help: "Jitter the camera and turn the cones every frame and accumulate the frames \
               (anti-aliasing, converged stills); off, every frame is a still of its own. \
               Area lights' shadows then sample points on the light, frame by frame (their \
               shadow maps are made anew).",
        domain: Domain::Bool,
        changes: Changes::Voxels,
        access: access!(options bool temporal),
    },
    Setting {
        key: "step_factor",
        label: "cone step",
        help: "Cone sample step as a fraction of the cone's diameter.",
        domain: Domain::Float {
            min: 0.05,
            max: 2.0,
        },
        changes: Changes::Lighting,
        access: access!(options float step_factor),
    },
    Setting {
        key: "cone_quarters",
        label: "cones trace quarters",
        help: "Each diffuse cone traces one quarter of its footprint, a different one from \
               pixel to pixel and frame to frame: nearer the path tracer where surfaces partly \
               cover the cones (the open Cornell box's walls and ceiling). False traces whole \
               footprints: about half the gather's time and less for the voxel bounces, with \
               the light beside openings too bright.",
        domain: Domain::Bool,
        changes: Changes::Lighting,
        access: access!(options bool cone_quarters),
    },
    Setting {
        key: "origin_offset",
        label: "cone origin offset (voxels)",
        help: "Cone origin offset along the normal, in finest voxels: keeps a cone from seeing \
               its own surface's voxels.",
        domain: Domain::Float { min: 0.0, max: 8.0 },
        changes: Changes::Lighting,
        access: access!(options float origin_offset),
    },
    Setting {
        key: "max_distance",
        label: "longest cone (m)",
        help: "Longest cone in metres; auto: the volume's diagonal.",
        domain: Domain::Auto,
        changes: Changes::Lighting,
        access: access!(options auto max_distance),
    },
    Setting {
        key: "ao_radius",
        label: "AO radius (m)",
        help: "Ambient-occlusion radius in metres; auto: a quarter of the volume.",
        domain: Domain::Auto,
        changes: Changes::Lighting,
        access: access!(options auto ao_radius),
    },
    Setting {
        key: "ao_lambda",
        label: "AO falloff (1/m)",
        help: "Ambient-occlusion falloff lambda in 1/(1 + lambda r), per metre; 0: plain \
               visibility within the radius, what the AO reference computes.",
        domain: Domain::Float {
            min: 0.0,
            max: 1000.0,
        },
        changes: Changes::Lighting,
        access: access!(options float ao_lambda),
    },
    Setting {
        key: "shadow_filter",
        label: "point, spot and sun shadows",
        help: "Shadow filter of point, spot and directional lights: pcf, or vsm-esm (the thesis' \
               prefiltered variance and exponential maps, the smaller visibility).",
        domain: Domain::Choice(|| ShadowFilter::ALL.map(ShadowFilter::name).to_vec()),
        changes: Changes::Voxels,
        access: access!(options ShadowFilter shadow_filter),
    },
    Setting {
        key: "shadow_map_size",
        label: "shadow map size",
        help: "Width and height of each shadow map, in texels.",
        domain: Domain::Int { min: 64, max: 8192 },
        changes: Changes::Voxels,
        access: access!(options int shadow_map_size),
    },
    Setting {
        key: "cone_shadows",
        label: "cone-traced area-light shadows",
        help: "Shadows of area lights by a cone traced through the voxels towards the light \
               instead of PCSS on the shadow map.",
        domain: Domain::Bool,
        changes: Changes::Voxels,
        access: access!(options bool cone_shadows),
    },
    Setting {
        key: "voxel_update_interval",
        label: "voxel update every k frames",
        help: "Voxel work on every k-th frame only; the voxels then trail moving meshes by up to \
               k - 1 frames (shadow maps follow every frame).",
        domain: Domain::Int { min: 1, max: 64 },
        changes: Changes::Frame,
        access: access!(options int voxel_update_interval),
    },
    Setting {
        key: "bounce_slices",
        label: "bounce: leaves gathering, 1 in k",
        help: "Voxel bounces gather at one leaf in k per update, in turns; the others keep the \
               light they last gathered; leaves near moved geometry gather at once. A moving \
               light costs a k-th of the bounces; the bounced light lags by up to k - 1 \
               updates and equals a full bounce's k updates (per voxel bounce) after the last \
               change.",
        domain: Domain::Int { min: 1, max: 16 },
        changes: Changes::Frame,
        access: access!(options int bounce_slices),
    },
    Setting {
        key: "max_texture_size",
        label: "largest material texture",
        help: "Largest material texture size; bigger textures are downsampled when the scene is \
               uploaded.",
        domain: Domain::Int { min: 1, max: 8192 },
        changes: Changes::Scene,
        access: access!(options int max_texture_size),
    },
    Setting {
        key: "default_light",
        label: "a sun when the scene has no light",
        help: "Add a sun when the scene has no light and nothing emissive, instead of rendering \
               black.",
        domain: Domain::Bool,
        changes: Changes::Scene,
        access: access!(options bool default_light),
    },
    Setting {
        key: "view",
        label: "view",
        help: "What to show; the voxel views ray-march the volume at voxel_level and show the \
               first voxel with opacity > 0.5.",
        domain: Domain::Choice(|| ViewMode::ALL.map(ViewMode::name).to_vec()),
        changes: Changes::Frame,
        access: access!(frame ViewMode view),
    },
    Setting {
        key: "voxel_level",
        label: "voxel level",
        help: "Mip level the voxel views show (0: the finest).",
        domain: Domain::Int { min: 0, max: 10 },
        changes: Changes::Frame,
        access: Access::Frame {
            get: |p| Value::Int(p.debug_level),
            set: |p, v| {
                if let Value::Int(n) = v {
                    p.debug_level = n;
                }
            },
        },
    },
    Setting {
        key: "voxel_dir",
        label: "voxel direction",
        help: "Directional chain the voxel views read above the finest level.",
        domain: Domain::Choice(|| DIRECTIONS.to_vec()),
        changes: Changes::Frame,
        access: Access::Frame {
            get: |p| Value::Name(DIRECTIONS[(p.debug_direction as usize).min(5)]),
            set: |p, v| {
                if let Value::Name(n) = v
                    && let Some(i) = DIRECTIONS.iter().position(|d| *d == n)
                {
                    p.debug_direction = i as u32;
                }
            },
        },
    },
    Setting {
        key: "exposure",
        label: "exposure (EV)",
        help: "Exposure in stops: the image is scaled by 2^EV before tone mapping.",
        domain: Domain::Float {
            min: -20.0,
            max: 20.0,
        },
        changes: Changes::Frame,
        access: access!(frame float exposure),
    },
    Setting {
        key: "tonemap",
        label: "tone map",
        help: "Tone-mapping curve: aces, neutral (Khronos PBR Neutral) or clamp (none, for \
               measurements).",
        domain: Domain::Choice(|| Tonemap::ALL.map(Tonemap::name).to_vec()),
        changes: Changes::Frame,
        access: access!(frame Tonemap tonemap),
    },
    Setting {
        key: "shadow_softness",
        label: "shadow softness (texels)",
        help: "Filter radius of point, spot and directional shadows, in shadow-map texels.",
        domain: Domain::Float {
            min: 0.0,
            max: 16.0,
        },
        changes: Changes::Frame,
        access: access!(frame float shadow_softness),
    },
    Setting {
        key: "background",
        label: "background",
        help: "Radiance where nothing is hit: linear r,g,b.",
        domain: Domain::Rgb,
        changes: Changes::Frame,
        access: Access::Frame {
            get: |p| Value::Rgb(p.background),
            set: |p, v| {
                if let Value::Rgb(c) = v {
                    p.background = c;
                }
            },
        },
    },
];
