//! Which way is up: voxel data keeps the mesh's axes (`i, j, k` along
//! `x, y, z`); formats whose home tools have a fixed up axis — MagicaVoxel
//! (`.vox`, z up) and Minecraft (`.schem`, y up) — get the data rotated so
//! the mesh's up axis points up there. Always a rotation (determinant +1),
//! never a mirror, so models keep their handedness; readers apply the
//! inverse, so files round-trip.
//!
//! | data up | MagicaVoxel `(x, y, z)` | Minecraft `(x, y, z)` |
//! |---|---|---|
//! | `x` | `(j, k, i)` | `(k, i, j)` |
//! | `y` (default: most OBJ and glTF models) | `(i, nz−1−k, j)` | `(i, j, k)` |
//! | `z` | `(i, j, k)` | `(i, k, ny−1−j)` |

topovox::choice! {
    /// The axis of the voxel data that points up.
    pub enum Up: "up axis" default Y {
        /// `+x` is up.
        X = "x",
        /// `+y` is up (OBJ and glTF convention; the default).
        Y = "y",
        /// `+z` is up.
        Z = "z",
    }
}

impl Up {
    /// The axis called `name` (`x`, `y`, `z`, any case), if any.
    pub fn from_name(name: &str) -> Option<Up> {
        topovox::choice::Choice::parse(name).ok()
    }
}

/// A rotation of the voxel grid onto a format's axes: target axis `a`
/// takes source axis `perm[a]`, reversed where `flip[a]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Orientation {
    perm: [usize; 3],
    flip: [bool; 3],
}

impl Orientation {
    /// MagicaVoxel (z up) for data whose up axis is `up`.
    pub fn magicavoxel(up: Up) -> Orientation {
        match up {
            Up::Z => Orientation { perm: [0, 1, 2], flip: [false; 3] },
            Up::Y => Orientation { perm: [0, 2, 1], flip: [false, true, false] },
            Up::X => Orientation { perm: [1, 2, 0], flip: [false; 3] },
        }
    }

    /// Minecraft (y up) for data whose up axis is `up`.
    pub fn minecraft(up: Up) -> Orientation {
        match up {
            Up::Y => Orientation { perm: [0, 1, 2], flip: [false; 3] },
            Up::Z => Orientation { perm: [0, 2, 1], flip: [false, false, true] },
            Up::X => Orientation { perm: [2, 0, 1], flip: [false; 3] },
        }
    }

    /// The grid's dims on the target axes.
    pub fn dims(&self, dims: [u32; 3]) -> [u32; 3] {
        self.perm.map(|a| dims[a])
    }

    /// Voxel `p` of a grid of `dims`, on the target axes.
    #[inline]
    pub fn apply(&self, p: [u32; 3], dims: [u32; 3]) -> [u32; 3] {
        std::array::from_fn(|a| {
            let (s, n) = (p[self.perm[a]], dims[self.perm[a]]);
            if self.flip[a] {
                n - 1 - s
            } else {
                s
            }
        })
    }

    /// The inverse: target voxel `t` of a target grid of `tdims` back on
    /// the data's axes.
    #[inline]
    pub fn invert(&self, t: [u32; 3], tdims: [u32; 3]) -> [u32; 3] {
        let mut p = [0u32; 3];
        for a in 0..3 {
            p[self.perm[a]] = if self.flip[a] { tdims[a] - 1 - t[a] } else { t[a] };
        }
        p
    }

    /// The data's dims from the target's.
    pub fn source_dims(&self, tdims: [u32; 3]) -> [u32; 3] {
        let mut d = [0u32; 3];
        for a in 0..3 {
            d[self.perm[a]] = tdims[a];
        }
        d
    }

    /// The determinant of the rotation (always +1: never a mirror).
    pub fn determinant(&self) -> i32 {
        let mut m = [[0i32; 3]; 3];
        for a in 0..3 {
            m[a][self.perm[a]] = if self.flip[a] { -1 } else { 1 };
        }
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_orientation_is_a_rotation_and_inverts() {
        let dims = [5, 7, 11];
        for up in [Up::X, Up::Y, Up::Z] {
            for o in [Orientation::magicavoxel(up), Orientation::minecraft(up)] {
                assert_eq!(o.determinant(), 1, "{up:?} {o:?}");
                let td = o.dims(dims);
                assert_eq!(o.source_dims(td), dims);
                for p in [[0, 0, 0], [4, 6, 10], [1, 2, 3]] {
                    let t = o.apply(p, dims);
                    assert!((0..3).all(|a| t[a] < td[a]));
                    assert_eq!(o.invert(t, td), p);
                }
            }
        }
    }

    #[test]
    fn the_up_axis_points_up() {
        let dims = [4, 4, 4];
        // Moving up along the data's up axis moves up in the target.
        for (up, axis) in [(Up::X, 0), (Up::Y, 1), (Up::Z, 2)] {
            let mut hi = [1, 1, 1];
            hi[axis] = 2;
            let (mv, mc) = (Orientation::magicavoxel(up), Orientation::minecraft(up));
            assert_eq!(mv.apply(hi, dims)[2], mv.apply([1, 1, 1], dims)[2] + 1, "{up:?} vox");
            assert_eq!(mc.apply(hi, dims)[1], mc.apply([1, 1, 1], dims)[1] + 1, "{up:?} schem");
        }
    }
}
