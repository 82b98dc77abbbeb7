//! The sound exposure bound: an upper bound of the true worst Class 1 ratio
//! of a scanned beam over every aperture azimuth, every pulse-clock phase,
//! every window placement and every window duration.
//!
//! The argument, rule by rule, is written down in `specs/eye_safety.md`;
//! the names below follow it.
//!
//! **Envelope.** Pulses are fired every `Δ = 1/f_p` s; a pulse fired at `t`
//! carries `P(t)·Δ` J. With `P̄(t) = max P` over `[t − Δ, t]` (the max
//! filter), every pulse's energy is at most `∫ P̄` over the `Δ` after it, and
//! these cells are disjoint: the energy of the pulses an aperture receives in
//! any time set `S` is at most `∫ P̄` over `S ⊕ [0, Δ]`, whatever the phase of
//! the pulse clock (free-running or locked to the rotation).
//!
//! **Passes.** The aperture at azimuth φ receives the pulses fired while the
//! head is in the closed arc `[φ − h, φ + h]`: a time interval `I_φ` of
//! length `τ(φ)` once per turn. The received envelope is periodic in the frame
//! period `T_f`, so a window of length `T` (`L = T + Δ = q·T_f + r`) holds at
//! most `q·E(φ) + min(E(φ), P̂·r)` J, where `E(φ) = ∫ P̄` over `I_φ ⊕ [0, Δ]`
//! and `P̂ = max P`.
//!
//! **Breakpoints.** `τ(φ)` and `E(φ)` are smooth between the azimuths where
//! a pass edge (or a pass edge shifted by `Δ` in time) meets a bin edge; on
//! each such cell both are `p_r·t(φ + h) − p_l·t(φ − h) + c` with `t` the
//! exact time along a constant-acceleration bin, whose one stationary point
//! solves a linear equation in φ (ω² is linear in angle). The maximum over a
//! cell is at a cell end or that point: every one is evaluated.
//!
//! **Windows.** For a fixed window start, the window energy is piecewise
//! linear in `T`, and on every row of Table 3 the AEL is `c·T^p` with
//! `0 ≤ p ≤ 1`: the ratio `(α + βT)/(c·T^p)` has no interior maximum, so the
//! supremum over all `T` is attained at window ends on envelope breakpoints,
//! at AEL row edges, or where the energy reaches the pass energy. Across
//! passes the same argument in the number of passes `q` leaves the first and
//! last `q` of each row.
//!
//! **Search.** The checker finds the same supremum by branch and bound
//! ([`Search::Pruned`]): linear sweeps give every cell's end values and a
//! cheap upper bound of its figures, and every window walk an upper bound of
//! its ratio; only cells and walks whose bound can still change the result
//! are evaluated exactly. [`Search::Exhaustive`] evaluates everything and is
//! tested bit-identical (`specs/eye_safety.md`, "Search"). Every shortcut
//! of the sweeps (merges for sorts, cached per-bin constants, memoized
//! monotone counts, cheaper `floor` and wrap) computes the same values as
//! the plain operation, and is tested so.
//!
//! **Rounding.** Every count that is a floor is taken as
//! `⌊x·(1 + 1e-9) + 1e-9⌋`, so a count that sits on an integer is taken
//! as the larger one and a perturbation of the inputs by 1e-12 cannot
//! lower it (`COUNT_MARGIN`, in the margin table of `bound/count.rs`).
//!
//! **Modules**, in the order of the argument (`specs/eye_safety.md`):
//! [`seg`] (the bins, runs merged), [`envelope`] (`P̄`), [`count`]
//! (counts, and the table of every margin), [`laser`] (the AEL, Rule 1,
//! the multi-pass rules), [`cells`] (the cells and the sweep),
//! [`pulse_cap`] (the pass's pulse caps), [`whole_pass`] (whole-pass
//! windows), [`walks`] (windows within a pass), [`search`] (branch and
//! bound), and the helpers [`order`] (sorts and merges) and [`sliding`]
//! (sliding maxima). This module only puts them together
//! ([`evaluate_with`]).

mod cells;
#[cfg(test)]
mod cells_adversarial;
mod count;
mod envelope;
mod laser;
mod order;
mod pulse_cap;
mod search;
mod seg;
mod sliding;
mod walks;
mod whole_pass;

pub(crate) use count::{floor_up, COUNT_MARGIN};
pub use count::{max_pulses_in, passes_in_window, RATIO_MARGIN};
pub use laser::{Laser, PassFigures, Rule};
pub use seg::Seg;
pub use walks::WALK_MAX_PIECES;

