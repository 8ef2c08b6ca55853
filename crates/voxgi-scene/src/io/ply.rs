//! PLY (Stanford polygon format), ASCII and binary little/big endian.
//!
//! This is a small parser of our own rather than `ply-rs-bw`. That crate caps its
//! preallocation, but it builds a key-value map per vertex by default (slow and memory-hungry
//! for 254k-point clouds unless one implements its `PropertyAccess` traits per element type),
//! its errors carry no line or element numbers, and it has no notion of checking declared counts
//! against the file size. Here every count is checked against the bytes that remain before
//! anything is allocated (a header may claim 2^40 vertices), list lengths are bounded by the
//! bytes or tokens left, and messages name the line (ASCII) or element index.
//!
//! Read: `vertex` element with `x y z` (float or double), optional `nx ny nz`, optional colour
//! `red green blue` or `diffuse_red ...` (integer types are sRGB-encoded and scaled by the type's
//! maximum, floats are linear in [0, 1]), optional `radius`, optional emitted radiance
//! `emission_red emission_green emission_blue` (or `emission_r ...`; linear W/(m² sr), any
//! numeric type; point clouds only, a mesh takes its emission from its material); `face` element with a
//! `vertex_indices` or `vertex_index` list (polygons become triangle fans). Other elements and
//! properties are parsed and skipped. With faces the result is a mesh, without a point cloud.

use crate::{
    Instance, Material, Mesh, PointCloud, Result, Scene, SceneError, compute_normals, limits,
    srgb_to_linear,
};
use glam::{Mat4, Vec3};
use std::path::Path;

#[derive(Clone, Copy, Debug, PartialEq)]
enum Ty {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Ty {
    fn parse(s: &str) -> Option<Ty> {
        Some(match s {
            "char" | "int8" => Ty::I8,
            "uchar" | "uint8" => Ty::U8,
            "short" | "int16" => Ty::I16,
            "ushort" | "uint16" => Ty::U16,
            "int" | "int32" => Ty::I32,
            "uint" | "uint32" => Ty::U32,
            "float" | "float32" => Ty::F32,
            "double" | "float64" => Ty::F64,
            _ => return None,
        })
    }
    fn size(self) -> usize {
        match self {
            Ty::I8 | Ty::U8 => 1,
            Ty::I16 | Ty::U16 => 2,
            Ty::I32 | Ty::U32 | Ty::F32 => 4,
            Ty::F64 => 8,
        }
    }
    fn is_float(self) -> bool {
        matches!(self, Ty::F32 | Ty::F64)
    }
    /// Largest value of an integer type (colour normalisation).
    fn max(self) -> f64 {
        match self {
            Ty::I8 => 127.0,
            Ty::U8 => 255.0,
            Ty::I16 => 32767.0,
            Ty::U16 => 65535.0,
            Ty::I32 => i32::MAX as f64,
            Ty::U32 => u32::MAX as f64,
            Ty::F32 | Ty::F64 => 1.0,
        }
    }
    /// Smallest value of an integer type.
    fn min(self) -> f64 {
        match self {
            Ty::I8 => -128.0,
            Ty::I16 => -32768.0,
            Ty::I32 => i32::MIN as f64,
            _ => 0.0,
        }
    }
    fn name(self) -> &'static str {
        match self {
            Ty::I8 => "char",
            Ty::U8 => "uchar",
            Ty::I16 => "short",
            Ty::U16 => "ushort",
            Ty::I32 => "int",
            Ty::U32 => "uint",
            Ty::F32 => "float",
            Ty::F64 => "double",
        }
    }
}

#[derive(Clone, Debug)]
struct Property {
    name: String,
    ty: Ty,
    /// `Some(count type)` for list properties; `ty` is then the item type.
    list: Option<Ty>,
}

