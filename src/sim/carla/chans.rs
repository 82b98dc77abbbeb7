//! A set of channel indices as a bitmask of `W` words (CARLA allows up to
//! 256 channels: `W = 4`; the paper's 64 fit one word): the fast path of
//! [`super::run_group`] handles a pulse's rays as sets.

use std::ops::{BitAnd, BitOr, BitOrAssign, Not};

/// Channels `0..64·W` as `W` 64-bit words.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Chans<const W: usize>([u64; W]);

impl<const W: usize> Chans<W> {
    /// No channel.
    pub const EMPTY: Self = Self([0; W]);

    /// The first `W` words of a wider set (channels beyond are dropped).
    #[must_use]
    pub fn narrow<const V: usize>(wide: Chans<V>) -> Self {
        Self(std::array::from_fn(|i| wide.0.get(i).copied().unwrap_or(0)))
    }

    /// Adds channel `ch` (`< 64·W`).
    pub fn insert(&mut self, ch: usize) {
        self.0[ch >> 6] |= 1 << (ch & 63);
    }

    /// The lowest channel of the set.
    #[must_use]
    pub fn first(&self) -> Option<usize> {
        self.0
            .iter()
            .position(|&w| w != 0)
            .map(|i| i * 64 + self.0[i].trailing_zeros() as usize)
    }

    /// The highest channel of the set.
    #[must_use]
    pub fn last(&self) -> Option<usize> {
        self.0
            .iter()
            .rposition(|&w| w != 0)
            .map(|i| i * 64 + 63 - self.0[i].leading_zeros() as usize)
    }

    /// Whether channel `ch` (`< 64·W`) is in the set.
    #[must_use]
    pub fn contains(&self, ch: usize) -> bool {
        self.0[ch >> 6] >> (ch & 63) & 1 == 1
    }

    /// Whether the set is empty.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.0.iter().all(|&w| w == 0)
    }

    /// Number of channels in the set.
    #[must_use]
    pub fn len(&self) -> u64 {
        self.0.iter().map(|w| u64::from(w.count_ones())).sum()
    }

    /// The channels in ascending order.
    #[must_use]
    pub fn iter(self) -> Iter<W> {
        Iter {
            words: self.0,
            word: 0,
        }
    }

    /// The channels of the set for which `keep` holds (asked in ascending
    /// order).
    #[must_use]
    pub fn filter(self, mut keep: impl FnMut(usize) -> bool) -> Self {
        let mut out = [0u64; W];
        for (i, (&word, o)) in self.0.iter().zip(&mut out).enumerate() {
            let mut w = word;
            while w != 0 {
                let b = w.trailing_zeros();
                w &= w - 1;
                *o |= u64::from(keep(i * 64 + b as usize)) << b;
            }
        }
        Self(out)
    }
}

/// The channels of a [`Chans`] in ascending order.
#[derive(Debug, Clone)]
pub struct Iter<const W: usize> {
    words: [u64; W],
    word: usize,
}

impl<const W: usize> Iterator for Iter<W> {
    type Item = usize;

    #[inline]
    fn next(&mut self) -> Option<usize> {
        while let Some(w) = self.words.get_mut(self.word) {
            if *w != 0 {
                let b = w.trailing_zeros() as usize;
                *w &= *w - 1;
                return Some(self.word * 64 + b);
            }
            self.word += 1;
        }
        None
    }
}

impl<const W: usize> BitAnd for Chans<W> {
    type Output = Self;
    fn bitand(self, o: Self) -> Self {
        Self(std::array::from_fn(|i| self.0[i] & o.0[i]))
    }
}

impl<const W: usize> BitOr for Chans<W> {
    type Output = Self;
    fn bitor(self, o: Self) -> Self {
        Self(std::array::from_fn(|i| self.0[i] | o.0[i]))
    }
}

impl<const W: usize> BitOrAssign for Chans<W> {
    fn bitor_assign(&mut self, o: Self) {
        *self = *self | o;
    }
}

impl<const W: usize> Not for Chans<W> {
    type Output = Self;
    fn not(self) -> Self {
        Self(self.0.map(|w| !w))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn set_operations_and_ascending_iteration() {
        let mut a = Chans::<4>::EMPTY;
        for ch in [0, 5, 63, 64, 130, 255] {
            a.insert(ch);
        }
        assert_eq!(a.iter().collect::<Vec<_>>(), [0, 5, 63, 64, 130, 255]);
        assert_eq!(a.len(), 6);
        assert_eq!((a.first(), a.last()), (Some(0), Some(255)));
        let mut c = Chans::<4>::EMPTY;
        assert!(c.is_empty() && c.first().is_none() && c.last().is_none());
        c.insert(70);
        c.insert(65);
        assert_eq!((c.first(), c.last()), (Some(65), Some(70)));
        assert!(a.contains(130) && !a.contains(131));
        let below = |n: usize| {
            let mut s = Chans::<4>::EMPTY;
            (0..n).for_each(|ch| s.insert(ch));
            s
        };
        let b = below(64);
        assert_eq!((a & b).iter().collect::<Vec<_>>(), [0, 5, 63]);
        assert_eq!((a & !b).iter().collect::<Vec<_>>(), [64, 130, 255]);
        assert_eq!((a | b).len(), 67);
        assert_eq!(below(256).len(), 256);
        assert!(Chans::<4>::EMPTY.is_empty() && Chans::<4>::EMPTY.iter().next().is_none());
        let mut asked = Vec::new();
        let odd = a.filter(|ch| {
            asked.push(ch);
            ch % 2 == 1
        });
        assert_eq!(asked, [0, 5, 63, 64, 130, 255]);
        assert_eq!(odd.iter().collect::<Vec<_>>(), [5, 63, 255]);
        // One word: the same set below 64.
        let one = Chans::<1>::narrow(a);
        assert_eq!(one.iter().collect::<Vec<_>>(), [0, 5, 63]);
        assert_eq!((one.first(), one.last(), one.len()), (Some(0), Some(63), 3));
    }
}
