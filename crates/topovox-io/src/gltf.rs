//! glTF 2.0 (`.gltf` with external or embedded buffers, and `.glb`),
//! through the `gltf` crate.
//!
//! Every triangle primitive (modes TRIANGLES, TRIANGLE_STRIP, TRIANGLE_FAN)
//! of every mesh instanced by the default scene (or the first scene if none
//! is marked default) is read with its node's world transform applied.
//! Point and line primitives are skipped with a warning.

use std::collections::HashMap;
use std::path::Path;

use glam::{DMat4, DVec3, Mat4};
use gltf::image::Format;
use gltf::mesh::Mode;
use gltf::texture::WrappingMode;
use topovox::attributes::colour::from_linear;
use topovox::attributes::{Appearance, Material, Texture, Wrap, DEFAULT_ROUGHNESS};

use crate::error::ErrorKind;
use crate::mesh_report::{finish, LoadedMesh};
use crate::resources::{uri_target, Resources, UriTarget};

/// Parses glTF JSON or GLB bytes; `res` resolves external buffer and
/// image URIs (a buffer outside the model's folder is an error, an image a
/// warning). Every file is read here, through `res`, never by the `gltf`
/// crate (which would open `file:` URIs, devices and FIFOs wherever they
/// are): it only decodes `data:` URIs and GLB chunks.
pub(crate) fn read(bytes: &[u8], res: &Resources) -> Result<LoadedMesh, ErrorKind> {
    let gltf::Gltf { document, blob } = gltf::Gltf::from_slice(bytes).map_err(|e| ErrorKind::malformed("glTF", e))?;
    let buffers = load_buffers(&document, blob, res)?;
    let mut out = Builder::default();
    out.materials(&document, &buffers, res);
    let scene = document.default_scene().or_else(|| document.scenes().next());
    if let Some(scene) = &scene {
        check_instances(scene, res.read_limit())?;
    }
    match scene {
        Some(scene) => {
            for node in scene.nodes() {
                out.node(&node, DMat4::IDENTITY, &buffers, 0)?;
            }
        }
        None => {
            out.warnings.push("no scene: reading every mesh untransformed".into());
            for mesh in document.meshes() {
                out.mesh(&mesh, DMat4::IDENTITY, &buffers)?;
            }
        }
    }
    let mut app = out.app;
    // Only glTF's default material: the file has no colour of its own.
    if app.materials.len() == 1 {
        app.triangle_material.clear();
        app.triangle_uv.clear();
        app.materials.clear();
    }
    if app.vertex_colour.iter().all(|&c| c == [255; 3]) {
        app.vertex_colour.clear();
    }
    let mut loaded = finish(out.positions, out.triangles, out.warnings)?;
    loaded.appearance = app;
    Ok(loaded)
}

#[derive(Default)]
struct Builder {
    positions: Vec<DVec3>,
    triangles: Vec<[i64; 3]>,
    warnings: Vec<String>,
    app: Appearance,
    /// Per glTF material: its texture coordinate set.
    tex_coord: Vec<u32>,
}

