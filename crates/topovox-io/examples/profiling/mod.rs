//! What the `profile_*` examples share: their first four arguments (`MESH
//! RESOLUTION THREADS [REPEATS]`), the mesh and grid they time on, a
//! thread pool of that size, and the median of repeated runs.

use std::time::Instant;

use topovox::GridSpec;
use topovox_io::LoadedMesh;

/// A profiling run's set-up, from the command line.
pub struct Profiled {
    /// The command line (further arguments are the example's own).
    #[allow(dead_code)] // `profile_solid` takes none
    pub args: Vec<String>,
    pub res: u64,
    pub threads: usize,
    pub reps: usize,
    pub loaded: LoadedMesh,
    pub grid: GridSpec,
    pub pool: rayon::ThreadPool,
}

impl Profiled {
    /// Reads the arguments (with these defaults), the mesh and its grid.
    pub fn from_args(mesh: &str, res: u64, reps: usize) -> Profiled {
        let args: Vec<String> = std::env::args().collect();
        let path = args.get(1).map(String::as_str).unwrap_or(mesh);
        let res: u64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(res);
        let threads: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(1);
        let reps: usize = args.get(4).and_then(|s| s.parse().ok()).unwrap_or(reps);
        let loaded = topovox_io::read_mesh(std::path::Path::new(path), &topovox_io::ReadOptions::default()).expect("mesh");
        let grid = GridSpec::from_resolution(&loaded.report.bounds, res).expect("grid");
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
        Profiled { args, res, threads, reps, loaded, grid, pool }
    }

    /// The median time of `f` over the repeats, in milliseconds.
    pub fn median_ms(&self, f: &mut dyn FnMut()) -> f64 {
        let mut v: Vec<f64> = (0..self.reps)
            .map(|_| {
                let t = Instant::now();
                f();
                t.elapsed().as_secs_f64() * 1e3
            })
            .collect();
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    }
}
