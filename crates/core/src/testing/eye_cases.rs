//! The constructed eye-safety profiles (`tests/data/eye_safety/`), each with
//! its true ratio worked out by hand from the profile's numbers, shared by
//! the core's differential test (library level) and the root crate's CLI
//! test (`gaze-lidar check` must exit 1 naming eye safety).

use crate::profile::Profile;
use std::path::PathBuf;

// ---------------------------------------------------------------------------
// Four constructed profiles (tests/data/eye_safety/), each within every
// non-eye-safety limit it declares and over Class 1 only in one kind of
// window. For each: the true ratio in closed form (computed here by hand,
// independently of the reference), the reference's value, and `check` must
// exit 1 naming eye safety.

/// `tests/data/eye_safety/` of the workspace (from the root crate or the core).
pub fn data_dir() -> PathBuf {
    super::data_path("eye_safety")
}

/// The committed profile `name` of [`data_dir`].
pub fn load(name: &str) -> Profile {
    let path = data_dir().join(name);
    let origin = path.display().to_string();
    Profile::from_json(&std::fs::read_to_string(&path).unwrap(), &origin).unwrap()
}

/// C4 at 905 nm, `10^(0.002·(905 − 700))`.
pub const C4_905: f64 = 2.570395782768864; // 10^(0.002·205)

/// Rule 1 at 905 nm: a 5 ns pulse of `e` J against C5(N)·7.7e-8·C4.
pub fn rule1_905(e: f64, n: f64) -> f64 {
    let c5 = if n <= 600.0 {
        1.0
    } else {
        (5.0 * n.powf(-0.25)).clamp(0.4, 1.0)
    };
    e / (c5 * 7.7e-8 * C4_905)
}

/// Time to turn `x` rad from a bin start with spin `w0` and acceleration `a`.
pub fn t_into(w0: f64, a: f64, x: f64) -> f64 {
    2.0 * x / (w0 + (w0 * w0 + 2.0 * a * x).sqrt())
}

/// A constructed profile and its true worst ratio.
pub struct Constructed {
    /// The file's name in [`data_dir`].
    pub name: &'static str,
    /// True worst ratio (closed form).
    pub truth: f64,
    /// The lowest value the reference may legitimately find (a
    /// phase-dependent pulse exactly on a window edge).
    pub truth_low: f64,
    /// How the truth was worked out (for failure messages).
    pub how: String,
    /// Aperture azimuths the reference is asked to look at, deg.
    pub phis: Vec<f64>,
    /// Whether the pulse clock is phase-locked to the turn.
    pub locked: bool,
}

