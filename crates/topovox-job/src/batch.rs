//! Whole datasets: one output per input mesh, a manifest of JSON lines
//! written as it goes, resumable, one bad mesh never stopping the rest.
//!
//! `topovox batch`, `topovox.batch` in Python and the Dask and Ray helpers
//! all use this module, so their outputs and manifest lines are the same
//! and a run started by one can be resumed by another.
//!
//! - Inputs are files or folders; folders are walked (sorted, so the order
//!   does not depend on the file system) for meshes matching a glob
//!   (default: every mesh extension topovox reads).
//! - Each output mirrors its input's path below the inputs' common folder,
//!   with the format's extension. Two inputs mapping to one output (`a.obj`
//!   and `a.stl`) are refused before any work.
//! - `manifest.jsonl` in the output folder gets one line per mesh as it
//!   finishes: input, output, status (`done` or `failed`), options, grid,
//!   voxels, times, error. Each line is written whole with one call;
//!   a torn last line (a crash mid-write) is ignored when reading.
//! - A mesh is skipped when the manifest says it was done with the same
//!   options and its output is still there with the recorded size
//!   (outputs are written to a temporary file and renamed, so an output
//!   that exists is complete). Failed meshes are tried again.

use std::collections::HashMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::Instant;

use rayon::prelude::*;
use serde_json::{json, Value};
use topovox::choice::Choice;
use topovox::voxelize::Stop;

use crate::distance::{DistanceFormat, SdfOptions};
use crate::error::{JobError, Result};
use crate::job::{SdfJob, VoxelizeJob};
use crate::options::JobOptions;
use crate::output::Output;
use crate::remesh::{RemeshJob, RemeshOptions};
use crate::sample::SampleOptions;
use topovox_io::mesh_out::MeshOut;

/// The manifest's file name in the output folder.
pub const MANIFEST: &str = "manifest.jsonl";

/// Mesh extensions taken from folders when no glob is given.
pub const MESH_EXTENSIONS: [&str; 7] = ["obj", "stl", "ply", "gltf", "glb", "lines", "off"];

topovox::choice! {
    /// What a batch runs on each mesh.
    pub enum Run: "run" default Voxelize {
        /// `voxelize`: a voxel file (or a mesh of the voxels) per mesh.
        Voxelize = "voxelize",
        /// `sdf`: a distance field per mesh.
        Sdf = "sdf",
        /// `remesh`: a watertight mesh per mesh.
        Remesh = "remesh",
        /// `sample`: training samples (an `.npz`) per mesh.
        Sample = "sample",
    }
}

impl Run {
    /// The output format when none is given.
    pub fn default_format(self) -> &'static str {
        match self {
            Run::Voxelize | Run::Sdf => "npy",
            Run::Remesh => "obj",
            Run::Sample => "npz",
        }
    }
}

/// What every mesh of a batch gets done to it.
#[derive(Clone, Debug)]
pub struct BatchOptions {
    /// The work, and how its result is written.
    pub work: Work,
    /// Worker threads per mesh (`None`: share the batch's pool).
    pub threads: Option<usize>,
    /// How meshes are read (external paths allowed or not).
    pub read: topovox_io::ReadOptions,
    /// The options as the user gave them, recorded in each manifest line
    /// and compared on resume.
    pub fingerprint: Value,
}

/// The work a batch does to each mesh.
#[derive(Clone, Debug)]
pub enum Work {
    /// `voxelize`.
    Voxelize(Box<VoxelizeJob>),
    /// `sdf`: a distance field.
    Sdf(SdfJob),
    /// `remesh`: a watertight mesh.
    Remesh(RemeshJob),
    /// `sample`: training samples.
    Sample(Box<SampleOptions>),
}

impl BatchOptions {
    /// A batch voxelizing each mesh and writing `format`.
    pub fn voxelize(o: &JobOptions, format: Output) -> Result<BatchOptions> {
        Ok(BatchOptions {
            work: Work::Voxelize(Box::new(VoxelizeJob::new(o, format, None)?)),
            threads: o.run.threads,
            read: o.run.read_options(),
            fingerprint: o.fingerprint(format),
        })
    }

