//! Exposure of a stationary aperture around a spinning head running a
//! profile: the Class 1 verdict of a profile, from the sound bound of
//! [`super::bound`].
//!
//! Model (IEC 60825-1:2014 Condition 3, scanned beam): the aperture (7 mm
//! for 400–1400 nm, 3.5 mm beyond) stands 100 mm from the scan centre at
//! azimuth φ; the beam (diameter `D_b` there) overlaps it while the head
//! sweeps the *pass angle* `(D_a + D_b) / 100 mm` rad centred on φ; the whole
//! energy of every pulse fired during the pass counts (no coupling loss).
//! Every rule is bounded over **all** azimuths, clock phases, window
//! placements and window durations (see [`super::bound`] and
//! `specs/eye_safety.md`).

use core::cmp::Ordering;
use serde::Serialize;

use super::ael::{self, APERTURE_DISTANCE_MM};
pub use super::bound::Rule;
use super::bound::{self, Laser, Search, Seg};
use super::head::geometry::Surface;
use super::head::{bound as head_bound, Head};
use super::{EyeSafetyError, EyeSafetyParams};
use crate::profile::Profile;

/// The eye-safety evaluation of a profile.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[non_exhaustive]
pub struct ExposureReport {
    /// Pass angle, degrees.
    pub pass_angle_deg: f64,
    /// Azimuth of the aperture where the binding rule is worst, degrees.
    pub worst_azimuth_deg: f64,
    /// The rule binding there.
    pub binding_rule: Rule,
    /// Upper bound of exposure / limit over every aperture, clock phase and
    /// window (≤ 1 is Class 1).
    pub worst_ratio: f64,
    /// `1 / worst_ratio`: how many times the power could grow.
    pub margin: f64,
    /// Each rule's ratio: single pulse, within a pass, several passes up to
    /// T2, up to the time base.
    pub rule_ratios: [f64; 4],
    /// Longest pass over all azimuths, s.
    pub max_pass_duration_s: f64,
    /// Most pulses entering in one pass, for any phase of the pulse clock.
    pub max_pulses_per_pass: f64,
    /// Largest energy one pass can deliver, J.
    pub max_pass_energy_j: f64,
    /// Window duration at which the binding train rule is worst, s.
    pub worst_window_s: f64,
    /// Worst ratio if the rotor stalls at the highest-power azimuth with the
    /// laser still firing (every pulse into one aperture): > 1 means the
    /// product needs a stall interlock.
    pub stalled_rotor_ratio: f64,
    /// The multi-beam head's overlap figures (absent: one channel).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub head: Option<super::head::HeadFigures>,
}

/// The laser constants of `params` at `pulse_rate_hz`, validated.
pub fn laser(params: &EyeSafetyParams, pulse_rate_hz: f64) -> Result<Laser, EyeSafetyError> {
    let band = params.validate()?;
    // The one numeric boundary: a rate of physical size (not subnormal).
    if let Err(reason) = crate::model::valid::rate_hz(pulse_rate_hz) {
        return Err(EyeSafetyError::Param {
            field: "pulse_rate_hz",
            value: pulse_rate_hz,
            reason,
        });
    }
    if pulse_rate_hz * params.pulse_duration_s >= 1.0 {
        return Err(EyeSafetyError::Param {
            field: "pulse_rate_hz",
            value: pulse_rate_hz,
            reason: "pulses overlap: pulse_rate_hz × pulse_duration_s must be < 1",
        });
    }
    Ok(Laser {
        band,
        c4: ael::c4(params.wavelength_nm),
        pulse_duration_s: params.pulse_duration_s,
        pulse_rate_hz,
    })
}

/// Pass angle of the Condition 3 aperture plus the beam, degrees (≤ 360).
#[must_use]
pub fn pass_angle_deg(params: &EyeSafetyParams, laser: &Laser) -> f64 {
    scan_pass_angle_deg(laser.band, params.beam_diameter_mm).min(360.0)
}