/// The four constructed profiles.
pub fn constructed() -> Vec<Constructed> {
    let mut v = Vec::new();
    let h905 = 0.5 * (7.0 + 8.0) / 100.0; // rad
                                          // (a) V-shaped spin minimum at the 180° edge (bins 17 and 18 decelerate
                                          // to ω_v and accelerate back), paper laser and clock (7812.5 Hz =
                                          // 390.625 pulses per turn: the clock pattern repeats every 8 turns).
    {
        let p = load("v_minimum_905.json");
        let b = &p.bins[17];
        let (w0, wv) = (b.spin_start_rad_s, b.spin_end_rad_s);
        let d = b.width_deg.to_radians();
        let a = (wv * wv - w0 * w0) / (2.0 * d);
        // Pass centred on the vertex: twice the time from 180° − h to 180°.
        let w = 2.0 * (t_into(w0, a, d) - t_into(w0, a, d - h905));
        let l = w * p.pulse_rate_hz; // pass length in pulse spacings
                                     // Over 8 turns the pass offsets are x0 + j/8 (j = 0..7); Hermite's
                                     // identity gives Σ_j #pulses = #{integers in [8x0, 8x0 + 8L]},
                                     // at most ⌊8L⌋ + 1. 200 turns = 10 s = 25 cycles, plus the first
                                     // pulse of pass 201 exactly 10 s after the window's first pulse.
        let n = 25.0 * ((8.0 * l).floor() + 1.0) + 1.0;
        // The pass centred on 180° lies in bins 17 and 18 (1.04 mW; the rest
        // of the turn runs at 0.992 mW so that the angle average is 1 mW).
        let e = p.bins[17].power_w / p.pulse_rate_hz;
        let truth = rule1_905(e, n);
        v.push(Constructed {
            name: "v_minimum_905.json",
            truth,
            truth_low: rule1_905(e, n - 1.0),
            how: format!("rule 1 at the vertex: pass {w:.6e} s = {l:.4} spacings, N = 25(⌊8L⌋+1)+1 = {n}, C5 = 5N^-1/4"),
            phis: vec![180.0],
            locked: false,
        });
    }
    // (b) Hot 1° bin at 190 kHz (9500 pulses per turn: phase-locked) in a
    // slow dark pass (dark bins have zero power).
    {
        let p = load("hot_sector_190khz.json");
        let hot = &p.bins[2];
        let fp = p.pulse_rate_hz;
        let t_hot = hot.width_deg.to_radians() / hot.spin_start_rad_s;
        let k = (t_hot * fp).floor() + 1.0; // pulse on the bin's first instant
        let e = hot.power_w / fp;
        let span = (k - 1.0) / fp;
        let truth = k * e / (7e-4 * C4_905 * span.powf(0.75));
        let truth_low = (k - 1.0) * e / (7e-4 * C4_905 * (span - 1.0 / fp).powf(0.75));
        v.push(Constructed {
            name: "hot_sector_190khz.json",
            truth,
            truth_low: truth_low.min(truth),
            how: format!("rule 2 over the hot run: K = ⌊t_hot·f_p⌋+1 = {k} pulses of {e:.4e} J in {span:.6e} s against 7e-4·C4·T^0.75"),
            phis: vec![180.5],
            locked: true,
        });
    }
    // (c) 1450 nm, uniform, 20 Hz, 1000 pulses per turn (locked): 8 passes
    // span 7·T_f + (K−1)/f_p, just over 0.35 s, where the AEL row is
    // 1e-2·T J.
    {
        let p = load("window_035s_1450.json");
        let fp = p.pulse_rate_hz;
        let w = (3.5 + 2.0) / 100.0 / p.bins[0].spin_start_rad_s;
        let k = (w * fp).floor() + 1.0;
        let e = p.bins[0].power_w / fp;
        let t_f = 1.0 / p.frame_rate_hz;
        let span8 = 7.0 * t_f + (k - 1.0) / fp;
        let truth = 8.0 * k * e / (1e-2 * span8);
        // Just below 0.35 s: 7 passes and the first pulse of the 8th.
        let below = (7.0 * k + 1.0) * e / (4.4e-3 * 0.35f64.powf(0.25));
        let t100 = 1999.0 * t_f + (k - 1.0) / fp;
        let r100 = 2000.0 * k * e / (1e-2 * t100);
        assert!(truth > below && truth > r100);
        v.push(Constructed {
            name: "window_035s_1450.json",
            truth,
            truth_low: truth,
            how: format!("rule 2, 8 passes of K = {k} pulses in {span8:.6} s against 1e-2·T (0.35 s−: {below:.4}, 100 s: {r100:.4})"),
            phis: vec![90.0],
            locked: true,
        });
    }
    // (d) 905 nm, uniform, 400 pulses per turn (locked): K = ⌊W·f_p⌋+1 = 10
    // pulses every pass where the mean is W·f_p = 9.55.
    {
        let p = load("locked_400_per_turn.json");
        let fp = p.pulse_rate_hz;
        let w = 2.0 * h905 / p.bins[0].spin_start_rad_s;
        let k = (w * fp).floor() + 1.0;
        let e = p.bins[0].power_w / fp;
        let n = 200.0 * k + 1.0;
        v.push(Constructed {
            name: "locked_400_per_turn.json",
            truth: rule1_905(e, n),
            truth_low: rule1_905(e, n - 1.0),
            how: format!("rule 1: K = {k} per pass (mean {:.4}), N = 200K+1 = {n}; with the mean count N = {:.1} it would be {:.4}", w * fp, 201.0 * w * fp, rule1_905(e, 201.0 * w * fp)),
            phis: vec![90.0],
            locked: true,
        });
    }
    v
}

// ---------------------------------------------------------------------------
// Two profiles over Class 1 only in a window *longer* than
// the pulses it holds, across a row edge where Table 3 steps down: a
// checker that takes the AEL at the pulses' span (a monotone-AEL reading)
// certified both. True ratios by hand from the files' numbers.

/// Table 10's largest aperture for 1400–4000 nm, the bound's (mm).
pub const APERTURE_IR_MODEL_MM: f64 = 3.557_060_558_492_482_4;

