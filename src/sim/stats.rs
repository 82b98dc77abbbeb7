//! Uncertainty of the simulator's numbers: a seeded bootstrap interval of
//! the median, the modes of a multi-modal time to arrival, and paired tests
//! of a variant against the baseline on the same draws.
//!
//! Conventions (each matches `scipy.stats`, checked against fixtures the
//! script `tests/fixtures/stats/make_fixtures.py` generated with scipy;
//! see `tests/it/simulate/stats.rs`):
//!
//! - **Median**: the middle order statistic, or the mean of the two middle
//!   ones (`numpy.median`).
//! - **Bootstrap interval** ([`bootstrap_median`]): the percentile bootstrap
//!   (`scipy.stats.bootstrap(method="percentile")`): [`BOOTSTRAP_RESAMPLES`]
//!   resamples of size n drawn with replacement, the median of each, and
//!   the 2.5th and 97.5th percentiles of those medians with linear
//!   interpolation between order statistics (`numpy.percentile`'s default).
//!   The resamples come from a ChaCha8 stream seeded by [`derive_seed`] from
//!   the run's seed and the cell's name, so the output is byte-identical for
//!   the same inputs and seed, and independent of the order cells are
//!   computed in.
//! - **Modes** ([`modes`]): the sorted sample is cut wherever two consecutive
//!   values differ by more than a gap (the simulator uses [`MODE_GAP_S`]);
//!   each piece is a mode, with its share of the sample, its median and its
//!   range.
//! - **Wilcoxon signed-rank test** ([`wilcoxon`]): two-sided, on the paired
//!   differences `variant − baseline`; zero differences dropped (`zero_method
//!   ="wilcox"`), |d| ranked with average ranks for ties. Exact null
//!   distribution when at most [`WILCOXON_EXACT_MAX_N`] non-zero differences
//!   remain and none are tied (`method="exact"`), otherwise the normal
//!   approximation with the tie correction of the variance and the continuity
//!   correction (`method="asymptotic", correction=True`). The normal CDF is
//!   `libm::erfc`.
//! - **Sign test** ([`sign_test`]): the exact two-sided binomial test of the
//!   number of positive differences among the non-zero ones against p = ½
//!   (`scipy.stats.binomtest`).
//! - **Effect sizes** ([`paired`]): the matched-pairs rank-biserial
//!   correlation `(R+ − R−) / (R+ + R−)` (Kerby 2014; +1: every non-zero
//!   difference positive) and the median paired difference (zeros included).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

/// Bootstrap resamples of every interval the simulator reports.
pub const BOOTSTRAP_RESAMPLES: usize = 2000;
/// Confidence level of the intervals.
pub const CONFIDENCE: f64 = 0.95;
/// Two TTA modes are separated by a gap between consecutive sorted values
/// larger than this, s. The simulator's TTA is two-peaked when the car is
/// first seen by the far ring or by the next one (carla geometry): the
/// peaks are ≈ 1.4 s apart, while the spread inside a peak (phase, start
/// offset, jitter) stays below 0.3 s, and a frame is 0.05 s.
pub const MODE_GAP_S: f64 = 0.5;
/// Largest number of non-zero differences for the exact Wilcoxon null
/// distribution (as `scipy.stats.wilcoxon`'s `method="auto"`).
pub const WILCOXON_EXACT_MAX_N: usize = 50;

/// The median (`numpy.median`); `None` for an empty sample.
#[must_use]
pub fn median(values: &[f64]) -> Option<f64> {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    median_sorted(&v)
}

fn median_sorted(v: &[f64]) -> Option<f64> {
    let n = v.len();
    if n == 0 {
        return None;
    }
    Some(if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    })
}

/// The `q`-th percentile (0–100) of a sorted sample with linear
/// interpolation between order statistics (`numpy.percentile`'s default).
#[must_use]
pub fn percentile_sorted(sorted: &[f64], q: f64) -> Option<f64> {
    if sorted.is_empty() {
        return None;
    }
    let x = q / 100.0 * (sorted.len() - 1) as f64;
    let i = (x.floor() as usize).min(sorted.len() - 1);
    let j = (i + 1).min(sorted.len() - 1);
    Some(sorted[i] + (sorted[j] - sorted[i]) * (x - i as f64))
}

