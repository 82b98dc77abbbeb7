//! Whether spin set-points can make one turn take the frame period on `N`
//! equal bins, before any solve.
//!
//! On `N` equal bins (`θ = 2π/N`) a profile at set-points takes
//! `t_i = θ/w_i` per bin, so its frame period is `(T/N)·Σ_i r_i` with
//! `r = ω̄/w` (`ω̄ = 2π·frame_rate_hz`): it depends only on how many bins
//! take each set-point (a composition of `N`). The checker accepts a frame
//! period within `REL_TOL` (10⁻⁹) of `T`, so a request is unreachable when
//! no composition brings `Σ r` within `1.2·10⁻⁹·N` of `N` (the float sums
//! here add less than 10⁻¹³ relative). The search enumerates the counts of
//! all set-points but the last two and solves for the split of the rest in
//! closed form (the sum is monotone in it); past a work budget it answers
//! "unknown" and the solve decides.

/// What [`reach`] found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Reach {
    /// Some composition is within the tolerance.
    Within,
    /// None is: the nearest sums below and above the target (in units of
    /// a bin's mean dwell), if any.
    Misses {
        below: Option<f64>,
        above: Option<f64>,
    },
    /// The work budget ran out first.
    Unknown,
}

struct Search<'a> {
    r: &'a [f64],
    target: f64,
    tol: f64,
    budget: u64,
    below: Option<f64>,
    above: Option<f64>,
    within: bool,
}

impl Search<'_> {
    fn consider(&mut self, v: f64) {
        if (v - self.target).abs() <= self.tol {
            self.within = true;
        } else if v < self.target {
            self.below = Some(self.below.map_or(v, |b| b.max(v)));
        } else {
            self.above = Some(self.above.map_or(v, |a| a.min(v)));
        }
    }

    /// Set-points `k..` share the `m` remaining bins; `s` is the sum so far.
    /// Returns false when the budget ran out.
    fn go(&mut self, k: usize, m: usize, s: f64) -> bool {
        if self.within {
            return true;
        }
        if self.budget == 0 {
            return false;
        }
        self.budget -= 1;
        let r = self.r;
        match r.len() - k {
            0 => true,
            1 => {
                self.consider(s + m as f64 * r[k]);
                true
            }
            2 => {
                // s + i·r[k] + (m − i)·r[k+1], monotone in i: the integers
                // around the exact split are the nearest on both sides.
                let (a, b) = (r[k], r[k + 1]);
                let base = s + m as f64 * b;
                if a == b {
                    self.consider(base);
                    return true;
                }
                let exact = (self.target - base) / (a - b);
                let mf = m as f64;
                for i in [exact.floor(), exact.ceil()] {
                    let i = i.clamp(0.0, mf);
                    self.consider(s + i * a + (mf - i) * b);
                }
                true
            }
            _ => {
                // The rest's sums lie between all `m` bins at its smallest
                // ratio and all at its largest (both reached): a subtree
                // wholly more than a tolerance off the target holds no
                // sum within it, and its nearest sum is that end.
                let (lo, hi) = span(r[k..].iter().copied(), m, s);
                if hi < self.target - 2.0 * self.tol {
                    self.consider(hi);
                    return true;
                }
                if lo > self.target + 2.0 * self.tol {
                    self.consider(lo);
                    return true;
                }
                (0..=m).all(|c| self.go(k + 1, m - c, s + c as f64 * r[k]))
            }
        }
    }
}

/// The least and greatest of `s + Σ c_j·r_j` over the counts `c` of `m`
/// bins on the ratios `r`: all `m` on the smallest ratio, all on the
/// largest.
fn span(r: impl Iterator<Item = f64>, m: usize, s: f64) -> (f64, f64) {
    let (lo, hi) = r.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
        (lo.min(x), hi.max(x))
    });
    let mf = m as f64;
    (s + mf * lo, s + mf * hi)
}

/// Whether `n` picks (with repetition) from the ratios `r` (`ω̄/w` per
/// allowed set-point, all > 0) can sum to `n` within `1.2·10⁻⁹·n`;
/// `budget` bounds the enumeration's steps.
pub(super) fn reach(r: &[f64], n: usize, budget: u64) -> Reach {
    let mut s = Search {
        r,
        target: n as f64,
        tol: 1.2e-9 * n as f64,
        budget,
        below: None,
        above: None,
        within: false,
    };
    let finished = s.go(0, n, 0.0);
    if s.within {
        Reach::Within
    } else if finished {
        Reach::Misses {
            below: s.below,
            above: s.above,
        }
    } else {
        Reach::Unknown
    }
}

