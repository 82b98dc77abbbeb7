//! Brute-force reference evaluator for the Class 1 eye-safety rules of a
//! scanned, pulsed beam (the profile@1 kinematics, constant angular acceleration within a
//! bin, as README's "The profile format" states them; IEC 60825-1:2014).
//!
//! Written independently of `crate::eye_safety`: it shares no code with
//! the crate (own kinematics, own AEL table, own pulse clock). It is slow and
//! plain on purpose.
//!
//! **Every value it reports is a true, achievable exposure ratio**: the
//! energy of a concrete set of pulses (fired by a concrete pulse clock, at
//! concrete times, received by an aperture at a concrete azimuth) inside a
//! concrete window, divided by the AEL of that window's own duration (the
//! span of its first and last pulse, at least the pulse duration). So the
//! result is a *lower bound* of the supremum a sound checker must bound;
//! any subset of apertures, clock phases or windows keeps it a lower bound,
//! the choices below only make it tight.
//!
//! Model (the brief of the differential test):
//! - head angle θ(t) exactly from the bins (ω² linear in angle inside a bin),
//!   periodic with the frame period `T_f = Σ dwell`;
//! - pulses at `t0 + k/f_p` (free-running clock), or, for a phase-locked
//!   clock, at `q·T_f + t0 + k/f_p` with `0 ≤ t0 + k/f_p < T_f` in turn `q`
//!   (the same azimuths every turn);
//! - a pulse carries `P(bin at firing time)/f_p` (bins are half-open
//!   `[start, end)` in time; a bin with zero power fires nothing);
//! - the aperture at φ receives a pulse iff θ(firing) ∈ [φ − h, φ + h]
//!   (closed), `h = ½(D_aperture + D_beam)/100 mm` rad, full energy counts;
//! - rule 1: every pulse ≤ C5·AEL(t_pulse); in 700–1050 nm pulses within
//!   `T_i = 5 µs` form a group compared with C5·AEL(T_i); C5 from the
//!   number N of pulses (groups) within 10 s — the reference uses a count it
//!   has actually seen (groups counted as `⌈K/g⌉` per pass, the fewest any
//!   grouping can give), so its C5 is never smaller than the true one;
//!   corneal bands C5 = 1;
//! - rule 2: energy in a window of duration T ≤ AEL(T), every T from one
//!   pulse to the 100 s time base; rule 3 is rule 2 at 100 s.

use std::fmt;

/// Spectral band (the columns of IEC 60825-1:2014 Table 3).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Band {
    /// 700–1050 nm.
    Nir,
    /// 1400–1500 nm (with the corrected 0.35–10 s row, 1e-2·t J).
    Ir1400,
    /// 1500–1800 nm.
    Ir1500,
}

impl Band {
    /// The band of `lambda_nm` (panics outside the three bands).
    pub fn of(lambda_nm: f64) -> Band {
        if (700.0..=1050.0).contains(&lambda_nm) {
            Band::Nir
        } else if (1400.0..1500.0).contains(&lambda_nm) {
            Band::Ir1400
        } else if (1500.0..=1800.0).contains(&lambda_nm) {
            Band::Ir1500
        } else {
            panic!("wavelength {lambda_nm} nm outside the reference's bands")
        }
    }
    /// The limiting aperture of the band, mm (7 in 700–1050 nm, 3.5 beyond).
    pub fn aperture_mm(self) -> f64 {
        match self {
            Band::Nir => 7.0,
            _ => 3.5,
        }
    }
    /// Durations where a row of the AEL table ends, s.
    pub fn breakpoints(self) -> &'static [f64] {
        match self {
            Band::Nir => &[5e-6, 10.0],
            Band::Ir1400 => &[1e-3, 0.35, 10.0],
            Band::Ir1500 => &[0.35, 10.0],
        }
    }
}

/// `t^0.75` as `√t · ⁴√t` (two correctly rounded square roots: within a few
/// ulp of `powf`, far inside the differential test's 1e-12, and several
/// times faster; `powf` was ~40 % of a long run's time).
fn pow_3_4(t: f64) -> f64 {
    let r = t.sqrt();
    r * r.sqrt()
}

/// Row `i` of the AEL table (J at duration `t`) and the duration where it ends.
fn row(band: Band, c4: f64, i: usize, t: f64) -> (f64, f64) {
    match (band, i) {
        (Band::Nir, 0) => (5e-6, 7.7e-8 * c4),
        (Band::Nir, 1) => (10.0, 7e-4 * c4 * pow_3_4(t)),
        (Band::Nir, _) => (f64::INFINITY, 3.9e-4 * c4 * t),
        (Band::Ir1400, 0) => (1e-3, 8e-4),
        (Band::Ir1400, 1) => (0.35, 4.4e-3 * t.sqrt().sqrt()),
        (Band::Ir1400, 2) => (10.0, 1e-2 * t),
        (Band::Ir1400, _) => (f64::INFINITY, 1e-2 * t),
        (Band::Ir1500, 0) => (0.35, 8e-3),
        (Band::Ir1500, 1) => (10.0, 1.8e-2 * pow_3_4(t)),
        (Band::Ir1500, _) => (f64::INFINITY, 1e-2 * t),
    }
}

