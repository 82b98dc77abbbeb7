//! Exact sums of products of doubles in fixed point: the certificate's
//! arithmetic ([`super::certificate::check`]).
//!
//! Every finite double is `m·2^e` with an integer `|m| < 2^53` and
//! `e ∈ [−1074, 971]`; a product of two is `m·2^e` with `|m| < 2^106` and
//! `e ≥ −2148`. So every sum of such products is an integer multiple of
//! `2^−2148`, and a two's-complement integer of a fixed width, counted in
//! units of `2^MIN` (`MIN ≤ −2148`), holds it **exactly** (a *long
//! accumulator*): adding a term is adding a shifted 128-bit integer into
//! three 64-bit limbs plus a carry, with no allocation and no gcd, where a
//! general rational (or a big integer per term) allocates on every
//! operation. The widths below leave hundreds of bits of head-room above
//! the largest possible sum; a term outside the range (impossible for
//! finite doubles, by the bounds above) marks the sum as overflowed rather
//! than losing bits, and the check then refuses.

use num_bigint::{BigInt, BigUint, Sign};
use num_rational::BigRational;

/// Limbs of a sum of products of two doubles.
pub(super) const SUM_LIMBS: usize = 70;
/// Its unit exponent: `2^−2176`, below every product's `2^−2148`.
pub(super) const SUM_MIN: i64 = -2176;
/// Limbs of a sum of (sum of products) × double: units `2^−3264`, below
/// `2^(−2176−1074)`; top `2^(−3264+64·104) = 2^3392`, above `2^(2304+1024)`.
pub(super) const WIDE_LIMBS: usize = 104;
/// Its unit exponent.
pub(super) const WIDE_MIN: i64 = -3264;

/// `v = (negative, m, e)` with `|v| = m·2^e` exactly (`v` finite).
fn decode(v: f64) -> (bool, u64, i64) {
    let bits = v.to_bits();
    let neg = bits >> 63 == 1;
    let field = ((bits >> 52) & 0x7ff) as i64;
    let frac = bits & ((1u64 << 52) - 1);
    if field == 0 {
        (neg, frac, -1074)
    } else {
        (neg, frac | (1u64 << 52), field - 1075)
    }
}

/// An exact sum `Σ terms` in two's complement, in units of `2^MIN`.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Acc<const L: usize, const MIN: i64> {
    limbs: [u64; L],
    /// A term fell outside the range (never, for finite doubles).
    overflow: bool,
}

impl<const L: usize, const MIN: i64> Default for Acc<L, MIN> {
    fn default() -> Self {
        Self {
            limbs: [0; L],
            overflow: false,
        }
    }
}

/// A sum of products of doubles.
pub(super) type Sum = Acc<SUM_LIMBS, SUM_MIN>;
/// A sum of (sums of products) × doubles.
pub(super) type Wide = Acc<WIDE_LIMBS, WIDE_MIN>;

impl<const L: usize, const MIN: i64> Acc<L, MIN> {
    /// Adds `±mag·2^exp`.
    fn add_term(&mut self, neg: bool, mag: u128, exp: i64) {
        if mag == 0 {
            return;
        }
        let s = exp - MIN;
        // The term's top bit must stay two limbs under the sign limb.
        let top = s + 128;
        if s < 0 || top >= 64 * (L as i64 - 1) {
            self.overflow = true;
            return;
        }
        let (li, off) = ((s / 64) as usize, (s % 64) as u32);
        let shifted = mag << off;
        let words = [
            shifted as u64,
            (shifted >> 64) as u64,
            if off == 0 {
                0
            } else {
                (mag >> (128 - off)) as u64
            },
        ];
        if neg {
            let mut borrow = false;
            for (k, &w) in words.iter().enumerate() {
                let (a, b1) = self.limbs[li + k].overflowing_sub(w);
                let (a, b2) = a.overflowing_sub(u64::from(borrow));
                self.limbs[li + k] = a;
                borrow = b1 || b2;
            }
            let mut k = li + 3;
            while borrow && k < L {
                let (a, b) = self.limbs[k].overflowing_sub(1);
                self.limbs[k] = a;
                borrow = b;
                k += 1;
            }
        } else {
            let mut carry = false;
            for (k, &w) in words.iter().enumerate() {
                let (a, c1) = self.limbs[li + k].overflowing_add(w);
                let (a, c2) = a.overflowing_add(u64::from(carry));
                self.limbs[li + k] = a;
                carry = c1 || c2;
            }
            let mut k = li + 3;
            while carry && k < L {
                let (a, c) = self.limbs[k].overflowing_add(1);
                self.limbs[k] = a;
                carry = c;
                k += 1;
            }
        }
    }

    /// Adds `a·b` exactly (`a`, `b` finite).
    pub(super) fn add_product(&mut self, a: f64, b: f64) {
        let (na, ma, ea) = decode(a);
        let (nb, mb, eb) = decode(b);
        self.add_term(na != nb, u128::from(ma) * u128::from(mb), ea + eb);
    }

    /// Adds `v` exactly (finite).
    pub(super) fn add(&mut self, v: f64) {
        let (n, m, e) = decode(v);
        self.add_term(n, u128::from(m), e);
    }

    /// Subtracts `v` exactly (finite).
    pub(super) fn sub(&mut self, v: f64) {
        let (n, m, e) = decode(v);
        self.add_term(!n, u128::from(m), e);
    }

