//! The camera and the CPU reference of the GPU frustum test.
//!
//! Frustum culling (seed 002, § "frustum culling"): a cluster's box is kept
//! unless an axis separates it from the view frustum. Two families of axes
//! are tried, as the report does:
//! - **world space**: the three coordinate axes, box against the bounding
//!   box of the frustum's eight corners;
//! - **projective (clip) space**: the six clip planes `x = ±w`, `y = ±w`,
//!   `z = 0`, `z = w`: the box is culled when its eight corners, multiplied
//!   by the view–projection matrix, all lie outside one plane. The planes
//!   are half-spaces of homogeneous coordinates, so corners behind the eye
//!   (`w < 0`) are classified correctly.
//!
//! Both tests are conservative: a kept box may still be invisible, a culled
//! box never is. The shader `cull.wgsl` evaluates the same expressions in
//! the same order; the tests compare its survivors with [`visible`].

use glam::{Mat4, Vec3, Vec4};

/// Eye, target, up and vertical field of view.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub eye: Vec3,
    /// Point looked at.
    pub target: Vec3,
    /// Up direction.
    pub up: Vec3,
    /// Vertical field of view in degrees.
    pub fov_deg: f32,
}

impl Camera {
    /// A camera looking at the box `lo..hi` from above-front-right (the
    /// `render` command's iso view), far enough to see all of it.
    pub fn framing(lo: Vec3, hi: Vec3, up_axis: usize) -> Camera {
        let centre = (lo + hi) * 0.5;
        let radius = ((hi - lo).length() * 0.5).max(1e-6);
        let mut up = Vec3::ZERO;
        up[up_axis] = 1.0;
        // Iso direction: equal parts of the two horizontal axes, raised.
        let mut dir = Vec3::ONE;
        dir[up_axis] = 0.8;
        let fov_deg = 45.0f32;
        let dist = radius / (fov_deg.to_radians() * 0.5).sin() * 1.05;
        Camera { eye: centre + dir.normalize() * dist, target: centre, up, fov_deg }
    }

    /// Near and far planes enclosing the scene box (`lo..hi`) seen from the eye.
    pub fn depth_range(&self, lo: Vec3, hi: Vec3) -> (f32, f32) {
        let centre = (lo + hi) * 0.5;
        let radius = (hi - lo).length() * 0.5;
        let far = ((self.eye - centre).length() + radius) * 1.01 + 1e-6;
        let near = ((self.eye - centre).length() - radius).max(far * 1e-4);
        (near, far)
    }

    /// The up direction the view uses: `up`, or when looking along it,
    /// any perpendicular.
    fn view_up(&self) -> Vec3 {
        let fwd = (self.target - self.eye).normalize_or_zero();
        if fwd.cross(self.up).length_squared() < 1e-10 {
            if fwd.x.abs() < 0.9 {
                Vec3::X
            } else {
                Vec3::Z
            }
        } else {
            self.up
        }
    }

    /// View–projection matrix (right-handed, depth 0..1) for `aspect`.
    pub fn view_proj(&self, aspect: f32, near: f32, far: f32) -> Mat4 {
        // wgpu's clip space is Direct3D's: y up, depth 0..1.
        glam::camera::rh::proj::directx::perspective(self.fov_deg.to_radians(), aspect, near, far)
            * glam::camera::rh::view::look_at_mat4(self.eye, self.target, self.view_up())
    }

    /// The picture's right and up directions and the forward direction,
    /// unit vectors as [`Camera::view_proj`] places them.
    pub fn basis(&self) -> (Vec3, Vec3, Vec3) {
        let fwd = (self.target - self.eye).normalize_or_zero();
        let right = fwd.cross(self.view_up()).normalize_or_zero();
        (right, right.cross(fwd), fwd)
    }

    /// The direction of the ray through picture point `(x, y)` in
    /// normalised coordinates (−1..1, y up) of a picture of `aspect`.
    pub fn ray(&self, aspect: f32, x: f32, y: f32) -> Vec3 {
        let (right, up, fwd) = self.basis();
        let h = (self.fov_deg.to_radians() * 0.5).tan();
        (fwd + right * (x * h * aspect) + up * (y * h)).normalize_or_zero()
    }
}

/// The frustum's world-space bounding box (its eight corners through the
/// inverse view–projection).
pub fn frustum_box(view_proj: Mat4) -> (Vec3, Vec3) {
    let inv = view_proj.inverse();
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for c in 0..8 {
        let ndc =
            Vec4::new(if c & 1 == 0 { -1.0 } else { 1.0 }, if c & 2 == 0 { -1.0 } else { 1.0 }, if c & 4 == 0 { 0.0 } else { 1.0 }, 1.0);
        let p = inv * ndc;
        let p = p.truncate() / p.w;
        lo = lo.min(p);
        hi = hi.max(p);
    }
    (lo, hi)
}

/// Clip coordinates of `p`, column by column in the shader's order.
fn clip(m: &Mat4, p: Vec3) -> Vec4 {
    ((m.x_axis * p.x + m.y_axis * p.y) + m.z_axis * p.z) + m.w_axis
}

/// The frustum test of one box (see the module doc): true when kept.
pub fn visible(lo: Vec3, hi: Vec3, view_proj: &Mat4, f_lo: Vec3, f_hi: Vec3) -> bool {
    if hi.cmplt(f_lo).any() || lo.cmpgt(f_hi).any() {
        return false;
    }
    let mut out = [0u32; 6];
    for c in 0..8 {
        let p = Vec3::new(if c & 1 == 0 { lo.x } else { hi.x }, if c & 2 == 0 { lo.y } else { hi.y }, if c & 4 == 0 { lo.z } else { hi.z });
        let q = clip(view_proj, p);
        out[0] += (q.x < -q.w) as u32;
        out[1] += (q.x > q.w) as u32;
        out[2] += (q.y < -q.w) as u32;
        out[3] += (q.y > q.w) as u32;
        out[4] += (q.z < 0.0) as u32;
        out[5] += (q.z > q.w) as u32;
    }
    out.iter().all(|&n| n < 8)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn boxes_in_front_are_kept_and_behind_or_aside_culled() {
        let cam = Camera { eye: Vec3::ZERO, target: Vec3::new(0.0, 0.0, -1.0), up: Vec3::Y, fov_deg: 60.0 };
        let m = cam.view_proj(1.0, 0.1, 100.0);
        let (flo, fhi) = frustum_box(m);
        let unit = Vec3::splat(0.5);
        let at = |c: Vec3| visible(c - unit, c + unit, &m, flo, fhi);
        assert!(at(Vec3::new(0.0, 0.0, -10.0)));
        assert!(!at(Vec3::new(0.0, 0.0, 10.0)), "behind the eye");
        assert!(!at(Vec3::new(30.0, 0.0, -10.0)), "far to the right");
        assert!(!at(Vec3::new(0.0, 0.0, -200.0)), "past the far plane");
        // A box around the eye is kept.
        assert!(visible(Vec3::splat(-1.0), Vec3::splat(1.0), &m, flo, fhi));
    }
}
