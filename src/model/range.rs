//! The range equation: **the one model** of how far a pulse of a given power
//! reaches. The simulator's `physical` return model
//! ([`crate::model::returns::ReturnModel`]) and the profile figures
//! ([`crate::planner::figures`]) both call it.
//!
//! Extended Lambertian target (a target wider than the beam): the received signal is
//! `P_r ∝ P·ρ·cos θ·e^(−2αR)/R²`. Calibrated on the sensor's rating — a pulse
//! at the average power `P̄` reaches its rated range `R₀` on the reference
//! reflectivity `ρ₀` in clear air (extinction `α₀`), i.e. there the signal
//! equals the detection threshold — the signal relative to that threshold is
//!
//! `S(R) = (P/P̄)·(ρ/ρ₀)·cos θ·(R₀/R)²·e^(−2αR + 2α₀R₀)`,
//!
//! and the range at a power is the `R` with `S(R) = 1` at normal incidence
//! ([`RangeEquation::range_m`]). Without extinction that is
//! `R = R₀·√((P/P̄)·(ρ/ρ₀))` (range ∝ √P); clear air's `α₀ = 2.996/20 km`
//! shortens a gain slightly.
//!
//! Extinction from visibility: the meteorological optical range (MOR, 5 %
//! contrast) gives `α = 2.996 / MOR` (2 % contrast, Koschmieder, would give
//! `3.912 / V`); clear air is a MOR of [`CLEAR_AIR_MOR_M`].

/// Meteorological optical range of clear air, m.
pub const CLEAR_AIR_MOR_M: f64 = 20_000.0;

/// Extinction coefficient `α = 2.996 / MOR`, 1/m.
#[must_use]
pub fn extinction_per_m(mor_m: f64) -> f64 {
    2.996 / mor_m
}

/// The range equation calibrated on a sensor's rating.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RangeEquation {
    /// Rated range `R₀` at the average power on the reference reflectivity
    /// in clear air, m.
    pub rated_range_m: f64,
    /// Reference reflectivity `ρ₀`.
    pub reference_reflectivity: f64,
    /// Clear-air extinction `α₀` of the rating, 1/m.
    pub clear_extinction_per_m: f64,
}

impl RangeEquation {
    /// The rating `rated_range_m` on `reference_reflectivity`, in clear air
    /// ([`CLEAR_AIR_MOR_M`]).
    #[must_use]
    pub fn rated(rated_range_m: f64, reference_reflectivity: f64) -> Self {
        Self {
            rated_range_m,
            reference_reflectivity,
            clear_extinction_per_m: extinction_per_m(CLEAR_AIR_MOR_M),
        }
    }

    /// The factor of `S` that depends on the range and the air alone:
    /// `e^(−2αR + 2α₀R₀)`.
    #[must_use]
    pub fn extinction_factor(&self, extinction_per_m: f64, range_m: f64) -> f64 {
        (-2.0 * extinction_per_m * range_m + 2.0 * self.clear_extinction_per_m * self.rated_range_m)
            .exp()
    }

    /// `scale · S(R)`, given `factor = extinction_factor(α, R)` (`scale`
    /// multiplies first: the simulator's amplitude in noise-σ units is
    /// `T · S`, and a `scale` of 1 gives `S`).
    #[must_use]
    pub fn signal(
        &self,
        scale: f64,
        power_ratio: f64,
        reflectivity: f64,
        cos_incidence: f64,
        range_m: f64,
        factor: f64,
    ) -> f64 {
        let geometric = (self.rated_range_m / range_m).powi(2);
        scale
            * power_ratio
            * (reflectivity / self.reference_reflectivity)
            * cos_incidence
            * geometric
            * factor
    }

