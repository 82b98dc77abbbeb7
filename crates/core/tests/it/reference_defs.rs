//! Second brute-force reference for the Class 1 rules of a scanned, pulsed
//! beam, written from the standard's **definitions** (IEC 60825-1:2014:
//! Table 3, Table 10, C5 and T_i, read row by row), not from the bound nor from the first
//! reference (`crates/core/src/testing/reference.rs`): it shares no code and no modelling
//! shortcut with either.
//!
//! - **Explicit pulse trains.** Every pulse is a clock tick `t0 + k/f_p`
//!   (free-running) or `q·T_f + t0 + k/f_p`, `0 ≤ t0 + k/f_p < T_f`
//!   (locked to the turn); its azimuth is the head's angle at that instant by
//!   forward kinematics (`θ = θ_s + ω_0·u + ½a·u²` inside the bin whose
//!   half-open time interval holds it), its energy the bin's power over
//!   `f_p`. The aperture at φ receives it iff `|θ − φ| ≤ h` (closed,
//!   `h = ½(D + d_beam)/100 mm`). Which ticks are candidates is found by
//!   inverting the motion, widened by two ticks; whether one is received is
//!   decided by the forward angle alone.
//! - **Windows by definition.** For every length `T` of a dense grid from
//!   the pulse duration to the 100 s time base — a log grid, every Table 3
//!   and Table 10 row edge and the edge `· (1 ± 1e-9)`, the spans of 2 to
//!   many pulses just exceeded, whole-pass and multi-pass lengths — the
//!   half-open windows `[t, t + T)` starting at every received pulse of
//!   the first passes, with the energy of the pulses inside, against
//!   **AEL(T), the AEL at the window's own length**, with **Table 10's
//!   aperture at that length** (1 mm to 0.35 s, `1.5·T^0.375` mm to 10 s,
//!   3.5 mm beyond, for 1400–4000 nm; 7 mm for 700–1050 nm). No window is
//!   replaced by the span of its pulses: a window longer than its pulses'
//!   span is evaluated at its own, possibly smaller, AEL.
//! - **Rule 1.** The largest received pulse against `C5·AEL(t_pulse)`; in
//!   700–1050 nm (pulses no longer than `T_i` = 5 µs) also the energy of
//!   every window `[t, t + T_i)` against `C5·AEL(T_i)`; `C5` from the most
//!   effective pulses seen in a window `[t, t + T2)` starting at a pass's
//!   first pulse, pulses within `T_i` grouped by the greedy cover (the
//!   fewest groups any grouping gives: the largest C5, so never above the
//!   true ratio).
//!
//! Every value it reports is the energy of concrete pulses in a concrete
//! window over that window's AEL: a true exposure ratio, so a lower bound of
//! the supremum a sound checker bounds.

#![allow(dead_code)]

/// Spectral band.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DBand {
    /// 700–1050 nm.
    Nir,
    /// 1400–1500 nm.
    Ir1400,
    /// 1500–1800 nm.
    Ir1500,
}

impl DBand {
    pub fn of(lambda_nm: f64) -> DBand {
        if (700.0..=1050.0).contains(&lambda_nm) {
            DBand::Nir
        } else if (1400.0..1500.0).contains(&lambda_nm) {
            DBand::Ir1400
        } else if (1500.0..=1800.0).contains(&lambda_nm) {
            DBand::Ir1500
        } else {
            panic!("{lambda_nm} nm: outside the definitions reference's bands")
        }
    }
}

/// Table 3, Class 1, C6 = C7 = 1, for an exposure of `t` s, J: the row
/// whose open interval holds `t`; on a row edge the smaller of the two rows.
pub fn def_ael_j(band: DBand, lambda_nm: f64, t: f64) -> f64 {
    let c4 = 10f64.powf(0.002 * (lambda_nm - 700.0));
    // (row end, value of the row at t) in time order; the last row is open.
    let rows: Vec<(f64, f64)> = match band {
        DBand::Nir => vec![
            (5e-6, 7.7e-8 * c4),
            (10.0, 7e-4 * c4 * t.powf(0.75)),
            (f64::INFINITY, 3.9e-4 * c4 * t),
        ],
        DBand::Ir1400 => vec![
            (1e-3, 8e-4),
            (0.35, 4.4e-3 * t.powf(0.25)),
            (f64::INFINITY, 1e-2 * t),
        ],
        DBand::Ir1500 => vec![
            (0.35, 8e-3),
            (10.0, 1.8e-2 * t.powf(0.75)),
            (f64::INFINITY, 1e-2 * t),
        ],
    };
    for (i, &(end, v)) in rows.iter().enumerate() {
        if t < end {
            return v;
        }
        if t == end {
            return v.min(rows[i + 1].1);
        }
    }
    unreachable!()
}