/// Class 1 AEL (J) for an exposure of duration `t` (Table 3, C6 = C7 = 1,
/// no C5). At a row edge the more restrictive of the two rows.
pub fn ael_j(band: Band, c4: f64, t: f64) -> f64 {
    for i in 0.. {
        let (end, v) = row(band, c4, i, t);
        if t < end {
            return v;
        }
        if t == end {
            return v.min(row(band, c4, i + 1, t).1);
        }
    }
    unreachable!()
}

/// C5 for N pulses (groups) within T2 (700–1050 nm; 1 in the corneal bands).
pub fn c5(band: Band, n: f64) -> f64 {
    if band != Band::Nir || n <= 600.0 {
        1.0
    } else {
        (5.0 * n.powf(-0.25)).clamp(0.4, 1.0)
    }
}

/// T2 (the pulse-count horizon of C5), s.
pub const T2_S: f64 = 10.0;
/// The classification time base, s.
pub const TIME_BASE_S: f64 = 100.0;
/// T_i in 700–1050 nm (pulses within it form one group), s.
pub const T_I_NIR_S: f64 = 5e-6;

/// One bin as the reference reads it.
#[derive(Debug, Clone)]
pub struct RBin {
    /// Start azimuth, deg.
    pub start_deg: f64,
    /// Angular width, deg.
    pub width_deg: f64,
    /// Laser power, W.
    pub power_w: f64,
    /// Spin at the bin's start, rad/s.
    pub w0: f64,
    /// Spin at the bin's end, rad/s.
    pub w1: f64,
}

/// The scan as plain numbers.
#[derive(Debug, Clone)]
pub struct Scan {
    /// The bins in scan order.
    pub bins: Vec<RBin>,
    /// Pulse repetition rate, Hz.
    pub pulse_rate_hz: f64,
    /// Wavelength, nm.
    pub lambda_nm: f64,
    /// Pulse duration, s.
    pub pulse_s: f64,
    /// Beam diameter at the aperture, mm.
    pub beam_mm: f64,
}

impl Scan {
    /// A profile's bins and laser as plain numbers (public fields only).
    pub fn of_profile(p: &crate::profile::Profile) -> Self {
        let es = p.limits.eye_safety.as_ref().expect("eye_safety params");
        Scan {
            bins: p
                .bins
                .iter()
                .map(|b| RBin {
                    start_deg: b.start_deg,
                    width_deg: b.width_deg,
                    power_w: b.power_w,
                    w0: b.spin_start_rad_s,
                    w1: b.spin_end_rad_s,
                })
                .collect(),
            pulse_rate_hz: p.pulse_rate_hz,
            lambda_nm: es.wavelength_nm,
            pulse_s: es.pulse_duration_s,
            beam_mm: es.beam_diameter_mm,
        }
    }
}

/// Head kinematics: time at every bin start, period.
struct Head {
    bins: Vec<RBin>,
    acc: Vec<f64>,
    t_start: Vec<f64>,
    period: f64,
}

impl Head {
    fn new(bins: &[RBin]) -> Head {
        let mut t = 0.0;
        let mut t_start = Vec::with_capacity(bins.len());
        let mut acc = Vec::with_capacity(bins.len());
        for b in bins {
            t_start.push(t);
            let dth = b.width_deg.to_radians();
            acc.push((b.w1 * b.w1 - b.w0 * b.w0) / (2.0 * dth));
            t += 2.0 * dth / (b.w0 + b.w1);
        }
        Head {
            bins: bins.to_vec(),
            acc,
            t_start,
            period: t,
        }
    }
    /// Time to turn `x_rad` into bin `i` (constant angular acceleration).
    fn time_into(&self, i: usize, x_rad: f64) -> f64 {
        if x_rad <= 0.0 {
            return 0.0;
        }
        let b = &self.bins[i];
        let wx = (b.w0 * b.w0 + 2.0 * self.acc[i] * x_rad).max(0.0).sqrt();
        2.0 * x_rad / (b.w0 + wx)
    }
    fn bin_of(&self, deg: f64) -> usize {
        let n = self.bins.len();
        self.bins
            .partition_point(|b| b.start_deg <= deg)
            .saturating_sub(1)
            .min(n - 1)
    }
}

fn wrap(deg: f64) -> f64 {
    let x = deg.rem_euclid(360.0);
    if x >= 360.0 {
        0.0
    } else {
        x
    }
}

/// A piece of one pass inside one bin: times relative to the pass entry.
#[derive(Debug, Clone, Copy)]
struct Seg {
    u0: f64,
    u1: f64,
    power_w: f64,
    /// 1 if this piece lies in the turn after the pass entry's turn.
    next_turn: bool,
}