    /// The range `R` at which a normal-incidence target of `reflectivity`
    /// hit by a pulse of `power_ratio = P/P̄` returns exactly the threshold
    /// (`S(R) = 1`) in air of `extinction_per_m`, m; 0 for a power of 0.
    ///
    /// `ln S(R)` falls strictly and is convex in `R` (`d/dR = −2/R − 2α`),
    /// so Newton's method on it from the extinction-free solution
    /// `R₀·√((P/P̄)·(ρ/ρ₀))` converges monotonically after its first step;
    /// it stops when a step moves `R` by less than 1e-13 of it. At the
    /// rating itself it returns `R₀` exactly.
    #[must_use]
    pub fn range_m(&self, power_ratio: f64, reflectivity: f64, extinction_per_m: f64) -> f64 {
        let gain = power_ratio * (reflectivity / self.reference_reflectivity);
        if !(gain > 0.0 && gain.is_finite() && extinction_per_m >= 0.0) {
            return 0.0;
        }
        let mut r = self.rated_range_m * gain.sqrt();
        for _ in 0..100 {
            let s = self.signal(
                1.0,
                power_ratio,
                reflectivity,
                1.0,
                r,
                self.extinction_factor(extinction_per_m, r),
            );
            let step = s.ln() / (2.0 / r + 2.0 * extinction_per_m);
            r += step;
            if step.abs() <= 1e-13 * r {
                break;
            }
        }
        r
    }

    /// [`Self::range_m`] on the reference reflectivity in clear air: the
    /// sensor's range at `power_ratio` of its average power.
    #[must_use]
    pub fn rated_conditions_range_m(&self, power_ratio: f64) -> f64 {
        self.range_m(
            power_ratio,
            self.reference_reflectivity,
            self.clear_extinction_per_m,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use proptest::prelude::*;

    #[test]
    fn the_rating_is_a_fixed_point() {
        let eq = RangeEquation::rated(100.0, 0.1);
        assert_eq!(eq.rated_conditions_range_m(1.0), 100.0);
        assert_eq!(eq.rated_conditions_range_m(0.0), 0.0);
    }

    #[test]
    fn hand_worked_ranges() {
        // Without extinction: R = R₀·√(P/P̄): 245 m at 1.5 P̄ → 245·√1.5
        // = 300.0625 m (√1.5 = 1.2247449).
        let eq = RangeEquation {
            clear_extinction_per_m: 0.0,
            ..RangeEquation::rated(245.0, 0.1)
        };
        assert_relative_eq!(eq.range_m(1.5, 0.1, 0.0), 300.062_493_5, epsilon = 1e-6);
        // Clear air, α₀ = 2.996/20,000 = 1.498e-4 /m, R₀ = 100 m, P = 1.1 P̄:
        // 1.1·(100/R)²·e^(−2α₀(R − 100)) = 1 ⇔ R = 100·√1.1·e^(−α₀(R − 100)).
        // First guess 104.8809 m; e^(−1.498e-4·4.8809) = 0.999269 → 104.8042;
        // again: e^(−1.498e-4·4.8042) = 0.999280 → 104.8054; once more
        // 104.8054 (4.8054·1.498e-4 = 7.1985e-4, e^−… = 0.9992804).
        let clear = RangeEquation::rated(100.0, 0.1);
        assert_relative_eq!(
            clear.rated_conditions_range_m(1.1),
            104.8054,
            epsilon = 1e-3
        );
        // P_low = 0.5 P̄: 100·√0.5 = 70.7107; e^(1.498e-4·29.29) = 1.004397
        // → 71.0216; e^(1.498e-4·28.978) = 1.004350 → 71.0183.
        assert_relative_eq!(clear.rated_conditions_range_m(0.5), 71.0183, epsilon = 1e-3);
    }

    proptest! {
        /// The range solves the equation it comes from: `S(R) = 1`.
        #[test]
        fn range_solves_the_equation(
            r0 in 1.0f64..2000.0, rho0 in 0.01f64..1.0, p in 1e-6f64..100.0,
            rho in 0.01f64..1.0, mor in 10.0f64..1e6,
        ) {
            let eq = RangeEquation::rated(r0, rho0);
            let alpha = extinction_per_m(mor);
            let r = eq.range_m(p, rho, alpha);
            prop_assert!(r > 0.0 && r.is_finite());
            let s = eq.signal(1.0, p, rho, 1.0, r, eq.extinction_factor(alpha, r));
            prop_assert!((s - 1.0).abs() < 1e-9, "S({r}) = {s}");
            // More power reaches farther.
            prop_assert!(eq.range_m(p * 1.01, rho, alpha) > r);
        }
    }
}
