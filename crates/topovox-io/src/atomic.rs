//! Writing outputs without ever losing what the user has.
//!
//! - A regular file (or a new one) is written to a temporary file beside
//!   it and renamed over it, so a failed write never leaves a half-written
//!   output. A symbolic link to a regular file is followed: the file it
//!   names is replaced, the link stays.
//! - Anything else that exists — `/dev/null`, `/dev/stdout`, a FIFO, a
//!   terminal — is written directly, as a careful Unix tool does: renaming
//!   over it would replace the device node or pipe with a regular file.
//!   Write errors are reported (`/dev/full`: no space left on device).
//! - `-` is standard output.
//! - Temporaries are named `.NAME.topovox-tmp-PID-N`, unique per write
//!   (the counter `N`; created exclusively), so threads saving to one path
//!   never share one. Those of a process that is interrupted are removed
//!   by its signal handler ([`remove_live_temporaries`]); those a killed
//!   process left behind are removed by the next write of the same output
//!   ([`remove_stale_temporaries`]).
//! - A folder (a Zarr array) is replaced the same way: built beside it,
//!   then swapped in with two renames that the signal handler cannot come
//!   between (`replace_dir`); a killed run's old folder is put back by
//!   the next write ([`recover_replaced`]).
//! - What an interrupted run promises: the output is as it was, or it is
//!   the complete new one (when the signal came after the final rename;
//!   the exit status is still the signal's) — never a part of either.

use std::collections::HashMap;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;

use topovox::voxelize::Stop;

use crate::error::{ErrorKind, IoError};

/// Where [`write_atomically`] puts the bytes for `path`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Target {
    /// Standard output (`-`).
    Stdout,
    /// An existing file that is not a regular file (a device, a FIFO):
    /// written in place.
    Special(PathBuf),
    /// A regular file, new or existing (symbolic links resolved): a
    /// temporary file beside it, renamed over it.
    Regular(PathBuf),
}

/// How `path` will be written.
pub fn target(path: &Path) -> Target {
    if path.as_os_str() == "-" {
        return Target::Stdout;
    }
    match std::fs::metadata(path) {
        Ok(m) if !m.is_file() && !m.is_dir() => Target::Special(path.to_path_buf()),
        Ok(m) if m.is_file() => Target::Regular(std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf())),
        _ => Target::Regular(path.to_path_buf()),
    }
}

/// Writes `path` through `fill` as [`Target`] says: atomically for regular
/// files (on any error the temporary file is removed and `path` is
/// untouched), directly for special files and standard output.
pub fn write_atomically(path: &Path, fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>) -> Result<(), IoError> {
    stage(path, fill)?.commit()
}

/// [`write_atomically`] that gives up once `stop` is requested: the
/// writes fail from then on, and a complete temporary file is removed
/// rather than put in place, so a stopped write leaves `path` as it was
/// (a special file or standard output keeps what was written before).
pub fn write_atomically_until(
    path: &Path,
    stop: Option<&Stop>,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<(), IoError> {
    let staged = stage(path, |w| fill(&mut Stopping { out: w, stop }))?;
    check_stop(stop).map_err(|e| IoError::new(path, ErrorKind::Write(e)))?;
    staged.commit()
}

/// The error of a write given up because a stop was requested.
pub fn stopped() -> std::io::Error {
    // Not `ErrorKind::Interrupted`: `write_all` retries those.
    std::io::Error::other("interrupted")
}

/// `Err(`[`stopped`]`)` once `stop` is requested.
pub fn check_stop(stop: Option<&Stop>) -> std::io::Result<()> {
    match stop {
        Some(s) if s.requested() => Err(stopped()),
        _ => Ok(()),
    }
}

/// A writer that fails once a stop is requested.
struct Stopping<'a, 'b> {
    out: &'a mut dyn Write,
    stop: Option<&'b Stop>,
}

impl Write for Stopping<'_, '_> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        check_stop(self.stop)?;
        self.out.write(buf)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.out.flush()
    }
}

/// Output written but not yet in place: for a regular file, a complete
/// temporary file beside it, renamed over it by [`Staged::commit`] and
/// removed if the `Staged` is dropped uncommitted. Staging several files
/// and committing them in order replaces them together as far as a file
/// system allows: nothing is renamed until every one is complete (the
/// `.obj` and its `.mtl`).
#[must_use = "a staged output is removed unless committed"]
pub struct Staged {
    path: PathBuf,
    temp: Option<Temporary>,
}

impl Staged {
    /// Renames the temporary file over the output (nothing to do for
    /// special files and standard output, written in place).
    pub fn commit(mut self) -> Result<(), IoError> {
        match self.temp.take() {
            None => Ok(()),
            Some(t) => t.rename_to(&self.path).map_err(|e| IoError::new(&self.path, ErrorKind::Write(e))),
        }
    }
}