/// Of the compositions of `n` bins over the ratios `r` (a count per
/// set-point) whose sum `Σ c_k·r_k` lies in `[lo, hi]`, the best by
/// `score` among those found near `near` (fractional counts, e.g. the LP
/// relaxation's): the counts of all set-points but two (the one with the
/// most bins in `near` and the one nearest it in ratio) within a radius of
/// `near`'s (1, 2, 4, … until some
/// composition fits or `budget` steps are spent), the split of the rest
/// between those two in closed form (the sum is monotone in it).
pub(super) fn best_composition(
    r: &[f64],
    n: usize,
    (lo, hi): (f64, f64),
    near: &[f64],
    score: &dyn Fn(&[usize]) -> f64,
    budget: u64,
) -> Option<Vec<usize>> {
    let k = r.len();
    if k == 0 || near.len() != k {
        return None;
    }
    // The set-point with the most bins and the one nearest it in ratio
    // take the rest (last in `order`): a line of splits between close
    // ratios is the likeliest to meet a narrow band.
    let top = (0..k)
        .max_by(|&a, &b| near[a].total_cmp(&near[b]).then(b.cmp(&a)))
        .unwrap_or(0);
    let mate = (0..k).filter(|&j| j != top).min_by(|&a, &b| {
        (r[a] - r[top])
            .abs()
            .total_cmp(&(r[b] - r[top]).abs())
            .then(a.cmp(&b))
    });
    let mut order: Vec<usize> = (0..k).filter(|&j| j != top && Some(j) != mate).collect();
    order.sort_by(|&a, &b| near[a].total_cmp(&near[b]).then(a.cmp(&b)));
    order.extend(mate);
    order.push(top);
    let free = k.saturating_sub(2);
    let mut steps = budget;
    let mut radius = 1usize;
    loop {
        let mut best: Option<(f64, Vec<usize>)> = None;
        let mut counts = vec![0usize; k];
        let exhausted = !around(
            &mut Around {
                r,
                order: &order,
                free,
                near,
                radius,
                band: (lo, hi),
                score,
                steps: &mut steps,
                best: &mut best,
            },
            0,
            n,
            0.0,
            &mut counts,
        );
        if let Some((_, c)) = best {
            return Some(c);
        }
        // The whole box searched once the radius covers every count.
        if exhausted || radius > n {
            return None;
        }
        radius *= 2;
    }
}

struct Around<'a> {
    r: &'a [f64],
    order: &'a [usize],
    free: usize,
    near: &'a [f64],
    radius: usize,
    band: (f64, f64),
    score: &'a dyn Fn(&[usize]) -> f64,
    steps: &'a mut u64,
    best: &'a mut Option<(f64, Vec<usize>)>,
}

impl Around<'_> {
    fn offer(&mut self, counts: &[usize], sum: f64) {
        if sum < self.band.0 || sum > self.band.1 {
            return;
        }
        let v = (self.score)(counts);
        if self.best.as_ref().is_none_or(|b| v > b.0) {
            *self.best = Some((v, counts.to_vec()));
        }
    }
}