/// Table 10, Condition 3 aperture diameter at an exposure of `t` s, mm.
pub fn def_aperture_mm(band: DBand, t: f64) -> f64 {
    match band {
        DBand::Nir => 7.0,
        _ if t <= 0.35 => 1.0,
        _ if t < 10.0 => 1.5 * t.powf(0.375),
        _ => 3.5,
    }
}

/// C5 for `n` effective pulses in T2 (700–1050 nm; 1 elsewhere), at most 1.
pub fn def_c5(band: DBand, n: f64) -> f64 {
    if band != DBand::Nir || n <= 600.0 {
        1.0
    } else {
        (5.0 * n.powf(-0.25)).clamp(0.4, 1.0)
    }
}

const T2_S: f64 = 10.0;
const TIME_BASE_S: f64 = 100.0;
const T_I_NIR_S: f64 = 5e-6;

/// One bin: start angle, width (deg), power (W), spin at its start and end.
#[derive(Debug, Clone, Copy)]
pub struct DBin {
    pub start_deg: f64,
    pub width_deg: f64,
    pub power_w: f64,
    pub w0: f64,
    pub w1: f64,
}

/// The laser and the scan.
#[derive(Debug, Clone)]
pub struct DScan {
    pub bins: Vec<DBin>,
    pub pulse_rate_hz: f64,
    pub lambda_nm: f64,
    pub pulse_s: f64,
    pub beam_mm: f64,
}

/// The pulse clock.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DClock {
    /// Ticks at `t0 + k/f_p`, every integer k.
    Free(f64),
    /// Ticks at `q·T_f + t0 + k/f_p` with `0 ≤ t0 + k/f_p < T_f`, every turn q.
    Locked(f64),
}

/// A worst case found: a concrete window.
#[derive(Debug, Clone, Copy)]
pub struct DWorst {
    pub ratio: f64,
    pub rule: &'static str,
    pub azimuth_deg: f64,
    pub clock: DClock,
    /// Window length (rule 2), s; the pulse duration for rule 1.
    pub window_s: f64,
    pub energy_j: f64,
    pub pulses: usize,
}

impl std::fmt::Display for DWorst {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{:.6} ({}, φ = {:.4}°, {:?}, window {:.9e} s, {} pulses, {:.6e} J)",
            self.ratio,
            self.rule,
            self.azimuth_deg,
            self.clock,
            self.window_s,
            self.pulses,
            self.energy_j
        )
    }
}

/// A received pulse: absolute time, energy, angular distance from the
/// aperture centre (deg).
#[derive(Debug, Clone, Copy)]
struct Pulse {
    t: f64,
    e: f64,
    dist_deg: f64,
}

/// The head: bin start times, accelerations, period.
struct Head {
    bins: Vec<DBin>,
    t_start: Vec<f64>,
    acc: Vec<f64>,
    period: f64,
}

impl Head {
    fn new(bins: &[DBin]) -> Head {
        let mut t = 0.0;
        let (mut t_start, mut acc) = (Vec::new(), Vec::new());
        for b in bins {
            t_start.push(t);
            let w = b.width_deg.to_radians();
            acc.push((b.w1 * b.w1 - b.w0 * b.w0) / (2.0 * w));
            t += 2.0 * w / (b.w0 + b.w1);
        }
        Head {
            bins: bins.to_vec(),
            t_start,
            acc,
            period: t,
        }
    }

    /// Bin index and azimuth (deg, unwrapped within the turn) at time `u`
    /// into the turn, `0 ≤ u < T_f`: forward kinematics in the bin whose
    /// half-open time interval holds `u`.
    fn at(&self, u: f64) -> (usize, f64) {
        let i = self
            .t_start
            .partition_point(|&s| s <= u)
            .saturating_sub(1)
            .min(self.bins.len() - 1);
        let b = &self.bins[i];
        let v = u - self.t_start[i];
        let x = (b.w0 * v + 0.5 * self.acc[i] * v * v).clamp(0.0, b.width_deg.to_radians());
        (i, b.start_deg + x.to_degrees())
    }

