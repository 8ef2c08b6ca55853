//! PCD, the Point Cloud Library's format (versions 0.5 to 0.7), with `ascii`, `binary` and
//! `binary_compressed` (LZF, fields one after another) data.
//!
//! Read: the fields `x y z` (required, any numeric type), `normal_x normal_y normal_z`, and the
//! colour packed in an `rgb` or `rgba` field (the bytes 0xRRGGBB of a 4-byte float or integer,
//! sRGB-encoded). Other fields (intensity, curvature, labels, ...) are skipped. `VIEWPOINT` is
//! the sensor's pose, not a transform of the points (PCL does not apply it either), so it is
//! ignored. Points without a finite position (an organized cloud marks missing depth so) are
//! dropped and counted in a log line; normals that are not all finite are dropped and left to
//! the renderer to estimate.
//!
//! As in the PLY parser, every count is checked against the bytes present before anything is
//! allocated, and a compressed block may claim at most what LZF can expand its bytes to.

use crate::{PointCloud, Result, Scene, SceneError, limits, srgb_to_linear};
use glam::{Mat4, Vec3};
use std::path::Path;

/// One field of a point: `count` values of `size` bytes of type `ty`.
#[derive(Clone, Debug)]
struct Field {
    name: String,
    size: usize,
    ty: u8,
    count: usize,
}

impl Field {
    fn bytes(&self) -> usize {
        self.size * self.count
    }

    /// Value `i` of this field, little-endian at the start of `b`.
    fn value(&self, b: &[u8]) -> f64 {
        let w = |n: usize| {
            let mut a = [0u8; 8];
            a[..n].copy_from_slice(&b[..n]);
            u64::from_le_bytes(a)
        };
        match (self.ty, self.size) {
            (b'F', 4) => f32::from_bits(w(4) as u32) as f64,
            (b'F', _) => f64::from_bits(w(8)),
            (b'U', n) => w(n) as f64,
            (b'I', 1) => w(1) as u8 as i8 as f64,
            (b'I', 2) => w(2) as u16 as i16 as f64,
            (b'I', 4) => w(4) as u32 as i32 as f64,
            (_, _) => w(8) as i64 as f64,
        }
    }

