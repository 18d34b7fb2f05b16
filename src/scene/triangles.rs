//! The scene's flattened triangles, held as an indexed mesh: each triangle
//! is three corner indices plus its material and object, and the corners
//! (position, shading normal, uv) are shared by every triangle that has a
//! corner with exactly the same bits. A closed mesh shares each corner
//! about six ways, so this takes about 37 bytes per triangle where three
//! corners of its own took 108.
//!
//! A flat-shaded triangle (`Triangle::is_flat`: each corner's normal is the
//! geometric normal, bit for bit) stores no normal: it is recomputed from
//! the positions, so the corners of a flat mesh are shared too.
//!
//! Renderers read a triangle as a `Triangle` value, assembled from its
//! corners, so sharing never changes a number: `get(i)` returns exactly the
//! `Triangle` that was pushed as triangle `i`.

use crate::scene::Triangle;
use crate::math::{Vec2, Vec3};
use rustc_hash::FxHashMap;

/// One corner's attributes, shared by the triangles that meet there. Laid
/// out as eight floats in a row (`CornerRow`): code that builds eight hits
/// at once loads a corner of each as one vector and transposes them.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
struct Corner {
    position: Vec3,
    normal: Vec3,
    uv: Vec2,
}

/// A corner as a row: position x, y, z, normal x, y, z, uv u, v. A flat
/// triangle's stored normals are zero (its normal is the geometric one).
pub type CornerRow = [f32; 8];

// `Corner` is eight floats without padding (glam's `Vec3` and `Vec2` are
// `repr(C)` structs of floats), so it can be read as a `CornerRow`.
const _: () = assert!(std::mem::size_of::<Corner>() == std::mem::size_of::<CornerRow>());
const _: () = assert!(std::mem::align_of::<Corner>() == std::mem::align_of::<CornerRow>());

impl Corner {
    #[inline(always)]
    fn as_row(&self) -> &CornerRow {
        // SAFETY: same size and alignment (checked above), and every bit
        // pattern of the eight floats is a valid `CornerRow`.
        unsafe { &*(self as *const Corner).cast::<CornerRow>() }
    }
}

/// What `Triangles::corner_rows` reads of one triangle.
#[derive(Clone, Copy, Debug)]
pub struct FaceRows<'a> {
    pub corners: [&'a CornerRow; 3],
    /// Its normals are the geometric one (the rows' normals are zero).
    pub flat: bool,
    pub material: u32,
    pub object: u32,
}

impl Corner {
    /// The exact bits, so that only identical corners are merged (0.0 and
    /// -0.0 stay apart).
    fn key(&self) -> [u32; 8] {
        let (p, n, uv) = (self.position, self.normal, self.uv);
        [p.x, p.y, p.z, n.x, n.y, n.z, uv.x, uv.y].map(f32::to_bits)
    }
}

/// One triangle: its corners, its material, and its object with the
/// two-sided and flat flags in the top bits (object indices stay far below
/// 2^30).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Face {
    corner: [u32; 3],
    material: u32,
    object_and_flags: u32,
}

const TWO_SIDED_BIT: u32 = 1 << 31;
/// The corners' normals are the geometric normal (stored as zero).
const FLAT_BIT: u32 = 1 << 30;
const FLAG_BITS: u32 = TWO_SIDED_BIT | FLAT_BIT;

/// A triangle's attributes as the store keeps them (`assemble` works out a
/// flat triangle's normals from them).
#[derive(Clone, Copy, Debug)]
pub struct StoredTriangle {
    pub v: [Vec3; 3],
    /// The corners' shading normals; `None` for a flat triangle, whose
    /// normals are its geometric normal.
    pub n: Option<[Vec3; 3]>,
    pub uv: [Vec2; 3],
    pub material: u32,
    pub object: u32,
}

/// The scene's triangles in scene order (see the module comment).
#[derive(Clone, Debug, Default)]
pub struct Triangles {
    corners: Vec<Corner>,
    faces: Vec<Face>,
    /// Ranges of corners pushed one triangle at a time since the last
    /// `share_corners`: only these are looked for duplicates (a mesh copied
    /// with `append_copy` keeps its sharing).
    pending: Vec<std::ops::Range<usize>>,
}