use crate::eye_safety::ael;
use crate::profile::kinematics::Timeline;
use cells::Cells;
use count::energy_rounding_j;
use envelope::Envelope;
use search::Best;
use seg::coalesce;
use walks::Walks;

/// Which cells and window walks [`evaluate_with`] evaluates exactly.
#[doc(hidden)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Search {
    /// Branch and bound: a cell or walk is evaluated only while its cheap
    /// upper bound could still change the result (the default).
    Pruned,
    /// Every cell and every walk (the reference the pruned search is
    /// tested bit-identical against).
    Exhaustive,
}

/// The result of the bound.
#[derive(Debug, Clone, PartialEq)]
pub struct Bound {
    /// Worst ratio over every rule (≤ 1 is Class 1).
    pub worst_ratio: f64,
    /// Rule binding there.
    pub binding_rule: Rule,
    /// Azimuth of the aperture where it binds (for window rules: the
    /// aperture with the largest pass energy), deg.
    pub worst_azimuth_deg: f64,
    /// Each rule's ratio, in [`Rule`] order.
    pub ratios: [f64; 4],
    /// Largest pass duration over all azimuths, s.
    pub max_pass_duration_s: f64,
    /// Largest pulse count per pass, any clock phase.
    pub max_pulses_per_pass: f64,
    /// Largest pass energy (envelope), J.
    pub max_pass_energy_j: f64,
    /// Window duration where the worst train rule binds, s.
    pub worst_window_s: f64,
    /// Azimuth where Rule 1 is worst, and the aperture with the largest
    /// pass energy (the train rules'), deg.
    pub rule_azimuths_deg: [f64; 2],
    /// Window duration where the within-pass rule is worst, and where the
    /// multi-pass rule is, s.
    pub rule_windows_s: [f64; 2],
    /// The pass figures the multi-pass rules used (largest envelope and
    /// pulse energy of one pass, longest pass).
    pub pass: PassFigures,
}

/// The rules in the order of [`Bound::ratios`].
pub(crate) const RULES: [Rule; 4] = [
    Rule::SinglePulse,
    Rule::PassTrain,
    Rule::T2Train,
    Rule::TimeBase,
];

/// The binding rule: the index and value of the largest ratio (the first
/// on a tie), over the rules in [`RULES`] order.
pub(crate) fn binding(ratios: &[f64; 4]) -> (usize, f64) {
    let (mut k_best, mut r_best) = (0, ratios[0]);
    for (k, &r) in ratios.iter().enumerate().skip(1) {
        if r > r_best {
            (k_best, r_best) = (k, r);
        }
    }
    (k_best, r_best)
}

/// Evaluates the bound for bins `segs` (validated: cover [0, 360) in order,
/// positive spins), half pass angle `half_deg`, and `laser`.
#[must_use]
pub fn evaluate(segs: &[Seg], half_deg: f64, laser: &Laser) -> Bound {
    evaluate_with(segs, half_deg, laser, Search::Pruned)
}

