//! PLY meshes (ASCII, binary little-endian and binary big-endian), read to
//! the format's specification by a small streaming reader.
//!
//! The header's element counts are never trusted: storage is reserved for
//! at most as many elements as the bytes after the header can hold, and
//! reading past the end is an error naming the element and its byte
//! offset. Vertices give positions (`x y z`), optional normals
//! (`nx ny nz`), uvs (`u v`, `s t`, `texture_u texture_v` or
//! `texture_s texture_t`) and colours (`red green blue`, read but not
//! drawn); faces (`vertex_indices` or `vertex_index`, a list of any count
//! and index types) of any size are split into a fan of triangles. Other
//! elements and properties are read past.

use crate::input::{InputKind, MAX_COORDINATE};
use crate::math::{Vec2, Vec3};
use crate::scene::assets::read_asset;
use crate::scene::obj::{smooth_normals, LoadedMesh, NormalMode};
use crate::scene::{Triangle, Triangles};
use std::path::Path;

/// Longest header accepted: real headers are a few hundred bytes.
const MAX_HEADER_BYTES: usize = 64 << 10;
/// Most properties one element may declare.
const MAX_PROPERTIES: usize = 256;

/// How the data after the header is written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    Ascii,
    LittleEndian,
    BigEndian,
}

/// A PLY scalar type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(name: &str) -> Option<Scalar> {
        Some(match name {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    fn is_integer(self) -> bool {
        !matches!(self, Scalar::F32 | Scalar::F64)
    }

    /// The smallest and largest value of an integer type.
    fn range(self) -> (f64, f64) {
        match self {
            Scalar::I8 => (i8::MIN as f64, i8::MAX as f64),
            Scalar::U8 => (0.0, u8::MAX as f64),
            Scalar::I16 => (i16::MIN as f64, i16::MAX as f64),
            Scalar::U16 => (0.0, u16::MAX as f64),
            Scalar::I32 => (i32::MIN as f64, i32::MAX as f64),
            Scalar::U32 => (0.0, u32::MAX as f64),
            Scalar::F32 => (f32::MIN as f64, f32::MAX as f64),
            Scalar::F64 => (f64::MIN, f64::MAX),
        }
    }
}

#[derive(Clone, Debug)]
enum Property {
    Scalar(Scalar),
    List { count: Scalar, item: Scalar },
}

#[derive(Clone, Debug)]
struct Element {
    name: String,
    count: u64,
    properties: Vec<(String, Property)>,
}

impl Element {
    /// Fewest bytes one element can take: one byte per property in ASCII
    /// (a digit; separators aside), its scalars and list counts in binary.
    fn min_size(&self, format: Format) -> usize {
        self.properties
            .iter()
            .map(|(_, p)| match (format, p) {
                (Format::Ascii, _) => 1,
                (_, Property::Scalar(s)) => s.size(),
                (_, Property::List { count, .. }) => count.size(),
            })
            .sum()
    }

    fn index_of(&self, names: &[&str]) -> Option<usize> {
        self.properties.iter().position(|(n, _)| names.contains(&n.as_str()))
    }
}

/// The header: format, elements in file order, and where the data starts.
struct Header {
    format: Format,
    elements: Vec<Element>,
    data_start: usize,
}

fn parse_header(bytes: &[u8]) -> Result<Header, String> {
    if !(bytes.starts_with(b"ply\n") || bytes.starts_with(b"ply\r\n")) {
        return Err("it does not start with the line `ply`, so it is not a PLY file".into());
    }
    let window = &bytes[..bytes.len().min(MAX_HEADER_BYTES)];
    let end = find_end_header(window).ok_or(format!("no `end_header` line in its first {MAX_HEADER_BYTES} bytes"))?;
    let text = std::str::from_utf8(&bytes[..end.0]).map_err(|_| "its header is not text".to_string())?;
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    for (i, line) in text.lines().enumerate().skip(1) {
        let line_no = i + 1;
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            [] | ["comment", ..] | ["obj_info", ..] => {}
            ["format", kind, version] => {
                if !version.starts_with('1') {
                    return Err(format!("header line {line_no}: format version {} is not 1.0", shorten(version)));
                }
                format = Some(match *kind {
                    "ascii" => Format::Ascii,
                    "binary_little_endian" => Format::LittleEndian,
                    "binary_big_endian" => Format::BigEndian,
                    other => return Err(format!("header line {line_no}: unknown format \"{}\"", shorten(other))),
                });
            }
            ["element", name, count] => {
                let count: u64 = count
                    .parse()
                    .map_err(|_| format!("header line {line_no}: element \"{}\" has count \"{}\", not a whole number", shorten(name), shorten(count)))?;
                elements.push(Element { name: shorten(name), count, properties: Vec::new() });
            }
            ["property", "list", count, item, name] => {
                let element = elements.last_mut().ok_or(format!("header line {line_no}: a property before any element"))?;
                let (Some(count), Some(item)) = (Scalar::parse(count), Scalar::parse(item)) else {
                    return Err(format!("header line {line_no}: unknown type in `property list {} {}`", shorten(count), shorten(item)));
                };
                if !count.is_integer() {
                    return Err(format!("header line {line_no}: a list's count must have an integer type"));
                }
                element.properties.push((shorten(name), Property::List { count, item }));
            }
            ["property", ty, name] => {
                let element = elements.last_mut().ok_or(format!("header line {line_no}: a property before any element"))?;
                let ty = Scalar::parse(ty).ok_or(format!("header line {line_no}: unknown property type \"{}\"", shorten(ty)))?;
                element.properties.push((shorten(name), Property::Scalar(ty)));
            }
            ["end_header"] => break,
            _ => return Err(format!("header line {line_no}: cannot read `{}`", shorten(line.trim()))),
        }
        if elements.last().is_some_and(|e| e.properties.len() > MAX_PROPERTIES) {
            return Err(format!("header line {line_no}: an element has more than {MAX_PROPERTIES} properties"));
        }
    }
    let format = format.ok_or("its header has no `format` line")?;
    Ok(Header { format, elements, data_start: end.1 })
}

