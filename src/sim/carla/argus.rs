//! ARGUS's detector and density count, as the paper's code does them
//! (fscari/ARGUS: `lidar2.py` `lidar_callback`, `preprocess_lidar.py`
//! `filter_road_points` / `create_grid` / `detect_vehicles_in_road_area`,
//! `grid.py` `GridCache`, `save_density.py`). Re-implemented from the
//! description, per sensor callback (one simulation tick):
//!
//! 1. keep the points of the half-plane chosen by the ego's world yaw ψ:
//!    `|wrap(θ − ψ − 90°)| ≤ 90°` (θ the point's azimuth);
//! 2. road points: `z < −2.8 m` (sensor frame); if this callback has any,
//!    the road mask (1 m cells, `floor(x)`, `floor(y)`) takes this
//!    callback's road cells when the cache is empty, on the second callback,
//!    or when the road's y-extent grows (new minimum, else new maximum);
//! 3. vehicle points: the other points at `z ≥ −2.6 m` whose cell is in the
//!    mask; the right car is detected when one of them lies at `y < −10 m`
//!    and `x > 8 m`.
//!
//! The density count (`save_density.py`): per trial, the points of step 1
//! (ground included) whose azimuth in `(−180°, 180°]` is below gaze − 30°.

use super::params::CarlaParams;

/// Azimuth in `(−180, 180]` from one in `[0, 360)`.
#[must_use]
pub fn signed_deg(az_deg: f64) -> f64 {
    if az_deg > 180.0 {
        az_deg - 360.0
    } else {
        az_deg
    }
}

/// Whether azimuth `az_deg` lies in the half-plane ARGUS keeps for an ego at
/// world yaw `ego_yaw_deg` (its `roi_mask`).
#[must_use]
pub fn in_half_plane(az_deg: f64, ego_yaw_deg: f64) -> bool {
    let rel = crate::model::angle::wrap_signed_deg(az_deg - ego_yaw_deg - 90.0);
    rel.abs() <= 90.0
}

/// Whether a point at azimuth `az_deg` counts in ARGUS's density: in the
/// half-plane and below gaze − 30° (no wrap, as the code compares degrees).
#[must_use]
pub fn in_density_region(az_deg: f64, gaze_deg: f64, ego_yaw_deg: f64) -> bool {
    in_half_plane(az_deg, ego_yaw_deg) && signed_deg(az_deg) < gaze_deg - 30.0
}

/// `⌊x⌋` as an integer (saturating far outside the grid; NaN → 0), without
/// a libm call: `x as i64` truncates toward zero, one less below zero.
fn floor_i64(x: f64) -> i64 {
    let t = x as i64;
    if (t as f64) > x {
        t - 1
    } else {
        t
    }
}

/// Largest grid stored densely (one byte per cell, 16 MiB): larger grids
/// (a fine `argus_cell_m` over a long `range_m`: 0.05 m cells over 1 km
/// are 1.6 × 10⁹ cells) store only the cells the road touches.
pub const DENSE_MASK_MAX_CELLS: u64 = 1 << 24;

/// The cells of a road mask: dense for a small grid, else only the marked
/// ones (a callback marks at most its road points, a few thousand).
#[derive(Debug, Clone)]
enum Cells {
    Dense(Vec<bool>),
    Sparse(std::collections::HashSet<usize>),
}

/// The road mask grid: cells of `cell_m` over `[-extent, extent)²`.
#[derive(Debug, Clone)]
pub struct RoadMask {
    cell_m: f64,
    /// Cells per side.
    side: i64,
    /// Index offset: cell `i` is stored at `i + offset`.
    offset: i64,
    cells: Cells,
}

impl RoadMask {
    /// An empty mask covering `|x|, |y| ≤ extent_m`: dense up to
    /// [`DENSE_MASK_MAX_CELLS`] cells, sparse beyond.
    #[must_use]
    pub fn new(cell_m: f64, extent_m: f64) -> Self {
        Self::with_dense_limit(cell_m, extent_m, DENSE_MASK_MAX_CELLS)
    }

