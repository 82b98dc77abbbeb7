//! A brute-force reference for the eye safety of a whole multi-beam head,
//! written from the definitions (IEC 60825-1:2014, as
//! `specs/eye_safety.md` quotes it; the head's conventions as
//! `eye_safety::head` documents them). It shares no code with the head bound:
//! only the AEL tables (`eye_safety::ael`, the project's one model of them)
//! and the head description (`eye_safety::head::Head`).
//!
//! - **Forward kinematics.** The head turns counter-clockwise about the z
//!   axis; its encoder azimuth is `θ(t)` (inside the bin whose half-open
//!   time interval holds `t mod T_f`: `θ = θ_s + ω₀·v + ½a·v²`). Channel `c`
//!   fires at every `t0 + slot_c + k·cycle` (a free-running clock, phase
//!   `t0`). Its ray leaves the crossing point `O = (r₀ cos θ, r₀ sin θ, z₀)`
//!   in the direction `(cos e cos ψ, cos e sin ψ, sin e)`, `ψ = θ + α_c`
//!   (elevation `e`, azimuth offset `α_c`). Its energy is
//!   `power_scale · P_bin · cycle` (the bin of the head at the firing).
//! - **The aperture** at `(φ, h)`: a disc of the band's diameter
//!   (`ael::Band::aperture_mm`: 7 mm in 700–1050 nm, the IR supremum
//!   3.557 mm in the corneal bands) centred at `(R cos φ, R sin φ, h)`,
//!   `R = aperture_distance_mm`, facing the spin axis (its plane is tangent to
//!   the cylinder of radius `R`). A pulse is received — counted whole — iff
//!   a concrete point of the disc lies inside the beam's cone: the point of
//!   the disc nearest to where the ray meets the plane, inside the cone of
//!   diameter `exit + divergence · s` at its distance `s` along the ray. (A
//!   sufficient condition for overlap: the reference never counts a pulse
//!   that does not overlap.)
//! - **Rules** on the explicit train (pulses at one instant summed): each
//!   single pulse against `C5·AEL(t_pulse)`; (pulses no longer than `T_i`)
//!   each group of pulses wholly inside `[t_i, t_i + T_i]` against
//!   `C5·AEL(T_i)`; each window holding exactly pulses `i..=j` against the
//!   smallest AEL over the lengths that hold exactly them
//!   (`ael::ael_inf_j` over `[t_j − t_i + t_pulse, t_{j+1} − t_i]`, capped
//!   at the time base); windows of exactly every Table 3 row edge and of the
//!   100 s time base (the time-base average). `N` for C5 is the greedy
//!   (fewest-groups) count of `T_i` groups in `[t, t + T2)` from the first
//!   pulse of each pass of the first turn: never more than the true count,
//!   so C5 never below the true one.
//!
//! Every figure is the energy of concrete pulses in a concrete window over
//! an AEL that window really has: a true exposure ratio, so the worst over
//! the positions and phases tried is a LOWER bound of the head's true worst.

#![allow(dead_code)]

use gaze_lidar_core::eye_safety::ael::{self, Band};
use gaze_lidar_core::eye_safety::head::Head;

/// One bin: start angle, width (deg), power (W), spin at its start and end
/// (rad/s, both > 0; constant angular acceleration in between).
#[derive(Debug, Clone, Copy)]
pub struct OBin {
    pub start_deg: f64,
    pub width_deg: f64,
    pub power_w: f64,
    pub w0: f64,
    pub w1: f64,
}

/// The scan the head turns through and the laser's pulse.
#[derive(Debug, Clone)]
pub struct OScan {
    pub bins: Vec<OBin>,
    pub lambda_nm: f64,
    pub pulse_s: f64,
}

/// The motion: bin start times, accelerations, period.
#[derive(Debug, Clone)]
pub struct Motion {
    bins: Vec<OBin>,
    t_start: Vec<f64>,
    acc: Vec<f64>,
    pub period_s: f64,
}

