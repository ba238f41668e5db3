//! Topology of voxel sets: connected components, exact inside/outside
//! classification, and the certificate `topovox check` prints.

pub mod certify;
pub mod cycles;
pub mod inside;
pub mod runs;

pub use certify::{certify, certify_sparse, CheckReport, ColumnStats, MeshFacts, Separation};