    /// Time into bin `i` at which the head has turned `x` rad (inverse of
    /// the forward motion; used only to find candidate ticks).
    fn time_into(&self, i: usize, x: f64) -> f64 {
        let b = &self.bins[i];
        let x = x.clamp(0.0, b.width_deg.to_radians());
        let wx = (b.w0 * b.w0 + 2.0 * self.acc[i] * x).max(0.0).sqrt();
        if b.w0 + wx > 0.0 {
            2.0 * x / (b.w0 + wx)
        } else {
            0.0
        }
    }
}

/// Angular distance of azimuths `a` and `b`, deg, in [0, 180].
fn ang_dist(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(360.0);
    d.min(360.0 - d)
}

/// The tick indices of `clock` in the turn-relative time interval
/// `[a, b)` of turn `q` (absolute `[q·T_f + a, q·T_f + b)`), as absolute
/// times.
fn ticks(clock: DClock, fp: f64, tf: f64, q: usize, a: f64, b: f64, out: &mut Vec<f64>) {
    let base = q as f64 * tf;
    match clock {
        DClock::Free(t0) => {
            let k0 = ((base + a - t0) * fp).ceil() as i64;
            let mut k = k0;
            loop {
                let t = t0 + k as f64 / fp;
                if t >= base + b {
                    break;
                }
                if t >= base + a {
                    out.push(t);
                }
                k += 1;
            }
        }
        DClock::Locked(t0) => {
            let k0 = ((a - t0) * fp).ceil().max(0.0) as i64;
            let mut k = k0;
            loop {
                let u = t0 + k as f64 / fp;
                if u >= b || u >= tf {
                    break;
                }
                if u >= a {
                    out.push(base + u);
                }
                k += 1;
            }
        }
    }
}

/// A filtered train: pulse times and prefix energies.
type Filtered = (Vec<f64>, Vec<f64>);

/// The reference.
pub struct DefReference {
    head: Head,
    band: DBand,
    scan: DScan,
    /// Log-grid window lengths per decade (30 by default).
    pub per_decade: usize,
}

impl DefReference {
    pub fn new(scan: &DScan) -> Self {
        DefReference {
            head: Head::new(&scan.bins),
            band: DBand::of(scan.lambda_nm),
            scan: scan.clone(),
            per_decade: 30,
        }
    }

    pub fn period_s(&self) -> f64 {
        self.head.period
    }

    /// Half-angle of the arc of an aperture of `d_mm`, deg.
    fn half_deg(&self, d_mm: f64) -> f64 {
        (0.5 * (d_mm + self.scan.beam_mm) / 100.0).to_degrees()
    }

    /// The widest aperture of the band (Table 10 over every duration up to
    /// the time base), mm: the train is generated for it, and narrower
    /// apertures filter it.
    fn widest_mm(&self) -> f64 {
        match self.band {
            DBand::Nir => 7.0,
            _ => 1.5 * 10f64.powf(0.375),
        }
    }

