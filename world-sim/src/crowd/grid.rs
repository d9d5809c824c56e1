//! A uniform grid over points, for "who is near me" queries in O(1) per query. Items are
//! visited in a fixed order (cells row by row, ascending index within a cell), so results that
//! sum over neighbours are deterministic.

use agent::math::{Real, Vec2};

/// Points bucketed into square cells.
#[derive(Debug, Clone, Default)]
pub struct PointGrid {
    cell: Real,
    min: Vec2,
    cols: usize,
    rows: usize,
    /// `starts[c]..starts[c + 1]` indexes `items` for cell c.
    starts: Vec<u32>,
    items: Vec<u32>,
    /// Where the next item of each cell goes while building (kept to reuse its memory).
    fill: Vec<u32>,
}

/// A grid has at most about twice this many cells per item (and at least this floor): a
/// cell side far below the points' spread would otherwise ask for more memory than there is.
const CELLS_PER_ITEM: usize = 4;
const CELLS_FLOOR: usize = 4096;

impl PointGrid {
    /// Buckets `points` into square cells of side `cell` (> 0), or wider where `cell` is so
    /// small against the points' spread that the grid would have more than a few cells per
    /// point. Wider cells only add candidates: [`runs_near`](Self::runs_near) still holds
    /// every item within `cell`.
    pub fn build(&mut self, points: &[Vec2], cell: Real) {
        debug_assert!(cell > 0.0);
        let (min, max) = agent::math::bounds(points);
        let extent = max - min;
        let limit = (CELLS_PER_ITEM * points.len()).max(CELLS_FLOOR) as Real;
        // (w/c + 1)(h/c + 1) ≤ 2·limit + 1 for c ≥ √(w·h/limit) and c ≥ (w + h)/limit.
        let cell = cell
            .max((extent.x * extent.y / limit).sqrt())
            .max((extent.x + extent.y) / limit);
        self.cell = cell;
        self.min = min;
        self.cols = ((max.x - min.x) / cell) as usize + 1;
        self.rows = ((max.y - min.y) / cell) as usize + 1;
        let cells = self.cols * self.rows;
        self.starts.clear();
        self.starts.resize(cells + 1, 0);
        for p in points {
            let c = self.cell_of(p);
            self.starts[c + 1] += 1;
        }
        for c in 0..cells {
            self.starts[c + 1] += self.starts[c];
        }
        self.items.clear();
        self.items.resize(points.len(), 0);
        self.fill.clone_from(&self.starts);
        for (i, p) in points.iter().enumerate() {
            let c = self.cell_of(p);
            self.items[self.fill[c] as usize] = i as u32;
            self.fill[c] += 1;
        }
    }

    fn cell_of(&self, p: &Vec2) -> usize {
        let cx = (((p.x - self.min.x) / self.cell) as usize).min(self.cols - 1);
        let cy = (((p.y - self.min.y) / self.cell) as usize).min(self.rows - 1);
        cy * self.cols + cx
    }

    /// The items in cell order (row by row, ascending index within a cell): the order in
    /// which [`runs_near`](Self::runs_near) numbers them.
    pub fn items(&self) -> &[u32] {
        &self.items
    }

    /// Calls `f(lo, hi)` for each row of the 3 × 3 cells around `p`: positions `lo..hi` of
    /// [`items`](Self::items), which together hold every item within one cell side of `p`
    /// (at least the side given to [`build`](Self::build)).
    /// The runs come in ascending order and do not overlap. Inlined, so that the crowd's
    /// vectorised force pass compiles it (and its `floor`) for its own instruction set.
    #[inline(always)]
    pub fn runs_near(&self, p: Vec2, mut f: impl FnMut(usize, usize)) {
        if self.items.is_empty() {
            return;
        }
        let fx = ((p.x - self.min.x) / self.cell).floor();
        let fy = ((p.y - self.min.y) / self.cell).floor();
        let x0 = (fx - 1.0).max(0.0);
        let x1 = (fx + 1.0).min(self.cols as Real - 1.0);
        if x0 > x1 {
            return;
        }
        for dy in -1..=1 {
            let y = fy + dy as Real;
            if y < 0.0 || y >= self.rows as Real {
                continue;
            }
            let row = y as usize * self.cols;
            let lo = self.starts[row + x0 as usize] as usize;
            let hi = self.starts[row + x1 as usize + 1] as usize;
            if lo < hi {
                f(lo, hi);
            }
        }
    }

    /// Calls `f` with every item in the 3 × 3 cells around `p`: a superset of the items within
    /// one cell side of `p` (at least the side given to [`build`](Self::build)).
    pub fn for_each_near(&self, p: Vec2, mut f: impl FnMut(usize)) {
        if self.items.is_empty() {
            return;
        }
        let fx = ((p.x - self.min.x) / self.cell).floor();
        let fy = ((p.y - self.min.y) / self.cell).floor();
        for dy in -1..=1 {
            let y = fy + dy as Real;
            if y < 0.0 || y >= self.rows as Real {
                continue;
            }
            for dx in -1..=1 {
                let x = fx + dx as Real;
                if x < 0.0 || x >= self.cols as Real {
                    continue;
                }
                let c = y as usize * self.cols + x as usize;
                for &i in &self.items[self.starts[c] as usize..self.starts[c + 1] as usize] {
                    f(i as usize);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use agent::math::vec2;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn finds_every_point_within_one_cell(
            pts in proptest::collection::vec((-20.0..20.0f64, -20.0..20.0f64), 0..80),
            q in (-25.0..25.0f64, -25.0..25.0f64),
            cell in prop_oneof![0.5..6.0f64, 1e-6..0.5f64],
        ) {
            let points: Vec<Vec2> = pts.iter().map(|&(x, y)| vec2(x, y)).collect();
            let mut grid = PointGrid::default();
            grid.build(&points, cell);
            let q = vec2(q.0, q.1);
            let mut found = Vec::new();
            grid.for_each_near(q, |i| found.push(i));
            for (i, p) in points.iter().enumerate() {
                if (p - q).norm() < cell {
                    prop_assert!(found.contains(&i), "point {i} at distance {} missed", (p - q).norm());
                }
            }
            found.sort_unstable();
            found.dedup();
            prop_assert!(found.iter().all(|&i| i < points.len()));
            // The runs hold the same items, each once.
            let mut in_runs = Vec::new();
            let mut last_hi = 0;
            grid.runs_near(q, |lo, hi| {
                assert!(lo >= last_hi && lo < hi, "runs ascend without overlap");
                last_hi = hi;
                in_runs.extend(grid.items()[lo..hi].iter().map(|&i| i as usize));
            });
            in_runs.sort_unstable();
            prop_assert_eq!(in_runs, found);
        }
    }

    /// A cell far below the points' spread (a 1 mm interaction range in a 100 m warehouse
    /// asked for 28 GB) gives a grid of bounded size that still finds the neighbours.
    #[test]
    fn a_tiny_cell_over_a_wide_spread_stays_small() {
        let points: Vec<Vec2> = (0..1000)
            .map(|i| vec2((i % 40) as Real * 2.5, (i / 40) as Real * 4.0))
            .collect();
        let mut grid = PointGrid::default();
        grid.build(&points, 1e-3);
        assert!(
            grid.cols * grid.rows <= 2 * 4 * 1000 + 1,
            "{} cells",
            grid.cols * grid.rows
        );
        let mut found = Vec::new();
        grid.for_each_near(points[123], |i| found.push(i));
        assert!(found.contains(&123));
    }
}