impl Builder {
    /// Every material of the document, plus glTF's default material (white, last).
    fn materials(&mut self, document: &gltf::Document, buffers: &[gltf::buffer::Data], res: &Resources) {
        let mut decoded: Vec<Option<Option<u32>>> = vec![None; document.textures().len()];
        for m in document.materials() {
            let pbr = m.pbr_metallic_roughness();
            let f = pbr.base_color_factor();
            let mut texture = None;
            let mut set = 0;
            if let Some(info) = pbr.base_color_texture() {
                set = info.tex_coord();
                let t = info.texture();
                texture = *decoded[t.index()].get_or_insert_with(|| match self.texture(&t, buffers, res) {
                    Ok(tex) => {
                        self.app.textures.push(tex);
                        Some(self.app.textures.len() as u32 - 1)
                    }
                    Err(e) => {
                        self.warnings.push(format!("texture {}: {e}; the base colour factor is used instead", t.index()));
                        None
                    }
                });
            }
            let name = format!("material {}", m.index().unwrap_or(0));
            let e = m.emissive_factor();
            let roughness = pbr.roughness_factor().clamp(0.0, 1.0);
            // MASK cuts out below alphaCutoff (glTF's default 0.5); BLEND
            // would need sorting and is drawn opaque, as OPAQUE is.
            let alpha_cutoff = match m.alpha_mode() {
                gltf::material::AlphaMode::Mask => Some(m.alpha_cutoff().unwrap_or(0.5)).filter(|c| c.is_finite()),
                _ => None,
            };
            self.app.materials.push(Material {
                name,
                factor: [f[0], f[1], f[2]],
                texture,
                emission: e.map(|x| x.max(0.0)),
                roughness,
                alpha_cutoff,
                alpha_texture: None,
            });
            self.tex_coord.push(set);
        }
        self.app.materials.push(Material {
            name: "default".into(),
            factor: [1.0; 3],
            texture: None,
            emission: [0.0; 3],
            roughness: DEFAULT_ROUGHNESS,
            alpha_cutoff: None,
            alpha_texture: None,
        });
        self.tex_coord.push(0);
    }

    fn texture(&self, t: &gltf::Texture<'_>, buffers: &[gltf::buffer::Data], res: &Resources) -> Result<Texture, String> {
        let wrap = |m: WrappingMode| match m {
            WrappingMode::ClampToEdge => Wrap::ClampToEdge,
            WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
            WrappingMode::Repeat => Wrap::Repeat,
        };
        let sampler = t.sampler();
        let wrap = [wrap(sampler.wrap_s()), wrap(sampler.wrap_t())];
        let data = load_image(t.source().source(), buffers, res)?;
        let n = data.width as usize * data.height as usize;
        type Pick = fn(&[u8]) -> [u8; 4];
        let (step, pick): (usize, Pick) = match data.format {
            Format::R8 => (1, |p| [p[0], p[0], p[0], 255]),
            Format::R8G8 => (2, |p| [p[0], p[0], p[0], p[1]]),
            Format::R8G8B8 => (3, |p| [p[0], p[1], p[2], 255]),
            Format::R8G8B8A8 => (4, |p| [p[0], p[1], p[2], p[3]]),
            Format::R16 => (2, |p| [p[1], p[1], p[1], 255]),
            Format::R16G16 => (4, |p| [p[1], p[1], p[1], p[3]]),
            Format::R16G16B16 => (6, |p| [p[1], p[3], p[5], 255]),
            Format::R16G16B16A16 => (8, |p| [p[1], p[3], p[5], p[7]]),
            f => return Err(format!("{f:?} images are not supported")),
        };
        if n == 0 || data.pixels.len() < n * step {
            return Err(format!("image is {}x{} but has {} bytes", data.width, data.height, data.pixels.len()));
        }
        let rgba = data.pixels.chunks_exact(step).take(n).flat_map(pick).collect();
        Ok(Texture { name: format!("texture {}", t.index()), width: data.width, height: data.height, rgba, wrap })
    }

    fn node(&mut self, node: &gltf::Node<'_>, parent: DMat4, buffers: &[gltf::buffer::Data], depth: usize) -> Result<(), ErrorKind> {
        if depth > 256 {
            return Err(ErrorKind::malformed("glTF", "node hierarchy deeper than 256 (cycle?)"));
        }
        let local = Mat4::from_cols_array_2d(&node.transform().matrix()).as_dmat4();
        let world = parent * local;
        if let Some(mesh) = node.mesh() {
            self.mesh(&mesh, world, buffers)?;
        }
        for child in node.children() {
            self.node(&child, world, buffers, depth + 1)?;
        }
        Ok(())
    }

