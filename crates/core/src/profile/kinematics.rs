//! Time along a profile: when the head reaches an azimuth, where it is at a
//! time, and the laser energy emitted up to an azimuth.
//!
//! Exact for the profile@1 semantics: within a bin the angular acceleration
//! is constant, so `ω(x)² = ω_s² + 2ax` and the time to advance `x` radians
//! is `2x / (ω_s + ω(x))` (stable also as `a → 0`).
//!
//! This is the one model of the head's motion: the planner, the simulator and
//! the eye-safety bound ([`crate::eye_safety::bound`], through
//! [`Timeline::time_at_unwrapped_s`] and [`Timeline::azimuth_at_unwrapped_deg`])
//! all call it.

use super::{Bin, Profile};
use crate::model::angle::{wrap_deg, FULL_TURN_DEG};

/// A bin as the head sweeps it: an arc of the circle run at constant angular
/// acceleration from `spin_start_rad_s` to `spin_end_rad_s`, at one power.
/// Implemented by profile bins and by the eye-safety bound's segments (a
/// firmware table as it runs), so both share the kinematics below.
pub trait BinMotion {
    /// Start azimuth, deg.
    fn start_deg(&self) -> f64;
    /// Angular width, deg.
    fn width_deg(&self) -> f64;
    /// Spin at the start, rad/s.
    fn spin_start_rad_s(&self) -> f64;
    /// Spin at the end, rad/s.
    fn spin_end_rad_s(&self) -> f64;
    /// Laser power while sweeping the bin, W.
    fn power_w(&self) -> f64;

    /// Dwell time `t = 2Δθ / (ω_start + ω_end)` (constant acceleration), s.
    fn dwell_s(&self) -> f64 {
        2.0 * self.width_deg().to_radians() / (self.spin_start_rad_s() + self.spin_end_rad_s())
    }

    /// Angular acceleration `a = (ω_end² − ω_start²) / (2Δθ)`, rad/s².
    fn accel_rad_s2(&self) -> f64 {
        (self.spin_end_rad_s().powi(2) - self.spin_start_rad_s().powi(2))
            / (2.0 * self.width_deg().to_radians())
    }

    /// Spin `x_rad` into the bin, rad/s: `ω(x) = √(ω_s² + 2ax)` ([`spin_sq`],
    /// the same law as [`Self::time_into_s`]), with `x` clamped to `[0, width]`.
    fn spin_into_rad_s(&self, x_rad: f64) -> f64 {
        let x = x_rad.clamp(0.0, self.width_deg().to_radians());
        spin_sq(self.spin_start_rad_s(), 2.0 * self.accel_rad_s2(), x)
            .max(0.0)
            .sqrt()
    }

    /// `ω²` along the bin as a line in the angle from its start in
    /// degrees, `(c₀, c₁)` with `ω²(x) = c₀ + c₁·x`: [`spin_sq`] at 0 and
    /// its slope `2a` per radian, per degree. The eye-safety bound's curved
    /// cells solve for their stationary points with it.
    fn spin_sq_line_deg(&self) -> (f64, f64) {
        let two_a = 2.0 * self.accel_rad_s2();
        (
            spin_sq(self.spin_start_rad_s(), two_a, 0.0),
            two_a * core::f64::consts::PI / 180.0,
        )
    }

    /// Time to advance `x_rad` into the bin from its start, s
    /// (`2x / (ω_s + ω(x))`; 0 for `x ≤ 0`).
    fn time_into_s(&self, x_rad: f64) -> f64 {
        time_into_s(self.spin_start_rad_s(), 2.0 * self.accel_rad_s2(), x_rad)
    }

    /// Angle advanced `t_s` after entering the bin, rad: `x = ω_s t + a t²/2`
    /// with `t` clamped to the dwell, so the result lies in `[0, width]`.
    fn angle_into_rad(&self, t_s: f64) -> f64 {
        angle_into_rad(
            self.spin_start_rad_s(),
            self.accel_rad_s2(),
            self.dwell_s(),
            self.width_deg(),
            t_s,
        )
    }
}