    /// [`Self::new`] with the dense storage limited to `dense_max_cells`.
    #[must_use]
    pub fn with_dense_limit(cell_m: f64, extent_m: f64, dense_max_cells: u64) -> Self {
        let offset = (extent_m / cell_m).ceil() as i64 + 2;
        let side = 2 * offset;
        let n = (side as u64).saturating_mul(side as u64);
        let cells = if n <= dense_max_cells {
            Cells::Dense(vec![false; n as usize])
        } else {
            Cells::Sparse(std::collections::HashSet::new())
        };
        Self {
            cell_m,
            side,
            offset,
            cells,
        }
    }

    /// Whether the cells are stored sparsely.
    #[must_use]
    pub fn is_sparse(&self) -> bool {
        matches!(self.cells, Cells::Sparse(_))
    }

    /// The cell of `(x, y)` (Python's `int(x // cell)`), as a storage index,
    /// or `None` outside the grid.
    #[must_use]
    pub fn index(&self, x: f64, y: f64) -> Option<usize> {
        let i = floor_i64(x / self.cell_m).checked_add(self.offset)?;
        let j = floor_i64(y / self.cell_m).checked_add(self.offset)?;
        ((0..self.side).contains(&i) && (0..self.side).contains(&j))
            .then(|| (i * self.side + j) as usize)
    }

    /// Marks a cell.
    pub fn insert(&mut self, index: usize) {
        match &mut self.cells {
            Cells::Dense(v) => v[index] = true,
            Cells::Sparse(s) => {
                s.insert(index);
            }
        }
    }

    /// Whether a cell is marked.
    #[must_use]
    pub fn contains(&self, index: usize) -> bool {
        match &self.cells {
            Cells::Dense(v) => v[index],
            Cells::Sparse(s) => s.contains(&index),
        }
    }
}

/// ARGUS's detector state for one trial (one LiDAR, one car of interest).
#[derive(Debug, Clone)]
pub struct ArgusDetector {
    mask: RoadMask,
    road_z: f64,
    vehicle_z: f64,
    y_max: f64,
    x_min: f64,
    /// `GridCache.grid is None`.
    empty: bool,
    /// `GridCache.prev_y_min / prev_y_max`.
    prev: Option<(f64, f64)>,
    // This callback's road points and vehicle candidates.
    tick_road: Vec<usize>,
    tick_y: Option<(f64, f64)>,
    tick_candidates: Vec<usize>,
}

impl ArgusDetector {
    /// A fresh detector with the scenario's thresholds.
    #[must_use]
    pub fn new(p: &CarlaParams) -> Self {
        Self {
            mask: RoadMask::new(p.argus_cell_m, p.range_m + 1.0),
            road_z: p.argus_road_z_m,
            vehicle_z: p.argus_vehicle_z_m,
            y_max: p.argus_y_max_m,
            x_min: p.argus_x_min_m,
            empty: true,
            prev: None,
            tick_road: Vec::new(),
            tick_y: None,
            tick_candidates: Vec::new(),
        }
    }

    /// Takes one point of the kept half-plane (sensor frame).
    pub fn point(&mut self, x: f64, y: f64, z: f64) {
        let cell = self.mask.index(x, y);
        self.point_in_cell(x, y, z, cell);
    }

    /// [`Self::point`] with the point's cell already found ([`Self::cell_of`]).
    pub fn point_in_cell(&mut self, x: f64, y: f64, z: f64, cell: Option<usize>) {
        if z < self.road_z {
            self.tick_y = Some(match self.tick_y {
                None => (y, y),
                Some((lo, hi)) => (lo.min(y), hi.max(y)),
            });
            if let Some(i) = cell {
                self.tick_road.push(i);
            }
        } else if z >= self.vehicle_z && y < self.y_max && x > self.x_min {
            if let Some(i) = cell {
                self.tick_candidates.push(i);
            }
        }
    }

