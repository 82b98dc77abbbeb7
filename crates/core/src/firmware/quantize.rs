//! Integer quantization of dwell times: a bounded largest-remainder
//! apportionment. Pure integer code, no allocation tricks: the part of the
//! crate the Kani harnesses point at.

use alloc::vec::Vec;

use thiserror::Error;

/// One bin's ideal dwell in ticks, as `floor + frac / 2^32`, with the
/// integer bounds the result must respect (from the spin limits).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TickTarget {
    /// `floor(ideal)`.
    pub floor: u64,
    /// Fractional part of the ideal, in units of 2^-32 tick.
    pub frac: u32,
    /// Smallest allowed result.
    pub min: u64,
    /// Largest allowed result.
    pub max: u64,
}

impl TickTarget {
    /// Smallest admissible result: `floor`, or `floor + 1` if `floor < min`.
    /// `None` if neither `floor` nor `ceil` lies in `[min, max]`.
    #[must_use]
    pub fn low(&self) -> Option<u64> {
        let ceil = self.ceil()?;
        if self.floor >= self.min && self.floor <= self.max {
            Some(self.floor)
        } else if ceil >= self.min && ceil <= self.max {
            Some(ceil)
        } else {
            None
        }
    }

    /// Largest admissible result.
    #[must_use]
    pub fn high(&self) -> Option<u64> {
        let ceil = self.ceil()?;
        if ceil >= self.min && ceil <= self.max {
            Some(ceil)
        } else if self.floor >= self.min && self.floor <= self.max {
            Some(self.floor)
        } else {
            None
        }
    }

    /// `ceil(ideal)`; `None` on overflow.
    #[must_use]
    pub fn ceil(&self) -> Option<u64> {
        if self.frac == 0 {
            Some(self.floor)
        } else {
            self.floor.checked_add(1)
        }
    }
}

/// Why no table within one tick of every dwell and within bounds sums to the frame.
#[derive(Debug, Error, Clone, PartialEq, Eq)]
pub enum QuantizeError {
    /// A bin admits neither floor nor ceil.
    #[error("bin {bin}: neither floor nor ceil of its dwell lies within its tick bounds")]
    BinBounds {
        /// Bin index.
        bin: usize,
    },
    /// The frame cannot be met by rounding each bin up or down.
    #[error("frame of {total} ticks is outside the reachable range {low}..={high}")]
    Total {
        /// Requested total.
        total: u64,
        /// Sum of the smallest admissible values.
        low: u128,
        /// Sum of the largest admissible values.
        high: u128,
    },
}

/// Rounds every target to `floor` or `ceil` within its bounds so that the
/// results sum to exactly `total`. Bins with larger fractional parts are
/// rounded up first (ties: lower index first).
///
/// Guarantees (proved by the harnesses below where Kani runs, tested here):
/// the sum is exactly `total`; every result is the floor or the ceil of its
/// ideal and within `[min, max]`; a bin rounded up never has a smaller
/// fractional part than a flexible bin rounded down.
pub fn apportion(targets: &[TickTarget], total: u64) -> Result<Vec<u64>, QuantizeError> {
    let mut out = Vec::with_capacity(targets.len());
    let mut low_sum: u128 = 0;
    let mut high_sum: u128 = 0;
    for (bin, t) in targets.iter().enumerate() {
        let (Some(lo), Some(hi)) = (t.low(), t.high()) else {
            return Err(QuantizeError::BinBounds { bin });
        };
        low_sum += u128::from(lo);
        high_sum += u128::from(hi);
        out.push(lo);
    }
    let total_wide = u128::from(total);
    if total_wide < low_sum || total_wide > high_sum {
        return Err(QuantizeError::Total {
            total,
            low: low_sum,
            high: high_sum,
        });
    }
    // need <= high_sum - low_sum <= number of flexible bins.
    let need = total_wide - low_sum;
    let mut flexible: Vec<usize> = (0..targets.len())
        .filter(|&i| targets[i].high() > targets[i].low())
        .collect();
    flexible.sort_by(|&a, &b| targets[b].frac.cmp(&targets[a].frac).then(a.cmp(&b)));
    for &i in flexible.iter().take(need as usize) {
        out[i] += 1;
    }
    Ok(out)
}

