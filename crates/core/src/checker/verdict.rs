//! The verdict of a check as data: what the CLI prints as JSON and what
//! Python's `Verdict` holds, built once from the checker's own result (no
//! second evaluation), serialisable with `serde`.

use serde::Serialize;

use super::{summarize, CertifiedProfile, Rejected, Violation};
use crate::eye_safety::head::bound::power_scale_to_certify;
use crate::eye_safety::head::HeadFigures;
use crate::eye_safety::{ExposureReport, Rule};
use crate::model::lidar::LidarSpec;
use crate::profile::{Profile, Summary};

/// A check's outcome, certified or not, with every violation and the
/// eye-safety evaluation the outcome rests on.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[non_exhaustive]
pub struct Verdict {
    /// No violation.
    pub certified: bool,
    /// Every violation, in the order checked.
    pub violations: Vec<ViolationEntry>,
    /// The checker's summary (absent when the bins are too broken to sum).
    pub summary: Option<Summary>,
    /// Whether eye safety was evaluated (it is not when the caller opted
    /// out and the file has no parameters: then the verdict is no Class 1
    /// evidence).
    pub eye_safety_evaluated: bool,
    /// The sensor the profile was also held against, by name.
    pub sensor: Option<String>,
    /// The eye-safety evaluation, when it ran.
    pub eye_safety: Option<EyeSafetyVerdict>,
}

/// One violation: the `limits` key (or field) it concerns, its message and
/// the typed violation.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[non_exhaustive]
pub struct ViolationEntry {
    /// The key the violation names ([`Violation::limit_key`]).
    pub limit: &'static str,
    /// The one-line message.
    pub message: String,
    /// The violation itself.
    pub detail: Violation,
}

/// The eye-safety figures of a verdict.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[non_exhaustive]
pub struct EyeSafetyVerdict {
    /// Azimuth of the worst aperture position, degrees.
    pub worst_azimuth_deg: f64,
    /// The rule that binds there.
    pub binding_rule: Rule,
    /// Exposure over the limit (> 1 fails).
    pub worst_ratio: f64,
    /// `1 / worst_ratio`.
    pub margin: f64,
    /// The stalled rotor's ratio (a warning, not a verdict).
    pub stalled_rotor_ratio: f64,
    /// `"head"` or `"one channel"`.
    pub evaluated_for: &'static str,
    /// The head's figures, when the profile declares a head.
    pub head: Option<HeadVerdict>,
    /// The largest uniform power scale at which the profile certifies.
    pub power_scale_to_certify: f64,
}

/// Where the head was worst and how many beams met the aperture there.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[non_exhaustive]
pub struct HeadVerdict {
    /// Channels of the head evaluated.
    pub channels_evaluated: u32,
    /// Azimuth of the worst aperture position, degrees.
    pub worst_azimuth_deg: f64,
    /// Height of the worst aperture position, mm.
    pub worst_height_mm: f64,
    /// Beams meeting the aperture there.
    pub beams_meeting_worst: u32,
    /// The rule that binds there.
    pub binding_rule: Rule,
    /// Every overlap figure of the head.
    pub figures: HeadFigures,
}

impl EyeSafetyVerdict {
    /// The figures of an evaluation.
    #[must_use]
    pub fn of(r: &ExposureReport) -> Self {
        Self {
            worst_azimuth_deg: r.worst_azimuth_deg,
            binding_rule: r.binding_rule,
            worst_ratio: r.worst_ratio,
            margin: r.margin,
            stalled_rotor_ratio: r.stalled_rotor_ratio,
            evaluated_for: if r.head.is_some() {
                "head"
            } else {
                "one channel"
            },
            head: r.head.as_ref().map(|h| {
                let (worst_height_mm, beams_meeting_worst) = worst_position(r.binding_rule, h);
                HeadVerdict {
                    channels_evaluated: h.channels,
                    worst_azimuth_deg: r.worst_azimuth_deg,
                    worst_height_mm,
                    beams_meeting_worst,
                    binding_rule: r.binding_rule,
                    figures: h.clone(),
                }
            }),
            power_scale_to_certify: power_scale_to_certify(r.worst_ratio),
        }
    }
}

/// The worst aperture position's height and the beams meeting it, for the
/// binding rule: Rule 1's largest group, else the energy rules' height.
#[must_use]
pub fn worst_position(rule: Rule, h: &HeadFigures) -> (f64, u32) {
    if rule == Rule::SinglePulse {
        (h.group_height_mm, h.count_group)
    } else {
        (h.worst_height_mm, h.channels_at_worst)
    }
}

impl Verdict {
    /// The verdict of `result`, the checker's answer on `profile` (held
    /// against `sensor` if given). The summary of a rejected profile is
    /// computed unless its bin count itself is the violation.
    #[must_use]
    pub fn of(
        result: &Result<CertifiedProfile, Rejected>,
        profile: &Profile,
        sensor: Option<&LidarSpec>,
    ) -> Self {
        let (certified, violations, summary, eye) = match result {
            Ok(c) => (true, &[][..], Some(c.summary().clone()), c.eye_safety()),
            Err(rej) => (
                false,
                &rej.violations[..],
                rej.violations
                    .iter()
                    .all(|v| !matches!(v, Violation::BinCount { .. }))
                    .then(|| summarize(profile)),
                rej.eye_safety.as_deref(),
            ),
        };
        Self {
            certified,
            violations: violations
                .iter()
                .map(|v| ViolationEntry {
                    limit: v.limit_key(),
                    message: v.to_string(),
                    detail: v.clone(),
                })
                .collect(),
            summary,
            eye_safety_evaluated: eye.is_some(),
            sensor: sensor.map(|s| s.name.clone()),
            eye_safety: eye.map(EyeSafetyVerdict::of),
        }
    }
}
