//! Angles, circular intervals and the binning of the full turn.
//!
//! This module is the **only** place in the crate that wraps angles or does
//! arithmetic on circular intervals; everything else calls it. Azimuths are in
//! degrees, in the vehicle frame (ISO 8855: x forward, y left, z up), measured
//! counter-clockwise from straight ahead, in `[0, 360)`.
//!
//! A [`CircularSet`] is a finite union of half-open arcs `[start, end)`. It is
//! stored as sorted, disjoint, non-touching linear segments inside `[0, 360]`,
//! so an arc that wraps through 0° is two segments `[a, 360)` and `[0, b)`;
//! [`CircularSet::arcs`] joins them again. No tolerance is applied to the
//! set operations: they are exact on the `f64` values given.

use serde::{Deserialize, Serialize};
use thiserror::Error;

/// One full turn in degrees.
pub const FULL_TURN_DEG: f64 = 360.0;

/// Two bin edges closer than this (degrees) are treated as one edge when a
/// region boundary is inserted into a uniform grid (the boundary wins).
pub const EDGE_SNAP_DEG: f64 = 1e-9;

/// Smallest and largest number of bins a [`Binning`] may have.
pub const MIN_BINS: usize = 4;
/// See [`MIN_BINS`].
pub const MAX_BINS: usize = 36_000;

/// Errors from angle and binning constructors.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum AngleError {
    /// An angle argument was NaN or infinite.
    #[error("{what} must be a finite angle in degrees, got {}", crate::text::Num(*.value))]
    NotFinite {
        /// Which argument.
        what: &'static str,
        /// The value given.
        value: f64,
    },
    /// An arc width outside `[0, 360]`.
    #[error("arc width_deg must lie in [0, 360], got {}", crate::text::Num(*.0))]
    BadWidth(f64),
    /// A bin count outside [`MIN_BINS`]..=[`MAX_BINS`].
    #[error("bin count must lie in [{MIN_BINS}, {MAX_BINS}], got {0}")]
    BadBinCount(usize),
}

/// Wraps an angle into `[0, 360)`. NaN and infinities propagate as NaN.
#[must_use]
pub fn wrap_deg(angle_deg: f64) -> f64 {
    // Fast paths, bit-identical to `rem_euclid` (whose `%` is exact, and
    // `x − 360` is exact for x in [360, 720) by Sterbenz's lemma) but at
    // −360 (+0 here, −0 there): the hot loops of the simulator call this per
    // pulse, and the eye-safety bound per cut.
    if (0.0..FULL_TURN_DEG).contains(&angle_deg) {
        return angle_deg;
    }
    if (-FULL_TURN_DEG..0.0).contains(&angle_deg) {
        let w = angle_deg + FULL_TURN_DEG;
        return if w >= FULL_TURN_DEG { 0.0 } else { w };
    }
    if (FULL_TURN_DEG..2.0 * FULL_TURN_DEG).contains(&angle_deg) {
        return angle_deg - FULL_TURN_DEG;
    }
    let w = angle_deg.rem_euclid(FULL_TURN_DEG);
    // rem_euclid can return exactly 360.0 for tiny negative inputs (rounding).
    if w >= FULL_TURN_DEG {
        0.0
    } else {
        w
    }
}

/// Wraps an angle into `(-180, 180]` (signed eccentricity / difference).
#[must_use]
pub fn wrap_signed_deg(angle_deg: f64) -> f64 {
    let w = wrap_deg(angle_deg);
    if w > 180.0 {
        w - FULL_TURN_DEG
    } else {
        w
    }
}

/// Signed angular difference `a − b` wrapped into `(-180, 180]`.
#[must_use]
pub fn diff_deg(a_deg: f64, b_deg: f64) -> f64 {
    wrap_signed_deg(a_deg - b_deg)
}

pub use super::index::{next_index, prev_index, rotate_index};

/// A circular arc `[start_deg, start_deg + width_deg)` modulo 360.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Arc {
    /// Start azimuth, in `[0, 360)`.
    pub start_deg: f64,
    /// Angular width, in `[0, 360]`.
    pub width_deg: f64,
}

