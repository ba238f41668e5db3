//! Every option of a voxelization job, once: what `topovox voxelize` and
//! `topovox batch` take as flags and the Python package as keywords, typed
//! ([`JobOptions`]), named ([`KEYWORDS`], [`JobOptions::set`]), and turned
//! here — and nowhere else — into the plan, the attribute policy, the
//! writer options, the batch options and the batch's fingerprint.

use std::path::PathBuf;

use serde_json::{json, Value};
use topovox::attributes::carry::CarryOptions;
use topovox::attributes::ColourRule;
use topovox::choice::Choice;
use topovox_io::orient::Up;

use crate::batch::BatchOptions;
use crate::error::{JobError, Result};
use crate::grid::{GridOptions, GridRequest};
use crate::invalid;
use crate::output::Output;
use crate::plan::{Fill, GpuPath, Hollow, Method, Mode, Plan, Request};

/// Every option of a voxelization job, typed; `Default` gives each
/// option's documented default.
#[derive(Clone, Debug, PartialEq)]
pub struct JobOptions {
    /// The mode.
    pub mode: Mode,
    /// The method.
    pub method: Method,
    /// The grid.
    pub grid: GridOptions,
    /// Solid modes: the surface of `solid+surface` and of a flood fill's shell.
    pub surface: Option<Mode>,
    /// Solid modes: fill by flood instead of the inside test.
    pub fill: Option<Fill>,
    /// Solid modes: keep only the skin.
    pub hollow: Option<Hollow>,
    /// `method gpu`: which GPU path.
    pub gpu_path: GpuPath,
    /// `bubble`: the seed of its random points.
    pub seed: u64,
    /// Tiles of this many voxels (`None`: only past memory).
    pub tile: Option<u32>,
    /// Memory the run may use, bytes (`None`: nine tenths of what is available).
    pub max_memory: Option<u64>,
    /// How colours combine in a voxel.
    pub colour_rule: ColourRule,
    /// Carry the average surface normal (`.vti`).
    pub normals: bool,
    /// Carry every attribute (colour, material, coverage and normal) and,
    /// for `.vdb` and `.zarr`, write every array.
    pub attributes: bool,
    /// `.vox`: dither colours onto the palette.
    pub dither: bool,
    /// `.vox` and `.schem`: the up axis of the data.
    pub up: Up,
    /// `.obj` and `.glb`: split T-junctions (watertight).
    pub watertight: bool,
    /// `.obj`: triangles only.
    pub triangulate: bool,
    /// `.schem`: a colour → block table file.
    pub block_palette: Option<PathBuf>,
    /// Read files the model names outside its folder.
    pub allow_external_paths: bool,
    /// Worker threads per mesh (`None`: all cores, or the batch's pool).
    pub threads: Option<usize>,
}

impl Default for JobOptions {
    fn default() -> JobOptions {
        JobOptions {
            mode: Mode::Cover,
            method: Method::Auto,
            grid: GridOptions::default(),
            surface: None,
            fill: None,
            hollow: None,
            gpu_path: GpuPath::Compute,
            seed: 0,
            tile: None,
            max_memory: None,
            colour_rule: ColourRule::Dominant,
            normals: false,
            attributes: false,
            dither: false,
            up: Up::Y,
            watertight: true,
            triangulate: false,
            block_palette: None,
            allow_external_paths: false,
            threads: None,
        }
    }
}

/// A value given to an option by name (a Python keyword's value).
#[derive(Clone, Debug, PartialEq)]
pub enum OptionValue {
    /// `True` / `False`.
    Bool(bool),
    /// An integer.
    Int(i64),
    /// A number.
    Float(f64),
    /// A name, a size (`"8G"`) or a path.
    Text(String),
    /// A sequence of numbers (`origin`, `dims`).
    Numbers(Vec<f64>),
}

/// One option by name: its help and a valid value that is not its default
/// (for the tests that check every front end takes every option).
#[derive(Clone, Copy, Debug)]
pub struct Keyword {
    /// The name (Python's keyword; the CLI's flag with `-` for `_`).
    pub name: &'static str,
    /// What it does.
    pub help: &'static str,
    /// A valid value other than the default.
    pub example: Example,
}

