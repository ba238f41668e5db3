//! Deterministic test scenes, as a mesh with materials (so they go through
//! every reader-facing path) and as OBJ + MTL text.
//!
//! - [`cornell`]: the Cornell box — white floor, ceiling and back wall, red
//!   left and green right walls, two white blocks, an emissive square just
//!   below the ceiling (its own material, `Ke` 12).

use voxkit::attributes::{Appearance, Material, NO_MATERIAL};
use voxkit::glam::DVec3;
use voxkit::Mesh;

/// A scene under construction: triangles and their materials.
#[derive(Default)]
struct Builder {
    mesh: Mesh,
    app: Appearance,
}

impl Builder {
    fn material(&mut self, name: &str, colour: [f32; 3], emission: [f32; 3], roughness: f32) -> u32 {
        self.app.materials.push(Material { name: name.into(), factor: colour, texture: None, emission, roughness });
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

/// The scene as OBJ text naming `mtl_name`, and the MTL text (`Kd`, `Ke`,
/// `Pr`).
pub fn to_obj(mesh: &Mesh, app: &Appearance, mtl_name: &str) -> (String, String) {
    use std::fmt::Write;
    let mut obj = format!("# written by voxkit\nmtllib {mtl_name}\n");
    for p in &mesh.positions {
        let _ = writeln!(obj, "v {} {} {}", p.x, p.y, p.z);
    }
    let mut current = NO_MATERIAL;
    for (t, tri) in mesh.triangles.iter().enumerate() {
        let m = app.triangle_material.get(t).copied().unwrap_or(NO_MATERIAL);
        if m != current && m != NO_MATERIAL {
            let _ = writeln!(obj, "usemtl {}", app.materials[m as usize].name);
            current = m;
        }
        let _ = writeln!(obj, "f {} {} {}", tri[0] + 1, tri[1] + 1, tri[2] + 1);
    }
    let mut mtl = String::from("# written by voxkit\n");
    for m in &app.materials {
        let (k, e) = (m.factor, m.emission);
        let _ = writeln!(mtl, "newmtl {}\nKd {} {} {}\nKe {} {} {}\nPr {}\n", m.name, k[0], k[1], k[2], e[0], e[1], e[2], m.roughness);
    }
    (obj, mtl)
}
