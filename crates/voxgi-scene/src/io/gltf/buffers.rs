//! Buffers and images: the GLB binary chunk, data URIs and external files, and decoding images
//! into textures.

use super::{R, io_reason};
use crate::Texture;
use std::path::Path;

pub(super) fn load_buffers(
    doc: &gltf::Document,
    base: &Path,
    blob: Option<&[u8]>,
) -> R<Vec<Vec<u8>>> {
    let mut out = Vec::new();
    for b in doc.buffers() {
        let i = b.index();
        let data = match b.source() {
            gltf::buffer::Source::Bin => blob
                .ok_or_else(|| {
                    format!("buffer {i}: refers to the GLB binary chunk, but the file has none")
                })?
                .to_vec(),
            gltf::buffer::Source::Uri(uri) => {
                read_uri(uri, base).map_err(|e| format!("buffer {i} ({}): {e}", short(uri)))?
            }
        };
        if data.len() < b.length() {
            return Err(format!(
                "buffer {i}: byteLength is {} but only {} bytes are present",
                b.length(),
                data.len()
            ));
        }
        out.push(data);
    }
    Ok(out)
}

/// A URI for messages: data URIs are cut short.
fn short(uri: &str) -> String {
    if uri.starts_with("data:") {
        let head: String = uri.chars().take(40).collect();
        format!("{head}...")
    } else {
        uri.to_string()
    }
}

fn read_uri(uri: &str, base: &Path) -> R<Vec<u8>> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (meta, payload) = rest
            .split_once(',')
            .ok_or("data URI without a ',' separator")?;
        if !meta.ends_with(";base64") {
            return Err("only base64 data URIs are supported".into());
        }
        return base64_decode(payload);
    }
    if uri.contains("://") {
        return Err("only relative file paths and data URIs are supported".into());
    }
    let rel = percent_decode(uri)?;
    let full = base.join(rel);
    crate::io::source::read(&full).map_err(|e| io_reason(&e))
}

fn percent_decode(s: &str) -> R<String> {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' {
            let hex = b
                .get(i + 1..i + 3)
                .and_then(|h| std::str::from_utf8(h).ok())
                .and_then(|h| u8::from_str_radix(h, 16).ok())
                .ok_or_else(|| format!("bad percent escape in URI '{s}'"))?;
            out.push(hex);
            i += 3;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    String::from_utf8(out).map_err(|_| format!("URI '{s}' is not UTF-8 after decoding"))
}

fn base64_decode(s: &str) -> R<Vec<u8>> {
    fn val(c: u8) -> Option<u32> {
        Some(match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            _ => return None,
        } as u32)
    }
    let mut out = Vec::with_capacity(s.len() / 4 * 3);
    let (mut acc, mut bits) = (0u32, 0u32);
    let mut padding = false;
    for &c in s.as_bytes() {
        if c.is_ascii_whitespace() {
            continue;
        }
        if c == b'=' {
            padding = true;
            continue;
        }
        if padding {
            return Err("invalid base64 in data URI (data after '=' padding)".into());
        }
        let v = val(c)
            .ok_or_else(|| format!("invalid base64 in data URI (character {:?})", char::from(c)))?;
        acc = (acc << 6) | v;
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    if bits >= 6 {
        return Err("invalid base64 in data URI (truncated)".into());
    }
    Ok(out)
}

pub(super) fn load_image(image: &gltf::Image, base: &Path, buffers: &[Vec<u8>]) -> R<Texture> {
    let i = image.index();
    let bytes: Vec<u8> = match image.source() {
        gltf::image::Source::View { view, .. } => view_bytes(&view, buffers)
            .map_err(|e| format!("image {i}: {e}"))?
            .to_vec(),
        gltf::image::Source::Uri { uri, .. } => {
            read_uri(uri, base).map_err(|e| format!("image {i} ({}): {e}", short(uri)))?
        }
    };
    let name = image
        .name()
        .map(str::to_string)
        .unwrap_or_else(|| format!("image {i}"));
    crate::io::texture::decode(&bytes, name).map_err(|e| format!("image {i}: {e}"))
}

pub(super) fn view_bytes<'b>(view: &gltf::buffer::View, buffers: &'b [Vec<u8>]) -> R<&'b [u8]> {
    let b = view.buffer().index();
    let data = &buffers[b];
    let start = view.offset();
    let end = start.checked_add(view.length());
    end.and_then(|end| data.get(start..end)).ok_or_else(|| {
        format!(
            "buffer view {} (bytes {start}..{start}+{}) extends beyond buffer {b} ({} bytes)",
            view.index(),
            view.length(),
            data.len()
        )
    })
}
