//! Retreat when a wait-for cycle lasts (see the parent module's docs).

use super::{Constraint, PolicyEvent, PolicyRobot, TrafficPolicy};
use crate::traffic::TrafficMonitor;
use agent::math::{Real, Vec2, vec2};

impl TrafficPolicy {
    pub(super) fn retreat(
        &mut self,
        now: Real,
        robots: &[PolicyRobot<'_>],
        monitor: &TrafficMonitor,
        events: &mut Vec<PolicyEvent>,
    ) {
        // The monitor has just seen this step's wait-for graph and its cycles.
        for cycle in monitor.cycles() {
            let old = self.lasting(now, cycle, monitor);
            let retreating = cycle.iter().any(|&i| self.retreat_until[i] > now);
            if !old || retreating || cycle.iter().any(|&i| self.giving_way(i)) {
                continue;
            }
            let holds = |i: usize| self.reservations.iter().any(|r| r.holders.contains(&i));
            let retreat_m = self.params.retreat_m;
            // Where robot i would back off to, straight back, if nobody stands there.
            let back_to = |i: usize| -> Option<Vec2> {
                let r = &robots[i];
                let ahead = *r.route.first()? - r.position;
                let norm = ahead.norm();
                if norm == 0.0 {
                    return None;
                }
                let to = r.position - ahead * (retreat_m / norm);
                let clear = robots.iter().enumerate().all(|(j, o)| {
                    j == i || {
                        let d = o.position - r.position;
                        d.dot(&ahead) >= 0.0 || (o.position - to).norm() > retreat_m
                    }
                });
                clear.then_some(to)
            };
            // A held robot cannot move: it is never the one sent back.
            let mut order: Vec<usize> =
                cycle.iter().copied().filter(|&i| !robots[i].held).collect();
            // Lowest priority first: not holding a segment, then the highest index.
            order.sort_by_key(|&i| (holds(i), std::cmp::Reverse(i)));
            let Some((loser, to)) =
                order
                    .iter()
                    .find_map(|&i| Some((i, back_to(i)?)))
                    .or_else(|| {
                        order
                            .iter()
                            .find_map(|&i| Some((i, self.room_for(i, robots)?)))
                    })
            else {
                continue;
            };
            self.retreat_until[loser] = now + self.params.retreat_s;
            self.totals.retreats += 1;
            events.push(PolicyEvent::Retreat { robot: loser });
            self.retreat_at[loser] = to;
        }
        // Retreats in progress keep their point.
        for (i, until) in self.retreat_until.iter().enumerate() {
            if *until > now && !self.giving_way(i) {
                self.constraints[i] = Constraint::Retreat(self.retreat_at[i]);
            }
        }
    }

    /// Where robot `i` could back off to when the way straight back is taken: back and to
    /// either side, or half as far, a point its body fits at (clear of shelves and of every
    /// other robot) and can drive to in a straight line. (Crowded crossings: every member of
    /// a cycle had a robot behind it, nobody retreated, and three robots stood 10 s in a
    /// cross-aisle of `warehouse-narrow`, seeds 71, 72 and 79 at 20 robots.)
    fn room_for(&self, i: usize, robots: &[PolicyRobot<'_>]) -> Option<Vec2> {
        let r = &robots[i];
        let ahead = *r.route.first()? - r.position;
        let norm = ahead.norm();
        if norm == 0.0 {
            return None;
        }
        let back = -ahead / norm;
        let side = vec2(-back.y, back.x);
        let body = self.robot_radius;
        let diagonal = std::f64::consts::FRAC_1_SQRT_2;
        let ways = [
            back,
            (back + side) * diagonal,
            (back - side) * diagonal,
            side,
            -side,
        ];
        [self.params.retreat_m, 0.5 * self.params.retreat_m]
            .into_iter()
            .flat_map(|d| ways.iter().map(move |&w| r.position + w * d))
            .find(|&to| {
                let mid = (r.position + to) * 0.5;
                self.map.distance(&to) > body + ROOM_GAP_M
                    && self.map.line_of_sight(r.position, to)
                    && robots.iter().enumerate().all(|(j, o)| {
                        j == i
                            || ((o.position - to).norm() > 2.0 * body + ROOM_GAP_M
                                && (o.position - mid).norm() > 2.0 * body)
                    })
            })
    }
}

/// Room kept between a robot backing off and shelves or other robots at the point it backs
/// off to (m).
const ROOM_GAP_M: Real = 0.2;
