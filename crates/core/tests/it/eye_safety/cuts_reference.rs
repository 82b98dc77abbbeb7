//! The optimizer's cuts (`eye_safety::cuts`) against a plain reference of
//! the exposures `specs/optimizer.md` ("Eye safety as cuts") and the
//! module's documentation describe, written from that text alone, for
//! profiles whose bins each turn at a constant spin (so a pass's timing is
//! a sum of `width/ω` and a pulse's bin a look-up in cumulative times: no
//! kinematics of the crate is used):
//!
//! - apertures at every bin edge `± h` and at the extra azimuths;
//! - the pass `[φ − h, φ + h]` of `τ` seconds (at most one frame), `K` the
//!   most pulses whose span `(K − 1)·Δ` stays below `τ` by the relative
//!   margin `1e-9`;
//! - three clocks, the first pulse `1e-3`, `0.5` and `1 − 1e-3` of the way
//!   through the slack `τ − (K − 1)·Δ`;
//! - every run of consecutive pulses when `K ≤ 32`, else the runs from the
//!   first pulse to the last pulse of each bin's run and from the first
//!   pulse of each bin's run to the last pulse; a run's windows from just
//!   over its span to just under the next pulse (the next pass's first one
//!   after the last), capped at the time base; its limit the smallest AEL
//!   over them;
//! - `q ≥ 2` whole passes, windows from just over `(q − 1)·T_f + span` to
//!   just under `q·T_f`, capped at the time base (every such `q`, where the
//!   code tries only `q` near the Table 3 row edges: the reference checks
//!   that those reach the best `q`);
//! - Rule 1 per bin: one pulse against the bound's Rule 1 limit at the
//!   counts of the pass (`max_pulses_in`, `passes_in_window`), the smallest
//!   over every aperture whose closed arc meets the bin;
//! - the `T_i` groups (700–1050 nm, several pulses within `T_i`): any `g`
//!   consecutive pulses against `C5(⌈K'/g⌉·passes)·AEL(T_i)`.
//!
//! The AEL infimum, C5, the group size and the bound's counts are the
//! model's own ([`Laser`], `max_pulses_in`, `passes_in_window`): one model
//! of each piece of physics; what is checked is which exposures the cuts
//! are built from. Checked both ways: every reference exposure is a cut
//! (with the same pulses and limit), and every cut is a reference exposure
//! (the same pulses, limit and window), and for every pass the code's
//! multi-pass cuts reach the best `q`.

use std::collections::BTreeMap;

use gaze_lidar_core::eye_safety::ael::{Band, T2_S, TIME_BASE_S};
use gaze_lidar_core::eye_safety::bound::{max_pulses_in, passes_in_window, Laser, Rule, Seg};
use gaze_lidar_core::eye_safety::cuts::{cuts, Cut};
use gaze_lidar_core::model::angle::EDGE_SNAP_DEG;
use proptest::prelude::*;

const MARGIN: f64 = 1e-9;
const PHASES: [f64; 3] = [1e-3, 0.5, 1.0 - 1e-3];
/// Relative tolerance between the code's and the reference's limits and
/// windows (both compute the same products of the same times; the frame
/// may differ in its last bits).
const REL: f64 = 1e-12;

