//! Social-navigation metrics, per robot and over a fleet, as the PGP paper and the literature
//! it follows (Francis et al. 2025; Gao & Huang 2022) define them.
//!
//! Definitions (all per robot, over one run; "moving" means speed > 0.05 m/s, because "if an
//! agent is standing, it should not be responsible for avoiding collisions"):
//! - **success**: the goal was reached within the scenario's time limit;
//! - **time to goal**: seconds until the goal was reached (successful runs only);
//! - **path length**: metres driven until the goal was reached or time ran out;
//! - **collision rate**: share of moving steps with a body overlap (centre distance below the
//!   sum of radii) with a person or another robot, or with a wall or shelf (the simulator
//!   does not stop robots at obstacles; it counts the contact);
//! - **space-violation rate (SVR)**: share of moving steps with any person or robot closer
//!   than 1.0 m, centre to centre;
//! - **social force**: the magnitude of the summed Social Force (PySocialForce's interaction
//!   force with its default parameters) that all people exert on the robot, averaged over all
//!   steps;
//! - **minimum human distance**: smallest centre distance to any person;
//! - **intimate / personal time**: seconds with any person's body closer than 0.45 m / 1.2 m
//!   to the robot's body (Hall's zones, surface to surface);
//! - **still time**: seconds at speed ≤ 0.05 m/s before the goal;
//! - **robot near misses**: steps with another robot's body closer than 0.3 m without overlap;
//! - **force on people**: the Social Force the robot exerts on all people, summed over people
//!   and averaged over steps (how much the robot pushes people around);
//! - **contacts by cause**: the onsets of body overlaps (a contact counts once, at the step it
//!   begins), told apart as HuNavSim does: with a person, **robot-caused** when at the onset
//!   the robot's own velocity along the line of centres toward the person exceeds
//!   [`CAUSING_SPEED`] ([`contact_cause`]), else **person-caused** (a person walked into a robot
//!   that stood or moved away); with another robot, and with a wall or shelf, each counted
//!   apart.

use crate::world::World;
use agent::math::{Real, Vec2};
use agent::social_force::social_force_pair;

/// A robot moves when faster than this (m/s).
pub const MOVING_SPEED: Real = 0.05;
/// Space-violation threshold, centre to centre (m).
pub const SVR_DISTANCE: Real = 1.0;
/// Hall's intimate zone, body to body (m).
pub const INTIMATE_GAP: Real = 0.45;
/// Hall's personal zone, body to body (m).
pub const PERSONAL_GAP: Real = 1.2;
/// The peek-and-pass paper's personal space (Sec. V-B: "defined here as 0.5 m"), taken as
/// the gap between the bodies' surfaces (their centres cannot come within 0.5 m without
/// overlapping).
pub const PERSONAL_SPACE_ENTRY_GAP: Real = 0.5;
/// Robot–robot near miss, body to body (m).
pub const NEAR_MISS_GAP: Real = 0.3;
/// A contact is the robot's when, at its onset, the robot moves toward the other body faster
/// than this along the line of centres (m/s): the moving threshold, so that a robot that
/// stands (or creeps at sensor-noise speed) is not blamed for being walked into.
pub const CAUSING_SPEED: Real = MOVING_SPEED;

/// Who caused a contact, judged at its onset.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ContactCause {
    /// The robot was moving toward the other body.
    Robot,
    /// The other body came to a robot that stood or moved away.
    Other,
}

/// The cause of a contact beginning between a robot at `robot` moving at `velocity` and a
/// body at `other`: the robot's when its velocity along the line of centres toward the body
/// exceeds [`CAUSING_SPEED`].
pub fn contact_cause(robot: Vec2, velocity: Vec2, other: Vec2) -> ContactCause {
    let line = other - robot;
    let distance = line.norm();
    // Coincident centres: the robot's speed alone decides.
    let toward = if distance > 0.0 {
        velocity.dot(&line) / distance
    } else {
        velocity.norm()
    };
    if toward > CAUSING_SPEED {
        ContactCause::Robot
    } else {
        ContactCause::Other
    }
}