/// [`evaluate`] with a choice of search; both searches return bit-identical
/// results (the pruned one skips only what provably cannot change them).
#[doc(hidden)]
#[must_use]
pub fn evaluate_with(segs: &[Seg], half_deg: f64, laser: &Laser, search: Search) -> Bound {
    let runs = coalesce(segs);
    let segs: &[Seg] = &runs;
    let tl = Timeline::from_bins(segs);
    let delta = 1.0 / laser.pulse_rate_hz;
    let frame_s = tl.period_s();
    let env = Envelope::new(&tl, delta);
    let p_hat = segs.iter().map(|s| s.power_w).fold(0.0, f64::max);
    let cells = Cells::new(&tl, &env, half_deg.min(180.0), laser);
    let best = cells.search(search);

    // Rule 2 within one revolution: the whole-pass windows, then window
    // walks over envelope breakpoints within one pass.
    let l_max = (best.tau_max + delta).min(frame_s);
    // Windows up to `one_pass` can meet one pass only: the pulses a
    // within-pass figure counts are compared with the smallest AEL over
    // every such length that holds them (longer ones are the multi-pass
    // rules'), never with the AEL at their span (Table 3 steps down).
    let one_pass = laser.one_pass_window_max_s(frame_s, best.tau_max);
    let walks = Walks {
        env: &env,
        tl: &tl,
        laser,
        two_h_deg: 2.0 * half_deg.min(180.0),
        e_pass: best.e_max.0,
        l_max,
        one_pass_s: one_pass,
    };
    // Windows of a whole pass or more hold at most `E⁺` (not above the
    // whole-pass bound below, a cheap first threshold for the pruning).
    let t0 = best.tau_max;
    let first = Best(best.e_max.0 / laser.ael_inf_j(t0, one_pass), t0);
    let within = walks.search(search, first);
    let Best(pass_ratio, pass_window) =
        cells.full_pass_max(search, best.e_max.0, best.tau_max, one_pass, within);
    // Every energy above is a difference of integrals from 0°: add the
    // bound on its rounding (`count::energy_rounding_j`), to the pass
    // figures and, over the smallest AEL any window can take, to the
    // within-pass ratio.
    let e_pad = energy_rounding_j(
        frame_s,
        env.max_variation_within(l_max + cells.t_pad) * (1.0 + COUNT_MARGIN),
        p_hat,
        env.total_j(),
    );
    let pass_ratio = pass_ratio + e_pad / laser.ael_inf_j(0.0, ael::T_MAX_TABLE_S);
    // Rule 2 over several passes, up to the time base.
    let pass = PassFigures {
        envelope_j: best.e_env_max + e_pad,
        pulses_j: best.e_max.0 + e_pad,
        duration_s: best.tau_max + cells.t_pad,
    };
    let (multi_ratio, multi_window) = laser.multi_pass_ratio(frame_s, pass, p_hat);
    let multi_rule = Rule::for_duration(multi_window, frame_s);
    let mut ratios = [best.single.0, pass_ratio, 0.0, 0.0];
    match multi_rule {
        Rule::TimeBase => ratios[3] = multi_ratio,
        _ => ratios[2] = multi_ratio,
    }
    // Also report the time-base figure itself (mean power over 100 s).
    ratios[3] = ratios[3].max(laser.time_base_ratio(frame_s, pass, p_hat));
    for r in &mut ratios {
        *r *= 1.0 + RATIO_MARGIN;
    }
    let (k_best, r_best) = binding(&ratios);
    Bound {
        worst_ratio: r_best,
        binding_rule: RULES[k_best],
        worst_azimuth_deg: if k_best == 0 {
            best.single.1
        } else {
            best.e_max.1
        },
        ratios,
        max_pass_duration_s: best.tau_max,
        max_pulses_per_pass: max_pulses_in(best.tau_max + cells.t_pad, laser.pulse_rate_hz),
        max_pass_energy_j: best.e_max.0,
        worst_window_s: if k_best == 1 {
            pass_window
        } else {
            multi_window
        },
        rule_azimuths_deg: [best.single.1, best.e_max.1],
        rule_windows_s: [pass_window, multi_window],
        pass,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eye_safety::ael::Band;
    use proptest::prelude::*;

    proptest! {
        /// The pruned search (sweep bounds, branch and bound, walks in
        /// decreasing order of their bound) against the exhaustive one
        /// (every cell and every walk evaluated): the whole result, bit for
        /// bit, on random profiles with steps, runs and in-bin
        /// acceleration, every band. (The root crate's
        /// `pruned_search_is_bit_identical_to_exhaustive` runs more.)
        #[test]
        fn pruned_search_is_exhaustive_search(
            bins in proptest::collection::vec((0.05f64..1.0, 0.0f64..0.4, 2.0f64..80.0, any::<bool>()), 1..24),
            band in prop_oneof![Just(Band::RetinalNir), Just(Band::Ir1400), Just(Band::Ir1500)],
            f_p in prop_oneof![Just(1e3), 1e3f64..5e5],
            half_deg in 0.05f64..5.0,
        ) {
            let total: f64 = bins.iter().map(|b| b.0).sum();
            let n = bins.len();
            let mut start = 0.0;
            let segs: Vec<Seg> = (0..n)
                .map(|i| {
                    let (w, p, w0, accel) = bins[i];
                    let width = 360.0 * w / total;
                    let w1 = if accel { bins[(i + 1) % n].2 } else { w0 };
                    let s = Seg {
                        start_deg: start,
                        width_deg: width,
                        power_w: p,
                        spin_start_rad_s: w0,
                        spin_end_rad_s: w1,
                    };
                    start += width;
                    s
                })
                .collect();
            let laser = Laser { band, c4: 1.0, pulse_duration_s: 5e-9, pulse_rate_hz: f_p };
            let pruned = evaluate_with(&segs, half_deg, &laser, Search::Pruned);
            let exhaustive = evaluate_with(&segs, half_deg, &laser, Search::Exhaustive);
            prop_assert_eq!(pruned.worst_ratio.to_bits(), exhaustive.worst_ratio.to_bits());
            prop_assert_eq!(pruned, exhaustive);
        }
    }
}
