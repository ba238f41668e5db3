//! Every option of a voxelization job, once: what `topovox voxelize` and
//! `topovox batch` take as flags and the Python package as keywords, typed
//! ([`JobOptions`]), named ([`KEYWORDS`], [`Table::set_named`]), and turned
//! here — and nowhere else — into the plan, the attribute policy, the
//! writer options, the batch options and the batch's fingerprint.

use std::path::PathBuf;

use serde_json::{json, Map, Value};
use topovox::attributes::carry::CarryOptions;
use topovox::attributes::ColourRule;
use topovox::choice::{Choice, Switch};
use topovox_io::orient::Up;

use crate::error::{JobError, Result};
use crate::grid::{GridOptions, GridRequest};
use crate::output::Output;
use crate::plan::{Fill, GpuPath, Hollow, Method, Mode, Plan, Request};
use crate::table::{choice, chosen, flag, int, text, value, Example, OptionValue, Shape, Table};

crate::option_table! {
    /// How a run may use the machine: threads, memory, files outside the
    /// model's folder (every command that runs a job).
    pub struct RunOptions {
        threads: Option<usize> = None,
            parse |k, v| Ok(Some(int(k, v, 1)? as usize)),
            example Example::Int(1),
            print |_| None,
            cli value("N"),
            "worker threads (default: all cores)";
        max_memory: Option<u64> = None,
            parse |k, v| Ok(Some(match v {
                OptionValue::Text(t) => crate::memory::parse_size(t)?,
                v => int(k, v, 1)?,
            })),
            example Example::Text("2G"),
            print |_| None,
            cli value("SIZE"),
            "memory the run may use, bytes or a size such as 8G or 512M (default: nine tenths of what is available)";
        allow_external_paths: bool = false,
            parse flag,
            example Example::Bool(true),
            print |_| None,
            cli Shape::Flag,
            "read files the model names (OBJ material libraries and textures, glTF buffers and images) even outside its folder: absolute paths, ../, links leading out (off by default)";
    }
}

crate::option_table! {
    /// What the writers carry and how they lay it out (`voxelize`, `batch`
    /// and `convert`).
    pub struct ExportOptions {
        colour_rule: ColourRule = ColourRule::Dominant,
            parse chosen,
            example Example::Text("blend"),
            print |o| Some(json!(o.colour_rule.name())),
            cli choice::<ColourRule>("RULE"),
            "how the colours of the surface inside a voxel combine: dominant (the colour covering the most area; never a new colour) or blend (area-weighted mean in linear light)";
        normals: bool = false,
            parse flag,
            example Example::Bool(true),
            print |o| Some(json!(o.normals)),
            cli Shape::Flag,
            "carry each voxel's average surface normal (.vti)";
        attributes: bool = false,
            parse flag,
            example Example::Bool(true),
            // Only when set, so manifests written before it existed still resume.
            print |o| o.attributes.then_some(json!(true)),
            cli Shape::Flag,
            "carry colours, materials, coverage and normals: .vdb grids `Cd`, `normal`, `coverage` and `material` beside `voxels`; a .zarr group of arrays `voxels`, `colour`, `normal`, `coverage` and `material`";
        dither: bool = false,
            parse flag,
            example Example::Bool(true),
            print |o| Some(json!(o.dither)),
            cli Shape::Flag,
            ".vox: dither colours onto the 255-colour palette (error diffusion; off by default)";
        up: Up = Up::Y,
            parse chosen,
            example Example::Text("z"),
            print |o| Some(json!(o.up.name())),
            cli choice::<Up>("x|y|z"),
            "the axis of the mesh (and the voxel grid) that points up: .vox and .schem are rotated (never mirrored) so the model stands upright in MagicaVoxel and Minecraft (default y)";
        watertight: bool = true,
            parse flag,
            example Example::Bool(false),
            print |o| Some(json!(o.watertight)),
            cli choice::<Switch>("on|off"),
            ".obj and .glb meshes of the voxels: on (default) splits the greedy quads at T-junctions so every edge is shared; off keeps the plain quads";
        triangulate: bool = false,
            parse flag,
            example Example::Bool(true),
            print |o| Some(json!(o.triangulate)),
            cli Shape::Flag,
            ".obj meshes of the voxels: triangles only (quads split in two), for readers such as Open3D";
        block_palette: Option<PathBuf> = None,
            parse |k, v| Ok(Some(text(k, v)?).filter(|t| !t.is_empty()).map(PathBuf::from)),
            example Example::Text(""),
            print |_| None,
            cli value("FILE"),
            ".schem: a colour -> block table, `namespace:block R G B` per line (default, or empty: the built-in table)";
    }
}

