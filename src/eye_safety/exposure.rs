//! Exposure of a stationary aperture around a spinning head running a profile.
//!
//! Model (IEC 60825-1:2014 Condition 3, scanned beam):
//! - the aperture (7 mm for 400–1400 nm, 3.5 mm beyond) stands 100 mm from
//!   the scan centre at azimuth φ; the beam (diameter `D_b` there) overlaps
//!   it while the head sweeps the *pass angle* `(D_a + D_b) / 100 mm` rad
//!   centred on φ;
//! - **conservatively, the whole energy of every pulse fired during the pass
//!   counts** (no geometric coupling loss);
//! - the pass repeats once per revolution, so a window of duration `T`
//!   contains at most `⌊T·f_frame⌋ + 1` passes.
//!
//! Rules checked at every aperture position (the worst ratio binds):
//! 1. [`Rule::SinglePulse`]: the largest pulse energy ≤ C5 · AEL(t_pulse),
//!    C5 from the pulses entering within `min(T2, time base)`;
//! 2. [`Rule::PassTrain`]: the energy of one pass ≤ AEL(pass duration);
//! 3. [`Rule::T2Train`]: the energy of the passes within T2 = 10 s ≤ AEL(10 s);
//! 4. [`Rule::TimeBase`]: the energy within the 100 s time base ≤ AEL(100 s).
//!
//! Positions evaluated: both window alignments at every bin edge, and every
//! bin centre. With power and spin constant within bins the window integrals
//! are piecewise linear in φ with breakpoints exactly there, so the maximum
//! over all φ is attained at one of them.

use serde::Serialize;
use std::fmt;

use super::ael::{self, Band, APERTURE_DISTANCE_MM, T2_S, TIME_BASE_S};
use super::{EyeSafetyError, EyeSafetyParams};
use crate::model::angle::wrap_deg;
use crate::profile::kinematics::Timeline;
use crate::profile::Profile;

/// An eye-safety rule (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Rule {
    /// Largest single pulse against the C5-corrected single-pulse AEL.
    SinglePulse,
    /// Energy of one pass against AEL(pass duration).
    PassTrain,
    /// Energy within T2 against AEL(T2).
    T2Train,
    /// Energy within the 100 s time base against AEL(100 s).
    TimeBase,
}

impl fmt::Display for Rule {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::SinglePulse => "single-pulse energy (C5-corrected)",
            Self::PassTrain => "pulse-train energy per pass",
            Self::T2Train => "pulse-train energy within T2 = 10 s",
            Self::TimeBase => "average power over the 100 s time base",
        })
    }
}

/// Exposure at one aperture azimuth.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AzimuthExposure {
    /// Aperture azimuth, degrees.
    pub azimuth_deg: f64,
    /// Pass duration, s.
    pub pass_duration_s: f64,
    /// Pulses entering per pass.
    pub pulses_per_pass: f64,
    /// Energy entering per pass, J.
    pub pass_energy_j: f64,
    /// Largest single-pulse energy in the pass, J.
    pub max_pulse_energy_j: f64,
    /// C5 used for the single-pulse rule.
    pub c5: f64,
    /// Exposure / limit of each rule, in [`Rule`] order.
    pub ratios: [f64; 4],
}

impl AzimuthExposure {
    /// The binding rule and its ratio.
    #[must_use]
    pub fn worst(&self) -> (Rule, f64) {
        const RULES: [Rule; 4] = [
            Rule::SinglePulse,
            Rule::PassTrain,
            Rule::T2Train,
            Rule::TimeBase,
        ];
        let mut best = (RULES[0], self.ratios[0]);
        for (r, &x) in RULES.iter().zip(&self.ratios).skip(1) {
            if x > best.1 {
                best = (*r, x);
            }
        }
        best
    }
}

/// The eye-safety evaluation of a profile.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ExposureReport {
    /// Pass angle, degrees.
    pub pass_angle_deg: f64,
    /// Azimuth of the worst aperture position, degrees.
    pub worst_azimuth_deg: f64,
    /// The rule binding there.
    pub binding_rule: Rule,
    /// Exposure / limit there (≤ 1 is Class 1).
    pub worst_ratio: f64,
    /// `1 / worst_ratio`: how many times the power could grow.
    pub margin: f64,
    /// Worst ratio if the rotor stalls at the highest-power azimuth with the
    /// laser still firing (every pulse into one aperture): > 1 means the
    /// product needs a stall interlock.
    pub stalled_rotor_ratio: f64,
    /// Every position evaluated, in azimuth order.
    pub positions: Vec<AzimuthExposure>,
}

