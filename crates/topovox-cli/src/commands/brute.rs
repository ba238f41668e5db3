//! The brute-force baseline of `topovox bench --baseline brute`: what a short
//! C loop does, kept here as a yardstick and not offered by the library.
//!
//! For every triangle, every voxel of its bounding box gets T.
//! Akenine-Möller's triangle/box overlap test ("Fast 3D Triangle-Box
//! Overlap Testing", JGT 2001: the 9 edge-cross axes, the box axes, the
//! plane) in `f64`, and hits are ORed into a dense bit grid. Serial. It is
//! not exact at ties (a triangle exactly touching a voxel may go either
//! way), so its voxel count can differ from `cover`'s by a few touches; it
//! measures speed only.

use topovox::{GridSpec, MeshRef};

/// Voxelizes `mesh` on `grid` by brute force; returns the bit grid (rows
/// along `i` in `u64` words), whose popcount the caller takes untimed.
pub fn cover(mesh: MeshRef<'_>, grid: &GridSpec) -> Vec<u64> {
    let [nx, ny, nz] = grid.dims().map(|d| d as i64);
    let wpr = (nx as usize).div_ceil(64);
    let mut bits = vec![0u64; wpr * ny as usize * nz as usize];
    // Vertices to grid units once, as a C loop would.
    let (o, inv) = (grid.origin(), 1.0 / grid.voxel_size().0);
    let verts: Vec<V> = mesh.positions.iter().map(|p| ((*p - o) * inv).to_array()).collect();
    for t in mesh.triangles {
        let (Some(&a), Some(&b), Some(&c)) = (verts.get(t[0] as usize), verts.get(t[1] as usize), verts.get(t[2] as usize)) else {
            continue;
        };
        let mut r = [(0i64, 0i64); 3];
        for (ax, r) in r.iter_mut().enumerate() {
            let (lo, hi) = (a[ax].min(b[ax]).min(c[ax]), a[ax].max(b[ax]).max(c[ax]));
            if !(lo.is_finite() && hi.is_finite()) {
                continue;
            }
            *r = ((lo.floor() as i64).max(0), (hi.floor() as i64).min([nx, ny, nz][ax] - 1));
        }
        for k in r[2].0..=r[2].1 {
            for j in r[1].0..=r[1].1 {
                for i in r[0].0..=r[0].1 {
                    let centre = [i as f64 + 0.5, j as f64 + 0.5, k as f64 + 0.5];
                    if tri_box(centre, [a, b, c]) {
                        let w = (k as usize * ny as usize + j as usize) * wpr + (i as usize >> 6);
                        bits[w] |= 1u64 << (i & 63);
                    }
                }
            }
        }
    }
    bits
}

type V = [f64; 3];

fn sub(a: V, b: V) -> V {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: V, b: V) -> V {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

fn dot(a: V, b: V) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Akenine-Möller's test (`tribox3`) for a box of half size 0.5 centred at
/// `c`: the nine edge × axis tests (each projecting the two vertices that
/// differ on it), the box's axes, then the triangle's plane.
fn tri_box(c: V, t: [V; 3]) -> bool {
    const H: f64 = 0.5;
    let v = [sub(t[0], c), sub(t[1], c), sub(t[2], c)];
    let e = [sub(v[1], v[0]), sub(v[2], v[1]), sub(v[0], v[2])];
    for (n, ei) in e.iter().enumerate() {
        // The vertex not on edge n projects like its two end points' other one.
        let (p, q) = (v[n], v[(n + 2) % 3]);
        for a in 0..3 {
            let (b, c) = ((a + 1) % 3, (a + 2) % 3);
            // axis = e × unit_a: components (0 on a, e_c on b, -e_b on c).
            let (fb, fc) = (ei[c], -ei[b]);
            let (p0, p1) = (fb * p[b] + fc * p[c], fb * q[b] + fc * q[c]);
            let r = H * (fb.abs() + fc.abs());
            if p0.min(p1) > r || p0.max(p1) < -r {
                return false;
            }
        }
    }
    let [a, b, c] = v;
    for ((x, y), z) in a.iter().zip(&b).zip(&c) {
        if x.min(*y).min(*z) > H || x.max(*y).max(*z) < -H {
            return false;
        }
    }
    let n = cross(e[0], e[1]);
    let d = dot(n, v[0]);
    let r = H * (n[0].abs() + n[1].abs() + n[2].abs());
    d.abs() <= r
}

/// What the brute-force program would load an OBJ with: one serial pass
/// over the lines, `v` records (three numbers) and `f` records (the vertex
/// index of each corner, 1-based, fanned); everything else skipped, no
/// validation. `None` if the file is unreadable or not an OBJ.
pub fn load_obj(path: &std::path::Path) -> Option<topovox::Mesh> {
    if !path.extension().is_some_and(|e| e.eq_ignore_ascii_case("obj")) {
        return None;
    }
    let text = std::fs::read(path).ok()?;
    let mut m = topovox::Mesh::default();
    let mut corners = Vec::new();
    for line in text.split(|&b| b == b'\n') {
        let mut w = line.split(|b| b.is_ascii_whitespace()).filter(|w| !w.is_empty());
        match w.next() {
            Some(b"v") => {
                let mut c = [0.0; 3];
                for x in &mut c {
                    *x = w.next().and_then(|s| std::str::from_utf8(s).ok()?.parse().ok()).unwrap_or(0.0);
                }
                m.positions.push(glam::DVec3::from_array(c));
            }
            Some(b"f") => {
                corners.clear();
                corners.extend(w.filter_map(|s| std::str::from_utf8(s.split(|&b| b == b'/').next()?).ok()?.parse::<u32>().ok()));
                for k in 1..corners.len().saturating_sub(1) {
                    m.triangles.push([corners[0] - 1, corners[k] - 1, corners[k + 1] - 1]);
                }
            }
            _ => {}
        }
    }
    Some(m)
}