impl Motion {
    pub fn new(bins: &[OBin]) -> Motion {
        let mut t = 0.0;
        let (mut t_start, mut acc) = (Vec::new(), Vec::new());
        for b in bins {
            assert!(b.w0 > 0.0 && b.w1 > 0.0, "spins must be > 0");
            t_start.push(t);
            let w = b.width_deg.to_radians();
            acc.push((b.w1 * b.w1 - b.w0 * b.w0) / (2.0 * w));
            t += 2.0 * w / (b.w0 + b.w1);
        }
        Motion {
            bins: bins.to_vec(),
            t_start,
            acc,
            period_s: t,
        }
    }

    /// Bin index and encoder azimuth (rad, unwrapped within the turn from
    /// the first bin's start) at absolute time `t`.
    pub fn at(&self, t: f64) -> (usize, f64) {
        let u = t.rem_euclid(self.period_s);
        let i = self
            .t_start
            .partition_point(|&s| s <= u)
            .saturating_sub(1)
            .min(self.bins.len() - 1);
        let b = &self.bins[i];
        let v = u - self.t_start[i];
        let x = (b.w0 * v + 0.5 * self.acc[i] * v * v).clamp(0.0, b.width_deg.to_radians());
        (i, b.start_deg.to_radians() + x)
    }

    /// Time into the turn at which the head is at `theta` rad (taken into
    /// `[θ_0, θ_0 + 2π)` of the first bin's start `θ_0`): the inverse of
    /// the forward motion, used only to find candidate pulses.
    pub fn time_of(&self, theta: f64) -> f64 {
        let a0 = self.bins[0].start_deg.to_radians();
        let th = a0 + (theta - a0).rem_euclid(std::f64::consts::TAU);
        let i = self
            .bins
            .partition_point(|b| b.start_deg.to_radians() <= th)
            .saturating_sub(1);
        let b = &self.bins[i];
        let x = (th - b.start_deg.to_radians()).clamp(0.0, b.width_deg.to_radians());
        let wx = (b.w0 * b.w0 + 2.0 * self.acc[i] * x).max(0.0).sqrt();
        self.t_start[i] + 2.0 * x / (b.w0 + wx)
    }
}

type V3 = [f64; 3];

fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn mul(a: V3, k: f64) -> V3 {
    [a[0] * k, a[1] * k, a[2] * k]
}
fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn norm(a: V3) -> f64 {
    dot(a, a).sqrt()
}

/// An aperture position: azimuth (deg) and height (mm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pos {
    pub azimuth_deg: f64,
    pub height_mm: f64,
}

/// Where channel `c`'s ray meets the aperture plane at `pos` with the head
/// at `theta` rad: the in-plane offset from the aperture centre (mm; along
/// the plane's horizontal and vertical), the distance along the ray (mm),
/// and whether the beam overlaps the aperture disc. `None` if the ray does
/// not meet the plane ahead of the crossing point.
pub fn hit(head: &Head, c: usize, theta: f64, pos: Pos, aperture_mm: f64) -> Option<Hit> {
    let ch = &head.channels[c];
    let r0 = head.origin_radius_mm;
    let o: V3 = [r0 * theta.cos(), r0 * theta.sin(), head.origin_height_mm];
    let psi = theta + ch.azimuth_offset_deg.to_radians();
    let el = ch.elevation_deg.to_radians();
    let d: V3 = [el.cos() * psi.cos(), el.cos() * psi.sin(), el.sin()];
    let phi = pos.azimuth_deg.to_radians();
    let big_r = head.aperture_distance_mm;
    let centre: V3 = [big_r * phi.cos(), big_r * phi.sin(), pos.height_mm];
    let n: V3 = [phi.cos(), phi.sin(), 0.0];
    let dn = dot(d, n);
    if dn <= 1e-9 {
        return None;
    }
    let s = dot(sub(centre, o), n) / dn;
    if s <= 0.0 {
        return None;
    }
    let p = add(o, mul(d, s));
    let q = sub(p, centre);
    let qn = norm(q);
    let a = 0.5 * aperture_mm;
    // The disc's point nearest the ray's crossing of the plane.
    let x = if qn <= a {
        p
    } else {
        add(centre, mul(q, a / qn))
    };
    let sx = dot(sub(x, o), d);
    let perp = norm(sub(sub(x, o), mul(d, sx)));
    let radius = 0.5 * (head.exit_diameter_mm + head.divergence_mrad * 1e-3 * sx.max(0.0));
    let lateral = dot(q, [-phi.sin(), phi.cos(), 0.0]);
    Some(Hit {
        miss_mm: qn,
        lateral_mm: lateral,
        height_mm: p[2],
        along_mm: s,
        overlaps: sx > 0.0 && perp <= radius,
    })
}