/// The angle the head turns while the beam (diameter `beam_diameter_mm` at
/// the aperture, on a ray from the spin axis) overlaps the Condition 3
/// aperture of `band`, 100 mm from the scan centre: the aperture centre
/// within (aperture + beam)/2 of the ray in 3-D,
/// [`super::head::geometry::radial_pass_angle_deg`], degrees (360 once the beam
/// reaches the aperture at every turn).
#[must_use]
pub fn scan_pass_angle_deg(band: ael::Band, beam_diameter_mm: f64) -> f64 {
    super::head::geometry::radial_pass_angle_deg(
        band.aperture_mm(),
        beam_diameter_mm,
        APERTURE_DISTANCE_MM,
    )
}

/// The bins of a profile as the bound sees them.
#[must_use]
pub fn segments(profile: &Profile) -> Vec<Seg> {
    profile
        .bins
        .iter()
        .map(|b| Seg {
            start_deg: b.start_deg,
            width_deg: b.width_deg,
            power_w: b.power_w,
            spin_start_rad_s: b.spin_start_rad_s,
            spin_end_rad_s: b.spin_end_rad_s,
        })
        .collect()
}

/// Evaluates a structurally valid profile (bins cover the circle in order,
/// positive spins) against Class 1: a sound upper bound of the worst ratio.
pub fn evaluate_profile(
    profile: &Profile,
    params: &EyeSafetyParams,
) -> Result<ExposureReport, EyeSafetyError> {
    evaluate_segments(&segments(profile), params, profile.pulse_rate_hz)
}

/// [`evaluate_profile`] with a choice of search (see [`bound::Search`]):
/// the branch and bound and the exhaustive search give identical reports;
/// the exhaustive one is kept as the reference for tests and benchmarks.
#[doc(hidden)]
pub fn evaluate_profile_with(
    profile: &Profile,
    params: &EyeSafetyParams,
    search: Search,
) -> Result<ExposureReport, EyeSafetyError> {
    evaluate_segments_with(&segments(profile), params, profile.pulse_rate_hz, search)
}

/// As [`evaluate_profile`], for bins given as [`Seg`]s (a firmware table as
/// it will run, for one).
pub fn evaluate_segments(
    segs: &[Seg],
    params: &EyeSafetyParams,
    pulse_rate_hz: f64,
) -> Result<ExposureReport, EyeSafetyError> {
    evaluate_segments_with(segs, params, pulse_rate_hz, Search::Pruned)
}

/// The bound of a head on its declared cylinder alone
/// (`aperture_distance_mm` from the spin axis), without the other surfaces
/// every verdict also covers ([`evaluate_segments`]): the bound as a
/// function of the distance, for tests of it against references at any
/// distance. Never a verdict. Without a head, [`evaluate_segments`].
#[doc(hidden)]
pub fn evaluate_segments_at_declared_distance(
    segs: &[Seg],
    params: &EyeSafetyParams,
    pulse_rate_hz: f64,
) -> Result<ExposureReport, EyeSafetyError> {
    evaluate_segments_on(segs, params, pulse_rate_hz, Surface::Cylinder)
}

/// [`evaluate_segments_at_declared_distance`] on `surface` at the declared
/// distance. Never a verdict.
#[doc(hidden)]
pub fn evaluate_segments_on(
    segs: &[Seg],
    params: &EyeSafetyParams,
    pulse_rate_hz: f64,
    surface: Surface,
) -> Result<ExposureReport, EyeSafetyError> {
    let laser = laser(params, pulse_rate_hz)?;
    match &params.head {
        Some(head) => evaluate_head_at(segs, params, head, surface, &laser, Search::Pruned),
        None => evaluate_segments(segs, params, pulse_rate_hz),
    }
}

