//! Writes one large tessellated mesh twice, as `big.obj` and `big.glb`,
//! for the load-time and peak-memory benchmarks of docs/speed.md:
//!
//!     cargo run --release --example big_mesh -- DIR [QUADS_PER_SIDE]
//!     /usr/bin/time -v pinhole bench DIR/big.glb --frames 1
//!     /usr/bin/time -v pinhole bench DIR/big.obj --frames 1
//!
//! The mesh is a rippled square of `n x n` quads (two triangles each;
//! n = 708 by default, 1,002,528 triangles) with smooth normals, the same
//! positions, normals and triangles in both files.

use std::io::Write;

fn main() -> std::io::Result<()> {
    let mut args = std::env::args().skip(1);
    let dir = std::path::PathBuf::from(args.next().expect("usage: big_mesh DIR [QUADS_PER_SIDE]"));
    let n: usize = args.next().map_or(708, |s| s.parse().expect("QUADS_PER_SIDE is a number"));
    std::fs::create_dir_all(&dir)?;
    let side = n + 1;
    // Height h(x, z) = 0.05 sin(9x) cos(7z) over [-1, 1]^2, and its normal.
    let mut positions = Vec::with_capacity(side * side);
    let mut normals = Vec::with_capacity(side * side);
    for j in 0..side {
        for i in 0..side {
            let (x, z) = (2.0 * i as f32 / n as f32 - 1.0, 2.0 * j as f32 / n as f32 - 1.0);
            let h = 0.05 * (9.0 * x).sin() * (7.0 * z).cos();
            let (dx, dz) = (0.45 * (9.0 * x).cos() * (7.0 * z).cos(), -0.35 * (9.0 * x).sin() * (7.0 * z).sin());
            let len = (dx * dx + 1.0 + dz * dz).sqrt();
            positions.push([x, h, z]);
            normals.push([-dx / len, 1.0 / len, -dz / len]);
        }
    }
    let mut indices: Vec<u32> = Vec::with_capacity(6 * n * n);
    for j in 0..n {
        for i in 0..n {
            let a = (j * side + i) as u32;
            let (b, c, d) = (a + 1, a + side as u32 + 1, a + side as u32);
            // Counter-clockwise seen from above (+y).
            indices.extend([a, d, c, a, c, b]);
        }
    }

    let mut obj = std::io::BufWriter::new(std::fs::File::create(dir.join("big.obj"))?);
    for p in &positions {
        writeln!(obj, "v {} {} {}", p[0], p[1], p[2])?;
    }
    for v in &normals {
        writeln!(obj, "vn {} {} {}", v[0], v[1], v[2])?;
    }
    for t in indices.chunks_exact(3) {
        writeln!(obj, "f {a}//{a} {b}//{b} {c}//{c}", a = t[0] + 1, b = t[1] + 1, c = t[2] + 1)?;
    }
    obj.flush()?;

    let mut bin = Vec::with_capacity(24 * positions.len() + 4 * indices.len());
    positions.iter().flatten().for_each(|f| bin.extend(f.to_le_bytes()));
    normals.iter().flatten().for_each(|f| bin.extend(f.to_le_bytes()));
    indices.iter().for_each(|i| bin.extend(i.to_le_bytes()));
    let (vp, vn) = (12 * positions.len(), 12 * normals.len());
    let json = format!(
        r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": [0]}}], "nodes": [{{"mesh": 0}}],
"meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "NORMAL": 1}}, "indices": 2}}]}}],
"buffers": [{{"byteLength": {len}}}],
"bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": {vp}}}, {{"buffer": 0, "byteOffset": {vp}, "byteLength": {vn}}}, {{"buffer": 0, "byteOffset": {vi_start}, "byteLength": {vi}}}],
"accessors": [
  {{"bufferView": 0, "componentType": 5126, "count": {nv}, "type": "VEC3", "min": [-1, -0.05, -1], "max": [1, 0.05, 1]}},
  {{"bufferView": 1, "componentType": 5126, "count": {nv}, "type": "VEC3"}},
  {{"bufferView": 2, "componentType": 5125, "count": {ni}, "type": "SCALAR"}}]}}"#,
        len = bin.len(),
        vi_start = vp + vn,
        vi = 4 * indices.len(),
        nv = positions.len(),
        ni = indices.len()
    );
    let mut json = json.into_bytes();
    while json.len() % 4 != 0 {
        json.push(b' ');
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut glb = std::io::BufWriter::new(std::fs::File::create(dir.join("big.glb"))?);
    glb.write_all(b"glTF")?;
    glb.write_all(&2u32.to_le_bytes())?;
    glb.write_all(&(total as u32).to_le_bytes())?;
    glb.write_all(&(json.len() as u32).to_le_bytes())?;
    glb.write_all(b"JSON")?;
    glb.write_all(&json)?;
    glb.write_all(&(bin.len() as u32).to_le_bytes())?;
    glb.write_all(b"BIN\0")?;
    glb.write_all(&bin)?;
    glb.flush()?;
    println!("{} triangles in {} and {}", indices.len() / 3, dir.join("big.obj").display(), dir.join("big.glb").display());
    Ok(())
}
