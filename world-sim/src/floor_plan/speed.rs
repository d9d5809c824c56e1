//! Speed zones from a Nav2 speed filter mask: where a floor plan's robots may drive no faster
//! than a limit.
//!
//! Nav2's speed filter reads a mask (an occupancy grid) and a filter info with a type, a base
//! and a multiplier: a cell of value v > 0 limits the robot to base + multiplier·v (percent of
//! its top speed, or m/s); cells of value 0 or unknown set no limit. A trinary mask's occupied
//! cells have v = 100, so with the absolute type and multiplier 0 every occupied cell limits
//! the speed to the base: what `[floor_plan] speed_mask` describes
//! ([`SpeedMaskSpec`]). The limit is the base's: the fleet clamps each command by the limit
//! where the robot stands, as a controller obeys Nav2's published limit.

use super::nav2::{Cell, OccupancyGrid};
use agent::math::{Real, Vec2, clamp_norm};
use agent::model::Command;

/// Speed limits above this (m/s) are refused: faster than any robot here drives.
pub const MAX_LIMIT_M_S: Real = 10.0;

/// `[floor_plan] speed_mask`: a Nav2 speed filter mask and its limit.
#[derive(Debug, Clone, PartialEq, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpeedMaskSpec {
    /// The mask's map.yaml (trinary), relative to the scenario file's folder.
    pub mask: String,
    /// The speed limit on the mask's occupied cells (m/s): Nav2's absolute speed filter
    /// (type 2) with this base and multiplier 0. In (0, [`MAX_LIMIT_M_S`]].
    pub limit_m_s: Real,
}

/// Which map cells are speed-limited, and the limit.
#[derive(Debug, Clone, PartialEq)]
pub struct SpeedZones {
    /// The limit (m/s).
    pub limit_m_s: Real,
    /// The floor plan's grid geometry: cells along x and y, side (m), lower-left corner.
    width: usize,
    height: usize,
    resolution: Real,
    origin: Vec2,
    /// Per map cell, whether it is in a zone.
    cells: Vec<bool>,
}

impl SpeedZones {
    /// The zones `mask` marks on `grid`'s cells (a cell whose centre falls on an occupied
    /// mask cell); `None` when it marks none.
    pub fn new(grid: &OccupancyGrid, mask: &OccupancyGrid, limit_m_s: Real) -> Option<Self> {
        let cells: Vec<bool> = (0..grid.height)
            .flat_map(|y| (0..grid.width).map(move |x| (x, y)))
            .map(|(x, y)| {
                mask.cell_of(grid.centre(x, y))
                    .is_some_and(|(mx, my)| mask.at(mx, my) == Cell::Occupied)
            })
            .collect();
        let any = cells.iter().any(|&c| c);
        any.then_some(Self {
            limit_m_s,
            width: grid.width,
            height: grid.height,
            resolution: grid.resolution,
            origin: grid.origin,
            cells,
        })
    }

    /// The limit at `p`, if it is in a zone.
    pub fn limit_at(&self, p: Vec2) -> Option<Real> {
        let q = (p - self.origin) / self.resolution;
        if !(q.x >= 0.0 && q.y >= 0.0) {
            return None;
        }
        let (x, y) = (q.x as usize, q.y as usize);
        (x < self.width && y < self.height && self.cells[y * self.width + x])
            .then_some(self.limit_m_s)
    }

    /// Map cells in a zone.
    pub fn cells(&self) -> usize {
        self.cells.iter().filter(|&&c| c).count()
    }
}

/// `command` with its speed held to `limit` (m/s): a velocity's norm, a unicycle's forward
/// speed either way; the turn rate is kept.
pub fn limit_speed(command: Command, limit: Real) -> Command {
    match command {
        Command::Velocity(v) => Command::Velocity(clamp_norm(v, limit)),
        Command::Unicycle { speed, yaw_rate } => Command::Unicycle {
            speed: speed.clamp(-limit, limit),
            yaw_rate,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use agent::math::vec2;

    #[test]
    fn zones_follow_the_mask_and_limit_speed_only() {
        // A 2 × 1 m map at 0.1 m; a 0.5 m mask whose right cell is occupied.
        let grid = OccupancyGrid {
            width: 20,
            height: 10,
            resolution: 0.1,
            origin: vec2(0.0, 0.0),
            cells: vec![Cell::Free; 200],
        };
        let mask = OccupancyGrid {
            width: 4,
            height: 2,
            resolution: 0.5,
            origin: vec2(0.0, 0.0),
            cells: vec![
                Cell::Free,
                Cell::Free,
                Cell::Occupied,
                Cell::Unknown,
                Cell::Free,
                Cell::Free,
                Cell::Occupied,
                Cell::Free,
            ],
        };
        let zones = SpeedZones::new(&grid, &mask, 0.4).expect("one zone");
        assert_eq!(zones.cells(), 50, "x 1 to 1.5 m, the whole height");
        assert_eq!(zones.limit_at(vec2(1.2, 0.7)), Some(0.4));
        assert_eq!(zones.limit_at(vec2(0.9, 0.7)), None);
        assert_eq!(
            zones.limit_at(vec2(1.7, 0.2)),
            None,
            "unknown sets no limit"
        );
        assert_eq!(zones.limit_at(vec2(-0.1, 0.2)), None, "off the map");
        let free = OccupancyGrid {
            cells: vec![Cell::Free; 8],
            ..mask
        };
        assert!(SpeedZones::new(&grid, &free, 0.4).is_none());
        assert_eq!(
            limit_speed(Command::Velocity(vec2(0.6, 0.8)), 0.5),
            Command::Velocity(vec2(0.3, 0.4))
        );
        assert_eq!(
            limit_speed(
                Command::Unicycle {
                    speed: -0.9,
                    yaw_rate: 0.7
                },
                0.5
            ),
            Command::Unicycle {
                speed: -0.5,
                yaw_rate: 0.7
            }
        );
        assert_eq!(
            limit_speed(Command::Velocity(vec2(0.1, 0.0)), 0.5),
            Command::Velocity(vec2(0.1, 0.0))
        );
    }
}