crate::option_table! {
    /// Every option of a voxelization job, typed; `Default` gives each
    /// option's documented default.
    pub struct JobOptions {
        [group grid: GridOptions, "The grid."]
        [group export: ExportOptions, "What the writers carry."]
        [group run: RunOptions, "Threads, memory, paths."]
        mode: Mode = Mode::Cover,
            parse chosen,
            example Example::Text("sep6"),
            print |o| Some(json!(o.mode.name())),
            cli choice::<Mode>("MODE"),
            "the voxelization mode";
        method: Method = Method::Auto,
            parse chosen,
            example Example::Text("fast"),
            print |o| Some(json!(o.method.name())),
            cli choice::<Method>("METHOD"),
            "the method (every method gives the mode's voxels)";
        surface: Option<Mode> = None,
            parse |k, v| chosen(k, v).map(Some),
            example Example::Text("sep26"),
            print |o| Some(json!(o.surface.map(Mode::name))),
            cli choice::<Mode>("MODE"),
            "solid modes: the surface mode of solid+surface and of the fill flood shell (default cover)";
        fill: Option<Fill> = None,
            parse |k, v| chosen(k, v).map(Some),
            example Example::Text("flood"),
            print |o| Some(json!(o.fill.map(Choice::name))),
            cli choice::<Fill>("flood"),
            "solid modes: flood fills everything a surface shell encloses (everything not reachable from the grid boundary through unset voxels)";
        hollow: Option<Hollow> = None,
            parse |k, v| chosen(k, v).map(Some),
            example Example::Int(6),
            print |o| Some(json!(o.hollow.map(|h| h.name().parse::<u32>().expect("6 or 26")))),
            cli choice::<Hollow>("6|26"),
            "solid modes: keep only the voxels touching the outside through a face (6) or also an edge or corner (26)";
        gpu_path: GpuPath = GpuPath::Compute,
            parse chosen,
            example Example::Text("raster"),
            print |o| Some(json!(o.gpu_path.name())),
            cli choice::<GpuPath>("PATH"),
            "with method gpu: compute (default), raster (the rasterizer path, same voxels) or msaa-approx (4x MSAA instead of conservative coverage: approximate, the summary says how many voxels it misses)";
        seed: u64 = 0,
            parse |k, v| int(k, v, 0),
            example Example::Int(5),
            print |o| Some(json!(o.seed)),
            cli value("SEED"),
            "bubble: the seed of its random points (same seed, same voxels; default 0)";
        tile: Option<u32> = None,
            parse |k, v| Ok(Some(u32::try_from(int(k, v, 8)?).map_err(|_| JobError::invalid("tile is too large"))?)),
            example Example::Int(64),
            // Only when set, so manifests written before it existed still resume.
            print |o| o.tile.map(|t| json!(t)),
            cli value("N"),
            "run the surface or line mode tile by tile with tiles of N voxels (a multiple of 8; default: only when the grid does not fit in max_memory, with tiles of 512); same voxels either way";
    }
}

/// Every option [`JobOptions`] takes by name, in documentation order.
pub const KEYWORDS: &[&[crate::table::Keyword]] = <JobOptions as Table>::KEYWORDS;