    /// A batch writing each mesh's distance field as `format`; the
    /// manifest records `"run": "sdf"` beside the options.
    pub fn sdf(o: &SdfOptions, format: DistanceFormat) -> Result<BatchOptions> {
        let mut fingerprint = crate::options::fingerprint_of(o, format.name());
        fingerprint["run"] = json!("sdf");
        Ok(BatchOptions {
            work: Work::Sdf(SdfJob { request: o.request(format)? }),
            threads: o.run.threads,
            read: o.run.read_options(),
            fingerprint,
        })
    }

    /// A batch writing each mesh's watertight mesh as `format`; the
    /// manifest records `"run": "remesh"` beside the options.
    pub fn remesh(o: &RemeshOptions, format: MeshOut) -> Result<BatchOptions> {
        let mut fingerprint = crate::options::fingerprint_of(o, format.name());
        fingerprint["run"] = json!("remesh");
        Ok(BatchOptions {
            work: Work::Remesh(RemeshJob { request: o.request(format.single())?, format }),
            threads: o.run.threads,
            read: o.run.read_options(),
            fingerprint,
        })
    }

    /// A batch writing each mesh's training samples (`.npz`, the only
    /// format); the manifest records `"run": "sample"` beside the options.
    pub fn sample(o: &SampleOptions, format: &str) -> Result<BatchOptions> {
        if format != "npz" {
            return Err(JobError::invalid(format!("samples are written as npz; got format {format:?}")));
        }
        let mut fingerprint = crate::options::fingerprint_of(o, "npz");
        fingerprint["run"] = json!("sample");
        Ok(BatchOptions { work: Work::Sample(Box::new(o.clone())), threads: o.run.threads, read: o.run.read_options(), fingerprint })
    }

    /// The outputs' extension.
    pub fn extension(&self) -> String {
        match &self.work {
            Work::Voxelize(job) => job.format.name().replace("npy-bool", "npy"),
            Work::Sdf(job) => job.request.format.name().to_string(),
            Work::Remesh(job) => job.format.name().to_string(),
            Work::Sample(_) => "npz".to_string(),
        }
    }
}

/// One input and where its output goes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Item {
    /// The mesh.
    pub input: PathBuf,
    /// Its output.
    pub output: PathBuf,
}

/// Expands `inputs` (files and folders) into mesh files, sorted within
/// each folder; `glob` (e.g. `**/*.obj`) filters the files found in
/// folders, relative to that folder. Files named directly are kept. The
/// output folder `out_dir` is never searched, and no file a manifest found
/// on the way lists as a batch's output is taken: a batch does not read
/// what it (or another batch) wrote. A link that loops back to a folder
/// above it is skipped with a warning (the second value).
pub fn collect_inputs(inputs: &[PathBuf], glob: Option<&str>, out_dir: &Path) -> Result<(Vec<PathBuf>, Vec<String>)> {
    let outputs = std::fs::canonicalize(out_dir).ok();
    let matcher = match glob {
        Some(g) => Some(
            globset::GlobBuilder::new(g)
                .literal_separator(true)
                .build()
                .map_err(|e| JobError::invalid(format!("--glob {g:?}: {e}")))?
                .compile_matcher(),
        ),
        None => None,
    };
    let mut out = Vec::new();
    let mut warnings = Vec::new();
    for input in inputs {
        let meta = std::fs::metadata(input).map_err(|e| JobError::Io(topovox_io::IoError::new(input, topovox_io::ErrorKind::Read(e))))?;
        if !meta.is_dir() {
            out.push(input.clone());
            continue;
        }
        let not_outputs = |e: &walkdir::DirEntry| {
            !e.file_type().is_dir() || outputs.as_ref().is_none_or(|o| std::fs::canonicalize(e.path()).ok().as_ref() != Some(o))
        };
        let mut written: std::collections::HashSet<String> = std::collections::HashSet::new();
        for entry in walkdir::WalkDir::new(input).follow_links(true).sort_by_file_name().into_iter().filter_entry(not_outputs) {
            let entry = match entry {
                Err(e) if e.loop_ancestor().is_some() => {
                    let link = e.path().map_or_else(|| input.display().to_string(), |p| p.display().to_string());
                    warnings.push(format!("{link}: skipped: a link back to a folder that holds it"));
                    continue;
                }
                // A link to nothing is one bad input, never the batch's end:
                // one named like a mesh fails in the batch with its own
                // manifest record, any other is skipped with a warning.
                Err(e) if e.path().is_some_and(is_broken_link) => {
                    let link = e.path().expect("checked above");
                    if wanted(link, input, matcher.as_ref()) {
                        out.push(link.to_path_buf());
                    } else {
                        warnings.push(format!("{}: skipped: a link to nothing (its target does not exist)", link.display()));
                    }
                    continue;
                }
                r => r.map_err(|e| JobError::failed(format!("{}: cannot list: {e}", input.display())))?,
            };
            if entry.file_type().is_dir() {
                // Folders come before what they hold.
                written.extend(outputs_listed_in(&entry.path().join(MANIFEST)));
            }
            if !entry.file_type().is_file() {
                continue;
            }
            let path = entry.path();
            if !written.is_empty() && written.contains(&file_key(path)) {
                continue;
            }
            if wanted(path, input, matcher.as_ref()) {
                out.push(path.to_path_buf());
            }
        }
    }
    if out.is_empty() {
        return Err(JobError::invalid("no input meshes found (give mesh files, or folders holding them; see --glob)"));
    }
    Ok((out, warnings))
}

