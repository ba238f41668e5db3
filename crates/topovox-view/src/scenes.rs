//! Deterministic test scenes, as a mesh with materials (so they go through
//! every reader-facing path) and as OBJ + MTL text.
//!
//! - [`cornell`]: the Cornell box — white floor, ceiling and back wall, red
//!   left and green right walls, two white blocks, an emissive square just
//!   below the ceiling (its own material, `Ke` 12).
//! - [`city`]: a large scene in the spirit of the report's — 144 buildings
//!   (occluders, facades cut into window panels), 600 trees (trunks and
//!   finely tessellated crowns, each crossed by three cards of alpha
//!   cut-out foliage), 169 street lamps with emissive heads, a ground
//!   plane: about a million triangles, from a fixed-seed generator.
//! - [`cut_outs`]: three quads one behind the other, the front one blue
//!   with an 8×8 checkerboard of cut-out texels (`alphaMode: MASK`); the
//!   alpha test's scene.

use topovox::attributes::{Appearance, Material, Texture, Wrap, NO_MATERIAL};
use topovox::glam::DVec3;
use topovox::Mesh;

/// A scene under construction: triangles and their materials, and the
/// texture coordinates of the triangles that have some.
#[derive(Default)]
struct Builder {
    mesh: Mesh,
    app: Appearance,
    uv: Vec<(usize, [[f32; 2]; 3])>,
}

impl Builder {
    fn material(&mut self, name: &str, colour: [f32; 3], emission: [f32; 3], roughness: f32) -> u32 {
        self.app.materials.push(Material {
            name: name.into(),
            factor: colour,
            texture: None,
            emission,
            roughness,
            alpha_cutoff: None,
            alpha_texture: None,
        });
        self.app.materials.len() as u32 - 1
    }

    /// A quad `a b c d` (counter-clockwise seen from its front).
    fn quad(&mut self, p: [DVec3; 4], material: u32) {
        let base = self.mesh.positions.len() as u32;
        self.mesh.positions.extend(p);
        self.mesh.triangles.push([base, base + 1, base + 2]);
        self.mesh.triangles.push([base, base + 2, base + 3]);
        self.app.triangle_material.extend([material, material]);
    }

    /// A quad with its texture's corners `(0, 1) (1, 1) (1, 0) (0, 0)`
    /// (`v = 0` at the top: `a b` is the texture's bottom edge).
    fn textured_quad(&mut self, p: [DVec3; 4], material: u32) {
        let t = self.mesh.triangles.len();
        self.quad(p, material);
        let uv = [[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]];
        self.uv.extend([(t, [uv[0], uv[1], uv[2]]), (t + 1, [uv[0], uv[2], uv[3]])]);
    }

    /// The mesh and appearance, every triangle without coordinates given NaN ones.
    fn finish(mut self) -> (Mesh, Appearance) {
        if !self.uv.is_empty() {
            self.app.triangle_uv = vec![[[f32::NAN; 2]; 3]; self.mesh.triangles.len()];
            for (t, uv) in self.uv {
                self.app.triangle_uv[t] = uv;
            }
        }
        (self.mesh, self.app)
    }

    /// A grid of `nu × nv` quads spanning `o + s·u + t·v`, `s, t ∈ [0, 1]`.
    fn panel(&mut self, o: DVec3, u: DVec3, v: DVec3, nu: u32, nv: u32, material: u32) {
        for a in 0..nu {
            for b in 0..nv {
                let at = |x: u32, y: u32| o + u * (x as f64 / nu as f64) + v * (y as f64 / nv as f64);
                self.quad([at(a, b), at(a + 1, b), at(a + 1, b + 1), at(a, b + 1)], material);
            }
        }
    }

    /// A UV sphere of `stacks × slices` quads (triangles at the poles).
    fn sphere(&mut self, c: DVec3, r: DVec3, stacks: u32, slices: u32, material: u32) {
        use std::f64::consts::PI;
        let at = |i: u32, j: u32| {
            let (th, ph) = (PI * i as f64 / stacks as f64, 2.0 * PI * j as f64 / slices as f64);
            c + r * DVec3::new(th.sin() * ph.cos(), th.cos(), th.sin() * ph.sin())
        };
        for i in 0..stacks {
            for j in 0..slices {
                let base = self.mesh.positions.len() as u32;
                self.mesh.positions.extend([at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i + 1, j)]);
                if i > 0 {
                    self.mesh.triangles.push([base, base + 1, base + 2]);
                    self.app.triangle_material.push(material);
                }
                if i + 1 < stacks {
                    self.mesh.triangles.push([base, base + 2, base + 3]);
                    self.app.triangle_material.push(material);
                }
            }
        }
    }

    /// An axis-aligned box, faces pointing out.
    fn block(&mut self, lo: DVec3, hi: DVec3, material: u32) {
        let c = |x: usize, y: usize, z: usize| DVec3::new([lo.x, hi.x][x], [lo.y, hi.y][y], [lo.z, hi.z][z]);
        self.quad([c(0, 0, 0), c(0, 0, 1), c(0, 1, 1), c(0, 1, 0)], material); // -x
        self.quad([c(1, 0, 0), c(1, 1, 0), c(1, 1, 1), c(1, 0, 1)], material); // +x
        self.quad([c(0, 0, 0), c(1, 0, 0), c(1, 0, 1), c(0, 0, 1)], material); // -y
        self.quad([c(0, 1, 0), c(0, 1, 1), c(1, 1, 1), c(1, 1, 0)], material); // +y
        self.quad([c(0, 0, 0), c(0, 1, 0), c(1, 1, 0), c(1, 0, 0)], material); // -z
        self.quad([c(0, 0, 1), c(1, 0, 1), c(1, 1, 1), c(0, 1, 1)], material); // +z
    }
}