/// A [`Keyword`]'s example value.
#[derive(Clone, Copy, Debug)]
pub enum Example {
    /// A boolean.
    Bool(bool),
    /// An integer.
    Int(i64),
    /// A number.
    Float(f64),
    /// A name or size.
    Text(&'static str),
    /// Numbers.
    Numbers(&'static [f64]),
}

impl Example {
    /// As an [`OptionValue`].
    pub fn value(self) -> OptionValue {
        match self {
            Example::Bool(b) => OptionValue::Bool(b),
            Example::Int(i) => OptionValue::Int(i),
            Example::Float(f) => OptionValue::Float(f),
            Example::Text(t) => OptionValue::Text(t.into()),
            Example::Numbers(n) => OptionValue::Numbers(n.to_vec()),
        }
    }
}

macro_rules! keywords {
    ($($name:literal: $example:expr, $help:literal;)+) => {
        /// Every option [`JobOptions::set`] takes, in documentation order.
        pub const KEYWORDS: &[Keyword] = &[$(Keyword { name: $name, help: $help, example: $example }),+];
    };
}

keywords! {
    "mode": Example::Text("sep6"), "the voxelization mode";
    "method": Example::Text("fast"), "the method (every method gives the mode's voxels)";
    "resolution": Example::Int(16), "the longest side of the bounding box spans N voxels";
    "voxel_size": Example::Float(0.5), "the voxel edge, or (sx, sy, sz) per axis; alone, the grid is fitted to the mesh";
    "origin": Example::Numbers(&[-1.0, -1.0, -1.0]), "an explicit grid's origin (with voxel_size and dims)";
    "dims": Example::Numbers(&[8.0, 8.0, 8.0]), "an explicit grid's dims (with origin and voxel_size)";
    "pad": Example::Int(1), "empty voxels on every side of a fitted grid";
    "fit": Example::Text("cube"), "box: to the bounding box; cube: N³ voxels centred on it (ShapeNet's convention)";
    "surface": Example::Text("sep26"), "solid modes: the surface of solid+surface and of a flood fill's shell";
    "fill": Example::Text("flood"), "solid modes: flood fills what a surface shell encloses";
    "hollow": Example::Int(6), "solid modes: keep the voxels 6- or 26-adjacent to the outside";
    "gpu_path": Example::Text("raster"), "with method gpu: compute, raster or msaa-approx";
    "seed": Example::Int(5), "bubble: the seed of its random points";
    "tile": Example::Int(64), "run tile by tile with tiles of N voxels (a multiple of 8)";
    "max_memory": Example::Text("2G"), "memory the run may use, bytes or a size such as 8G";
    "colour_rule": Example::Text("blend"), "how colours combine in a voxel: dominant or blend";
    "normals": Example::Bool(true), "carry the average surface normal";
    "attributes": Example::Bool(true), "carry colours, materials, coverage and normals";
    "dither": Example::Bool(true), ".vox: dither colours onto the palette";
    "up": Example::Text("z"), ".vox and .schem: the data's up axis";
    "watertight": Example::Bool(false), ".obj and .glb: split T-junctions (on by default)";
    "triangulate": Example::Bool(true), ".obj: triangles only";
    "block_palette": Example::Text(""), ".schem: a colour -> block table file (empty: the built-in one)";
    "allow_external_paths": Example::Bool(true), "read files the model names outside its folder";
    "threads": Example::Int(1), "worker threads";
}

/// Other spellings of option names (the ecosystem's American ones).
const ALIASES: &[(&str, &str)] = &[("color_rule", "colour_rule")];

fn text<'a>(key: &str, v: &'a OptionValue) -> Result<&'a str> {
    match v {
        OptionValue::Text(t) => Ok(t),
        v => invalid!("{key} must be a string; got {}", shown(v)),
    }
}

fn flag(key: &str, v: &OptionValue) -> Result<bool> {
    match v {
        OptionValue::Bool(b) => Ok(*b),
        v => invalid!("{key} must be True or False; got {}", shown(v)),
    }
}

fn int(key: &str, v: &OptionValue, least: i64) -> Result<u64> {
    match v {
        OptionValue::Int(i) if *i >= least => Ok(*i as u64),
        OptionValue::Int(i) => invalid!("{key} must be at least {least}; got {i}"),
        v => invalid!("{key} must be an integer; got {}", shown(v)),
    }
}

fn number(key: &str, v: &OptionValue) -> Result<f64> {
    match v {
        OptionValue::Float(f) => Ok(*f),
        OptionValue::Int(i) => Ok(*i as f64),
        v => invalid!("{key} must be a number; got {}", shown(v)),
    }
}

/// One number (cubes) or three (a size per axis).
fn voxel_size(key: &str, v: &OptionValue) -> Result<topovox::VoxelSize> {
    match v {
        OptionValue::Numbers(n) => Ok(<[f64; 3]>::try_from(numbers(key, v)?).unwrap_or([n[0]; 3]).into()),
        v => number(key, v)
            .map(topovox::VoxelSize::from)
            .map_err(|_| JobError::invalid(format!("{key} must be a number or 3 numbers; got {}", shown(v)))),
    }
}

fn numbers(key: &str, v: &OptionValue) -> Result<Vec<f64>> {
    match v {
        OptionValue::Numbers(n) if n.len() == 3 => Ok(n.clone()),
        OptionValue::Numbers(n) => invalid!("{key} must have 3 values; got {}", n.len()),
        v => invalid!("{key} must be a sequence of 3 numbers; got {}", shown(v)),
    }
}

