//! Where stuck robots stand, who stands next to them and what holds them: the fleet's stuck
//! robot-seconds (`crate::traffic`) split by place (aisle, cross-aisle, near a station,
//! corridor), by company (a person next to it, else another robot, else nobody) and by cause
//! ([`Hold`]: the traffic policy, a person in its way, a robot in its way, the safety layer,
//! or nothing visible). It answers where a fleet jams and why.

use crate::traffic::{TrafficParams, ahead_within};
use crate::warehouse::{Segment, Site};
use agent::map::StaticMap;
use agent::math::{Real, Vec2};
use serde::{Deserialize, Serialize};

/// "Next to": within this distance, centre to centre (m). 1.5 m: a robot and a person
/// (or two robots) with half a metre or less between them.
pub const NEXT_TO_M: Real = 1.5;

/// "Near a station": within this distance of one (m). 6 m: where robots start to queue for
/// one (`traffic_policy::PolicyParams::station_request_m`).
pub const NEAR_STATION_M: Real = 6.0;

/// Where a robot stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Place {
    /// In an aisle, between shelves.
    Aisle,
    /// In a cross-aisle.
    CrossAisle,
    /// Elsewhere, within [`NEAR_STATION_M`] of a station.
    Station,
    /// Elsewhere: the corridors (all of a hallway away from its ends).
    Corridor,
}

/// Who is next to it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Company {
    /// A person within [`NEXT_TO_M`].
    Person,
    /// No person, another robot within [`NEXT_TO_M`].
    Robot,
    /// Neither.
    Nobody,
}

/// Stuck robot-seconds by place and company.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct StuckBreakdown {
    /// In aisles.
    pub aisle_s: Real,
    /// In cross-aisles.
    pub cross_aisle_s: Real,
    /// Near stations.
    pub station_s: Real,
    /// In corridors.
    pub corridor_s: Real,
    /// With a person next to it.
    pub person_s: Real,
    /// With a robot next to it and no person.
    pub robot_s: Real,
    /// With nobody next to it.
    pub nobody_s: Real,
}

impl StuckBreakdown {
    /// Adds `dt` seconds of one stuck robot.
    pub fn add(&mut self, place: Place, company: Company, dt: Real) {
        *match place {
            Place::Aisle => &mut self.aisle_s,
            Place::CrossAisle => &mut self.cross_aisle_s,
            Place::Station => &mut self.station_s,
            Place::Corridor => &mut self.corridor_s,
        } += dt;
        *match company {
            Company::Person => &mut self.person_s,
            Company::Robot => &mut self.robot_s,
            Company::Nobody => &mut self.nobody_s,
        } += dt;
    }
}

/// Tells places apart on one site.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Places {
    aisles: Vec<Segment>,
    site: Site,
}

impl Places {
    /// The places of `site`.
    pub fn new(site: &Site) -> Self {
        Self {
            aisles: site.narrow_segments(Real::INFINITY),
            site: site.clone(),
        }
    }

    /// Where `p` is.
    pub fn of(&self, p: Vec2) -> Place {
        if self.aisles.iter().any(|s| s.contains(p)) {
            Place::Aisle
        } else if self.site.in_cross_aisle(p) {
            Place::CrossAisle
        } else if self
            .site
            .stations
            .iter()
            .any(|s| (s.position - p).norm() <= NEAR_STATION_M)
        {
            Place::Station
        } else {
            Place::Corridor
        }
    }
}

/// Who is next to robot `i` at `p`, among `people` and `robots` (robot `i` among them).
pub fn company(i: usize, p: Vec2, people: &[Vec2], robots: &[Vec2]) -> Company {
    let next_to = |q: &Vec2| (q - p).norm() <= NEXT_TO_M;
    if people.iter().any(next_to) {
        Company::Person
    } else if robots.iter().enumerate().any(|(j, q)| j != i && next_to(q)) {
        Company::Robot
    } else {
        Company::Nobody
    }
}

/// What holds a stuck robot: the first of these that applies, in this order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Hold {
    /// The traffic policy: it waits for a segment or a station, gives way or backs off.
    Policy,
    /// A person, or a group, in its way ([`in_the_way`]).
    Person,
    /// Another robot in its way: it waits on one (`TrafficMonitor::waits_on`).
    Robot,
    /// Its safety layer: the command it drove on was stopped, slowed in the protective field
    /// or replaced by a way out, with nobody in its way.
    Layer,
    /// Nothing visible: its way is clear, nobody holds it, and it still makes no progress (a
    /// planner failure).
    Planner,
}

/// Stuck robot-seconds by what held the robot.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct StuckCauses {
    /// Held by the traffic policy.
    pub policy_s: Real,
    /// A person or group in the way.
    pub person_s: Real,
    /// A robot in the way.
    pub robot_s: Real,
    /// Held by the safety layer, nobody in the way.
    pub layer_s: Real,
    /// Nothing visible.
    pub planner_s: Real,
}

