//! Keep right: lanes right of the centre line in corridors and cross-aisles wide enough for
//! two robots (see the parent module's docs).

use super::{PolicyRobot, TrafficPolicy};
use agent::math::{Real, Vec2, vec2};

impl TrafficPolicy {
    /// `at` moved onto the right-hand lane for travel along `heading` (a unit vector, or zero),
    /// where the corridor or cross-aisle there is wide enough for two; else `at`.
    pub(super) fn right_of(&self, at: Vec2, heading: Vec2) -> Vec2 {
        let horizontal = heading.x.abs() >= heading.y.abs();
        let Some((centre, half)) = self.lanes.site.lane_axis(at, horizontal) else {
            return at;
        };
        if heading == vec2(0.0, 0.0) || 2.0 * half < self.lanes.min_width {
            return at;
        }
        let offset = self.lane_offset(horizontal, half);
        if horizontal {
            vec2(at.x, centre - heading.x.signum() * offset)
        } else {
            vec2(centre + heading.y.signum() * offset, at.y)
        }
    }

    /// How far right of the centre line the lane runs in a corridor (`horizontal`) or a
    /// cross-aisle of half width `half`.
    fn lane_offset(&self, horizontal: bool, half: Real) -> Real {
        let fraction = if horizontal {
            self.params.lane_offset_fraction
        } else {
            self.params.cross_aisle_lane_offset_fraction
        };
        fraction * 2.0 * half
    }

    /// Keep right: the point `lane_lookahead_m` ahead on the right lane of the corridor or
    /// cross-aisle the robot's current leg runs along, if wide enough and the leg long enough,
    /// and no held robot (at `held`) stands on the lane within `lane_lookahead_m` and a body
    /// length ahead. A lost robot stands on its lane until found; the robot behind it drives
    /// to its route's waypoint instead, and its planner takes it round.
    pub(super) fn lane(&self, r: &PolicyRobot<'_>, held: &[Vec2]) -> Option<Vec2> {
        let lanes = &self.lanes;
        let target = *r.route.first()?;
        let leg = target - r.position;
        let horizontal = leg.x.abs() >= leg.y.abs();
        let (run, sign) = if horizontal {
            (leg.x.abs(), leg.x.signum())
        } else {
            (leg.y.abs(), leg.y.signum())
        };
        let lead = self.params.lane_lookahead_m;
        if run <= lead + 1.0 {
            return None;
        }
        let (centre, half) = lanes.site.lane_axis(target, horizontal)?;
        if 2.0 * half < lanes.min_width {
            return None;
        }
        let offset = self.lane_offset(horizontal, half);
        // Right of travel along +x is −y; along +y, +x.
        let lane = if horizontal {
            centre - sign * offset
        } else {
            centre + sign * offset
        };
        // Across the centre line, in the oncoming lane: change lanes before driving on.
        let across = if horizontal {
            r.position.y
        } else {
            r.position.x
        };
        let ahead = self.params.lane_lookahead_m + 2.0 * self.robot_radius;
        let blocked = held.iter().any(|h| {
            let (along, off) = if horizontal {
                (sign * (h.x - r.position.x), h.y - lane)
            } else {
                (sign * (h.y - r.position.y), h.x - lane)
            };
            along > 0.0 && along <= ahead && off.abs() < 2.0 * self.robot_radius
        });
        if blocked {
            return None;
        }
        let lead = if (across - lane).abs() > offset {
            self.params.lane_change_lookahead_m
        } else {
            lead
        };
        Some(if horizontal {
            vec2(r.position.x + sign * lead, lane)
        } else {
            vec2(lane, r.position.y + sign * lead)
        })
    }
}
