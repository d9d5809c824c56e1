//! Heatmaps over the floor: where robots came within 1 m of people, where contacts happened,
//! where robots stood stuck, where people lost time to robots, over a sliding window and over
//! the whole run.
//!
//! Each frame brings a few [`HeatEvent`]s (a point and a weight); adding one, and taking it
//! out of the window when it gets old, costs O(1): the cost per tick is O(events), not
//! O(cells). The grids are drawn as images under the map once per simulated second.

use crate::{HeatEvent, HeatKind, MapFrame, P};
use std::collections::VecDeque;

/// Heatmap settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeatParams {
    /// Cell size (m). 0.5 m: about a person's width; a 63 × 21 m warehouse is 126 × 42 cells.
    pub cell_m: f32,
    /// The sliding window (s). 60 s.
    pub window_s: f64,
}

impl Default for HeatParams {
    fn default() -> Self {
        Self {
            cell_m: 0.5,
            window_s: 60.0,
        }
    }
}

/// The grid's placement: its lower-left corner and size in cells.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    /// Lower-left corner (m).
    pub origin: P,
    /// Columns (along x) and rows (along y).
    pub size: [u32; 2],
    /// Cell size (m).
    pub cell_m: f32,
}

impl Grid {
    /// A grid covering everything on `map` (shelves, walls, stations), at least one cell.
    pub fn covering(map: &MapFrame, cell_m: f32) -> Self {
        let points = map
            .shelves
            .iter()
            .flatten()
            .chain(map.walls.iter().flatten())
            .chain(map.stations.iter().map(|s| &s.0));
        let (mut lo, mut hi) = ([f32::INFINITY; 2], [f32::NEG_INFINITY; 2]);
        for p in points {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        if !lo[0].is_finite() {
            (lo, hi) = ([0.0; 2], [cell_m; 2]);
        }
        let cells = |k: usize| (((hi[k] - lo[k]) / cell_m).ceil() as u32).max(1);
        Self {
            origin: lo,
            size: [cells(0), cells(1)],
            cell_m,
        }
    }

    /// The cell holding `p`, if it is on the grid.
    pub fn cell(&self, p: P) -> Option<usize> {
        let col = ((p[0] - self.origin[0]) / self.cell_m).floor();
        let row = ((p[1] - self.origin[1]) / self.cell_m).floor();
        let inside =
            col >= 0.0 && row >= 0.0 && (col as u32) < self.size[0] && (row as u32) < self.size[1];
        inside.then(|| row as usize * self.size[0] as usize + col as usize)
    }

    fn cells(&self) -> usize {
        self.size[0] as usize * self.size[1] as usize
    }
}

/// One kind's grids.
#[derive(Debug, Clone)]
pub struct Layer {
    /// Summed weight per cell over the whole run.
    pub run: Vec<f32>,
    /// ... over the last [`HeatParams::window_s`].
    pub window: Vec<f32>,
    /// The window's events, oldest first: time, cell, weight.
    recent: VecDeque<(f64, usize, f32)>,
}

/// Every kind's grids.
#[derive(Debug, Clone)]
pub struct Heat {
    /// Settings.
    pub params: HeatParams,
    /// Placement.
    pub grid: Grid,
    /// Per kind, in [`HeatKind::ALL`] order.
    pub layers: Vec<Layer>,
}

impl Heat {
    /// Empty grids covering `map`.
    pub fn new(map: &MapFrame, params: HeatParams) -> Self {
        let grid = Grid::covering(map, params.cell_m);
        let layer = Layer {
            run: vec![0.0; grid.cells()],
            window: vec![0.0; grid.cells()],
            recent: VecDeque::new(),
        };
        Self {
            params,
            grid,
            layers: vec![layer; HeatKind::ALL.len()],
        }
    }

