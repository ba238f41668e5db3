//! One 8×8×8 brick of voxels: 512 bits, one 64-byte cache line — the unit
//! every storage ([`super::bricks`], [`super::sparse`], the writers and the
//! checks) hands bits around in. Nothing here depends on a storage.

/// Edge length of a brick in voxels.
pub const BRICK: u32 = 8;

/// One brick: word `z & 7`, bit `(y & 7) * 8 + (x & 7)`.
pub type Brick = [u64; 8];

/// Sets voxel `(i, j, k)` in its brick `b` (only the coordinates' low
/// three bits count: whole-grid and brick-local coordinates alike).
#[inline(always)]
pub fn set_in_brick(b: &mut Brick, i: u32, j: u32, k: u32) {
    b[(k & 7) as usize] |= 1u64 << (((j & 7) << 3) | (i & 7));
}