    /// Every pulse the aperture at `phi` (widest arc) receives from the
    /// ticks of `clock` in turns `0..turns`.
    fn train(&self, phi: f64, clock: DClock, turns: usize) -> Vec<Pulse> {
        let h = self.half_deg(self.widest_mm());
        let fp = self.scan.pulse_rate_hz;
        let tf = self.head.period;
        // The turn-relative time intervals of the bins' parts within the
        // arc (either unwrapping), widened by two ticks within the bin:
        // (bin, shift of φ, start, end).
        let mut segs: Vec<(usize, f64, f64, f64)> = Vec::new();
        for (i, b) in self.head.bins.iter().enumerate() {
            for shift in [-360.0, 0.0, 360.0] {
                let lo = (phi - h + shift).max(b.start_deg);
                let hi = (phi + h + shift).min(b.start_deg + b.width_deg);
                if lo > hi {
                    continue;
                }
                let ta =
                    self.head.t_start[i] + self.head.time_into(i, (lo - b.start_deg).to_radians());
                let tb =
                    self.head.t_start[i] + self.head.time_into(i, (hi - b.start_deg).to_radians());
                let bin_end = if i + 1 < self.head.bins.len() {
                    self.head.t_start[i + 1]
                } else {
                    tf
                };
                segs.push((
                    i,
                    shift,
                    (ta - 2.0 / fp).max(self.head.t_start[i]),
                    (tb + 2.0 / fp).min(bin_end),
                ));
            }
        }
        // A tick at `u` into the turn lies in bin `i` (the segment is inside
        // the bin's half-open time interval): its azimuth by the forward
        // motion, its distance from φ (unwrapped by the segment's shift).
        let receive = |i: usize, shift: f64, u: f64| -> Option<(f64, f64)> {
            let b = &self.head.bins[i];
            let v = u - self.head.t_start[i];
            let x =
                (b.w0 * v + 0.5 * self.head.acc[i] * v * v).clamp(0.0, b.width_deg.to_radians());
            let d = (b.start_deg + x.to_degrees() - (phi + shift)).abs();
            (d <= h && b.power_w > 0.0).then_some((b.power_w / fp, d))
        };
        let mut out = Vec::new();
        let mut cand = Vec::new();
        // A locked clock fires at the same instants of every turn
        // (`q·T_f + u`): turn 0's received pulses, repeated.
        let turns_generated = match clock {
            DClock::Locked(_) => 1,
            DClock::Free(_) => turns,
        };
        for q in 0..turns_generated {
            for &(i, shift, a, z) in &segs {
                cand.clear();
                ticks(clock, fp, tf, q, a, z, &mut cand);
                for &t in &cand {
                    if let Some((e, dist_deg)) = receive(i, shift, t - q as f64 * tf) {
                        out.push(Pulse { t, e, dist_deg });
                    }
                }
            }
        }
        if matches!(clock, DClock::Locked(_)) {
            out.sort_by(|a, b| a.t.total_cmp(&b.t));
            let one = out.clone();
            for q in 1..turns {
                let base = q as f64 * tf;
                out.extend(one.iter().map(|p| Pulse {
                    t: base + p.t,
                    ..*p
                }));
            }
        }
        out.sort_by(|a, b| a.t.total_cmp(&b.t));
        out.dedup_by(|a, b| a.t == b.t);
        out
    }

    /// The clock phases tried at `phi`: spread over one spacing, plus one
    /// tick just after the entry into each aperture class's arc (found by
    /// bisection on the forward angle).
    pub fn clocks(&self, phi: f64, locked: bool, spread: usize) -> Vec<DClock> {
        let fp = self.scan.pulse_rate_hz;
        let sp = 1.0 / fp;
        let mut t0s: Vec<f64> = (0..spread)
            .map(|j| (j as f64 + 0.37) / spread as f64 * sp)
            .collect();
        let tf = self.head.period;
        let mut dmm = vec![self.widest_mm()];
        if self.band != DBand::Nir {
            dmm.push(1.0);
            dmm.push(3.5);
        }
        for d in dmm {
            let h = self.half_deg(d);
            let inside = |u: f64| ang_dist(self.head.at(u.rem_euclid(tf)).1, phi) <= h;
            // A time outside the arc, then scan forward for the entry.
            let n = 20_000usize;
            let mut prev_out: Option<f64> = None;
            let mut entry = None;
            for s in 0..=2 * n {
                let u = tf * s as f64 / n as f64;
                if inside(u) {
                    if let Some(a) = prev_out {
                        let (mut lo, mut hi) = (a, u);
                        for _ in 0..80 {
                            let m = 0.5 * (lo + hi);
                            if inside(m) {
                                hi = m;
                            } else {
                                lo = m;
                            }
                        }
                        entry = Some(hi);
                        break;
                    }
                } else {
                    prev_out = Some(u);
                }
            }
            if let Some(e) = entry {
                let e = e.rem_euclid(tf);
                let t = e + 1e-7 * sp;
                t0s.push((t * fp).rem_euclid(1.0) * sp);
            }
        }
        t0s.into_iter()
            .map(|t0| {
                if locked {
                    DClock::Locked(t0)
                } else {
                    DClock::Free(t0)
                }
            })
            .collect()
    }

