//! A set of channel indices (CARLA allows up to 256 channels) as a bitmask:
//! the fast path of [`super::run_group`] handles a pulse's rays as sets.

use std::ops::{BitAnd, BitOr, BitOrAssign, Not};

/// Channels `0..256` as four 64-bit words.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Chans([u64; 4]);

impl Chans {
    /// No channel.
    pub const EMPTY: Self = Self([0; 4]);

    /// Adds channel `ch` (`< 256`).
    pub fn insert(&mut self, ch: usize) {
        self.0[ch >> 6] |= 1 << (ch & 63);
    }

    /// Adds channel `ch` (`< 256`) if `yes`, without a branch.
    pub fn put(&mut self, ch: usize, yes: bool) {
        self.0[ch >> 6] |= u64::from(yes) << (ch & 63);
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

    /// Removes channel `ch` (`< 256`).
    pub fn remove(&mut self, ch: usize) {
        self.0[ch >> 6] &= !(1 << (ch & 63));
    }

    /// Whether channel `ch` (`< 256`) is in the set.
    #[must_use]
    pub fn contains(&self, ch: usize) -> bool {
        self.0[ch >> 6] >> (ch & 63) & 1 == 1
    }

    /// Whether the set is empty.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.0 == [0; 4]
    }

    /// Number of channels in the set.
    #[must_use]
    pub fn len(&self) -> u64 {
        self.0.iter().map(|w| u64::from(w.count_ones())).sum()
    }

    /// The channels in ascending order.
    pub fn iter(self) -> impl Iterator<Item = usize> {
        self.0.into_iter().enumerate().flat_map(|(i, mut w)| {
            std::iter::from_fn(move || {
                (w != 0).then(|| {
                    let b = w.trailing_zeros() as usize;
                    w &= w - 1;
                    i * 64 + b
                })
            })
        })
    }
}

impl BitAnd for Chans {
    type Output = Self;
    fn bitand(self, o: Self) -> Self {
        Self(std::array::from_fn(|i| self.0[i] & o.0[i]))
    }
}

impl BitOr for Chans {
    type Output = Self;
    fn bitor(self, o: Self) -> Self {
        Self(std::array::from_fn(|i| self.0[i] | o.0[i]))
    }
}

impl BitOrAssign for Chans {
    fn bitor_assign(&mut self, o: Self) {
        *self = *self | o;
    }
}

impl Not for Chans {
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
        let mut a = Chans::EMPTY;
        for ch in [0, 5, 63, 64, 130, 255] {
            a.insert(ch);
        }
        assert_eq!(a.iter().collect::<Vec<_>>(), [0, 5, 63, 64, 130, 255]);
        assert_eq!(a.len(), 6);
        assert_eq!((a.first(), a.last()), (Some(0), Some(255)));
        let mut c = Chans::EMPTY;
        c.put(70, false);
        assert!(c.is_empty() && c.first().is_none() && c.last().is_none());
        c.put(70, true);
        c.put(65, true);
        assert_eq!((c.first(), c.last()), (Some(65), Some(70)));
        assert!(a.contains(130) && !a.contains(131));
        a.remove(64);
        assert!(!a.contains(64));
        let below = |n: usize| {
            let mut s = Chans::EMPTY;
            (0..n).for_each(|ch| s.insert(ch));
            s
        };
        let b = below(64);
        assert_eq!((a & b).iter().collect::<Vec<_>>(), [0, 5, 63]);
        assert_eq!((a & !b).iter().collect::<Vec<_>>(), [130, 255]);
        assert_eq!((a | b).len(), 66);
        assert_eq!(below(256).len(), 256);
        assert!(Chans::EMPTY.is_empty() && Chans::EMPTY.iter().next().is_none());
    }
}
