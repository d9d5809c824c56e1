//! The walls' index: for each 1 m cell, the blocks of wall points that can act on a body
//! there, so that a body visits only those instead of every point of the map (with the full
//! scan's bits: the other points add exact zeros to the same partial sums).

use agent::fastmath::LANES;
use agent::math::{Real, Vec2, bounds, vec2};

/// The runs of blocks of points that can act within `reach` of `pos`: those of its cell when
/// `index` covers `reach`, else every block (`all`).
#[inline(always)]
pub(super) fn runs_near<'a>(
    index: Option<&'a WallIndex>,
    pos: Vec2,
    reach: Real,
    all: &'a [(u32, u32); 1],
) -> &'a [(u32, u32)] {
    match index {
        Some(index) if reach <= index.reach => index.runs_at(pos),
        _ => all,
    }
}

/// For each cell of a square grid, the blocks of `LANES` points that hold every point within
/// `reach` of the cell, as ascending, disjoint runs of block numbers.
#[derive(Debug, Clone)]
pub(super) struct WallIndex {
    pub(super) reach: Real,
    cell: Real,
    min: Vec2,
    cols: usize,
    rows: usize,
    /// `starts[c]..starts[c + 1]` indexes `runs` for cell c.
    starts: Vec<u32>,
    runs: Vec<(u32, u32)>,
}

impl WallIndex {
    /// Cell side (m): smaller cells visit fewer points that do not act but take more memory.
    const CELL: Real = 1.0;

    pub(super) fn build(points: &[Vec2], reach: Real) -> Self {
        // A little slack so that rounding in a body's distance test cannot drop a point.
        let slack = 1e-9 * (1.0 + reach);
        let cell = Self::CELL;
        let (mut min, mut max) = bounds(points);
        let margin = vec2(reach + cell, reach + cell);
        min -= margin;
        max += margin;
        let cols = ((max.x - min.x) / cell) as usize + 1;
        let rows = ((max.y - min.y) / cell) as usize + 1;
        // Per cell, the blocks (ascending, since points are visited in order).
        let mut blocks: Vec<Vec<u32>> = vec![Vec::new(); cols * rows];
        for (i, p) in points.iter().enumerate() {
            let block = (i / LANES) as u32;
            let lo = ((p - min).add_scalar(-reach - slack) / cell).map(|v| v.floor().max(0.0));
            let hi = ((p - min).add_scalar(reach + slack) / cell).map(|v| v.floor());
            for cy in lo.y as usize..=(hi.y as usize).min(rows - 1) {
                for cx in lo.x as usize..=(hi.x as usize).min(cols - 1) {
                    // Distance from p to the cell's square.
                    let corner = min + vec2(cx as Real, cy as Real) * cell;
                    let dx = (corner.x - p.x).max(p.x - (corner.x + cell)).max(0.0);
                    let dy = (corner.y - p.y).max(p.y - (corner.y + cell)).max(0.0);
                    let list = &mut blocks[cy * cols + cx];
                    if dx * dx + dy * dy <= (reach + slack) * (reach + slack)
                        && list.last() != Some(&block)
                    {
                        list.push(block);
                    }
                }
            }
        }
        let mut starts = Vec::with_capacity(blocks.len() + 1);
        let mut runs: Vec<(u32, u32)> = Vec::new();
        for list in &blocks {
            starts.push(runs.len() as u32);
            let first_run = runs.len();
            for &b in list {
                match runs[first_run..].last_mut() {
                    Some(run) if run.1 == b => run.1 = b + 1,
                    _ => runs.push((b, b + 1)),
                }
            }
        }
        starts.push(runs.len() as u32);
        Self {
            reach,
            cell,
            min,
            cols,
            rows,
            starts,
            runs,
        }
    }

    /// The runs of blocks for a body at `pos`; empty when no point is within `reach`.
    #[inline(always)]
    pub(super) fn runs_at(&self, pos: Vec2) -> &[(u32, u32)] {
        let fx = ((pos.x - self.min.x) / self.cell).floor();
        let fy = ((pos.y - self.min.y) / self.cell).floor();
        // Outside the grid (which extends `reach` beyond every point) nothing acts; NaN too.
        if !(fx >= 0.0 && fy >= 0.0 && fx < self.cols as Real && fy < self.rows as Real) {
            return &[];
        }
        let c = fy as usize * self.cols + fx as usize;
        &self.runs[self.starts[c] as usize..self.starts[c + 1] as usize]
    }
}
