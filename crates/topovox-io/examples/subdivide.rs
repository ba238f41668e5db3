//! Makes a large test mesh from a small one: flat midpoint subdivision
//! (each triangle into four, midpoints shared between neighbours, so a
//! closed mesh stays closed) until the next round would pass the target,
//! then a last round over only as many triangles as reach it exactly (that
//! round leaves T-junctions: the surface is the same, its triangles no
//! longer share every edge). Writes binary STL. Used by the large-grid
//! benchmarks (BENCHMARKS.md, "Grids past memory").
//!
//! ```text
//! cargo run --release -p topovox-io --example subdivide -- IN.obj OUT.stl TRIANGLES
//! ```

use std::collections::HashMap;
use std::io::Write;

use glam::DVec3;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 4 {
        eprintln!("usage: subdivide IN OUT.stl TRIANGLES");
        std::process::exit(2);
    }
    let target: usize = args[3].parse().expect("TRIANGLES is a count");
    let loaded = topovox_io::read_mesh(std::path::Path::new(&args[1]), &topovox_io::ReadOptions::default()).unwrap_or_else(|e| {
        eprintln!("subdivide: {e}");
        std::process::exit(1)
    });
    let mut pos = loaded.mesh.positions;
    let mut tris = loaded.mesh.triangles;
    while tris.len() < target {
        // Triangles split this round: all, or the first `m` so that the
        // count lands on the target (each split adds three).
        let m = if tris.len() * 4 <= target { tris.len() } else { (target - tris.len()).div_ceil(3) };
        let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
        let mut next = Vec::with_capacity(tris.len() + 3 * m);
        for (n, t) in tris.iter().enumerate() {
            if n >= m {
                next.push(*t);
                continue;
            }
            let mut at = |a: u32, b: u32| -> u32 {
                *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                    pos.push((pos[a as usize] + pos[b as usize]) * 0.5);
                    pos.len() as u32 - 1
                })
            };
            let (a, b, c) = (t[0], t[1], t[2]);
            let (ab, bc, ca) = (at(a, b), at(b, c), at(c, a));
            next.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
        }
        tris = next;
    }
    let mut out = std::io::BufWriter::new(std::fs::File::create(&args[2]).expect("create output"));
    out.write_all(&[0u8; 80]).unwrap();
    out.write_all(&(tris.len() as u32).to_le_bytes()).unwrap();
    for t in &tris {
        let p: [DVec3; 3] = t.map(|i| pos[i as usize]);
        let n = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero();
        for v in std::iter::once(n).chain(p) {
            for c in v.to_array() {
                out.write_all(&(c as f32).to_le_bytes()).unwrap();
            }
        }
        out.write_all(&[0, 0]).unwrap();
    }
    out.flush().unwrap();
    eprintln!("subdivide: {} triangles, {} vertices -> {}", tris.len(), pos.len(), args[2]);
}