/// The manifest must be a regular file of the output folder (or not exist
/// yet): a link leading out of the folder would have the batch append to a
/// file of the user's elsewhere, and a FIFO or device would hang the read
/// or swallow the records. Refused before anything is read or written.
fn check_manifest_file(out_dir: &Path, path: &Path) -> std::io::Result<()> {
    let refuse = |why: &str| Err(std::io::Error::other(why.to_string()));
    let Ok(meta) = std::fs::symlink_metadata(path) else { return Ok(()) };
    if meta.file_type().is_symlink() {
        let (target, folder) = (std::fs::canonicalize(path), std::fs::canonicalize(out_dir));
        match (target, folder) {
            (Ok(t), Ok(f)) if t.starts_with(&f) && t.is_file() => return Ok(()),
            (Ok(_), Ok(_)) => {
                return refuse("a link leading out of the output folder (or to no regular file); the manifest is written only inside it")
            }
            _ => return refuse("a link to nothing; remove it or give another output folder"),
        }
    }
    if !meta.is_file() {
        return refuse("not a regular file (a FIFO, a device or a folder); the manifest must be a file of the output folder");
    }
    Ok(())
}

/// Whether `path`, found under the folder `input`, is an input: it matches
/// `--glob`, or without one has a mesh file's extension.
fn wanted(path: &Path, input: &Path, matcher: Option<&globset::GlobMatcher>) -> bool {
    match matcher {
        Some(m) => path.strip_prefix(input).is_ok_and(|rel| m.is_match(rel)),
        None => path.extension().and_then(|e| e.to_str()).is_some_and(|e| MESH_EXTENSIONS.iter().any(|m| m.eq_ignore_ascii_case(e))),
    }
}

/// A symbolic link whose target does not exist.
fn is_broken_link(path: &Path) -> bool {
    path.symlink_metadata().is_ok_and(|m| m.file_type().is_symlink()) && std::fs::metadata(path).is_err()
}

/// The keys of the outputs a manifest at `path` lists (none if there is
/// no such file, or it is not a manifest).
fn outputs_listed_in(path: &Path) -> Vec<String> {
    // Only a regular file (a FIFO named so would hang the walk).
    if !std::fs::metadata(path).is_ok_and(|m| m.is_file()) {
        return Vec::new();
    }
    let Ok(text) = std::fs::read_to_string(path) else { return Vec::new() };
    text.lines()
        .filter_map(|l| serde_json::from_str::<Value>(l).ok())
        .filter(|v| v["input"].is_string() && v["options"].is_object())
        .filter_map(|v| recorded_key(&v, "output"))
        .collect()
}