impl BinMotion for Bin {
    fn start_deg(&self) -> f64 {
        self.start_deg
    }
    fn width_deg(&self) -> f64 {
        self.width_deg
    }
    fn spin_start_rad_s(&self) -> f64 {
        self.spin_start_rad_s
    }
    fn spin_end_rad_s(&self) -> f64 {
        self.spin_end_rad_s
    }
    fn power_w(&self) -> f64 {
        self.power_w
    }
}

/// A bin's constants for [`BinMotion::time_into_s`] and
/// [`BinMotion::angle_into_rad`], computed once per timeline with the same
/// operations those compute per call: the spin at its start, the
/// acceleration `a`, the dwell, and, when `a = 0`, the denominator
/// `ω_s + √(ω_s²)` (the value the general formula computes for every `x`,
/// since `ω_s² + 0·x = ω_s²`), which saves the square root.
#[derive(Debug, Clone, Copy)]
struct Motion {
    w_s: f64,
    accel: f64,
    dwell_s: f64,
    /// `ω_s + √(max(ω_s², 0))` if `2a = 0`, else NaN.
    den_const: f64,
}

impl Motion {
    fn of<B: BinMotion + ?Sized>(b: &B) -> Self {
        let w_s = b.spin_start_rad_s();
        let accel = b.accel_rad_s2();
        let den_const = if 2.0 * accel == 0.0 {
            w_s + w_s.powi(2).max(0.0).sqrt()
        } else {
            f64::NAN
        };
        Self {
            w_s,
            accel,
            dwell_s: b.dwell_s(),
            den_const,
        }
    }

    /// Time to advance `x_rad` into the bin: `2x / (ω_s + ω(x))`,
    /// `ω(x) = √(ω_s² + 2ax)`; 0 for `x ≤ 0`.
    #[inline]
    fn time_into_s(&self, x_rad: f64) -> f64 {
        if x_rad <= 0.0 {
            return 0.0;
        }
        let two_a = 2.0 * self.accel;
        if two_a == 0.0 && x_rad < f64::INFINITY {
            return 2.0 * x_rad / self.den_const;
        }
        time_into_s(self.w_s, two_a, x_rad)
    }

    /// Angle advanced `t_s` after entering the bin (of `width_deg`), rad:
    /// `x = ω_s t + a t²/2` with `t` clamped to the dwell.
    #[inline]
    fn angle_into_rad(&self, t_s: f64, width_deg: f64) -> f64 {
        angle_into_rad(self.w_s, self.accel, self.dwell_s, width_deg, t_s)
    }
}

/// `ω²` at `x_rad` into a bin entered at `w_s` rad/s with angular
/// acceleration `two_a / 2`: `ω_s² + 2a·x` (constant acceleration). The one
/// statement of this line ([`BinMotion::spin_sq_line_deg`] is it per degree).
#[inline]
#[must_use]
pub fn spin_sq(w_s: f64, two_a: f64, x_rad: f64) -> f64 {
    w_s.powi(2) + two_a * x_rad
}

/// [`BinMotion::time_into_s`] from the spin at the start and `2a`.
#[inline]
fn time_into_s(w_s: f64, two_a: f64, x_rad: f64) -> f64 {
    if x_rad <= 0.0 {
        return 0.0;
    }
    let w_x = spin_sq(w_s, two_a, x_rad).max(0.0).sqrt();
    2.0 * x_rad / (w_s + w_x)
}

/// [`BinMotion::angle_into_rad`] from the bin's constants.
#[inline]
fn angle_into_rad(w_s: f64, accel: f64, dwell_s: f64, width_deg: f64, t_s: f64) -> f64 {
    let t = t_s.clamp(0.0, dwell_s);
    (w_s * t + 0.5 * accel * t * t).clamp(0.0, width_deg.to_radians())
}

/// `x` split into whole periods and the rest: `(k, x − k·period)` with
/// `k = ⌊x/period⌋` (an unwrapped time into frame periods, an unwrapped
/// azimuth into turns). The one split into periods: the timeline, and the
/// eye-safety bound's envelope, call it.
#[inline]
#[must_use]
pub fn split_periods(x: f64, period: f64) -> (f64, f64) {
    if (0.0..period).contains(&x) {
        // The common case, without a call to `floor` (same result).
        return (0.0, x);
    }
    let k = (x / period).floor();
    (k, x - k * period)
}

