//! Where stuck robots stand and who stands next to them: the fleet's stuck robot-seconds
//! (`crate::traffic`) split by place (aisle, cross-aisle, near a station, corridor) and by
//! company (a person next to it, else another robot, else nobody). It answers where a fleet
//! jams and whether people or robots are in the way.

use crate::warehouse::{Segment, Site};
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