impl Triangles {
    pub fn new() -> Triangles {
        Triangles::default()
    }

    #[inline]
    pub fn len(&self) -> usize {
        self.faces.len()
    }

    #[inline]
    pub fn is_empty(&self) -> bool {
        self.faces.is_empty()
    }

    /// Triangle `i`, or `None` past the end.
    #[inline]
    pub fn get(&self, i: usize) -> Option<Triangle> {
        self.faces.get(i).map(|f| self.assemble(f))
    }

    /// Triangle `i`; panics past the end, as indexing a slice does.
    #[inline]
    pub fn at(&self, i: usize) -> Triangle {
        self.assemble(&self.faces[i])
    }

    /// The three vertex positions of triangle `i` (all that visibility reads).
    #[inline]
    pub fn positions(&self, i: usize) -> [Vec3; 3] {
        self.faces[i].corner.map(|c| self.corners[c as usize].position)
    }

    /// Asks the cache for triangle `i`'s three corners (nothing past the
    /// end): loops over the triangles in order read the faces in order but
    /// their shared corners scattered about the array. A hint only.
    #[inline(always)]
    pub fn prefetch_corners(&self, i: usize) {
        if let Some(f) = self.faces.get(i) {
            for c in f.corner {
                crate::math::prefetch::prefetch_value(&self.corners[c as usize]);
            }
        }
    }

    /// The positions of triangle `i` and whether it is two-sided: what
    /// visibility reads.
    #[inline]
    pub fn geometry(&self, i: usize) -> ([Vec3; 3], bool) {
        let f = &self.faces[i];
        (f.corner.map(|c| self.corners[c as usize].position), f.object_and_flags & TWO_SIDED_BIT != 0)
    }

    #[inline(always)]
    fn assemble(&self, f: &Face) -> Triangle {
        let s = self.stored_face(f);
        Triangle {
            v: s.v,
            n: s.n.unwrap_or_else(|| [Triangle::normal_of(&s.v); 3]),
            uv: s.uv,
            material: s.material,
            object: s.object,
            two_sided: f.object_and_flags & TWO_SIDED_BIT != 0,
        }
    }

    #[inline(always)]
    fn stored_face(&self, f: &Face) -> StoredTriangle {
        let [a, b, c] = f.corner.map(|k| self.corners[k as usize]);
        StoredTriangle {
            v: [a.position, b.position, c.position],
            n: (f.object_and_flags & FLAT_BIT == 0).then_some([a.normal, b.normal, c.normal]),
            uv: [a.uv, b.uv, c.uv],
            material: f.material,
            object: f.object_and_flags & !FLAG_BITS,
        }
    }