    fn mesh(&mut self, mesh: &gltf::Mesh<'_>, world: DMat4, buffers: &[gltf::buffer::Data]) -> Result<(), ErrorKind> {
        for prim in mesh.primitives() {
            let mode = prim.mode();
            if !matches!(mode, Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan) {
                self.warnings.push(format!("mesh {}: skipped a {mode:?} primitive (not triangles)", mesh.index()));
                continue;
            }
            let mi = mesh.index();
            let pos_acc = prim.get(&gltf::Semantic::Positions);
            if let Some(a) = &pos_acc {
                check_accessor(a, buffers, mi)?;
            }
            if let Some(a) = prim.indices() {
                check_accessor(&a, buffers, mi)?;
            }
            let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
            let Some(pos) = reader.read_positions() else {
                self.warnings.push(format!("mesh {}: primitive without POSITION skipped", mesh.index()));
                continue;
            };
            let base = self.positions.len() as i64;
            self.positions.extend(pos.map(|p| world.transform_point3(DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64))));
            let n = self.positions.len() as i64 - base;
            let material = prim.material().index().unwrap_or(self.app.materials.len() - 1);
            let set = self.tex_coord.get(material).copied().unwrap_or(0);
            let uvs: Vec<[f32; 2]> = match prim.get(&gltf::Semantic::TexCoords(set)) {
                Some(a) => {
                    check_accessor(&a, buffers, mi)?;
                    reader.read_tex_coords(set).map(|t| t.into_f32().collect()).unwrap_or_default()
                }
                None => Vec::new(),
            };
            if let Some(a) = prim.get(&gltf::Semantic::Colors(0)) {
                check_accessor(&a, buffers, mi)?;
                if let Some(c) = reader.read_colors(0) {
                    self.app.vertex_colour.resize(base as usize, [255; 3]);
                    self.app.vertex_colour.extend(c.into_rgb_f32().map(|c| c.map(|x| from_linear(x as f64))));
                }
            }
            if !self.app.vertex_colour.is_empty() {
                self.app.vertex_colour.resize(self.positions.len(), [255; 3]);
            }
            let first_triangle = self.triangles.len();
            let idx: Vec<i64> = match reader.read_indices() {
                Some(i) => i.into_u32().map(|i| i as i64 + base).collect(),
                None => (base..base + n).collect(),
            };
            // Checked here, per primitive, so that no message quotes an
            // index: a buffer's bytes come from a file the user did not name.
            if let Some(at) = idx.iter().position(|&i| i >= base + n) {
                return Err(ErrorKind::malformed("glTF", format!("mesh {mi}: index {at} of a primitive refers past its {n} vertices")));
            }
            match mode {
                Mode::Triangles => {
                    for t in idx.chunks_exact(3) {
                        self.triangles.push([t[0], t[1], t[2]]);
                    }
                }
                Mode::TriangleStrip => {
                    for w in 0..idx.len().saturating_sub(2) {
                        let t = if w % 2 == 0 { [idx[w], idx[w + 1], idx[w + 2]] } else { [idx[w + 1], idx[w], idx[w + 2]] };
                        self.triangles.push(t);
                    }
                }
                _ => {
                    for w in 1..idx.len().saturating_sub(1) {
                        self.triangles.push([idx[0], idx[w], idx[w + 1]]);
                    }
                }
            }
            let uv_of = |v: i64| uvs.get((v - base) as usize).copied().unwrap_or([f32::NAN; 2]);
            for t in &self.triangles[first_triangle..] {
                self.app.triangle_material.push(material as u32);
                self.app.triangle_uv.push(t.map(uv_of));
            }
        }
        Ok(())
    }
}

/// Vertices and index entries (a bound on triangles) of everything under
/// a node, meshes counted once per instance.
#[derive(Clone, Copy, Default)]
struct Size {
    vertices: u64,
    indices: u64,
    instances: u64,
    /// Nodes the expansion walks (a node without a mesh still costs a visit).
    visits: u64,
}