/// Where the aperture at `phi` sees the beam: entry time in the turn and the
/// pieces of the pass.
struct PassGeom {
    t_in: f64,
    segs: Vec<Seg>,
}

fn pass_geom(head: &Head, phi_deg: f64, h_deg: f64) -> PassGeom {
    let n = head.bins.len();
    let alpha = wrap(phi_deg - h_deg);
    let mut i = head.bin_of(alpha);
    let b = &head.bins[i];
    let x_in = (alpha - b.start_deg).clamp(0.0, b.width_deg);
    let t_in = head.t_start[i] + head.time_into(i, x_in.to_radians());
    let mut remaining = 2.0 * h_deg;
    let mut pos = x_in; // degrees into bin i
    let mut u = 0.0;
    let mut next_turn = false;
    let mut segs = Vec::new();
    loop {
        let b = &head.bins[i];
        let end = (pos + remaining).min(b.width_deg);
        let t_a = head.time_into(i, pos.to_radians());
        let t_b = head.time_into(i, end.to_radians());
        let dt = (t_b - t_a).max(0.0);
        segs.push(Seg {
            u0: u,
            u1: u + dt,
            power_w: b.power_w,
            next_turn,
        });
        u += dt;
        remaining -= end - pos;
        if remaining <= 0.0 {
            break;
        }
        i += 1;
        if i == n {
            i = 0;
            next_turn = true;
        }
        pos = 0.0;
    }
    PassGeom { t_in, segs }
}

/// The pulse clock.
#[derive(Debug, Clone, Copy)]
pub enum Clock {
    /// Pulses at `t0 + k/f_p`, every integer k.
    Free {
        /// Phase of pulse 0, s.
        t0: f64,
    },
    /// Pulses at `q·T_f + t0 + k/f_p`, `0 ≤ t0 + k/f_p < T_f`, `t0 ∈ [0, 1/f_p)`.
    PerTurn {
        /// Phase of pulse 0 within the turn, s.
        t0: f64,
    },
}

/// A run of consecutive pulses of equal energy.
#[derive(Debug, Clone, Copy)]
struct Run {
    t_first: f64,
    n: u64,
    e: f64,
}

/// Pulses received by one aperture over the horizon, for one clock.
struct Train {
    fp: f64,
    runs: Vec<Run>,
    cum_e: Vec<f64>, // cum_e[r] = energy of runs < r
    /// Per pass: [first run, end run), pulses, energy, first/last pulse time.
    pass_runs: Vec<(usize, usize)>,
    pass_k: Vec<u64>,
    pass_e: Vec<f64>,
    pass_first: Vec<f64>,
    pass_last: Vec<f64>,
}

impl Train {
    fn build(head: &Head, geom: &PassGeom, fp: f64, clock: Clock, passes: usize) -> Train {
        let tf = head.period;
        let mut runs = Vec::new();
        let mut pass_runs = Vec::with_capacity(passes);
        let (mut pass_k, mut pass_e, mut pass_first, mut pass_last) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let nseg = geom.segs.len();
        for m in 0..passes {
            let s = m as f64 * tf + geom.t_in;
            let r0 = runs.len();
            let (mut k_tot, mut e_tot) = (0u64, 0.0);
            for (j, sg) in geom.segs.iter().enumerate() {
                let a = s + sg.u0;
                let b = s + sg.u1;
                let closed = j + 1 == nseg;
                let turn = m + usize::from(sg.next_turn);
                let (first, n) = ticks(clock, fp, tf, turn, a, b, closed);
                if n == 0 || sg.power_w <= 0.0 {
                    continue;
                }
                let e = sg.power_w / fp;
                runs.push(Run {
                    t_first: first,
                    n,
                    e,
                });
                k_tot += n;
                e_tot += e * n as f64;
            }
            pass_runs.push((r0, runs.len()));
            pass_k.push(k_tot);
            pass_e.push(e_tot);
            if runs.len() > r0 {
                let last = runs[runs.len() - 1];
                pass_first.push(runs[r0].t_first);
                pass_last.push(last.t_first + (last.n - 1) as f64 / fp);
            } else {
                pass_first.push(f64::NAN);
                pass_last.push(f64::NAN);
            }
        }
        let mut cum_e = Vec::with_capacity(runs.len() + 1);
        let mut c = 0.0;
        cum_e.push(0.0);
        for r in &runs {
            c += r.e * r.n as f64;
            cum_e.push(c);
        }
        Train {
            fp,
            runs,
            cum_e,
            pass_runs,
            pass_k,
            pass_e,
            pass_first,
            pass_last,
        }
    }

    fn run_last(&self, r: &Run) -> f64 {
        r.t_first + (r.n - 1) as f64 / self.fp
    }

    /// Pulses of run `r` with time in [t1, t2] (tolerance 1e-6 pulse
    /// spacings: which pulses are included decides only *which* concrete
    /// window is evaluated; its span is taken from the pulses themselves).
    fn run_slice(&self, r: &Run, t1: f64, t2: f64) -> Option<(u64, u64)> {
        const TOL: f64 = 1e-6;
        let lo = ((t1 - r.t_first) * self.fp - TOL).ceil().max(0.0);
        let hi = ((t2 - r.t_first) * self.fp + TOL)
            .floor()
            .min((r.n - 1) as f64);
        (hi >= lo).then_some((lo as u64, hi as u64))
    }