fn cases() -> u32 {
    std::env::var("GAZE_LIDAR_CUTS_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .map_or(48, |n: u32| n.max(1))
}

/// One exposure of the reference: pulses per bin, limit, window.
#[derive(Debug, Clone)]
struct Exposure {
    pulses: Vec<(usize, f64)>,
    limit_j: f64,
    window_s: (f64, f64),
}

/// The reference's view of a profile of constant-spin bins.
struct Profile {
    start_deg: Vec<f64>,
    width_deg: Vec<f64>,
    rate_deg_s: Vec<f64>,
    /// Time from 0° to the start of each bin, and the frame at the end.
    cum_s: Vec<f64>,
}

impl Profile {
    fn new(segs: &[Seg]) -> Self {
        let mut cum_s = vec![0.0];
        for s in segs {
            assert_eq!(s.spin_start_rad_s, s.spin_end_rad_s);
            let t = cum_s.last().unwrap() + s.width_deg.to_radians() / s.spin_start_rad_s;
            cum_s.push(t);
        }
        Self {
            start_deg: segs.iter().map(|s| s.start_deg).collect(),
            width_deg: segs.iter().map(|s| s.width_deg).collect(),
            rate_deg_s: segs
                .iter()
                .map(|s| s.spin_start_rad_s.to_degrees())
                .collect(),
            cum_s,
        }
    }

    fn frame_s(&self) -> f64 {
        *self.cum_s.last().unwrap()
    }

    /// Unwrapped time at the unwrapped azimuth `theta`.
    fn time_at(&self, theta: f64) -> f64 {
        let turns = (theta / 360.0).floor();
        let r = theta - 360.0 * turns;
        let mut b = 0;
        while b + 1 < self.start_deg.len() && self.start_deg[b + 1] <= r {
            b += 1;
        }
        let x = (r - self.start_deg[b]).clamp(0.0, self.width_deg[b]);
        turns * self.frame_s() + self.cum_s[b] + x.to_radians() / self.rate_deg_s[b].to_radians()
    }

    /// Bin the head is in at unwrapped time `t`, and the distance (s) from
    /// `t` to the nearest bin boundary in time.
    fn bin_at(&self, t: f64) -> (usize, f64) {
        let f = self.frame_s();
        let u = t - (t / f).floor() * f;
        let mut b = 0;
        while b + 1 < self.start_deg.len() && self.cum_s[b + 1] <= u {
            b += 1;
        }
        let d = (u - self.cum_s[b]).min(self.cum_s[b + 1] - u).abs();
        (b, d)
    }

    /// Bins whose closed extent meets the closed arc `[lo, hi]` (up to the
    /// edge snap), on the circle.
    fn met(&self, lo: f64, hi: f64) -> Vec<usize> {
        let (lo, hi) = (lo - EDGE_SNAP_DEG, hi + EDGE_SNAP_DEG);
        (0..self.start_deg.len())
            .filter(|&b| {
                let (s, e) = (self.start_deg[b], self.start_deg[b] + self.width_deg[b]);
                (-2..=2).any(|k: i32| {
                    let o = 360.0 * f64::from(k);
                    s + o <= hi && e + o >= lo
                })
            })
            .collect()
    }
}

fn tally(bins: &[usize], q: f64) -> Vec<(usize, f64)> {
    let mut m: BTreeMap<usize, f64> = BTreeMap::new();
    for &b in bins {
        *m.entry(b).or_insert(0.0) += 1.0;
    }
    m.into_iter().map(|(b, n)| (b, n * q)).collect()
}

fn key(pulses: &[(usize, f64)]) -> Vec<(usize, u64)> {
    pulses.iter().map(|&(b, n)| (b, n.to_bits())).collect()
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= REL * a.abs().max(b.abs())
}

/// Absolute tolerance on a window's ends, in units of `f64::EPSILON` times
/// the frame. A window end is a difference of times within the frame (the
/// last pulse of a whole-frame pass to the next pass's first is
/// `T_f − (K − 1)·Δ`, the pass's slack): where it is many decades below the
/// frame, the code's and the reference's frames, equal up to their last
/// bits, differ in it by far more than `REL` of its size (a slack of
/// 1.8 µs in a 64 ms frame: 2 ulps of the frame are 8e-12 of it). A few
/// ulps of the frame stay far below the windows' own margin
/// (`COUNT_INSIDE` = 1e-9 of a window of 1 µs is 1e-15 s, this 5e-16 s at
/// a frame of 0.07 s), so a window without its margin is still caught.
const WINDOW_FRAME_ULPS: f64 = 32.0;

/// Window ends equal up to `REL` of their size or rounding of the frame.
fn close_window(a: f64, b: f64, frame_s: f64) -> bool {
    (a - b).abs() <= REL * a.abs().max(b.abs()) + WINDOW_FRAME_ULPS * f64::EPSILON * frame_s
}

/// What the reference derives for one profile.
struct Reference {
    /// Runs within a pass and group cuts, keyed by their pulses.
    exposures: BTreeMap<Vec<(usize, u64)>, Vec<Exposure>>,
    /// Whole passes, every `q`, keyed by their pulses.
    passes: BTreeMap<Vec<(usize, u64)>, Vec<Exposure>>,
    /// Per pass (aperture × clock): the whole pass's pulses and the best
    /// ratio over every `q`, for the powers given.
    best_q: Vec<(Vec<(usize, f64)>, f64)>,
    /// Rule 1's limit per bin (the smallest over the apertures meeting it).
    rule_one_j: Vec<Option<f64>>,
    /// `false` when a pulse falls within rounding of a bin boundary or a
    /// pass holds a count within rounding of an integer (the code and the
    /// reference may then round differently: the case is skipped).
    clean: bool,
}

fn reference(segs: &[Seg], half_deg: f64, laser: &Laser, extra: &[f64]) -> Reference {
    let pr = Profile::new(segs);
    let frame = pr.frame_s();
    let f_p = laser.pulse_rate_hz;
    let delta = 1.0 / f_p;
    let h = half_deg.min(180.0);
    let power: Vec<f64> = segs.iter().map(|s| s.power_w).collect();
    let mut out = Reference {
        exposures: BTreeMap::new(),
        passes: BTreeMap::new(),
        best_q: Vec::new(),
        rule_one_j: vec![None; segs.len()],
        clean: true,
    };
    let push = |out: &mut Reference, e: Exposure| {
        out.exposures.entry(key(&e.pulses)).or_default().push(e);
    };
    let mut apertures: Vec<f64> = Vec::new();
    for &s in &pr.start_deg {
        apertures.push(s - h);
        apertures.push(s + h);
    }
    apertures.extend_from_slice(extra);
    for phi in apertures {
        let t_a = pr.time_at(phi - h);
        let tau = (pr.time_at(phi + h) - t_a).min(frame);
        // K: the most pulses whose span stays below τ by the margin.
        let mut k_n = 1usize;
        while (k_n as f64) * delta < tau * (1.0 - MARGIN) {
            k_n += 1;
        }
        let x = tau * f_p;
        if (x - x.round()).abs() < 1e-6 * x.max(1.0) {
            out.clean = false;
        }
        // Rule 1 at this aperture, every bin its closed arc meets.
        let per_pass = max_pulses_in(tau, f_p);
        let passes = passes_in_window(T2_S.min(TIME_BASE_S), tau, frame);
        let limit1 = 1.0 / laser.single_pulse_ratio_per_j(per_pass, passes);
        for b in pr.met(phi - h, phi + h) {
            let r = &mut out.rule_one_j[b];
            *r = Some(r.map_or(limit1, |l: f64| l.min(limit1)));
        }
        let slack = tau - (k_n as f64 - 1.0) * delta;
        for phase in PHASES {
            let t0 = t_a + phase * slack;
            let t: Vec<f64> = (0..k_n).map(|j| j as f64 * delta).collect();
            let mut bins = Vec::with_capacity(k_n);
            for &dt in &t {
                let (b, d) = pr.bin_at(t0 + dt);
                if d < 1e-9 * frame {
                    out.clean = false;
                }
                bins.push(b);
            }
            // Runs of consecutive pulses.
            let runs: Vec<(usize, usize)> = if k_n <= 32 {
                (0..k_n)
                    .flat_map(|i| (i..k_n).map(move |k| (i, k)))
                    .collect()
            } else {
                let mut r = Vec::new();
                for j in 0..k_n {
                    if j + 1 == k_n || bins[j + 1] != bins[j] {
                        r.push((0, j));
                    }
                    if j > 0 && bins[j - 1] != bins[j] {
                        r.push((j, k_n - 1));
                    }
                }
                r
            };
            for (i, k) in runs {
                let next = if k + 1 < k_n { t[k + 1] } else { frame };
                let lo = ((t[k] - t[i]) * (1.0 + MARGIN)).max(laser.pulse_duration_s);
                let hi = ((next - t[i]) * (1.0 - MARGIN)).min(TIME_BASE_S);
                push(
                    &mut out,
                    Exposure {
                        pulses: tally(&bins[i..=k], 1.0),
                        limit_j: laser.ael_inf_j(lo, hi),
                        window_s: (lo, hi.max(lo)),
                    },
                );
            }
            // The T_i groups.
            let g = laser.group(per_pass);
            if g > 1.0 {
                let n_groups = (per_pass / g).ceil() * passes;
                let limit_g = laser.c5(n_groups) * laser.ael_j(laser.band.t_i_s());
                let len = (g as usize).min(k_n);
                if len >= 2 {
                    for i in 0..=(k_n - len) {
                        push(
                            &mut out,
                            Exposure {
                                pulses: tally(&bins[i..i + len], 1.0),
                                limit_j: limit_g,
                                window_s: (laser.band.t_i_s(), laser.band.t_i_s()),
                            },
                        );
                    }
                }
            }
            // Whole passes, every q.
            let whole = tally(&bins, 1.0);
            let e_pass: f64 = whole.iter().map(|&(b, n)| n * power[b]).sum::<f64>() / f_p;
            let span = t[k_n - 1];
            let mut best: f64 = 0.0;
            let mut q = 2.0;
            loop {
                let lo = ((q - 1.0) * frame + span) * (1.0 + MARGIN);
                if lo > TIME_BASE_S {
                    break;
                }
                let hi = (q * frame * (1.0 - MARGIN)).min(TIME_BASE_S);
                if lo <= hi {
                    let limit = laser.ael_inf_j(lo, hi);
                    best = best.max(q * e_pass / limit);
                    let pulses: Vec<(usize, f64)> =
                        whole.iter().map(|&(b, n)| (b, n * q)).collect();
                    out.passes.entry(key(&pulses)).or_default().push(Exposure {
                        pulses,
                        limit_j: limit,
                        window_s: (lo, hi),
                    });
                }
                q += 1.0;
            }
            out.best_q.push((whole, best));
        }
    }
    out
}

fn is_rule_one(c: &Cut, laser: &Laser) -> bool {
    c.rule == Rule::SinglePulse
        && c.pulses.len() == 1
        && c.pulses[0].1 == 1.0
        && c.window_s == (laser.pulse_duration_s, laser.pulse_duration_s)
}

/// The comparison; `Err` names the first disagreement.
fn compare(segs: &[Seg], half_deg: f64, laser: &Laser, extra: &[f64]) -> Result<bool, String> {
    let r = reference(segs, half_deg, laser, extra);
    if !r.clean {
        return Ok(false);
    }
    let f_p = laser.pulse_rate_hz;
    let frame_s = Profile::new(segs).frame_s();
    let p: Vec<f64> = segs.iter().map(|s| s.power_w).collect();
    let got = cuts(segs, half_deg, laser, extra, 0.0);
    let mut by_key: BTreeMap<Vec<(usize, u64)>, Vec<&Cut>> = BTreeMap::new();
    for c in &got {
        by_key.entry(key(&c.pulses)).or_default().push(c);
    }
    // Rule 1: per bin, one pulse at the smallest limit (a one-pulse run
    // with the same limit may stand for it: equal cuts are kept once), and
    // no other Rule 1 cut.
    for (b, want) in r.rule_one_j.iter().enumerate() {
        let mine: Vec<&Cut> = got
            .iter()
            .filter(|c| is_rule_one(c, laser) && c.pulses[0].0 == b)
            .collect();
        let ok = match want {
            None => mine.is_empty(),
            Some(l) => {
                mine.len() <= 1
                    && mine.iter().all(|c| close(c.limit_j, *l))
                    && got
                        .iter()
                        .any(|c| c.pulses == [(b, 1.0)] && close(c.limit_j, *l))
            }
        };
        if !ok {
            return Err(format!("bin {b}: Rule 1 limit {want:?}, cuts {mine:?}"));
        }
    }
    // Every run and group of the reference is a cut (same pulses, same
    // limit).
    for (k, es) in &r.exposures {
        for e in es {
            let found = by_key
                .get(k)
                .is_some_and(|cs| cs.iter().any(|c| close(c.limit_j, e.limit_j)));
            if !found {
                return Err(format!("no cut for the exposure {e:?}"));
            }
        }
    }
    // Every cut other than Rule 1's is a reference exposure or whole passes
    // (same pulses, limit and window).
    for c in got.iter().filter(|c| !is_rule_one(c, laser)) {
        let k = key(&c.pulses);
        let found = [r.exposures.get(&k), r.passes.get(&k)]
            .into_iter()
            .flatten()
            .any(|es| {
                es.iter().any(|e| {
                    close(c.limit_j, e.limit_j)
                        && close_window(c.window_s.0, e.window_s.0, frame_s)
                        && close_window(c.window_s.1, e.window_s.1, frame_s)
                })
            });
        if !found {
            return Err(format!("the cut {c:?} is no reference exposure"));
        }
    }
    // Every pass's best q is reached by a cut of whole passes.
    for (whole, best) in &r.best_q {
        let reached = got.iter().any(|c| {
            let q = c.pulses.first().map_or(0.0, |&(_, n)| n) / whole[0].1;
            q >= 2.0
                && c.pulses.len() == whole.len()
                && c.pulses
                    .iter()
                    .zip(whole)
                    .all(|(a, w)| a.0 == w.0 && a.1 == w.1 * q)
                && c.ratio(&p, f_p) >= best * (1.0 - 1e-9)
        });
        if !reached {
            return Err(format!(
                "the best q of the pass {whole:?} ({best}) is missed"
            ));
        }
    }
    Ok(true)
}

/// Bins of constant spins: `(share, power, spin factor)` at `base` rad/s.
fn constant_spin_profile(bins: &[(f64, f64, f64)], base: f64) -> Vec<Seg> {
    let total: f64 = bins.iter().map(|b| b.0).sum();
    let mut start = 0.0;
    bins.iter()
        .map(|&(w, p, s)| {
            let width = 360.0 * w / total;
            let seg = Seg {
                start_deg: start,
                width_deg: width,
                power_w: p,
                spin_start_rad_s: base * s,
                spin_end_rad_s: base * s,
            };
            start += width;
            seg
        })
        .collect()
}

fn log_uniform(lo: f64, hi: f64) -> impl Strategy<Value = f64> {
    (lo.ln()..hi.ln()).prop_map(f64::exp)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(cases()))]

    /// The cuts are exactly the reference's exposures (and Rule 1 its
    /// smallest limit per bin), and reach the best number of whole passes.
    /// `pulses` sets the pulses of a typical pass (the pulse rate follows
    /// from it): up to 32, every run; beyond, the runs to and from the bins'
    /// edges. Pulse durations at the bands' `T_i` groups included (the pulse
    /// rate of a pass of a few µs reaches MHz). Pass angles of 360° and
    /// more too: a pass of the whole frame meets its first bin again at its
    /// end (one bin, two runs of its pulses).
    #[test]
    fn cuts_are_the_reference_s_exposures(
        bins in proptest::collection::vec((0.05f64..1.0, 0.0f64..0.4, 1.0f64..3.0), 1..8),
        base in 5.0f64..60.0,
        band in prop_oneof![Just(Band::RetinalNir), Just(Band::Ir1400), Just(Band::Ir1500)],
        half_deg in prop_oneof![4 => log_uniform(1e-3, 5.0), 1 => Just(1.0), 1 => Just(180.0), 1 => 180.0f64..400.0],
        pulses in prop_oneof![1.2f64..10.0, 10.0f64..60.0],
        pulse_s in prop_oneof![Just(5e-9), Just(1e-7)],
        extra in 0.0f64..360.0,
        offset in -1.0f64..1.0,
    ) {
        let segs = constant_spin_profile(&bins, base);
        // Extra apertures with a bin edge inside the pass (at `offset·h`
        // from its middle): there the clock's phase decides which side of
        // the edge a pulse falls on.
        let mut extras = vec![extra];
        extras.extend(segs.iter().map(|s| s.start_deg + offset * half_deg.min(180.0)));
        let tau_typ = (2.0 * half_deg).to_radians() / (2.0 * base);
        let f_p = (pulses / tau_typ).min(0.5 / pulse_s);
        let laser = Laser { band, c4: 1.0, pulse_duration_s: pulse_s, pulse_rate_hz: f_p };
        let ok = compare(&segs, half_deg, &laser, &extras);
        prop_assert!(ok.is_ok(), "{}", ok.unwrap_err());
        prop_assume!(ok.unwrap());
    }
}