fn evaluate_segments_with(
    segs: &[Seg],
    params: &EyeSafetyParams,
    pulse_rate_hz: f64,
    search: Search,
) -> Result<ExposureReport, EyeSafetyError> {
    let laser = laser(params, pulse_rate_hz)?;
    if let Some(head) = &params.head {
        return evaluate_head(segs, params, head, &laser, search);
    }
    let pass = pass_angle_deg(params, &laser);
    if segs.is_empty() {
        return Err(no_bins());
    }
    let b = bound::evaluate_with(segs, 0.5 * pass, &laser, search);
    check_pass_duration(&b)?;
    let p_top = segs.iter().map(|s| s.power_w).fold(0.0, f64::max);
    let (stalled_rotor_ratio, _) = laser.stationary_ratio(p_top);
    Ok(ExposureReport {
        pass_angle_deg: pass,
        worst_azimuth_deg: b.worst_azimuth_deg,
        binding_rule: b.binding_rule,
        worst_ratio: b.worst_ratio,
        margin: 1.0 / b.worst_ratio,
        rule_ratios: b.ratios,
        max_pass_duration_s: b.max_pass_duration_s,
        max_pulses_per_pass: b.max_pulses_per_pass,
        max_pass_energy_j: b.max_pass_energy_j,
        worst_window_s: b.worst_window_s,
        stalled_rotor_ratio,
        head: None,
    })
}

fn no_bins() -> EyeSafetyError {
    EyeSafetyError::Param {
        field: "bins",
        value: 0.0,
        reason: "a profile needs at least one bin",
    }
}

fn check_pass_duration(b: &bound::Bound) -> Result<(), EyeSafetyError> {
    if b.max_pass_duration_s > ael::T_MAX_TABLE_S {
        return Err(ael::AelError::Duration {
            what: "pass duration",
            value: b.max_pass_duration_s,
            reason: "exceeds 3·10⁴ s, beyond Table 3 (the spin is too slow)",
        }
        .into());
    }
    Ok(())
}

/// The head's verdict (`specs/eye_safety.md`, "The head", "The aperture's
/// surface"): a certificate always covers the two Condition 3 surfaces at
/// 100 mm, the cylinder around the spin axis and the sphere around the scan
/// centre. A head declaring another `aperture_distance_mm` is evaluated at
/// its declared distance **and** at 100 mm, on both surfaces, and the report
/// with the largest worst ratio is the verdict (no surface is provably the
/// stricter one for every head, so none is skipped); the stalled-rotor
/// figure is the largest of them. A crossing point at or beyond 100 mm from
/// the axis leaves no 100 mm surface to evaluate: refused by name.
fn evaluate_head(
    segs: &[Seg],
    params: &EyeSafetyParams,
    head: &Head,
    laser: &Laser,
    search: Search,
) -> Result<ExposureReport, EyeSafetyError> {
    let mut worst: Option<ExposureReport> = None;
    let mut stalled = 0.0f64;
    for (h, surface) in surfaces(head)? {
        let r = evaluate_head_at(segs, params, &h, surface, laser, search)?;
        stalled = stalled.max(r.stalled_rotor_ratio);
        // Ties (and a NaN, which never compares greater) keep the earlier.
        worst = Some(match worst {
            Some(w) if r.worst_ratio.partial_cmp(&w.worst_ratio) != Some(Ordering::Greater) => w,
            _ => r,
        });
    }
    let mut worst = worst.ok_or(EyeSafetyError::Param {
        field: "head",
        value: f64::NAN,
        reason: "no aperture surface to evaluate",
    })?;
    worst.stalled_rotor_ratio = stalled;
    Ok(worst)
}

/// The aperture surfaces a head's verdict covers, in the order ties are
/// settled: the 100 mm cylinder and sphere, then (a head declaring another
/// distance) the declared distance's cylinder and sphere. Refuses an
/// invalid head, and a crossing point at or beyond 100 mm from the axis
/// (no 100 mm surface outside the head) naming `head.origin_radius_mm`.
pub fn surfaces(head: &Head) -> Result<Vec<(Head, Surface)>, EyeSafetyError> {
    head.validate()?;
    // Exact comparison: any other distance, however near, is evaluated too.
    #[allow(clippy::float_cmp)]
    if head.aperture_distance_mm == APERTURE_DISTANCE_MM {
        return Ok(Surface::ALL.iter().map(|&s| (head.clone(), s)).collect());
    }
    // Not `< 100` written as a negation: NaN was refused by the validation.
    if head.origin_radius_mm >= APERTURE_DISTANCE_MM {
        return Err(EyeSafetyError::Param {
            field: "head.origin_radius_mm",
            value: head.origin_radius_mm,
            reason: "must be < 100 mm: a certificate covers the Condition 3 surface 100 mm from the spin axis",
        });
    }
    let standard = Head {
        aperture_distance_mm: APERTURE_DISTANCE_MM,
        ..head.clone()
    };
    Ok(Surface::ALL
        .iter()
        .map(|&s| (standard.clone(), s))
        .chain(Surface::ALL.iter().map(|&s| (head.clone(), s)))
        .collect())
}