/// A red quad at z = 0 (side 3) and a green one at z = 0.25 (side 0.6)
/// behind a unit quad at z = 0.5 whose base texture is blue with an 8×8
/// checkerboard alpha (texel `(i, j)`, `i` across and `j` down from the
/// top, opaque where `i + j` is even), cut out below 0.5; all centred on
/// `(0.5, 0.5)` and facing +z. The green quad lies wholly behind the front
/// one, so only an occlusion test that honours the cut-outs keeps it.
pub fn cut_outs() -> (Mesh, Appearance) {
    let mut b = Builder::default();
    let red = b.material("red", [1.0, 0.0, 0.0], [0.0; 3], 0.8);
    let green = b.material("green", [0.0, 1.0, 0.0], [0.0; 3], 0.8);
    let leaf = b.material("checker", [1.0; 3], [0.0; 3], 0.8);
    b.app.materials[leaf as usize].texture = Some(0);
    b.app.materials[leaf as usize].alpha_cutoff = Some(0.5);
    let rgba = (0..64).flat_map(|i| [0, 0, 255, if (i % 8 + i / 8) % 2 == 0 { 255 } else { 0 }]).collect();
    b.app.textures.push(Texture { name: "checker".into(), width: 8, height: 8, rgba, wrap: [Wrap::Repeat; 2] });
    for (z, side, m) in [(0.0, 3.0, red), (0.25, 0.6, green), (0.5, 1.0, leaf)] {
        let p = |x: f64, y: f64| DVec3::new(0.5 + (x - 0.5) * side, 0.5 + (y - 0.5) * side, z);
        b.textured_quad([p(0.0, 0.0), p(1.0, 0.0), p(1.0, 1.0), p(0.0, 1.0)], m);
    }
    b.finish()
}

/// The Cornell box, y up, 0..1 on every axis, open towards +z.
pub fn cornell() -> (Mesh, Appearance) {
    let mut b = Builder::default();
    let white = b.material("white", [0.73, 0.73, 0.73], [0.0; 3], 0.8);
    let red = b.material("red", [0.65, 0.05, 0.05], [0.0; 3], 0.8);
    let green = b.material("green", [0.12, 0.45, 0.15], [0.0; 3], 0.8);
    let light = b.material("light", [1.0; 3], [12.0; 3], 0.8);
    let p = DVec3::new;
    b.quad([p(0.0, 0.0, 0.0), p(0.0, 0.0, 1.0), p(1.0, 0.0, 1.0), p(1.0, 0.0, 0.0)], white); // floor
    b.quad([p(0.0, 1.0, 0.0), p(1.0, 1.0, 0.0), p(1.0, 1.0, 1.0), p(0.0, 1.0, 1.0)], white); // ceiling
    b.quad([p(0.0, 0.0, 0.0), p(1.0, 0.0, 0.0), p(1.0, 1.0, 0.0), p(0.0, 1.0, 0.0)], white); // back
    b.quad([p(0.0, 0.0, 0.0), p(0.0, 1.0, 0.0), p(0.0, 1.0, 1.0), p(0.0, 0.0, 1.0)], red); // left
    b.quad([p(1.0, 0.0, 0.0), p(1.0, 0.0, 1.0), p(1.0, 1.0, 1.0), p(1.0, 1.0, 0.0)], green); // right
    b.quad([p(0.38, 0.998, 0.38), p(0.62, 0.998, 0.38), p(0.62, 0.998, 0.62), p(0.38, 0.998, 0.62)], light);
    b.block(p(0.15, 0.0, 0.2), p(0.45, 0.6, 0.5), white); // tall block
    b.block(p(0.55, 0.0, 0.5), p(0.85, 0.3, 0.8), white); // short block
    (b.mesh, b.app)
}

