//! A palette of at most `k` colours for a multiset of colours: median cut
//! (P. Heckbert, "Color image quantization for frame buffer display",
//! SIGGRAPH 1982) in Oklab, refined by weighted k-means (Lloyd), with every
//! palette entry snapped to the nearest **input** colour, so the palette
//! never invents a colour. With at most `k` distinct colours the palette is
//! exactly those colours.

use std::collections::BTreeMap;

use super::colour::{dist2, oklab, pack, unpack};

/// Refinement rounds of k-means.
const ROUNDS: usize = 8;

/// A palette for `colours` (with repeats: each voxel's colour).
/// Deterministic; at most `k` entries, sorted by `0xRRGGBB`.
pub fn palette(colours: &[[u8; 3]], k: usize) -> Vec<[u8; 3]> {
    let mut counts: BTreeMap<u32, u64> = BTreeMap::new();
    for &c in colours {
        *counts.entry(pack(c)).or_default() += 1;
    }
    let items: Vec<Item> = counts.into_iter().map(|(c, n)| Item { rgb: unpack(c), lab: oklab(unpack(c)), n: n as f64 }).collect();
    if items.len() <= k || k == 0 {
        return items.iter().take(k).map(|i| i.rgb).collect();
    }
    // Median cut: split the box with the largest weighted spread at its weighted median.
    let mut boxes: Vec<Vec<usize>> = vec![(0..items.len()).collect()];
    while boxes.len() < k {
        let Some((bi, axis, spread)) = boxes
            .iter()
            .enumerate()
            .filter(|(_, b)| b.len() > 1)
            .map(|(bi, b)| {
                let (axis, spread) = widest_axis(&items, b);
                (bi, axis, spread)
            })
            .max_by(|a, b| a.2.total_cmp(&b.2).then(b.0.cmp(&a.0)))
        else {
            break;
        };
        if spread <= 0.0 {
            break;
        }
        let mut b = std::mem::take(&mut boxes[bi]);
        b.sort_by(|&x, &y| items[x].lab[axis].total_cmp(&items[y].lab[axis]).then(x.cmp(&y)));
        let total: f64 = b.iter().map(|&i| items[i].n).sum();
        let mut acc = 0.0;
        let mut cut = 1;
        for (p, &i) in b.iter().enumerate() {
            acc += items[i].n;
            if acc >= total / 2.0 {
                cut = (p + 1).clamp(1, b.len() - 1);
                break;
            }
        }
        let hi = b.split_off(cut);
        boxes[bi] = b;
        boxes.push(hi);
    }
    let mut centres: Vec<[f32; 3]> = boxes.iter().map(|b| mean(&items, b)).collect();
    // Lloyd refinement.
    let mut assign = vec![0usize; items.len()];
    for _ in 0..ROUNDS {
        for (i, it) in items.iter().enumerate() {
            assign[i] = nearest(&centres, it.lab);
        }
        let mut sum = vec![([0f64; 3], 0f64); centres.len()];
        for (i, it) in items.iter().enumerate() {
            let s = &mut sum[assign[i]];
            (0..3).for_each(|a| s.0[a] += it.lab[a] as f64 * it.n);
            s.1 += it.n;
        }
        for (c, s) in centres.iter_mut().zip(&sum) {
            if s.1 > 0.0 {
                *c = s.0.map(|v| (v / s.1) as f32);
            }
        }
    }
    // Snap each centre to its nearest input colour; drop duplicates.
    let mut out: Vec<u32> = centres
        .iter()
        .map(|c| {
            let best = items.iter().min_by(|a, b| dist2(a.lab, *c).total_cmp(&dist2(b.lab, *c))).map(|i| i.rgb).unwrap_or([0; 3]);
            pack(best)
        })
        .collect();
    out.sort_unstable();
    out.dedup();
    out.into_iter().map(unpack).collect()
}

/// Index of the palette entry nearest (in Oklab) to each colour of `colours`.
pub fn map_to_palette(colours: &[[u8; 3]], palette: &[[u8; 3]]) -> Vec<u8> {
    let labs: Vec<[f32; 3]> = palette.iter().map(|&c| oklab(c)).collect();
    let mut cache: BTreeMap<u32, u8> = BTreeMap::new();
    colours.iter().map(|&c| *cache.entry(pack(c)).or_insert_with(|| nearest(&labs, oklab(c)) as u8)).collect()
}

