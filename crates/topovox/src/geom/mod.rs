//! Geometry, and the lattice floor every algorithm stands on: the
//! fixed-point lattice ([`fixed`]), mesh preparation onto it ([`lattice`]:
//! `prepare`), the tie rule ([`perturb`]), the triangle setup of the exact
//! target tests ([`setup`]) and exact floor/ceiling division ([`divide`]), and nearest points
//! of triangles and segments in f64 ([`closest`]), and exact solid angles
//! and orientations ([`solid_angle`]).
//! Algorithm files (`voxelize/`) and certificates (`topology/`) import
//! from here; nothing here imports from them.

pub use crate::aabb;
pub mod clip;
pub mod closest;
pub mod divide;
pub mod fixed;
pub mod lattice;
pub mod perturb;
pub mod setup;
pub mod solid_angle;