/// Writes `path`'s bytes through `fill` to where [`Target`] says, without
/// putting a regular file in place yet (see [`Staged`]).
pub fn stage(path: &Path, fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>) -> Result<Staged, IoError> {
    let err = |e| IoError::new(path, ErrorKind::Write(e));
    // Everything goes through one buffer, flushed before it is put in place.
    let through = |out: &mut dyn Write| {
        let mut w = BufWriter::with_capacity(1 << 20, out);
        fill(&mut w).and_then(|_| w.flush())
    };
    match target(path) {
        Target::Stdout => {
            through(&mut std::io::stdout().lock()).map_err(err)?;
            Ok(Staged { path: path.to_path_buf(), temp: None })
        }
        Target::Special(p) => {
            let mut file = std::fs::OpenOptions::new().write(true).open(&p).map_err(err)?;
            through(&mut file).map_err(err)?;
            Ok(Staged { path: path.to_path_buf(), temp: None })
        }
        Target::Regular(real) => {
            remove_stale_temporaries(&real);
            let (temp, mut file) = Temporary::create_file(&real).map_err(err)?;
            through(&mut file).map_err(err)?;
            Ok(Staged { path: real, temp: Some(temp) })
        }
    }
}

/// A scratch section of an output that can only be placed once the
/// writer has seen the end (a PLY's faces come after all vertices, but the
/// header counts both): held in memory up to [`Spool::SPILL`] bytes, then
/// in a file beside the output (the same file system, the same free
/// space), or in the system's temporary folder for standard output and
/// special files; named and removed like any temporary.
pub struct Spool {
    output: PathBuf,
    /// Bytes held in memory before spilling.
    limit: usize,
    memory: Vec<u8>,
    file: Option<(Temporary, BufWriter<File>)>,
}

impl Spool {
    /// Bytes held in memory before the section goes to a file.
    pub const SPILL: usize = 32 << 20;

    /// A new, empty spool for `output` (nothing is created yet).
    pub fn for_output(output: &Path) -> Spool {
        Spool { output: output.to_path_buf(), limit: Self::SPILL, memory: Vec::new(), file: None }
    }

    /// The same, spilling past `limit` bytes (tests spill at once).
    pub fn spilling_past(output: &Path, limit: usize) -> Spool {
        Spool { limit, ..Spool::for_output(output) }
    }

    /// Makes room for `more` bytes about to be written (one allocation
    /// instead of a doubling series while it stays in memory).
    pub fn reserve(&mut self, more: usize) {
        if self.file.is_none() && self.memory.len() + more <= self.limit {
            self.memory.reserve_exact(more);
        }
    }

    /// Moves what memory holds to a new scratch file.
    fn spill(&mut self) -> std::io::Result<&mut BufWriter<File>> {
        let beside = match target(&self.output) {
            Target::Regular(real) => real,
            Target::Stdout | Target::Special(_) => std::env::temp_dir().join("topovox-spool"),
        };
        let (temp, file) = Temporary::create_file(&beside)?;
        let mut out = BufWriter::with_capacity(1 << 20, file);
        out.write_all(&std::mem::take(&mut self.memory))?;
        Ok(&mut self.file.insert((temp, out)).1)
    }

    /// Copies everything written so far to `w`; the scratch file, if any,
    /// is removed.
    pub fn copy_into(self, w: &mut dyn Write) -> std::io::Result<u64> {
        match self.file {
            None => w.write_all(&self.memory).map(|()| self.memory.len() as u64),
            Some((temp, mut out)) => {
                out.flush()?;
                let mut back = File::open(temp.path())?;
                std::io::copy(&mut back, w)
            }
        }
    }
}

impl Write for Spool {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        if let Some((_, out)) = &mut self.file {
            return out.write(buf);
        }
        if self.memory.len() + buf.len() <= self.limit {
            self.memory.extend_from_slice(buf);
            return Ok(buf.len());
        }
        self.spill()?.write(buf)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        match &mut self.file {
            Some((_, out)) => out.flush(),
            None => Ok(()),
        }
    }
}

/// The marker in every temporary name, between the output's name and the
/// writing process's id: `.NAME.topovox-tmp-PID-N`.
const TEMP_MARK: &str = ".topovox-tmp-";

/// Temporaries this process is writing, removed by
/// [`remove_live_temporaries`] when the process is interrupted.
static LIVE: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Makes every temporary name unique within the process (several threads
/// may write the same output at once).
static COUNTER: AtomicU64 = AtomicU64::new(0);

fn live() -> std::sync::MutexGuard<'static, Vec<PathBuf>> {
    LIVE.lock().unwrap_or_else(|e| e.into_inner())
}