    /// The window lengths: a log grid (`per_decade`), every row edge of
    /// Tables 3 and 10 `· (1 ± 1e-9)` and on it, pulse spans just exceeded,
    /// whole- and multi-pass lengths; all within `[pulse, time base]`.
    fn lengths(&self, per_decade: usize, pass_span_s: f64, pulses_max: usize) -> Vec<f64> {
        let fp = self.scan.pulse_rate_hz;
        let lo = self.scan.pulse_s.max(1e-11);
        let tb = TIME_BASE_S;
        let mut v = Vec::new();
        let decades = (tb / lo).log10();
        let n = (decades * per_decade as f64).ceil() as usize;
        for i in 0..=n {
            v.push(lo * 10f64.powf(decades * i as f64 / n as f64));
        }
        let edges: &[f64] = match self.band {
            DBand::Nir => &[5e-6, 10.0],
            DBand::Ir1400 => &[1e-3, 0.35, 10.0],
            DBand::Ir1500 => &[0.35, 10.0],
        };
        for &e in edges.iter().chain([tb].iter()) {
            for x in [e * (1.0 - 1e-9), e, e * (1.0 + 1e-9)] {
                v.push(x);
            }
        }
        // Spans of k pulses, just exceeded (half-open windows).
        let mut k = 2usize;
        while k <= pulses_max + 1 {
            let span = (k - 1) as f64 / fp;
            v.push(span * (1.0 + 1e-9) + 1e-15);
            k = if k < 64 { k + 1 } else { k + k / 16 };
        }
        // Whole passes and m passes (the first, near every edge, the base).
        let tf = self.head.period;
        let mut ms: Vec<f64> = vec![1.0, 2.0, 3.0];
        for &e in edges.iter().chain([tb].iter()) {
            let m = (e / tf).floor();
            for d in -1..=2 {
                ms.push(m + d as f64);
            }
        }
        for m in ms {
            if m >= 1.0 {
                v.push((m - 1.0) * tf + pass_span_s * (1.0 + 1e-9) + 1e-15);
                v.push(m * tf * (1.0 - 1e-9));
                v.push(m * tf * (1.0 + 1e-9));
            }
        }
        v.retain(|&t| t >= lo && t <= tb);
        v.sort_by(f64::total_cmp);
        v.dedup();
        v
    }

    /// The worst ratio over the apertures `phis`, the clocks of
    /// [`Self::clocks`] (`spread` uniform phases), windows starting at every
    /// pulse of the first `start_passes` passes.
    pub fn worst(&self, phis: &[f64], locked: bool, spread: usize, start_passes: usize) -> DWorst {
        let mut best: Option<DWorst> = None;
        for &phi in phis {
            for clock in self.clocks(phi, locked, spread) {
                let w = self.evaluate(phi, clock, start_passes);
                if best.is_none_or(|b| w.ratio > b.ratio) {
                    best = Some(w);
                }
            }
        }
        best.expect("at least one aperture")
    }