/// The folder every input lies in (the deepest common one).
fn common_folder(inputs: &[PathBuf]) -> PathBuf {
    let dirs: Vec<PathBuf> = inputs.iter().map(|p| absolute(p).parent().map(Path::to_path_buf).unwrap_or_default()).collect();
    let mut common = dirs.first().cloned().unwrap_or_default();
    for d in &dirs[1..] {
        while !d.starts_with(&common) {
            if !common.pop() {
                break;
            }
        }
    }
    common
}

fn absolute(p: &Path) -> PathBuf {
    std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf())
}

/// The items of a batch writing `format` under `out_dir`: the inputs found
/// ([`collect_inputs`]) paired with their outputs ([`plan_items`]), and
/// the walk's warnings. What every front end runs before [`run`].
pub fn items(inputs: &[PathBuf], glob: Option<&str>, out_dir: &Path, opts: &BatchOptions) -> Result<(Vec<Item>, Vec<String>)> {
    let (files, warnings) = collect_inputs(inputs, glob, out_dir)?;
    Ok((plan_items(&files, out_dir, &opts.extension())?, warnings))
}

/// Pairs each input with its output under `out_dir`: the input's path
/// below the common folder of all inputs, with `ext`. Inputs that differ
/// only in their extension (`a.obj`, `a.stl`) keep it in their outputs'
/// names (`a.obj.npy`, `a.stl.npy`), so each has its own. Refuses two
/// inputs with one output still (the same file given twice), and an
/// output that is an input.
pub fn plan_items(inputs: &[PathBuf], out_dir: &Path, ext: &str) -> Result<Vec<Item>> {
    let common = common_folder(inputs);
    let below = |input: &Path| {
        let abs = absolute(input);
        abs.strip_prefix(&common).map(Path::to_path_buf).unwrap_or(abs)
    };
    let plain = |input: &Path| out_dir.join(below(input)).with_extension(ext);
    let mut sharing: HashMap<PathBuf, usize> = HashMap::new();
    for input in inputs {
        *sharing.entry(plain(input)).or_default() += 1;
    }
    let mut seen: HashMap<PathBuf, &Path> = HashMap::new();
    let mut items = Vec::with_capacity(inputs.len());
    for input in inputs {
        let mut output = plain(input);
        if sharing[&output] > 1 {
            let rel = below(input);
            let mut name = rel.file_name().map(|n| n.to_os_string()).unwrap_or_default();
            name.push(".");
            name.push(ext);
            output = out_dir.join(rel).with_file_name(name);
        }
        if let Some(other) = seen.insert(output.clone(), input) {
            return Err(JobError::invalid(format!(
                "{} and {} would both be written to {}; batch them separately or rename one",
                other.display(),
                input.display(),
                output.display()
            )));
        }
        if absolute(&output) == absolute(input) {
            return Err(JobError::invalid(format!(
                "{}: the output would overwrite the input; choose another output folder",
                input.display()
            )));
        }
        items.push(Item { input: input.clone(), output });
    }
    Ok(items)
}

/// A path as the manifest keys it, losslessly: its text when it is UTF-8,
/// else a NUL (which no file name holds) and its bytes in hex. Two names
/// that display alike (`caf\xe9` and `caf\u{FFFD}`) never share a key.
pub fn path_key(p: &Path) -> String {
    match p.to_str() {
        Some(s) => s.to_string(),
        None => format!("\0{}", hex(&raw_bytes(p))),
    }
}

fn raw_bytes(p: &Path) -> Vec<u8> {
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStrExt;
        p.as_os_str().as_bytes().to_vec()
    }
    #[cfg(not(unix))]
    {
        p.to_string_lossy().into_owned().into_bytes()
    }
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// For a path that is not UTF-8, `NAME_raw`: its bytes in hex (the record's
/// `NAME` is the lossy text, for people).
fn record_raw_path(record: &mut Value, name: &str, p: &Path) {
    if p.to_str().is_none() {
        record[format!("{name}_raw")] = hex(&raw_bytes(p)).into();
    }
}