/// A temporary file or folder beside an output, unique to this write
/// (process id and a counter, created exclusively), registered while it
/// exists and removed when dropped unless renamed into place.
pub(crate) struct Temporary {
    path: PathBuf,
}

impl Temporary {
    /// A new temporary name for `output`, registered as live.
    fn name_for(output: &Path) -> Temporary {
        let name = output.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let path = output.with_file_name(format!(".{name}{TEMP_MARK}{}-{n}", std::process::id()));
        live().push(path.clone());
        Temporary { path }
    }

    /// A new, exclusively created temporary file for `output`.
    fn create_file(output: &Path) -> std::io::Result<(Temporary, File)> {
        let t = Temporary::name_for(output);
        let file = std::fs::OpenOptions::new().write(true).create_new(true).open(&t.path)?;
        Ok((t, file))
    }

    /// A new, exclusively created temporary folder for `output`.
    pub(crate) fn create_dir(output: &Path) -> std::io::Result<Temporary> {
        let t = Temporary::name_for(output);
        std::fs::create_dir(&t.path)?;
        Ok(t)
    }

    /// Where it is.
    pub(crate) fn path(&self) -> &Path {
        &self.path
    }

    /// Renames it to `to`; on failure it is removed. The rename happens
    /// under the registry's lock, which the signal handler holds while it
    /// removes temporaries: it never removes one mid-rename (it used to
    /// happen that a folder half removed was renamed into place).
    pub(crate) fn rename_to(self, to: &Path) -> std::io::Result<()> {
        let mut live = live();
        std::fs::rename(&self.path, to)?;
        live.retain(|p| p != &self.path);
        drop(live);
        std::mem::forget(self);
        Ok(())
    }
}

/// What a folder being replaced is renamed to while the new one takes its
/// place: `.NAME.topovox-old-PID-N`.
const OLD_MARK: &str = ".topovox-old-";

/// Puts the finished temporary folder `tmp` at `path`, all or nothing: an
/// existing folder there is moved aside, the new one renamed in, and the
/// old one removed only then. Both renames happen under the registry's
/// lock, so the signal handler runs before or after the pair, never
/// between them. A process killed outright (no handler) between them
/// leaves the old folder under its aside name: [`recover_replaced`] puts
/// it back on the next write.
pub(crate) fn replace_dir(tmp: Temporary, path: &Path) -> std::io::Result<()> {
    let aside = {
        let mut live = live();
        let aside = match std::fs::symlink_metadata(path) {
            Ok(_) => {
                let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
                let n = COUNTER.fetch_add(1, Ordering::Relaxed);
                let aside = path.with_file_name(format!(".{name}{OLD_MARK}{}-{n}", std::process::id()));
                std::fs::rename(path, &aside)?;
                Some(aside)
            }
            Err(_) => None,
        };
        if let Err(e) = std::fs::rename(&tmp.path, path) {
            if let Some(a) = &aside {
                let _ = std::fs::rename(a, path);
            }
            return Err(e);
        }
        live.retain(|p| p != &tmp.path);
        // From here the handler may remove the old folder: the new one is in place.
        live.extend(aside.clone());
        std::mem::forget(tmp);
        aside
    };
    if let Some(a) = aside {
        remove_path(&a);
        forget_live(&a);
    }
    Ok(())
}

/// Puts back what a killed run was replacing: a folder `.NAME.topovox-old-
/// PID-N` beside `output` whose process is gone goes back to `output` when
/// nothing is there (the run died between its two renames), and is removed
/// when the new output is in place. Only where a process's end can be told
/// (Linux's `/proc`).
pub fn recover_replaced(output: &Path) {
    let Some(name) = output.file_name().map(|n| n.to_string_lossy().into_owned()) else { return };
    let dir = match output.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let prefix = format!(".{name}{OLD_MARK}");
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    let mut left: Vec<PathBuf> = entries
        .flatten()
        .filter_map(|e| e.file_name().into_string().ok())
        .filter(|n| n.strip_prefix(&prefix).and_then(|rest| rest.split('-').next()?.parse::<u32>().ok()).is_some_and(process_is_gone))
        .map(|n| dir.join(n))
        .collect();
    left.sort();
    for aside in left {
        if std::fs::symlink_metadata(output).is_err() {
            let _ = std::fs::rename(&aside, output);
        } else {
            remove_path(&aside);
        }
    }
}

impl Drop for Temporary {
    fn drop(&mut self) {
        remove_path(&self.path);
        forget_live(&self.path);
    }
}

