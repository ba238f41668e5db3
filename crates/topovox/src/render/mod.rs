//! Pictures of results: [`raycast`], a headless CPU renderer of voxel grids.

pub mod raycast;

crate::choice! {
    /// Which clusters the GPU renderer (`topovox-view`) draws; named here so
    /// that the command line knows the settings without the renderer.
    pub enum Culling: "culling" default Occlusion {
        /// Every cluster.
        None = "none",
        /// Clusters whose box meets the view frustum (compute pass).
        Frustum = "frustum",
        /// Frustum survivors not hidden behind the depth of all frustum
        /// survivors, tested against a Hi-Z pyramid.
        Occlusion = "occlusion",
        /// The two-pass variant: the depth pass draws only the clusters the
        /// previous frame drew (all of them on the first frame), so it is
        /// cheaper; the pyramid of that partial depth is farther than the
        /// final one, so the test stays a bound and the picture the same.
        OcclusionTwoPass = "occlusion-two-pass",
    }
}