/// The most node visits a scene's expansion may take: about a second of
/// transforms. A scene of empty nodes that share children can ask for 10⁹.
const MAX_NODE_VISITS: u64 = 1 << 24;

impl Size {
    fn add(self, o: Size) -> Size {
        Size {
            vertices: self.vertices.saturating_add(o.vertices),
            indices: self.indices.saturating_add(o.indices),
            instances: self.instances.saturating_add(o.instances),
            visits: self.visits.saturating_add(o.visits),
        }
    }

    /// Bytes reading the expanded mesh holds at its peak beyond its
    /// buffers: per vertex 36, per triangle 96 (positions in f64, the
    /// triangles as read and as kept, a material and three UVs; measured
    /// on 10⁶-triangle meshes and soups, 2026-12-02, and rounded up).
    fn bytes(self) -> u64 {
        self.vertices.saturating_mul(36).saturating_add((self.indices / 3).saturating_mul(96))
    }
}

/// Refuses a scene whose nodes share children so often that expanding
/// every instance would not fit in the memory a read may take: a 9.5 KB
/// file can place one mesh 10⁹ times, or walk 10⁹ nodes without a mesh.
/// Counted from the accessors' counts, each node once (memoized), before
/// anything is expanded.
fn check_instances(scene: &gltf::Scene<'_>, limit: u64) -> Result<(), ErrorKind> {
    fn mesh_size(mesh: &gltf::Mesh<'_>) -> Size {
        mesh.primitives().fold(Size { instances: 1, ..Size::default() }, |s, p| {
            let v = p.get(&gltf::Semantic::Positions).map_or(0, |a| a.count() as u64);
            let i = p.indices().map_or(v, |a| a.count() as u64);
            s.add(Size { vertices: v, indices: i, ..Size::default() })
        })
    }
    fn size(node: &gltf::Node<'_>, depth: usize, memo: &mut HashMap<usize, Size>) -> Result<Size, ErrorKind> {
        if depth > 256 {
            return Err(ErrorKind::malformed("glTF", "node hierarchy deeper than 256 (cycle?)"));
        }
        if let Some(&s) = memo.get(&node.index()) {
            return Ok(s);
        }
        let mut s = node.mesh().map(|m| mesh_size(&m)).unwrap_or_default();
        s.visits = 1;
        for child in node.children() {
            s = s.add(size(&child, depth + 1, memo)?);
        }
        memo.insert(node.index(), s);
        Ok(s)
    }
    let mut memo = HashMap::new();
    let mut total = Size::default();
    for node in scene.nodes() {
        total = total.add(size(&node, 0, &mut memo)?);
    }
    if total.bytes() > limit {
        return Err(ErrorKind::malformed(
            "glTF",
            format!(
                "the scene places its meshes {} times: {} vertices, about {} expanded, more than the {} a read may take",
                total.instances,
                total.vertices,
                crate::bytes(total.bytes()),
                crate::bytes(limit)
            ),
        ));
    }
    if total.visits > MAX_NODE_VISITS {
        return Err(ErrorKind::malformed(
            "glTF",
            format!(
                "the scene's nodes share children so often that expanding it visits {} nodes, more than {MAX_NODE_VISITS}",
                total.visits
            ),
        ));
    }
    Ok(())
}