    /// The pulses with time in [t1, t2]: (energy, count, first time, last time).
    fn window(&self, t1: f64, t2: f64) -> Option<(f64, u64, f64, f64)> {
        let tol = 1e-6 / self.fp;
        // First run whose last pulse is >= t1, last run whose first pulse is <= t2.
        let lo = self.runs.partition_point(|r| self.run_last(r) < t1 - tol);
        let hi = self.runs.partition_point(|r| r.t_first <= t2 + tol);
        if lo >= hi {
            return None;
        }
        let (mut e, mut n) = (0.0, 0u64);
        let mut first = f64::NAN;
        let last;
        let rl = &self.runs[lo];
        let (a, b) = self.run_slice(rl, t1, t2)?;
        first = first.min(rl.t_first + a as f64 / self.fp);
        if lo + 1 == hi {
            e += rl.e * (b - a + 1) as f64;
            n += b - a + 1;
            last = rl.t_first + b as f64 / self.fp;
            return Some((e, n, first, last));
        }
        e += rl.e * (b - a + 1) as f64;
        n += b - a + 1;
        e += self.cum_e[hi - 1] - self.cum_e[lo + 1];
        n += self.runs[lo + 1..hi - 1].iter().map(|r| r.n).sum::<u64>();
        let rh = &self.runs[hi - 1];
        if let Some((a2, b2)) = self.run_slice(rh, t1, t2) {
            e += rh.e * (b2 - a2 + 1) as f64;
            n += b2 - a2 + 1;
            last = rh.t_first + b2 as f64 / self.fp;
        } else {
            let r = &self.runs[hi - 2];
            last = self.run_last(r);
        }
        Some((e, n, first, last))
    }

    /// First pulse strictly after `t` (beyond tolerance).
    fn pulse_after(&self, t: f64) -> Option<f64> {
        let tol = 1e-6 / self.fp;
        let r = self.runs.partition_point(|r| self.run_last(r) <= t + tol);
        let run = self.runs.get(r)?;
        let k = ((t - run.t_first) * self.fp + 1e-6).floor() + 1.0;
        Some(run.t_first + k.max(0.0) / self.fp)
    }

    /// Last pulse strictly before `t`.
    fn pulse_before(&self, t: f64) -> Option<f64> {
        let tol = 1e-6 / self.fp;
        let r = self.runs.partition_point(|r| r.t_first < t - tol);
        let run = self.runs.get(r.checked_sub(1)?)?;
        let k = ((t - run.t_first) * self.fp - 1e-6).ceil() - 1.0;
        Some(run.t_first + k.min((run.n - 1) as f64) / self.fp)
    }

    /// Every window from a run boundary (first or last pulse of a run in
    /// `starts`) to a later run boundary of a run before `end_run`:
    /// `f(energy, span)`. Runs are contiguous pulses in time order, so the
    /// energy is a difference of prefix sums minus the excluded pulses of
    /// the two end runs.
    fn boundary_windows(
        &self,
        starts: std::ops::Range<usize>,
        end_run: usize,
        mut f: impl FnMut(f64, f64),
    ) {
        let sp = 1.0 / self.fp;
        for r1 in starts {
            let a = &self.runs[r1];
            for s1 in 0..2u64 {
                if s1 == 1 && a.n == 1 {
                    continue;
                }
                let t1 = a.t_first + (s1 * (a.n - 1)) as f64 * sp;
                for r2 in r1..end_run {
                    let b = &self.runs[r2];
                    for s2 in 0..2u64 {
                        if s2 == 1 && b.n == 1 {
                            continue;
                        }
                        let t2 = b.t_first + (s2 * (b.n - 1)) as f64 * sp;
                        let e = if r1 == r2 {
                            match (s1, s2) {
                                (0, 0) | (1, 1) => a.e,
                                (0, 1) => a.e * a.n as f64,
                                _ => continue,
                            }
                        } else {
                            self.cum_e[r2 + 1]
                                - self.cum_e[r1]
                                - if s1 == 1 { a.e * (a.n - 1) as f64 } else { 0.0 }
                                - if s2 == 0 { b.e * (b.n - 1) as f64 } else { 0.0 }
                        };
                        f(e, t2 - t1);
                    }
                }
            }
        }
    }

    /// Run boundaries (first and last pulse of every run) of pass `m`.
    fn b_points(&self, m: usize) -> Vec<f64> {
        let (r0, r1) = self.pass_runs[m];
        let mut v = Vec::new();
        for r in &self.runs[r0..r1] {
            v.push(r.t_first);
            v.push(self.run_last(r));
        }
        v
    }
}

