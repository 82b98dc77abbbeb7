//! Time along a profile: when the head reaches an azimuth, where it is at a
//! time, and the laser energy emitted up to an azimuth.
//!
//! Exact for the profile@1 semantics: within a bin the angular acceleration
//! is constant, so `ω(x)² = ω_s² + 2ax` and the time to advance `x` radians
//! is `2x / (ω_s + ω(x))` (stable also as `a → 0`).

use super::{Bin, Profile};
use crate::model::angle::{wrap_deg, FULL_TURN_DEG};

/// Time to advance `x_rad` into `bin` from its start.
#[must_use]
pub fn time_into_bin_s(bin: &Bin, x_rad: f64) -> f64 {
    if x_rad <= 0.0 {
        return 0.0;
    }
    let a = bin.spin_accel_rad_s2();
    let w_x = (bin.spin_start_rad_s.powi(2) + 2.0 * a * x_rad)
        .max(0.0)
        .sqrt();
    2.0 * x_rad / (bin.spin_start_rad_s + w_x)
}

/// Angle (rad) advanced `t_s` after entering `bin`: `x = ω_s t + a t²/2`.
#[must_use]
pub fn angle_into_bin_rad(bin: &Bin, t_s: f64) -> f64 {
    let a = bin.spin_accel_rad_s2();
    (bin.spin_start_rad_s * t_s + 0.5 * a * t_s * t_s).clamp(0.0, bin.width_deg.to_radians())
}

/// Cumulative time and energy at every bin start of a profile.
#[derive(Debug, Clone)]
pub struct Timeline<'a> {
    bins: &'a [Bin],
    /// `cum_time_s[i]` = time from 0° to the start of bin i; last entry = frame period.
    cum_time_s: Vec<f64>,
    /// Same for emitted energy, J.
    cum_energy_j: Vec<f64>,
}

impl<'a> Timeline<'a> {
    /// Builds the timeline of a structurally valid profile (bins cover the
    /// circle, spins positive; the checker guarantees this).
    #[must_use]
    pub fn new(profile: &'a Profile) -> Self {
        let n = profile.bins.len();
        let mut cum_time_s = Vec::with_capacity(n + 1);
        let mut cum_energy_j = Vec::with_capacity(n + 1);
        let (mut t, mut e) = (0.0, 0.0);
        cum_time_s.push(0.0);
        cum_energy_j.push(0.0);
        for b in &profile.bins {
            let dt = b.dwell_time_s();
            t += dt;
            e += dt * b.power_w;
            cum_time_s.push(t);
            cum_energy_j.push(e);
        }
        Self {
            bins: &profile.bins,
            cum_time_s,
            cum_energy_j,
        }
    }

    /// Frame period: the time of one revolution, s.
    #[must_use]
    pub fn period_s(&self) -> f64 {
        self.cum_time_s[self.bins.len()]
    }

    /// Energy emitted in one revolution, J.
    #[must_use]
    pub fn energy_per_turn_j(&self) -> f64 {
        self.cum_energy_j[self.bins.len()]
    }