impl Arc {
    /// An arc starting at `start_deg` (wrapped) of `width_deg`.
    pub fn new(start_deg: f64, width_deg: f64) -> Result<Self, AngleError> {
        if !start_deg.is_finite() {
            return Err(AngleError::NotFinite {
                what: "start_deg",
                value: start_deg,
            });
        }
        if !(0.0..=FULL_TURN_DEG).contains(&width_deg) {
            return Err(AngleError::BadWidth(width_deg));
        }
        Ok(Self {
            start_deg: wrap_deg(start_deg),
            width_deg,
        })
    }

    /// The arc of `width_deg` centred on `center_deg`.
    pub fn centered(center_deg: f64, width_deg: f64) -> Result<Self, AngleError> {
        if !center_deg.is_finite() {
            return Err(AngleError::NotFinite {
                what: "center_deg",
                value: center_deg,
            });
        }
        Self::new(center_deg - width_deg / 2.0, width_deg)
    }

    /// End azimuth, wrapped into `[0, 360)`.
    #[must_use]
    pub fn end_deg(&self) -> f64 {
        wrap_deg(self.start_deg + self.width_deg)
    }

    /// Whether `azimuth_deg` (any real) lies in the half-open arc.
    #[must_use]
    pub fn contains(&self, azimuth_deg: f64) -> bool {
        if self.width_deg >= FULL_TURN_DEG {
            return azimuth_deg.is_finite();
        }
        let off = wrap_deg(azimuth_deg - self.start_deg);
        off < self.width_deg
    }

    /// The arc as one or two linear segments inside `[0, 360]`.
    fn segments(&self) -> impl Iterator<Item = (f64, f64)> {
        let full = self.width_deg >= FULL_TURN_DEG;
        let end = self.start_deg + self.width_deg;
        let (a, b) = if full {
            ((0.0, FULL_TURN_DEG), None)
        } else if end <= FULL_TURN_DEG {
            ((self.start_deg, end), None)
        } else {
            (
                (self.start_deg, FULL_TURN_DEG),
                Some((0.0, end - FULL_TURN_DEG)),
            )
        };
        std::iter::once(a).chain(b).filter(|(lo, hi)| hi > lo)
    }
}

/// A finite union of half-open circular arcs. See the module docs.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct CircularSet {
    /// Sorted, disjoint, non-touching `[lo, hi)` with `0 <= lo < hi <= 360`.
    segments: Vec<(f64, f64)>,
}

impl CircularSet {
    /// The empty set.
    #[must_use]
    pub fn empty() -> Self {
        Self::default()
    }

    /// The whole circle.
    #[must_use]
    pub fn full() -> Self {
        Self {
            segments: vec![(0.0, FULL_TURN_DEG)],
        }
    }

    /// The union of `arcs`.
    pub fn from_arcs<I: IntoIterator<Item = Arc>>(arcs: I) -> Self {
        Self::from_segments(arcs.into_iter().flat_map(|a| a.segments()).collect())
    }

    /// Builds from linear segments `[lo, hi)` in `[0, 360]` (any order, may overlap).
    fn from_segments(mut segs: Vec<(f64, f64)>) -> Self {
        segs.retain(|(lo, hi)| hi > lo);
        segs.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut merged: Vec<(f64, f64)> = Vec::with_capacity(segs.len());
        for (lo, hi) in segs {
            match merged.last_mut() {
                Some(last) if lo <= last.1 => last.1 = last.1.max(hi),
                _ => merged.push((lo, hi)),
            }
        }
        Self { segments: merged }
    }

    /// Union of two sets.
    #[must_use]
    pub fn union(&self, other: &Self) -> Self {
        let mut segs = self.segments.clone();
        segs.extend_from_slice(&other.segments);
        Self::from_segments(segs)
    }

    /// Complement in `[0, 360)`.
    #[must_use]
    pub fn complement(&self) -> Self {
        let mut out = Vec::with_capacity(self.segments.len() + 1);
        let mut cursor = 0.0;
        for &(lo, hi) in &self.segments {
            if lo > cursor {
                out.push((cursor, lo));
            }
            cursor = hi;
        }
        if cursor < FULL_TURN_DEG {
            out.push((cursor, FULL_TURN_DEG));
        }
        Self { segments: out }
    }

    /// Total angular measure in degrees.
    #[must_use]
    pub fn measure_deg(&self) -> f64 {
        self.segments.iter().map(|(lo, hi)| hi - lo).sum()
    }

