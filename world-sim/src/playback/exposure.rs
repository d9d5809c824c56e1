//! What a run is judged by, measured as it goes: the closest approach, the density of people
//! around, and contacts counted at their onset by cause (robot-caused, person-caused, or with
//! someone who appeared too close to stop for).

use super::RunOutcome;
use crate::dataset::Recording;
use crate::metrics::{ContactCause, contact_cause};
use agent::math::{Real, Vec2};
use agent::model::Neighbour;

/// Running s and density.
pub(super) struct Exposure {
    min_distance: Real,
    closest: Option<(u64, Real)>,
    density_sum: Real,
    density_max: Real,
    samples: usize,
    radius: Real,
    /// Centre distance at which two bodies touch.
    contact: Real,
    /// The people touching now.
    touching: Vec<u64>,
    was_touching: Vec<u64>,
    /// Everyone in the recording at this sample and at the one before.
    present: Vec<u64>,
    was_present: Vec<u64>,
    robot_caused: u64,
    person_caused: u64,
    appeared: u64,
    /// For a robot's run: when it started and how hard it brakes (m/s²).
    robot: Option<(Real, Real)>,
    /// People whose track began during the run, by the time the robot perceived them, and
    /// the time by which it could stand braking from then on.
    stand_by: Vec<(u64, Real)>,
}

impl Exposure {
    pub(super) fn new(radius: Real, contact: Real) -> Self {
        Self {
            min_distance: Real::INFINITY,
            closest: None,
            density_sum: 0.0,
            density_max: 0.0,
            samples: 0,
            radius,
            contact,
            touching: Vec::new(),
            was_touching: Vec::new(),
            present: Vec::new(),
            was_present: Vec::new(),
            robot_caused: 0,
            person_caused: 0,
            appeared: 0,
            robot: None,
            stand_by: Vec::new(),
        }
    }

    /// For a robot's run that started at `t_start` and brakes at `braking` (m/s²).
    pub(super) fn for_robot(mut self, t_start: Real, braking: Real) -> Self {
        self.robot = Some((t_start, braking));
        self
    }

    /// The robot, moving at `speed`, perceives `seen` at `t`: the people among them who
    /// appeared during the run are noted with the time by which braking now would stop it.
    pub(super) fn perceive(
        &mut self,
        recording: &Recording,
        t: Real,
        speed: Real,
        seen: &[Neighbour],
    ) {
        let Some((t_start, braking)) = self.robot else {
            return;
        };
        for n in seen {
            if self.stand_by.iter().any(|&(id, _)| id == n.id) {
                continue;
            }
            if appeared_after(recording, n.id, t_start) {
                self.stand_by.push((n.id, t + speed / braking.max(1e-9)));
            }
        }
    }

    /// Whether a contact with `id` beginning at `t` is one the robot could not have stopped
    /// for ([`RunOutcome::appeared_contacts`]).
    fn too_late(&self, recording: &Recording, id: u64, t: Real) -> bool {
        let Some((t_start, _)) = self.robot else {
            return false;
        };
        match self.stand_by.iter().find(|&&(seen, _)| seen == id) {
            Some(&(_, stand_by)) => t < stand_by,
            // Never perceived: only someone who appeared since the last plan.
            None => appeared_after(recording, id, t_start),
        }
    }

    /// The robot (or the person) at `at` moving at `velocity` at time `t`.
    pub(super) fn record(
        &mut self,
        recording: &Recording,
        t: Real,
        at: Vec2,
        velocity: Vec2,
        skip: u64,
    ) {
        let mut near = 0usize;
        std::mem::swap(&mut self.touching, &mut self.was_touching);
        std::mem::swap(&mut self.present, &mut self.was_present);
        self.touching.clear();
        self.present.clear();
        for (id, p, _) in recording.people_at(t, Some(skip)) {
            self.present.push(id);
            let d = (p - at).norm();
            if d < self.min_distance {
                self.min_distance = d;
                self.closest = Some((id, t));
            }
            if d <= self.radius {
                near += 1;
            }
            if d < self.contact {
                self.touching.push(id);
                // A contact under way at the first sample (the run's start, where the robot
                // is put in the person's place before it has acted) began before it, and a
                // person whose track begins inside the robot appeared there: no onsets.
                if self.was_present.contains(&id) && !self.was_touching.contains(&id) {
                    match contact_cause(at, velocity, p) {
                        ContactCause::Robot if self.too_late(recording, id, t) => {
                            self.appeared += 1
                        }
                        ContactCause::Robot => self.robot_caused += 1,
                        ContactCause::Other => self.person_caused += 1,
                    }
                }
            }
        }
        let density = near as Real / (std::f64::consts::PI * self.radius * self.radius);
        self.density_sum += density;
        self.density_max = self.density_max.max(density);
        self.samples += 1;
    }

    pub(super) fn finish(
        self,
        reached: bool,
        path_m: Real,
        human_path_m: Real,
        duration_s: Real,
        replans: usize,
    ) -> RunOutcome {
        RunOutcome {
            reached,
            min_distance_m: self.min_distance,
            closest: self.closest,
            path_m,
            human_path_m,
            duration_s,
            mean_density: self.density_sum / self.samples.max(1) as Real,
            max_density: self.density_max,
            replans,
            robot_caused_contacts: self.robot_caused,
            appeared_contacts: self.appeared,
            person_caused_contacts: self.person_caused,
        }
    }
}

/// Whether `id`'s annotated track begins after `t`.
fn appeared_after(recording: &Recording, id: u64, t: Real) -> bool {
    recording
        .track(id)
        .and_then(|track| track.samples.first())
        .is_some_and(|first| first.t > t)
}
