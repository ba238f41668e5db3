//! Training samples (`topovox sample`, `topovox.sample`, batch `--run
//! sample`): points on, near and around a mesh with their exact signed
//! distance and occupancy ([`topovox::query::sample`]), and the `.npz`
//! they are written to.

use std::path::Path;
use std::time::Instant;

use glam::DVec3;
use serde_json::{json, Value};
use topovox::query::sample::{default_bounds, normalization, sample as draw, Normalize, SampleSpec, Samples};
use topovox::query::{Query, QueryFacts};
use topovox::MeshRef;

use crate::distance::Sign;
use crate::error::{JobError, Result};
use crate::options::RunOptions;
use crate::table::{choice, chosen, int, number_list, value, Example};
use topovox::choice::Choice;

topovox::choice! {
    /// How the mesh is moved and scaled before sampling.
    pub enum Normalization: "normalize" default None {
        /// As given.
        None = "none",
        /// Box centre to the origin, longest side 1 (Occupancy Networks, IF-Net).
        UnitCube = "unit-cube",
        /// Box centre to the origin, farthest vertex at distance 1 (DeepSDF).
        UnitSphere = "unit-sphere",
    }
}

fn count(k: &str, v: &crate::table::OptionValue) -> Result<u64> {
    let n = int(k, v, 0)?;
    if n > 1 << 32 {
        return Err(JobError::invalid(format!("{k} must be at most 4294967296 points; got {n}")));
    }
    Ok(n)
}

crate::option_table! {
    /// What to draw (`topovox sample`, `topovox.sample`).
    pub struct SampleDraw {
        surface: u64 = 0,
            parse count,
            example Example::Int(1000),
            print |o| Some(json!(o.surface)),
            cli value("N"),
            "points uniform on the surface (by area), with their triangle's unit normal";
        near: u64 = 0,
            parse count,
            example Example::Int(1000),
            print |o| Some(json!(o.near)),
            cli value("N"),
            "surface points moved by an isotropic Gaussian of each --sigma in turn (DeepSDF's near-surface samples, IF-Net's boundary sampling)";
        sigma: Vec<f64> = vec![0.005, 0.05],
            parse |k, v| {
                let s = number_list(k, v)?;
                if s.is_empty() || s.iter().any(|x| !(*x > 0.0 && x.is_finite())) {
                    return Err(JobError::invalid(format!("{k} must be positive numbers; got {s:?}")));
                }
                Ok(s)
            },
            example Example::Float(0.01),
            print |o| Some(json!(o.sigma)),
            cli value("S,S,..."),
            "the near points' standard deviations, in the (normalized) mesh's units (default 0.005,0.05)";
        uniform: u64 = 0,
            parse count,
            example Example::Int(1000),
            print |o| Some(json!(o.uniform)),
            cli value("N"),
            "points uniform in --bounds (Occupancy Networks' box samples)";
        bounds: Option<Vec<f64>> = None,
            parse |k, v| {
                let b = number_list(k, v)?;
                if b.len() != 6 || b.iter().any(|x| !x.is_finite()) || (0..3).any(|a| b[a] >= b[a + 3]) {
                    return Err(JobError::invalid(format!("{k} must be six finite numbers X0,Y0,Z0,X1,Y1,Z1 with low < high; got {b:?}")));
                }
                Ok(Some(b))
            },
            example Example::Numbers(&[-1.0, -1.0, -1.0, 1.0, 1.0, 1.0]),
            print |o| Some(json!(o.bounds)),
            cli value("X0,Y0,Z0,X1,Y1,Z1"),
            "the uniform points' box (default: the (normalized) mesh's box grown by 5 % of its longest side on every side)";
        normalize: Normalization = Normalization::None,
            parse chosen,
            example Example::Text("unit-sphere"),
            print |o| Some(json!(o.normalize.name())),
            cli choice::<Normalization>("HOW"),
            "move the box centre to the origin and scale the longest side (unit-cube) or the farthest vertex (unit-sphere) to 1 first; offset and scale are saved";
        seed: u64 = 0,
            parse |k, v| int(k, v, 0),
            example Example::Int(1),
            print |o| Some(json!(o.seed)),
            cli value("SEED"),
            "the random seed: the same samples for a seed on any machine and thread count";
        sign: Sign = Sign::Auto,
            parse chosen,
            example Example::Text("winding"),
            print |o| Some(json!(o.sign.name())),
            cli choice::<Sign>("RULE"),
            "how inside is decided: auto (the rule of voxelize --mode solid), parity or winding";
    }
}

