//! Consecutive runs of equal keys, for writers that group bricks.

/// Consecutive runs of `items` with the same `key`.
pub(crate) fn runs<T, K: PartialEq>(items: &[T], key: impl Fn(&T) -> K) -> Vec<std::ops::Range<usize>> {
    let mut out = Vec::new();
    let mut s = 0;
    while s < items.len() {
        let k = key(&items[s]);
        let e = s + items[s..].iter().take_while(|x| key(x) == k).count();
        out.push(s..e);
        s = e;
    }
    out
}