/// A seed for one statistic derived from the run's seed and a label (the
/// cell's name): FNV-1a over the label, mixed with the seed by SplitMix64.
#[must_use]
pub fn derive_seed(run_seed: u64, label: &str) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in label.bytes() {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    let mut z = run_seed ^ h.rotate_left(17);
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The median with its percentile-bootstrap interval.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MedianInterval {
    /// Sample median.
    pub median: f64,
    /// Lower end of the interval.
    pub lo: f64,
    /// Upper end of the interval.
    pub hi: f64,
    /// Resamples drawn.
    pub resamples: usize,
    /// Confidence level.
    pub level: f64,
}

/// The medians of `resamples` bootstrap resamples (each of size n, drawn
/// with replacement from a ChaCha8 stream seeded with `seed`), sorted.
///
/// A resample is n uniform indices into the sorted sample; its median is
/// read from the index counts (the order statistics at positions
/// ⌊(n−1)/2⌋ and ⌊n/2⌋), O(n) per resample instead of a sort.
#[must_use]
pub fn bootstrap_medians(values: &[f64], resamples: usize, seed: u64) -> Vec<f64> {
    let n = values.len();
    if n == 0 {
        return Vec::new();
    }
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut counts = vec![0u32; n];
    let (lo_pos, hi_pos) = ((n - 1) / 2, n / 2);
    let mut medians = Vec::with_capacity(resamples);
    for _ in 0..resamples {
        counts.fill(0);
        for _ in 0..n {
            counts[rng.random_range(0..n)] += 1;
        }
        // The values at sorted positions lo_pos and hi_pos of the resample.
        let (mut lo, mut hi) = (None, None);
        let mut seen = 0usize;
        for (i, &c) in counts.iter().enumerate() {
            seen += c as usize;
            if lo.is_none() && seen > lo_pos {
                lo = Some(sorted[i]);
            }
            if seen > hi_pos {
                hi = Some(sorted[i]);
                break;
            }
        }
        let (lo, hi) = (lo.unwrap_or(f64::NAN), hi.unwrap_or(f64::NAN));
        medians.push(if lo_pos == hi_pos {
            lo
        } else {
            0.5 * (lo + hi)
        });
    }
    medians.sort_unstable_by(f64::total_cmp);
    medians
}

/// The median of `values` and its percentile-bootstrap [`CONFIDENCE`]
/// interval from `resamples` resamples; `None` for an empty sample.
#[must_use]
pub fn bootstrap_median(values: &[f64], resamples: usize, seed: u64) -> Option<MedianInterval> {
    let median = median(values)?;
    let medians = bootstrap_medians(values, resamples.max(1), seed);
    let tail = (1.0 - CONFIDENCE) / 2.0 * 100.0;
    Some(MedianInterval {
        median,
        lo: percentile_sorted(&medians, tail)?,
        hi: percentile_sorted(&medians, 100.0 - tail)?,
        resamples: resamples.max(1),
        level: CONFIDENCE,
    })
}

/// One mode of a sample.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Mode {
    /// Share of the sample in this mode, 0–1.
    pub share: f64,
    /// Values in this mode.
    pub count: usize,
    /// Median of the mode.
    pub median: f64,
    /// Smallest value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
}

/// The modes of a sample: the sorted values cut wherever consecutive values
/// differ by more than `gap`, in increasing order of value.
#[must_use]
pub fn modes(values: &[f64], gap: f64) -> Vec<Mode> {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    let mut out = Vec::new();
    let mut start = 0;
    for i in 1..=n {
        if i == n || v[i] - v[i - 1] > gap {
            let part = &v[start..i];
            out.push(Mode {
                share: part.len() as f64 / n as f64,
                count: part.len(),
                median: median_sorted(part).unwrap_or(f64::NAN),
                min: part[0],
                max: part[part.len() - 1],
            });
            start = i;
        }
    }
    out
}

