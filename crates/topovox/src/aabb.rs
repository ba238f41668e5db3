//! Axis-aligned bounding boxes in world space.

use glam::DVec3;

/// An axis-aligned box `[min, max]` (closed).
///
/// # Guarantees
/// A box built by [`Aabb::from_points`] from at least one finite point has
/// `min <= max` on every axis. [`Aabb::EMPTY`] has `min > max`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Smallest corner.
    pub min: DVec3,
    /// Largest corner.
    pub max: DVec3,
}

impl Aabb {
    /// The empty box: contains nothing, and grows to the first point added.
    pub const EMPTY: Aabb = Aabb { min: DVec3::splat(f64::INFINITY), max: DVec3::splat(f64::NEG_INFINITY) };

    /// The smallest box holding every point (ignores non-finite points).
    pub fn from_points<'a>(points: impl IntoIterator<Item = &'a DVec3>) -> Aabb {
        let mut b = Aabb::EMPTY;
        for p in points {
            if p.is_finite() {
                b.grow(*p);
            }
        }
        b
    }

    /// Enlarges the box to hold `p`.
    pub fn grow(&mut self, p: DVec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    /// True when the box holds no point.
    pub fn is_empty(&self) -> bool {
        !(self.min.x <= self.max.x && self.min.y <= self.max.y && self.min.z <= self.max.z)
    }

    /// `max - min` (zero for an empty box).
    pub fn extent(&self) -> DVec3 {
        if self.is_empty() {
            DVec3::ZERO
        } else {
            self.max - self.min
        }
    }
}