    /// One aperture, one clock.
    pub fn evaluate(&self, phi: f64, clock: DClock, start_passes: usize) -> DWorst {
        let tf = self.head.period;
        let band = self.band;
        let lambda = self.scan.lambda_nm;
        let starts_until = start_passes as f64 * tf;
        let turns = ((starts_until + TIME_BASE_S + T2_S) / tf).ceil() as usize + 2;
        let horizon = turns as f64 * tf;
        let t_gen = std::time::Instant::now();
        let all = self.train(phi, clock, turns);
        let timing = std::env::var_os("GAZE_LIDAR_REF_TIMING").is_some();
        if timing {
            eprintln!(
                "  defs: {} pulses generated in {:?}",
                all.len(),
                t_gen.elapsed()
            );
        }
        let mut best = DWorst {
            ratio: 0.0,
            rule: "none",
            azimuth_deg: phi,
            clock,
            window_s: 0.0,
            energy_j: 0.0,
            pulses: 0,
        };
        if all.is_empty() {
            return best;
        }
        // Filtered trains per aperture diameter (times, prefix energies), up
        // to `t_max` (the last pulse any window using it can reach).
        let filtered = |d_mm: f64, t_max: f64| -> Filtered {
            let h = self.half_deg(d_mm);
            let mut ts = Vec::new();
            let mut pre = vec![0.0];
            for p in all
                .iter()
                .take_while(|p| p.t <= t_max)
                .filter(|p| p.dist_deg <= h)
            {
                ts.push(p.t);
                pre.push(pre.last().unwrap() + p.e);
            }
            (ts, pre)
        };
        // The largest pass: the most pulses within one turn's worth of the
        // widest train, and their span (for the length grid).
        let (wide_t, _) = filtered(self.widest_mm(), f64::INFINITY);
        let (mut pulses_max, mut pass_span) = (1usize, 0.0f64);
        {
            let mut a = 0usize;
            for b in 0..wide_t.len() {
                while wide_t[b] - wide_t[a] > 0.5 * tf {
                    a += 1;
                }
                if b + 1 - a > pulses_max {
                    pulses_max = b + 1 - a;
                    pass_span = wide_t[b] - wide_t[a];
                }
            }
        }
        let lengths = self.lengths(self.per_decade, pass_span, pulses_max.min(50_000));
        let mut cache: Vec<(f64, Filtered)> = Vec::new();
        let t_first = wide_t[0];
        // The longest window each aperture diameter serves.
        let mut reach: Vec<(f64, f64)> = Vec::new();
        for &len in &lengths {
            let d = def_aperture_mm(band, len);
            match reach.iter_mut().find(|(dd, _)| *dd == d) {
                Some(r) => r.1 = r.1.max(len),
                None => reach.push((d, len)),
            }
        }
        for &len in &lengths {
            let d = def_aperture_mm(band, len);
            let k = match cache.iter().position(|(dd, _)| *dd == d) {
                Some(k) => k,
                None => {
                    let longest = reach.iter().find(|(dd, _)| *dd == d).map_or(len, |r| r.1);
                    cache.push((d, filtered(d, t_first + starts_until + longest)));
                    cache.len() - 1
                }
            };
            let (ts, pre) = &cache[k].1;
            let ael = def_ael_j(band, lambda, len);
            // Windows [t_i, t_i + len) from every pulse of the first passes.
            let mut j = ts.partition_point(|&t| t < t_first + len);
            for i in 0..ts.len() {
                if ts[i] >= t_first + starts_until || ts[i] + len > horizon {
                    break;
                }
                j = j.max(i);
                while j < ts.len() && ts[j] < ts[i] + len {
                    j += 1;
                }
                let e = pre[j] - pre[i];
                let r = e / ael;
                if r > best.ratio {
                    best = DWorst {
                        ratio: r,
                        rule: "window",
                        azimuth_deg: phi,
                        clock,
                        window_s: len,
                        energy_j: e,
                        pulses: j - i,
                    };
                }
            }
        }
        if timing {
            eprintln!(
                "  defs: {} lengths, {} apertures, windows done at {:?}",
                lengths.len(),
                cache.len(),
                t_gen.elapsed()
            );
        }
        // Rule 1: pulses and (700–1050 nm) T_i groups, with C5 from the most
        // greedy groups in a T2 window starting at a pass's first pulse.
        let d1 = def_aperture_mm(band, self.scan.pulse_s);
        let (ts, pre) = filtered(d1, t_first + starts_until + T2_S);
        if ts.is_empty() {
            return best;
        }
        let e_max = (0..ts.len())
            .map(|i| pre[i + 1] - pre[i])
            .fold(0.0, f64::max);
        let grouping = band == DBand::Nir && self.scan.pulse_s <= T_I_NIR_S;
        let c5 = if band == DBand::Nir {
            let mut n_max = 0usize;
            let mut i = 0usize;
            while i < ts.len() && ts[i] < t_first + starts_until {
                if ts[i] + T2_S > horizon {
                    break;
                }
                let (mut n, mut group_end) = (0usize, f64::NEG_INFINITY);
                for &t in ts[i..].iter().take_while(|&&t| t < ts[i] + T2_S) {
                    if !grouping || t > group_end {
                        n += 1;
                        group_end = t + T_I_NIR_S;
                    }
                }
                n_max = n_max.max(n);
                // Next pass's first pulse.
                let next = ts[i..].iter().position(|&t| t > ts[i] + 0.5 * tf);
                match next {
                    Some(off) => i += off,
                    None => break,
                }
            }
            if self.scan.pulse_s > T_I_NIR_S {
                1.0
            } else {
                def_c5(band, n_max as f64)
            }
        } else {
            1.0
        };
        let r1 = e_max / (c5 * def_ael_j(band, lambda, self.scan.pulse_s));
        if r1 > best.ratio {
            best = DWorst {
                ratio: r1,
                rule: "pulse",
                azimuth_deg: phi,
                clock,
                window_s: self.scan.pulse_s,
                energy_j: e_max,
                pulses: 1,
            };
        }
        if grouping {
            let ael = c5 * def_ael_j(band, lambda, T_I_NIR_S);
            let mut j = 0usize;
            for i in 0..ts.len() {
                if ts[i] >= t_first + starts_until {
                    break;
                }
                j = j.max(i);
                while j < ts.len() && ts[j] < ts[i] + T_I_NIR_S {
                    j += 1;
                }
                let e = pre[j] - pre[i];
                if j - i >= 2 && e / ael > best.ratio {
                    best = DWorst {
                        ratio: e / ael,
                        rule: "group",
                        azimuth_deg: phi,
                        clock,
                        window_s: T_I_NIR_S,
                        energy_j: e,
                        pulses: j - i,
                    };
                }
            }
        }
        best
    }
}
