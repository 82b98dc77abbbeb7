//! Cyclic index arithmetic over `n` bins, without overflow for any index
//! below `n` (Kani harnesses in [`super::angle`]'s verification module).
//! Integer only, so it builds without `std` for the firmware checker.

/// Index of the next bin in a cyclic array of `n` bins (`n > 0`).
///
/// Written without overflow for every `i < n` (checked by Kani harnesses).
#[must_use]
pub fn next_index(i: usize, n: usize) -> usize {
    debug_assert!(i < n);
    if i + 1 >= n {
        0
    } else {
        i + 1
    }
}

/// Index of the previous bin in a cyclic array of `n` bins (`n > 0`).
#[must_use]
pub fn prev_index(i: usize, n: usize) -> usize {
    debug_assert!(i < n);
    if i == 0 {
        n - 1
    } else {
        i - 1
    }
}

/// `(i + shift) mod n` for `i < n`, any `shift`, without overflow.
#[must_use]
pub fn rotate_index(i: usize, shift: usize, n: usize) -> usize {
    debug_assert!(i < n && n > 0);
    let s = shift % n;
    // i < n and s < n, so i + s < 2n; subtracting avoids overflow at usize::MAX.
    if i >= n - s {
        i - (n - s)
    } else {
        i + s
    }
}