/// Lowers `codes` (never below `min`, never raised) until
/// `Σ codes[i]·weights[i] <= budget`, in exact integer arithmetic: the
/// energy budget as [`check_integer`](super::check_integer) reads it.
///
/// Rounding each dwell to a whole tick (and each code down to the DAC's step)
/// can leave a table a few code·ticks over a budget its float profile met;
/// the quantizer rounds towards safety, so it takes the excess out of the
/// codes: one code at a time, heaviest bins first (ties: lower index first),
/// in passes until the energy fits or every code is at `min`. Returns the
/// energy left (`<= budget` unless every code reached `min`).
///
/// `weights` and `codes` have the same length (extra entries of the longer
/// one are ignored).
pub fn lower_to_budget(codes: &mut [u32], weights: &[u64], min: u32, budget: u64) -> u128 {
    let n = codes.len().min(weights.len());
    let mut energy: u128 = (0..n)
        .map(|i| u128::from(codes[i]) * u128::from(weights[i]))
        .sum();
    let budget = u128::from(budget);
    if energy <= budget {
        return energy;
    }
    let mut order: Vec<usize> = (0..n).filter(|&i| weights[i] > 0).collect();
    order.sort_by(|&a, &b| weights[b].cmp(&weights[a]).then(a.cmp(&b)));
    // A whole pass lowers every code above `min` by one; when the excess
    // needs many passes, take them at once (each code lowered by the same
    // `k`, never below `min`), then finish one code at a time.
    let lowerable: u128 = order
        .iter()
        .filter(|&&i| codes[i] > min)
        .map(|&i| u128::from(weights[i]))
        .sum();
    if let Some(passes) = (energy - budget).checked_div(lowerable) {
        if passes > 1 {
            let k = u32::try_from(passes - 1).unwrap_or(u32::MAX);
            for &i in &order {
                let lowered = codes[i].saturating_sub(k).max(min).min(codes[i]);
                energy -= u128::from(codes[i] - lowered) * u128::from(weights[i]);
                codes[i] = lowered;
            }
        }
    }
    while energy > budget {
        let mut progress = false;
        for &i in &order {
            if energy <= budget {
                break;
            }
            if codes[i] > min {
                codes[i] -= 1;
                energy -= u128::from(weights[i]);
                progress = true;
            }
        }
        if !progress {
            break;
        }
    }
    energy
}

/// `ceil(value / step)` for a non-negative power and a positive step, exact
/// at the boundaries as [`floor_code`]: the smallest code whose power
/// `code·step` is at least `value`. `None` if it does not fit a `u32` or
/// the inputs are not finite and non-negative.
#[cfg(feature = "std")]
#[must_use]
pub fn ceil_code(value: f64, step: f64) -> Option<u32> {
    let code = floor_code(value, step)?;
    if f64::from(code) * step >= value {
        Some(code)
    } else {
        code.checked_add(1)
    }
}

/// `floor(value / step)` for a non-negative power and a positive step, exact
/// at the boundaries (a float quotient that rounds across an integer is
/// corrected): `code·step <= value < (code+1)·step`. `None` if it does not
/// fit a `u32` or the inputs are not finite and non-negative.
#[cfg(feature = "std")]
#[must_use]
pub fn floor_code(value: f64, step: f64) -> Option<u32> {
    if !(value.is_finite() && step.is_finite() && value >= 0.0 && step > 0.0) {
        return None;
    }
    let q = (value / step).floor();
    if q > f64::from(u32::MAX) {
        return None;
    }
    let mut code = q as u32;
    if f64::from(code) * step > value {
        code = code.checked_sub(1)?;
    } else if code < u32::MAX && f64::from(code + 1) * step <= value {
        code += 1;
    }
    Some(code)
}

#[cfg(any(kani, test))]
pub(crate) mod verification {
    use super::*;
    use crate::verification::{cover, for_all};

    /// Bounded symbolic targets: `n <= 4` bins, small magnitudes.
    fn targets_from(raw: &[(u8, u8, u8, u8)]) -> Vec<TickTarget> {
        raw.iter()
            .map(|&(floor, frac, min, span)| TickTarget {
                floor: u64::from(floor),
                frac: u32::from(frac) << 24,
                min: u64::from(min),
                max: u64::from(min) + u64::from(span),
            })
            .collect()
    }

    /// Targets and a frame total from raw input: as drawn (`shaped` false),
    /// or shaped so that an apportionment usually exists — each bin's bounds
    /// start at most 2 ticks below its floor, and the total lies within one
    /// tick of the sum of the lowest admissible roundings. Under Kani
    /// `shaped` is symbolic too, so the raw branch still covers every input;
    /// under `cargo test` the shaped branch makes the success covers likely
    /// (raw, a success with several bins is about one draw in 6,000).
    pub(crate) fn targets_and_total(
        raw: &[(u8, u8, u8, u8)],
        total: u16,
        shaped: bool,
    ) -> (Vec<TickTarget>, u64) {
        if !shaped {
            return (targets_from(raw), u64::from(total % 1100));
        }
        let targets: Vec<TickTarget> = raw
            .iter()
            .map(|&(floor, frac, below, span)| {
                let floor = u64::from(floor);
                let min = floor.saturating_sub(u64::from(below % 3));
                TickTarget {
                    floor,
                    frac: u32::from(frac) << 24,
                    min,
                    max: min + u64::from(span % 4),
                }
            })
            .collect();
        let low: u64 = targets.iter().map(|t| t.low().unwrap_or(0)).sum();
        (targets, low.saturating_sub(1) + u64::from(total % 4))
    }