crate::option_table! {
    /// Every option of a sample job.
    pub struct SampleOptions {
        [group draw: SampleDraw, "What to draw."]
        [group run: RunOptions, "Threads, memory, paths."]
    }
}

/// Samples of one mesh and how they were made.
#[derive(Clone, Debug)]
pub struct Sampled {
    /// The samples (in normalized coordinates).
    pub samples: Samples,
    /// `normalized = (original − offset) · scale`.
    pub offset: DVec3,
    /// See `offset`.
    pub scale: f64,
    /// The uniform points' box.
    pub bounds: (DVec3, DVec3),
    /// The colour of each surface point (sRGB in [0, 1]; NaN for the
    /// other kinds), when the mesh has colours.
    pub colours: Option<Vec<[f32; 3]>>,
    /// What the query knew of the mesh.
    pub facts: QueryFacts,
    /// Seconds: building the query, drawing and measuring.
    pub seconds: (f64, f64),
}

/// Bytes a sample takes while drawn and measured (point, normal, its
/// triangle and weights, two f64 values, flags, the Morton order, a
/// colour) and written (f32 copies).
const BYTES_PER_SAMPLE: u64 = 188;

/// Draws `options`' samples of `loaded` (`name` in errors), refusing
/// before any work a count and a mesh that do not fit in `--max-memory`
/// (default: 90 % of the memory available; see
/// [`crate::query_bytes`]). Surface points carry the mesh's colour
/// where it has colours ([`topovox::attributes::carry::colour_at`]).
pub fn sample(loaded: &topovox_io::LoadedMesh, name: &str, options: &SampleOptions) -> Result<Sampled> {
    let mesh = loaded.mesh.as_ref();
    let o = &options.draw;
    let total = o.surface + o.near + o.uniform;
    let query = crate::memory::query_bytes(mesh);
    let need = total.saturating_mul(BYTES_PER_SAMPLE).saturating_add(query);
    let budget = crate::memory::budget(options.run.max_memory);
    if need > budget {
        return Err(JobError::failed(format!(
            "{total} samples of {} triangles need about {} of memory (the mesh's query {}), more than the {} this run may use; draw fewer, simplify the mesh or raise --max-memory",
            mesh.triangles.len(),
            crate::memory::bytes(need),
            crate::memory::bytes(query),
            crate::memory::bytes(budget)
        )));
    }
    let t = Instant::now();
    let how = match o.normalize {
        Normalization::None => Normalize::None,
        Normalization::UnitCube => Normalize::UnitCube,
        Normalization::UnitSphere => Normalize::UnitSphere,
    };
    let used = topovox::query::inside::triangles(mesh);
    let (offset, scale) = normalization(&used, how);
    let moved: Vec<DVec3> = mesh.positions.iter().map(|&p| (p - offset) * scale).collect();
    let m = MeshRef { positions: &moved, triangles: mesh.triangles, segments: mesh.segments };
    let q = Query::new(m, o.sign.into()).map_err(|e| JobError::invalid(format!("{name}: {e}")))?;
    let built = t.elapsed().as_secs_f64();
    let bounds = match &o.bounds {
        Some(b) => (DVec3::new(b[0], b[1], b[2]), DVec3::new(b[3], b[4], b[5])),
        None => default_bounds(&q.triangles()),
    };
    let spec = SampleSpec {
        surface: o.surface as usize,
        near: o.near as usize,
        sigma: o.sigma.clone(),
        uniform: o.uniform as usize,
        bounds,
        seed: o.seed,
    };
    let t = Instant::now();
    let samples = draw(&q, &spec).map_err(|e| JobError::invalid(format!("{name}: {e}")))?;
    let colours = loaded.appearance.has_colour().then(|| colours(mesh, &loaded.appearance, &samples));
    Ok(Sampled { samples, offset, scale, bounds, colours, facts: q.facts(), seconds: (built, t.elapsed().as_secs_f64()) })
}

