//! Give way when robots of both directions knot in a two-lane corridor (see the parent
//! module's docs).

use super::{Constraint, PolicyEvent, PolicyRobot, TrafficPolicy};
use crate::traffic::TrafficMonitor;
use agent::math::{Real, Vec2};

/// A two-way knot being untangled: one direction stops where it stands, the other passes.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub(super) struct Knot {
    /// The way along x that passes (+1, −1).
    pass_dir: Real,
    /// The members of the knot travelling that way.
    passers: Vec<usize>,
    /// The members giving way, each with where it stopped.
    yielders: Vec<(usize, Vec2)>,
    /// Given up at this time, passed or not (s).
    until: Real,
}

impl TrafficPolicy {
    /// Finds lasting wait-for cycles whose members all travel along one two-lane hallway,
    /// both ways, and untangles them: the direction with fewer members (ties: toward −x)
    /// stops where it stands until every member of the other direction is past it (at most
    /// [`PolicyParams::give_way_s`]), so that the other direction moves round robots that
    /// stand still instead of robots that dodge it. A knot given up unpassed is left to the
    /// retreat rule for as long again.
    ///
    /// [`PolicyParams::give_way_s`]: super::PolicyParams::give_way_s
    pub(super) fn give_way(
        &mut self,
        now: Real,
        robots: &[PolicyRobot<'_>],
        monitor: &TrafficMonitor,
        events: &mut Vec<PolicyEvent>,
    ) {
        let beside = 2.0 * self.robot_radius;
        // Those giving way drive on once every passer is past them (or has no task left).
        for knot in &mut self.knots {
            let passers: Vec<Real> = knot
                .passers
                .iter()
                .filter(|&&j| !robots[j].route.is_empty())
                .map(|&j| robots[j].position.x)
                .collect();
            let dir = knot.pass_dir;
            knot.yielders.retain(|&(i, _)| {
                let x = robots[i].position.x;
                passers.iter().any(|&p| (x - p) * dir > -beside)
            });
        }
        // Given up unpassed: its robots are left to the retreat rule for as long again.
        for knot in self.knots.iter().filter(|k| now >= k.until) {
            let members = knot
                .passers
                .iter()
                .chain(knot.yielders.iter().map(|y| &y.0));
            for &i in members {
                self.knot_given_up[i] = now + self.params.give_way_s;
            }
        }
        self.knots
            .retain(|k| now < k.until && !k.yielders.is_empty());
        for cycle in monitor.cycles() {
            let taken = |i: usize| {
                self.giving_way(i) || self.retreat_until[i] > now || self.knot_given_up[i] > now
            };
            if !self.lasting(now, cycle, monitor) || cycle.iter().any(|&i| taken(i)) {
                continue;
            }
            if let Some(knot) = self.knot_of(cycle, robots, now) {
                for &(i, _) in &knot.yielders {
                    events.push(PolicyEvent::GiveWay { robot: i });
                }
                self.totals.give_ways += 1;
                self.knots.push(knot);
            }
        }
        for knot in &self.knots {
            for &(i, at) in &knot.yielders {
                self.constraints[i] = Constraint::GiveWay(at);
            }
        }
    }

    /// Whether robot `i` is a member of a knot being untangled.
    pub(super) fn giving_way(&self, i: usize) -> bool {
        self.knots
            .iter()
            .any(|k| k.passers.contains(&i) || k.yielders.iter().any(|y| y.0 == i))
    }

    /// Whether two members of `cycle` have been in cycles for
    /// [`PolicyParams::retreat_after_s`](super::PolicyParams::retreat_after_s).
    pub(super) fn lasting(&self, now: Real, cycle: &[usize], monitor: &TrafficMonitor) -> bool {
        cycle
            .iter()
            .filter(|&&i| {
                monitor
                    .in_cycle_since(i)
                    .is_some_and(|s| now - s >= self.params.retreat_after_s - 1e-9)
            })
            .count()
            >= 2
    }

    /// The knot `cycle` makes, if its members all travel along one two-lane hallway (a
    /// corridor no cross-aisle crosses), both ways. Not in a warehouse's corridors, where
    /// cross-aisles open every few metres and robots stopped in a knot stand in the
    /// crossings: with the rule there, 40 robots in `warehouse-narrow` had a deadlock in 12
    /// runs of seeds 1–73 against 3 without it, and in 7 of seeds 1–58 against 3 with the
    /// rule kept to knots whose members all travel along the corridor.
    fn knot_of(&self, cycle: &[usize], robots: &[PolicyRobot<'_>], now: Real) -> Option<Knot> {
        if self.lanes.site.cross_aisle_count() > 0 {
            return None;
        }
        // Each member on a corridor leg: its corridor's centre line and its way along x.
        let ways: Vec<(usize, Real, Real)> = cycle
            .iter()
            .filter_map(|&i| {
                let r = &robots[i];
                let leg = *r.route.first()? - r.position;
                if leg.x.abs() < leg.y.abs() {
                    return None;
                }
                let (centre, half) = self.lanes.site.lane_axis(r.position, true)?;
                (2.0 * half >= self.lanes.min_width).then_some((i, centre, leg.x.signum()))
            })
            .collect();
        // All on one corridor, both ways.
        let &(_, centre, way) = ways.first()?;
        if ways.len() < cycle.len()
            || ways.iter().any(|w| w.1 != centre)
            || ways.iter().all(|w| w.2 == way)
        {
            return None;
        }
        let going = |d: Real| -> Vec<usize> {
            ways.iter()
                .filter(|w| w.1 == centre && w.2 == d)
                .map(|w| w.0)
                .collect()
        };
        let (east, west) = (going(1.0), going(-1.0));
        let (pass_dir, passers, yielding) = if west.len() <= east.len() {
            (1.0, east, west)
        } else {
            (-1.0, west, east)
        };
        Some(Knot {
            pass_dir,
            passers,
            yielders: yielding
                .into_iter()
                .map(|i| (i, robots[i].position))
                .collect(),
            until: now + self.params.give_way_s,
        })
    }
}
