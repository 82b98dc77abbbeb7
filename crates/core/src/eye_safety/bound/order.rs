//! Sort and merge helpers of the sweeps: Euclidean index splits, and the
//! linear-time sort of a few increasing runs ([`sort_runs`]), bit-identical
//! to a sort by `f64::total_cmp` and a dedup.

/// `(idx div m, idx mod m)` (Euclidean, `m > 0`) without an integer
/// division for the indices the sweeps use (within a period of `[0, m)`).
pub(super) fn split_index(idx: i64, m: i64) -> (i64, usize) {
    if (0..m).contains(&idx) {
        (0, idx as usize)
    } else if (-m..0).contains(&idx) {
        (-1, (idx + m) as usize)
    } else if (m..2 * m).contains(&idx) {
        (1, (idx - m) as usize)
    } else {
        (idx.div_euclid(m), idx.rem_euclid(m) as usize)
    }
}

/// `idx mod m` in `[0, m)` (see [`split_index`]).
pub(super) fn wrap_index(idx: i64, m: i64) -> usize {
    split_index(idx, m).1
}

/// The key `f64::total_cmp` orders by, as an integer (the same transform).
fn total_key(x: f64) -> i64 {
    let k = x.to_bits() as i64;
    k ^ (((k >> 63) as u64) >> 1) as i64
}

/// The inverse of [`total_key`].
fn of_total_key(k: i64) -> f64 {
    f64::from_bits((k ^ (((k >> 63) as u64) >> 1) as i64) as u64)
}

/// The runs `v[bounds[k]..bounds[k + 1]]`, each nondecreasing but for at
/// most one wrap (a single descent), sorted by `f64::total_cmp` and
/// deduplicated: the same vector as `sort_by(total_cmp)` then `dedup`
/// (the sorted order of a total order is unique), in linear time (merges of
/// the rotated runs, in two buffers). Falls back to the sort if a run has
/// two descents or a NaN. The runs must cover `v` (`bounds` from 0 to its
/// length).
pub(super) fn sort_runs(mut v: Vec<f64>, bounds: &[usize]) -> Vec<f64> {
    debug_assert!(bounds.first() == Some(&0) && bounds.last() == Some(&v.len()));
    if v.iter().any(|x| x.is_nan()) {
        v.sort_by(f64::total_cmp);
        v.dedup();
        return v;
    }
    let keys: Vec<i64> = v.iter().map(|&x| total_key(x)).collect();
    // Each run rotated at its descent (if any) into `merged`.
    let mut merged: Vec<i64> = Vec::with_capacity(keys.len());
    for w in bounds.windows(2) {
        let run = &keys[w[0]..w[1]];
        let (mut descents, mut at) = (0usize, 0usize);
        for i in 1..run.len() {
            if run[i - 1] > run[i] {
                descents += 1;
                at = i;
            }
        }
        if descents > 1 || (descents == 1 && run[run.len() - 1] > run[0]) {
            v.sort_by(f64::total_cmp);
            v.dedup();
            return v;
        }
        merged.extend_from_slice(&run[at..]);
        merged.extend_from_slice(&run[..at]);
    }
    // Bottom-up: merge neighbouring runs pairwise until one is left.
    let mut other = keys;
    let mut starts: Vec<usize> = bounds.to_vec();
    while starts.len() > 2 {
        let mut next = Vec::with_capacity(starts.len() / 2 + 2);
        for k in (0..starts.len() - 1).step_by(2) {
            let (lo, mid) = (starts[k], starts[k + 1]);
            let hi = starts.get(k + 2).copied().unwrap_or(mid);
            next.push(lo);
            merge_keys(&merged[lo..mid], &merged[mid..hi], &mut other[lo..hi]);
        }
        next.push(merged.len());
        starts = next;
        std::mem::swap(&mut merged, &mut other);
    }
    v.clear();
    for &k in &merged {
        let x = of_total_key(k);
        if v.last() != Some(&x) {
            v.push(x);
        }
    }
    v
}

/// The stable merge of the sorted keys `a` and `b` (no `i64::MAX` or
/// `i64::MIN`, the keys of NaNs) into `out` (of their total length), built
/// from both ends at once: the front takes the smaller head (`a` on ties),
/// the back the larger tail (`b` on ties), so they fill the merged order's
/// two halves without branches on the data and as two independent chains.
fn merge_keys(a: &[i64], b: &[i64], out: &mut [i64]) {
    let n = a.len() + b.len();
    debug_assert_eq!(out.len(), n);
    let (mut i, mut j) = (0usize, 0usize);
    let (mut ie, mut je) = (a.len(), b.len());
    for k in 0..n / 2 {
        let av = if i < a.len() { a[i] } else { i64::MAX };
        let bv = if j < b.len() { b[j] } else { i64::MAX };
        let take_b = bv < av;
        out[k] = if take_b { bv } else { av };
        j += usize::from(take_b);
        i += usize::from(!take_b);
        let av = if ie > 0 { a[ie - 1] } else { i64::MIN };
        let bv = if je > 0 { b[je - 1] } else { i64::MIN };
        let take_a = av > bv;
        out[n - 1 - k] = if take_a { av } else { bv };
        ie -= usize::from(take_a);
        je -= usize::from(!take_a);
    }
    if n % 2 == 1 {
        let av = if i < a.len() { a[i] } else { i64::MAX };
        let bv = if j < b.len() { b[j] } else { i64::MAX };
        out[n / 2] = av.min(bv);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn bits(v: &[f64]) -> Vec<u64> {
        v.iter().map(|x| x.to_bits()).collect()
    }

    fn sorted(mut v: Vec<f64>) -> Vec<f64> {
        v.sort_by(f64::total_cmp);
        v.dedup();
        v
    }

    /// A run increasing but for one wrap: `xs` (sorted) rotated by `r`.
    fn wrapped_run(mut xs: Vec<f64>, r: usize) -> Vec<f64> {
        xs.sort_by(f64::total_cmp);
        let r = if xs.is_empty() { 0 } else { r % xs.len() };
        xs.rotate_left(r);
        xs
    }

    proptest! {
        #[test]
        fn sort_runs_is_sort_and_dedup(
            runs in proptest::collection::vec(
                (proptest::collection::vec(prop_oneof![
                    0.0f64..360.0,
                    Just(0.0), Just(-0.0), Just(90.0), Just(359.999_999_999),
                ], 0..40), 0usize..40),
                1..5,
            ),
            extra in proptest::option::of((0usize..4, 0usize..40, prop_oneof![
                Just(f64::NAN), Just(-1.0), Just(1e300), Just(5.0),
            ])),
        ) {
            let mut v = Vec::new();
            let mut bounds = vec![0];
            for (k, (xs, r)) in runs.into_iter().enumerate() {
                let mut run = wrapped_run(xs, r);
                // Sometimes a second descent, or a NaN: the fallback.
                if let Some((j, at, x)) = extra {
                    if j == k && !run.is_empty() {
                        let at = at % run.len();
                        run[at] = x;
                    }
                }
                v.extend(run);
                bounds.push(v.len());
            }
            let expected = sorted(v.clone());
            prop_assert_eq!(bits(&sort_runs(v, &bounds)), bits(&expected));
        }

        #[test]
        fn split_index_is_euclidean(idx in -10_000i64..10_000, m in 1i64..500) {
            let (k, j) = split_index(idx, m);
            prop_assert_eq!((k, j as i64), (idx.div_euclid(m), idx.rem_euclid(m)));
            prop_assert_eq!(wrap_index(idx, m) as i64, idx.rem_euclid(m));
        }
    }
}