/// The byte where the `end_header` line starts and the byte after its end.
fn find_end_header(bytes: &[u8]) -> Option<(usize, usize)> {
    let mut start = 0;
    while start < bytes.len() {
        let end = bytes[start..].iter().position(|&b| b == b'\n').map(|k| start + k);
        let line = &bytes[start..end.unwrap_or(bytes.len())];
        let line = line.strip_suffix(b"\r").unwrap_or(line);
        if line.trim_ascii() == b"end_header" {
            return Some((start, end.map_or(bytes.len(), |e| e + 1)));
        }
        start = end? + 1;
    }
    None
}

fn shorten(s: &str) -> String {
    s.chars().take(40).collect()
}

/// Reads values one after another from the data after the header.
struct Reader<'a> {
    bytes: &'a [u8],
    pos: usize,
    format: Format,
    /// ASCII only: the rest of the current element's line.
    line: std::ops::Range<usize>,
}

impl<'a> Reader<'a> {
    /// Starts the next element: in ASCII, the next non-blank line.
    fn begin(&mut self) -> Result<(), String> {
        if self.format != Format::Ascii {
            return Ok(());
        }
        loop {
            if self.pos >= self.bytes.len() {
                return Err("the file ends here".into());
            }
            let end = self.bytes[self.pos..].iter().position(|&b| b == b'\n').map_or(self.bytes.len(), |k| self.pos + k);
            let line = self.pos..end;
            self.pos = (end + 1).min(self.bytes.len());
            if !self.bytes[line.clone()].trim_ascii().is_empty() {
                self.line = line;
                return Ok(());
            }
        }
    }

    /// Ends the element: in ASCII, nothing may be left on its line.
    fn end(&mut self) -> Result<(), String> {
        if self.format == Format::Ascii && !self.bytes[self.line.clone()].trim_ascii().is_empty() {
            return Err("its line holds more values than the header's properties".into());
        }
        Ok(())
    }