/// Time to advance `x_rad` into `bin` from its start.
#[must_use]
pub fn time_into_bin_s(bin: &Bin, x_rad: f64) -> f64 {
    bin.time_into_s(x_rad)
}

/// Angle (rad) advanced `t_s` after entering `bin`: `x = ω_s t + a t²/2`.
#[must_use]
pub fn angle_into_bin_rad(bin: &Bin, t_s: f64) -> f64 {
    bin.angle_into_rad(t_s)
}

/// A running sum with Neumaier's compensation (Higham, *Accuracy and
/// Stability of Numerical Algorithms*, 2nd ed., §4.3): for `n` terms of one
/// sign the value is within `2u·|S| + O(n·u²)·|S|` of the exact sum `S`
/// (`u = 2⁻⁵³`), independent of `n` to first order, where a plain running
/// sum is only within `(n − 1)·u·|S|`. The timeline's cumulative times
/// use it, so a time from 0° is within a few `u·T_f` of the exact one
/// whatever the number of bins: the bound's time-rounding slack
/// (`eye_safety::bound::count::time_rounding_s`) relies on it.
#[derive(Debug, Clone, Copy, Default)]
pub struct Compensated {
    sum: f64,
    comp: f64,
}

impl Compensated {
    /// Adds `x`.
    #[inline]
    pub fn add(&mut self, x: f64) {
        let s = self.sum + x;
        self.comp += if self.sum.abs() >= x.abs() {
            (self.sum - s) + x
        } else {
            (x - s) + self.sum
        };
        self.sum = s;
    }

    /// The compensated sum so far.
    #[inline]
    #[must_use]
    pub fn value(&self) -> f64 {
        self.sum + self.comp
    }
}

/// Cumulative time and energy at every bin start of a profile (or of any
/// bins that cover the circle in order, see [`Timeline::from_bins`]).
#[derive(Debug, Clone)]
pub struct Timeline<'a, B = Bin> {
    bins: &'a [B],
    /// `cum_time_s[i]` = time from 0° to the start of bin i; last entry = frame period.
    cum_time_s: Vec<f64>,
    /// Same for emitted energy, J.
    cum_energy_j: Vec<f64>,
    /// Each bin's [`Motion`].
    motion: Vec<Motion>,
}

impl<'a> Timeline<'a, Bin> {
    /// Builds the timeline of a structurally valid profile (bins cover the
    /// circle, spins positive; the checker guarantees this).
    #[must_use]
    pub fn new(profile: &'a Profile) -> Self {
        Self::from_bins(&profile.bins)
    }
}

impl<'a, B: BinMotion> Timeline<'a, B> {
    /// Builds the timeline of bins that cover `[0, 360)` in order with
    /// positive spins (at least one bin).
    #[must_use]
    pub fn from_bins(bins: &'a [B]) -> Self {
        let n = bins.len();
        let mut cum_time_s = Vec::with_capacity(n + 1);
        let mut cum_energy_j = Vec::with_capacity(n + 1);
        let mut motion = Vec::with_capacity(n);
        let (mut t, mut e) = (Compensated::default(), Compensated::default());
        cum_time_s.push(0.0);
        cum_energy_j.push(0.0);
        for b in bins {
            let m = Motion::of(b);
            let dt = m.dwell_s;
            t.add(dt);
            e.add(dt * b.power_w());
            cum_time_s.push(t.value());
            cum_energy_j.push(e.value());
            motion.push(m);
        }
        Self {
            bins,
            cum_time_s,
            cum_energy_j,
            motion,
        }
    }

    /// Time from 0° to the start of bin `i` (`i = len` gives the period), s.
    #[must_use]
    pub fn bin_start_time_s(&self, i: usize) -> f64 {
        self.cum_time_s[i]
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
    pub fn bins(&self) -> &'a [B] {
        self.bins
    }