    /// The 32 bits of a packed colour field, little-endian at the start of `b`.
    fn bits(&self, b: &[u8]) -> u32 {
        u32::from_le_bytes([b[0], b[1], b[2], b[3]])
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Data {
    Ascii,
    Binary,
    Compressed,
}

struct Header {
    fields: Vec<Field>,
    points: usize,
    data: Data,
    /// Where the data starts.
    body: usize,
    /// The data's first line (1-based), for ASCII messages.
    body_line: usize,
}

/// The header: lines up to and including `DATA`.
fn parse_header(bytes: &[u8]) -> std::result::Result<Header, String> {
    let mut names: Vec<String> = Vec::new();
    let mut sizes: Vec<usize> = Vec::new();
    let mut types: Vec<u8> = Vec::new();
    let mut counts: Option<Vec<usize>> = None;
    let (mut width, mut height, mut points) = (None::<usize>, None::<usize>, None::<usize>);
    let mut pos = 0;
    let mut line_no = 0;
    while pos < bytes.len() {
        let end = bytes[pos..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(bytes.len(), |e| pos + e + 1);
        line_no += 1;
        let line = std::str::from_utf8(&bytes[pos..end])
            .map_err(|_| format!("header line {line_no} is not text"))?
            .trim();
        pos = end;
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let mut words = line.split_whitespace();
        let key = words.next().unwrap_or_default().to_ascii_uppercase();
        let rest: Vec<&str> = words.collect();
        let numbers = |what: &str| -> std::result::Result<Vec<usize>, String> {
            rest.iter()
                .map(|w| {
                    w.parse::<usize>()
                        .map_err(|_| format!("header line {line_no}: {what} '{w}' is not a count"))
                })
                .collect()
        };
        let one = |what: &str| -> std::result::Result<usize, String> {
            match numbers(what)?.as_slice() {
                [n] => Ok(*n),
                _ => Err(format!("header line {line_no}: {what} takes one number")),
            }
        };
        match key.as_str() {
            "VERSION" | "VIEWPOINT" => {}
            "FIELDS" | "COLUMNS" => names = rest.iter().map(|s| s.to_string()).collect(),
            "SIZE" => sizes = numbers("SIZE")?,
            "TYPE" => {
                types = rest
                    .iter()
                    .map(|t| match t.to_ascii_uppercase().as_str() {
                        "F" => Ok(b'F'),
                        "U" => Ok(b'U'),
                        "I" => Ok(b'I'),
                        _ => Err(format!(
                            "header line {line_no}: TYPE '{t}' is none of F, U, I"
                        )),
                    })
                    .collect::<std::result::Result<_, _>>()?
            }
            "COUNT" => counts = Some(numbers("COUNT")?),
            "WIDTH" => width = Some(one("WIDTH")?),
            "HEIGHT" => height = Some(one("HEIGHT")?),
            "POINTS" => points = Some(one("POINTS")?),
            "DATA" => {
                let data = match rest.first().map(|d| d.to_ascii_lowercase()).as_deref() {
                    Some("ascii") => Data::Ascii,
                    Some("binary") => Data::Binary,
                    Some("binary_compressed") => Data::Compressed,
                    other => {
                        return Err(format!(
                            "header line {line_no}: DATA '{}' is none of ascii, binary, \
                             binary_compressed",
                            other.unwrap_or_default()
                        ));
                    }
                };
                let n = names.len();
                if n == 0 {
                    return Err("the header has no FIELDS".into());
                }
                let counts = counts.unwrap_or_else(|| vec![1; n]);
                if sizes.len() != n || types.len() != n || counts.len() != n {
                    return Err(format!(
                        "the header's FIELDS ({n}), SIZE ({}), TYPE ({}) and COUNT ({}) differ \
                         in length",
                        sizes.len(),
                        types.len(),
                        counts.len()
                    ));
                }
                let mut fields = Vec::with_capacity(n);
                for i in 0..n {
                    let (ty, size) = (types[i], sizes[i]);
                    let ok = match ty {
                        b'F' => size == 4 || size == 8,
                        _ => matches!(size, 1 | 2 | 4 | 8),
                    };
                    if !ok {
                        return Err(format!(
                            "field '{}': type {} of {size} bytes is not a PCD type",
                            names[i], ty as char
                        ));
                    }
                    if counts[i] == 0 {
                        return Err(format!("field '{}': COUNT 0", names[i]));
                    }
                    if counts[i] > 1 << 16 {
                        return Err(format!(
                            "field '{}': COUNT {} is more than {}",
                            names[i],
                            counts[i],
                            1 << 16
                        ));
                    }
                    fields.push(Field {
                        name: names[i].clone(),
                        size,
                        ty,
                        count: counts[i],
                    });
                }
                let area = match (width, height) {
                    (Some(w), h) => Some(
                        w.checked_mul(h.unwrap_or(1))
                            .ok_or("WIDTH × HEIGHT overflows")?,
                    ),
                    _ => None,
                };
                let points = match (points, area) {
                    (Some(p), Some(a)) if p != a => {
                        return Err(format!("POINTS {p} differs from WIDTH × HEIGHT = {a}"));
                    }
                    (Some(p), _) | (None, Some(p)) => p,
                    (None, None) => return Err("the header has neither POINTS nor WIDTH".into()),
                };
                if points > limits::MAX_ELEMENTS {
                    return Err(format!(
                        "{points} points, more than voxgi's limit of {}",
                        limits::MAX_ELEMENTS
                    ));
                }
                return Ok(Header {
                    fields,
                    points,
                    data,
                    body: pos,
                    body_line: line_no + 1,
                });
            }
            other => {
                return Err(format!(
                    "header line {line_no}: '{other}' is not a PCD header keyword (not a PCD file?)"
                ));
            }
        }
    }
    Err("the header ends without a DATA line".into())
}

pub fn load(path: &Path) -> Result<Scene> {
    let bytes = super::source::read(path).map_err(|e| SceneError::load(path, e))?;
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "pcd".into());
    parse(&bytes, &name, &path.display().to_string())
        .map_err(|reason| SceneError::load(path, reason))
}

/// Parses a whole PCD file into a scene called `name`; errors do not name the file (the caller
/// adds it), log lines name it `file`.
pub fn parse(bytes: &[u8], name: &str, file: &str) -> std::result::Result<Scene, String> {
    let h = parse_header(bytes)?;
    let find = |names: &[&str]| {
        h.fields
            .iter()
            .position(|f| names.iter().any(|n| f.name.eq_ignore_ascii_case(n)))
    };
    let (Some(x), Some(y), Some(z)) = (find(&["x"]), find(&["y"]), find(&["z"])) else {
        return Err("the fields lack one of x, y, z".into());
    };
    let normal = match (
        find(&["normal_x"]),
        find(&["normal_y"]),
        find(&["normal_z"]),
    ) {
        (Some(a), Some(b), Some(c)) => Some([a, b, c]),
        _ => None,
    };
    let color = find(&["rgb", "rgba"]);
    if let Some(c) = color
        && h.fields[c].size != 4
    {
        return Err(format!(
            "field '{}' is {} bytes; a packed colour is 4",
            h.fields[c].name, h.fields[c].size
        ));
    }

    let n = h.points;
    let record: usize = h.fields.iter().map(Field::bytes).sum();
    // Per field, its first value's bytes for every point, as (bytes, stride): the binary data
    // interleaves the fields, the compressed data stores them one after another.
    let decompressed;
    let mut ascii_values: Vec<f64> = Vec::new();
    let mut ascii_bits: Vec<u32> = Vec::new();
    let body = &bytes[h.body..];
    let columns: Vec<(&[u8], usize)> = match h.data {
        Data::Ascii => Vec::new(),
        Data::Binary => {
            let need = n
                .checked_mul(record)
                .ok_or("the declared points overflow the file size")?;
            if body.len() < need {
                return Err(format!(
                    "the binary data holds {} of the {n} points the header declares",
                    body.len() / record.max(1)
                ));
            }
            if body.len() > need {
                log::warn!(
                    "{file}: {} bytes after the last point the header declares, ignored",
                    body.len() - need
                );
            }
            let mut at = 0;
            // Point p's field at `at + p * record`, within `need` for p < n (none for n = 0).
            h.fields
                .iter()
                .map(|f| {
                    let c = (body.get(at..need).unwrap_or_default(), record);
                    at += f.bytes();
                    c
                })
                .collect()
        }
        Data::Compressed => {
            if body.len() < 8 {
                return Err("binary_compressed data lacks its two sizes".into());
            }
            let packed = u32::from_le_bytes(body[0..4].try_into().unwrap()) as usize;
            let unpacked = u32::from_le_bytes(body[4..8].try_into().unwrap()) as usize;
            let need = n
                .checked_mul(record)
                .ok_or("the declared points overflow the file size")?;
            if unpacked != need {
                return Err(format!(
                    "binary_compressed data unpacks to {unpacked} bytes, not the {need} of \
                     {n} points of {record} bytes"
                ));
            }
            if packed > body.len() - 8 {
                return Err(format!(
                    "binary_compressed data is {packed} bytes, but the file holds {}",
                    body.len() - 8
                ));
            }
            // An LZF back-reference writes at most 264 bytes from 3.
            if unpacked > 88 * packed + 32 {
                return Err(format!(
                    "binary_compressed data claims {unpacked} bytes from {packed}, more than \
                     LZF expands to"
                ));
            }
            decompressed = if unpacked == 0 {
                Vec::new()
            } else {
                lzf::decompress(&body[8..8 + packed], unpacked)
                    .map_err(|e| format!("binary_compressed data is corrupt ({e:?})"))?
            };
            if decompressed.len() != unpacked {
                return Err(format!(
                    "binary_compressed data unpacks to {} bytes, not {unpacked}",
                    decompressed.len()
                ));
            }
            let mut at = 0;
            h.fields
                .iter()
                .map(|f| {
                    let len = f.bytes() * n;
                    let c = (&decompressed[at..at + len], f.bytes());
                    at += len;
                    c
                })
                .collect()
        }
    };
    if h.data == Data::Ascii {
        // Only the fields read are kept: x, y, z, the normal's three, the colour's bits.
        let text = std::str::from_utf8(body)
            .map_err(|_| "the ASCII data is not valid text".to_string())?;
        let per_point: usize = h.fields.iter().map(|f| f.count).sum();
        let mut lines = text
            .lines()
            .enumerate()
            .filter(|(_, l)| !l.trim().is_empty());
        // Bounded by the lines present, not by the header's claim.
        ascii_values.reserve(n.min(text.len() / 2 + 1) * 6);
        for p in 0..n {
            let Some((i, line)) = lines.next() else {
                return Err(format!(
                    "the ASCII data holds {p} of the {n} points the header declares"
                ));
            };
            let line_no = h.body_line + i;
            let tokens: Vec<&str> = line.split_whitespace().collect();
            if tokens.len() != per_point {
                return Err(format!(
                    "line {line_no}: {} values, the fields make {per_point}",
                    tokens.len()
                ));
            }
            let mut t = 0;
            for (k, f) in h.fields.iter().enumerate() {
                let first = tokens[t];
                t += f.count;
                let wanted = k == x || k == y || k == z || normal.is_some_and(|nm| nm.contains(&k));
                if Some(k) == color {
                    // PCL writes a float colour's value, an integer one's number.
                    let bits = if f.ty == b'F' {
                        first.parse::<f32>().ok().map(f32::to_bits)
                    } else {
                        first.parse::<i64>().ok().map(|v| v as u32)
                    }
                    .ok_or_else(|| format!("line {line_no}: colour '{first}' is not a number"))?;
                    ascii_bits.push(bits);
                } else if wanted {
                    let v = first.parse::<f64>().map_err(|_| {
                        format!("line {line_no}: '{first}' ({}) is not a number", f.name)
                    })?;
                    ascii_values.push(v);
                }
            }
        }
        if lines.next().is_some() {
            log::warn!("{file}: lines after the last point the header declares, ignored");
        }
    }

    // Field `k`'s first value of point `p`, from the binary columns or the ASCII values (in
    // the order the fields come, x y z and the normal's three kept).
    let kept: Vec<usize> = {
        let mut k = vec![x, y, z];
        if let Some(nm) = normal {
            k.extend(nm);
        }
        k.sort_unstable();
        k
    };
    let value = |k: usize, p: usize| -> f64 {
        if h.data == Data::Ascii {
            let slot = kept.iter().position(|&q| q == k).expect("a kept field");
            ascii_values[p * kept.len() + slot]
        } else {
            let (col, stride) = columns[k];
            h.fields[k].value(&col[p * stride..])
        }
    };
    let bits = |p: usize| -> Option<u32> {
        let c = color?;
        Some(if h.data == Data::Ascii {
            ascii_bits[p]
        } else {
            let (col, stride) = columns[c];
            h.fields[c].bits(&col[p * stride..])
        })
    };

    let mut positions = Vec::with_capacity(n);
    let mut normals = Vec::with_capacity(if normal.is_some() { n } else { 0 });
    let mut colors = Vec::with_capacity(n);
    let mut missing = 0usize;
    let mut bad_normals = 0usize;
    for p in 0..n {
        let pos = Vec3::new(value(x, p) as f32, value(y, p) as f32, value(z, p) as f32);
        if !pos.is_finite() {
            missing += 1;
            continue;
        }
        positions.push(pos);
        if let Some([a, b, c]) = normal {
            let v = Vec3::new(value(a, p) as f32, value(b, p) as f32, value(c, p) as f32);
            if !v.is_finite() || v == Vec3::ZERO {
                bad_normals += 1;
            }
            normals.push(v.normalize_or_zero());
        }
        colors.push(match bits(p) {
            Some(b) => [16, 8, 0].map(|s| srgb_to_linear(((b >> s) & 0xff) as f32 / 255.0)),
            None => [0.8; 3],
        });
    }
    if missing > 0 {
        log::info!(
            "{file}: {missing} of {n} points have no finite position (missing depth), dropped"
        );
    }
    if bad_normals > 0 {
        log::warn!(
            "{file}: {bad_normals} points have no usable normal: normals are estimated instead"
        );
        normals.clear();
    }
    if positions.is_empty() {
        return Err(if n == 0 {
            "contains no points".into()
        } else {
            format!("none of its {n} points has a finite position")
        });
    }
    let mut scene = Scene {
        name: name.into(),
        ..Default::default()
    };
    scene.point_clouds.push(PointCloud {
        name: name.into(),
        positions,
        colors,
        normals,
        radii: Vec::new(),
        regions: Vec::new(),
        emission: Vec::new(),
        transform: Mat4::IDENTITY,
        dynamic: false,
        light: None,
    });
    Ok(scene)
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEADER: &str = "VERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F U\n\
                          COUNT 1 1 1 1\nWIDTH 3\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\n";

    fn points() -> [([f32; 3], u32); 3] {
        [
            ([0.0, 1.0, 2.0], 0xff0000),
            ([f32::NAN, 0.0, 0.0], 0x00ff00),
            ([-1.5, 0.25, 3.0], 0x0000ff),
        ]
    }

    fn binary_record(p: &([f32; 3], u32)) -> Vec<u8> {
        let mut b = Vec::new();
        for v in p.0 {
            b.extend(v.to_le_bytes());
        }
        b.extend(p.1.to_le_bytes());
        b
    }

    /// The two finite points, red and blue, in order.
    fn check(s: &Scene) {
        let pc = &s.point_clouds[0];
        assert_eq!(
            pc.positions,
            vec![Vec3::new(0.0, 1.0, 2.0), Vec3::new(-1.5, 0.25, 3.0)]
        );
        assert_eq!(pc.colors, vec![[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]);
        assert!(pc.normals.is_empty());
    }

    #[test]
    fn ascii_binary_and_compressed_data_give_the_same_points() {
        let mut ascii = format!("# a comment\n{HEADER}DATA ascii\n");
        for (p, c) in points() {
            ascii += &format!("{} {} {} {c}\n", p[0], p[1], p[2]);
        }
        check(&parse(ascii.as_bytes(), "a", "a.pcd").unwrap());

        let mut binary = format!("{HEADER}DATA binary\n").into_bytes();
        for p in &points() {
            binary.extend(binary_record(p));
        }
        check(&parse(&binary, "b", "b.pcd").unwrap());

        // Fields one after another, then LZF.
        let mut columns = Vec::new();
        for k in 0..4 {
            for p in &points() {
                columns.extend(&binary_record(p)[4 * k..4 * k + 4]);
            }
        }
        let packed = lzf::compress(&columns).unwrap_or_else(|_| {
            // Too small to compress: LZF's literal runs (a length byte, then the bytes).
            let mut l = Vec::new();
            for chunk in columns.chunks(32) {
                l.push(chunk.len() as u8 - 1);
                l.extend(chunk);
            }
            l
        });
        let mut compressed = format!("{HEADER}DATA binary_compressed\n").into_bytes();
        compressed.extend((packed.len() as u32).to_le_bytes());
        compressed.extend((columns.len() as u32).to_le_bytes());
        compressed.extend(&packed);
        check(&parse(&compressed, "c", "c.pcd").unwrap());
    }

    #[test]
    fn bad_headers_and_short_data_are_errors_naming_the_cause() {
        let err = |bytes: &[u8]| parse(bytes, "x", "x.pcd").unwrap_err();
        let no_z = "FIELDS x y\nSIZE 4 4\nTYPE F F\nPOINTS 1\nDATA ascii\n1 2\n";
        assert!(err(no_z.as_bytes()).contains("x, y, z"));
        let sizes = "FIELDS x y z\nSIZE 4 4\nTYPE F F F\nPOINTS 1\nDATA ascii\n";
        assert!(err(sizes.as_bytes()).contains("differ in length"));
        let f2 = "FIELDS x y z\nSIZE 2 4 4\nTYPE F F F\nPOINTS 1\nDATA ascii\n";
        assert!(err(f2.as_bytes()).contains("not a PCD type"));
        let mismatch = "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 2\nPOINTS 3\nDATA ascii\n";
        assert!(err(mismatch.as_bytes()).contains("WIDTH × HEIGHT"));
        let short = "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 2\nDATA ascii\n1 2 3\n";
        assert!(err(short.as_bytes()).contains("1 of the 2 points"));
        let huge = "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 1000000000\nDATA binary\n";
        assert!(err(huge.as_bytes()).contains("more than voxgi's limit"));
        let claim = "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 1000000\nDATA binary\n";
        assert!(err(claim.as_bytes()).contains("holds 0 of the 1000000 points"));
        let mut bomb = b"FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 100000000\n\
                         DATA binary_compressed\n"
            .to_vec();
        bomb.extend(4u32.to_le_bytes());
        bomb.extend(1_200_000_000u32.to_le_bytes());
        bomb.extend([0, 0, 0, 0]);
        assert!(err(&bomb).contains("more than LZF expands to"));
        assert!(err(b"ply\nformat ascii 1.0\n").contains("not a PCD header keyword"));
        assert!(err(b"FIELDS x y z\n").contains("without a DATA line"));
        // Fuzzing finding: binary data of no points sliced its fields past the end.
        let none = "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 0\nDATA binary\n";
        assert!(err(none.as_bytes()).contains("contains no points"));
        let zero = "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 0 1\nPOINTS 1\nDATA ascii\n1 2\n";
        assert!(err(zero.as_bytes()).contains("COUNT 0"));
        let text = "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 1\nDATA ascii\n1 two 3\n";
        assert!(err(text.as_bytes()).contains("line 6: 'two' (y) is not a number"));
    }
}