/// Depth `d` of [`best_composition`]'s search: `m` bins left, partial sum
/// `s`; false when the step budget ran out.
fn around(a: &mut Around<'_>, d: usize, m: usize, s: f64, counts: &mut [usize]) -> bool {
    if *a.steps == 0 {
        return false;
    }
    *a.steps -= 1;
    let k = a.order.len();
    if d < a.free {
        // No composition of the rest reaches the band (a relative 10⁻⁹ of
        // head-room over the float sums' 10⁻¹³): nothing to offer here.
        let (lo, hi) = span(a.order[d..].iter().map(|&j| a.r[j]), m, s);
        let slack = 1e-9 * a.band.1.abs().max(1.0);
        if hi < a.band.0 - slack || lo > a.band.1 + slack {
            return true;
        }
        let j = a.order[d];
        // `near`'s count, within what is left (the box then reaches every
        // count once the radius reaches `m`).
        let c0 = (a.near[j].round().max(0.0) as usize).min(m);
        let from = c0.saturating_sub(a.radius);
        let to = (c0 + a.radius).min(m);
        for c in from..=to {
            counts[j] = c;
            if !around(a, d + 1, m - c, s + c as f64 * a.r[j], counts) {
                counts[j] = 0;
                return false;
            }
        }
        counts[j] = 0;
        return true;
    }
    match k - d {
        1 => {
            let j = a.order[d];
            counts[j] = m;
            a.offer(counts, s + m as f64 * a.r[j]);
            counts[j] = 0;
        }
        2 => {
            let (ja, jb) = (a.order[d], a.order[d + 1]);
            let (ra, rb) = (a.r[ja], a.r[jb]);
            let mf = m as f64;
            let base = s + mf * rb;
            // i bins at `ra`, m − i at `rb`: the integers around the ends
            // of the band's interval of i.
            let cands: Vec<f64> = if ra == rb {
                vec![0.0]
            } else {
                let (x0, x1) = ((a.band.0 - base) / (ra - rb), (a.band.1 - base) / (ra - rb));
                let (x0, x1) = (x0.min(x1), x0.max(x1));
                let mut v = vec![x0.floor(), x0.ceil(), x1.floor(), x1.ceil()];
                // A wide band: its middle too.
                v.push((0.5 * (x0 + x1)).round());
                v
            };
            for i in cands {
                let i = i.clamp(0.0, mf);
                counts[ja] = i as usize;
                counts[jb] = m - i as usize;
                a.offer(counts, s + i * ra + (mf - i) * rb);
            }
            counts[ja] = 0;
            counts[jb] = 0;
        }
        _ => {}
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Every composition of `n` over `r.len()` set-points, plainly.
    fn brute(r: &[f64], n: usize) -> Vec<f64> {
        fn rec(r: &[f64], m: usize, s: f64, out: &mut Vec<f64>) {
            if r.len() == 1 {
                out.push(s + m as f64 * r[0]);
                return;
            }
            for c in 0..=m {
                rec(&r[1..], m - c, s + c as f64 * r[0], out);
            }
        }
        let mut out = Vec::new();
        rec(r, n, 0.0, &mut out);
        out
    }

    proptest! {
        /// Differential: the closed-form search agrees with enumerating
        /// every composition (within, or the same nearest sums).
        #[test]
        fn agrees_with_enumeration(
            r in proptest::collection::vec(0.3f64..3.0, 1..5),
            n in 1usize..40,
            exact in any::<bool>(),
        ) {
            // Half the cases with set-points that do reach (r = 1 present).
            let mut r = r;
            if exact {
                r.push(1.0);
            }
            let all = brute(&r, n);
            let tol = 1.2e-9 * n as f64;
            let target = n as f64;
            let within = all.iter().any(|v| (v - target).abs() <= tol);
            match reach(&r, n, u64::MAX) {
                Reach::Within => prop_assert!(within),
                Reach::Misses { below, above } => {
                    prop_assert!(!within);
                    let b = all.iter().copied().filter(|&v| v < target).fold(None, |m: Option<f64>, v| Some(m.map_or(v, |m| m.max(v))));
                    let a = all.iter().copied().filter(|&v| v > target).fold(None, |m: Option<f64>, v| Some(m.map_or(v, |m| m.min(v))));
                    let close = |x: Option<f64>, y: Option<f64>| match (x, y) {
                        (Some(x), Some(y)) => (x - y).abs() <= 1e-12 * x.abs().max(1.0),
                        (None, None) => true,
                        _ => false,
                    };
                    prop_assert!(close(below, b), "{below:?} {b:?}");
                    prop_assert!(close(above, a), "{above:?} {a:?}");
                }
                Reach::Unknown => prop_assert!(false, "unbounded budget"),
            }
        }
    }

    proptest! {
        /// Differential: with an unlimited budget the composition search
        /// finds a composition in the band exactly when enumeration does,
        /// and what it returns is one (counts summing to `n`, sum in band).
        #[test]
        fn best_composition_finds_the_band_when_enumeration_does(
            r in proptest::collection::vec(0.3f64..3.0, 1..5),
            n in 1usize..30,
            width in 0.0f64..0.3,
            near in proptest::collection::vec(0.0f64..30.0, 5),
        ) {
            let band = (n as f64 - width, n as f64 + width);
            let near = &near[..r.len()];
            let all = brute(&r, n);
            let any = all.iter().any(|&v| v >= band.0 && v <= band.1);
            let score = |c: &[usize]| c.iter().zip(&r).map(|(&c, &x)| c as f64 * x.sqrt()).sum();
            match best_composition(&r, n, band, near, &score, u64::MAX) {
                Some(c) => {
                    prop_assert_eq!(c.iter().sum::<usize>(), n);
                    let v: f64 = c.iter().zip(&r).map(|(&c, &x)| c as f64 * x).sum();
                    prop_assert!(v >= band.0 - 1e-9 && v <= band.1 + 1e-9, "{v} outside {band:?}");
                }
                None => prop_assert!(!any, "enumeration finds a composition in the band"),
            }
        }
    }

    /// The set-points of `tests/it/optimizer/dwell_certificate_adversarial.rs` (24
    /// bins): the best composition is 4.1e-4 off.
    #[test]
    fn a_known_miss() {
        let w_mean = std::f64::consts::TAU * 20.0; // the paper preset
        let sp = [
            118.8631000948167,
            174.2955077230426,
            204.56011000022755,
            209.66075882411533,
        ];
        let r: Vec<f64> = sp.iter().map(|w| w_mean / w).collect();
        assert!(matches!(reach(&r, 24, u64::MAX), Reach::Misses { .. }));
        // A budget too small to finish says so.
        assert_eq!(reach(&r, 24, 3), Reach::Unknown);
    }
}