/// The stalled-rotor figure (the head stopped, the laser firing at
/// `power_max_w`): one channel's stationary ratio, or a head's
/// ([`head_bound::stalled_ratio`]) on every surface of [`surfaces`], the
/// largest. The figure a profile's report carries, for inputs that are not
/// a profile (a firmware table: its hottest code's power).
pub fn stalled_rotor_ratio(
    params: &EyeSafetyParams,
    pulse_rate_hz: f64,
    power_max_w: f64,
) -> Result<f64, EyeSafetyError> {
    let laser = laser(params, pulse_rate_hz)?;
    let Some(head) = &params.head else {
        return Ok(laser.stationary_ratio(power_max_w).0);
    };
    let mut worst = 0.0f64;
    for (h, surface) in surfaces(head)? {
        // The stalled figures do not depend on the spin (no widening).
        let hf = head_bound::head_figures_on(&h, surface, params, &laser, 0.0)?;
        worst = worst.max(head_bound::stalled_ratio(&hf, &laser, power_max_w));
    }
    Ok(worst)
}

/// The head's evaluation on `surface`, `head.aperture_distance_mm` from the
/// spin axis (cylinder) or the scan centre (sphere): the single-channel bound at the head's widest pass, every
/// energy rule times `W_v`, Rule 1 from the head's groups
/// ([`head_bound::single_pulse_ratio`]) and the stalled rotor for every
/// channel meeting one aperture.
fn evaluate_head_at(
    segs: &[Seg],
    params: &EyeSafetyParams,
    head: &Head,
    surface: Surface,
    laser: &Laser,
    search: Search,
) -> Result<ExposureReport, EyeSafetyError> {
    if segs.is_empty() {
        return Err(no_bins());
    }
    let spin_max = segs
        .iter()
        .map(|s| s.spin_start_rad_s.max(s.spin_end_rad_s))
        .fold(0.0, f64::max);
    let hf = head_bound::head_figures_on(head, surface, params, laser, spin_max)?;
    let pass = hf.pass_angle_deg.min(360.0);
    let b = bound::evaluate_with(segs, 0.5 * pass, laser, search);
    check_pass_duration(&b)?;
    let p_top = segs.iter().map(|s| s.power_w).fold(0.0, f64::max);
    let frame_s = crate::profile::kinematics::Timeline::from_bins(segs).period_s();
    let w = hf.weight_vertical;
    let mut ratios = [
        head_bound::single_pulse_ratio(
            &hf,
            laser,
            head_bound::SingleFigures {
                single_pulse_ratio: b.ratios[0],
                pass_duration_s: b.max_pass_duration_s,
                frame_s,
                power_max_w: p_top,
            },
        ),
        0.0,
        0.0,
        0.0,
    ];
    let energy = head_bound::energy_ratios(&hf, laser, b.ratios, b.pass, frame_s, p_top, spin_max);
    ratios[1..].copy_from_slice(&energy[1..]);
    let (k_best, r_best) = crate::eye_safety::bound::binding(&ratios);
    let stalled_rotor_ratio = head_bound::stalled_ratio(&hf, laser, p_top);
    Ok(ExposureReport {
        pass_angle_deg: pass,
        worst_azimuth_deg: b.rule_azimuths_deg[usize::from(k_best > 0)],
        binding_rule: crate::eye_safety::bound::RULES[k_best],
        worst_ratio: r_best,
        margin: 1.0 / r_best,
        rule_ratios: ratios,
        max_pass_duration_s: b.max_pass_duration_s,
        max_pulses_per_pass: b.max_pulses_per_pass,
        max_pass_energy_j: w * b.max_pass_energy_j,
        worst_window_s: if k_best == 1 {
            b.rule_windows_s[0]
        } else {
            b.rule_windows_s[1]
        },
        stalled_rotor_ratio,
        head: Some(hf),
    })
}