/// The manifest's key of a file: [`path_key`] of its canonical path, so
/// every spelling of it (`out`, `./out`, `/abs/out`, `../ds/a.obj`, a
/// link), from any front end (CLI, Python, Dask, Ray), has one key. A file
/// that does not exist keys by its absolute path.
pub fn file_key(p: &Path) -> String {
    path_key(&std::fs::canonicalize(p).unwrap_or_else(|_| absolute(p)))
}

/// The key of a record's path `name`: its `NAME_key` ([`file_key`] when
/// written), else (a line of an earlier version) the key of the path as
/// recorded (see [`path_key`]), made canonical where it still names a file.
fn recorded_key(v: &Value, name: &str) -> Option<String> {
    if let Some(k) = v[format!("{name}_key")].as_str() {
        return Some(k.to_string());
    }
    match v[format!("{name}_raw")].as_str() {
        Some(raw) => Some(format!("\0{raw}")),
        None => v[name].as_str().map(|p| file_key(Path::new(p))),
    }
}

/// The manifest: the lines read back on resume, and appending new ones.
pub struct Manifest {
    path: PathBuf,
    file: Mutex<std::fs::File>,
    /// The last `done` line per input path.
    done: HashMap<String, Value>,
    /// Per input path, its last line when that is a failure.
    failed: Mutex<HashMap<String, Value>>,
}

impl Manifest {
    /// Opens (creating) `out_dir/manifest.jsonl` for appending and reads
    /// the lines already there; lines that do not parse (a torn last line)
    /// are ignored.
    pub fn open(out_dir: &Path) -> Result<Manifest> {
        let path = out_dir.join(MANIFEST);
        let io = |e| JobError::Io(topovox_io::IoError::new(&path, topovox_io::ErrorKind::Write(e)));
        check_manifest_file(out_dir, &path).map_err(io)?;
        let (mut done, mut failed) = (HashMap::new(), HashMap::new());
        if let Ok(text) = std::fs::read_to_string(&path) {
            for line in text.lines() {
                let Ok(v) = serde_json::from_str::<Value>(line) else { continue };
                let Some(input) = recorded_key(&v, "input") else { continue };
                match v["status"].as_str() {
                    Some("done") => {
                        failed.remove(&input);
                        done.insert(input, v);
                    }
                    Some("failed") => {
                        failed.insert(input, v);
                    }
                    _ => {}
                }
            }
            // A torn last line: start the next one on a line of its own.
            if !text.is_empty() && !text.ends_with('\n') {
                let mut f = std::fs::OpenOptions::new().append(true).open(&path).map_err(io)?;
                f.write_all(b"\n").map_err(io)?;
            }
        }
        let file = std::fs::OpenOptions::new().create(true).append(true).open(&path).map_err(io)?;
        Ok(Manifest { path: path.clone(), file: Mutex::new(file), done, failed: Mutex::new(failed) })
    }

    /// The manifest's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Refuses to let a batch with these options replace an output that an
    /// earlier batch wrote with other options (a rerun used to overwrite it
    /// without a word): the error names the output and the options that
    /// differ. Python raises it as `FileExistsError`.
    pub fn refuse_other_options(&self, items: &[Item], fingerprint: &Value) -> Result<()> {
        for item in items {
            let Some(v) = self.done.get(&file_key(&item.input)) else { continue };
            if v["options"] == *fingerprint || recorded_key(v, "output") != Some(file_key(&item.output)) || !item.output.exists() {
                continue;
            }
            let why = format!(
                "written by an earlier batch with other options ({}); give another output folder, or delete the outputs to redo them",
                option_changes(&v["options"], fingerprint)
            );
            let e = std::io::Error::new(std::io::ErrorKind::AlreadyExists, why);
            return Err(JobError::Io(topovox_io::IoError::new(&item.output, topovox_io::ErrorKind::Write(e))));
        }
        Ok(())
    }