impl ExportOptions {
    /// Whether any attribute is asked for (normals are one): what a grid
    /// kept in memory carries by [`crate::Keep::wants`]; a file's format
    /// decides too.
    pub fn carries(&self) -> bool {
        self.attributes || self.normals
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
}

impl RunOptions {
    /// How meshes are read.
    pub fn read_options(&self) -> topovox_io::ReadOptions {
        topovox_io::ReadOptions { allow_external_paths: self.allow_external_paths, max_memory: self.max_memory, ..Default::default() }
    }
}

/// A table's options as one JSON object (keys sorted, defaults filled in),
/// the same from every front end: what a batch's manifest records and a
/// resumed run compares.
pub fn fingerprint_of<T: Table>(options: &T, format: &str) -> Value {
    let mut out = Map::new();
    options.fingerprint(&mut out);
    out.insert("format".into(), json!(format));
    Value::Object(out)
}

impl JobOptions {
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
            max_memory: self.run.max_memory,
            writer_bytes_per_brick: 0,
        })
    }

    /// What a batch's manifest records, unchanged from earlier releases so
    /// their manifests resume ([`fingerprint_of`]).
    pub fn fingerprint(&self, format: Output) -> Value {
        fingerprint_of(self, format.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_keyword_is_set_by_its_example_and_changes_the_options() {
        for k in JobOptions::keywords() {
            let mut o = JobOptions::default();
            o.set_named(k.name, &k.example.value()).unwrap_or_else(|e| panic!("{}: {e}", k.name));
            assert!(o != JobOptions::default() || k.name == "block_palette", "{}: the example is the default", k.name);
        }
        let mut o = JobOptions::default();
        o.set_named("color_rule", &OptionValue::Text("BLEND".into())).unwrap();
        assert_eq!(o.export.colour_rule, ColourRule::Blend);
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
            let e = o.set_named(k, &v).unwrap_err().to_string();
            assert!(e.contains(want), "{k}: {e}");
        }
    }

    #[test]
    fn the_fingerprint_keeps_its_released_form() {
        let mut o = JobOptions::default();
        o.set_named("hollow", &OptionValue::Text("26".into())).unwrap();
        o.set_named("mode", &OptionValue::Text("solid".into())).unwrap();
        let f = o.fingerprint(Output::from_name("npy").unwrap());
        assert_eq!(f["hollow"], 26);
        assert_eq!((f["mode"].as_str(), f["up"].as_str(), f["colour_rule"].as_str()), (Some("solid"), Some("y"), Some("dominant")));
        assert_eq!(f["resolution"], 128);
        assert!(f.get("attributes").is_none() && f.get("tile").is_none());
        // The defaults, byte for byte as releases wrote them.
        let released = r#"{"colour_rule":"dominant","dims":null,"dither":false,"fill":null,"format":"npy","gpu_path":"compute","hollow":null,"method":"auto","mode":"cover","normals":false,"origin":null,"pad":0,"resolution":128,"seed":0,"surface":null,"triangulate":false,"up":"y","voxel_size":null,"watertight":true}"#;
        assert_eq!(JobOptions::default().fingerprint(Output::from_name("npy").unwrap()).to_string(), released);
        // Options recorded only when set; the run's own are never recorded.
        let mut o = JobOptions::default();
        for (k, v) in [
            ("attributes", OptionValue::Bool(true)),
            ("tile", OptionValue::Int(64)),
            ("fit", OptionValue::Text("cube".into())),
            ("threads", OptionValue::Int(3)),
            ("max_memory", OptionValue::Text("1G".into())),
            ("pad", OptionValue::Int(2)),
        ] {
            o.set_named(k, &v).unwrap();
        }
        let f = o.fingerprint(Output::from_name("vdb").unwrap());
        assert_eq!(
            (f["attributes"].clone(), f["tile"].clone(), f["fit"].clone(), f["pad"].clone()),
            (json!(true), json!(64), json!("cube"), json!(2))
        );
        assert!(f.get("threads").is_none() && f.get("max_memory").is_none() && f.get("allow_external_paths").is_none());
    }
}