    /// Stored triangle `i`'s corners as rows, with its face data; `None`
    /// past the end (copies of the two-level layer).
    #[inline(always)]
    pub fn corner_rows(&self, i: usize) -> Option<FaceRows<'_>> {
        let f = self.faces.get(i)?;
        Some(FaceRows {
            corners: f.corner.map(|c| self.corners[c as usize].as_row()),
            flat: f.object_and_flags & FLAT_BIT != 0,
            material: f.material,
            object: f.object_and_flags & !FLAG_BITS,
        })
    }

    /// Where triangle `i`'s record lies in memory, for prefetching (its
    /// corners are found only once it is read).
    #[inline(always)]
    pub fn record_ptr(&self, i: usize) -> *const u8 {
        self.faces.as_ptr().wrapping_add(i).cast()
    }

    /// The triangles in order.
    /// Each triangle's material index, in order (no corners assembled).
    pub fn materials(&self) -> impl Iterator<Item = u32> + '_ {
        self.faces.iter().map(|f| f.material)
    }

    pub fn iter(&self) -> Iter<'_> {
        Iter { store: self, faces: self.faces.iter() }
    }

    /// The triangles of `range`, in order; panics if it runs past the end.
    pub fn range(&self, range: std::ops::Range<usize>) -> Iter<'_> {
        Iter { store: self, faces: self.faces[range].iter() }
    }

    /// All triangles as values, for code that wants a slice.
    pub fn to_vec(&self) -> Vec<Triangle> {
        self.iter().collect()
    }

    /// Appends `t` with three corners of its own; `share_corners` merges
    /// them with equal ones later.
    pub fn push(&mut self, t: Triangle) {
        debug_assert!(t.object & FLAG_BITS == 0, "object index {} too large", t.object);
        let flat = t.is_flat();
        let first = self.corners.len() as u32;
        for k in 0..3 {
            let normal = if flat { Vec3::ZERO } else { t.n[k] };
            self.corners.push(Corner { position: t.v[k], normal, uv: t.uv[k] });
        }
        match self.pending.last_mut() {
            Some(r) if r.end == first as usize => r.end += 3,
            _ => self.pending.push(first as usize..first as usize + 3),
        }
        let flags = if t.two_sided { TWO_SIDED_BIT } else { 0 } | if flat { FLAT_BIT } else { 0 };
        self.faces.push(Face { corner: [first, first + 1, first + 2], material: t.material, object_and_flags: (t.object & !FLAG_BITS) | flags });
    }

    /// Room for `n` more triangles (their corners are counted as they come).
    pub fn reserve_faces(&mut self, n: usize) {
        self.faces.reserve(n);
    }

    /// Room for `copies` copies of `mesh` (`append_copy`).
    pub fn reserve_copies(&mut self, mesh: &Triangles, copies: usize) {
        self.faces.reserve(mesh.faces.len() * copies);
        self.corners.reserve(mesh.corners.len() * copies);
    }

    /// Appends `t`, its corner k shared with the corner last made for
    /// `keys[k]` (an index into `made`, the caller's record of corners by
    /// key) when that one has exactly the same bits; otherwise made anew
    /// and recorded. A loader whose corners are a function of some key
    /// (an OBJ's vertex index) shares them so without hashing.
    pub fn push_keyed(&mut self, t: Triangle, keys: [usize; 3], made: &mut [u32]) {
        debug_assert!(t.object & FLAG_BITS == 0, "object index {} too large", t.object);
        let flat = t.is_flat();
        let mut corner = [0u32; 3];
        for k in 0..3 {
            let c = Corner { position: t.v[k], normal: if flat { Vec3::ZERO } else { t.n[k] }, uv: t.uv[k] };
            let known = made[keys[k]];
            corner[k] = if known != u32::MAX && self.corners[known as usize].key() == c.key() {
                known
            } else {
                self.corners.push(c);
                made[keys[k]] = self.corners.len() as u32 - 1;
                made[keys[k]]
            };
        }
        let flags = if t.two_sided { TWO_SIDED_BIT } else { 0 } | if flat { FLAT_BIT } else { 0 };
        self.faces.push(Face { corner, material: t.material, object_and_flags: (t.object & !FLAG_BITS) | flags });
    }

    pub fn clear(&mut self) {
        self.faces.clear();
        self.corners.clear();
        self.pending.clear();
    }

    /// Appends a copy of every triangle of `mesh`, keeping its shared
    /// corners shared: each corner's position and normal pass through
    /// `place` once, `flips` reverses every winding (a mirroring placement),
    /// and each triangle takes the material `material` maps its own to, and
    /// `object` and `two_sided`. Gives the triangles that pushing each of
    /// `mesh`'s triangles, placed corner by corner, would give.
    pub fn append_copy(
        &mut self,
        mesh: &Triangles,
        place: impl Fn(Vec3, Vec3) -> (Vec3, Vec3),
        flips: bool,
        material: impl Fn(u32) -> u32,
        object: u32,
        two_sided: bool,
    ) {
        debug_assert!(object & FLAG_BITS == 0, "object index {object} too large");
        let base = self.corners.len() as u32;
        self.corners.extend(mesh.corners.iter().map(|c| {
            let (position, normal) = place(c.position, c.normal);
            // A flat triangle's corners hold no normal (zero), whatever the placement.
            Corner { position, normal, uv: c.uv }
        }));
        let sides = if two_sided { TWO_SIDED_BIT } else { 0 };
        self.faces.extend(mesh.faces.iter().map(|f| {
            let mut corner = f.corner.map(|k| k + base);
            if flips {
                corner.swap(1, 2);
            }
            Face { corner, material: material(f.material), object_and_flags: object | sides | (f.object_and_flags & FLAT_BIT) }
        }));
        self.pending.extend(mesh.pending.iter().map(|r| r.start + base as usize..r.end + base as usize));
    }

    /// Replaces triangle `i` by `t` (with corners of its own, so that the
    /// triangles sharing its old corners keep them).
    pub fn set(&mut self, i: usize, t: Triangle) {
        let last = self.faces.len();
        self.push(t);
        self.faces.swap_remove(i);
        debug_assert_eq!(self.faces.len(), last);
    }

    /// Removes and returns the triangles from `at` on.
    pub fn split_off(&mut self, at: usize) -> Vec<Triangle> {
        let tail: Vec<Triangle> = self.range(at..self.len()).collect();
        self.faces.truncate(at);
        tail
    }

    /// Keeps only the triangles `keep` accepts, in order (their corners stay).
    pub fn retain(&mut self, mut keep: impl FnMut(&Triangle) -> bool) {
        let faces = std::mem::take(&mut self.faces);
        self.faces = faces.into_iter().filter(|f| keep(&self.assemble(f))).collect();
    }

    /// Moves every vertex position by `f` (each shared corner once).
    pub fn map_positions(&mut self, mut f: impl FnMut(Vec3) -> Vec3) {
        for c in &mut self.corners {
            c.position = f(c.position);
        }
    }

    /// Merges the corners pushed one triangle at a time with identical
    /// ones pushed so, so that each is stored once; the triangles read back
    /// unchanged. Nothing to do when no triangle was pushed since.
    pub fn share_corners(&mut self) {
        if self.pending.is_empty() {
            return;
        }
        let pending_corners: usize = self.pending.iter().map(|r| r.len()).sum();
        let mut index: FxHashMap<[u32; 8], u32> = FxHashMap::with_capacity_and_hasher(pending_corners / 4, Default::default());
        let mut kept: Vec<Corner> = Vec::with_capacity(self.corners.len() - pending_corners * 3 / 4);
        let mut renumber = vec![0u32; self.corners.len()];
        let mut ranges = std::mem::take(&mut self.pending).into_iter().peekable();
        for (old, c) in self.corners.iter().enumerate() {
            while ranges.peek().is_some_and(|r| r.end <= old) {
                ranges.next();
            }
            renumber[old] = if ranges.peek().is_some_and(|r| r.contains(&old)) {
                *index.entry(c.key()).or_insert_with(|| {
                    kept.push(*c);
                    kept.len() as u32 - 1
                })
            } else {
                kept.push(*c);
                kept.len() as u32 - 1
            };
        }
        for f in &mut self.faces {
            f.corner = f.corner.map(|c| renumber[c as usize]);
        }
        kept.shrink_to_fit();
        self.faces.shrink_to_fit();
        self.corners = kept;
    }

    /// Bytes held: the corners and the triangle records.
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(&self.corners[..]) + std::mem::size_of_val(&self.faces[..])
    }
}