/// Apertures whose pass holds more than 10⁶ pulses are skipped (the
/// module's resource limit): one bin turning once a second, a pass of the
/// whole frame (half-angle 180°) at 2 MHz holds 2·10⁶ pulses, so there is
/// no cut at all; at 0.9 MHz (9·10⁵ pulses) there are.
#[test]
fn passes_of_more_than_a_million_pulses_are_skipped() {
    let segs = [Seg {
        start_deg: 0.0,
        width_deg: 360.0,
        power_w: 1e-3,
        spin_start_rad_s: std::f64::consts::TAU,
        spin_end_rad_s: std::f64::consts::TAU,
    }];
    let laser = |f_p| Laser {
        band: Band::Ir1500,
        c4: 1.0,
        pulse_duration_s: 1e-7,
        pulse_rate_hz: f_p,
    };
    assert!(cuts(&segs, 180.0, &laser(2e6), &[], 0.0).is_empty());
    assert!(!cuts(&segs, 180.0, &laser(9e5), &[], 0.0).is_empty());
}

/// The reference itself, by hand: 4 bins of 90° at 10 turns/s, pass angle
/// 4° (τ = 1/900 s), 9 kHz: τ·f_p = 10 on the nose, so a pass holds 10
/// pulses with room (11 would need the pulses on both pass edges at once).
/// The code must offer 10-pulse runs of one pass and nothing longer (the
/// count margin), and two whole passes of 10 pulses.
#[test]
fn a_pass_of_an_integer_pulse_count_holds_one_pulse_less() {
    let spin = std::f64::consts::TAU * 10.0;
    let segs: Vec<Seg> = (0..4)
        .map(|i| Seg {
            start_deg: 90.0 * f64::from(i),
            width_deg: 90.0,
            power_w: 1e-3,
            spin_start_rad_s: spin,
            spin_end_rad_s: spin,
        })
        .collect();
    let laser = Laser {
        band: Band::RetinalNir,
        c4: 1.0,
        pulse_duration_s: 5e-9,
        pulse_rate_hz: 9e3,
    };
    let all = cuts(&segs, 2.0, &laser, &[], 0.0);
    // One-pass runs: windows under 0.1 s.
    let most = all
        .iter()
        .filter(|c| {
            c.window_s.0 < 0.05
                && !(c.window_s.0 == laser.pulse_duration_s
                    && c.window_s.1 == laser.pulse_duration_s)
        })
        .map(|c| c.pulses.iter().map(|&(_, n)| n).sum::<f64>())
        .fold(0.0, f64::max);
    assert_eq!(most, 10.0);
    assert!(all
        .iter()
        .any(|c| c.pulses.iter().map(|&(_, n)| n).sum::<f64>() == 20.0));
}

