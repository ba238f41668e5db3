//! The oriented boundary of a triangle mesh as closed cycles, and polygons
//! split into triangles: what the generalized winding number caps holes
//! with (`voxelize::winding` on the lattice, `query::caps` in the world).

use rustc_hash::FxHashMap;

/// The oriented boundary of a mesh, from its [`Snapped::net_edges`], as
/// closed cycles of lattice points.
pub(crate) fn boundary_cycles<P: Copy + Ord + std::hash::Hash>(net: &[(P, P, i64)]) -> Vec<Vec<P>> {
    // Outgoing boundary half-edges per vertex (with multiplicity), in a
    // deterministic order.
    let mut half: Vec<(P, P)> = Vec::new();
    for &(a, b, n) in net {
        for _ in 0..n.unsigned_abs() {
            half.push(if n > 0 { (a, b) } else { (b, a) });
        }
    }
    half.sort_unstable();
    let mut out: FxHashMap<P, Vec<P>> = FxHashMap::default();
    for &(a, b) in half.iter().rev() {
        out.entry(a).or_default().push(b);
    }
    let mut starts: Vec<P> = half.iter().map(|h| h.0).collect();
    starts.dedup();
    let mut cycles = Vec::new();
    for s in starts {
        while out.get(&s).is_some_and(|v| !v.is_empty()) {
            // Walk until back at the start: in- and out-degrees balance at
            // every vertex (the boundary of a boundary is empty), so the
            // walk cannot get stuck elsewhere.
            let mut cycle = vec![s];
            let mut at = s;
            while let Some(next) = out.get_mut(&at).and_then(|v| v.pop()) {
                if next == s {
                    break;
                }
                cycle.push(next);
                at = next;
            }
            cycles.push(cycle);
        }
    }
    cycles
}

/// Triangulates the polygon of vertices `p` (indices; any shape, only its
/// boundary matters) by splitting it along the diagonal from its first
/// vertex to its middle one, keeping the polygon's orientation.
pub(crate) fn triangulate(p: &[u32], out: &mut Vec<[u32; 3]>) {
    match p.len() {
        0..=2 => {}
        3 => out.push([p[0], p[1], p[2]]),
        n => {
            let mid = n / 2;
            triangulate(&p[..=mid], out);
            let mut rest: Vec<u32> = p[mid..].to_vec();
            rest.push(p[0]);
            triangulate(&rest, out);
        }
    }
}