/// One robot's metrics over a run.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RobotMetrics {
    /// Reached the goal in time.
    pub success: bool,
    /// Seconds to the goal (NaN if not reached).
    pub time_to_goal_s: Real,
    /// Metres driven.
    pub path_length_m: Real,
    /// Share of moving steps with a body overlap.
    pub collision_rate: Real,
    /// Share of moving steps with someone within 1 m.
    pub svr: Real,
    /// Mean magnitude of the Social Force on the robot.
    pub social_force: Real,
    /// Smallest centre distance to a person (m).
    pub min_human_distance_m: Real,
    /// Seconds with a person in the intimate zone.
    pub intimate_time_s: Real,
    /// Seconds with a person in the personal zone.
    pub personal_time_s: Real,
    /// Seconds standing still before arriving.
    pub still_time_s: Real,
    /// Steps with a robot–robot near miss.
    pub robot_near_misses: u64,
    /// Steps with a body overlap with another robot.
    pub robot_contacts: u64,
    /// Mean Social Force the robot exerts on people (summed over people).
    pub force_on_people: Real,
    /// Delay the robot caused people (person-seconds, `impact::HumanImpact`); 0 where the
    /// impact is not measured.
    pub human_delay_s: Real,
    /// Extra path the robot caused people (m, `impact::HumanImpact`); 0 where not measured.
    pub human_extra_path_m: Real,
    /// Contacts with people the robot caused (onsets, [`contact_cause`]).
    pub robot_caused_contacts: u64,
    /// Contacts people caused, walking into the robot (onsets).
    pub person_caused_contacts: u64,
    /// Contacts with other robots (onsets).
    pub robot_robot_contacts: u64,
    /// Contacts with walls and shelves (onsets).
    pub wall_contacts: u64,
    /// Times the robot entered a person's personal space: onsets of a gap under
    /// [`PERSONAL_SPACE_ENTRY_GAP`], counted per person.
    pub personal_space_entries: u64,
    /// Times people changed their path because of the robot (`impact::HumanImpact`, where it
    /// is measured; 0 elsewhere).
    pub human_path_changes: u64,
}

impl RobotMetrics {
    /// Every contact onset: with people (robot-caused and person-caused), with robots, with
    /// walls and shelves.
    pub fn total_contacts(&self) -> u64 {
        self.robot_caused_contacts
            + self.person_caused_contacts
            + self.robot_robot_contacts
            + self.wall_contacts
    }
}

/// Accumulates one robot's metrics step by step.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct MetricsRecorder {
    index: usize,
    steps: u64,
    moving_steps: u64,
    collision_steps: u64,
    violation_steps: u64,
    social_force_sum: Real,
    force_on_people_sum: Real,
    min_human_distance: Real,
    intimate_steps: u64,
    personal_steps: u64,
    still_steps: u64,
    near_miss_steps: u64,
    robot_contact_steps: u64,
    /// Contact onsets by cause, and who is touching the robot now (people, robots, a wall).
    contacts: ContactCounts,
    touching_people: Vec<bool>,
    in_personal_space: Vec<bool>,
    personal_space_entries: u64,
    touching_robots: Vec<bool>,
    touching_wall: bool,
    path_length: Real,
    last_position: Vec2,
    arrived_at: Option<Real>,
    /// Episodes stop recording at the goal; fleets (whose goals move) never do.
    stop_at_goal: bool,
    dt: Real,
}

impl MetricsRecorder {
    /// Starts recording robot `index` of `world`.
    pub fn new(world: &World, index: usize) -> Self {
        Self {
            index,
            steps: 0,
            moving_steps: 0,
            collision_steps: 0,
            violation_steps: 0,
            social_force_sum: 0.0,
            force_on_people_sum: 0.0,
            min_human_distance: Real::INFINITY,
            intimate_steps: 0,
            personal_steps: 0,
            still_steps: 0,
            near_miss_steps: 0,
            robot_contact_steps: 0,
            contacts: ContactCounts::default(),
            touching_people: vec![false; world.humans.crowd.len()],
            in_personal_space: vec![false; world.humans.crowd.len()],
            personal_space_entries: 0,
            touching_robots: vec![false; world.robots.len()],
            touching_wall: false,
            path_length: 0.0,
            last_position: world.robots[index].state.position,
            arrived_at: None,
            stop_at_goal: true,
            dt: world.dt,
        }
    }

    /// Records robot `index` for as long as it runs, whatever its goals (fleets with tasks).
    pub fn continuous(world: &World, index: usize) -> Self {
        Self {
            stop_at_goal: false,
            ..Self::new(world, index)
        }
    }