/// See [`hit`].
#[derive(Debug, Clone, Copy)]
pub struct Hit {
    /// Distance in the plane from the aperture centre to the ray, mm.
    pub miss_mm: f64,
    /// Its horizontal component (along the plane), mm.
    pub lateral_mm: f64,
    /// Height of the ray's crossing of the plane, mm.
    pub height_mm: f64,
    /// Distance along the ray from the crossing point, mm.
    pub along_mm: f64,
    /// The beam overlaps the disc.
    pub overlaps: bool,
}

/// [`hit`]'s overlap test with the trigonometry of the channel and of the
/// aperture computed once (the same formulas by the angle-addition
/// identities; `fast_hit_is_hit` checks them against [`hit`]).
#[derive(Debug, Clone, Copy)]
pub struct Fast {
    r0: f64,
    z0: f64,
    cos_e: f64,
    sin_e: f64,
    cos_a: f64,
    sin_a: f64,
    centre: V3,
    n: V3,
    a: f64,
    exit: f64,
    div: f64,
}

impl Fast {
    pub fn new(head: &Head, c: usize, pos: Pos, aperture_mm: f64) -> Fast {
        let ch = &head.channels[c];
        let (sin_e, cos_e) = ch.elevation_deg.to_radians().sin_cos();
        let (sin_a, cos_a) = ch.azimuth_offset_deg.to_radians().sin_cos();
        let (sp, cp) = pos.azimuth_deg.to_radians().sin_cos();
        let big_r = head.aperture_distance_mm;
        Fast {
            r0: head.origin_radius_mm,
            z0: head.origin_height_mm,
            cos_e,
            sin_e,
            cos_a,
            sin_a,
            centre: [big_r * cp, big_r * sp, pos.height_mm],
            n: [cp, sp, 0.0],
            a: 0.5 * aperture_mm,
            exit: head.exit_diameter_mm,
            div: head.divergence_mrad * 1e-3,
        }
    }

    /// Whether the beam overlaps the disc with the head at `theta`.
    pub fn overlaps(&self, theta: f64) -> bool {
        let (st, ct) = theta.sin_cos();
        let o: V3 = [self.r0 * ct, self.r0 * st, self.z0];
        let (cpsi, spsi) = (
            ct * self.cos_a - st * self.sin_a,
            st * self.cos_a + ct * self.sin_a,
        );
        let d: V3 = [self.cos_e * cpsi, self.cos_e * spsi, self.sin_e];
        let dn = dot(d, self.n);
        if dn <= 1e-9 {
            return false;
        }
        let s = dot(sub(self.centre, o), self.n) / dn;
        if s <= 0.0 {
            return false;
        }
        let p = add(o, mul(d, s));
        let q = sub(p, self.centre);
        let qn = norm(q);
        let x = if qn <= self.a {
            p
        } else {
            add(self.centre, mul(q, self.a / qn))
        };
        let sx = dot(sub(x, o), d);
        let perp = norm(sub(sub(x, o), mul(d, sx)));
        sx > 0.0 && perp <= 0.5 * (self.exit + self.div * sx.max(0.0))
    }
}

/// A worst case found.
#[derive(Debug, Clone, Copy)]
pub struct OWorst {
    pub ratio: f64,
    pub rule: &'static str,
    pub pos: Pos,
    pub t0_s: f64,
    pub window_s: f64,
    pub energy_j: f64,
    pub pulses: usize,
}

impl std::fmt::Display for OWorst {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{:.6} ({}, φ = {:.4}°, h = {:.4} mm, t0 = {:.3e} s, window {:.6e} s, {} pulses, {:.6e} J)",
            self.ratio,
            self.rule,
            self.pos.azimuth_deg,
            self.pos.height_mm,
            self.t0_s,
            self.window_s,
            self.pulses,
            self.energy_j
        )
    }
}