fn shown(v: &OptionValue) -> String {
    match v {
        OptionValue::Bool(b) => if *b { "True" } else { "False" }.into(),
        OptionValue::Int(i) => i.to_string(),
        OptionValue::Float(f) => f.to_string(),
        OptionValue::Text(t) => format!("{t:?}"),
        OptionValue::Numbers(n) => format!("{n:?}"),
    }
}

/// A choice given by name (or, for `hollow`, by number).
fn chosen<T: Choice>(key: &str, v: &OptionValue) -> Result<T> {
    let name = match v {
        OptionValue::Int(i) => i.to_string(),
        v => text(key, v)?.to_string(),
    };
    T::parse(&name).map_err(|e| JobError::invalid(format!("{key}: {e}")))
}

impl JobOptions {
    /// Sets the option called `key` (see [`KEYWORDS`]; `color_rule` is
    /// `colour_rule`) from a value given by name, checking its type and range.
    pub fn set(&mut self, key: &str, v: &OptionValue) -> Result<()> {
        let key = ALIASES.iter().find(|a| a.0 == key).map_or(key, |a| a.1);
        match key {
            "mode" => self.mode = chosen(key, v)?,
            "method" => self.method = chosen(key, v)?,
            "resolution" => self.grid.resolution = Some(int(key, v, 1)?),
            "voxel_size" => self.grid.voxel_size = Some(voxel_size(key, v)?),
            "origin" => self.grid.origin = Some(numbers(key, v)?),
            "dims" => {
                let d = numbers(key, v)?;
                if d.iter().any(|&x| x < 1.0 || x.fract() != 0.0 || x > u32::MAX as f64) {
                    invalid!("dims must be 3 integers of at least 1; got {d:?}");
                }
                self.grid.dims = Some(d.iter().map(|&x| x as u64).collect());
            }
            // 0 is no pad (so a batch's fingerprint is the one without).
            "pad" => {
                self.grid.pad = Some(u32::try_from(int(key, v, 0)?).map_err(|_| JobError::invalid("pad is too large"))?).filter(|&p| p > 0)
            }
            "fit" => self.grid.fit = Some(chosen(key, v)?),
            "surface" => self.surface = Some(chosen(key, v)?),
            "fill" => self.fill = Some(chosen(key, v)?),
            "hollow" => self.hollow = Some(chosen(key, v)?),
            "gpu_path" => self.gpu_path = chosen(key, v)?,
            "seed" => self.seed = int(key, v, 0)?,
            "tile" => self.tile = Some(u32::try_from(int(key, v, 8)?).map_err(|_| JobError::invalid("tile is too large"))?),
            "max_memory" => {
                self.max_memory = Some(match v {
                    OptionValue::Text(t) => crate::memory::parse_size(t)?,
                    v => int(key, v, 1)?,
                })
            }
            "colour_rule" => self.colour_rule = chosen(key, v)?,
            "normals" => self.normals = flag(key, v)?,
            "attributes" => self.attributes = flag(key, v)?,
            "dither" => self.dither = flag(key, v)?,
            "up" => self.up = chosen(key, v)?,
            "watertight" => self.watertight = flag(key, v)?,
            "triangulate" => self.triangulate = flag(key, v)?,
            "block_palette" => self.block_palette = Some(text(key, v)?).filter(|t| !t.is_empty()).map(PathBuf::from),
            "allow_external_paths" => self.allow_external_paths = flag(key, v)?,
            "threads" => self.threads = Some(int(key, v, 1)? as usize),
            _ => invalid!("unknown option {key:?} (expected one of: {})", KEYWORDS.iter().map(|k| k.name).collect::<Vec<_>>().join(", ")),
        }
        Ok(())
    }

    /// The validated plan.
    pub fn plan(&self) -> Result<Plan> {
        Plan::new(Request {
            mode: self.mode,
            method: self.method,
            grid: GridRequest::new(&self.grid)?,
            surface: self.surface,
            fill: self.fill,
            hollow: self.hollow,
            gpu_path: self.gpu_path,
            seed: self.seed,
            tile: self.tile,
            max_memory: self.max_memory,
            writer_bytes_per_brick: 0,
        })
    }

    /// What the attribute carrier computes, the same in every front end:
    /// normals when `normals` or `attributes` asks for them.
    pub fn carry(&self) -> CarryOptions {
        CarryOptions { rule: self.colour_rule, normals: self.normals || self.attributes }
    }