    fn value(&mut self, ty: Scalar) -> Result<f64, String> {
        match self.format {
            Format::Ascii => {
                let rest = &self.bytes[self.line.clone()];
                let skip = rest.iter().take_while(|b| b.is_ascii_whitespace()).count();
                let len = rest[skip..].iter().take_while(|b| !b.is_ascii_whitespace()).count();
                if len == 0 {
                    return Err("its line holds fewer values than the header's properties".into());
                }
                let word = &rest[skip..skip + len];
                self.line.start += skip + len;
                let text = std::str::from_utf8(word).unwrap_or("");
                let v: f64 = text.parse().map_err(|_| format!("\"{}\" is not a number", shorten(&String::from_utf8_lossy(word))))?;
                let (lo, hi) = ty.range();
                if ty.is_integer() && (v.fract() != 0.0 || v < lo || v > hi) {
                    return Err(format!("\"{}\" is not a value of its integer type", shorten(text)));
                }
                Ok(v)
            }
            _ => {
                let n = ty.size();
                let Some(b) = self.bytes.get(self.pos..self.pos + n) else {
                    return Err("the file ends inside it".into());
                };
                self.pos += n;
                let mut a = [0u8; 8];
                a[..n].copy_from_slice(b);
                if self.format == Format::BigEndian {
                    a[..n].reverse();
                }
                Ok(match ty {
                    Scalar::I8 => a[0] as i8 as f64,
                    Scalar::U8 => a[0] as f64,
                    Scalar::I16 => i16::from_le_bytes([a[0], a[1]]) as f64,
                    Scalar::U16 => u16::from_le_bytes([a[0], a[1]]) as f64,
                    Scalar::I32 => i32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
                    Scalar::U32 => u32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
                    Scalar::F32 => f32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
                    Scalar::F64 => f64::from_le_bytes(a),
                })
            }
        }
    }

    /// Bytes not yet read.
    fn remaining(&self) -> usize {
        self.bytes.len() - self.pos
    }
}

/// What a PLY file holds that pinhole draws: per-vertex attributes and the
/// faces split into triangles.
pub struct PlyMesh {
    pub positions: Vec<Vec3>,
    pub normals: Option<Vec<Vec3>>,
    pub uvs: Option<Vec<Vec2>>,
    /// Whether the vertices carry colours (read, not drawn).
    pub colours: bool,
    pub triangles: Vec<[u32; 3]>,
    /// Faces with fewer than three corners.
    pub short_faces: usize,
    /// Elements other than vertices and faces, read past.
    pub ignored: Vec<String>,
    /// Bytes after the last element the header declares.
    pub trailing_bytes: usize,
}

/// Parses a whole PLY file. Errors are one sentence without the file's
/// name, naming the element, its index and the byte offset.
pub fn parse_ply(bytes: &[u8]) -> Result<PlyMesh, String> {
    let header = parse_header(bytes)?;
    let format = header.format;
    let vertex_count = header.elements.iter().find(|e| e.name == "vertex").map(|e| e.count).ok_or("its header declares no `vertex` element")?;
    let mut mesh = PlyMesh {
        positions: Vec::new(),
        normals: None,
        uvs: None,
        colours: false,
        triangles: Vec::new(),
        short_faces: 0,
        ignored: Vec::new(),
        trailing_bytes: 0,
    };
    let mut r = Reader { bytes, pos: header.data_start, format, line: 0..0 };
    let mut seen_vertices = false;
    let mut seen_faces = false;
    for element in &header.elements {
        let min = element.min_size(format);
        let room = if min == 0 { u64::MAX } else { (r.remaining() / min) as u64 };
        if element.count > room {
            return Err(format!(
                "its header declares {} `{}` elements but only {} bytes of data follow (byte {}), room for at most {room}",
                element.count,
                element.name,
                r.remaining(),
                r.pos
            ));
        }
        let count = element.count as usize;
        if element.name == "vertex" && !seen_vertices {
            seen_vertices = true;
            read_vertices(&mut r, element, count, &mut mesh)?;
        } else if element.name == "face" && !seen_faces {
            seen_faces = true;
            read_faces(&mut r, element, count, vertex_count, &mut mesh)?;
        } else {
            if element.count > 0 {
                mesh.ignored.push(format!("{} `{}`", element.count, element.name));
            }
            for i in 0..count {
                read_element(&mut r, element, i, |_, _, _| Ok(()))?;
            }
        }
    }
    mesh.trailing_bytes = match format {
        Format::Ascii => bytes[r.pos..].trim_ascii().len(),
        _ => r.remaining(),
    };
    Ok(mesh)
}