/// Which null distribution a Wilcoxon p-value came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum WilcoxonMethod {
    /// The exact distribution of R+ (no ties, n ≤ [`WILCOXON_EXACT_MAX_N`]).
    Exact,
    /// Normal approximation with tie and continuity corrections.
    Normal,
    /// No non-zero difference: nothing to test (p = 1).
    NoDifference,
}

/// A two-sided Wilcoxon signed-rank test.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Wilcoxon {
    /// Non-zero differences ranked.
    pub n: usize,
    /// Sum of the ranks of the positive differences.
    pub r_plus: f64,
    /// Sum of the ranks of the negative differences.
    pub r_minus: f64,
    /// Two-sided p-value.
    pub p_value: f64,
    /// How the p-value was computed.
    pub method: WilcoxonMethod,
}

/// Average ranks (1-based) of `x` and whether any two values tie, plus
/// Σ (t³ − t) over the groups of tied values.
fn average_ranks(x: &[f64]) -> (Vec<f64>, f64) {
    let mut idx: Vec<usize> = (0..x.len()).collect();
    idx.sort_by(|&a, &b| x[a].total_cmp(&x[b]));
    let mut ranks = vec![0.0; x.len()];
    let mut ties = 0.0;
    let mut i = 0;
    while i < idx.len() {
        let mut j = i + 1;
        while j < idx.len() && x[idx[j]] == x[idx[i]] {
            j += 1;
        }
        // Positions i..j (0-based) share the average rank.
        let avg = (i + 1 + j) as f64 / 2.0;
        for &k in &idx[i..j] {
            ranks[k] = avg;
        }
        let t = (j - i) as f64;
        ties += t * t * t - t;
        i = j;
    }
    (ranks, ties)
}

/// Standard normal survival function, `P(Z > z)`.
fn normal_sf(z: f64) -> f64 {
    0.5 * libm::erfc(z / std::f64::consts::SQRT_2)
}

/// Counts of the subsets of {1, …, n} by their sum: `c[k]` subsets sum to
/// k (the exact null distribution of R+ times 2ⁿ). n ≤ 63.
fn signed_rank_counts(n: usize) -> Vec<u64> {
    let max = n * (n + 1) / 2;
    let mut c = vec![0u64; max + 1];
    c[0] = 1;
    for r in 1..=n {
        for k in (r..=max).rev() {
            c[k] += c[k - r];
        }
    }
    c
}

/// The two-sided Wilcoxon signed-rank test of the differences `d`.
#[must_use]
pub fn wilcoxon(d: &[f64]) -> Wilcoxon {
    let nz: Vec<f64> = d.iter().copied().filter(|&x| x != 0.0).collect();
    let n = nz.len();
    if n == 0 {
        return Wilcoxon {
            n: 0,
            r_plus: 0.0,
            r_minus: 0.0,
            p_value: 1.0,
            method: WilcoxonMethod::NoDifference,
        };
    }
    let abs: Vec<f64> = nz.iter().map(|x| x.abs()).collect();
    let (ranks, ties) = average_ranks(&abs);
    let r_plus: f64 = nz
        .iter()
        .zip(&ranks)
        .filter(|(x, _)| **x > 0.0)
        .map(|(_, r)| r)
        .sum();
    let r_minus: f64 = nz
        .iter()
        .zip(&ranks)
        .filter(|(x, _)| **x < 0.0)
        .map(|(_, r)| r)
        .sum();
    let nf = n as f64;
    if n <= WILCOXON_EXACT_MAX_N && ties == 0.0 {
        // No ties: ranks are 1..n, R+ is an integer.
        let c = signed_rank_counts(n);
        let total = 2f64.powi(n as i32);
        let t = r_plus.round() as usize;
        let cdf: u64 = c[..=t].iter().sum();
        let sf: u64 = c[t..].iter().sum();
        let p = (2.0 * cdf.min(sf) as f64 / total).min(1.0);
        return Wilcoxon {
            n,
            r_plus,
            r_minus,
            p_value: p,
            method: WilcoxonMethod::Exact,
        };
    }
    let mean = nf * (nf + 1.0) / 4.0;
    let var = (nf * (nf + 1.0) * (2.0 * nf + 1.0) - ties / 2.0) / 24.0;
    let se = var.sqrt();
    let p = if se > 0.0 {
        let z = (r_plus - mean) / se;
        let zc = z - z.signum() * 0.5 / se;
        (2.0 * normal_sf(zc.abs())).min(1.0)
    } else {
        1.0
    };
    Wilcoxon {
        n,
        r_plus,
        r_minus,
        p_value: p,
        method: WilcoxonMethod::Normal,
    }
}