/// The colour of each surface sample, sRGB in [0, 1]; NaN for the others.
fn colours(mesh: MeshRef<'_>, app: &topovox::attributes::Appearance, samples: &Samples) -> Vec<[f32; 3]> {
    use rayon::prelude::*;
    samples
        .faces
        .par_iter()
        .map(|&(face, w)| {
            if face == u32::MAX {
                [f32::NAN; 3]
            } else {
                topovox::attributes::carry::colour_at(mesh, app, face as usize, w).map(|c| c as f32 / 255.0)
            }
        })
        .collect()
}

impl Sampled {
    /// The warning for a mesh of sheets only: its points and distances
    /// are exact, its signs a guess (solids refuse it).
    pub fn sign_warning(&self, name: &str) -> Option<String> {
        self.facts.orientation.filter(|r| r.only_sheets()).map(|_| {
            format!("{name}: encloses no volume (only open sheets): distances are exact, but the signs and occupancy are the generalized winding number's guess")
        })
    }

    /// The facts of a summary: counts, the rule, normalization, times.
    pub fn summary(&self) -> Value {
        let kinds = |k: u8| self.samples.kind.iter().filter(|&&x| x as u8 == k).count();
        let inside = self.samples.occupancy.iter().filter(|&&x| x).count();
        json!({
            "points": self.samples.points.len(),
            "colours": self.colours.is_some(),
            "surface": kinds(0), "near": kinds(1), "uniform": kinds(2),
            "inside": inside,
            "sign": Sign::from(self.facts.sign).name(),
            "watertight": self.facts.watertight,
            "boundary_cycles": self.facts.cycles,
            "orientation": self.facts.orientation.map(crate::facts::OrientFacts::from),
            "offset": self.offset.to_array(), "scale": self.scale,
            "bounds": [self.bounds.0.to_array(), self.bounds.1.to_array()],
            "times": {"query_s": self.seconds.0, "sample_s": self.seconds.1},
        })
    }

    /// Writes the samples to `path` as `.npz`, all or nothing: `points`
    /// (N, 3) float32, `sdf` (N,) float32, `occupancy` (N,) bool,
    /// `normals` (N, 3) float32 (NaN except surface points), `kind` (N,)
    /// uint8 (0 surface, 1 near, 2 uniform), `offset` (3,) and `scale` ()
    /// float64, `bounds` (2, 3) float64, and where the mesh has colours
    /// `colours` (N, 3) float32 (sRGB in [0, 1], NaN except surface points).
    pub fn write(&self, path: &Path) -> Result<()> {
        use topovox_io::npz::{write_arrays, Member};
        let s = &self.samples;
        let n = s.points.len() as u64;
        let f32s = |v: &mut dyn Iterator<Item = f64>| v.flat_map(|x| (x as f32).to_le_bytes()).collect::<Vec<u8>>();
        let f64s = |v: &[f64]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
        let mut members = vec![
            Member { name: "points", descr: "<f4", shape: vec![n, 3], bytes: f32s(&mut s.points.iter().flat_map(|p| p.to_array())) },
            Member { name: "sdf", descr: "<f4", shape: vec![n], bytes: f32s(&mut s.sdf.iter().copied()) },
            Member { name: "occupancy", descr: "|b1", shape: vec![n], bytes: s.occupancy.iter().map(|&o| u8::from(o)).collect() },
            Member { name: "normals", descr: "<f4", shape: vec![n, 3], bytes: f32s(&mut s.normals.iter().flat_map(|p| p.to_array())) },
            Member { name: "kind", descr: "|u1", shape: vec![n], bytes: s.kind.iter().map(|&k| k as u8).collect() },
            Member { name: "offset", descr: "<f8", shape: vec![3], bytes: f64s(&self.offset.to_array()) },
            Member { name: "scale", descr: "<f8", shape: vec![], bytes: f64s(&[self.scale]) },
            Member {
                name: "bounds",
                descr: "<f8",
                shape: vec![2, 3],
                bytes: f64s(&[self.bounds.0.to_array(), self.bounds.1.to_array()].concat()),
            },
        ];
        if let Some(c) = &self.colours {
            members.push(Member {
                name: "colours",
                descr: "<f4",
                shape: vec![n, 3],
                bytes: f32s(&mut c.iter().flatten().map(|&x| x as f64)),
            });
        }
        topovox_io::atomic::write_atomically(path, |w| write_arrays(w, &members)).map_err(JobError::from)
    }
}
