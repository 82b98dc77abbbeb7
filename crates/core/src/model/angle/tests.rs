use super::*;
use approx::assert_abs_diff_eq;
use proptest::prelude::*;

#[test]
fn wrapping() {
    assert_eq!(wrap_deg(-30.0), 330.0);
    assert_eq!(wrap_deg(720.0), 0.0);
    assert_eq!(wrap_deg(-1e-20), 0.0);
    assert_eq!(wrap_signed_deg(190.0), -170.0);
    assert_eq!(wrap_signed_deg(180.0), 180.0);
    assert_eq!(wrap_signed_deg(-180.0), 180.0);
    assert_eq!(diff_deg(10.0, 350.0), 20.0);
}

#[test]
fn arc_through_zero_is_exact() {
    let a = Arc::centered(0.0, 60.0).unwrap();
    assert_eq!(a.start_deg, 330.0);
    assert_eq!(a.end_deg(), 30.0);
    let s = CircularSet::from_arcs([a]);
    assert_eq!(s.measure_deg(), 60.0);
    assert!(s.contains(359.9) && s.contains(0.0) && s.contains(29.99));
    assert!(!s.contains(30.0) && !s.contains(329.9));
    assert_eq!(s.arcs(), vec![a]);
    assert_eq!(s.boundaries_deg(), vec![30.0, 330.0]);
    let c = s.complement();
    assert_eq!(c.measure_deg(), 300.0);
    assert_eq!(c.arcs(), vec![Arc::new(30.0, 300.0).unwrap()]);
}

#[test]
fn union_merges_overlaps() {
    let s = CircularSet::from_arcs([
        Arc::new(350.0, 20.0).unwrap(),
        Arc::new(5.0, 10.0).unwrap(),
        Arc::new(100.0, 10.0).unwrap(),
    ]);
    assert_eq!(s.measure_deg(), 35.0);
    assert_eq!(s.arcs().len(), 2);
    assert_eq!(s.union(&s.complement()), CircularSet::full());
}

#[test]
fn full_and_empty() {
    assert_eq!(CircularSet::full().complement(), CircularSet::empty());
    assert_eq!(CircularSet::empty().complement(), CircularSet::full());
    assert!(CircularSet::full().boundaries_deg().is_empty());
    let full = CircularSet::from_arcs([Arc::new(123.0, 360.0).unwrap()]);
    assert_eq!(full.measure_deg(), 360.0);
}

#[test]
fn binning_any_count() {
    for n in [4, 7, 360, 1000, 36_000] {
        let b = Binning::uniform(n).unwrap();
        let total: f64 = (0..n).map(|i| b.width_deg(i)).sum();
        assert_abs_diff_eq!(total, 360.0, epsilon = 1e-9);
        assert_eq!(b.bin_of(359.999_999), n - 1);
        assert_eq!(b.bin_of(0.0), 0);
    }
    assert!(Binning::uniform(3).is_err());
    assert!(Binning::uniform(36_001).is_err());
}

#[test]
fn breaks_become_edges() {
    let b = Binning::uniform_with_breaks(360, &[17.5, 77.5, 60.0]).unwrap();
    assert_eq!(b.len(), 362);
    assert!(b.starts_deg().contains(&17.5) && b.starts_deg().contains(&77.5));
    let b = Binning::uniform_with_breaks(7, &[0.0, 359.999_999_999_9]).unwrap();
    assert_eq!(b.len(), 7);
}

#[test]
fn index_arithmetic() {
    assert_eq!(next_index(4, 5), 0);
    assert_eq!(prev_index(0, 5), 4);
    assert_eq!(rotate_index(3, 4, 5), 2);
    assert_eq!(rotate_index(3, usize::MAX, 5), (3 + usize::MAX % 5) % 5);
}