    /// Adds the events of the frame at `now` (s) and lets the window's old ones go.
    pub fn add(&mut self, now: f64, events: &[HeatEvent]) {
        for e in events {
            if !e.weight.is_finite() || e.weight <= 0.0 {
                continue;
            }
            let Some(cell) = self.grid.cell(e.at) else {
                continue;
            };
            let layer = &mut self.layers[e.kind as usize];
            layer.run[cell] += e.weight;
            layer.window[cell] += e.weight;
            layer.recent.push_back((now, cell, e.weight));
        }
        for layer in &mut self.layers {
            while let Some(&(t, cell, w)) = layer.recent.front() {
                if now - t < self.params.window_s {
                    break;
                }
                // Clamped: float sums need not come back to exactly 0.
                layer.window[cell] = (layer.window[cell] - w).max(0.0);
                layer.recent.pop_front();
            }
        }
    }

    /// `values` as an RGBA image, row 0 at the grid's lowest y: empty cells transparent,
    /// the rest in `colour`, more opaque the larger (square-root scale, so a few busy cells
    /// do not wash out the rest).
    pub fn image(&self, values: &[f32], colour: [u8; 3]) -> Vec<u8> {
        let max = values.iter().copied().fold(0.0_f32, f32::max);
        let mut rgba = Vec::with_capacity(values.len() * 4);
        for &v in values {
            let alpha = if v > 0.0 && max > 0.0 {
                (40.0 + 200.0 * (v / max).sqrt()) as u8
            } else {
                0
            };
            rgba.extend_from_slice(&[colour[0], colour[1], colour[2], alpha]);
        }
        rgba
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn map() -> MapFrame {
        MapFrame {
            walls: vec![[[0.0, 0.0], [10.0, 0.0]], [[10.0, 0.0], [10.0, 4.0]]],
            ..MapFrame::default()
        }
    }

    /// The grid covers the map; points map to the cell under them, row 0 at the bottom.
    #[test]
    fn cells_cover_the_map_bottom_row_first() {
        let grid = Grid::covering(&map(), 0.5);
        assert_eq!(grid.size, [20, 8]);
        assert_eq!(grid.cell([0.1, 0.1]), Some(0));
        assert_eq!(grid.cell([1.2, 0.6]), Some(20 + 2));
        assert_eq!(grid.cell([9.9, 3.9]), Some(7 * 20 + 19));
        assert_eq!(grid.cell([-0.1, 1.0]), None);
        assert_eq!(grid.cell([10.1, 1.0]), None);
        assert_eq!(grid.cell([f32::NAN, 1.0]), None);
    }

    /// An event counts in the run for good and in the window until it is `window_s` old;
    /// weights that are not finite and positive are ignored.
    #[test]
    fn the_window_forgets_what_the_run_keeps() {
        let params = HeatParams {
            cell_m: 1.0,
            window_s: 10.0,
        };
        let mut heat = Heat::new(&map(), params);
        let stuck = |at: P, weight: f32| HeatEvent {
            kind: HeatKind::Stuck,
            at,
            weight,
        };
        heat.add(0.0, &[stuck([2.5, 1.5], 0.1), stuck([2.5, 1.5], f32::NAN)]);
        heat.add(5.0, &[stuck([2.5, 1.5], 0.1), stuck([7.5, 0.5], -1.0)]);
        let layer = &heat.layers[HeatKind::Stuck as usize];
        let cell = heat.grid.cell([2.5, 1.5]).expect("on the grid");
        assert!((layer.window[cell] - 0.2).abs() < 1e-6);
        heat.add(10.0, &[]);
        let layer = &heat.layers[HeatKind::Stuck as usize];
        assert!((layer.window[cell] - 0.1).abs() < 1e-6);
        assert!((layer.run[cell] - 0.2).abs() < 1e-6);
        heat.add(15.0, &[]);
        let layer = &heat.layers[HeatKind::Stuck as usize];
        assert_eq!(layer.window[cell], 0.0);
        assert!(layer.recent.is_empty());
        assert_eq!(layer.run.iter().filter(|&&v| v > 0.0).count(), 1);
        let image = heat.image(&layer.run, [1, 2, 3]);
        assert_eq!(image.len(), 4 * 10 * 4);
        assert_eq!(&image[4 * cell..4 * cell + 4], &[1, 2, 3, 240]);
        assert_eq!(image[3], 0);
    }
}