    /// Index of the bin containing `azimuth_deg` in `[0, 360]` (360 → last bin).
    #[must_use]
    pub fn bin_index(&self, azimuth_deg: f64) -> usize {
        self.bins
            .partition_point(|b| b.start_deg() <= azimuth_deg)
            .saturating_sub(1)
            .min(self.bins.len() - 1)
    }

    /// Time and energy from 0° to `azimuth_deg` in `[0, 360]`.
    #[must_use]
    pub fn time_energy_at(&self, azimuth_deg: f64) -> (f64, f64) {
        let i = self.bin_index(azimuth_deg);
        let b = &self.bins[i];
        let x = (azimuth_deg - b.start_deg())
            .clamp(0.0, b.width_deg())
            .to_radians();
        let dt = self.motion[i].time_into_s(x);
        (
            self.cum_time_s[i] + dt,
            self.cum_energy_j[i] + dt * b.power_w(),
        )
    }

    /// Splits an unwrapped azimuth into (whole turns, bin, offset into that
    /// bin in deg).
    #[must_use]
    pub fn locate_unwrapped(&self, theta_deg: f64) -> (f64, usize, f64) {
        let (k, a) = split_periods(theta_deg, FULL_TURN_DEG);
        let i = self.bin_index(a);
        (k, i, a - self.bins[i].start_deg())
    }

    /// As [`Self::locate_unwrapped`], searching forward from bin `*hint`
    /// (then set to the bin found): the same result, in amortised constant
    /// time for a nondecreasing sequence of azimuths.
    #[inline]
    pub fn locate_unwrapped_from(&self, theta_deg: f64, hint: &mut usize) -> (f64, usize, f64) {
        let (k, a) = split_periods(theta_deg, FULL_TURN_DEG);
        let n = self.bins.len();
        let mut i = (*hint).min(n - 1);
        if self.bins[i].start_deg() > a {
            i = self.bin_index(a);
        } else {
            // The last bin starting at or before `a`, as `bin_index` finds it.
            while i + 1 < n && self.bins[i + 1].start_deg() <= a {
                i += 1;
            }
        }
        *hint = i;
        (k, i, a - self.bins[i].start_deg())
    }

    /// Unwrapped time at which the head reaches the unwrapped azimuth
    /// `theta_deg` (turn `k` of the periodic motion starts at `k·T_f`), s.
    #[must_use]
    pub fn time_at_unwrapped_s(&self, theta_deg: f64) -> f64 {
        self.time_at_located(self.locate_unwrapped(theta_deg))
    }

    /// As [`Self::time_at_unwrapped_s`] with a forward search from `*hint`
    /// (see [`Self::locate_unwrapped_from`]): the same value.
    #[inline]
    pub fn time_at_unwrapped_from_s(&self, theta_deg: f64, hint: &mut usize) -> f64 {
        self.time_at_located(self.locate_unwrapped_from(theta_deg, hint))
    }

    /// The unwrapped time at an azimuth located by
    /// [`Self::locate_unwrapped`] (or [`Self::locate_unwrapped_from`]):
    /// `time_at_located(locate_unwrapped(θ))` is
    /// [`Self::time_at_unwrapped_s`]`(θ)`, for a caller that needs both.
    #[inline]
    #[must_use]
    pub fn time_at_located(&self, (k, i, x_deg): (f64, usize, f64)) -> f64 {
        let b = &self.bins[i];
        k * self.period_s()
            + self.cum_time_s[i]
            + self.motion[i].time_into_s(x_deg.clamp(0.0, b.width_deg()).to_radians())
    }

    /// Unwrapped azimuth at unwrapped time `t_s`, deg.
    #[must_use]
    pub fn azimuth_at_unwrapped_deg(&self, t_s: f64) -> f64 {
        let (k, t) = split_periods(t_s, self.period_s());
        self.azimuth_at_located(k, t, self.bin_at_time(t))
    }