/// `Arc::contains` is half-open and wraps (found by `cargo mutants`: the
/// core's tests used only `CircularSet::contains`).
#[test]
fn arc_contains_by_hand() {
    // [10°, 30°): offsets from the start are 0…20.
    let a = Arc::new(10.0, 20.0).unwrap();
    assert!(a.contains(10.0) && a.contains(20.0) && a.contains(29.99));
    assert!(!a.contains(30.0) && !a.contains(9.99) && !a.contains(100.0));
    // Any real: 370° is 10°, −340° is 20°, 390° is 30° (outside).
    assert!(a.contains(370.0) && a.contains(-340.0) && !a.contains(390.0));
    assert!(!a.contains(f64::NAN) && !a.contains(f64::INFINITY));
    // [350°, 10°) through 0°.
    let b = Arc::new(350.0, 20.0).unwrap();
    assert!(b.contains(350.0) && b.contains(359.0) && b.contains(0.0) && b.contains(9.99));
    assert!(!b.contains(10.0) && !b.contains(349.99) && !b.contains(180.0));
    // A full arc holds every finite azimuth (and only those); an empty one none.
    let full = Arc::new(123.0, 360.0).unwrap();
    assert!(full.contains(0.0) && full.contains(122.9) && full.contains(-1e9));
    assert!(!full.contains(f64::NAN) && !full.contains(f64::NEG_INFINITY));
    let none = Arc::new(10.0, 0.0).unwrap();
    assert!(!none.contains(10.0) && !none.contains(9.0) && !none.contains(11.0));
}

/// Constructors and `end_deg` by hand.
#[test]
fn arc_construction_by_hand() {
    assert_eq!(Arc::new(10.0, 20.0).unwrap().end_deg(), 30.0);
    assert_eq!(Arc::new(350.0, 20.0).unwrap().end_deg(), 10.0);
    assert_eq!(Arc::new(90.0, 360.0).unwrap().end_deg(), 90.0);
    let w = Arc::new(-30.0, 10.0).unwrap();
    assert_eq!((w.start_deg, w.width_deg), (330.0, 10.0));
    // Centred: start = centre − width/2.
    let c = Arc::centered(100.0, 30.0).unwrap();
    assert_eq!((c.start_deg, c.width_deg), (85.0, 30.0));
    let c = Arc::centered(5.0, 30.0).unwrap();
    assert_eq!((c.start_deg, c.width_deg), (350.0, 30.0));
    assert_eq!(Arc::new(0.0, 360.0).unwrap().width_deg, 360.0);
    assert_eq!(Arc::new(0.0, 0.0).unwrap().width_deg, 0.0);
    assert!(matches!(
        Arc::centered(f64::NAN, 10.0),
        Err(AngleError::NotFinite {
            what: "center_deg",
            ..
        })
    ));
    assert!(matches!(
        Arc::new(f64::INFINITY, 10.0),
        Err(AngleError::NotFinite {
            what: "start_deg",
            ..
        })
    ));
    for bad in [-1e-9, 360.000_001, f64::NAN] {
        assert!(
            matches!(Arc::new(0.0, bad), Err(AngleError::BadWidth(_))),
            "{bad}"
        );
    }
}

/// `overlap_deg`, `is_empty` and `contains` of a set by hand.
#[test]
fn set_overlap_and_membership_by_hand() {
    // [10, 30) ∪ [100, 130): 20° + 30°.
    let s = CircularSet::from_arcs([
        Arc::new(100.0, 30.0).unwrap(),
        Arc::new(10.0, 20.0).unwrap(),
    ]);
    assert_eq!(s.measure_deg(), 50.0);
    assert_eq!(s.overlap_deg(0.0, 360.0), 50.0);
    assert_eq!(s.overlap_deg(20.0, 110.0), 20.0); // [20,30) + [100,110)
    assert_eq!(s.overlap_deg(25.0, 26.0), 1.0);
    assert_eq!(s.overlap_deg(40.0, 90.0), 0.0);
    assert_eq!(s.overlap_deg(30.0, 100.0), 0.0); // touches both, meets neither
    assert_eq!(s.overlap_deg(120.0, 120.0), 0.0);
    assert_eq!(CircularSet::empty().overlap_deg(0.0, 360.0), 0.0);
    assert!(CircularSet::empty().is_empty());
    assert!(!s.is_empty() && !CircularSet::full().is_empty());
    assert!(s.contains(10.0) && s.contains(129.99) && s.contains(-250.0)); // 110°
    assert!(!s.contains(9.99) && !s.contains(30.0) && !s.contains(130.0) && !s.contains(0.0));
    assert!(
        !CircularSet::full().contains(f64::NAN) && !CircularSet::full().contains(f64::INFINITY)
    );
    assert!(CircularSet::full().contains(0.0) && CircularSet::full().contains(359.99));
    // Touching arcs merge into one; disjoint ones stay apart.
    let t = CircularSet::from_arcs([Arc::new(10.0, 20.0).unwrap(), Arc::new(30.0, 5.0).unwrap()]);
    assert_eq!(t.arcs(), vec![Arc::new(10.0, 25.0).unwrap()]);
    assert_eq!(t.boundaries_deg(), vec![10.0, 35.0]);
    assert_eq!(s.boundaries_deg(), vec![10.0, 30.0, 100.0, 130.0]);
    // Starting at 0° without reaching 360°: not joined with the last arc.
    let z = CircularSet::from_arcs([Arc::new(0.0, 10.0).unwrap(), Arc::new(200.0, 10.0).unwrap()]);
    assert_eq!(
        z.arcs(),
        vec![Arc::new(0.0, 10.0).unwrap(), Arc::new(200.0, 10.0).unwrap()]
    );
    let e = CircularSet::from_arcs([
        Arc::new(100.0, 10.0).unwrap(),
        Arc::new(350.0, 10.0).unwrap(),
    ]);
    assert_eq!(
        e.arcs(),
        vec![
            Arc::new(100.0, 10.0).unwrap(),
            Arc::new(350.0, 10.0).unwrap()
        ]
    );
    assert_eq!(e.complement().measure_deg(), 340.0);
}