    /// The writers' options (reads the block palette file, if any).
    pub fn write_options(&self) -> Result<topovox_io::WriteOptions> {
        let blocks = self.block_palette.as_deref().map(topovox_io::schem::BlockPalette::read).transpose()?;
        Ok(topovox_io::WriteOptions {
            dither: self.dither,
            blocks,
            up: self.up,
            mesh: topovox_io::voxel_mesh::MeshOptions { watertight: self.watertight, triangulate: self.triangulate },
            stop: None,
        })
    }

    /// How meshes are read.
    pub fn read_options(&self) -> topovox_io::ReadOptions {
        topovox_io::ReadOptions { allow_external_paths: self.allow_external_paths }
    }

    /// The options as one JSON object (keys sorted, defaults filled in),
    /// the same from every front end: what a batch's manifest records and a
    /// resumed run compares. Unchanged from earlier releases, so their
    /// manifests resume.
    pub fn fingerprint(&self, format: Output) -> Value {
        let g = &self.grid;
        let mut v = json!({
            "mode": self.mode.name(),
            "method": self.method.name(),
            "resolution": g.resolution.or((!g.any()).then_some(128)),
            "voxel_size": g.voxel_size.map(topovox_io::size_json),
            "origin": g.origin,
            "dims": g.dims,
            "pad": g.pad.unwrap_or(0),
            "surface": self.surface.map(Mode::name),
            "fill": self.fill.map(Choice::name),
            "hollow": self.hollow.map(|h| h.name().parse::<u32>().expect("6 or 26")),
            "gpu_path": self.gpu_path.name(),
            "format": format.name(),
            "colour_rule": self.colour_rule.name(),
            "normals": self.normals,
            "dither": self.dither,
            "up": self.up.name(),
            "watertight": self.watertight,
            "triangulate": self.triangulate,
            "seed": self.seed,
        });
        // Only when set, so manifests written before these existed still resume.
        if self.attributes {
            v["attributes"] = json!(true);
        }
        if let Some(t) = self.tile {
            v["tile"] = json!(t);
        }
        if g.cube() {
            v["fit"] = json!("cube");
        }
        v
    }

    /// The options of a batch writing `format`.
    pub fn batch(&self, format: Output) -> Result<BatchOptions> {
        let mut plan = self.plan()?;
        if let Some(why) = plan.request.grid.boxes().and_then(|s| crate::output::refuses(format, s)) {
            return Err(JobError::invalid(why));
        }
        plan.request.writer_bytes_per_brick = crate::output::writer_bytes_per_brick(format);
        Ok(BatchOptions {
            plan,
            format,
            carry: self.carry(),
            attributes: self.attributes,
            write: self.write_options()?,
            threads: self.threads,
            read: self.read_options(),
            fingerprint: self.fingerprint(format),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_keyword_is_set_by_its_example_and_changes_the_options() {
        for k in KEYWORDS {
            let mut o = JobOptions::default();
            o.set(k.name, &k.example.value()).unwrap_or_else(|e| panic!("{}: {e}", k.name));
            assert!(o != JobOptions::default() || k.name == "block_palette", "{}: the example is the default", k.name);
        }
        let mut o = JobOptions::default();
        o.set("color_rule", &OptionValue::Text("BLEND".into())).unwrap();
        assert_eq!(o.colour_rule, ColourRule::Blend);
    }

    #[test]
    fn bad_values_name_the_option() {
        let mut o = JobOptions::default();
        for (k, v, want) in [
            ("resolution", OptionValue::Int(0), "resolution must be at least 1; got 0"),
            ("resolution", OptionValue::Text("a".into()), "resolution must be an integer"),
            ("mode", OptionValue::Text("cube".into()), "mode: unknown mode \"cube\""),
            ("hollow", OptionValue::Int(7), "expected one of: 6, 26"),
            ("origin", OptionValue::Numbers(vec![1.0]), "origin must have 3 values"),
            ("dims", OptionValue::Numbers(vec![1.0, 0.0, 2.0]), "dims must be 3 integers"),
            ("normals", OptionValue::Int(1), "normals must be True or False"),
            ("sed", OptionValue::Int(1), "unknown option \"sed\""),
        ] {
            let e = o.set(k, &v).unwrap_err().to_string();
            assert!(e.contains(want), "{k}: {e}");
        }
    }

    #[test]
    fn the_fingerprint_keeps_its_released_form() {
        let mut o = JobOptions::default();
        o.set("hollow", &OptionValue::Text("26".into())).unwrap();
        o.set("mode", &OptionValue::Text("solid".into())).unwrap();
        let f = o.fingerprint(Output::from_name("npy").unwrap());
        assert_eq!(f["hollow"], 26);
        assert_eq!((f["mode"].as_str(), f["up"].as_str(), f["colour_rule"].as_str()), (Some("solid"), Some("y"), Some("dominant")));
        assert_eq!(f["resolution"], 128);
        assert!(f.get("attributes").is_none() && f.get("tile").is_none());
    }
}