/// An exact two-sided sign test.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SignTest {
    /// Positive differences.
    pub positive: usize,
    /// Negative differences.
    pub negative: usize,
    /// Zero differences (not counted).
    pub zero: usize,
    /// Two-sided p-value.
    pub p_value: f64,
}

/// `ln C(n, k)`.
fn ln_choose(n: usize, k: usize) -> f64 {
    libm::lgamma(n as f64 + 1.0) - libm::lgamma(k as f64 + 1.0) - libm::lgamma((n - k) as f64 + 1.0)
}

/// `P(X ≤ k)` for X ~ Binomial(n, ½).
fn binom_half_cdf(n: usize, k: usize) -> f64 {
    let ln_half_n = -(n as f64) * std::f64::consts::LN_2;
    (0..=k.min(n))
        .map(|i| (ln_choose(n, i) + ln_half_n).exp())
        .sum()
}

/// The sign test of the differences `d`: the exact two-sided binomial test
/// of the positive count among the non-zero differences against ½.
#[must_use]
pub fn sign_test(d: &[f64]) -> SignTest {
    let positive = d.iter().filter(|&&x| x > 0.0).count();
    let negative = d.iter().filter(|&&x| x < 0.0).count();
    let zero = d.len() - positive - negative;
    let n = positive + negative;
    let p_value = if n == 0 {
        1.0
    } else {
        // Symmetric null: both tails as far out as the observed count.
        (2.0 * binom_half_cdf(n, positive.min(negative))).min(1.0)
    };
    SignTest {
        positive,
        negative,
        zero,
        p_value,
    }
}

/// A paired comparison of a variant with the baseline on the same trials.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Paired {
    /// Pairs compared.
    pub pairs: usize,
    /// Median of `variant − baseline` over the pairs (zeros included).
    pub median_difference: f64,
    /// Matched-pairs rank-biserial correlation, −1 to 1 (0 when no
    /// difference is non-zero).
    pub rank_biserial: f64,
    /// Wilcoxon signed-rank test.
    pub wilcoxon: Wilcoxon,
    /// Sign test.
    pub sign: SignTest,
}

/// The paired comparison of `variant` with `baseline` (equal lengths, the
/// i-th of each from the same draw); `None` when there are no pairs.
#[must_use]
pub fn paired(variant: &[f64], baseline: &[f64]) -> Option<Paired> {
    let d: Vec<f64> = variant.iter().zip(baseline).map(|(a, b)| a - b).collect();
    let median_difference = median(&d)?;
    let wilcoxon = wilcoxon(&d);
    let sum = wilcoxon.r_plus + wilcoxon.r_minus;
    let rank_biserial = if sum > 0.0 {
        (wilcoxon.r_plus - wilcoxon.r_minus) / sum
    } else {
        0.0
    };
    Some(Paired {
        pairs: d.len(),
        median_difference,
        rank_biserial,
        wilcoxon,
        sign: sign_test(&d),
    })
}