/// Reads element `index` of `element`, handing each scalar property to
/// `scalar(property index, value)` and each list's items to it one by one
/// (`Some(item index)`); errors name the element and the byte offset.
fn read_element(
    r: &mut Reader,
    element: &Element,
    index: usize,
    mut take: impl FnMut(usize, Option<usize>, f64) -> Result<(), String>,
) -> Result<(), String> {
    let start = r.pos;
    let at = |e: String| format!("{} {index} (byte {start}): {e}", element.name);
    r.begin().map_err(at)?;
    for (p, (_, property)) in element.properties.iter().enumerate() {
        match *property {
            Property::Scalar(ty) => {
                let v = r.value(ty).map_err(at)?;
                take(p, None, v).map_err(at)?;
            }
            Property::List { count, item } => {
                let n = r.value(count).map_err(at)?;
                if n < 0.0 {
                    return Err(at(format!("a list has {n} items")));
                }
                let n = n as usize;
                // Each item takes at least a byte of the line, or its size.
                let room = if r.format == Format::Ascii { r.line.len() } else { r.remaining() / item.size() };
                if n > room {
                    return Err(at(format!("a list of {n} items runs past the end of the file")));
                }
                for k in 0..n {
                    let v = r.value(item).map_err(at)?;
                    take(p, Some(k), v).map_err(at)?;
                }
            }
        }
    }
    r.end().map_err(at)
}

fn read_vertices(r: &mut Reader, element: &Element, count: usize, mesh: &mut PlyMesh) -> Result<(), String> {
    let scalar = |names: &[&str]| -> Result<Option<usize>, String> {
        match element.index_of(names) {
            Some(i) if matches!(element.properties[i].1, Property::List { .. }) => Err(format!("the vertex property `{}` is a list, not a number", names[0])),
            other => Ok(other),
        }
    };
    let (Some(x), Some(y), Some(z)) = (scalar(&["x"])?, scalar(&["y"])?, scalar(&["z"])?) else {
        return Err("its `vertex` element lacks one of the properties x, y and z".into());
    };
    let normal = match (scalar(&["nx"])?, scalar(&["ny"])?, scalar(&["nz"])?) {
        (Some(a), Some(b), Some(c)) => Some([a, b, c]),
        _ => None,
    };
    let uv = [["u", "v"], ["s", "t"], ["texture_u", "texture_v"], ["texture_s", "texture_t"]]
        .iter()
        .find_map(|[a, b]| Some([element.index_of(&[a])?, element.index_of(&[b])?]))
        .filter(|uv| uv.iter().all(|&i| matches!(element.properties[i].1, Property::Scalar(_))));
    mesh.colours = ["red", "green", "blue"].iter().all(|c| element.index_of(&[c]).is_some());
    mesh.positions = Vec::with_capacity(count);
    let mut normals = normal.map(|_| Vec::with_capacity(count));
    let mut uvs = uv.map(|_| Vec::with_capacity(count));
    let mut values = vec![0.0f64; element.properties.len()];
    for i in 0..count {
        let start = r.pos;
        read_element(r, element, i, |p, item, v| {
            if item.is_none() {
                values[p] = v;
            }
            Ok(())
        })?;
        let p = Vec3::new(values[x] as f32, values[y] as f32, values[z] as f32);
        if !(p.abs().max_element() <= MAX_COORDINATE) {
            return Err(format!("vertex {i} (byte {start}): position {p} is not finite or out of range; coordinates must be between -{MAX_COORDINATE:e} and {MAX_COORDINATE:e}"));
        }
        mesh.positions.push(p);
        if let (Some(ns), Some([a, b, c])) = (&mut normals, normal) {
            let n = Vec3::new(values[a] as f32, values[b] as f32, values[c] as f32);
            ns.push(if n.is_finite() { n } else { Vec3::ZERO });
        }
        if let (Some(ts), Some([a, b])) = (&mut uvs, uv) {
            let t = Vec2::new(values[a] as f32, values[b] as f32);
            ts.push(if t.is_finite() { t } else { Vec2::ZERO });
        }
    }
    mesh.normals = normals;
    mesh.uvs = uvs;
    Ok(())
}

