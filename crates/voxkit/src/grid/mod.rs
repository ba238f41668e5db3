//! Grids: the specification (where voxels are) and storage (which are set).

pub mod dense;
pub mod spec;