/// Evaluation effort.
#[derive(Debug, Clone)]
pub struct Effort {
    /// Clock phases (uniform over one cycle).
    pub phases: usize,
    /// Window starts per position at most (evenly chosen among the first
    /// turn's pulses; pass starts always included).
    pub starts_max: usize,
    /// Head-angle scan step for candidate arcs, deg.
    pub scan_step_deg: f64,
    /// Positions evaluated in full per proxy (see [`Oracle::worst`]).
    pub top_k: usize,
}

impl Default for Effort {
    fn default() -> Self {
        Effort {
            phases: 3,
            starts_max: 300,
            scan_step_deg: 0.05,
            top_k: 3,
        }
    }
}

/// The reference.
pub struct Oracle {
    pub head: Head,
    pub scan: OScan,
    pub motion: Motion,
    pub band: Band,
    pub c4: f64,
    pub aperture_mm: f64,
}

/// Candidate firing times of one channel within a turn, and the heights
/// its ray crosses the aperture plane at meanwhile (widened by the reach).
#[derive(Debug, Clone, Copy)]
pub struct Interval {
    pub lo_s: f64,
    pub hi_s: f64,
    pub h_lo_mm: f64,
    pub h_hi_mm: f64,
}

/// A train: times (ascending, distinct) and energies (pulses at one
/// instant summed), complete on `[0, horizon_s)`.
#[derive(Debug, Clone, Default)]
pub struct Train {
    pub t: Vec<f64>,
    pub e: Vec<f64>,
    pub horizon_s: f64,
}

impl Oracle {
    pub fn new(head: &Head, scan: &OScan) -> Oracle {
        let band = Band::of(scan.lambda_nm).expect("supported band");
        Oracle {
            head: head.clone(),
            scan: scan.clone(),
            motion: Motion::new(&scan.bins),
            band,
            c4: ael::c4(scan.lambda_nm),
            aperture_mm: band.aperture_mm(),
        }
    }

    /// For every channel, the time intervals within a turn (`[a, b]`, `b`
    /// may pass `T_f`: then the rest lies in the next turn) at which it can
    /// overlap an aperture at azimuth `phi` of any height, with the range
    /// of heights its ray crosses the plane at meanwhile: a scan of head
    /// angles at `step_deg` marking every angle whose ray passes within the
    /// reach (plus a Lipschitz margin) horizontally, widened by one step
    /// and by one cycle (a superset; the forward test decides).
    pub fn intervals(&self, phi: f64, step_deg: f64) -> Vec<Vec<Interval>> {
        let n = (360.0 / step_deg).ceil() as usize;
        let step = std::f64::consts::TAU / n as f64;
        let h = &self.head;
        let tf = self.motion.period_s;
        let cyc = h.cycle_s;
        let pos = Pos {
            azimuth_deg: phi,
            height_mm: 0.0,
        };
        let mut all = Vec::new();
        for c in 0..h.channels.len() {
            let hits: Vec<Option<Hit>> = (0..n)
                .map(|k| hit(h, c, k as f64 * step, pos, self.aperture_mm))
                .collect();
            let margin = 4.0 * (h.aperture_distance_mm + h.origin_radius_mm) * step + 1.0;
            let reach_at = |x: &Hit| {
                0.5 * self.aperture_mm
                    + 0.5 * (h.exit_diameter_mm + h.divergence_mrad * 1e-3 * 2.0 * x.along_mm)
                    + margin
            };
            let near: Vec<bool> = hits
                .iter()
                .map(|x| x.is_some_and(|x| x.lateral_mm.abs() <= reach_at(&x)))
                .collect();
            let mut out = Vec::new();
            if near.iter().all(|&b| b) {
                out.push(Interval {
                    lo_s: -cyc,
                    hi_s: tf + cyc,
                    h_lo_mm: f64::NEG_INFINITY,
                    h_hi_mm: f64::INFINITY,
                });
                all.push(out);
                continue;
            }
            // Start at a far sample so no run wraps.
            let k0 = near.iter().position(|&b| !b).unwrap();
            let mut k = 0usize;
            while k < n {
                if !near[(k0 + k) % n] {
                    k += 1;
                    continue;
                }
                let start = k0 + k;
                let (mut h_lo, mut h_hi) = (f64::INFINITY, f64::NEG_INFINITY);
                while k < n && near[(k0 + k) % n] {
                    let x = hits[(k0 + k) % n].unwrap();
                    let r = reach_at(&x) + 2.0;
                    h_lo = h_lo.min(x.height_mm - r);
                    h_hi = h_hi.max(x.height_mm + r);
                    k += 1;
                }
                let end = k0 + k;
                let a = (start as f64 - 1.0) * step;
                let b = end as f64 * step;
                let ta = self.motion.time_of(a.rem_euclid(std::f64::consts::TAU));
                let mut tb = self.motion.time_of(b.rem_euclid(std::f64::consts::TAU));
                if tb <= ta {
                    tb += tf;
                }
                out.push(Interval {
                    lo_s: ta - cyc,
                    hi_s: tb + cyc,
                    h_lo_mm: h_lo,
                    h_hi_mm: h_hi,
                });
            }
            all.push(out);
        }
        all
    }