/// A binning's accessors, by hand on 8 bins of 45°.
#[test]
fn binning_accessors_by_hand() {
    let b = Binning::uniform(8).unwrap();
    assert_eq!(b.len(), 8);
    assert!(!b.is_empty());
    assert_eq!(
        b.starts_deg(),
        &[0.0, 45.0, 90.0, 135.0, 180.0, 225.0, 270.0, 315.0]
    );
    assert_eq!(
        (b.start_deg(3), b.end_deg(3), b.width_deg(3)),
        (135.0, 180.0, 45.0)
    );
    assert_eq!(
        (b.start_deg(7), b.end_deg(7), b.width_deg(7)),
        (315.0, 360.0, 45.0)
    );
    assert_eq!(b.end_deg(0), 45.0);
    assert_eq!(
        (b.center_deg(0), b.center_deg(1), b.center_deg(7)),
        (22.5, 67.5, 337.5)
    );
    // An edge belongs to the bin it starts.
    assert_eq!(
        (
            b.bin_of(0.0),
            b.bin_of(44.999),
            b.bin_of(45.0),
            b.bin_of(90.0)
        ),
        (0, 0, 1, 2)
    );
    assert_eq!(
        (b.bin_of(359.999), b.bin_of(-10.0), b.bin_of(370.0)),
        (7, 7, 0)
    );
    // 7 bins: edges i·360/7 (not a divisor of 360).
    let s = Binning::uniform(7).unwrap();
    assert_eq!(s.start_deg(3), 3.0 * 360.0 / 7.0);
    assert_eq!(s.end_deg(6), 360.0);
    assert!(matches!(
        Binning::uniform(3),
        Err(AngleError::BadBinCount(3))
    ));
    assert!(Binning::uniform(4).is_ok() && Binning::uniform(36_000).is_ok());
    assert!(matches!(
        Binning::uniform(36_001),
        Err(AngleError::BadBinCount(36_001))
    ));
}

/// `from_starts`: must start at 0 and rise strictly below 360.
#[test]
fn binning_from_starts_by_hand() {
    let b = Binning::from_starts(vec![0.0, 10.0, 200.0]).unwrap();
    assert_eq!(b.len(), 3);
    assert_eq!(
        (b.width_deg(0), b.width_deg(1), b.width_deg(2)),
        (10.0, 190.0, 160.0)
    );
    assert_eq!((b.bin_of(5.0), b.bin_of(10.0), b.bin_of(359.0)), (0, 1, 2));
    assert!(Binning::from_starts(vec![0.0]).is_some());
    assert!(Binning::from_starts(vec![0.0, 359.9]).is_some());
    for bad in [
        vec![],
        vec![1.0, 90.0],
        vec![0.0, 90.0, 90.0],
        vec![0.0, 100.0, 90.0],
        vec![0.0, 360.0],
        vec![0.0, 90.0, f64::NAN],
    ] {
        assert!(Binning::from_starts(bad.clone()).is_none(), "{bad:?}");
    }
}