fn read_faces(r: &mut Reader, element: &Element, count: usize, vertex_count: u64, mesh: &mut PlyMesh) -> Result<(), String> {
    let list = element.index_of(&["vertex_indices", "vertex_index"]).ok_or("its `face` element has no `vertex_indices` list")?;
    if !matches!(element.properties[list].1, Property::List { .. }) {
        return Err("the face property `vertex_indices` is a number, not a list".into());
    }
    mesh.triangles = Vec::with_capacity(count);
    let mut corners: Vec<u32> = Vec::new();
    for i in 0..count {
        corners.clear();
        read_element(r, element, i, |p, item, v| {
            if p == list && item.is_some() {
                if !(v >= 0.0 && v < vertex_count as f64) {
                    return Err(format!("vertex index {v} is beyond the {vertex_count} vertices the file declares"));
                }
                corners.push(v as u32);
            }
            Ok(())
        })?;
        if corners.len() < 3 {
            mesh.short_faces += 1;
            continue;
        }
        for k in 1..corners.len() - 1 {
            mesh.triangles.push([corners[0], corners[k], corners[k + 1]]);
        }
    }
    Ok(())
}

/// A PLY file as a mesh, normals chosen by `mode` as for an OBJ.
pub fn load_ply(path: &Path, mode: NormalMode) -> Result<LoadedMesh, String> {
    let name = path.display();
    let bytes = read_asset(path, InputKind::Mesh).map_err(|e| format!("cannot read PLY {e}"))?;
    let ply = parse_ply(&bytes).map_err(|e| format!("{name}: {e}"))?;
    let mut warnings = Vec::new();
    if ply.colours {
        warnings.push(format!("{name}: its vertex colours are not drawn (pinhole has no per-vertex colour)"));
    }
    if !ply.ignored.is_empty() {
        warnings.push(format!("{name}: ignored its elements {}", ply.ignored.join(", ")));
    }
    if ply.trailing_bytes > 0 {
        warnings.push(format!("{name}: {} bytes after the last element its header declares were ignored", ply.trailing_bytes));
    }
    if ply.short_faces > 0 {
        warnings.push(format!("{name}: skipped {} faces with fewer than three corners", ply.short_faces));
    }
    let indices: Vec<u32> = ply.triangles.iter().flatten().copied().collect();
    let pos = &ply.positions;
    let use_file_normals = ply.normals.is_some() && mode == NormalMode::Auto;
    let smooth = (mode == NormalMode::Smooth || (mode == NormalMode::Auto && ply.normals.is_none())).then(|| smooth_normals(pos, &indices));
    let mut triangles = Triangles::new();
    let mut vertex_corner = vec![u32::MAX; pos.len()];
    let mut degenerate = 0;
    for idx in &ply.triangles {
        let v = idx.map(|i| pos[i as usize]);
        // Skip triangles whose normal cannot be formed; they cover no area.
        let Some(geo) = Triangle::normal_if_not_degenerate(&v) else {
            degenerate += 1;
            continue;
        };
        let corner = |k: usize| -> Vec3 {
            let i = idx[k] as usize;
            match (&ply.normals, &smooth) {
                (Some(ns), _) if use_file_normals => ns[i].normalize_or(geo),
                (_, Some(s)) => s[i].normalize_or(geo),
                _ => geo,
            }
        };
        let uv = |k: usize| ply.uvs.as_ref().map_or(Vec2::ZERO, |u| u[idx[k] as usize]);
        let t = Triangle { v, n: [corner(0), corner(1), corner(2)], uv: [uv(0), uv(1), uv(2)], material: u32::MAX, object: 0, two_sided: false };
        // Every attribute is the vertex's own, so corners are found by vertex.
        triangles.push_keyed(t, idx.map(|i| i as usize), &mut vertex_corner);
    }
    if triangles.is_empty() {
        return Err(format!("{name}: the PLY has no triangles with area"));
    }
    triangles.share_corners();
    Ok(LoadedMesh { triangles, materials: Vec::new(), degenerate, warnings })
}