    /// Every pulse the aperture at `pos` receives from the clock of phase
    /// `t0`, complete on `[0, horizon)`; `ivs` from [`Self::intervals`] at
    /// `pos.azimuth_deg`.
    pub fn train(&self, pos: Pos, t0: f64, horizon_s: f64, ivs: &[Vec<Interval>]) -> Train {
        let tf = self.motion.period_s;
        let cyc = self.head.cycle_s;
        let mut pulses: Vec<(f64, f64)> = Vec::new();
        let mut mine: Vec<(i64, f64, f64)> = Vec::new();
        for (c, ch) in self.head.channels.iter().enumerate() {
            if ch.power_scale == 0.0 {
                continue;
            }
            let fast = Fast::new(&self.head, c, pos, self.aperture_mm);
            mine.clear();
            let turns = (horizon_s / tf).ceil() as i64 + 1;
            for iv in &ivs[c] {
                if pos.height_mm < iv.h_lo_mm || pos.height_mm > iv.h_hi_mm {
                    continue;
                }
                for q in -1..=turns {
                    let lo = q as f64 * tf + iv.lo_s;
                    let hi = q as f64 * tf + iv.hi_s;
                    if hi < 0.0 || lo >= horizon_s {
                        continue;
                    }
                    let base = t0 + ch.slot_s;
                    let mut k = ((lo.max(0.0) - base) / cyc).floor() as i64 - 1;
                    loop {
                        let t = base + k as f64 * cyc;
                        if t > hi || t >= horizon_s {
                            break;
                        }
                        let kk = k;
                        k += 1;
                        if t < lo.max(0.0) {
                            continue;
                        }
                        let (bin, theta) = self.motion.at(t);
                        let p = self.scan.bins[bin].power_w;
                        if p <= 0.0 {
                            continue;
                        }
                        if fast.overlaps(theta) {
                            mine.push((kk, t, ch.power_scale * p * cyc));
                        }
                    }
                }
            }
            // One firing found from two overlapping intervals is one pulse.
            mine.sort_by_key(|m| m.0);
            mine.dedup_by_key(|m| m.0);
            pulses.extend(mine.iter().map(|m| (m.1, m.2)));
        }
        pulses.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut tr = Train {
            horizon_s,
            ..Train::default()
        };
        for (t, e) in pulses {
            if tr.t.last() == Some(&t) {
                *tr.e.last_mut().unwrap() += e;
            } else {
                tr.t.push(t);
                tr.e.push(e);
            }
        }
        tr
    }

