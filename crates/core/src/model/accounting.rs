//! How a power budget is accounted (integer firmware code needs it, so it
//! builds without `std`).

use serde::{Deserialize, Serialize};

/// How the average-power budget of a profile is accounted.
///
/// The paper's eq. 4 averages power over *angle*. When the spin varies, the
/// laser spends more *time* in slow sectors, so the angle average is not the
/// energy per frame; `Time` is the physical energy (thermal) budget.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum PowerAccounting {
    /// Energy per frame divided by the frame period (physical; the default).
    #[default]
    Time,
    /// `Σ P_i Δθ_i / 360°`, eq. 4 of the paper as printed.
    Angle,
}

impl core::fmt::Display for PowerAccounting {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            Self::Time => "time",
            Self::Angle => "angle",
        })
    }
}
