//! What each robot perceives: the people and robots within its sensor range and line of
//! sight (walls and shelves occlude unless the scenario turns that off; people and robots too
//! with `body_occlusion`), with the scenario's noise, and the sensor's visibility profile.

use super::{ROBOT_ID_BIT, World, gaussian2};
use agent::map::{LocalMap, StaticMap};
use agent::math::{Real, Vec2};
use agent::model::{AgentKind, EgoState, Neighbour};
use agent::visibility::{DEFAULT_RAYS, Visibility};

impl World {
    /// Every body but robot `index`'s: (centre, radius), people first.
    fn bodies_except(&self, index: usize) -> impl Iterator<Item = (Vec2, Real)> + '_ {
        let radius = self.humans.radius;
        let people = self
            .humans
            .crowd
            .positions
            .iter()
            .map(move |&p| (p, radius));
        let robots = self
            .robots
            .iter()
            .enumerate()
            .filter(move |&(j, _)| j != index)
            .map(|(_, r)| (r.state.position, r.state.radius));
        people.chain(robots)
    }

    /// What robot `index`'s sensor sees around it, when its scenario has `body_occlusion`:
    /// the free range along [`agent::visibility::DEFAULT_RAYS`] bearings, ended by walls and
    /// shelves (unless occlusion is off) and by every other body. `None` otherwise.
    pub fn visibility(&self, index: usize, local: &mut LocalMap) -> Option<Visibility> {
        let robot = &self.robots[index];
        if !robot.spec.body_occlusion {
            return None;
        }
        let empty = StaticMap::empty();
        let walls = if robot.spec.occlusion {
            &self.map
        } else {
            &empty
        };
        Some(Visibility::scan(
            robot.state.position,
            robot.spec.sensor_range_m,
            DEFAULT_RAYS,
            walls,
            self.bodies_except(index),
            local,
        ))
    }

    /// What robot `index` perceives: itself, and every person and other robot within its
    /// sensor range whose centre it can see past walls and shelves (unless occlusion is off)
    /// and, with `body_occlusion`, past every other body, with the scenario's noise.
    pub fn observe(&mut self, index: usize) -> (EgoState, Vec<Neighbour>) {
        let robot = &self.robots[index];
        let ego = robot.state;
        let range = robot.spec.sensor_range_m;
        let (pos_noise, vel_noise) = (robot.spec.position_noise_m, robot.spec.velocity_noise);
        let mut seen = Vec::new();
        let crowd = &self.humans.crowd;
        let occlusion = robot.spec.occlusion && !self.map.is_empty();
        let in_range = |p: Vec2| (p - ego.position).norm() <= range;
        let visible =
            |p: Vec2| in_range(p) && (!occlusion || self.map.line_of_sight(ego.position, p));
        for i in 0..crowd.len() {
            if visible(crowd.positions[i]) {
                seen.push(Neighbour::new(
                    i as u64,
                    crowd.positions[i],
                    crowd.velocities[i],
                    self.humans.radius,
                    AgentKind::Human,
                ));
            }
        }
        for (j, other) in self.robots.iter().enumerate() {
            if j != index && visible(other.state.position) {
                let id = ROBOT_ID_BIT | j as u64;
                seen.push(Neighbour::new(
                    id,
                    other.state.position,
                    other.state.velocity,
                    other.state.radius,
                    AgentKind::Robot,
                ));
            }
        }
        if robot.spec.body_occlusion {
            // Every body within range blocks, seen or not (one hidden behind a wall hides
            // nothing in view).
            let blockers: Vec<(Vec2, Real)> = self
                .bodies_except(index)
                .filter(|&(p, r)| (p - ego.position).norm() <= range + r)
                .collect();
            seen.retain(|n| !hidden_by(ego.position, n.position, &blockers));
        }
        if pos_noise > 0.0 || vel_noise > 0.0 {
            let mut rng = super::noise_stream(self.seed, self.step, index);
            for n in &mut seen {
                n.position += gaussian2(&mut rng) * pos_noise;
                n.velocity += gaussian2(&mut rng) * vel_noise;
            }
        }
        (ego, seen)
    }
}