fn forget_live(path: &Path) {
    live().retain(|p| p != path);
}

fn remove_path(path: &Path) {
    match std::fs::symlink_metadata(path) {
        Ok(m) if m.is_dir() => {
            let _ = std::fs::remove_dir_all(path);
        }
        Ok(_) => {
            let _ = std::fs::remove_file(path);
        }
        Err(_) => {}
    }
}

/// Removes every temporary this process is writing: for a signal handler
/// that is about to end the process (the CLI's Ctrl-C), so an interrupted
/// run leaves nothing behind. Holds the registry until the process ends
/// if `then_exit` is given, so no new temporary appears meanwhile.
pub fn remove_live_temporaries(then_exit: Option<i32>) {
    let mut live = live();
    let gone: Vec<PathBuf> = live.drain(..).collect();
    for p in &gone {
        remove_path(p);
    }
    // A writer thread still filling a temporary folder (a Zarr array's
    // chunks) can make its folders again (`create_dir_all`) just after
    // they were removed: look again a few times before the process ends
    // (2 of 16 signals left a `.out.zarr.topovox-tmp-PID-0` behind).
    if !gone.is_empty() {
        for _ in 0..4 {
            std::thread::sleep(std::time::Duration::from_millis(5));
            gone.iter().for_each(|p| remove_path(p));
        }
    }
    if let Some(code) = then_exit {
        std::process::exit(code);
    }
}

/// Removes the temporaries of `output` that an earlier run left behind
/// (killed before it could clean up): names `.NAME.topovox-tmp-PID…`
/// beside it whose process `PID` is gone. Only where that can be told
/// (Linux's `/proc`); elsewhere they are left alone. Each folder is listed
/// once per process (a batch writes thousands of outputs into one): the
/// stale names found then are kept and removed output by output.
pub fn remove_stale_temporaries(output: &Path) {
    static STALE: Mutex<Option<HashMap<PathBuf, Vec<String>>>> = Mutex::new(None);
    let Some(name) = output.file_name().map(|n| n.to_string_lossy().into_owned()) else { return };
    let dir = match output.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let prefix = format!(".{name}{TEMP_MARK}");
    let mut stale = STALE.lock().unwrap_or_else(|e| e.into_inner());
    let names = stale.get_or_insert_with(HashMap::new).entry(dir.to_path_buf()).or_insert_with(|| stale_in(dir));
    names.retain(|n| {
        let ours = n.starts_with(&prefix);
        if ours {
            remove_path(&dir.join(n));
        }
        !ours
    });
}

/// The names in `dir` of temporaries (`….topovox-tmp-PID…`) whose process
/// is gone.
fn stale_in(dir: &Path) -> Vec<String> {
    let Ok(entries) = std::fs::read_dir(dir) else { return Vec::new() };
    entries
        .flatten()
        .filter_map(|e| e.file_name().into_string().ok())
        .filter(|n| {
            let pid = n.split_once(TEMP_MARK).and_then(|(_, rest)| rest.split('-').next()?.parse::<u32>().ok());
            pid.is_some_and(process_is_gone)
        })
        .collect()
}

/// True when no process `pid` runs (Linux: no `/proc/PID`); false where it
/// cannot be told.
fn process_is_gone(pid: u32) -> bool {
    if pid == std::process::id() {
        return false;
    }
    cfg!(target_os = "linux") && Path::new("/proc/self").exists() && !Path::new("/proc").join(pid.to_string()).exists()
}

/// The same file by identity (device and inode on Unix; the resolved path
/// elsewhere), whatever the spelling: symbolic links, `./`, hard links.
/// `false` if either does not exist.
pub fn same_file(a: &Path, b: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        match (std::fs::metadata(a), std::fs::metadata(b)) {
            (Ok(x), Ok(y)) => x.dev() == y.dev() && x.ino() == y.ino(),
            _ => false,
        }
    }
    #[cfg(not(unix))]
    {
        match (std::fs::canonicalize(a), std::fs::canonicalize(b)) {
            (Ok(x), Ok(y)) => x == y,
            _ => false,
        }
    }
}

/// Refuses to write `output` over any of `inputs` (the files a job reads:
/// a mesh, its material libraries and textures, a voxel file): one line
/// naming both.
pub fn refuse_overwriting_inputs(output: &Path, inputs: &[PathBuf]) -> Result<(), IoError> {
    for input in inputs {
        if same_file(output, input) {
            return Err(IoError::new(
                output,
                ErrorKind::Write(std::io::Error::other(format!(
                    "it is the same file as the input {}; refusing to overwrite it",
                    input.display()
                ))),
            ));
        }
    }
    Ok(())
}