    /// Whether the robot has arrived (recording stops then).
    pub fn arrived(&self) -> bool {
        self.arrived_at.is_some()
    }

    /// Records the world after a step.
    pub fn record(&mut self, world: &World) {
        if self.arrived_at.is_some() {
            return;
        }
        let robot = &world.robots[self.index];
        let ego = robot.state;
        let sf = world.sf_params().social;
        self.steps += 1;
        self.path_length += (ego.position - self.last_position).norm();
        self.last_position = ego.position;
        let moving = ego.velocity.norm() > MOVING_SPEED;

        let (mut overlap, mut violation, mut intimate, mut personal) = (false, false, false, false);
        let mut force = Vec2::zeros();
        let mut force_on_people = 0.0;
        let crowd = &world.humans.crowd;
        for i in 0..crowd.len() {
            let d = (crowd.positions[i] - ego.position).norm();
            let gap = d - ego.radius - world.humans.radius;
            self.min_human_distance = self.min_human_distance.min(d);
            overlap |= gap < 0.0;
            self.contacts.person_onset(
                &mut self.touching_people[i],
                gap < 0.0,
                contact_cause(ego.position, ego.velocity, crowd.positions[i]),
            );
            violation |= d < SVR_DISTANCE;
            intimate |= gap < INTIMATE_GAP;
            personal |= gap < PERSONAL_GAP;
            let inside = gap < PERSONAL_SPACE_ENTRY_GAP;
            self.personal_space_entries += u64::from(inside && !self.in_personal_space[i]);
            self.in_personal_space[i] = inside;
            force += social_force_pair(
                ego.position,
                ego.velocity,
                crowd.positions[i],
                crowd.velocities[i],
                &sf,
            );
            force_on_people += (social_force_pair(
                crowd.positions[i],
                crowd.velocities[i],
                ego.position,
                ego.velocity,
                &sf,
            ) * sf.factor)
                .norm();
        }
        // Walls and shelves: the simulator does not stop a robot at them, so touching one is
        // counted here as a collision.
        let on_wall = world.map.distance(&ego.position) < ego.radius;
        overlap |= on_wall;
        self.contacts.wall += u64::from(on_wall && !self.touching_wall);
        self.touching_wall = on_wall;
        for (j, other) in world.robots.iter().enumerate() {
            if j == self.index {
                continue;
            }
            let d = (other.state.position - ego.position).norm();
            let gap = d - ego.radius - other.state.radius;
            overlap |= gap < 0.0;
            violation |= d < SVR_DISTANCE;
            if (0.0..NEAR_MISS_GAP).contains(&gap) {
                self.near_miss_steps += 1;
            }
            if gap < 0.0 {
                self.robot_contact_steps += 1;
            }
            self.contacts.robot += u64::from(gap < 0.0 && !self.touching_robots[j]);
            self.touching_robots[j] = gap < 0.0;
        }
        if moving {
            self.moving_steps += 1;
            self.collision_steps += u64::from(overlap);
            self.violation_steps += u64::from(violation);
        } else {
            self.still_steps += 1;
        }
        self.intimate_steps += u64::from(intimate);
        self.personal_steps += u64::from(personal);
        self.social_force_sum += (force * sf.factor).norm();
        self.force_on_people_sum += force_on_people;
        if self.stop_at_goal && robot.arrived() {
            self.arrived_at = Some(world.time);
        }
    }

    /// The metrics so far.
    pub fn finish(&self) -> RobotMetrics {
        let per_moving = |k: u64| {
            if self.moving_steps > 0 {
                k as Real / self.moving_steps as Real
            } else {
                0.0
            }
        };
        let per_step = |x: Real| {
            if self.steps > 0 {
                x / self.steps as Real
            } else {
                0.0
            }
        };
        RobotMetrics {
            success: self.arrived_at.is_some(),
            time_to_goal_s: self.arrived_at.unwrap_or(Real::NAN),
            path_length_m: self.path_length,
            collision_rate: per_moving(self.collision_steps),
            svr: per_moving(self.violation_steps),
            social_force: per_step(self.social_force_sum),
            min_human_distance_m: self.min_human_distance,
            intimate_time_s: self.intimate_steps as Real * self.dt,
            personal_time_s: self.personal_steps as Real * self.dt,
            still_time_s: self.still_steps as Real * self.dt,
            robot_near_misses: self.near_miss_steps,
            robot_contacts: self.robot_contact_steps,
            force_on_people: per_step(self.force_on_people_sum),
            human_delay_s: 0.0,
            human_extra_path_m: 0.0,
            robot_caused_contacts: self.contacts.robot_caused,
            person_caused_contacts: self.contacts.person_caused,
            robot_robot_contacts: self.contacts.robot,
            wall_contacts: self.contacts.wall,
            personal_space_entries: self.personal_space_entries,
            human_path_changes: 0,
        }
    }
}

