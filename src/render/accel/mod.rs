//! Rays in, hits out: the queries that find what a ray meets, and nothing of
//! how it is lit. `brute` is the book's reference (every primitive, in scene
//! order); `bvh` is the fast method checked against it, with its traversal
//! kernels (`traverse`), packets of rays (`packet`), the instance layer
//! (`instances`), the ray-primitive tests (`intersect`) and the CSG intervals
//! (`csg`).

pub mod brute;
pub mod bvh;
pub mod csg;
pub mod instances;
pub mod intersect;
pub mod packet;
pub mod scene_edges;
pub mod surface;
pub mod traverse;
