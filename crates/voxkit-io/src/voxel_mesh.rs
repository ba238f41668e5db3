//! A mesh of the voxels as Wavefront OBJ: the greedy quads of
//! [`voxkit::export::greedy`], corners shared, faces as quads.

use std::collections::HashMap;
use std::path::Path;

use voxkit::export::greedy::Quad;
use voxkit::GridSpec;

use crate::atomic::write_atomically;
use crate::error::IoError;

/// Writes `quads` on `grid` (world coordinates) as an OBJ of quad faces,
/// counter-clockwise seen from outside. Returns the number of vertices.
pub fn write_quads_obj(path: &Path, quads: &[Quad], grid: &GridSpec) -> Result<usize, IoError> {
    let mut index: HashMap<[u32; 3], u32> = HashMap::with_capacity(quads.len() * 2);
    let mut order: Vec<[u32; 3]> = Vec::with_capacity(quads.len() * 2);
    let faces: Vec<[u32; 4]> = quads
        .iter()
        .map(|q| {
            q.corners().map(|c| {
                *index.entry(c).or_insert_with(|| {
                    order.push(c);
                    order.len() as u32
                })
            })
        })
        .collect();
    let (o, s) = (grid.origin(), grid.voxel_size());
    write_atomically(path, |w| {
        writeln!(w, "# voxkit: {} greedy quads of the voxels' boundary faces", quads.len())?;
        for c in &order {
            writeln!(w, "v {} {} {}", o.x + c[0] as f64 * s, o.y + c[1] as f64 * s, o.z + c[2] as f64 * s)?;
        }
        for f in &faces {
            writeln!(w, "f {} {} {} {}", f[0], f[1], f[2], f[3])?;
        }
        Ok(())
    })?;
    Ok(order.len())
}