#[derive(Clone, Debug)]
struct Element {
    name: String,
    count: usize,
    props: Vec<Property>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Format {
    Ascii,
    Le,
    Be,
}

struct Header {
    format: Format,
    elements: Vec<Element>,
    /// Byte offset of the body.
    body: usize,
    /// Line number (1-based) of the first body line, for ASCII messages.
    body_line: usize,
}

fn parse_header(bytes: &[u8]) -> std::result::Result<Header, String> {
    if bytes.is_empty() {
        return Err("empty file".into());
    }
    if !(bytes.starts_with(b"ply\n") || bytes.starts_with(b"ply\r\n")) {
        return Err("not a PLY file (first line is not 'ply')".into());
    }
    let mut pos = 0;
    let mut line_no = 0;
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    loop {
        let Some(len) = bytes[pos..].iter().position(|&b| b == b'\n') else {
            return Err("header has no 'end_header' line".into());
        };
        let raw = &bytes[pos..pos + len];
        pos += len + 1;
        line_no += 1;
        let line = std::str::from_utf8(raw)
            .map_err(|_| format!("header line {line_no} is not text"))?
            .trim();
        let words: Vec<&str> = line.split_whitespace().collect();
        let bad = || format!("header line {line_no}: cannot parse '{line}'");
        match words.first().copied() {
            Some("ply") if line_no == 1 => {}
            Some("comment") | Some("obj_info") | None => {}
            Some("format") => {
                format = Some(match words.get(1).copied() {
                    Some("ascii") => Format::Ascii,
                    Some("binary_little_endian") => Format::Le,
                    Some("binary_big_endian") => Format::Be,
                    _ => return Err(format!("header line {line_no}: unknown format '{line}'")),
                });
            }
            Some("element") => {
                let [_, name, count] = words[..] else {
                    return Err(bad());
                };
                let count: u64 = count.parse().map_err(|_| {
                    format!("header line {line_no}: element count '{count}' is not a number")
                })?;
                if count > limits::MAX_ELEMENTS as u64 {
                    return Err(format!(
                        "header line {line_no}: element '{name}' claims {count} entries, more than the limit of {}",
                        limits::MAX_ELEMENTS
                    ));
                }
                elements.push(Element {
                    name: name.into(),
                    count: count as usize,
                    props: Vec::new(),
                });
            }
            Some("property") => {
                let el = elements
                    .last_mut()
                    .ok_or_else(|| format!("header line {line_no}: property before any element"))?;
                let prop = match words[..] {
                    [_, "list", ct, it, name] => Property {
                        name: name.into(),
                        ty: Ty::parse(it).ok_or_else(bad)?,
                        list: Some(Ty::parse(ct).ok_or_else(bad)?),
                    },
                    [_, ty, name] => Property {
                        name: name.into(),
                        ty: Ty::parse(ty).ok_or_else(|| {
                            format!("header line {line_no}: unknown property type '{ty}'")
                        })?,
                        list: None,
                    },
                    _ => return Err(bad()),
                };
                if prop.list.is_some_and(|t| t.is_float()) {
                    return Err(format!(
                        "header line {line_no}: list count type must be an integer"
                    ));
                }
                el.props.push(prop);
            }
            Some("end_header") => break,
            Some(_) => return Err(format!("header line {line_no}: unknown keyword '{line}'")),
        }
    }
    let format = format.ok_or("header has no 'format' line")?;
    // Reject counts that cannot fit the rest of the file before anything is allocated.
    let remaining = (bytes.len() - pos) as u128;
    let mut needed: u128 = 0;
    for el in &elements {
        let min_record: u128 = match format {
            Format::Ascii => 2 * el.props.len() as u128, // a digit and a separator per value
            _ => el
                .props
                .iter()
                .map(|p| p.list.unwrap_or(p.ty).size() as u128)
                .sum(),
        };
        needed += min_record * el.count as u128;
    }
    // ASCII: the very last value may lack its trailing separator.
    let slack = if format == Format::Ascii { 1 } else { 0 };
    if needed > remaining + slack {
        return Err(format!(
            "header declares {} but the body has only {remaining} bytes (need at least {needed}); truncated file or corrupt counts",
            elements
                .iter()
                .map(|e| format!("{} {}", e.count, e.name))
                .collect::<Vec<_>>()
                .join(", ")
        ));
    }
    Ok(Header {
        format,
        elements,
        body: pos,
        body_line: line_no + 1,
    })
}

/// Sequential reader of property values from the body.
enum Body<'a> {
    Ascii {
        lines: std::iter::Enumerate<std::str::Lines<'a>>,
        first_line: usize,
        tokens: Vec<&'a str>,
        next: usize,
        line: usize,
    },
    Binary {
        bytes: &'a [u8],
        pos: usize,
        big: bool,
    },
}

