//! The bytes a glTF file's buffers and images point at: the GLB's binary
//! chunk, `data:` URIs (base64) or files beside the glTF. A file URI must
//! stay inside the glTF's folder (no absolute paths, no `..` out of it, no
//! links leading out) and exist; every error names the buffer or image.

use crate::input::{read_file, InputKind};
use std::path::{Component, Path, PathBuf};

/// The bytes of `uri` (a `data:` URI or a relative path) for `what`
/// ("buffer 2", "image 0"), read from `folder`.
pub fn read_uri(uri: &str, folder: &Path, what: &str, kind: InputKind) -> Result<Vec<u8>, String> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (_, data) = rest.split_once(";base64,").ok_or(format!("{what}: its data URI is not base64 (`data:...;base64,...`)"))?;
        return decode_base64(data).ok_or(format!("{what}: its data URI holds characters that are not base64"));
    }
    let path = confined(uri, folder).map_err(|e| format!("{what}: {e}"))?;
    read_file(&path, kind).map_err(|e| format!("{what}: {e}"))
}

/// `uri` as a path inside `folder`, or why it is refused.
fn confined(uri: &str, folder: &Path) -> Result<PathBuf, String> {
    let shown: String = uri.chars().take(80).collect();
    if uri.contains("://") || uri.starts_with('/') || uri.starts_with('\\') || uri.get(1..2) == Some(":") {
        return Err(format!("URI \"{shown}\" is not a relative path inside the glTF's folder"));
    }
    let decoded = percent_decode(uri).ok_or(format!("URI \"{shown}\" has a bad percent escape"))?;
    let relative = Path::new(&decoded);
    if relative.components().any(|c| !matches!(c, Component::Normal(_) | Component::CurDir)) {
        return Err(format!("URI \"{shown}\" points outside the glTF's folder"));
    }
    let path = folder.join(relative);
    let real = std::fs::canonicalize(&path).map_err(|e| format!("URI \"{shown}\" names {}, which cannot be read: {e}", path.display()))?;
    let root = std::fs::canonicalize(folder).unwrap_or_else(|_| folder.to_path_buf());
    if !real.starts_with(&root) {
        return Err(format!("URI \"{shown}\" leads (through a link) outside the glTF's folder"));
    }
    Ok(real)
}

fn percent_decode(s: &str) -> Option<String> {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' {
            let hex = std::str::from_utf8(b.get(i + 1..i + 3)?).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}

/// Standard base64 (padding optional), or `None` on a foreign character.
pub fn decode_base64(s: &str) -> Option<Vec<u8>> {
    let mut out = Vec::with_capacity(s.len() / 4 * 3 + 3);
    let (mut acc, mut bits) = (0u32, 0);
    for c in s.bytes() {
        let v = match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            b'=' => break,
            _ => return None,
        };
        acc = (acc << 6) | v as u32;
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_decodes_with_and_without_padding() {
        assert_eq!(decode_base64("aGVsbG8=").unwrap(), b"hello");
        assert_eq!(decode_base64("aGVsbG8").unwrap(), b"hello");
        assert!(decode_base64("a$b").is_none());
    }

    #[test]
    fn uris_leaving_the_folder_are_refused() {
        let dir = std::env::temp_dir();
        for uri in ["../x.bin", "/etc/passwd", "a/../../x.bin", "http://example.com/x.bin", "C:/x.bin", "%2e%2e/x.bin"] {
            let e = read_uri(uri, &dir, "buffer 0", InputKind::Mesh).err().unwrap_or_else(|| panic!("{uri}: accepted"));
            assert!(e.starts_with("buffer 0: ") && e.contains("URI"), "{uri}: {e}");
        }
    }
}