    /// Bins of the profile.
    #[must_use]
    pub fn bins(&self) -> &'a [Bin] {
        self.bins
    }

    /// Index of the bin containing `azimuth_deg` in `[0, 360]` (360 → last bin).
    #[must_use]
    pub fn bin_index(&self, azimuth_deg: f64) -> usize {
        self.bins
            .partition_point(|b| b.start_deg <= azimuth_deg)
            .saturating_sub(1)
            .min(self.bins.len() - 1)
    }

    /// Time and energy from 0° to `azimuth_deg` in `[0, 360]`.
    #[must_use]
    pub fn time_energy_at(&self, azimuth_deg: f64) -> (f64, f64) {
        let i = self.bin_index(azimuth_deg);
        let b = &self.bins[i];
        let x = (azimuth_deg - b.start_deg)
            .clamp(0.0, b.width_deg)
            .to_radians();
        let dt = time_into_bin_s(b, x);
        (
            self.cum_time_s[i] + dt,
            self.cum_energy_j[i] + dt * b.power_w,
        )
    }

    /// Time and energy spent sweeping the arc `[lo, lo + width)` (wrapping), width ≤ 360.
    #[must_use]
    pub fn window(&self, lo_deg: f64, width_deg: f64) -> (f64, f64) {
        let lo = wrap_deg(lo_deg);
        let hi = lo + width_deg.min(FULL_TURN_DEG);
        let (t0, e0) = self.time_energy_at(lo);
        if hi <= FULL_TURN_DEG {
            let (t1, e1) = self.time_energy_at(hi);
            (t1 - t0, e1 - e0)
        } else {
            let (t1, e1) = self.time_energy_at(hi - FULL_TURN_DEG);
            (
                self.period_s() - t0 + t1,
                self.energy_per_turn_j() - e0 + e1,
            )
        }
    }

    /// Indices of the bins whose closed extent meets the closed arc
    /// `[lo, lo + width]` (wrapping), bins touched only at an edge included
    /// (up to [`EDGE_SNAP_DEG`](crate::model::angle::EDGE_SNAP_DEG)). A window
    /// that reaches a bin by any amount can receive its pulses, so the
    /// supremum over windows next to a bin edge includes that bin.
    pub fn bins_touching(&self, lo_deg: f64, width_deg: f64) -> Vec<usize> {
        let snap = crate::model::angle::EDGE_SNAP_DEG;
        let n = self.bins.len();
        let a = lo_deg - snap;
        let hi = lo_deg + width_deg + snap;
        let mut i = self.bin_index(wrap_deg(a));
        // Unwrapped start of bin i on the same turn as `a`.
        let mut pos = self.bins[i].start_deg + (a - wrap_deg(a));
        let mut out = Vec::new();
        for _ in 0..n {
            out.push(i);
            pos += self.bins[i].width_deg;
            if pos > hi {
                break;
            }
            i = crate::model::angle::next_index(i, n);
        }
        out
    }

    /// Highest bin power over the closed arc `[lo, lo + width]` (wrapping;
    /// see [`Self::bins_touching`]), W.
    #[must_use]
    pub fn max_power_in(&self, lo_deg: f64, width_deg: f64) -> f64 {
        self.bins_touching(lo_deg, width_deg)
            .into_iter()
            .map(|i| self.bins[i].power_w)
            .fold(0.0, f64::max)
    }

    /// Azimuth (degrees, `[0, 360)`) and bin index at `t_s` after the head passed 0°,
    /// for `t_s` in `[0, period)`.
    #[must_use]
    pub fn azimuth_at(&self, t_s: f64) -> (f64, usize) {
        let n = self.bins.len();
        let i = self
            .cum_time_s
            .partition_point(|&c| c <= t_s)
            .saturating_sub(1)
            .min(n - 1);
        self.azimuth_in_bin(t_s, i)
    }

    /// As [`Self::azimuth_at`], searching forward from bin `hint` (the bin of
    /// an earlier time in the same turn): the same bin, found in amortised
    /// constant time for increasing times.
    #[must_use]
    pub fn azimuth_at_from(&self, t_s: f64, hint: usize) -> (f64, usize) {
        let n = self.bins.len();
        let mut i = hint.min(n - 1);
        if self.cum_time_s[i] > t_s {
            return self.azimuth_at(t_s);
        }
        while i + 1 < n && self.cum_time_s[i + 1] <= t_s {
            i += 1;
        }
        self.azimuth_in_bin(t_s, i)
    }

    fn azimuth_in_bin(&self, t_s: f64, i: usize) -> (f64, usize) {
        let b = &self.bins[i];
        let x = angle_into_bin_rad(b, t_s - self.cum_time_s[i]);
        (wrap_deg(b.start_deg + x.to_degrees()), i)
    }
}