    /// Whether `item` was done with these options and its output is still
    /// there, complete (the recorded size).
    pub fn is_done(&self, item: &Item, fingerprint: &Value) -> bool {
        let Some(v) = self.done.get(&file_key(&item.input)) else { return false };
        let same = v["options"] == *fingerprint && recorded_key(v, "output") == Some(file_key(&item.output));
        let size = std::fs::metadata(&item.output).map(|m| m.len()).ok();
        same && size.is_some() && v["output_bytes"].as_u64() == size
    }

    /// Appends one record as one line, with one write. A failure the
    /// manifest already ends with for that input (same options, same
    /// error) is not written again: a rerun retries failed meshes, but
    /// their lines do not pile up.
    pub fn append(&self, record: &Value) -> Result<()> {
        if let Some(input) = recorded_key(record, "input") {
            let mut failed = self.failed.lock().unwrap_or_else(|e| e.into_inner());
            if record["status"] == "failed" {
                let same = failed.get(&input).is_some_and(|p| p["options"] == record["options"] && p["error"] == record["error"]);
                if same {
                    return Ok(());
                }
                failed.insert(input, record.clone());
            } else {
                failed.remove(&input);
            }
        }
        let mut line = record.to_string();
        line.push('\n');
        let mut f = self.file.lock().unwrap_or_else(|e| e.into_inner());
        f.write_all(line.as_bytes())
            .and_then(|_| f.flush())
            .map_err(|e| JobError::Io(topovox_io::IoError::new(&self.path, topovox_io::ErrorKind::Write(e))))
    }
}

/// The options two fingerprints give differently, as `name old → new`
/// (at most four; `unset` where one has none).
fn option_changes(old: &Value, new: &Value) -> String {
    let keys: std::collections::BTreeSet<&String> = [old, new].iter().filter_map(|v| v.as_object()).flat_map(|o| o.keys()).collect();
    let shown = |v: Option<&Value>| match v {
        None | Some(Value::Null) => "unset".to_string(),
        Some(Value::String(s)) => s.clone(),
        Some(v) => v.to_string(),
    };
    let changed: Vec<String> = keys
        .into_iter()
        .filter(|k| old.get(k.as_str()) != new.get(k.as_str()))
        .map(|k| format!("{k} {} → {}", shown(old.get(k.as_str())), shown(new.get(k.as_str()))))
        .collect();
    let more = changed.len().saturating_sub(4);
    let mut text = changed.into_iter().take(4).collect::<Vec<_>>().join(", ");
    if more > 0 {
        text += &format!(" and {more} more");
    }
    text
}

/// Voxelizes one mesh and writes its output; never fails: a failure is
/// the record's `error`. The record is what the manifest gets, unless its
/// `status` is `"interrupted"` (`stop` was requested: nothing was
/// written, and the mesh is to be done again).
pub fn process_one(item: &Item, opts: &BatchOptions, stop: Option<&Arc<Stop>>) -> Value {
    let t0 = Instant::now();
    let mut record = json!({
        "input": item.input.display().to_string(),
        "output": item.output.display().to_string(),
        "options": opts.fingerprint,
    });
    record_raw_path(&mut record, "input", &item.input);
    record_raw_path(&mut record, "output", &item.output);
    record["input_key"] = json!(file_key(&item.input));
    let result = (|| -> Result<Value> {
        if let Some(dir) = item.output.parent() {
            std::fs::create_dir_all(dir).map_err(|e| JobError::Io(topovox_io::IoError::new(dir, topovox_io::ErrorKind::Write(e))))?;
        }
        let t = Instant::now();
        let loaded = topovox_io::read_mesh(&item.input, &opts.read)?;
        let load_s = t.elapsed().as_secs_f64();
        let name = item.input.display().to_string();
        let run = || -> Result<Value> {
            let mut facts = match &opts.work {
                Work::Voxelize(job) => voxelize_one(job, &loaded, &name, &item.output, stop)?,
                Work::Sdf(job) => sdf_one(job, &loaded, &name, &item.output, stop.map(|s| &**s))?,
                Work::Remesh(job) => remesh_one(job, &loaded, &name, &item.output, stop.map(|s| &**s))?,
                Work::Sample(o) => sample_one(o, &loaded, &name, &item.output)?,
            };
            facts["times"]["load_s"] = json!(load_s);
            facts["triangles"] = json!(loaded.report.triangles);
            Ok(facts)
        };
        match opts.threads {
            Some(n) => crate::pool(n)?.install(run),
            None => run(),
        }
    })();
    match result {
        Ok(facts) => {
            if let (Some(r), Some(f)) = (record.as_object_mut(), facts.as_object()) {
                r.extend(f.clone());
            }
            record["status"] = json!("done");
            record["output_bytes"] = json!(std::fs::metadata(&item.output).map(|m| m.len()).ok());
            record["output_key"] = json!(file_key(&item.output));
            record["error"] = Value::Null;
        }
        Err(JobError::Interrupted) => {
            record["status"] = json!("interrupted");
            record["error"] = json!(JobError::Interrupted.to_string());
        }
        Err(e) => {
            record["status"] = json!("failed");
            record["error"] = json!(e.to_string());
        }
    }
    record["times"]["total_s"] = json!(t0.elapsed().as_secs_f64());
    record
}