/// Pulses of the clock in [a, b) (or [a, b] if `closed`): first time, count.
fn ticks(clock: Clock, fp: f64, tf: f64, turn: usize, a: f64, b: f64, closed: bool) -> (f64, u64) {
    let (base, k_min, k_max) = match clock {
        Clock::Free { t0 } => (t0, f64::NEG_INFINITY, f64::INFINITY),
        Clock::PerTurn { t0 } => {
            // Pulses of this turn: k = 0 .. K−1 with t0 + k/fp < T_f.
            let k_turn = ((tf - t0) * fp).ceil();
            (turn as f64 * tf + t0, 0.0, k_turn - 1.0)
        }
    };
    let lo = ((a - base) * fp).ceil().max(k_min);
    let hi_raw = if closed {
        ((b - base) * fp).floor()
    } else {
        ((b - base) * fp).ceil() - 1.0
    };
    let hi = hi_raw.min(k_max);
    if hi < lo {
        return (f64::NAN, 0);
    }
    (base + lo / fp, (hi - lo + 1.0) as u64)
}

/// Which rule a worst value belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RuleKind {
    /// Rule 1: pulse or T_i group against C5·AEL.
    Pulse,
    /// Rule 2: a window inside one pass or two neighbouring passes.
    ShortWindow,
    /// Rule 2: a window anchored at a pulse and an AEL breakpoint duration.
    BreakpointWindow,
    /// Rule 2/3: whole passes.
    PassesWindow,
}

/// The worst exposure the reference found.
#[derive(Debug, Clone, Copy)]
pub struct Worst {
    /// Exposure over its limit.
    pub ratio: f64,
    /// The rule it is measured against.
    pub rule: RuleKind,
    /// The aperture's azimuth, deg.
    pub azimuth_deg: f64,
    /// Window duration (rule 2) or N (rule 1).
    pub detail: f64,
    /// Energy received, J.
    pub energy_j: f64,
    /// The pulse clock that fired it.
    pub clock: Clock,
}

impl fmt::Display for Worst {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{:.6} ({:?} at {:.6}°, {} {:.6e}, energy {:.6e} J, {:?})",
            self.ratio,
            self.rule,
            self.azimuth_deg,
            if self.rule == RuleKind::Pulse {
                "N"
            } else {
                "T"
            },
            self.detail,
            self.energy_j,
            self.clock
        )
    }
}

/// How hard to look.
#[derive(Debug, Clone, Copy)]
pub struct Effort {
    /// Clock phases spread over one pulse spacing (plus the aligned ones).
    pub phases: usize,
    /// Apertures taken from the screening into the full evaluation, per category.
    pub top_per_category: usize,
    /// Uniform grid points over 360° for the aperture positions.
    pub grid: usize,
    /// Phase-locked clock (pulses at the same azimuths every turn).
    pub locked: bool,
}

impl Default for Effort {
    fn default() -> Self {
        Effort {
            phases: 8,
            top_per_category: 1,
            grid: 360,
            locked: false,
        }
    }
}

/// The reference evaluator.
pub struct Reference {
    head: Head,
    band: Band,
    c4: f64,
    fp: f64,
    pulse_s: f64,
    h_deg: f64,
    /// Pulses per T_i group (700–1050 nm), 1 otherwise.
    g: u64,
}

impl Reference {
    /// The reference for `scan`.
    pub fn new(scan: &Scan) -> Reference {
        let band = Band::of(scan.lambda_nm);
        let c4 = if band == Band::Nir {
            10f64.powf(0.002 * (scan.lambda_nm - 700.0))
        } else {
            1.0
        };
        let h_rad = 0.5 * (band.aperture_mm() + scan.beam_mm) / 100.0;
        let g = if band == Band::Nir {
            (T_I_NIR_S * scan.pulse_rate_hz).floor() as u64 + 1
        } else {
            1
        };
        Reference {
            head: Head::new(&scan.bins),
            band,
            c4,
            fp: scan.pulse_rate_hz,
            pulse_s: scan.pulse_s,
            h_deg: h_rad.to_degrees(),
            g,
        }
    }

    /// The frame period `T_f = Σ dwell`, s.
    pub fn period_s(&self) -> f64 {
        self.head.period
    }
    /// Half the angle over which one aperture receives the beam, deg.
    pub fn half_pass_deg(&self) -> f64 {
        self.h_deg
    }

    fn ael(&self, t: f64) -> f64 {
        ael_j(self.band, self.c4, t)
    }

    /// Dense aperture positions: every bin edge (spin extremes sit on bin
    /// edges: ω² is linear, hence monotone, inside a bin), every bin edge
    /// ± h ± tiny epsilons, bin centres, and a uniform grid.
    pub fn positions(&self, grid: usize) -> Vec<f64> {
        let h = self.h_deg;
        let mut v = Vec::new();
        for b in &self.head.bins {
            let e = b.start_deg;
            v.push(wrap(e));
            v.push(wrap(b.start_deg + 0.5 * b.width_deg));
            for s in [h, -h] {
                for eps in [0.0, 1e-9, -1e-9] {
                    v.push(wrap(e + s + eps));
                }
            }
        }
        for k in 0..grid {
            v.push(360.0 * (k as f64 + 0.5) / grid as f64);
        }
        v.sort_by(f64::total_cmp);
        v.dedup();
        v
    }