/// The triangles of a `Triangles`, in order, as values.
#[derive(Clone)]
pub struct Iter<'a> {
    store: &'a Triangles,
    faces: std::slice::Iter<'a, Face>,
}

impl Iterator for Iter<'_> {
    type Item = Triangle;
    #[inline]
    fn next(&mut self) -> Option<Triangle> {
        self.faces.next().map(|f| self.store.assemble(f))
    }
    #[inline]
    fn size_hint(&self) -> (usize, Option<usize>) {
        self.faces.size_hint()
    }
}

impl DoubleEndedIterator for Iter<'_> {
    #[inline]
    fn next_back(&mut self) -> Option<Triangle> {
        self.faces.next_back().map(|f| self.store.assemble(f))
    }
}

impl ExactSizeIterator for Iter<'_> {}

impl<'a> IntoIterator for &'a Triangles {
    type Item = Triangle;
    type IntoIter = Iter<'a>;
    fn into_iter(self) -> Iter<'a> {
        self.iter()
    }
}

impl PartialEq for Triangles {
    fn eq(&self, other: &Triangles) -> bool {
        self.len() == other.len() && self.iter().eq(other.iter())
    }
}

impl FromIterator<Triangle> for Triangles {
    fn from_iter<I: IntoIterator<Item = Triangle>>(iter: I) -> Triangles {
        let mut t = Triangles::new();
        t.extend(iter);
        t
    }
}

