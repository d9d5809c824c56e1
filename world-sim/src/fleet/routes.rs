//! Routes: the legs a robot is given and given again, through the cross-aisles the traffic
//! policy names or round the people in the way ([`Fleet::reroute`]).

use super::{Fleet, Stage};
use crate::traffic_policy::{PEOPLE_ROUTE_REACH_M, route_length};
use agent::math::{Real, Vec2, dist_sq_point_segment};

/// How [`Fleet::reroute`] leads a robot's new route.
#[derive(Debug, Clone, Copy)]
pub(super) enum Through {
    /// The site's shortest route (weighed by people when the policy asks).
    Shortest,
    /// Into the station's one-way segment through this cross-aisle
    /// ([`Site::route_via`](crate::warehouse::Site::route_via)).
    Entry(usize),
    /// Out of the robot's one-way segment through this cross-aisle, round through another
    /// corridor when the station lies behind it in the same row
    /// ([`Site::route_out`](crate::warehouse::Site::route_out)).
    Exit(usize),
}

impl Fleet {
    /// With the policy on, the cross-aisle through which to enter the one-way segment a
    /// station `to` lies in: of the two at its ends, the one nearer the way from `from`.
    pub(super) fn pick_entry(&self, from: Vec2, to: Vec2) -> Option<usize> {
        let policy = self.policy.as_ref()?;
        let segment = policy.segments().iter().find(|s| s.contains(to))?;
        let (a, b) = segment.ends;
        let cost = |x: Real| (from.x - x).abs() + (x - to.x).abs();
        Some(if cost(segment.x0) <= cost(segment.x1) {
            a
        } else {
            b
        })
    }

    /// Gives a robot pushed off its route (round a shelf's end into the next aisle, say) a new
    /// route from where it is to its station. A route's legs are straight lines inside one
    /// corridor or cross-aisle; a robot is off its route when it is in a corridor or aisle
    /// other than its waypoint's and not in a cross-aisle (its local planner would press it against the shelf between, as close to the waypoint
    /// as it can get, for good: seen in `warehouse-narrow`, seed 1, 20 robots, where such a
    /// robot also held its aisle's reservation for 200 s).
    pub(super) fn keep_on_route(&mut self) {
        for i in 0..self.robots() {
            let here = self.world.robots[i].state.position;
            let Some(job) = &self.jobs[i] else {
                continue;
            };
            let Some(waypoint) = job.waypoint() else {
                continue;
            };
            // From a cross-aisle every corridor is a turn away: a robot there is on its way.
            if self.site.in_cross_aisle(here) || self.site.in_one_leg(here, waypoint) {
                continue;
            }
            let station = self.site.stations[job.station()].position;
            // Out of a one-way segment with its flow (it may have been pushed in against
            // it); into the station's segment by the nearer end, as at the leg's start.
            let exit = self.policy.as_ref().and_then(|p| p.flow_exit(here));
            let entry = match job.stage {
                Stage::ToPick => self.pick_entry(here, station),
                Stage::ToDrop => None,
            };
            let through = match (exit, entry) {
                (Some(j), _) => Through::Exit(j),
                (None, Some(j)) => Through::Entry(j),
                (None, None) => Through::Shortest,
            };
            self.reroute(i, through);
            self.reroutes += 1;
        }
    }

    /// Gives robot `i` a new route from where it is to its job's station.
    pub(super) fn reroute(&mut self, i: usize, through: Through) {
        let here = self.world.robots[i].state.position;
        let Some(job) = &self.jobs[i] else {
            return;
        };
        let station = self.site.stations[job.station()].position;
        let route = match (through, &self.policy) {
            (Through::Exit(j), Some(policy)) => {
                self.site
                    .route_out(here, station, j, policy.passing_width())
            }
            (Through::Exit(j) | Through::Entry(j), _) => self.site.route_via(here, station, j),
            (Through::Shortest, _) => self.route_among_people(here, station),
        };
        if let Some(job) = &mut self.jobs[i] {
            job.waypoints = route.into();
        }
    }

    /// The route from `from` to `to`: the site's shortest, or, with the traffic policy's
    /// [`PolicyParams::people_route_weight_m`], the one through the cross-aisle that is
    /// shortest once each person near its legs, standing or coming the other way (velocity
    /// against the leg), counts that much extra length. People are where they are now: a
    /// route is chosen when a leg starts, and again when the robot is pushed off it.
    pub(super) fn route_among_people(&self, from: Vec2, to: Vec2) -> Vec<Vec2> {
        let shortest = self.site.route(from, to);
        let weight = self
            .policy
            .as_ref()
            .map_or(0.0, |p| p.params.people_route_weight_m);
        if weight <= 0.0 || shortest.len() < 3 {
            return shortest;
        }
        let crowd = &self.world.humans.crowd;
        let reach_sq = PEOPLE_ROUTE_REACH_M * PEOPLE_ROUTE_REACH_M;
        let cost = |route: &[Vec2]| {
            let legs = std::iter::once(&from).chain(route).zip(route);
            let near: usize = legs
                .map(|(&at, &next)| {
                    crowd
                        .positions
                        .iter()
                        .zip(&crowd.velocities)
                        .filter(|(p, v)| {
                            dist_sq_point_segment(&at, &next, p) < reach_sq
                                && v.dot(&(next - at)) <= 0.0
                        })
                        .count()
                })
                .sum();
            route_length(from, route) + weight * near as Real
        };
        (0..self.site.cross_aisle_count())
            .map(|j| self.site.route_via(from, to, j))
            .chain(std::iter::once(shortest))
            .map(|route| (cost(&route), route))
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .map(|(_, route)| route)
            .unwrap_or_default()
    }

    /// Times a robot pushed off its route got a new one.
    pub fn reroutes(&self) -> u64 {
        self.reroutes
    }
}