    /// Clock phases: spread over one spacing, plus phases that put a pulse
    /// just inside the pass entry and at every piece boundary of pass 0.
    fn clocks(&self, geom: &PassGeom, effort: &Effort) -> Vec<Clock> {
        let sp = 1.0 / self.fp;
        let mut t0s: Vec<f64> = (0..effort.phases)
            .map(|j| (j as f64 + 0.37) / effort.phases as f64 * sp)
            .collect();
        // Aligned phases: the pass entry and the starts of the three
        // hottest pieces (a pulse just inside each).
        let mut hot: Vec<&Seg> = geom.segs.iter().filter(|s| s.u1 > s.u0).collect();
        hot.sort_by(|a, b| b.power_w.total_cmp(&a.power_w));
        hot.truncate(3);
        if let Some(first) = geom.segs.first() {
            hot.insert(0, first);
        }
        for sg in hot {
            // Free clock: absolute time of pass 0's piece; locked clock:
            // time from the start of the piece's own turn.
            let t = geom.t_in + sg.u0;
            let t = if effort.locked && sg.next_turn {
                t - self.head.period
            } else {
                t
            };
            let frac = (t * self.fp).rem_euclid(1.0);
            t0s.push(((frac + 1e-7) % 1.0) * sp);
        }
        t0s.into_iter()
            .map(|t0| {
                if effort.locked {
                    Clock::PerTurn { t0 }
                } else {
                    Clock::Free { t0 }
                }
            })
            .collect()
    }