    /// Adds `s·b` exactly for another accumulator `s` and a finite `b`.
    pub(super) fn add_scaled<const L2: usize, const MIN2: i64>(
        &mut self,
        s: &Acc<L2, MIN2>,
        b: f64,
    ) {
        self.overflow |= s.overflow;
        let (ns, mag) = s.magnitude();
        let (nb, mb, eb) = decode(b);
        for (k, &limb) in mag.iter().enumerate() {
            if limb != 0 {
                self.add_term(
                    ns != nb,
                    u128::from(limb) * u128::from(mb),
                    MIN2 + 64 * k as i64 + eb,
                );
            }
        }
    }

    /// Sign and magnitude limbs.
    fn magnitude(&self) -> (bool, [u64; L]) {
        if self.limbs[L - 1] >> 63 == 0 {
            return (false, self.limbs);
        }
        let mut m = [0u64; L];
        let mut carry = true;
        for (o, &l) in m.iter_mut().zip(&self.limbs) {
            let (a, c) = (!l).overflowing_add(u64::from(carry));
            *o = a;
            carry = c;
        }
        (true, m)
    }

    /// Whether a term fell outside the range (the sum is then unknown).
    pub(super) fn overflowed(&self) -> bool {
        self.overflow
    }

    /// The sign of the sum.
    pub(super) fn signum(&self) -> std::cmp::Ordering {
        use std::cmp::Ordering::{Equal, Greater, Less};
        if self.limbs[L - 1] >> 63 == 1 {
            Less
        } else if self.limbs.iter().all(|&l| l == 0) {
            Equal
        } else {
            Greater
        }
    }

    /// The sign of `sum − v` (`v` finite).
    pub(super) fn cmp_f64(&self, v: f64) -> std::cmp::Ordering {
        let mut d = self.clone();
        d.sub(v);
        d.signum()
    }

    /// The sum as a rational (exact).
    pub(super) fn rational(&self) -> BigRational {
        let (neg, mag) = self.magnitude();
        let digits: Vec<u32> = mag
            .iter()
            .flat_map(|&l| [l as u32, (l >> 32) as u32])
            .collect();
        let m = BigInt::from_biguint(
            if neg { Sign::Minus } else { Sign::Plus },
            BigUint::new(digits),
        );
        let den = BigInt::from(1) << usize::try_from(-MIN).unwrap_or(0);
        BigRational::new(m, den)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn q(v: f64) -> BigRational {
        BigRational::from_float(v).unwrap()
    }

    /// Doubles over the whole finite range, both signs, subnormals and
    /// zeros included.
    fn any_double() -> impl Strategy<Value = f64> {
        prop_oneof![
            any::<u64>()
                .prop_map(f64::from_bits)
                .prop_filter("finite", |v| v.is_finite()),
            (-1e3f64..1e3),
            Just(0.0),
            Just(-0.0),
            Just(f64::MIN_POSITIVE / 8.0),
            Just(f64::MAX),
            Just(-f64::MAX),
        ]
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(300))]

        /// The long accumulator against plain rationals (the reference):
        /// sums of products, of scaled sums, and their signs.
        #[test]
        fn sums_of_products_are_exact(
            terms in proptest::collection::vec((any_double(), any_double()), 0..12),
            extra in proptest::collection::vec(any_double(), 0..4),
            scale in any_double(),
        ) {
            let mut acc = Sum::default();
            let mut reference = q(0.0);
            for &(a, b) in &terms {
                acc.add_product(a, b);
                reference += q(a) * q(b);
            }
            for &v in &extra {
                acc.sub(v);
                reference -= q(v);
            }
            prop_assert!(!acc.overflowed());
            prop_assert_eq!(acc.rational(), reference.clone());
            prop_assert_eq!(acc.signum(), reference.cmp(&q(0.0)));
            let mut wide = Wide::default();
            wide.add_scaled(&acc, scale);
            wide.add(1.5);
            prop_assert!(!wide.overflowed());
            prop_assert_eq!(wide.rational(), reference * q(scale) + q(1.5));
        }
    }

    #[test]
    fn extreme_products_stay_in_range_and_cancel_exactly() {
        let tiny = f64::from_bits(1); // 2^−1074
        let mut acc = Sum::default();
        acc.add_product(tiny, tiny);
        acc.add_product(f64::MAX, f64::MAX);
        acc.add_product(-f64::MAX, f64::MAX);
        assert!(!acc.overflowed());
        assert_eq!(acc.rational(), q(tiny) * q(tiny));
        assert_eq!(acc.cmp_f64(0.0), std::cmp::Ordering::Greater);
        acc.add_product(-tiny, tiny);
        assert_eq!(acc.signum(), std::cmp::Ordering::Equal);
        let mut wide = Wide::default();
        let mut big = Sum::default();
        for _ in 0..1000 {
            big.add_product(f64::MAX, f64::MAX);
        }
        wide.add_scaled(&big, f64::MAX);
        wide.add_scaled(&big, -tiny);
        assert!(!wide.overflowed());
        assert_eq!(
            wide.rational(),
            q(1000.0) * q(f64::MAX) * q(f64::MAX) * (q(f64::MAX) - q(tiny))
        );
    }
}