    /// Whether the set is empty.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.segments.is_empty()
    }

    /// Whether `azimuth_deg` (wrapped) is in the set.
    #[must_use]
    pub fn contains(&self, azimuth_deg: f64) -> bool {
        if !azimuth_deg.is_finite() {
            return false;
        }
        let a = wrap_deg(azimuth_deg);
        // Segments are sorted by lo: find the last one starting at or before a.
        let idx = self.segments.partition_point(|(lo, _)| *lo <= a);
        idx > 0 && a < self.segments[idx - 1].1
    }

    /// Measure (degrees) of the intersection with the linear range `[lo, hi)`, `0 <= lo <= hi <= 360`.
    #[must_use]
    pub fn overlap_deg(&self, lo: f64, hi: f64) -> f64 {
        self.segments
            .iter()
            .map(|&(a, b)| (b.min(hi) - a.max(lo)).max(0.0))
            .sum()
    }

    /// The set as maximal circular arcs; an arc through 0° is returned whole.
    #[must_use]
    pub fn arcs(&self) -> Vec<Arc> {
        let mut segs = self.segments.clone();
        if segs.len() >= 2 {
            let first = segs[0];
            let last = segs[segs.len() - 1];
            if first.0 == 0.0 && last.1 == FULL_TURN_DEG {
                segs.remove(0);
                let n = segs.len();
                segs[n - 1].1 = FULL_TURN_DEG + first.1;
            }
        }
        segs.into_iter()
            .map(|(lo, hi)| Arc {
                start_deg: lo,
                width_deg: hi - lo,
            })
            .collect()
    }

    /// Azimuths in `[0, 360)` where membership changes (arc starts and ends).
    #[must_use]
    pub fn boundaries_deg(&self) -> Vec<f64> {
        let mut b: Vec<f64> = self
            .arcs()
            .iter()
            .filter(|a| a.width_deg < FULL_TURN_DEG)
            .flat_map(|a| [a.start_deg, a.end_deg()])
            .collect();
        b.sort_by(f64::total_cmp);
        b.dedup();
        b
    }
}

/// A partition of `[0, 360)` into contiguous bins, in azimuth order, the
/// first starting at 0°. Bin `i` is `[edge_i, edge_{i+1})`, the last ends at 360°.
#[derive(Debug, Clone, PartialEq)]
pub struct Binning {
    edges_deg: Vec<f64>,
}

impl Binning {
    /// `n` equal bins (any `n` in [`MIN_BINS`]..=[`MAX_BINS`], not only divisors of 360).
    pub fn uniform(n: usize) -> Result<Self, AngleError> {
        if !(MIN_BINS..=MAX_BINS).contains(&n) {
            return Err(AngleError::BadBinCount(n));
        }
        let nf = n as f64;
        Ok(Self {
            edges_deg: (0..n).map(|i| (i as f64) * FULL_TURN_DEG / nf).collect(),
        })
    }

    /// `n` equal bins with extra edges at `breaks_deg` (wrapped), so that a
    /// region boundary is always a bin edge. A break within [`EDGE_SNAP_DEG`]
    /// of an existing edge replaces it; the result has between `n` and
    /// `n + breaks.len()` bins.
    pub fn uniform_with_breaks(n: usize, breaks_deg: &[f64]) -> Result<Self, AngleError> {
        let mut b = Self::uniform(n)?;
        for &raw in breaks_deg {
            if !raw.is_finite() {
                return Err(AngleError::NotFinite {
                    what: "break_deg",
                    value: raw,
                });
            }
            let x = wrap_deg(raw);
            let idx = b.edges_deg.partition_point(|&e| e < x);
            let near = |j: usize| {
                b.edges_deg
                    .get(j)
                    .is_some_and(|&e| (e - x).abs() <= EDGE_SNAP_DEG)
            };
            if idx < b.edges_deg.len() && near(idx) {
                if idx != 0 {
                    b.edges_deg[idx] = x;
                }
            } else if idx > 0 && near(idx - 1) {
                if idx - 1 != 0 {
                    b.edges_deg[idx - 1] = x;
                }
            } else if FULL_TURN_DEG - x <= EDGE_SNAP_DEG {
                // Snaps onto 360° == 0°, already an edge.
            } else {
                b.edges_deg.insert(idx, x);
            }
        }
        Ok(b)
    }