    /// Full evaluation of one aperture for one clock over the time base.
    fn evaluate(
        &self,
        phi: f64,
        geom: &PassGeom,
        clock: Clock,
        horizon_passes: usize,
    ) -> Vec<Worst> {
        let tf = self.head.period;
        let tr = Train::build(&self.head, geom, self.fp, clock, horizon_passes);
        let mut out: Vec<Worst> = Vec::new();
        let mut best = [f64::NEG_INFINITY; 4];
        let mut push = |out: &mut Vec<Worst>, w: Worst| {
            let i = w.rule as usize;
            if w.ratio > best[i] {
                best[i] = w.ratio;
                out.push(w);
            }
        };
        let mk = |ratio, rule, detail, energy_j| Worst {
            ratio,
            rule,
            azimuth_deg: phi,
            detail,
            energy_j,
            clock,
        };
        let m_total = tr.pass_k.len();
        if tr.runs.is_empty() {
            return out;
        }
        let t_end_all = tr.run_last(tr.runs.last().unwrap());
        let span_ael = |span: f64| self.ael(span.max(self.pulse_s));
        let window = |t1: f64, t2: f64| -> Option<(f64, f64)> {
            let (e, _, a, b) = tr.window(t1, t2)?;
            Some((e, b - a))
        };

        // --- Rule 1: N, the most groups seen within any T2 window.
        let g = self.g;
        let groups = |k: u64| k.div_ceil(g);
        let mut gpre = vec![0u64; m_total + 1];
        for m in 0..m_total {
            gpre[m + 1] = gpre[m] + groups(tr.pass_k[m]);
        }
        let mut n_max = 0u64;
        let mut b = 0usize;
        for a in 0..m_total {
            if tr.pass_k[a] == 0 {
                continue;
            }
            let t_end = tr.pass_first[a] + T2_S;
            if t_end > t_end_all {
                break; // the window must lie inside the simulated horizon
            }
            b = b.max(a);
            while b + 1 < m_total && (tr.pass_k[b + 1] == 0 || tr.pass_last[b + 1] <= t_end) {
                b += 1;
            }
            let mut n = gpre[b + 1] - gpre[a];
            if b + 1 < m_total {
                if let Some((_, k, _, _)) = tr.window(tr.pass_first[b + 1] - 1e-9, t_end) {
                    n += groups(k);
                }
            }
            n_max = n_max.max(n);
        }
        let c5 = c5(self.band, n_max as f64);
        // Largest single pulse, and (700–1050 nm) largest T_i group.
        let e_pulse = tr.runs.iter().map(|r| r.e).fold(0.0, f64::max);
        push(
            &mut out,
            mk(
                e_pulse / (c5 * self.ael(self.pulse_s)),
                RuleKind::Pulse,
                n_max as f64,
                e_pulse,
            ),
        );
        if g > 1 {
            let short = 8.min(m_total);
            let r_end = tr.pass_runs[short - 1].1;
            for r in &tr.runs[..r_end] {
                for (t1, t2) in [
                    (r.t_first, r.t_first + T_I_NIR_S),
                    (tr.run_last(r) - T_I_NIR_S, tr.run_last(r)),
                ] {
                    if let Some((e, k, a, b)) = tr.window(t1, t2) {
                        if k >= 2 && b - a <= T_I_NIR_S {
                            let lim = c5 * self.ael(T_I_NIR_S);
                            push(&mut out, mk(e / lim, RuleKind::Pulse, n_max as f64, e));
                        }
                    }
                }
            }
        }

        // --- Rule 2 (a): pairs of run boundaries within a pass and the next.
        let short_passes = 3.min(m_total);
        for m in 0..short_passes {
            let bs = tr.b_points(m);
            let mut ends = bs.clone();
            if m + 1 < m_total {
                ends.extend(tr.b_points(m + 1));
            }
            let _ = (&bs, &ends);
            let (r0, r1) = tr.pass_runs[m];
            let r2 = if m + 1 < m_total {
                tr.pass_runs[m + 1].1
            } else {
                r1
            };
            tr.boundary_windows(r0..r1, r2, |e, span| {
                push(
                    &mut out,
                    mk(e / span_ael(span), RuleKind::ShortWindow, span, e),
                );
            });
        }

        // --- Rule 2 (b): windows of an AEL breakpoint duration anchored at
        // a pulse (and one pulse beyond it), both directions.
        let mut taus: Vec<f64> = self.band.breakpoints().to_vec();
        taus.push(TIME_BASE_S);
        let mut starts: Vec<f64> = Vec::new();
        for m in 0..short_passes {
            starts.extend(tr.b_points(m));
        }
        let stride = (m_total / 64).max(1);
        for m in (0..m_total).step_by(stride) {
            if tr.pass_k[m] > 0 {
                starts.push(tr.pass_first[m]);
            }
        }
        for &tau in &taus {
            for &t1 in &starts {
                let t2 = t1 + tau;
                if t2 > t_end_all {
                    continue;
                }
                for t2x in [Some(t2), tr.pulse_after(t2)] {
                    let Some(t2x) = t2x else { continue };
                    if let Some((e, span)) = window(t1, t2x) {
                        push(
                            &mut out,
                            mk(e / span_ael(span), RuleKind::BreakpointWindow, span, e),
                        );
                    }
                }
            }
            // Anchored at the end: the last pulse of a pass.
            for m in (0..m_total).step_by(stride) {
                if tr.pass_k[m] == 0 {
                    continue;
                }
                let t2 = tr.pass_last[m];
                let t1 = t2 - tau;
                if t1 < tr.runs[0].t_first {
                    continue;
                }
                for t1x in [Some(t1), tr.pulse_before(t1)] {
                    let Some(t1x) = t1x else { continue };
                    if let Some((e, span)) = window(t1x, t2) {
                        push(
                            &mut out,
                            mk(e / span_ael(span), RuleKind::BreakpointWindow, span, e),
                        );
                    }
                }
            }
        }

        // --- Rule 2 (c) and rule 3: whole passes a..a+m−1 for m near every
        // AEL breakpoint and the time base, every start pass.
        let mut epre = vec![0.0; m_total + 1];
        for m in 0..m_total {
            epre[m + 1] = epre[m] + tr.pass_e[m];
        }
        let f = 1.0 / tf;
        let mut ms: Vec<usize> = vec![1, 2, 3];
        for &tau in taus.iter() {
            let mstar = (tau * f).floor() as i64 + 1;
            for d in -2..=2 {
                let m = mstar + d;
                if m >= 1 {
                    ms.push(m as usize);
                }
            }
        }
        ms.sort_unstable();
        ms.dedup();
        for &m in &ms {
            if m > m_total {
                continue;
            }
            for a in 0..=(m_total - m) {
                let b = a + m - 1;
                if tr.pass_k[a] == 0 || tr.pass_k[b] == 0 {
                    continue;
                }
                let span = tr.pass_last[b] - tr.pass_first[a];
                if span > TIME_BASE_S {
                    continue;
                }
                let e = epre[b + 1] - epre[a];
                push(
                    &mut out,
                    mk(e / span_ael(span), RuleKind::PassesWindow, span, e),
                );
            }
        }
        out
    }

    /// Cheap screening of one aperture: one clock, three passes, and the
    /// multi-pass windows extrapolated from them. Only used to choose which
    /// apertures get the full evaluation; never reported.
    fn screen(&self, geom: &PassGeom, locked: bool) -> [f64; 4] {
        let mut best = [0.0f64; 4];
        let effort = Effort {
            phases: 1,
            locked,
            ..Effort::default()
        };
        let clocks = self.clocks(geom, &effort);
        // The uniform phase, the entry-aligned and the hottest-piece-aligned.
        for clock in clocks.iter().take(3) {
            let s = self.screen_one(geom, *clock);
            for i in 0..3 {
                best[i] = best[i].max(s[i]);
            }
        }
        // Long windows with the mean (time-integral) pass energy: what a
        // free-running clock delivers over many passes.
        let e_cont: f64 = geom.segs.iter().map(|s| (s.u1 - s.u0) * s.power_w).sum();
        let w = geom.segs.last().map_or(0.0, |s| s.u1);
        let tf = self.head.period;
        let mut taus: Vec<f64> = self.band.breakpoints().to_vec();
        taus.push(TIME_BASE_S);
        for tau in taus {
            let m = ((tau - w) / tf).floor().max(0.0) + 1.0;
            for mm in [m, m + 1.0] {
                let span = (mm - 1.0) * tf + w;
                best[3] = best[3].max(mm * e_cont / self.ael(span.max(self.pulse_s)));
            }
        }
        best
    }

