//! The eye-safety rules, by the window each bounds: one type for the
//! float bound ([`crate::eye_safety::bound`]) and the integer firmware
//! checker (`firmware::eye`, which builds without `std`).

use core::fmt;

use serde::{Deserialize, Serialize};

/// An eye-safety rule, by the window it bounds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
#[non_exhaustive]
pub enum Rule {
    /// Each pulse (or `T_i` group) against the C5-corrected single-pulse AEL.
    SinglePulse,
    /// Pulse-train energy in windows shorter than one revolution (within a pass).
    PassTrain,
    /// Pulse-train energy in windows of one revolution up to T2 = 10 s.
    T2Train,
    /// Pulse-train energy in windows beyond T2 up to the 100 s time base
    /// (the average-power rule).
    TimeBase,
}

#[cfg(feature = "std")]
impl Rule {
    /// The rule whose windows contain duration `t_s` (frame period `frame_s`).
    #[must_use]
    pub fn for_duration(t_s: f64, frame_s: f64) -> Self {
        if t_s < frame_s {
            Self::PassTrain
        } else if t_s <= super::ael::T2_S {
            Self::T2Train
        } else {
            Self::TimeBase
        }
    }
}

impl fmt::Display for Rule {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::SinglePulse => "single-pulse energy (C5-corrected)",
            Self::PassTrain => "pulse-train energy within one pass",
            Self::T2Train => "pulse-train energy over several passes (up to T2 = 10 s)",
            Self::TimeBase => "average power over the 100 s time base",
        })
    }
}

#[cfg(all(test, feature = "json"))]
mod tests {
    use super::*;

    /// The names both checkers wrote before they shared the type (the
    /// float report's `binding_rule`, the integer limits'
    /// `pass_energy_rule`), read back.
    #[test]
    fn names_round_trip() {
        for (rule, name) in [
            (Rule::SinglePulse, "\"single_pulse\""),
            (Rule::PassTrain, "\"pass_train\""),
            (Rule::T2Train, "\"t2_train\""),
            (Rule::TimeBase, "\"time_base\""),
        ] {
            assert_eq!(serde_json::to_string(&rule).unwrap(), name);
            assert_eq!(serde_json::from_str::<Rule>(name).unwrap(), rule);
        }
    }
}