impl<'a> Body<'a> {
    /// Starts a new record (ASCII: the next non-empty line).
    fn begin_record(&mut self, what: &str) -> std::result::Result<(), String> {
        if let Body::Ascii {
            lines,
            first_line,
            tokens,
            next,
            line,
        } = self
        {
            loop {
                let Some((i, l)) = lines.next() else {
                    return Err(format!("file ends before {what}"));
                };
                *line = *first_line + i;
                tokens.clear();
                tokens.extend(l.split_whitespace());
                *next = 0;
                if !tokens.is_empty() {
                    return Ok(());
                }
            }
        }
        Ok(())
    }

    fn value(&mut self, ty: Ty, what: &str) -> std::result::Result<f64, String> {
        match self {
            Body::Ascii {
                tokens, next, line, ..
            } => {
                let Some(tok) = tokens.get(*next) else {
                    return Err(format!("line {line}: too few values for {what}"));
                };
                *next += 1;
                let v: f64 = tok
                    .parse()
                    .map_err(|_| format!("line {line}: '{tok}' is not a number ({what})"))?;
                if !ty.is_float() && v.fract() != 0.0 {
                    return Err(format!("line {line}: '{tok}' is not an integer ({what})"));
                }
                // A binary value always fits its type; text can say anything.
                if !ty.is_float() && !(ty.min()..=ty.max()).contains(&v) {
                    return Err(format!(
                        "line {line}: {tok} is out of the range of its type {} ({what})",
                        ty.name()
                    ));
                }
                Ok(v)
            }
            Body::Binary { bytes, pos, big } => {
                let n = ty.size();
                let Some(b) = bytes.get(*pos..*pos + n) else {
                    return Err(format!("file is truncated in {what}"));
                };
                *pos += n;
                let mut a = [0u8; 8];
                a[..n].copy_from_slice(b);
                if *big {
                    a[..n].reverse();
                }
                Ok(match ty {
                    Ty::I8 => a[0] as i8 as f64,
                    Ty::U8 => a[0] as f64,
                    Ty::I16 => i16::from_le_bytes([a[0], a[1]]) as f64,
                    Ty::U16 => u16::from_le_bytes([a[0], a[1]]) as f64,
                    Ty::I32 => i32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
                    Ty::U32 => u32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
                    Ty::F32 => f32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
                    Ty::F64 => f64::from_le_bytes(a),
                })
            }
        }
    }

    /// What is left after the last element: bytes (binary) or non-empty lines (ASCII).
    fn trailing(&mut self) -> usize {
        match self {
            Body::Ascii { lines, .. } => lines.filter(|(_, l)| !l.trim().is_empty()).count(),
            Body::Binary { bytes, pos, .. } => bytes.len() - *pos,
        }
    }

    /// Bytes (binary) or tokens (ASCII) left, to bound list lengths before reading them.
    fn room(&self) -> usize {
        match self {
            Body::Ascii { tokens, next, .. } => tokens.len().saturating_sub(*next),
            Body::Binary { bytes, pos, .. } => bytes.len() - pos,
        }
    }
}

/// Roles of vertex properties.
#[derive(Default)]
struct VertexLayout {
    pos: [Option<usize>; 3],
    normal: [Option<usize>; 3],
    color: [Option<usize>; 3],
    emission: [Option<usize>; 3],
    radius: Option<usize>,
}

pub fn load(path: &Path) -> Result<Scene> {
    let bytes = super::source::read(path).map_err(|e| SceneError::load(path, e))?;
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "ply".into());
    parse(&bytes, &name, &path.display().to_string())
        .map_err(|reason| SceneError::load(path, reason))
}