/// A city: buildings on a 12 × 12 grid of blocks, trees and street lamps
/// along the streets, y up, about 1 M triangles; the same every time.
pub fn city() -> (Mesh, Appearance) {
    let mut b = Builder::default();
    let mut state = 0x05ee_dc17_u64;
    let mut rnd = move || {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let ground = b.material("asphalt", [0.18, 0.18, 0.2], [0.0; 3], 0.9);
    let facades: Vec<u32> = [[0.62, 0.58, 0.52], [0.45, 0.47, 0.52], [0.7, 0.66, 0.6], [0.5, 0.35, 0.3]]
        .iter()
        .enumerate()
        .map(|(n, c)| b.material(&format!("facade{n}"), *c, [0.0; 3], 0.7))
        .collect();
    let roof = b.material("roof", [0.3, 0.3, 0.32], [0.0; 3], 0.8);
    let trunk = b.material("bark", [0.3, 0.2, 0.12], [0.0; 3], 0.9);
    let leaves = b.material("leaves", [0.15, 0.4, 0.12], [0.0; 3], 0.8);
    let foliage = b.material("foliage", [1.0; 3], [0.0; 3], 0.8);
    b.app.materials[foliage as usize].texture = Some(b.app.textures.len() as u32);
    b.app.materials[foliage as usize].alpha_cutoff = Some(0.5);
    b.app.textures.push(leaf_texture());
    let pole = b.material("pole", [0.12, 0.12, 0.13], [0.0; 3], 0.4);
    let lamp = b.material("lamp", [1.0, 0.95, 0.8], [2.5, 2.2, 1.6], 0.5);
    let (blocks, cell, street) = (12u32, 20.0f64, 6.0f64);
    let size = blocks as f64 * cell;
    let p = DVec3::new;
    // z then x: the ground faces up.
    b.panel(p(-street, 0.0, -street), p(0.0, 0.0, size + 2.0 * street), p(size + 2.0 * street, 0.0, 0.0), 24, 24, ground);
    for bx in 0..blocks {
        for bz in 0..blocks {
            let (x0, z0) = (bx as f64 * cell + street * 0.5, bz as f64 * cell + street * 0.5);
            let w = cell - street;
            let (dx, dz) = (w * (0.7 + 0.3 * rnd()), w * (0.7 + 0.3 * rnd()));
            let h = 8.0 + 52.0 * rnd() * rnd();
            let m = facades[(rnd() * facades.len() as f64) as usize % facades.len()];
            let (lo, hi) = (p(x0, 0.0, z0), p(x0 + dx, h, z0 + dz));
            let floors = (h / 3.0).ceil() as u32;
            // Facades cut into window panels, each face pointing out.
            b.panel(lo, p(0.0, 0.0, dz), p(0.0, h, 0.0), 12, floors, m);
            b.panel(p(hi.x, 0.0, lo.z), p(0.0, h, 0.0), p(0.0, 0.0, dz), floors, 12, m);
            b.panel(lo, p(0.0, h, 0.0), p(dx, 0.0, 0.0), floors, 12, m);
            b.panel(p(lo.x, 0.0, hi.z), p(dx, 0.0, 0.0), p(0.0, h, 0.0), 12, floors, m);
            b.panel(p(lo.x, h, lo.z), p(0.0, 0.0, dz), p(dx, 0.0, 0.0), 4, 4, roof);
        }
    }
    // Trees along the streets between blocks, lamps at every crossing.
    let mut trees = 0;
    while trees < 600 {
        let along = rnd() * size;
        let line = (rnd() * (blocks + 1) as f64).floor() * cell;
        let side = if rnd() < 0.5 { -1.8 } else { 1.8 };
        let (x, z) = if rnd() < 0.5 { (along, line + side) } else { (line + side, along) };
        let h = 3.0 + 2.0 * rnd();
        b.block(p(x - 0.2, 0.0, z - 0.2), p(x + 0.2, h, z + 0.2), trunk);
        let r = 1.4 + 0.8 * rnd();
        let c = p(x, h + r * 0.6, z);
        b.sphere(c, p(r, r * 0.9, r), 24, 32, leaves);
        // Three vertical cards of cut-out foliage through the crown.
        let turn = rnd() * std::f64::consts::PI;
        for k in 0..3 {
            let a = turn + k as f64 * std::f64::consts::PI / 3.0;
            let across = p(a.cos(), 0.0, a.sin()) * (1.3 * r);
            let (lo, hi) = (c.y - 1.2 * r, c.y + 1.1 * r);
            let at = |s: f64, y: f64| p(c.x + across.x * s, y, c.z + across.z * s);
            b.textured_quad([at(-1.0, lo), at(1.0, lo), at(1.0, hi), at(-1.0, hi)], foliage);
        }
        trees += 1;
    }
    for lx in 0..=blocks {
        for lz in 0..=blocks {
            let (x, z) = (lx as f64 * cell - 1.0, lz as f64 * cell - 1.0);
            b.block(p(x - 0.1, 0.0, z - 0.1), p(x + 0.1, 6.0, z + 0.1), pole);
            b.block(p(x - 0.5, 6.0, z - 0.5), p(x + 0.5, 6.3, z + 0.5), lamp);
        }
    }
    b.finish()
}

/// A 64×64 foliage card: leaf-green blobs on transparent texels, from a
/// fixed-seed generator (alpha 255 inside a leaf, 0 outside).
fn leaf_texture() -> Texture {
    const N: usize = 64;
    let mut state = 0x1eaf_u64;
    let mut rnd = move || {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    // Leaves: ellipses at random places inside the card's rounded outline.
    let leaves: Vec<[f64; 5]> = (0..90).map(|_| [rnd(), rnd(), 0.03 + 0.05 * rnd(), rnd() * std::f64::consts::PI, rnd()]).collect();
    let mut rgba = vec![0u8; 4 * N * N];
    for y in 0..N {
        for x in 0..N {
            let (u, v) = ((x as f64 + 0.5) / N as f64, (y as f64 + 0.5) / N as f64);
            let outline = ((u - 0.5) / 0.5).powi(2) + ((v - 0.45) / 0.55).powi(2) < 1.0;
            let leaf = leaves.iter().find(|l| {
                let (du, dv) = (u - l[0], v - l[1]);
                let (s, c) = l[3].sin_cos();
                let (a, b) = (du * c + dv * s, -du * s + dv * c);
                (a / l[2]).powi(2) + (b / (0.45 * l[2])).powi(2) < 1.0
            });
            if let (true, Some(l)) = (outline, leaf) {
                let shade = 0.75 + 0.25 * l[4];
                let at = 4 * (y * N + x);
                rgba[at..at + 4].copy_from_slice(&[(60.0 * shade) as u8, (140.0 * shade) as u8, (45.0 * shade) as u8, 255]);
            }
        }
    }
    Texture { name: "leaves".into(), width: N as u32, height: N as u32, rgba, wrap: [Wrap::ClampToEdge; 2] }
}

/// The scene as OBJ text naming `mtl_name`, and the MTL text (`Kd`, `Ke`,
/// `Pr`, and `map_Kd` and `map_d` naming `texture_files[t]` for a
/// material of texture `t`: the caller writes those images beside).
pub fn to_obj(mesh: &Mesh, app: &Appearance, mtl_name: &str, texture_files: &[String]) -> (String, String) {
    use std::fmt::Write;
    let mut obj = format!("# written by topovox\nmtllib {mtl_name}\n");
    for p in &mesh.positions {
        let _ = writeln!(obj, "v {} {} {}", p.x, p.y, p.z);
    }
    // One vt per textured corner (OBJ's v = 0 is the image's bottom row).
    let mut vt = 0usize;
    let mut corners = vec![None; mesh.triangles.len()];
    for (t, uv) in app.triangle_uv.iter().enumerate().take(mesh.triangles.len()) {
        if uv.iter().flatten().all(|x| x.is_finite()) {
            for c in uv {
                let _ = writeln!(obj, "vt {} {}", c[0], 1.0 - c[1]);
            }
            corners[t] = Some(vt);
            vt += 3;
        }
    }
    let mut current = NO_MATERIAL;
    for (t, tri) in mesh.triangles.iter().enumerate() {
        let m = app.triangle_material.get(t).copied().unwrap_or(NO_MATERIAL);
        if m != current && m != NO_MATERIAL {
            let _ = writeln!(obj, "usemtl {}", app.materials[m as usize].name);
            current = m;
        }
        match corners[t] {
            Some(k) => {
                let _ = writeln!(obj, "f {}/{} {}/{} {}/{}", tri[0] + 1, k + 1, tri[1] + 1, k + 2, tri[2] + 1, k + 3);
            }
            None => {
                let _ = writeln!(obj, "f {} {} {}", tri[0] + 1, tri[1] + 1, tri[2] + 1);
            }
        }
    }
    let mut mtl = String::from("# written by topovox\n");
    for m in &app.materials {
        let (k, e) = (m.factor, m.emission);
        let _ = writeln!(mtl, "newmtl {}\nKd {} {} {}\nKe {} {} {}\nPr {}", m.name, k[0], k[1], k[2], e[0], e[1], e[2], m.roughness);
        if let Some(file) = m.texture.and_then(|t| texture_files.get(t as usize)) {
            let _ = writeln!(mtl, "map_Kd {file}");
            if m.alpha_cutoff.is_some() {
                let _ = writeln!(mtl, "map_d {file}");
            }
        }
        mtl.push('\n');
    }
    (obj, mtl)
}