/// At most how many passes a window of `window_s` holds.
fn passes_in(window_s: f64, frame_rate_hz: f64) -> f64 {
    (window_s * frame_rate_hz).floor() + 1.0
}

/// Per-evaluation constants and the exposure at one aperture azimuth.
struct Evaluator<'a> {
    tl: Timeline<'a>,
    band: Band,
    c4: f64,
    pulse_duration_s: f64,
    pass_angle_deg: f64,
    f_frame: f64,
    f_pulse: f64,
    t_max: f64,
    ael_pulse: f64,
    ael_t2: f64,
    ael_tb: f64,
}

impl Evaluator<'_> {
    fn at(&self, phi: f64) -> Result<AzimuthExposure, EyeSafetyError> {
        let half = 0.5 * self.pass_angle_deg;
        let (t_pass, e_pass) = self.tl.window(phi - half, self.pass_angle_deg);
        let pulses = self.f_pulse * t_pass;
        let p_max = self.tl.max_power_in(phi - half, self.pass_angle_deg);
        // Pulses closer than T_i are one effective pulse (retinal band).
        let group = if self.band == Band::RetinalNir {
            (self.band.t_i_s() * self.f_pulse)
                .ceil()
                .clamp(1.0, pulses.max(1.0))
        } else {
            1.0
        };
        let e_pulse = p_max / self.f_pulse * group;
        let n_eff = pulses * passes_in(self.t_max, self.f_frame) / group;
        let c5 = ael::c5(self.band, n_eff, self.t_max);
        let ael_single = if group > 1.0 {
            ael::table3_j(self.band, self.c4, self.band.t_i_s())
        } else {
            self.ael_pulse
        };
        let t_pass_eff = t_pass.max(self.pulse_duration_s);
        if t_pass_eff > 3e4 {
            return Err(ael::AelError::Duration {
                what: "pass duration",
                value: t_pass_eff,
                reason: "exceeds 3·10⁴ s, beyond Table 3 (the spin is too slow)",
            }
            .into());
        }
        let ael_pass = ael::table3_j(self.band, self.c4, t_pass_eff);
        let ratios = [
            e_pulse / (c5 * ael_single),
            e_pass / ael_pass,
            e_pass * passes_in(T2_S, self.f_frame) / self.ael_t2,
            e_pass * passes_in(TIME_BASE_S, self.f_frame) / self.ael_tb,
        ];
        Ok(AzimuthExposure {
            azimuth_deg: phi,
            pass_duration_s: t_pass,
            pulses_per_pass: pulses,
            pass_energy_j: e_pass,
            max_pulse_energy_j: e_pulse,
            c5,
            ratios,
        })
    }
}

fn evaluator<'a>(
    profile: &'a Profile,
    params: &EyeSafetyParams,
) -> Result<Evaluator<'a>, EyeSafetyError> {
    let band = params.validate()?;
    let lambda = params.wavelength_nm;
    let tl = Timeline::new(profile);
    let f_frame = 1.0 / tl.period_s();
    Ok(Evaluator {
        band,
        c4: ael::c4(lambda),
        pulse_duration_s: params.pulse_duration_s,
        pass_angle_deg: ((band.aperture_mm() + params.beam_diameter_mm) / APERTURE_DISTANCE_MM)
            .to_degrees()
            .min(360.0),
        f_frame,
        f_pulse: profile.pulse_rate_hz,
        t_max: T2_S.min(TIME_BASE_S),
        ael_pulse: ael::ael_j(lambda, params.pulse_duration_s)?,
        ael_t2: ael::ael_j(lambda, T2_S)?,
        ael_tb: ael::ael_j(lambda, TIME_BASE_S)?,
        tl,
    })
}

