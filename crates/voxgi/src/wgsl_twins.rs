//! Every `#[repr(C)]` struct shared with WGSL against its twin as naga lays it out: the size,
//! and each field's offset by name (a field in the wrong place, or missing on one side, fails).
//! Padding fields (`_…`) are left out of the comparison by name; the offsets around them and
//! the size still pin them. The octree's layout constants are checked against tree.wgsl's.

use crate::fragments::{GpuFragmentGrid, GpuRegion, TableSpan};
use crate::frame::uniforms::GpuFrame;
use crate::gpu::shader::compose;
use crate::gpu_scene::{GpuDraw, GpuLight, GpuMaterial, GpuPoint, GpuVertex};
use crate::lighting::atlas::GpuShadowView;
use crate::lighting::blend::GpuBlend;
use crate::lighting::bounce::GpuSlices;
use crate::lighting::cones::GpuCones;
use crate::lighting::inject::GpuInjectParams;
use crate::lighting::moments::GpuMomentRect;
use crate::reference::probe::ConeQuery;
use crate::reference::progressive::GpuDisplay;
use crate::reference::{GpuNode, GpuParams, GpuTri, GpuTriShading};
use crate::voxel::octree::{GpuAtlasShape, GpuOctree};
use crate::voxel::{GpuVolume, VoxelKind};
use std::mem::{offset_of, size_of};

fn module(src: &str) -> naga::Module {
    naga::front::wgsl::parse_str(src).unwrap_or_else(|e| panic!("{}", e.emit_to_string(src)))
}

/// The modules that between them define every twin.
fn modules() -> Vec<naga::Module> {
    let octree = crate::gpu::shader::compose_with(
        "voxels/octree/sample.wgsl",
        Some(VoxelKind::OCTREE.shaders()),
    );
    let inject =
        crate::gpu::shader::compose_with("lighting/inject.wgsl", Some(VoxelKind::DENSE.shaders()));
    let gather =
        crate::gpu::shader::compose_with("screen/gather.wgsl", Some(VoxelKind::DENSE.shaders()));
    let blend =
        crate::gpu::shader::compose_with("lighting/blend.wgsl", Some(VoxelKind::DENSE.shaders()));
    let bounce =
        crate::gpu::shader::compose_with("lighting/bounce.wgsl", Some(VoxelKind::DENSE.shaders()));
    let clipmap = crate::gpu::shader::compose_with(
        "voxels/clipmap/sample.wgsl",
        Some(VoxelKind::CLIPMAP.shaders()),
    );
    [
        compose("screen/composite.wgsl"),
        compose("screen/gbuffer.wgsl"),
        compose("fragments/voxelize.wgsl"),
        compose("lighting/moments.wgsl"),
        compose("reference.wgsl"),
        compose("reference_display.wgsl"),
        gather,
        blend,
        bounce,
        inject,
        octree,
        clipmap,
    ]
    .iter()
    .map(|s| module(s))
    .collect()
}

/// (members by name and offset, size) of WGSL struct `name`.
fn wgsl_struct(modules: &[naga::Module], name: &str) -> (Vec<(String, u32)>, u32) {
    modules
        .iter()
        .flat_map(|m| m.types.iter())
        .find_map(|(_, t)| match (&t.name, &t.inner) {
            (Some(n), naga::TypeInner::Struct { members, span }) if n == name => Some((
                members
                    .iter()
                    .map(|m| (m.name.clone().unwrap_or_default(), m.offset))
                    .collect(),
                *span,
            )),
            _ => None,
        })
        .unwrap_or_else(|| panic!("WGSL struct {name} not found"))
}

/// Checks Rust struct `$rust` against WGSL struct `$wgsl`: sizes, and for every listed field
/// the WGSL member of the same name (`$field = "name"` where the names differ) at the same
/// offset; every WGSL member that is not padding must be listed.
macro_rules! twin {
    ($m:expr, $rust:ty, $wgsl:literal, [$($field:ident $(= $name:literal)?),* $(,)?]) => {{
        let (members, span) = wgsl_struct($m, $wgsl);
        assert_eq!(
            span as usize,
            size_of::<$rust>(),
            "{}: WGSL {} bytes, Rust {}",
            $wgsl,
            span,
            size_of::<$rust>()
        );
        let mut listed: Vec<&str> = Vec::new();
        $(
            let name = twin!(@name $field $(= $name)?);
            listed.push(name);
            let (_, offset) = members
                .iter()
                .find(|(n, _)| n == name)
                .unwrap_or_else(|| panic!("{}: no WGSL member {name}", $wgsl));
            assert_eq!(
                *offset as usize,
                offset_of!($rust, $field),
                "{}.{name}: WGSL offset {offset}, Rust {}",
                $wgsl,
                offset_of!($rust, $field)
            );
        )*
        for (n, _) in &members {
            assert!(
                n.starts_with('_') || listed.contains(&n.as_str()),
                "{}: WGSL member {n} has no Rust field listed",
                $wgsl
            );
        }
    }};
    (@name $field:ident = $name:literal) => { $name };
    (@name $field:ident) => { stringify!($field) };
}