    /// The rules on one train. `first_turn_end`: windows and C5 counts
    /// start at pulses before it.
    pub fn evaluate(&self, tr: &Train, pos: Pos, t0: f64, starts_max: usize) -> OWorst {
        let mut best = OWorst {
            ratio: 0.0,
            rule: "none",
            pos,
            t0_s: t0,
            window_s: 0.0,
            energy_j: 0.0,
            pulses: 0,
        };
        let n = tr.t.len();
        if n == 0 {
            return best;
        }
        let tf = self.motion.period_s;
        let (band, c4) = (self.band, self.c4);
        let pulse_s = self.scan.pulse_s;
        let t_i = band.t_i_s();
        let tb = ael::TIME_BASE_S;
        let horizon = tr.horizon_s;
        let mut pre = Vec::with_capacity(n + 1);
        pre.push(0.0);
        for &e in &tr.e {
            pre.push(pre.last().unwrap() + e);
        }
        let t_first = tr.t[0];
        let first_end = tr.t.partition_point(|&t| t < t_first + tf);
        // Pass starts of the first turn: a gap of more than 100 T_i (and
        // 10 cycles) before.
        let gap = (100.0 * t_i).max(10.0 * self.head.cycle_s).min(0.25 * tf);
        let pass_starts: Vec<usize> = (0..first_end)
            .filter(|&i| i == 0 || tr.t[i] - tr.t[i - 1] > gap)
            .collect();
        // Rule 1: C5 from the greedy group count in [t, t + T2).
        let grouping = pulse_s <= t_i;
        let mut n_max = 0usize;
        for &i in &pass_starts {
            if tr.t[i] + ael::T2_S > horizon {
                continue;
            }
            let (mut cnt, mut group_end) = (0usize, f64::NEG_INFINITY);
            for &t in tr.t[i..].iter().take_while(|&&t| t < tr.t[i] + ael::T2_S) {
                // Groups a hair wider than T_i: never more groups than
                // any grouping of the standard's (C5 never below it).
                if !grouping || t > group_end {
                    cnt += 1;
                    group_end = t + t_i * (1.0 + 1e-9);
                }
            }
            n_max = n_max.max(cnt);
        }
        let c5 = if grouping {
            ael::c5(band, n_max as f64, ael::T2_S.min(tb))
        } else {
            1.0
        };
        let e_max = tr.e[..first_end.max(1)].iter().cloned().fold(0.0, f64::max);
        let r1 = e_max / (c5 * ael::table3_j(band, c4, pulse_s));
        if r1 > best.ratio {
            best = OWorst {
                ratio: r1,
                rule: "pulse",
                window_s: pulse_s,
                energy_j: e_max,
                pulses: 1,
                ..best
            };
        }
        if grouping {
            let ael_g = c5 * ael::table3_j(band, c4, t_i);
            let mut j = 0usize;
            for i in 0..first_end {
                j = j.max(i);
                // Pulses wholly inside [t_i, t_i + T_i].
                while j < n && tr.t[j] + pulse_s <= tr.t[i] + t_i {
                    j += 1;
                }
                if tr.t[i] + t_i > horizon {
                    break;
                }
                let e = pre[j] - pre[i];
                if j - i >= 2 && e / ael_g > best.ratio {
                    best = OWorst {
                        ratio: e / ael_g,
                        rule: "group",
                        window_s: t_i,
                        energy_j: e,
                        pulses: j - i,
                        ..best
                    };
                }
            }
        }
        // Rule 2: windows from one pulse to the time base.
        let mut starts: Vec<usize> = if first_end <= starts_max {
            (0..first_end).collect()
        } else {
            (0..starts_max)
                .map(|k| k * first_end / starts_max)
                .chain(pass_starts.iter().cloned())
                .collect()
        };
        starts.sort_unstable();
        starts.dedup();
        // Cluster ends: the last pulse before a gap.
        let ends: Vec<usize> = (0..n)
            .filter(|&j| j + 1 == n || tr.t[j + 1] - tr.t[j] > gap)
            .collect();
        let mut edges: Vec<f64> = ael::rows(band, c4)
            .iter()
            .map(|r| r.t_hi_s)
            .filter(|&e| e <= tb)
            .collect();
        edges.push(tb);
        edges.push(t_i);
        for &i in &starts {
            let ti = tr.t[i];
            // Every j within one turn, then every cluster end.
            let full_until = tr.t.partition_point(|&t| t < ti + tf);
            let consider = |j: usize, best: &mut OWorst| {
                let span = tr.t[j] - ti;
                let lo = span + pulse_s;
                let next = if j + 1 < n { tr.t[j + 1] } else { horizon };
                let hi = (next.min(horizon) - ti).min(tb);
                if lo > hi || lo > tb {
                    return;
                }
                let e = pre[j + 1] - pre[i];
                let a = ael::ael_inf_j(band, c4, lo, hi);
                if e / a > best.ratio {
                    *best = OWorst {
                        ratio: e / a,
                        rule: "window",
                        window_s: lo,
                        energy_j: e,
                        pulses: j + 1 - i,
                        ..*best
                    };
                }
            };
            for j in i..full_until {
                consider(j, &mut best);
            }
            let k0 = ends.partition_point(|&j| j < full_until);
            for &j in &ends[k0..] {
                if tr.t[j] - ti + pulse_s > tb {
                    break;
                }
                consider(j, &mut best);
            }
            // Windows of exactly every row edge and the time base.
            for &len in &edges {
                if ti + len > horizon {
                    continue;
                }
                let j = tr.t.partition_point(|&t| t + pulse_s <= ti + len);
                if j <= i {
                    continue;
                }
                let e = pre[j] - pre[i];
                let a = ael::table3_j(band, c4, len);
                if e / a > best.ratio {
                    best = OWorst {
                        ratio: e / a,
                        rule: "window",
                        window_s: len,
                        energy_j: e,
                        pulses: j - i,
                        ..best
                    };
                }
            }
        }
        best
    }