/// Evaluates a structurally valid profile (checked bins, positive spin)
/// against Class 1 at every azimuth.
pub fn evaluate_profile(
    profile: &Profile,
    params: &EyeSafetyParams,
) -> Result<ExposureReport, EyeSafetyError> {
    let ev = evaluator(profile, params)?;
    let (band, lambda, f_pulse, t_max) = (ev.band, params.wavelength_nm, ev.f_pulse, ev.t_max);
    let (ael_t2, ael_tb, pass_angle_deg) = (ev.ael_t2, ev.ael_tb, ev.pass_angle_deg);
    let half = 0.5 * pass_angle_deg;
    // With constant spin and power in every bin the window quantities are
    // piecewise linear in the aperture azimuth with breakpoints where a
    // window edge meets a bin edge, so those positions contain the maximum.
    // Accelerating bins make the dwell density vary inside a bin: then the
    // bin centres are sampled as well.
    let accelerating = profile
        .bins
        .iter()
        .any(|b| b.spin_start_rad_s != b.spin_end_rad_s);
    let mut centers: Vec<f64> = Vec::with_capacity(3 * profile.bins.len());
    for b in &profile.bins {
        centers.push(wrap_deg(b.start_deg + half));
        centers.push(wrap_deg(b.start_deg - half));
        if accelerating {
            centers.push(wrap_deg(b.center_deg()));
        }
    }
    centers.sort_by(f64::total_cmp);
    centers.dedup();
    let positions = centers
        .into_iter()
        .map(|phi| ev.at(phi))
        .collect::<Result<Vec<_>, _>>()?;

    let (mut worst_i, mut worst_rule, mut worst_ratio) = (0, Rule::SinglePulse, f64::NEG_INFINITY);
    for (i, p) in positions.iter().enumerate() {
        let (r, x) = p.worst();
        if x > worst_ratio {
            (worst_i, worst_rule, worst_ratio) = (i, r, x);
        }
    }

    // Stalled rotor: every pulse of the highest-power bin enters one aperture.
    let p_top = profile.bins.iter().map(|b| b.power_w).fold(0.0, f64::max);
    let stalled_group = if band == Band::RetinalNir {
        (band.t_i_s() * f_pulse).ceil().max(1.0)
    } else {
        1.0
    };
    let stalled_c5 = ael::c5(band, f_pulse * t_max / stalled_group, t_max);
    let stalled_t = if stalled_group > 1.0 {
        band.t_i_s()
    } else {
        params.pulse_duration_s
    };
    let stalled_ratio = [
        p_top / f_pulse * stalled_group / (stalled_c5 * ael::ael_j(lambda, stalled_t)?),
        p_top * T2_S / ael_t2,
        p_top * TIME_BASE_S / ael_tb,
    ]
    .into_iter()
    .fold(0.0, f64::max);

    Ok(ExposureReport {
        pass_angle_deg,
        worst_azimuth_deg: positions[worst_i].azimuth_deg,
        binding_rule: worst_rule,
        worst_ratio,
        margin: 1.0 / worst_ratio,
        stalled_rotor_ratio: stalled_ratio,
        positions,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets;
    use crate::planner::closed_form::build_profile;
    use crate::planner::Mode;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(40))]

        /// Without acceleration, the edge-aligned positions hold the maximum
        /// over every azimuth: dense sampling never finds a worse one.
        #[test]
        fn edge_positions_bound_dense_sampling(
            gaze in 0.0f64..360.0,
            bins in 8usize..200,
            mode in 0usize..4,
            scale in proptest::collection::vec(0.3f64..1.7, 200),
        ) {
            let mut p = build_profile(&presets::paper(), Mode::ALL[mode], Some(gaze), bins).unwrap();
            for (b, k) in p.bins.iter_mut().zip(scale.iter().cycle()) {
                b.power_w *= k;
            }
            let params = p.limits.eye_safety.clone().unwrap();
            let report = evaluate_profile(&p, &params).unwrap();
            let ev = evaluator(&p, &params).unwrap();
            for b in &p.bins {
                for k in 0..17 {
                    let phi = wrap_deg(b.start_deg + b.width_deg * f64::from(k) / 17.0 + 0.013);
                    let (_, r) = ev.at(phi).unwrap().worst();
                    prop_assert!(r <= report.worst_ratio * (1.0 + 1e-9), "{} > {} at {}", r, report.worst_ratio, phi);
                }
            }
        }
    }
}