/// The grid as a manifest records it.
fn grid_json(g: &topovox::GridSpec) -> Value {
    let o = g.origin();
    json!({"origin": [o.x, o.y, o.z], "voxel_size": topovox_io::size_json(g.voxel_size()), "dims": g.dims()})
}

/// The record's warnings: the mesh's, then the work's.
fn warnings<'a>(loaded: &'a topovox_io::LoadedMesh, work: &'a [String]) -> Vec<&'a String> {
    loaded.warnings.iter().chain(work).collect()
}

/// Voxelizes one loaded mesh and writes it: the record's facts.
fn voxelize_one(job: &VoxelizeJob, loaded: &topovox_io::LoadedMesh, name: &str, out: &Path, stop: Option<&Arc<Stop>>) -> Result<Value> {
    let done = job.run(out, loaded, name, None, stop)?;
    let v = &done.made.voxels;
    Ok(json!({
        "grid": grid_json(&v.grid),
        "voxels": v.report.voxels,
        "method": v.method,
        "times": {"voxelize_s": v.voxelize_s, "attributes_s": done.made.attributes_s, "write_s": done.write_s},
        "warnings": warnings(loaded, &v.warnings),
    }))
}

/// The distance field of one loaded mesh, written: the record's facts.
fn sdf_one(job: &SdfJob, loaded: &topovox_io::LoadedMesh, name: &str, out: &Path, stop: Option<&Stop>) -> Result<Value> {
    let done = job.run(out, loaded, name, None, stop)?;
    let sdf = &done.sdf;
    Ok(json!({
        "grid": grid_json(&sdf.grid),
        "stored_voxels": sdf.field.band.count(),
        "signed": sdf.signed,
        "times": {"sdf_s": done.sdf_s, "write_s": done.write_s},
        "warnings": warnings(loaded, &sdf.warnings),
    }))
}

/// The watertight mesh of one loaded mesh, written: the record's facts.
fn remesh_one(job: &RemeshJob, loaded: &topovox_io::LoadedMesh, name: &str, out: &Path, stop: Option<&Stop>) -> Result<Value> {
    let done = job.run(out, loaded, name, None, stop)?;
    let r = &done.made;
    Ok(json!({
        "grid": grid_json(&r.grid),
        "vertices": r.vertices,
        "faces": r.triangles,
        "remesh": r.summary(),
        "times": {"inside_s": r.facts.inside_s, "surface_s": r.facts.surface_s, "write_s": done.write_s},
        "warnings": warnings(loaded, &r.warnings),
    }))
}

/// The training samples of one loaded mesh, written: the record's facts.
fn sample_one(o: &SampleOptions, loaded: &topovox_io::LoadedMesh, name: &str, out: &Path) -> Result<Value> {
    topovox_io::atomic::refuse_overwriting_inputs(out, &loaded.sources)?;
    let s = crate::sample::sample(loaded, name, o)?;
    let t = Instant::now();
    s.write(out)?;
    let summary = s.summary();
    Ok(json!({
        "points": s.samples.points.len(),
        "sample": summary,
        "times": {"query_s": s.seconds.0, "sample_s": s.seconds.1, "write_s": t.elapsed().as_secs_f64()},
        "warnings": warnings(loaded, &[]),
    }))
}