    /// REQ-FW-1: the ticks sum to the frame exactly; each is the floor or
    /// ceil of its ideal and within its bounds; larger remainders round up first.
    #[cfg_attr(kani, kani::proof, kani::unwind(6))]
    #[cfg_attr(not(kani), test)]
    fn apportion_is_exact_and_within_one_tick() {
        for_all!(([(u8, u8, u8, u8); 4], u8, u16, bool), |(
            raw,
            n,
            total,
            shaped,
        )| {
            let n = usize::from(n % 5);
            let (targets, total) = targets_and_total(&raw[..n], total, shaped);
            match apportion(&targets, total) {
                Ok(r) => {
                    cover!(n >= 2, "several bins apportioned");
                    assert_eq!(r.len(), n);
                    assert_eq!(
                        r.iter().map(|&x| u128::from(x)).sum::<u128>(),
                        u128::from(total)
                    );
                    for (t, &x) in targets.iter().zip(&r) {
                        assert!(x == t.floor || Some(x) == t.ceil());
                        assert!(t.min <= x && x <= t.max);
                    }
                    for a in 0..n {
                        for b in 0..n {
                            let up_a = Some(r[a]) == targets[a].ceil()
                                && targets[a].frac > 0
                                && targets[a].low() == Some(targets[a].floor);
                            let down_b =
                                r[b] == targets[b].floor && targets[b].high() > targets[b].low();
                            if up_a && down_b {
                                assert!(targets[a].frac >= targets[b].frac);
                            }
                        }
                    }
                }
                Err(QuantizeError::Total { low, high, .. }) => {
                    cover!(true, "unreachable frame rejected");
                    assert!(u128::from(total) < low || u128::from(total) > high);
                }
                Err(QuantizeError::BinBounds { bin }) => {
                    cover!(true, "bin without admissible rounding rejected");
                    assert!(targets[bin].low().is_none());
                }
            }
        });
        #[cfg(not(kani))]
        crate::verification::assert_covered(&[
            "several bins apportioned",
            "unreachable frame rejected",
            "bin without admissible rounding rejected",
        ]);
    }

    /// REQ-FW-2: lowering to a budget never raises a code, never goes
    /// below the minimum, and meets the budget unless every code is at the
    /// minimum; the energy it returns is the table's (plain restatement).
    #[cfg_attr(kani, kani::proof, kani::unwind(8))]
    #[cfg_attr(not(kani), test)]
    fn lowering_to_a_budget_is_sound() {
        for_all!(([(u8, u8); 4], u8, u8, u16), |(raw, n, min, budget)| {
            let n = 1 + usize::from(n % 4);
            let mut codes: Vec<u32> = raw[..n].iter().map(|r| u32::from(r.0)).collect();
            let weights: Vec<u64> = raw[..n].iter().map(|r| u64::from(r.1)).collect();
            let before = codes.clone();
            let min = u32::from(min % 8);
            let budget = u64::from(budget);
            let energy = lower_to_budget(&mut codes, &weights, min, budget);
            let plain: u128 = codes
                .iter()
                .zip(&weights)
                .map(|(&c, &w)| u128::from(c) * u128::from(w))
                .sum();
            assert_eq!(energy, plain);
            for (a, b) in codes.iter().zip(&before) {
                assert!(a <= b);
                assert!(*a >= min.min(*b));
            }
            let floor_reached = codes
                .iter()
                .zip(&before)
                .zip(&weights)
                .all(|((&c, &b), &w)| w == 0 || c == min.min(b));
            cover!(
                energy <= u128::from(budget) && codes != before,
                "lowered to fit"
            );
            assert!(energy <= u128::from(budget) || floor_reached);
        });
        #[cfg(not(kani))]
        crate::verification::assert_covered(&["lowered to fit"]);
    }

    /// REQ-FW-2: a power code never exceeds the certified power and is within one code of it.
    #[cfg_attr(kani, kani::proof)]
    #[cfg_attr(not(kani), test)]
    fn power_code_is_conservative() {
        for_all!((u32, u16), |(units, step_units)| {
            // Integer-valued inputs keep the float arithmetic exact, so the
            // property is decidable (Kani is weak on general floats).
            let step = f64::from(step_units.max(1));
            let value = f64::from(units);
            let code = floor_code(value, step).expect("finite non-negative inputs");
            cover!(code > 0, "non-zero code");
            assert!(f64::from(code) * step <= value);
            assert!(value < f64::from(code) * step + step);
        });
        #[cfg(not(kani))]
        crate::verification::assert_covered(&["non-zero code"]);
    }
}