/// Parses a whole PLY file into a scene called `name`; errors do not name the file (the caller
/// adds it), warnings name it `file`.
pub fn parse(bytes: &[u8], name: &str, file: &str) -> std::result::Result<Scene, String> {
    let h = parse_header(bytes)?;
    let mut body = match h.format {
        Format::Ascii => {
            let text = std::str::from_utf8(&bytes[h.body..])
                .map_err(|_| "ASCII body is not valid text".to_string())?;
            Body::Ascii {
                lines: text.lines().enumerate(),
                first_line: h.body_line,
                tokens: Vec::new(),
                next: 0,
                line: h.body_line,
            }
        }
        f => Body::Binary {
            bytes: &bytes[h.body..],
            pos: 0,
            big: f == Format::Be,
        },
    };

    let vertex_el = h.elements.iter().position(|e| e.name == "vertex");
    let Some(vertex_el) = vertex_el else {
        return Err("no 'vertex' element".into());
    };
    let mut layout = VertexLayout::default();
    let mut color_ty = [Ty::U8; 3];
    for (i, p) in h.elements[vertex_el].props.iter().enumerate() {
        if p.list.is_some() {
            continue;
        }
        let slot = |s: &mut [Option<usize>; 3], k: usize| s[k] = Some(i);
        match p.name.as_str() {
            "x" => slot(&mut layout.pos, 0),
            "y" => slot(&mut layout.pos, 1),
            "z" => slot(&mut layout.pos, 2),
            "nx" => slot(&mut layout.normal, 0),
            "ny" => slot(&mut layout.normal, 1),
            "nz" => slot(&mut layout.normal, 2),
            "red" | "diffuse_red" | "r" => {
                slot(&mut layout.color, 0);
                color_ty[0] = p.ty;
            }
            "green" | "diffuse_green" | "g" => {
                slot(&mut layout.color, 1);
                color_ty[1] = p.ty;
            }
            "blue" | "diffuse_blue" | "b" => {
                slot(&mut layout.color, 2);
                color_ty[2] = p.ty;
            }
            "emission_red" | "emission_r" => slot(&mut layout.emission, 0),
            "emission_green" | "emission_g" => slot(&mut layout.emission, 1),
            "emission_blue" | "emission_b" => slot(&mut layout.emission, 2),
            "radius" => layout.radius = Some(i),
            _ => {}
        }
    }
    let [Some(_), Some(_), Some(_)] = layout.pos else {
        return Err("vertex element lacks one of the x, y, z properties".into());
    };
    let has_normals = layout.normal.iter().all(Option::is_some);
    let has_colors = layout.color.iter().all(Option::is_some);
    let has_emission = layout.emission.iter().all(Option::is_some);
    if !has_emission && layout.emission.iter().any(Option::is_some) {
        return Err("vertex element has some but not all of the emission_red, \
                    emission_green, emission_blue properties"
            .into());
    }

    let nv = h.elements[vertex_el].count;
    let mut positions = Vec::with_capacity(nv);
    let mut normals = Vec::with_capacity(if has_normals { nv } else { 0 });
    let mut colors = Vec::with_capacity(if has_colors { nv } else { 0 });
    let mut radii = Vec::with_capacity(if layout.radius.is_some() { nv } else { 0 });
    let mut emission = Vec::with_capacity(if has_emission { nv } else { 0 });
    let mut indices: Vec<u32> = Vec::new();
    let mut face_count = 0usize;
    let mut skipped_faces = 0usize;
    let mut bright_colors = 0usize;
    let mut values: Vec<f64> = Vec::new();
    let mut list: Vec<f64> = Vec::new();
    // Faces are checked against the vertex count once all elements are read (PLY allows any order).
    for (ei, el) in h.elements.iter().enumerate() {
        let face_prop = (el.name == "face")
            .then(|| {
                el.props.iter().position(|p| {
                    p.list.is_some() && (p.name == "vertex_indices" || p.name == "vertex_index")
                })
            })
            .flatten();
        if el.name == "face" && face_prop.is_none() && el.count > 0 {
            return Err("face element has no 'vertex_indices' list".into());
        }
        if el.props.is_empty() {
            // Nothing to read; do not spin through a (possibly huge) declared count.
            continue;
        }
        for r in 0..el.count {
            let what = format!("{} {r}", el.name);
            body.begin_record(&what)?;
            values.clear();
            for (pi, p) in el.props.iter().enumerate() {
                match p.list {
                    None => values.push(body.value(p.ty, &what)?),
                    Some(ct) => {
                        let n = body.value(ct, &what)?;
                        if n < 0.0 {
                            return Err(format!("{what}: negative list length {n}"));
                        }
                        let n = n as usize;
                        let fits = match body {
                            Body::Binary { .. } => n.saturating_mul(p.ty.size()) <= body.room(),
                            Body::Ascii { .. } => n <= body.room(),
                        };
                        if !fits {
                            return Err(format!(
                                "{what}: list of {n} entries runs past the end of the {}",
                                if h.format == Format::Ascii {
                                    "line"
                                } else {
                                    "file"
                                }
                            ));
                        }
                        let keep = Some(pi) == face_prop;
                        if keep {
                            list.clear();
                        }
                        for _ in 0..n {
                            let v = body.value(p.ty, &what)?;
                            if keep {
                                list.push(v);
                            }
                        }
                        values.push(0.0);
                    }
                }
            }
            if ei == vertex_el {
                let get = |k: Option<usize>| values[k.unwrap()];
                let p = Vec3::new(
                    get(layout.pos[0]) as f32,
                    get(layout.pos[1]) as f32,
                    get(layout.pos[2]) as f32,
                );
                if !p.is_finite() {
                    return Err(format!("vertex {r}: non-finite position"));
                }
                positions.push(p);
                if has_normals {
                    let n = Vec3::new(
                        get(layout.normal[0]) as f32,
                        get(layout.normal[1]) as f32,
                        get(layout.normal[2]) as f32,
                    );
                    normals.push(n.normalize_or_zero());
                }
                if has_colors {
                    let mut c = [0f32; 3];
                    for k in 0..3 {
                        let v = get(layout.color[k]);
                        c[k] = if color_ty[k].is_float() {
                            if !(v.is_finite() && v >= 0.0) {
                                return Err(format!(
                                    "vertex {r}: colour {v} is not a reflectance >= 0"
                                ));
                            }
                            if v > 1.0 {
                                bright_colors += 1;
                            }
                            v.min(1.0) as f32
                        } else {
                            srgb_to_linear((v / color_ty[k].max()).clamp(0.0, 1.0) as f32)
                        };
                    }
                    colors.push(c);
                }
                if let Some(k) = layout.radius {
                    radii.push(values[k] as f32);
                }
                if has_emission {
                    let e = [0, 1, 2].map(|k| get(layout.emission[k]) as f32);
                    if e.iter().any(|v| !v.is_finite() || *v < 0.0) {
                        return Err(format!(
                            "vertex {r}: emission {e:?} is not a finite radiance >= 0"
                        ));
                    }
                    emission.push(e);
                }
            } else if face_prop.is_some() {
                if list.len() < 3 {
                    skipped_faces += 1;
                    continue;
                }
                for &v in &list {
                    // Written so that NaN (possible with float index lists) is rejected too.
                    if !(v >= 0.0 && v < nv as f64) {
                        return Err(format!(
                            "face {r}: vertex index {v} out of range ({nv} vertices)"
                        ));
                    }
                }
                for k in 1..list.len() - 1 {
                    indices.extend_from_slice(&[
                        list[0] as u32,
                        list[k] as u32,
                        list[k + 1] as u32,
                    ]);
                }
                face_count += 1;
            }
        }
    }
    if skipped_faces > 0 {
        log::warn!("{file}: skipped {skipped_faces} faces with fewer than 3 vertices");
    }
    if bright_colors > 0 {
        log::warn!(
            "{file}: {bright_colors} float colour values above 1 (a surface reflects at most \
             all the light) clamped to 1"
        );
    }
    let trailing = body.trailing();
    if trailing > 0 {
        let what = if h.format == Format::Ascii {
            "lines"
        } else {
            "bytes"
        };
        log::warn!(
            "{file}: {trailing} {what} after the last element the header declares, ignored \
             (a wrong count in the header?)"
        );
    }
    let has_face_element = h.elements.iter().any(|e| e.name == "face" && e.count > 0);
    let mut scene = Scene {
        name: name.into(),
        ..Default::default()
    };
    if has_face_element {
        if face_count == 0 {
            return Err("contains no triangles (every face has fewer than 3 vertices)".into());
        }
        // Fall back to computed normals for vertices whose file normal is zero.
        let normals = if has_normals {
            let computed = compute_normals(&positions, &indices);
            normals
                .iter()
                .zip(&computed)
                .map(|(n, c)| if *n == Vec3::ZERO { *c } else { *n })
                .collect()
        } else {
            compute_normals(&positions, &indices)
        };
        scene.meshes.push(Mesh {
            name: name.into(),
            positions,
            normals,
            uvs: Vec::new(),
            indices,
            material: 0,
        });
        scene.materials.push(Material::default());
        scene.instances.push(Instance {
            name: name.into(),
            mesh: 0,
            transform: Mat4::IDENTITY,
            dynamic: false,
            light: None,
        });
    } else {
        if positions.is_empty() {
            return Err("contains no vertices".into());
        }
        let n = positions.len();
        scene.point_clouds.push(PointCloud {
            name: name.into(),
            positions,
            colors: if has_colors {
                colors
            } else {
                vec![[0.8; 3]; n]
            },
            normals,
            radii,
            regions: Vec::new(),
            emission,
            transform: Mat4::IDENTITY,
            dynamic: false,
            light: None,
        });
    }
    Ok(scene)
}