#[test]
fn every_twin_has_the_wgsl_layout() {
    let m = &modules();
    twin!(
        m,
        GpuFrame,
        "Frame",
        [
            view_proj,
            inv_view_proj,
            camera_pos,
            light_count,
            size,
            inv_size,
            exposure,
            tonemap,
            shadow_softness,
            view_mode,
            background,
            cone_shadows,
            geometry_points,
            jitter,
            prev_view_proj,
            view_proj_unjittered,
            prev_camera_pos,
            history,
            cone_turn,
            light_sample,
        ]
    );
    twin!(m, GpuVertex, "Vertex", [position, u, normal, v]);
    twin!(
        m,
        GpuBlend,
        "Blend",
        [weight, restart, from_bounce, store_all]
    );
    twin!(
        m,
        GpuSlices,
        "Slices",
        [count, turn, all, capacity, near_min, near_max, carry]
    );
    twin!(m, GpuDraw, "Draw", [model, normal_matrix, material, light]);
    twin!(
        m,
        GpuMaterial,
        "Material",
        [
            base_color,
            emissive,
            roughness,
            metallic,
            specular,
            base_texture,
            emissive_texture,
            alpha_cutoff,
            double_sided,
        ]
    );
    twin!(
        m,
        GpuPoint,
        "Point",
        [
            position,
            radius,
            normal,
            albedo_rg,
            albedo_b_emission_r,
            emission_gb,
        ]
    );
    twin!(
        m,
        GpuLight,
        "Light",
        [
            position,
            kind,
            direction,
            range,
            radiance,
            area,
            axis_u,
            cos_inner,
            axis_v,
            cos_outer,
            shadow_first,
            shadow_count,
            size,
            sample_first,
        ]
    );
    twin!(
        m,
        GpuShadowView,
        "ShadowView",
        [
            view_proj,
            inv_view_proj,
            origin,
            kind,
            dir,
            texel,
            near,
            far,
            resolution,
            layer,
            plane,
            offset,
        ]
    );
    twin!(
        m,
        GpuVolume,
        "Volume",
        [origin, resolution, voxel_size, levels, anisotropic, windows]
    );
    twin!(
        m,
        GpuCones,
        "Cones",
        [
            dirs,
            count,
            diffuse_tan,
            step_factor,
            max_distance,
            ao_lambda,
            ao_radius,
            origin_offset,
            indirect,
            quarters,
        ]
    );
    twin!(
        m,
        GpuFragmentGrid,
        "FragmentGrid",
        [origin, resolution, voxel_size, inv_voxel_size, z_offset]
    );
    twin!(m, GpuRegion, "FragmentRegion", [lo, hi, kept_lo, kept_hi]);
    twin!(
        m,
        TableSpan,
        "TableSpan",
        [small_first, small_count, large_first, large_count]
    );
    twin!(
        m,
        crate::voxel::clipmap::GpuClipLevels,
        "ClipLevels",
        [
            levels, scene_lo, scene_hi, bounds_lo, bounds_hi, count, resolution, rebuilt, kept,
            kept_by
        ]
    );
    twin!(
        m,
        GpuInjectParams,
        "InjectParams",
        [light_count, all, store_all, materials, moved_min, moved_max]
    );
    twin!(m, GpuMomentRect, "MomentRect", [min, max, layer, far]);
    twin!(
        m,
        GpuOctree,
        "Octree",
        [
            origin,
            resolution,
            voxel_size,
            depth,
            anisotropic,
            dirs,
            base_v,
            base_e,
            base_o,
            tiles,
            slots,
            ndf,
            lobes,
            leaf_atlas,
            even_atlas,
            odd_atlas,
        ]
    );
    twin!(m, GpuAtlasShape, "AtlasShape", [shift, block, z0, inv_size]);
    twin!(
        m,
        GpuParams,
        "Params",
        [
            inv_view_proj,
            background,
            light_count,
            width,
            height,
            x0,
            sample_count,
            seed,
            bounces,
            mode,
            ao_radius,
            rr_depth,
            x1,
            y0,
            y1,
        ]
    );
    twin!(m, GpuNode, "Node", [lo, first, hi, count]);
    twin!(m, GpuTri, "Tri", [p0, material, p1, light, p2, kind]);
    twin!(m, GpuTriShading, "TriShading", [n0, n1, n2, uv]);
    twin!(
        m,
        ConeQuery,
        "ConeQuery",
        [origin, tan_half, dir, max_distance, normal]
    );
    twin!(m, GpuDisplay, "Display", [exposure, tonemap, width]);
}

/// The octree's layout constants, which Rust and WGSL both define, agree.
#[test]
fn octree_constants_agree_with_the_wgsl() {
    for (name, rust) in crate::voxel::octree::SHARED_CONSTANTS {
        let wgsl = shader_constant("voxels/octree/octree_update.wgsl", VoxelKind::OCTREE, name);
        assert_eq!(wgsl, *rust, "{name}: WGSL and Rust differ");
    }
}

#[test]
fn dense_constants_agree_with_the_wgsl() {
    for (name, rust) in crate::voxel::dense::SHARED_CONSTANTS {
        let wgsl = shader_constant("voxels/dense/dense_update.wgsl", VoxelKind::DENSE, name);
        assert_eq!(wgsl, *rust, "{name}: WGSL and Rust differ");
    }
    // Every clipmap level is a window of the slot pool.
    let windows = shader_constant(
        "voxels/dense/dense_update.wgsl",
        VoxelKind::DENSE,
        "MAX_WINDOWS",
    );
    assert!(crate::voxel::clipmap::MAX_LEVELS as u64 <= windows);
}

/// The value of the literal `const` `name` in shader `file` composed for `kind`.
fn shader_constant(file: &str, kind: VoxelKind, name: &str) -> u64 {
    let m = module(&crate::gpu::shader::compose_with(
        file,
        Some(kind.shaders()),
    ));
    let (_, c) = m
        .constants
        .iter()
        .find(|(_, c)| c.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("{file}: no const {name}"));
    match m.global_expressions[c.init] {
        naga::Expression::Literal(naga::Literal::U32(v)) => v as u64,
        naga::Expression::Literal(naga::Literal::I32(v)) => v as u64,
        naga::Expression::Literal(naga::Literal::AbstractInt(v)) => v as u64,
        ref e => panic!("{file}: {name} = {e:?}"),
    }
}