/// Every buffer of the document: the GLB chunk, a `data:` URI, or a file
/// read through `res` (the folder rule, regular files only, exactly its
/// `byteLength` bytes), padded to four bytes as the `gltf` crate pads.
fn load_buffers(document: &gltf::Document, mut blob: Option<Vec<u8>>, res: &Resources) -> Result<Vec<gltf::buffer::Data>, ErrorKind> {
    let mut out = Vec::with_capacity(document.buffers().len());
    for b in document.buffers() {
        let bad = |why: String| ErrorKind::malformed("glTF", format!("buffer {}: {why}", b.index()));
        let mut data = match b.source() {
            gltf::buffer::Source::Bin => blob.take().ok_or_else(|| bad("refers to the GLB binary chunk, which is missing".into()))?,
            gltf::buffer::Source::Uri(uri) => match uri_target(uri).map_err(bad)? {
                UriTarget::Data(data) => {
                    gltf::buffer::Data::from_source(gltf::buffer::Source::Uri(&data), None).map_err(|e| bad(e.to_string()))?.0
                }
                UriTarget::Path(reference) => res.read(&reference, Some(b.length() as u64)).map_err(bad)?,
            },
        };
        if data.len() < b.length() {
            return Err(bad(format!("holds {} bytes, fewer than its byteLength {}", data.len(), b.length())));
        }
        data.resize(data.len().next_multiple_of(4), 0);
        out.push(gltf::buffer::Data(data));
    }
    Ok(out)
}

/// An image's pixels: from a buffer view or a `data:` URI (decoded by the
/// `gltf` crate, which then reads no file), or from a file read through
/// `res` and decoded by [`crate::texture::decode`].
fn load_image(source: gltf::image::Source<'_>, buffers: &[gltf::buffer::Data], res: &Resources) -> Result<gltf::image::Data, String> {
    let reference = match source {
        gltf::image::Source::View { .. } => return decoded(source, buffers),
        gltf::image::Source::Uri { uri, mime_type } => match uri_target(uri).map_err(|why| format!("image {why}"))? {
            UriTarget::Data(data) => return decoded(gltf::image::Source::Uri { uri: &data, mime_type }, buffers),
            UriTarget::Path(reference) => reference,
        },
    };
    let bytes = res.read(&reference, None).map_err(|why| format!("image {why}"))?;
    let t = crate::texture::decode(&bytes, &reference.display().to_string(), [Wrap::Repeat; 2])?;
    Ok(gltf::image::Data { pixels: t.rgba, format: Format::R8G8B8A8, width: t.width, height: t.height })
}

/// An image from a buffer view or a `data:` URI, decoded by the `gltf`
/// crate: its base folder is given (the crate asks for one) but never read
/// from, since neither source names a file.
fn decoded(source: gltf::image::Source<'_>, buffers: &[gltf::buffer::Data]) -> Result<gltf::image::Data, String> {
    gltf::image::Data::from_source(source, Some(Path::new("")), buffers).map_err(|e| format!("image could not be loaded ({e})"))
}

/// Checks that an accessor's elements lie inside its buffer view and the
/// view inside its buffer, so reading can neither fail silently nor panic.
fn check_accessor(a: &gltf::Accessor<'_>, buffers: &[gltf::buffer::Data], mesh: usize) -> Result<(), ErrorKind> {
    let bad = |d: String| ErrorKind::malformed("glTF", format!("mesh {mesh}, accessor {}: {d}", a.index()));
    let Some(view) = a.view() else {
        if a.sparse().is_some() {
            return Err(ErrorKind::Unsupported(format!("sparse accessor {} without a buffer view", a.index())));
        }
        return Err(bad("no buffer view".into()));
    };
    let buf_len = buffers.get(view.buffer().index()).map(|d| d.0.len()).ok_or_else(|| bad("buffer not loaded".into()))?;
    let view_end = view.offset().checked_add(view.length()).ok_or_else(|| bad("view overflows".into()))?;
    if view_end > buf_len {
        return Err(bad(format!("buffer view {} ends at byte {view_end}, past the buffer's {buf_len} bytes", view.index())));
    }
    if a.count() > 0 {
        let elem = a.size();
        let stride = view.stride().unwrap_or(elem);
        let need = (a.count() as u64 - 1) * stride as u64 + elem as u64 + a.offset() as u64;
        if need > view.length() as u64 {
            return Err(bad(format!("{} elements need {need} bytes but buffer view {} has {}", a.count(), view.index(), view.length())));
        }
    }
    Ok(())
}