/// A `T_i` group is several pulses: on the knife edge where a pass holds
/// one pulse with room but the bound counts two (`τ·f_p` = 1: 10 turns a
/// second, pass angle 0.018°, τ = 5 µs, 200 kHz, `T_i` = 5 µs holds two
/// pulses), there is no group cut of one pulse.
#[test]
fn no_group_cut_of_one_pulse() {
    let spin = std::f64::consts::TAU * 10.0;
    let segs: Vec<Seg> = (0..4)
        .map(|i| Seg {
            start_deg: 90.0 * f64::from(i),
            width_deg: 90.0,
            power_w: 1e-3,
            spin_start_rad_s: spin,
            spin_end_rad_s: spin,
        })
        .collect();
    let laser = Laser {
        band: Band::RetinalNir,
        c4: 1.0,
        pulse_duration_s: 5e-9,
        pulse_rate_hz: 2e5,
    };
    assert_eq!(laser.group(2.0), 2.0);
    let t_i = laser.band.t_i_s();
    let all = cuts(&segs, 0.009, &laser, &[], 0.0);
    assert!(!all.is_empty());
    for c in &all {
        if c.window_s == (t_i, t_i) {
            assert!(
                c.pulses.iter().map(|&(_, n)| n).sum::<f64>() >= 2.0,
                "{c:?}"
            );
        }
    }
}
