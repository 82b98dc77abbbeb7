//! The bins as the bound sees them ([`Seg`]: a start, a width, a power and
//! the spin at both edges, moving as [`BinMotion`] says), with runs of equal
//! bins merged first ([`coalesce`]).

use crate::profile::kinematics::BinMotion;

/// A bin as the bound sees it: start angle (deg), width (deg), power (W),
/// and the spin at its two edges (constant angular acceleration between;
/// the kinematics are [`BinMotion`]'s, shared with profile bins).
#[derive(Debug, Clone, Copy)]
pub struct Seg {
    /// Start azimuth, deg.
    pub start_deg: f64,
    /// Width, deg.
    pub width_deg: f64,
    /// Power, W.
    pub power_w: f64,
    /// Spin at the start, rad/s.
    pub spin_start_rad_s: f64,
    /// Spin at the end, rad/s.
    pub spin_end_rad_s: f64,
}

impl BinMotion for Seg {
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

/// Whether `b` continues `a` as the same emission: equal power and one
/// constant spin across both (no acceleration in either).
fn same_run(a: &Seg, b: &Seg) -> bool {
    a.power_w == b.power_w
        && a.spin_start_rad_s == a.spin_end_rad_s
        && b.spin_start_rad_s == b.spin_end_rad_s
        && a.spin_start_rad_s == b.spin_start_rad_s
}

/// `segs` with every run of consecutive bins of one power and one constant
/// spin merged into one bin (not across 0°). The head's motion and the
/// emitted power are the same functions of time, so every quantity the
/// bound bounds (pass durations, pulse counts, envelope integrals) is the
/// same; only edges where nothing changes are dropped, and with them the
/// cells, walks and per-bin pulse caps they would cost (a pulse cap over a
/// merged bin is at most the sum of its parts' caps). The merged width is
/// the sum of the parts' (the times differ from the parts' sum by float
/// rounding only, far inside [`RATIO_MARGIN`](super::RATIO_MARGIN)). Borrowed when nothing
/// merges. Piecewise-constant profiles (the closed forms: three runs in
/// 360 bins) cost their runs, not their bins.
pub(super) fn coalesce(segs: &[Seg]) -> std::borrow::Cow<'_, [Seg]> {
    if !segs.windows(2).any(|w| same_run(&w[0], &w[1])) {
        return std::borrow::Cow::Borrowed(segs);
    }
    let mut out: Vec<Seg> = Vec::with_capacity(segs.len());
    for s in segs {
        match out.last_mut() {
            Some(last) if same_run(last, s) => last.width_deg += s.width_deg,
            _ => out.push(*s),
        }
    }
    std::borrow::Cow::Owned(out)
}

/// A bin of `width` degrees from `start` at `power`, spinning from
/// `w0` to `w1` rad/s.
#[cfg(test)]
pub(super) fn seg(start: f64, width: f64, power: f64, w0: f64, w1: f64) -> Seg {
    Seg {
        start_deg: start,
        width_deg: width,
        power_w: power,
        spin_start_rad_s: w0,
        spin_end_rad_s: w1,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fields(s: &Seg) -> [f64; 5] {
        [
            s.start_deg,
            s.width_deg,
            s.power_w,
            s.spin_start_rad_s,
            s.spin_end_rad_s,
        ]
    }

    /// Runs of one power and one constant spin merge (widths summed, the
    /// first bin's start kept); a change of power, an acceleration in
    /// either bin or a change of spin ends a run. Expected lists by hand.
    #[test]
    fn coalesce_merges_runs_of_one_power_and_constant_spin() {
        let segs = [
            seg(0.0, 90.0, 1.0, 10.0, 10.0),
            seg(90.0, 45.0, 1.0, 10.0, 10.0),
            seg(135.0, 45.0, 1.0, 10.0, 10.0), // three of a run: 0..180
            seg(180.0, 45.0, 2.0, 10.0, 10.0), // power changes
            seg(225.0, 45.0, 2.0, 10.0, 10.0), // run: 180..270
            seg(270.0, 30.0, 2.0, 10.0, 12.0), // accelerates
            seg(300.0, 30.0, 2.0, 12.0, 12.0), // follows an accelerating bin
            seg(330.0, 30.0, 2.0, 11.0, 11.0), // another spin
        ];
        let expected = [
            seg(0.0, 180.0, 1.0, 10.0, 10.0),
            seg(180.0, 90.0, 2.0, 10.0, 10.0),
            segs[5],
            segs[6],
            segs[7],
        ];
        let out = coalesce(&segs);
        assert!(matches!(out, std::borrow::Cow::Owned(_)));
        assert_eq!(out.len(), expected.len());
        for (got, want) in out.iter().zip(&expected) {
            assert_eq!(fields(got), fields(want));
        }
        // Nothing to merge (each pair differs in one respect only): the
        // same slice, borrowed.
        let apart = [
            seg(0.0, 90.0, 1.0, 10.0, 10.0),
            seg(90.0, 90.0, 2.0, 10.0, 10.0),  // power
            seg(180.0, 90.0, 2.0, 10.0, 11.0), // accelerates
            seg(270.0, 90.0, 2.0, 11.0, 11.0), // after an acceleration
        ];
        let out = coalesce(&apart);
        assert!(matches!(out, std::borrow::Cow::Borrowed(s) if std::ptr::eq(s, &apart[..])));
        // The first and last bins alike: 0° stays an edge.
        let ring = [
            seg(0.0, 180.0, 1.0, 10.0, 10.0),
            seg(180.0, 90.0, 2.0, 10.0, 10.0),
            seg(270.0, 90.0, 1.0, 10.0, 10.0),
        ];
        assert!(matches!(coalesce(&ring), std::borrow::Cow::Borrowed(_)));
        // Same power and spin but one of two accelerating: no merge.
        assert!(!same_run(&apart[2], &apart[3]));
        assert!(!same_run(
            &seg(0.0, 1.0, 1.0, 11.0, 11.0),
            &seg(1.0, 1.0, 1.0, 11.0, 12.0)
        ));
        assert!(!same_run(
            &seg(0.0, 1.0, 1.0, 11.0, 11.0),
            &seg(1.0, 1.0, 1.0, 12.0, 12.0)
        ));
        assert!(same_run(
            &seg(0.0, 1.0, 1.0, 11.0, 11.0),
            &seg(1.0, 1.0, 1.0, 11.0, 11.0)
        ));
    }
}