    /// As [`Self::azimuth_at_unwrapped_deg`], searching forward from bin
    /// `*hint` (then set to the bin found): the same value, in amortised
    /// constant time for a nondecreasing sequence of times.
    pub fn azimuth_at_unwrapped_from_deg(&self, t_s: f64, hint: &mut usize) -> f64 {
        let (k, t) = split_periods(t_s, self.period_s());
        let n = self.bins.len();
        let mut i = (*hint).min(n - 1);
        if self.cum_time_s[i] > t {
            i = self.bin_at_time(t);
        } else {
            while i + 1 < n && self.cum_time_s[i + 1] <= t {
                i += 1;
            }
        }
        *hint = i;
        self.azimuth_at_located(k, t, i)
    }

    fn azimuth_at_located(&self, k: f64, t: f64, i: usize) -> f64 {
        let b = &self.bins[i];
        FULL_TURN_DEG * k
            + b.start_deg()
            + self.motion[i]
                .angle_into_rad(t - self.cum_time_s[i], b.width_deg())
                .to_degrees()
                .clamp(0.0, b.width_deg())
    }

    /// Index of the bin the head is in at `t_s` in `[0, period)`.
    fn bin_at_time(&self, t_s: f64) -> usize {
        self.cum_time_s
            .partition_point(|&c| c <= t_s)
            .saturating_sub(1)
            .min(self.bins.len() - 1)
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
        let mut pos = self.bins[i].start_deg() + (a - wrap_deg(a));
        let mut out = Vec::new();
        for _ in 0..n {
            out.push(i);
            pos += self.bins[i].width_deg();
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
            .map(|i| self.bins[i].power_w())
            .fold(0.0, f64::max)
    }

    /// Azimuth (degrees, `[0, 360)`) and bin index at `t_s` after the head passed 0°,
    /// for `t_s` in `[0, period)`.
    #[must_use]
    pub fn azimuth_at(&self, t_s: f64) -> (f64, usize) {
        self.azimuth_in_bin(t_s, self.bin_at_time(t_s))
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
        let x = self.motion[i].angle_into_rad(t_s - self.cum_time_s[i], b.width_deg());
        (wrap_deg(b.start_deg() + x.to_degrees()), i)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The per-call formulas as they were before [`Motion`] cached their
    /// constants: the reference the cache must match bit for bit.
    fn time_into_reference(b: &Bin, x_rad: f64) -> f64 {
        if x_rad <= 0.0 {
            return 0.0;
        }
        let w_s = b.spin_start_rad_s;
        let w_x = (w_s.powi(2) + 2.0 * b.accel_rad_s2() * x_rad)
            .max(0.0)
            .sqrt();
        2.0 * x_rad / (w_s + w_x)
    }

    fn angle_into_reference(b: &Bin, t_s: f64) -> f64 {
        let t = t_s.clamp(0.0, b.dwell_s());
        (b.spin_start_rad_s * t + 0.5 * b.accel_rad_s2() * t * t)
            .clamp(0.0, b.width_deg.to_radians())
    }

    fn bin(width_deg: f64, w0: f64, w1: f64) -> Bin {
        Bin {
            start_deg: 0.0,
            width_deg,
            power_w: 1e-3,
            spin_start_rad_s: w0,
            spin_end_rad_s: w1,
            region: None,
            dwell_s: None,
        }
    }

    proptest! {
        /// The one split into periods against its plain statement
        /// (`floor`, then the rest): bit for bit but for the sign of a
        /// zero (`−0` gives `(0, −0)`, not `(−0, …)`). Below one period
        /// `x/period ≤ 1 − 2⁻⁵³` rounds below 1, so the fast path's `k = 0`
        /// is the floor's.
        #[test]
        fn split_periods_is_floor_and_rest(
            x in prop_oneof![-1e4f64..1e4, 0.0f64..1.0, Just(0.0), Just(-0.0), Just(360.0), Just(f64::NAN)],
            period in prop_oneof![1e-3f64..10.0, Just(360.0), Just(0.05)],
        ) {
            let k = (x / period).floor();
            let r = x - k * period;
            let (gk, gr) = split_periods(x, period);
            if x == 0.0 {
                prop_assert!(gk == 0.0 && gr == 0.0);
            } else {
                prop_assert_eq!(gk.to_bits(), k.to_bits());
                prop_assert_eq!(gr.to_bits(), r.to_bits());
            }
            // Just below a period: still the first period.
            let below = period - period * f64::EPSILON / 2.0;
            if below < period {
                prop_assert_eq!(split_periods(below, period).0, (below / period).floor());
            }
        }

        #[test]
        fn cached_motion_is_the_per_call_formula(
            width in prop_oneof![1e-6f64..360.0, Just(1.0)],
            w0 in prop_oneof![1e-3f64..1e4, Just(62.83185307179586), Just(1e-160), Just(1e160)],
            w1_same in any::<bool>(),
            w1 in 1e-3f64..1e4,
            x in prop_oneof![-1.0f64..7.0, Just(0.0), Just(-0.0), Just(f64::INFINITY), Just(f64::NAN)],
            t in prop_oneof![-1.0f64..10.0, Just(0.0), Just(f64::INFINITY)],
        ) {
            let b = bin(width, w0, if w1_same { w0 } else { w1 });
            let m = Motion::of(&b);
            prop_assert_eq!(m.time_into_s(x).to_bits(), time_into_reference(&b, x).to_bits());
            prop_assert_eq!(b.time_into_s(x).to_bits(), time_into_reference(&b, x).to_bits());
            prop_assert_eq!(
                m.angle_into_rad(t, b.width_deg).to_bits(),
                angle_into_reference(&b, t).to_bits()
            );
            prop_assert_eq!(b.angle_into_rad(t).to_bits(), angle_into_reference(&b, t).to_bits());
            prop_assert_eq!(m.dwell_s.to_bits(), b.dwell_s().to_bits());
        }
    }

    proptest! {
        /// The compensated sum of nonnegative terms (a frame's dwells: one
        /// huge, many tiny, or spread over 20 decades) is within
        /// `2u·S + 4n·u²·S` of the exact sum (rationals): the bound
        /// `eye_safety::bound::count::time_rounding_s` relies on. A plain
        /// running sum fails it (a large term, then many small ones).
        #[test]
        fn compensated_sum_is_within_2u_of_the_exact_sum(
            terms in proptest::collection::vec(prop_oneof![
                1e-12f64..1e-6, 1e-3f64..1.0, Just(1e6), 0.0f64..1e9,
            ], 1..400),
        ) {
            use num_rational::BigRational;
            use num_traits::{Signed, ToPrimitive};
            let mut c = Compensated::default();
            let mut exact = BigRational::from_integer(0.into());
            for &x in &terms {
                c.add(x);
                exact += BigRational::from_float(x).unwrap();
            }
            let got = BigRational::from_float(c.value()).unwrap();
            let err = (got - exact.clone()).abs().to_f64().unwrap();
            let s = exact.to_f64().unwrap();
            let u = f64::EPSILON / 2.0;
            let n = terms.len() as f64;
            prop_assert!(err <= (2.0 * u + 4.0 * n * u * u) * s, "err {err} of {s}");
        }

        /// ω(x) is the derivative of the angle law: the time to advance x
        /// is 2x/(ω_s + ω(x)) (the trapezoid rule, exact at constant
        /// acceleration), and the bin's ends give its declared spins.
        #[test]
        fn spin_into_matches_time_law_and_ends(
            width in 1e-3f64..360.0,
            w0 in 1e-2f64..1e3,
            w1 in 1e-2f64..1e3,
            f in 0.0f64..=1.0,
        ) {
            let b = bin(width, w0, w1);
            let x = f * width.to_radians();
            let w_x = b.spin_into_rad_s(x);
            prop_assert!((b.spin_into_rad_s(0.0) - w0).abs() <= 1e-9 * w0);
            prop_assert!((b.spin_into_rad_s(width.to_radians()) - w1).abs() <= 1e-9 * w0.max(w1));
            if x > 0.0 {
                let t = b.time_into_s(x);
                prop_assert!((2.0 * x / (w0 + w_x) - t).abs() <= 1e-9 * t);
            }
            // Clamped outside the bin.
            prop_assert_eq!(b.spin_into_rad_s(-1.0), b.spin_into_rad_s(0.0));
            prop_assert_eq!(b.spin_into_rad_s(1e9), b.spin_into_rad_s(width.to_radians()));
        }
    }
}