/// The index of the entry of `labs` nearest to `lab` (ties: the lower index).
pub fn nearest(labs: &[[f32; 3]], lab: [f32; 3]) -> usize {
    let mut best = (0, f32::INFINITY);
    for (i, &c) in labs.iter().enumerate() {
        let d = dist2(c, lab);
        if d < best.1 {
            best = (i, d);
        }
    }
    best.0
}

/// Palette indices by error diffusion over the voxels (Floyd–Steinberg
/// carried to 3D): voxels are visited in key order and each passes its
/// quantization error, in linear light, to its set neighbours at `+i`
/// (3/8), `+j` (3/8) and `+k` (2/8). Deterministic.
pub fn dither(attrs: &super::VoxelAttributes, colours: &[[u8; 3]], palette: &[[u8; 3]]) -> Vec<u8> {
    use super::colour::{linear_to_rgb, rgb_to_linear};
    let labs: Vec<[f32; 3]> = palette.iter().map(|&c| oklab(c)).collect();
    let lins: Vec<[f64; 3]> = palette.iter().map(|&c| rgb_to_linear(c)).collect();
    let mut err = vec![[0f64; 3]; colours.len()];
    let mut out = Vec::with_capacity(colours.len());
    for (s, &c) in colours.iter().enumerate() {
        let want = rgb_to_linear(c);
        let target: [f64; 3] = std::array::from_fn(|a| (want[a] + err[s][a]).clamp(0.0, 1.0));
        let idx = nearest(&labs, oklab(linear_to_rgb(target)));
        out.push(idx as u8);
        let e: [f64; 3] = std::array::from_fn(|a| target[a] - lins[idx][a]);
        let [i, j, k] = attrs.voxel(attrs.keys[s]);
        for (axis, share) in [(0, 3.0 / 8.0), (1, 3.0 / 8.0), (2, 2.0 / 8.0)] {
            let mut q = [i, j, k];
            q[axis] += 1;
            if q[axis] >= attrs.dims[axis] {
                continue;
            }
            if let Some(t) = attrs.slot(q[0], q[1], q[2]) {
                (0..3).for_each(|a| err[t][a] += e[a] * share);
            }
        }
    }
    out
}

struct Item {
    rgb: [u8; 3],
    lab: [f32; 3],
    n: f64,
}

fn widest_axis(items: &[Item], b: &[usize]) -> (usize, f64) {
    // Weighted sum of squared deviations: boxes holding many, spread-out voxels split first.
    let m = mean(items, b);
    (0..3)
        .map(|a| (a, b.iter().map(|&i| items[i].n * ((items[i].lab[a] - m[a]) as f64).powi(2)).sum::<f64>()))
        .max_by(|x, y| x.1.total_cmp(&y.1).then(y.0.cmp(&x.0)))
        .unwrap_or((0, 0.0))
}

fn mean(items: &[Item], b: &[usize]) -> [f32; 3] {
    let mut s = [0f64; 3];
    let mut n = 0.0;
    for &i in b {
        (0..3).for_each(|a| s[a] += items[i].lab[a] as f64 * items[i].n);
        n += items[i].n;
    }
    s.map(|v| if n > 0.0 { (v / n) as f32 } else { 0.0 })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn few_colours_are_kept_exactly() {
        let c = vec![[1, 2, 3], [200, 10, 10], [1, 2, 3]];
        assert_eq!(palette(&c, 255), vec![[1, 2, 3], [200, 10, 10]]);
    }

    #[test]
    fn many_colours_make_at_most_k_input_colours() {
        let mut c = Vec::new();
        for r in 0..40u8 {
            for g in 0..40u8 {
                c.push([r * 6, g * 6, 128]);
            }
        }
        let p = palette(&c, 16);
        assert!(p.len() <= 16 && p.len() >= 12, "{}", p.len());
        for e in &p {
            assert!(c.contains(e));
        }
        // Every colour maps to an entry not far from it (a good spread, not one corner).
        let idx = map_to_palette(&c, &p);
        let worst = c.iter().zip(&idx).map(|(&x, &i)| dist2(oklab(x), oklab(p[i as usize]))).fold(0f32, f32::max);
        assert!(worst < 0.01, "worst squared Oklab error {worst}");
    }
}