/// Told about a batch's progress (the CLI draws a bar; core never prints).
pub trait BatchProgress: Sync {
    /// `total` meshes to go, `skipped` of them already done.
    fn start(&self, total: u64, skipped: u64);
    /// One mesh finished (its manifest record).
    fn finished(&self, record: &Value);
}

/// No progress reporting.
pub struct Silent;

impl BatchProgress for Silent {
    fn start(&self, _total: u64, _skipped: u64) {}
    fn finished(&self, _record: &Value) {}
}

/// What a batch did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Summary {
    /// Meshes voxelized and written now.
    pub done: u64,
    /// Meshes skipped as already done.
    pub skipped: u64,
    /// Meshes that failed (recorded in the manifest).
    pub failed: u64,
    /// Wall-clock seconds.
    pub total_s: f64,
    /// The manifest.
    pub manifest: PathBuf,
}

impl Summary {
    /// As JSON.
    pub fn to_json(&self) -> Value {
        json!({"done": self.done, "skipped": self.skipped, "failed": self.failed, "total_s": self.total_s,
            "manifest": self.manifest.display().to_string()})
    }
}

/// Makes the output folder (and those above it). A file standing in its
/// place is a `NotADirectory` error that says so (Python's
/// `NotADirectoryError`), not the system's bare "File exists".
pub fn create_out_dir(out_dir: &Path) -> Result<()> {
    let io = |e| JobError::Io(topovox_io::IoError::new(out_dir, topovox_io::ErrorKind::Write(e)));
    if out_dir.exists() && !out_dir.is_dir() {
        let e = std::io::Error::new(std::io::ErrorKind::NotADirectory, "a file stands there; the output must be a folder");
        return Err(io(e));
    }
    std::fs::create_dir_all(out_dir).map_err(io)
}

/// Runs a whole batch on the current rayon pool (meshes in parallel, each
/// voxelized in parallel too, on the same pool). Once `stop` is requested
/// no mesh is started, those under way give up, none of them is recorded,
/// and the result is [`JobError::Interrupted`]: a later run does them.
pub fn run(items: &[Item], out_dir: &Path, opts: &BatchOptions, progress: &dyn BatchProgress, stop: Option<&Arc<Stop>>) -> Result<Summary> {
    if let Some(n) = opts.threads {
        crate::check_threads(n, "threads")?;
    }
    let t0 = Instant::now();
    create_out_dir(out_dir)?;
    let manifest = Manifest::open(out_dir)?;
    manifest.refuse_other_options(items, &opts.fingerprint)?;
    let todo: Vec<&Item> = items.iter().filter(|i| !manifest.is_done(i, &opts.fingerprint)).collect();
    let skipped = (items.len() - todo.len()) as u64;
    progress.start(items.len() as u64, skipped);
    let failed = std::sync::atomic::AtomicU64::new(0);
    let first_error = Mutex::new(None);
    let stopped = || stop.is_some_and(|s| s.requested());
    todo.par_iter().with_max_len(1).for_each(|item| {
        if stopped() {
            return;
        }
        let record = process_one(item, opts, stop);
        if record["status"] == "interrupted" {
            return;
        }
        if record["status"] != "done" {
            failed.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        }
        if let Err(e) = manifest.append(&record) {
            first_error.lock().unwrap_or_else(|e| e.into_inner()).get_or_insert(e);
        }
        progress.finished(&record);
    });
    if let Some(e) = first_error.into_inner().unwrap_or_else(|e| e.into_inner()) {
        return Err(e);
    }
    if stopped() {
        return Err(JobError::Interrupted);
    }
    let failed = failed.into_inner();
    Ok(Summary {
        done: todo.len() as u64 - failed,
        skipped,
        failed,
        total_s: t0.elapsed().as_secs_f64(),
        manifest: manifest.path().to_path_buf(),
    })
}