    fn screen_one(&self, geom: &PassGeom, clock: Clock) -> [f64; 3] {
        let tf = self.head.period;
        let tr = Train::build(&self.head, geom, self.fp, clock, 3);
        if tr.runs.is_empty() {
            return [0.0; 3];
        }
        let e_pulse = tr.runs.iter().map(|r| r.e).fold(0.0, f64::max);
        let k_max = *tr.pass_k.iter().max().unwrap();
        let e_max = tr.pass_e.iter().cloned().fold(0.0, f64::max);
        let n_est = (k_max.div_ceil(self.g)) as f64 * ((T2_S / tf).floor() + 1.0);
        let group = self.g.min(k_max).max(1) as f64;
        let r1 = e_pulse * group / (c5(self.band, n_est) * self.ael(self.pulse_s));
        let mut r2 = 0.0f64;
        let (a0, a1) = tr.pass_runs[0];
        tr.boundary_windows(a0..a1, a1, |e, span| {
            r2 = r2.max(e / self.ael(span.max(self.pulse_s)));
        });
        let w = (tr.pass_last[0] - tr.pass_first[0]).max(0.0);
        let mut r3 = 0.0f64;
        let mut taus: Vec<f64> = self.band.breakpoints().to_vec();
        taus.push(TIME_BASE_S);
        for tau in taus {
            let m = ((tau - w) / tf).floor().max(0.0) + 1.0;
            for mm in [m, m + 1.0] {
                let span = (mm - 1.0) * tf + w;
                r3 = r3.max(mm * e_max / self.ael(span.max(self.pulse_s)));
            }
        }
        [r1, r2, r3]
    }

    /// The worst ratio found over the dense aperture positions, the chosen
    /// clock phases and the candidate windows.
    pub fn worst(&self, effort: &Effort) -> Worst {
        let start = std::time::Instant::now();
        let positions = self.positions(effort.grid);
        let mut scored: Vec<(f64, [f64; 4])> = positions
            .iter()
            .map(|&phi| {
                (
                    phi,
                    self.screen(&pass_geom(&self.head, phi, self.h_deg), effort.locked),
                )
            })
            .collect();
        let mut chosen: Vec<f64> = Vec::new();
        for cat in 0..5 {
            let key = |s: &[f64; 4]| {
                if cat == 4 {
                    s[0].max(s[1]).max(s[2]).max(s[3])
                } else {
                    s[cat]
                }
            };
            scored.sort_by(|a, b| key(&b.1).total_cmp(&key(&a.1)));
            let take = if cat == 4 {
                effort.top_per_category + 1
            } else {
                effort.top_per_category
            };
            for s in scored.iter().take(take) {
                if !chosen.contains(&s.0) {
                    chosen.push(s.0);
                }
            }
        }
        let screened = std::time::Instant::now();
        if std::env::var_os("GAZE_LIDAR_REF_TIMING").is_some() {
            eprintln!(
                "screen {} positions: {:?}",
                positions.len(),
                screened.duration_since(start)
            );
        }
        let horizon = ((TIME_BASE_S + T2_S) / self.head.period).ceil() as usize + 3;
        let mut worst: Option<Worst> = None;
        for &phi in &chosen {
            let geom = pass_geom(&self.head, phi, self.h_deg);
            for clock in self.clocks(&geom, effort) {
                for w in self.evaluate(phi, &geom, clock, horizon) {
                    if worst.is_none_or(|x| w.ratio > x.ratio) {
                        worst = Some(w);
                    }
                }
            }
        }
        if std::env::var_os("GAZE_LIDAR_REF_TIMING").is_some() {
            eprintln!("full {} positions: {:?}", chosen.len(), screened.elapsed());
        }
        worst.expect("at least one aperture receives a pulse")
    }

    /// Full evaluation at given apertures (for the constructed cases).
    pub fn worst_at(&self, phis: &[f64], effort: &Effort) -> Worst {
        let horizon = ((TIME_BASE_S + T2_S) / self.head.period).ceil() as usize + 3;
        let mut worst: Option<Worst> = None;
        for &phi in phis {
            let geom = pass_geom(&self.head, phi, self.h_deg);
            for clock in self.clocks(&geom, effort) {
                for w in self.evaluate(phi, &geom, clock, horizon) {
                    if worst.is_none_or(|x| w.ratio > x.ratio) {
                        worst = Some(w);
                    }
                }
            }
        }
        worst.expect("at least one aperture receives a pulse")
    }
}