    /// The mask cell of `(x, y)` (the same for every detector of a scenario).
    #[must_use]
    pub fn cell_of(&self, x: f64, y: f64) -> Option<usize> {
        self.mask.index(x, y)
    }

    /// Takes the y of a road point (`z` below the road threshold) whose
    /// cell the caller keeps: it hands such cells to [`Self::end_tick_with`]
    /// only if the callback updates the mask (the extent decides that).
    pub fn road_y(&mut self, y: f64) {
        self.tick_y = Some(match self.tick_y {
            None => (y, y),
            Some((lo, hi)) => (lo.min(y), hi.max(y)),
        });
    }

    /// Ends a callback: updates the road mask as `GridCache` does and
    /// returns whether the right car was detected in it.
    pub fn end_tick(&mut self) -> bool {
        self.end_tick_with(|_| {})
    }

    /// [`Self::end_tick`] where `road_cells` yields (to the function it is
    /// given) the cells of this callback's road points taken by
    /// [`Self::road_y`]; it is called only if the mask takes them.
    pub fn end_tick_with(&mut self, road_cells: impl FnOnce(&mut dyn FnMut(usize))) -> bool {
        let Some((y_lo, y_hi)) = self.tick_y.take() else {
            self.tick_road.clear();
            self.tick_candidates.clear();
            return false;
        };
        let update = if self.empty {
            true
        } else {
            match &mut self.prev {
                None => {
                    self.prev = Some((y_lo, y_hi));
                    true
                }
                Some((lo, hi)) => {
                    if y_lo < *lo {
                        *lo = y_lo;
                        true
                    } else if y_hi > *hi {
                        *hi = y_hi;
                        true
                    } else {
                        false
                    }
                }
            }
        };
        if update {
            for &i in &self.tick_road {
                self.mask.insert(i);
            }
            let mask = &mut self.mask;
            road_cells(&mut |i| mask.insert(i));
            self.empty = false;
        }
        self.tick_road.clear();
        let found = self.tick_candidates.iter().any(|&i| self.mask.contains(i));
        self.tick_candidates.clear();
        found
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floor_matches_libm() {
        for x in [
            -2.5,
            -2.0,
            -1e-300,
            -0.0,
            0.0,
            0.3,
            1.0,
            7.999_999_999_999_999,
            1e15 + 0.5,
            -1e15 - 0.5,
        ] {
            assert_eq!(floor_i64(x), x.floor() as i64, "{x}");
        }
    }

    #[test]
    fn half_plane_and_region() {
        // Ego yaw −90°: the front half-plane x ≥ 0.
        assert!(in_half_plane(0.0, -90.0));
        assert!(in_half_plane(270.0, -90.0));
        assert!(in_half_plane(90.0, -90.0));
        assert!(!in_half_plane(180.0, -90.0));
        assert!(!in_half_plane(91.0, -90.0));
        // Yaw 0°: the left half-plane.
        assert!(in_half_plane(90.0, 0.0) && !in_half_plane(300.0, 0.0));
        // Density: gaze 90 → azimuths [−90°, 60°).
        assert!(in_density_region(300.0, 90.0, -90.0));
        assert!(in_density_region(59.9, 90.0, -90.0));
        assert!(!in_density_region(60.0, 90.0, -90.0));
        assert!(!in_density_region(200.0, 90.0, -90.0));
    }

    #[test]
    fn mask_grows_only_with_the_road_extent() {
        let p = CarlaParams::default();
        let mut d = ArgusDetector::new(&p);
        // Tick 1 and 2 always add.
        d.point(9.5, -50.5, -3.0);
        assert!(!d.end_tick());
        d.point(9.5, -60.5, -3.0);
        assert!(!d.end_tick());
        // Tick 3: extent unchanged (tick 2 set it to [−60.5, −60.5]): its
        // road cell (8, −61) is not added.
        d.point(8.5, -60.5, -3.0);
        d.point(8.5, -60.4, -2.0);
        assert!(!d.end_tick(), "cell (8, −61) was never added");
        // A vehicle point over a known cell (9, −51), right of −10, x > 8.
        d.point(9.5, -60.5, -3.0);
        d.point(9.7, -50.2, -2.0);
        assert!(d.end_tick());
        // No road points this tick: no check at all.
        d.point(9.7, -50.2, -2.0);
        assert!(!d.end_tick());
        // Too low for a vehicle (between the thresholds) or left of −10.
        d.point(9.5, -60.5, -3.0);
        d.point(9.7, -50.2, -2.7);
        d.point(9.7, -5.2, -2.0);
        assert!(!d.end_tick());
        // New minimum: the tick's cells are added.
        d.point(8.5, -61.5, -3.0);
        d.point(8.4, -61.6, -2.0);
        assert!(d.end_tick());
    }

    #[test]
    fn sparse_mask_equals_dense_mask() {
        // The same marks through both storages give the same answers.
        let (cell, extent) = (0.37, 60.0);
        let mut dense = RoadMask::with_dense_limit(cell, extent, u64::MAX);
        let mut sparse = RoadMask::with_dense_limit(cell, extent, 0);
        assert!(!dense.is_sparse() && sparse.is_sparse());
        let mut state = 0x9e37_79b9_u64;
        let mut next = || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..20_000 {
            let (x, y) = (130.0 * next() - 65.0, 130.0 * next() - 65.0);
            assert_eq!(dense.index(x, y), sparse.index(x, y));
            if let Some(i) = dense.index(x, y) {
                if next() < 0.3 {
                    dense.insert(i);
                    sparse.insert(i);
                }
                assert_eq!(dense.contains(i), sparse.contains(i));
            }
        }
        // Every cell of the grid agrees.
        let side = dense.side as usize;
        assert!((0..side * side).all(|i| dense.contains(i) == sparse.contains(i)));
    }

    #[test]
    fn fine_long_range_mask_is_sparse_and_small() {
        // 0.05 m cells over a 1 km trace must not make a dense 1.6 GB mask
        // per detector.
        let p = CarlaParams {
            argus_cell_m: 0.05,
            range_m: 1000.0,
            ..CarlaParams::default()
        };
        let d = ArgusDetector::new(&p);
        assert!(d.mask.is_sparse());
        assert!(d.mask.side * d.mask.side > 1_600_000_000);
        // The default scene stays dense.
        assert!(!ArgusDetector::new(&CarlaParams::default()).mask.is_sparse());
    }

    #[test]
    fn lazy_road_cells_equal_eager_ones() {
        // The same points, road cells either pushed with each point or taken
        // by extent first and handed over only when the mask takes them.
        let p = CarlaParams::default();
        let (mut eager, mut lazy) = (ArgusDetector::new(&p), ArgusDetector::new(&p));
        let mut state = 0x1234_5678_u64;
        let mut next = || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut found = 0;
        for tick in 0..400 {
            let mut road = Vec::new();
            for _ in 0..50 {
                let (x, y) = (30.0 * next(), -60.0 * next() - 0.5 * f64::from(tick % 7));
                let z = if next() < 0.7 { -3.0 } else { -2.0 };
                eager.point(x, y, z);
                if z < p.argus_road_z_m {
                    lazy.road_y(y);
                    road.push(lazy.cell_of(x, y));
                } else {
                    lazy.point(x, y, z);
                }
            }
            let a = eager.end_tick();
            let b = lazy.end_tick_with(|insert| road.iter().flatten().for_each(|&i| insert(i)));
            assert_eq!(a, b, "tick {tick}");
            found += usize::from(a);
        }
        assert!(found > 0);
    }
}