/// The uncertainty of one (model, variant, fog) cell, flattened into its
/// row of the results: bootstrap intervals of the medians, the modes of the
/// right car's TTA, and the paired test of the right car's TTA against the
/// baseline variant of the same model and fog on the same trials.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct CellStats {
    /// Bootstrap resamples behind every interval of this row.
    pub bootstrap_resamples: usize,
    /// Right car's TTA: lower end of the 95 % interval of the median, s.
    pub tta_ci_lo_s: Option<f64>,
    /// Upper end, s.
    pub tta_ci_hi_s: Option<f64>,
    /// Modes of the right car's TTA (split at gaps > [`MODE_GAP_S`]).
    pub tta_mode_count: usize,
    /// The modes as `median:share` pairs separated by `;`, increasing
    /// TTA (median to 3 decimals in s, share to 3 decimals).
    pub tta_modes: String,
    /// Left car's LiDAR TTA: 95 % interval of the median, s.
    pub left_tta_ci_lo_s: Option<f64>,
    /// Upper end, s.
    pub left_tta_ci_hi_s: Option<f64>,
    /// Right car's hybrid TTA: 95 % interval of the median, s.
    pub hybrid_tta_ci_lo_s: Option<f64>,
    /// Upper end, s.
    pub hybrid_tta_ci_hi_s: Option<f64>,
    /// Accumulated RoI density: 95 % interval of the median, points/degree.
    pub density_ci_lo_pts_per_deg: Option<f64>,
    /// Upper end, points/degree.
    pub density_ci_hi_pts_per_deg: Option<f64>,
    /// Trials where both this variant and the baseline detected the right
    /// car (the pairs of the tests; 0 for the baseline itself or when the
    /// baseline was not run).
    pub vs_baseline_pairs: usize,
    /// Median of (this − baseline) TTA over the pairs, s (positive: earlier
    /// detection than the baseline).
    pub vs_baseline_median_diff_s: Option<f64>,
    /// Matched-pairs rank-biserial correlation of the differences.
    pub vs_baseline_rank_biserial: Option<f64>,
    /// Two-sided Wilcoxon signed-rank p-value.
    pub vs_baseline_wilcoxon_p: Option<f64>,
    /// How that p-value was computed.
    pub vs_baseline_wilcoxon_method: Option<WilcoxonMethod>,
    /// Two-sided exact sign-test p-value.
    pub vs_baseline_sign_p: Option<f64>,
    /// Accumulated RoI density against the baseline on the same trials
    /// (every trial pairs): median of (this − baseline), points/degree.
    pub density_vs_baseline_median_diff_pts_per_deg: Option<f64>,
    /// Matched-pairs rank-biserial correlation of the density differences.
    pub density_vs_baseline_rank_biserial: Option<f64>,
    /// Two-sided Wilcoxon signed-rank p-value of the density differences.
    pub density_vs_baseline_wilcoxon_p: Option<f64>,
    /// Two-sided exact sign-test p-value of the density differences.
    pub density_vs_baseline_sign_p: Option<f64>,
}

/// `median:share;…` of [`modes`].
#[must_use]
pub fn format_modes(modes: &[Mode]) -> String {
    modes
        .iter()
        .map(|m| format!("{:.3}:{:.3}", m.median, m.share))
        .collect::<Vec<_>>()
        .join(";")
}