#[cfg(test)]
mod tests {
    use super::*;

    const SQUARE: &str = "ply\nformat ascii 1.0\ncomment a unit square\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty float s\nproperty float t\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0 0 0\n1 0 0 1 0\n1 1 0 1 1\n0 1 0 0 1\n4 0 1 2 3\n";

    #[test]
    fn ascii_square_is_a_fan_of_two_triangles_with_uvs() {
        let m = parse_ply(SQUARE.as_bytes()).unwrap();
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(m.uvs.unwrap()[2], Vec2::new(1.0, 1.0));
        assert!(m.normals.is_none());
    }

    #[test]
    fn lying_counts_truncation_and_bad_indices_are_refused_with_the_place() {
        let lie = SQUARE.replace("element vertex 4", "element vertex 4000000000");
        let e = parse_ply(lie.as_bytes()).err().unwrap();
        assert!(e.contains("4000000000") && e.contains("vertex") && e.contains("byte"), "{e}");
        let cut = &SQUARE[..SQUARE.len() - 4];
        let e = parse_ply(cut.as_bytes()).err().unwrap();
        assert!(e.contains("face 0") && e.contains("byte"), "{e}");
        let bad = SQUARE.replace("4 0 1 2 3", "4 0 1 2 9");
        let e = parse_ply(bad.as_bytes()).err().unwrap();
        assert!(e.contains("face 0") && e.contains("vertex index 9"), "{e}");
        let e = parse_ply(b"PK\x03\x04garbage").err().unwrap();
        assert!(e.contains("not a PLY file"), "{e}");
    }

    #[test]
    fn binary_endianness_is_honoured() {
        let mut le = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty double x\nproperty float y\nproperty short z\nelement face 1\nproperty list ushort uint vertex_index\nend_header\n".to_vec();
        let mut be = String::from_utf8(le.clone()).unwrap().replace("little", "big").into_bytes();
        for (x, y, z) in [(0.0f64, 0.0f32, 0i16), (1.0, 0.0, 0), (0.0, 1.0, -2)] {
            le.extend(x.to_le_bytes().iter().chain(&y.to_le_bytes()).chain(&z.to_le_bytes()));
            be.extend(x.to_be_bytes().iter().chain(&y.to_be_bytes()).chain(&z.to_be_bytes()));
        }
        le.extend(3u16.to_le_bytes().iter().chain(&0u32.to_le_bytes()).chain(&1u32.to_le_bytes()).chain(&2u32.to_le_bytes()));
        be.extend(3u16.to_be_bytes().iter().chain(&0u32.to_be_bytes()).chain(&1u32.to_be_bytes()).chain(&2u32.to_be_bytes()));
        let (a, b) = (parse_ply(&le).unwrap(), parse_ply(&be).unwrap());
        assert_eq!(a.positions, b.positions);
        assert_eq!(a.positions[2], Vec3::new(0.0, 1.0, -2.0));
        assert_eq!(a.triangles, b.triangles);
    }
}