    /// Builds from explicit bin starts (must start at 0 and increase strictly below 360).
    #[must_use]
    pub fn from_starts(starts_deg: Vec<f64>) -> Option<Self> {
        let ok = starts_deg.first() == Some(&0.0)
            && starts_deg.windows(2).all(|w| w[1] > w[0])
            && starts_deg.last().is_some_and(|&l| l < FULL_TURN_DEG);
        ok.then_some(Self {
            edges_deg: starts_deg,
        })
    }

    /// Number of bins.
    #[must_use]
    pub fn len(&self) -> usize {
        self.edges_deg.len()
    }

    /// Always false: a binning has at least one bin.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.edges_deg.is_empty()
    }

    /// Start azimuth of bin `i`.
    #[must_use]
    pub fn start_deg(&self, i: usize) -> f64 {
        self.edges_deg[i]
    }

    /// End azimuth of bin `i` (360 for the last bin).
    #[must_use]
    pub fn end_deg(&self, i: usize) -> f64 {
        self.edges_deg.get(i + 1).copied().unwrap_or(FULL_TURN_DEG)
    }

    /// Width of bin `i` in degrees.
    #[must_use]
    pub fn width_deg(&self, i: usize) -> f64 {
        self.end_deg(i) - self.start_deg(i)
    }

    /// Centre azimuth of bin `i`.
    #[must_use]
    pub fn center_deg(&self, i: usize) -> f64 {
        0.5 * (self.start_deg(i) + self.end_deg(i))
    }

    /// Index of the bin containing `azimuth_deg` (wrapped).
    #[must_use]
    pub fn bin_of(&self, azimuth_deg: f64) -> usize {
        let a = wrap_deg(azimuth_deg);
        self.edges_deg
            .partition_point(|&e| e <= a)
            .saturating_sub(1)
    }

    /// Bin start azimuths.
    #[must_use]
    pub fn starts_deg(&self) -> &[f64] {
        &self.edges_deg
    }
}

#[cfg(test)]
mod tests;

#[cfg(any(kani, test))]
mod verification {
    use super::*;
    use crate::verification::{cover, for_all};

    /// REQ-IDX-1: cyclic neighbours stay in bounds for every bin count and index.
    #[cfg_attr(kani, kani::proof)]
    #[cfg_attr(not(kani), test)]
    fn neighbours_in_bounds() {
        for_all!((usize, usize, bool), |(i, n, last)| {
            let n = n.max(1);
            // `last` steers random testing to the wrap-around edge.
            let i = if last { n - 1 } else { i % n };
            cover!(n > 1 && i == n - 1, "last bin wraps to the first");
            let (nx, pv) = (next_index(i, n), prev_index(i, n));
            assert!(nx < n && pv < n);
            assert_eq!(prev_index(nx, n), i);
            assert_eq!(next_index(pv, n), i);
        });
        #[cfg(not(kani))]
        crate::verification::assert_covered(&["last bin wraps to the first"]);
    }

    /// REQ-IDX-1: rotating an index never overflows, stays in bounds and
    /// equals modular addition, for any shift (a gaze index of any size).
    #[cfg_attr(kani, kani::proof)]
    #[cfg_attr(not(kani), test)]
    fn rotate_in_bounds_and_modular() {
        for_all!((usize, usize, usize), |(i, shift, n)| {
            let n = n.max(1);
            let i = i % n;
            let r = rotate_index(i, shift, n);
            cover!(shift > usize::MAX - n, "shift near usize::MAX");
            assert!(r < n);
            let expected = ((i as u128 + shift as u128) % n as u128) as usize;
            assert_eq!(r, expected);
        });
        #[cfg(not(kani))]
        crate::verification::assert_covered(&["shift near usize::MAX"]);
    }

    /// REQ-IDX-1: rotating by `s` then by `n − s mod n` is the identity (the
    /// fast path's rotated profile maps back onto the original bins).
    #[cfg_attr(kani, kani::proof)]
    #[cfg_attr(not(kani), test)]
    fn rotate_inverse() {
        for_all!((usize, usize, usize), |(i, shift, n)| {
            let n = n.max(1);
            let i = i % n;
            let back = n - shift % n;
            cover!(shift % n != 0, "non-trivial rotation");
            assert_eq!(rotate_index(rotate_index(i, shift, n), back, n), i);
        });
        #[cfg(not(kani))]
        crate::verification::assert_covered(&["non-trivial rotation"]);
    }
}