/// Fills every row's [`CellStats`]. `records` are in the rows' order,
/// `trials` per row; `density[i]` is row i's accumulated density per trial.
/// The row whose variant is `baseline` with the same model and fog is the
/// reference of the paired test. Each interval's seed is [`derive_seed`] of
/// `seed` and the cell's `model/variant/fog/quantity`, so results do not
/// depend on the cells' order or the threads.
pub fn annotate(
    seed: u64,
    trials: usize,
    records: &[super::TrialRecord],
    density: &[Vec<f64>],
    rows: &mut [super::Row],
) {
    use rayon::prelude::*;
    let chunks: Vec<&[super::TrialRecord]> = records.chunks(trials.max(1)).collect();
    let baseline_of = |row: &super::Row| {
        rows.iter().position(|b| {
            b.model == row.model && b.fog_pct == row.fog_pct && b.variant == "baseline"
        })
    };
    let base: Vec<Option<usize>> = rows.iter().map(baseline_of).collect();
    let computed: Vec<CellStats> = rows
        .par_iter()
        .enumerate()
        .map(|(i, row)| {
            let chunk = chunks.get(i).copied().unwrap_or(&[]);
            let label = format!("{}/{}/{}", row.model.name(), row.variant, row.fog_pct);
            let ci = |values: &[f64], what: &str| {
                bootstrap_median(
                    values,
                    BOOTSTRAP_RESAMPLES,
                    derive_seed(seed, &format!("{label}/{what}")),
                )
            };
            let right: Vec<f64> = chunk.iter().filter_map(|r| r.outcome.tta_s[1]).collect();
            let left: Vec<f64> = chunk.iter().filter_map(|r| r.outcome.tta_s[0]).collect();
            let hybrid: Vec<f64> = chunk
                .iter()
                .filter_map(|r| r.outcome.hybrid_tta_s[1])
                .collect();
            let (t, l, h) = (
                ci(&right, "tta"),
                ci(&left, "left_tta"),
                ci(&hybrid, "hybrid"),
            );
            let d = density.get(i).and_then(|v| ci(v, "density"));
            let m = modes(&right, MODE_GAP_S);
            let mut out = CellStats {
                bootstrap_resamples: BOOTSTRAP_RESAMPLES,
                tta_ci_lo_s: t.map(|c| c.lo),
                tta_ci_hi_s: t.map(|c| c.hi),
                tta_mode_count: m.len(),
                tta_modes: format_modes(&m),
                left_tta_ci_lo_s: l.map(|c| c.lo),
                left_tta_ci_hi_s: l.map(|c| c.hi),
                hybrid_tta_ci_lo_s: h.map(|c| c.lo),
                hybrid_tta_ci_hi_s: h.map(|c| c.hi),
                density_ci_lo_pts_per_deg: d.map(|c| c.lo),
                density_ci_hi_pts_per_deg: d.map(|c| c.hi),
                ..CellStats::default()
            };
            if let Some(b) = base[i].filter(|&b| b != i) {
                let base_chunk = chunks.get(b).copied().unwrap_or(&[]);
                let (mut v, mut w) = (Vec::new(), Vec::new());
                for (x, y) in chunk.iter().zip(base_chunk) {
                    if x.trial != y.trial {
                        continue;
                    }
                    if let (Some(a), Some(c)) = (x.outcome.tta_s[1], y.outcome.tta_s[1]) {
                        v.push(a);
                        w.push(c);
                    }
                }
                if let Some(p) = paired(&v, &w) {
                    out.vs_baseline_pairs = p.pairs;
                    out.vs_baseline_median_diff_s = Some(p.median_difference);
                    out.vs_baseline_rank_biserial = Some(p.rank_biserial);
                    out.vs_baseline_wilcoxon_p = Some(p.wilcoxon.p_value);
                    out.vs_baseline_wilcoxon_method = Some(p.wilcoxon.method);
                    out.vs_baseline_sign_p = Some(p.sign.p_value);
                }
                // Density: every trial pairs with the baseline's same trial.
                let (mut v, mut w) = (Vec::new(), Vec::new());
                if let (Some(dv), Some(dw)) = (density.get(i), density.get(b)) {
                    for ((x, y), (a, c)) in chunk.iter().zip(base_chunk).zip(dv.iter().zip(dw)) {
                        if x.trial == y.trial {
                            v.push(*a);
                            w.push(*c);
                        }
                    }
                }
                if let Some(p) = paired(&v, &w) {
                    out.density_vs_baseline_median_diff_pts_per_deg = Some(p.median_difference);
                    out.density_vs_baseline_rank_biserial = Some(p.rank_biserial);
                    out.density_vs_baseline_wilcoxon_p = Some(p.wilcoxon.p_value);
                    out.density_vs_baseline_sign_p = Some(p.sign.p_value);
                }
            }
            out
        })
        .collect();
    for (row, s) in rows.iter_mut().zip(computed) {
        row.stats = s;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_and_percentile_follow_numpy() {
        assert_eq!(median(&[]), None);
        assert_eq!(median(&[3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&[4.0, 1.0, 3.0, 2.0]), Some(2.5));
        let s = [1.0, 2.0, 3.0, 4.0, 5.0];
        assert_eq!(percentile_sorted(&s, 2.5), Some(1.1));
        assert_eq!(percentile_sorted(&s, 100.0), Some(5.0));
    }

    #[test]
    fn bootstrap_is_seeded_and_brackets_the_median() {
        let v: Vec<f64> = (0..60).map(|i| f64::from((i * 37) % 61) * 0.3).collect();
        let a = bootstrap_median(&v, 500, 7).unwrap();
        assert_eq!(a, bootstrap_median(&v, 500, 7).unwrap());
        assert_ne!(bootstrap_medians(&v, 500, 7), bootstrap_medians(&v, 500, 8));
        assert!(a.lo <= a.median && a.median <= a.hi, "{a:?}");
        assert!(a.lo < a.hi);
        // A constant sample has a degenerate interval.
        let c = bootstrap_median(&[2.0; 9], 100, 1).unwrap();
        assert_eq!((c.lo, c.median, c.hi), (2.0, 2.0, 2.0));
    }

    /// The counting median equals the sorted median of the same resample
    /// (the plain reference: materialise the resample and sort it).
    #[test]
    fn counting_median_matches_sorting() {
        for n in [1usize, 2, 3, 10, 11, 57] {
            let v: Vec<f64> = (0..n).map(|i| ((i * 7919) % 23) as f64 * 0.1).collect();
            let mut sorted = v.clone();
            sorted.sort_by(f64::total_cmp);
            let mut rng = ChaCha8Rng::seed_from_u64(5);
            let mut want = Vec::new();
            for _ in 0..200 {
                let mut r: Vec<f64> = (0..n).map(|_| sorted[rng.random_range(0..n)]).collect();
                r.sort_by(f64::total_cmp);
                want.push(median_sorted(&r).unwrap());
            }
            want.sort_by(f64::total_cmp);
            assert_eq!(bootstrap_medians(&v, 200, 5), want, "n = {n}");
        }
    }

    #[test]
    fn derived_seeds_differ_by_label_and_seed() {
        assert_ne!(derive_seed(1, "a"), derive_seed(1, "b"));
        assert_ne!(derive_seed(1, "a"), derive_seed(2, "a"));
        assert_eq!(derive_seed(3, "cell"), derive_seed(3, "cell"));
    }

    #[test]
    fn modes_split_at_gaps() {
        let v = [4.6, 5.9, 4.58, 5.97, 4.64, 6.0];
        let m = modes(&v, MODE_GAP_S);
        assert_eq!(m.len(), 2);
        assert_eq!((m[0].count, m[1].count), (3, 3));
        assert_eq!(m[0].max, 4.64);
        assert_eq!(m[1].min, 5.9);
        assert!((m[0].share - 0.5).abs() < 1e-15);
        assert_eq!(modes(&[], 0.5), vec![]);
        assert_eq!(modes(&[1.0, 1.2, 1.4], 0.5).len(), 1);
    }

    #[test]
    fn exact_counts_are_the_subset_sums() {
        // n = 3: subsets of {1,2,3} sum to 0,1,2,3,3,4,5,6.
        assert_eq!(signed_rank_counts(3), vec![1, 1, 1, 2, 1, 1, 1]);
        let c = signed_rank_counts(20);
        assert_eq!(c.iter().sum::<u64>(), 1 << 20);
    }

    #[test]
    fn all_zero_differences_are_no_difference() {
        let w = wilcoxon(&[0.0; 5]);
        assert_eq!(w.method, WilcoxonMethod::NoDifference);
        assert_eq!(w.p_value, 1.0);
        let p = paired(&[1.0, 2.0], &[1.0, 2.0]).unwrap();
        assert_eq!(p.rank_biserial, 0.0);
        assert_eq!(p.sign.p_value, 1.0);
        assert_eq!(paired(&[], &[]), None);
    }

    #[test]
    fn all_positive_differences_give_full_effect() {
        let p = paired(&[2.0, 3.0, 5.0, 9.0], &[1.0, 1.0, 1.0, 1.0]).unwrap();
        assert_eq!(p.rank_biserial, 1.0);
        // Exact: only the subset of all ranks reaches R+ = 10 of 16.
        assert!((p.wilcoxon.p_value - 2.0 / 16.0).abs() < 1e-15);
        assert!((p.sign.p_value - 2.0 / 16.0).abs() < 1e-12);
        assert_eq!(p.median_difference, 3.0);
    }
}
