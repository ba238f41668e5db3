//! binvox (Patrick Min's format, read by viewvox and the `binvox` Python
//! packages), written by hand: no crate writes it.
//!
//! ```text
//! #binvox 1
//! dim D D D
//! translate tx ty tz
//! scale S
//! data
//! <run-length pairs: value byte, count byte (1..=255)>
//! ```
//! Readers assume a cube, so the grid is written as a cube of side
//! `D = max(nx, ny, nz)`, padded with empty voxels. Voxel order in the data:
//! x slowest, then z, then y fastest (index `x·D² + z·D + y`), which is why
//! readers such as `binvox_rw` transpose axes 1 and 2 to get `[x][y][z]`.
//! `translate` is the world position of the grid origin, `scale` the world
//! length of the cube side (`D · voxel_size`), so voxel `(i,j,k)` spans
//! `translate + (i,j,k)·scale/D`.

use std::io::Write;

use glam::DVec3;
use topovox::{GridSpec, VoxelSource};

use crate::error::{quoted, ErrorKind};
use crate::LoadedVoxels;

struct Rle<'a> {
    w: &'a mut dyn Write,
    value: u8,
    run: u32,
    buf: Vec<u8>,
}

impl Rle<'_> {
    fn push(&mut self, v: u8, mut n: u32) -> std::io::Result<()> {
        while n > 0 {
            if v != self.value || self.run == 255 {
                self.flush_run()?;
                self.value = v;
            }
            let take = n.min(255 - self.run);
            self.run += take;
            n -= take;
        }
        Ok(())
    }

    /// Pushes a slice of 0/1 bytes run by run.
    fn push_slice(&mut self, s: &[u8]) -> std::io::Result<()> {
        let mut i = 0;
        while i < s.len() {
            let v = s[i];
            let n = s[i..].iter().position(|&x| x != v).unwrap_or(s.len() - i);
            self.push(v, n as u32)?;
            i += n;
        }
        Ok(())
    }

    fn flush_run(&mut self) -> std::io::Result<()> {
        if self.run > 0 {
            self.buf.push(self.value);
            self.buf.push(self.run as u8);
            self.run = 0;
            if self.buf.len() >= 1 << 16 {
                self.w.write_all(&self.buf)?;
                self.buf.clear();
            }
        }
        Ok(())
    }
}

/// Writes `bits` on `grid` as binvox.
/// A grid of boxes is refused (binvox's one `scale` makes cubes).
pub fn write(w: &mut dyn Write, bits: &dyn VoxelSource, grid: &GridSpec) -> std::io::Result<()> {
    let Some(s) = grid.voxel_size().cube() else {
        return Err(std::io::Error::other(crate::VoxelFormat::Binvox.refuses(grid.voxel_size()).unwrap_or_default()));
    };
    let [nx, ny, nz] = bits.dims();
    let d = nx.max(ny).max(nz);
    let o = grid.origin();
    writeln!(w, "#binvox 1")?;
    writeln!(w, "dim {d} {d} {d}")?;
    writeln!(w, "translate {} {} {}", o.x, o.y, o.z)?;
    writeln!(w, "scale {}", s * d as f64)?;
    writeln!(w, "data")?;
    let (nyu, nzu) = (ny as usize, nz as usize);
    let plane = nyu * nzu;
    let block = crate::npy::plane_block(plane);
    let mut planes = vec![0u8; plane * block as usize];
    let mut rle = Rle { w, value: 0, run: 0, buf: Vec::with_capacity(1 << 16) };
    let mut i0 = 0;
    while i0 < nx {
        let count = block.min(nx - i0);
        bits.fill_i_planes(i0, count, false, &mut planes);
        for p in 0..count as usize {
            let pl = &planes[p * plane..(p + 1) * plane];
            for k in 0..nzu {
                rle.push_slice(&pl[k * nyu..(k + 1) * nyu])?;
                rle.push(0, d - ny)?;
            }
            rle.push(0, (d - nz) * d)?;
        }
        i0 += count;
    }
    rle.push(0, (d - nx) * d * d)?;
    rle.flush_run()?;
    let Rle { w, buf, .. } = rle;
    w.write_all(&buf)
}

/// Reads a cubic binvox file.
pub fn read(bytes: &[u8]) -> Result<LoadedVoxels, ErrorKind> {
    let bad = |d: String| ErrorKind::Malformed { format: "binvox", detail: d };
    let mut pos = 0;
    let mut line = || -> Option<&str> {
        let end = bytes[pos..].iter().position(|&b| b == b'\n')? + pos;
        let s = std::str::from_utf8(&bytes[pos..end]).ok()?;
        pos = end + 1;
        Some(s.trim())
    };
    if !line().is_some_and(|l| l.starts_with("#binvox")) {
        return Err(bad("missing '#binvox' header".into()));
    }
    let (mut dims, mut translate, mut scale) = (None, DVec3::ZERO, 1.0);
    loop {
        let l = line().ok_or_else(|| bad("header ends before 'data'".into()))?;
        let mut it = l.split_whitespace();
        match it.next() {
            Some("dim") => {
                let v: Vec<u32> =
                    it.map(|s| s.parse()).collect::<Result<_, _>>().map_err(|_| bad(format!("bad dim line {}", quoted(l))))?;
                dims = Some(v);
            }
            Some("translate") => {
                let v: Vec<f64> =
                    it.map(|s| s.parse()).collect::<Result<_, _>>().map_err(|_| bad(format!("bad translate line {}", quoted(l))))?;
                if v.len() != 3 {
                    return Err(bad(format!("bad translate line {}", quoted(l))));
                }
                translate = DVec3::new(v[0], v[1], v[2]);
            }
            Some("scale") => scale = it.next().and_then(|s| s.parse().ok()).ok_or_else(|| bad(format!("bad scale line {}", quoted(l))))?,
            Some("data") => break,
            _ => return Err(bad(format!("unexpected header line {}", quoted(l)))),
        }
    }
    let dims = dims.ok_or_else(|| bad("no dim line".into()))?;
    let [a, b, c] = dims[..] else { return Err(bad("dim needs 3 values".into())) };
    if a != b || b != c {
        return Err(ErrorKind::Unsupported(format!("non-cubic binvox grid {a}x{b}x{c}")));
    }
    if a == 0 || a > 4096 {
        return Err(bad(format!("dim {a} out of range")));
    }
    let d = a as u64;
    let total = d * d * d;
    let mut bits = crate::dense_grid([a, a, a])?;
    let mut idx = 0u64;
    for pair in bytes[pos..].chunks(2) {
        let [v, n] = pair else { return Err(bad("odd number of data bytes".into())) };
        let n = *n as u64;
        if idx + n > total {
            return Err(bad("more data than the grid holds".into()));
        }
        if *v != 0 {
            for t in idx..idx + n {
                let (x, z, y) = (t / (d * d), (t / d) % d, t % d);
                bits.set(x as u32, y as u32, z as u32);
            }
        }
        idx += n;
    }
    if idx != total {
        return Err(bad(format!("data covers {idx} of {total} voxels (truncated?)")));
    }
    Ok(LoadedVoxels { bits, placement: Some((translate, DVec3::splat(scale / d as f64))), attributes: None })
}