/// An AEL step-down profile and its true ratios.
pub struct AelStepCase {
    /// The file's name in [`data_dir`].
    pub name: &'static str,
    /// Sup over clock phases, under the model's aperture.
    pub truth: f64,
    /// For every clock phase, under the model's aperture.
    pub truth_low: f64,
    /// What the monotone reading (AEL at the pulses' span) gives.
    pub monotone: f64,
    /// Under the standard's own Table 10 aperture at the window's length
    /// (every phase), when it is over too.
    pub truth_standard: Option<f64>,
    /// How the truth was worked out (for failure messages).
    pub how: String,
}

/// The two AEL step-down profiles.
pub fn ael_step_cases() -> Vec<AelStepCase> {
    let mut v = Vec::new();
    // (a) 1550 nm, 1 kHz, uniform 10.1 mW, spin 0.00701 rad/s: one pass of
    // 9.99 s (beam + aperture over 100 mm, over ω), T_f = 896 s. The window
    // [first pulse, first + 10 s) holds the whole pass and nothing else; at
    // 10 s the table is 1e-2·T = 0.1 J (10 s edge: the smaller row), where
    // the AEL at the pass's span is 1.8e-2·τ^0.75 = 0.1011 J.
    {
        let p = load("regression_ael_step_10s_1550.json");
        let es = p.limits.eye_safety.clone().unwrap();
        let (w, pw, f) = (
            p.bins[0].spin_start_rad_s,
            p.bins[0].power_w,
            p.pulse_rate_hz,
        );
        assert!(p
            .bins
            .iter()
            .all(|b| b.power_w == pw && b.spin_start_rad_s == w));
        let tau = (APERTURE_IR_MODEL_MM + es.beam_diameter_mm) / 100.0 / w;
        let k = (tau * f).floor(); // pulses a closed τ holds at every phase
        let e = pw / f;
        let ael_10 = 1e-2 * 10.0;
        let truth = (k + 1.0) * e / ael_10;
        let truth_low = k * e / ael_10;
        let monotone = (k + 1.0) * e / (1.8e-2 * (k / f).powf(0.75));
        // Table 10 at 10 s: 3.5 mm.
        let tau_std = (3.5 + es.beam_diameter_mm) / 100.0 / w;
        let truth_standard = (tau_std * f).floor() * e / ael_10;
        v.push(AelStepCase {
            name: "regression_ael_step_10s_1550.json",
            truth,
            truth_low,
            monotone,
            truth_standard: Some(truth_standard),
            how: format!(
                "pass {tau:.6} s: {} pulses of {e:.4e} J in a 10 s window against 1e-2·10 J (at the span: 1.8e-2·τ^0.75); 3.5 mm (Table 10 at 10 s): pass {tau_std:.4} s, {} pulses",
                k + 1.0,
                (tau_std * f).floor()
            ),
        });
    }
    // (b) 1450 nm, 200 kHz, a 20° sector at 0.804 W (55.99 rad/s), 5 Hz:
    // one pass of 0.9925 ms inside the sector holds ⌊τ f⌋ + 1 = 199 pulses
    // at the best phase (198 at every phase), spanning 0.99 ms; the window of
    // 1 ms holds them against 4.4e-3·(1e-3)^0.25 = 7.824e-4 J (the 1 ms
    // edge: the smaller row), not the 8e-4 J of the first row.
    {
        let p = load("regression_ael_step_1ms_1450.json");
        let es = p.limits.eye_safety.clone().unwrap();
        let (w, pw, f) = (
            p.bins[0].spin_start_rad_s,
            p.bins[0].power_w,
            p.pulse_rate_hz,
        );
        let tau = (APERTURE_IR_MODEL_MM + es.beam_diameter_mm) / 100.0 / w;
        let k = (tau * f).floor();
        let e = pw / f;
        let ael_1ms = 4.4e-3 * 1e-3f64.powf(0.25);
        assert!(ael_1ms < 8e-4 && k / f < 1e-3);
        v.push(AelStepCase {
            name: "regression_ael_step_1ms_1450.json",
            truth: (k + 1.0) * e / ael_1ms,
            truth_low: k * e / ael_1ms,
            monotone: (k + 1.0) * e / 8e-4,
            // Table 10 gives 1 mm at 1 ms: the pass is 0.54 ms, not over.
            truth_standard: None,
            how: format!(
                "pass {tau:.6e} s: {} pulses of {e:.4e} J within 1 ms against 4.4e-3·(1e-3)^0.25 J (at the span: 8e-4 J)",
                k + 1.0
            ),
        });
    }
    v
}