    /// The full horizon: one turn of starts, T2 and the time base after it.
    pub fn full_horizon_s(&self) -> f64 {
        2.0 * self.motion.period_s + ael::TIME_BASE_S.max(ael::T2_S) + 1e-6
    }

    /// The heights at which channel `c`'s footprint touches the aperture's
    /// edge at azimuth `phi` (± `eps` inside), from the ray's crossing of
    /// the plane where it passes closest to the centre horizontally.
    pub fn edge_heights(&self, c: usize, phi: f64, eps: f64) -> Vec<f64> {
        let pos = Pos {
            azimuth_deg: phi,
            height_mm: self.head.origin_height_mm,
        };
        let mut best: Option<Hit> = None;
        let n = 7200;
        for k in 0..n {
            let th = k as f64 / n as f64 * std::f64::consts::TAU;
            if let Some(hh) = hit(&self.head, c, th, pos, self.aperture_mm) {
                if best.is_none_or(|b| hh.lateral_mm.abs() < b.lateral_mm.abs()) {
                    best = Some(hh);
                }
            }
        }
        let Some(hh) = best else { return vec![] };
        let reach = 0.5 * self.aperture_mm
            + 0.5 * (self.head.exit_diameter_mm + self.head.divergence_mrad * 1e-3 * hh.along_mm);
        vec![
            hh.height_mm - reach + eps,
            hh.height_mm + reach - eps,
            hh.height_mm,
        ]
    }

    /// The aperture azimuth (deg) at which channel `c`'s ray crosses the
    /// cylinder of radius `aperture_distance_mm` (horizontally) with the head
    /// at `theta_deg`: where the channel passes when the head is there
    /// (azimuth offset and the parallax of the crossing point).
    pub fn pass_azimuth_deg(&self, c: usize, theta_deg: f64) -> f64 {
        let th = theta_deg.to_radians();
        let psi = th + self.head.channels[c].azimuth_offset_deg.to_radians();
        let o = [
            self.head.origin_radius_mm * th.cos(),
            self.head.origin_radius_mm * th.sin(),
        ];
        let d = [psi.cos(), psi.sin()];
        let od = o[0] * d[0] + o[1] * d[1];
        let oo = o[0] * o[0] + o[1] * o[1];
        let r = self.head.aperture_distance_mm;
        let s = -od + (od * od - oo + r * r).sqrt();
        (o[1] + s * d[1])
            .atan2(o[0] + s * d[0])
            .to_degrees()
            .rem_euclid(360.0)
    }

