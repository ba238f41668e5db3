//! Geometry: bounding boxes, the fixed-point lattice, lattice triangles and
//! polygon clipping.

pub mod aabb;
pub mod clip;
pub mod fixed;
pub mod lattice;
pub mod perturb;