/// Whether a body between `eye` and `target` (and not around `eye`) crosses the line of sight
/// to `target`. The target's own disc, centred on `target`, never blocks it.
fn hidden_by(eye: Vec2, target: Vec2, blockers: &[(Vec2, Real)]) -> bool {
    let line = target - eye;
    let len_sq = line.norm_squared();
    blockers.iter().any(|&(c, r)| {
        let w = c - eye;
        if c == target || w.norm_squared() <= r * r || len_sq == 0.0 {
            return false;
        }
        let s = w.dot(&line) / len_sq;
        // Only bodies between the eye and the target's centre, whose disc the line cuts.
        s > 0.0 && s < 1.0 && (w - line * s).norm_squared() < r * r
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::Scenario;
    use agent::math::{unit, vec2};

    #[test]
    fn walls_hide_people_unless_occlusion_is_off() {
        let mut s = Scenario::builtin("hallway").expect("valid");
        let mut w = World::from_scenario(&s);
        let ego = w.robots[0].state.position;
        // Someone just outside the corridor's lower wall, 2 m ahead.
        w.humans.crowd.positions[0] = ego + vec2(2.0, -2.0);
        let seen = |w: &mut World| w.observe(0).1.iter().any(|n| n.id == 0);
        assert!(!seen(&mut w), "the wall hides them");
        s.robot.occlusion = false;
        let mut transparent = World::from_scenario(&s);
        transparent.humans.crowd.positions[0] = ego + vec2(2.0, -2.0);
        assert!(seen(&mut transparent), "without occlusion they are seen");
    }

    #[test]
    fn in_a_hallway_a_person_behind_another_is_perceived_only_once_they_step_out() {
        let mut s = Scenario::builtin("hallway").expect("valid");
        s.robot.body_occlusion = true;
        let mut w = World::from_scenario(&s);
        let ego = w.robots[0].state.position;
        let ahead = unit(w.robots[0].state.heading);
        let aside = vec2(-ahead.y, ahead.x);
        // Person 0 walks 2 m ahead of the robot; person 1 4 m ahead steps out sideways.
        w.humans.crowd.positions[0] = ego + ahead * 2.0;
        for p in &mut w.humans.crowd.positions[2..] {
            *p = ego - ahead * 30.0;
        }
        let mut first_seen = None;
        for k in 0..=10 {
            let offset = 0.1 * k as Real;
            w.humans.crowd.positions[1] = ego + ahead * 4.0 + aside * offset;
            let (_, seen) = w.observe(0);
            assert!(
                seen.iter().any(|n| n.id == 0),
                "the near person is always seen"
            );
            let seen_1 = seen.iter().any(|n| n.id == 1);
            if seen_1 {
                first_seen.get_or_insert(offset);
            } else {
                assert!(first_seen.is_none(), "hidden again at {offset}");
            }
            // The profile (1° rays) agrees away from the edge of the shadow: the near side
            // of their body is in view exactly when they are seen.
            if (offset - 0.65).abs() >= 0.25 - 1e-9 {
                let profile = w.visibility(0, &mut LocalMap::default()).expect("on");
                let centre = w.humans.crowd.positions[1];
                let near_side = centre - (centre - ego).normalize() * 0.35;
                assert_eq!(profile.sees(near_side), seen_1, "at {offset}");
            }
        }
        // The line of sight to their centre clears person 0's disc (half-way along it) once
        // its distance from person 0's centre, 2·o / √(16 + o²) at offset o, exceeds the radius.
        let r = w.humans.radius;
        let clears = |o: Real| 2.0 * o / (16.0 + o * o).sqrt() > r;
        let first = first_seen.expect("they step out within 1 m");
        assert!(
            clears(first) && !clears(first - 0.1),
            "first seen at {first}, radius {r}"
        );
        // Without body occlusion they are seen from the start.
        s.robot.body_occlusion = false;
        let mut clear = World::from_scenario(&s);
        clear.humans.crowd.positions = w.humans.crowd.positions.clone();
        clear.humans.crowd.positions[1] = ego + ahead * 4.0;
        assert!(clear.observe(0).1.iter().any(|n| n.id == 1));
        assert!(clear.visibility(0, &mut LocalMap::default()).is_none());
    }

    #[test]
    fn perception_respects_range_and_noise_is_seeded() {
        let mut s = Scenario::builtin("open-space").expect("valid");
        s.open_space.as_mut().expect("layout").density = 0.5;
        s.seed = 2;
        s.robot.sensor_range_m = 3.0;
        let mut w = World::open_space(&s);
        let (ego, seen) = w.observe(0);
        assert!(
            seen.iter()
                .all(|n| (n.position - ego.position).norm() <= 3.0)
        );
        s.robot.position_noise_m = 0.1;
        let (mut a, mut b) = (World::open_space(&s), World::open_space(&s));
        let noisy = a.observe(0).1;
        assert_eq!(noisy, b.observe(0).1);
        assert_ne!(noisy, seen, "noise is drawn");
        // The noise of an observation depends on the step and the robot only: observing
        // again (or other robots first) draws the same.
        assert_eq!(a.observe(0).1, noisy);
    }
}