/// `uniform_with_breaks` on 8 bins of 45°: every branch of the snapping.
#[test]
fn breaks_snap_or_insert_by_hand() {
    let starts = |breaks: &[f64]| {
        Binning::uniform_with_breaks(8, breaks)
            .unwrap()
            .starts_deg()
            .to_vec()
    };
    let grid = [0.0, 45.0, 90.0, 135.0, 180.0, 225.0, 270.0, 315.0];
    let with = |i: usize, x: f64| {
        let mut g = grid.to_vec();
        g[i] = x;
        g
    };
    // Far from every edge: inserted (9 bins), in order; wrapped first.
    assert_eq!(
        starts(&[10.0]),
        [0.0, 10.0, 45.0, 90.0, 135.0, 180.0, 225.0, 270.0, 315.0]
    );
    assert_eq!(
        starts(&[400.0]),
        [0.0, 40.0, 45.0, 90.0, 135.0, 180.0, 225.0, 270.0, 315.0]
    );
    assert_eq!(
        starts(&[-10.0]),
        [0.0, 45.0, 90.0, 135.0, 180.0, 225.0, 270.0, 315.0, 350.0]
    );
    // Within 1e-9 below an edge: the edge moves onto the break.
    let x = 90.0 - 5e-10;
    assert_eq!(starts(&[x]), with(2, x));
    // Within 1e-9 above an edge: likewise.
    let x = 45.0 + 5e-10;
    assert_eq!(starts(&[x]), with(1, x));
    // Exactly on an edge: unchanged.
    assert_eq!(starts(&[45.0, 0.0]), grid);
    // Near 0° from above or below (360° ≡ 0°): 0° stays the first edge.
    assert_eq!(starts(&[5e-10]), grid);
    assert_eq!(starts(&[360.0 - 5e-10]), grid);
    assert_eq!(starts(&[-5e-10]), grid);
    // Just beyond the snap distance: inserted.
    assert_eq!(starts(&[90.0 - 2e-9]).len(), 9);
    assert_eq!(starts(&[360.0 - 2e-9]).len(), 9);
    assert!(matches!(
        Binning::uniform_with_breaks(8, &[10.0, f64::NAN]),
        Err(AngleError::NotFinite {
            what: "break_deg",
            ..
        })
    ));
    assert!(matches!(
        Binning::uniform_with_breaks(3, &[10.0]),
        Err(AngleError::BadBinCount(3))
    ));
}

proptest! {
    #[test]
    fn complement_partitions_circle(
        arcs in proptest::collection::vec((0.0f64..360.0, 0.0f64..360.0), 0..6),
        probe in 0.0f64..360.0,
    ) {
        let s = CircularSet::from_arcs(arcs.iter().map(|&(a, w)| Arc::new(a, w).unwrap()));
        let c = s.complement();
        prop_assert!((s.measure_deg() + c.measure_deg() - 360.0).abs() < 1e-9);
        prop_assert!(s.contains(probe) != c.contains(probe));
        // Re-building from arcs reproduces the set up to rounding of `start + width`.
        let again = CircularSet::from_arcs(s.arcs());
        prop_assert!((again.measure_deg() - s.measure_deg()).abs() < 1e-9);
        let (b0, b1) = (again.boundaries_deg(), s.boundaries_deg());
        prop_assert_eq!(b0.len(), b1.len());
        for (x, y) in b0.iter().zip(&b1) { prop_assert!((x - y).abs() < 1e-9); }
    }

    #[test]
    fn rotate_matches_modular(i in 0usize..1000, shift in any::<usize>(), n in 1usize..1000) {
        let i = i % n;
        prop_assert_eq!(rotate_index(i, shift, n), ((i as u128 + shift as u128) % n as u128) as usize);
    }

    #[test]
    fn wrap_fast_paths_match_rem_euclid(a in prop_oneof![
        -1000.0f64..1000.0, -1e4f64..1e4, -720.0f64..720.0, -1e-12f64..1e-12,
        Just(-0.0), Just(0.0), Just(360.0), Just(720.0), Just(-1e-300),
        Just(359.999_999_999_999_94), Just(719.999_999_999_999_9), Just(f64::NAN),
        Just(f64::INFINITY),
    ]) {
        let reference = {
            let w = a.rem_euclid(FULL_TURN_DEG);
            if w >= FULL_TURN_DEG { 0.0 } else { w }
        };
        if a == -FULL_TURN_DEG {
            // `rem_euclid` gives −0 there.
            prop_assert_eq!(wrap_deg(a).to_bits(), 0.0f64.to_bits());
        } else {
            prop_assert_eq!(wrap_deg(a).to_bits(), reference.to_bits());
        }
    }

    #[test]
    fn wrap_signed_in_range(a in -1e6f64..1e6) {
        let w = wrap_signed_deg(a);
        prop_assert!(w > -180.0 && w <= 180.0);
        prop_assert!((wrap_deg(w) - wrap_deg(a)).abs() < 1e-6 || (wrap_deg(w) - wrap_deg(a)).abs() > 360.0 - 1e-6);
    }
}