impl StuckCauses {
    /// Adds `dt` seconds of one stuck robot held by `hold`.
    pub fn add(&mut self, hold: Hold, dt: Real) {
        *match hold {
            Hold::Policy => &mut self.policy_s,
            Hold::Person => &mut self.person_s,
            Hold::Robot => &mut self.robot_s,
            Hold::Layer => &mut self.layer_s,
            Hold::Planner => &mut self.planner_s,
        } += dt;
    }

    /// All of them.
    pub fn total(&self) -> Real {
        self.policy_s + self.person_s + self.robot_s + self.layer_s + self.planner_s
    }
}

/// Whether one of `people` (of radius `person_radius`) is in the way of a robot at `p` of
/// `radius` that drives toward `toward`, as the traffic monitor finds robots in each other's
/// way: in sight, within [`TrafficParams::blocking_gap_m`] surface to surface, and within
/// [`TrafficParams::blocking_cone_rad`] of the direction to `toward` (any direction when
/// `toward` is under the robot's body).
pub fn in_the_way(
    p: Vec2,
    radius: Real,
    toward: Vec2,
    people: &[Vec2],
    person_radius: Real,
    params: &TrafficParams,
    map: &StaticMap,
) -> bool {
    let reach = params.blocking_gap_m + radius + person_radius;
    let ahead = toward - p;
    let heading = (ahead.norm() > radius).then(|| ahead.normalize());
    let cos_cone = params.blocking_cone_rad.cos();
    people
        .iter()
        .any(|&q| ahead_within(p, heading, q, reach, cos_cone) && map.line_of_sight(p, q))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::Scenario;
    use agent::math::vec2;

    /// On the narrow warehouse: an aisle, a cross-aisle, the docks' corridor near and far
    /// from a dock; in the hallway, its ends and its middle.
    #[test]
    fn places_of_both_sites() {
        let s = Scenario::builtin("warehouse-narrow").expect("valid");
        let site = Site::generate(&s.warehouse.expect("layout"));
        let places = Places::new(&site);
        let aisle = site.narrow_segments(Real::INFINITY)[3];
        let (x, _) = site.cross_aisle(aisle.ends.1);
        assert_eq!(
            places.of(vec2(0.5 * (aisle.x0 + aisle.x1), aisle.y)),
            Place::Aisle
        );
        assert_eq!(places.of(vec2(x, aisle.y)), Place::CrossAisle);
        let dock = site
            .stations
            .iter()
            .map(|s| s.position)
            .find(|&p| !site.in_cross_aisle(p))
            .expect("a dock off the cross-aisles");
        assert_eq!(places.of(dock), Place::Station);
        let hallway = Site::hallway(40.0, 3.0, 3);
        let places = Places::new(&hallway);
        assert_eq!(places.of(vec2(3.0, 1.5)), Place::Station);
        assert_eq!(places.of(vec2(20.0, 1.5)), Place::Corridor);
    }

    /// A person ahead and close is in the way; one behind, one too far, one behind a shelf
    /// is not; with the goal under the robot, any close person is.
    #[test]
    fn people_in_the_way() {
        let params = TrafficParams::default();
        let open = StaticMap::empty();
        let (p, east) = (vec2(0.0, 0.0), vec2(10.0, 0.0));
        let way = |q: Vec2, map: &StaticMap, toward: Vec2| {
            in_the_way(p, 0.4, toward, &[q], 0.3, &params, map)
        };
        assert!(way(vec2(1.5, 0.3), &open, east));
        assert!(!way(vec2(-1.5, 0.0), &open, east));
        assert!(!way(vec2(1.8, 0.0), &open, east));
        let shelf = StaticMap::new(vec![agent::map::Obstacle::Wall(
            vec2(1.0, -2.0),
            vec2(1.0, 2.0),
        )])
        .expect("wall");
        assert!(!way(vec2(1.5, 0.0), &shelf, east));
        assert!(way(vec2(-1.5, 0.0), &open, vec2(0.1, 0.0)));
        let mut c = StuckCauses::default();
        c.add(Hold::Person, 0.1);
        c.add(Hold::Planner, 0.2);
        assert_eq!((c.person_s, c.planner_s, c.total()), (0.1, 0.2, 0.1 + 0.2));
    }

    /// A person next to a robot counts first, then a robot; the robot itself never does.
    #[test]
    fn company_prefers_people() {
        let robots = [vec2(0.0, 0.0), vec2(1.0, 0.0), vec2(5.0, 0.0)];
        assert_eq!(
            company(0, robots[0], &[vec2(0.0, 1.4)], &robots),
            Company::Person
        );
        assert_eq!(
            company(0, robots[0], &[vec2(0.0, 1.6)], &robots),
            Company::Robot
        );
        assert_eq!(company(2, robots[2], &[], &robots), Company::Nobody);
        let mut b = StuckBreakdown::default();
        b.add(Place::Aisle, Company::Robot, 0.1);
        b.add(Place::Corridor, Company::Person, 0.2);
        assert_eq!(
            (b.aisle_s, b.corridor_s, b.robot_s, b.person_s),
            (0.1, 0.2, 0.1, 0.2)
        );
    }
}