/// Contact onsets by cause.
#[derive(Debug, Clone, Copy, Default, serde::Serialize, serde::Deserialize)]
struct ContactCounts {
    robot_caused: u64,
    person_caused: u64,
    robot: u64,
    wall: u64,
}

impl ContactCounts {
    /// Counts a contact with a person if one begins now (`touching` holds whether one was
    /// under way).
    fn person_onset(&mut self, touching: &mut bool, overlap: bool, cause: ContactCause) {
        if overlap && !*touching {
            match cause {
                ContactCause::Robot => self.robot_caused += 1,
                ContactCause::Other => self.person_caused += 1,
            }
        }
        *touching = overlap;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::Scenario;
    use agent::math::vec2;
    use agent::model::Command;

    fn world_with_one_person(at: Vec2) -> World {
        let mut s = Scenario::builtin("open-space").expect("valid");
        s.open_space.as_mut().expect("layout").density = 0.01;
        let mut w = World::open_space(&s);
        w.humans.crowd.positions[0] = at;
        w.humans.crowd.velocities[0] = vec2(0.0, 0.0);
        w.humans.crowd.goals[0] = at;
        w.humans.react_to_robots = false;
        w
    }

    #[test]
    fn overlap_while_moving_counts_as_collision_and_violation() {
        let start = vec2(0.0, 5.0);
        let mut w = world_with_one_person(start + vec2(0.5, 0.0));
        let mut m = MetricsRecorder::new(&w, 0);
        w.step(&[Command::Velocity(vec2(1.0, 0.0))]);
        m.record(&w);
        let r = m.finish();
        assert_eq!((r.collision_rate, r.svr), (1.0, 1.0));
        assert!(
            (r.min_human_distance_m - (0.5 - 0.015)).abs() < 1e-9,
            "moved 0.015 m at 1.5 m/s²"
        );
        assert!(r.intimate_time_s > 0.0 && r.personal_time_s > 0.0);
        assert!(r.social_force > 0.0 && r.force_on_people > 0.0);
    }

    #[test]
    fn standing_overlap_is_not_a_collision_while_moving() {
        let start = vec2(0.0, 5.0);
        let mut w = world_with_one_person(start + vec2(0.5, 0.0));
        let mut m = MetricsRecorder::new(&w, 0);
        w.step(&[Command::STOP]);
        m.record(&w);
        let r = m.finish();
        assert_eq!((r.collision_rate, r.svr), (0.0, 0.0));
        assert!((r.still_time_s - 0.1).abs() < 1e-12);
    }

    #[test]
    fn touching_a_wall_while_moving_is_a_collision() {
        let s = Scenario::builtin("open-space-walled").expect("valid");
        let mut w = World::from_scenario(&s);
        w.humans
            .crowd
            .positions
            .iter_mut()
            .for_each(|p| *p += vec2(100.0, 0.0));
        let mut m = MetricsRecorder::new(&w, 0);
        // 1 m from the wall at x = −1; drive into it.
        for _ in 0..15 {
            w.step(&[Command::Velocity(vec2(-1.0, 0.0))]);
            m.record(&w);
        }
        let r = m.finish();
        assert!(r.collision_rate > 0.0);
        assert_eq!(r.wall_contacts, 1);
    }

    /// Each class of contact, on constructed cases.
    #[test]
    fn contacts_are_told_apart_by_cause() {
        let (at, east) = (vec2(0.0, 0.0), vec2(1.0, 0.0));
        // Driving into a person ahead: the robot's.
        assert_eq!(contact_cause(at, east, vec2(0.6, 0.0)), ContactCause::Robot);
        // Standing, or backing away, while a person walks in: theirs.
        let person = vec2(0.6, 0.0);
        assert_eq!(
            contact_cause(at, vec2(0.0, 0.0), person),
            ContactCause::Other
        );
        assert_eq!(contact_cause(at, -east, person), ContactCause::Other);
        // Passing sideways, or creeping below the moving speed toward them: theirs.
        assert_eq!(
            contact_cause(at, vec2(0.0, 1.0), person),
            ContactCause::Other
        );
        assert_eq!(contact_cause(at, east * 0.04, person), ContactCause::Other);
        // At an angle, the component along the line of centres decides.
        let diagonal = vec2(0.4, 0.4);
        assert_eq!(contact_cause(at, east * 0.1, diagonal), ContactCause::Robot);
        assert_eq!(
            contact_cause(at, east * 0.07, diagonal),
            ContactCause::Other
        );
    }

    #[test]
    fn entries_into_personal_space_are_counted_per_person_at_their_onset() {
        // The robot drives past a standing person 0.8 m to its side (a 0.15 m gap between
        // the bodies at the closest): one entry, however long it lasts.
        let start = vec2(0.0, 5.0);
        let mut w = world_with_one_person(start + vec2(2.0, 0.8));
        w.humans.crowd.max_speeds[0] = 0.0;
        let mut m = MetricsRecorder::new(&w, 0);
        for _ in 0..40 {
            w.step(&[Command::Velocity(vec2(1.0, 0.0))]);
            m.record(&w);
        }
        assert_eq!(m.finish().personal_space_entries, 1);
        // Passing 1.5 m to its side (a 0.85 m gap): none.
        let mut w = world_with_one_person(start + vec2(2.0, 1.5));
        w.humans.crowd.max_speeds[0] = 0.0;
        let mut m = MetricsRecorder::new(&w, 0);
        for _ in 0..40 {
            w.step(&[Command::Velocity(vec2(1.0, 0.0))]);
            m.record(&w);
        }
        assert_eq!(m.finish().personal_space_entries, 0);
        // Out and back in: two.
        let mut w = world_with_one_person(start + vec2(2.0, 0.8));
        w.humans.crowd.max_speeds[0] = 0.0;
        let mut m = MetricsRecorder::new(&w, 0);
        for v in [1.0, -1.0] {
            for _ in 0..40 {
                w.step(&[Command::Velocity(vec2(v, 0.0))]);
                m.record(&w);
            }
        }
        assert_eq!(m.finish().personal_space_entries, 2);
    }

    #[test]
    fn the_recorder_counts_each_contact_once_at_its_onset() {
        // The robot drives into a standing person: one robot-caused contact, however long
        // the overlap lasts.
        let start = vec2(0.0, 5.0);
        let mut w = world_with_one_person(start + vec2(0.8, 0.0));
        // Standing: no speed to walk at, wherever the world sends them.
        w.humans.crowd.max_speeds[0] = 0.0;
        let mut m = MetricsRecorder::new(&w, 0);
        for _ in 0..12 {
            w.step(&[Command::Velocity(vec2(1.0, 0.0))]);
            m.record(&w);
        }
        let r = m.finish();
        assert_eq!((r.robot_caused_contacts, r.person_caused_contacts), (1, 0));
        // A person walks into the standing robot: theirs.
        let mut w = world_with_one_person(start + vec2(1.5, 0.0));
        w.humans.crowd.velocities[0] = vec2(-1.0, 0.0);
        w.humans.crowd.goals[0] = start - vec2(5.0, 0.0);
        w.humans.crowd.max_speeds[0] = 1.0;
        let mut m = MetricsRecorder::new(&w, 0);
        for _ in 0..15 {
            w.step(&[Command::STOP]);
            m.record(&w);
        }
        let r = m.finish();
        assert_eq!((r.robot_caused_contacts, r.person_caused_contacts), (0, 1));
        assert_eq!((r.robot_robot_contacts, r.wall_contacts), (0, 0));
    }

    #[test]
    fn far_person_gives_no_violation_and_path_length_adds_up() {
        let mut w = world_with_one_person(vec2(8.0, 9.0));
        let mut m = MetricsRecorder::new(&w, 0);
        for _ in 0..20 {
            w.step(&[Command::Velocity(vec2(1.0, 0.0))]);
            m.record(&w);
        }
        let r = m.finish();
        assert_eq!((r.collision_rate, r.svr), (0.0, 0.0));
        let driven = w.robots[0].state.position.x;
        assert!((r.path_length_m - driven).abs() < 1e-9);
        assert!(!r.success && r.time_to_goal_s.is_nan());
    }
}