    /// A cheap proxy of a position (one turn's train at phase 0): the
    /// largest instant energy, the largest `T_i` group energy, the largest
    /// energy within half a turn.
    pub fn proxy(&self, pos: Pos, ivs: &[Vec<Interval>]) -> [f64; 3] {
        let tf = self.motion.period_s;
        let tr = self.train(pos, 0.0, 1.5 * tf, ivs);
        let mut out = [0.0f64; 3];
        let n = tr.t.len();
        let mut pre = vec![0.0];
        for &e in &tr.e {
            pre.push(pre.last().unwrap() + e);
            out[0] = out[0].max(e);
        }
        let (mut j1, mut j2) = (0usize, 0usize);
        for i in 0..n {
            while j1 < n && tr.t[j1] < tr.t[i] + self.band.t_i_s() {
                j1 += 1;
            }
            while j2 < n && tr.t[j2] < tr.t[i] + 0.5 * tf {
                j2 += 1;
            }
            out[1] = out[1].max(pre[j1] - pre[i]);
            out[2] = out[2].max(pre[j2] - pre[i]);
        }
        out
    }

    /// The worst over `positions`: every position's proxy, then the full
    /// rules at `effort.phases` clock phases on the `top_k` positions of
    /// each proxy (a sample: the result stays a lower bound).
    pub fn worst(&self, positions: &[Pos], effort: &Effort) -> OWorst {
        let timing = std::env::var_os("HEAD_ORACLE_TIMING").is_some();
        let clock = std::time::Instant::now();
        let mut cache: Vec<(f64, Vec<Vec<Interval>>)> = Vec::new();
        let mut ivs_of = |phi: f64| -> usize {
            match cache.iter().position(|(a, _)| *a == phi) {
                Some(k) => k,
                None => {
                    cache.push((phi, self.intervals(phi, effort.scan_step_deg)));
                    cache.len() - 1
                }
            }
        };
        let idx: Vec<usize> = positions.iter().map(|p| ivs_of(p.azimuth_deg)).collect();
        let proxies: Vec<[f64; 3]> = positions
            .iter()
            .zip(&idx)
            .map(|(&p, &k)| self.proxy(p, &cache[k].1))
            .collect();
        let mut chosen: Vec<usize> = Vec::new();
        for key in [
            |x: &[f64; 3]| x[0],
            |x: &[f64; 3]| x[1],
            |x: &[f64; 3]| x[2],
        ] {
            let mut idx: Vec<usize> = (0..positions.len()).collect();
            idx.sort_by(|&a, &b| key(&proxies[b]).total_cmp(&key(&proxies[a])));
            chosen.extend(idx.into_iter().take(effort.top_k));
        }
        chosen.sort_unstable();
        chosen.dedup();
        let horizon = self.full_horizon_s();
        if timing {
            eprintln!(
                "  oracle: {} proxies at {:?}",
                positions.len(),
                clock.elapsed()
            );
        }
        let mut best: Option<OWorst> = None;
        for &pi in &chosen {
            for ph in 0..effort.phases {
                let t0 = (ph as f64 + 0.31) / effort.phases as f64 * self.head.cycle_s;
                let tr = self.train(positions[pi], t0, horizon, &cache[idx[pi]].1);
                if timing {
                    eprintln!("  oracle: train of {} at {:?}", tr.t.len(), clock.elapsed());
                }
                let w = self.evaluate(&tr, positions[pi], t0, effort.starts_max);
                if timing {
                    eprintln!("  oracle: evaluated at {:?}", clock.elapsed());
                }
                if best.is_none_or(|b| w.ratio > b.ratio) {
                    best = Some(w);
                }
            }
        }
        best.expect("at least one position")
    }

    /// Positions: an azimuth list × (a height grid plus every channel's
    /// edge heights at each azimuth).
    pub fn positions(&self, azimuths: &[f64], height_grid: &[f64]) -> Vec<Pos> {
        let mut out = Vec::new();
        for &phi in azimuths {
            let mut hs: Vec<f64> = height_grid.to_vec();
            for c in 0..self.head.channels.len() {
                hs.extend(self.edge_heights(c, phi, 1e-6));
            }
            hs.sort_by(f64::total_cmp);
            hs.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
            out.extend(hs.into_iter().map(|h| Pos {
                azimuth_deg: phi,
                height_mm: h,
            }));
        }
        out
    }
}
