//! Which blocks a controller moves: the paper's four controllers, and the
//! optimizer's objective modes (the same names). A model notion both the
//! planner and the optimizer use, so it lives below both.

use crate::names::named_enum;

/// Which of the paper's controllers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// Uniform power and spin (the non-adaptive LiDAR; also the fail-safe).
    Baseline,
    /// Range control: `P_low` in the RoF, `P_high` in the RoI (eq. 3–4).
    Range,
    /// Resolution control: `ω_high` in the RoF, `ω_low` in the RoI (eq. 5–6).
    Resolution,
    /// Both.
    Joint,
}

named_enum!(Mode {
    Baseline => "baseline", "Uniform power and spin (the non-adaptive LiDAR; also the fail-safe)";
    Range => "range", "Range control: `P_low` in the RoF, `P_high` in the RoI (eq. 3–4)";
    Resolution => "resolution", "Resolution control: `ω_high` in the RoF, `ω_low` in the RoI (eq. 5–6)";
    Joint => "joint", "Both";
});

impl Mode {
    /// All modes, in the paper's order.
    pub const ALL: [Mode; 4] = [Mode::Baseline, Mode::Range, Mode::Resolution, Mode::Joint];

    /// Whether the power is modulated.
    #[must_use]
    pub fn controls_range(self) -> bool {
        matches!(self, Self::Range | Self::Joint)
    }

    /// Whether the spin is modulated.
    #[must_use]
    pub fn controls_resolution(self) -> bool {
        matches!(self, Self::Resolution | Self::Joint)
    }
}