impl Extend<Triangle> for Triangles {
    fn extend<I: IntoIterator<Item = Triangle>>(&mut self, iter: I) {
        for t in iter {
            self.push(t);
        }
    }
}

impl From<Vec<Triangle>> for Triangles {
    fn from(v: Vec<Triangle>) -> Triangles {
        v.into_iter().collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(v: [[f32; 3]; 3], object: u32, two_sided: bool) -> Triangle {
        Triangle {
            v: v.map(Vec3::from),
            n: [Vec3::Z, Vec3::Y, Vec3::Z],
            uv: [Vec2::ZERO, Vec2::X, Vec2::Y],
            material: 3,
            object,
            two_sided,
        }
    }

    #[test]
    fn sharing_corners_stores_each_once_and_changes_no_triangle() {
        // Two triangles of a quad share the diagonal's two corners; a third
        // has the same position as one of them but -0.0 in its uv, so it is
        // a different corner.
        let a = tri([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]], 1, false);
        let b = Triangle { v: [a.v[0], a.v[2], Vec3::new(0.0, 1.0, 0.0)], n: [a.n[0], a.n[2], Vec3::Y], uv: [a.uv[0], a.uv[2], Vec2::Y], ..a.clone() };
        let mut c = tri([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 2.0, 0.0]], 7, true);
        c.uv[0] = Vec2::new(-0.0, 0.0);
        assert!(!a.is_flat() && !b.is_flat() && !c.is_flat());
        let mut store: Triangles = vec![a.clone(), b.clone(), c.clone()].into();
        assert_eq!(store.corners.len(), 9);
        store.share_corners();
        assert_eq!(store.corners.len(), 4 + 3, "the quad's 4 corners and the third triangle's 3");
        assert_eq!(store.to_vec(), vec![a.clone(), b.clone(), c.clone()]);
        assert!(store.at(2).two_sided && store.at(2).object == 7 && !store.at(0).two_sided);
        assert_eq!(store.memory_bytes(), 7 * 32 + 3 * 20);
        // Flat triangles store no normals, so a flat quad's corners are
        // shared too (and -0.0 still differs from 0.0).
        let flat = |t: &Triangle| Triangle { n: [t.geometric_normal(); 3], ..t.clone() };
        let (fa, fb, fc) = (flat(&a), flat(&b), flat(&c));
        assert!(fa.is_flat() && !a.is_flat());
        let mut flats: Triangles = vec![fa.clone(), fb.clone(), fc.clone()].into();
        flats.share_corners();
        assert_eq!(flats.corners.len(), 7);
        assert_eq!(flats.to_vec(), vec![fa, fb, fc]);
        // Editing one triangle leaves its neighbour's shared corners alone.
        let moved = Triangle { v: [Vec3::splat(5.0); 3], ..a.clone() };
        store.set(0, moved.clone());
        assert_eq!(store.to_vec(), vec![moved, b, c]);
    }

    #[test]
    fn keyed_corners_are_shared_only_when_their_bits_agree() {
        // A quad over vertices 0..4, then a triangle on vertex 0 whose normal
        // there differs (a face-dependent fallback): it must get a corner of
        // its own, and every triangle must read back as pushed.
        let p = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
        let smooth = |v: [usize; 3], n0: Vec3| Triangle {
            v: v.map(|i| p[i]),
            n: [n0, Vec3::Y, Vec3::Y],
            uv: [Vec2::ZERO; 3],
            material: 0,
            object: 0,
            two_sided: false,
        };
        let tris = [(smooth([0, 1, 2], Vec3::Y), [0, 1, 2]), (smooth([0, 2, 3], Vec3::Y), [0, 2, 3]), (smooth([0, 3, 1], Vec3::X), [0, 3, 1])];
        let mut made = vec![u32::MAX; 4];
        let mut store = Triangles::new();
        for (t, keys) in &tris {
            store.push_keyed(t.clone(), *keys, &mut made);
        }
        assert_eq!(store.to_vec(), tris.iter().map(|(t, _)| t.clone()).collect::<Vec<_>>());
        assert_eq!(store.corners.len(), 4 + 1, "four shared vertices and one corner with another normal");
        // Nothing is left for `share_corners` to do.
        assert!(store.pending.is_empty());
    }
}
