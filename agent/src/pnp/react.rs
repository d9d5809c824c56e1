//! Predictions that react to each candidate ([`super::Prediction::Reactive`]): people in a
//! hallway give way to a robot that commits to passing, so each candidate is scored against
//! what the people would do were the robot to drive it.
//!
//! Once per plan, a Social Force rollout of the people among themselves (the robot left out)
//! gives each person's mean track without the robot and the push of the others on them at
//! every step. Per candidate, each person whose track without the robot comes near its path
//! is rolled out again: relaxing toward their perceived velocity (0.5 s), pushed by the others
//! as in the shared rollout, and by the robot where the candidate puts it, at the candidate's
//! velocity (PySocialForce's force law, as the simulated people and [`super::predict`]'s
//! rollout use). Walls are left out, as in that rollout.

use super::predict::Predicted;
use super::risk::bounds;
use crate::math::{Real, Vec2, vec2};
use crate::model::{AgentKind, Neighbour};
use crate::prediction::SigmaModel;
use crate::social_force::{SfParams, capped_velocity, mutual_social_forces, social_force_pair};

/// The shared rollout: per person, where they start, what they want and the others' push.
#[derive(Debug, Clone, Default)]
pub(super) struct Reaction {
    /// Per neighbour: its person slot, or `None` for a robot (which does not react).
    slot_of: Vec<Option<usize>>,
    /// Per person: perceived position and velocity (the desired velocity too).
    start: Vec<(Vec2, Vec2)>,
    /// Per person, per step k in 1..=n (at `(slot · n) + k − 1`): the others' push, already
    /// scaled by the social factor.
    others: Vec<Vec2>,
    n: usize,
    dt: Real,
    sf: SfParams,
}

impl Reaction {
    /// Rolls the people out among themselves, filling their tracks in `predicted` (mean and
    /// σ, grown with each step's speed as PGP's is).
    pub(super) fn prepare(
        &mut self,
        neighbours: &[Neighbour],
        n: usize,
        dt: Real,
        sigma: &SigmaModel,
        predicted: &mut [Predicted],
    ) {
        self.n = n;
        self.dt = dt;
        self.slot_of.clear();
        self.start.clear();
        for b in neighbours {
            if b.kind == AgentKind::Human {
                self.slot_of.push(Some(self.start.len()));
                self.start.push((b.position, b.velocity));
            } else {
                self.slot_of.push(None);
            }
        }
        let people = self.start.len();
        self.others.clear();
        self.others.resize(people * n, vec2(0.0, 0.0));
        let mut pos: Vec<Vec2> = self.start.iter().map(|s| s.0).collect();
        let mut vel: Vec<Vec2> = self.start.iter().map(|s| s.1).collect();
        let mut speeds = vec![vec![0.0]; people];
        for (i, slot) in self.slot_of.iter().enumerate() {
            if let Some(a) = *slot {
                predicted[i].track.positions.clear();
                predicted[i].track.positions.push(pos[a]);
            }
        }
        let social = &self.sf.social;
        let mut push = vec![vec2(0.0, 0.0); people];
        for k in 1..=n {
            // Each pair once: the push on a and its reaction on b, which is bit for bit the
            // push on b by a unless they stand on one point. Each person's pushes still add up
            // in the others' order.
            push.fill(vec2(0.0, 0.0));
            for a in 0..people {
                for b in a + 1..people {
                    let (on_a, on_b) = if (pos[a] - pos[b]).norm_squared() == 0.0 {
                        (
                            social_force_pair(pos[a], vel[a], pos[b], vel[b], social),
                            social_force_pair(pos[b], vel[b], pos[a], vel[a], social),
                        )
                    } else {
                        mutual_social_forces(pos[a], vel[a], pos[b], vel[b], social)
                    };
                    push[a] += on_a;
                    push[b] += on_b;
                }
                self.others[a * n + k - 1] = push[a] * social.factor;
            }
            for a in 0..people {
                let desired = self.start[a].1;
                let force = self.relax(desired, vel[a]) + self.others[a * n + k - 1];
                vel[a] = capped_velocity(
                    vel[a] + force * dt,
                    desired.norm() * self.sf.max_speed_multiplier,
                );
                pos[a] += vel[a] * dt;
                speeds[a].push(vel[a].norm());
            }
            for (i, slot) in self.slot_of.iter().enumerate() {
                if let Some(a) = *slot {
                    predicted[i].track.positions.push(pos[a]);
                }
            }
        }
        for (i, slot) in self.slot_of.iter().enumerate() {
            if let Some(a) = *slot {
                let track = &mut predicted[i].track;
                track.sigma.resize(n + 1, 0.0);
                sigma.fill(&speeds[a], &mut track.sigma);
            }
        }
    }

    fn relax(&self, desired: Vec2, velocity: Vec2) -> Vec2 {
        let d = &self.sf.desired;
        (desired - velocity) / d.relaxation_time * d.factor
    }

    /// Whether neighbour `i` reacts to the robot (people do, robots do not).
    pub(super) fn reacts(&self, i: usize) -> bool {
        self.slot_of.get(i).is_some_and(Option::is_some)
    }

    /// Neighbour `i`'s prediction were the robot to follow `path` (on the plan's grid):
    /// `base` with its mean track rolled out again against the path, into `out`.
    pub(super) fn respond(&self, i: usize, path: &[Vec2], base: &Predicted, out: &mut Predicted) {
        let Some(a) = self.slot_of[i] else {
            out.clone_from(base);
            return;
        };
        let (n, dt) = (self.n, self.dt);
        let (mut pos, mut vel) = self.start[a];
        let desired = vel;
        let cap = desired.norm() * self.sf.max_speed_multiplier;
        let social = &self.sf.social;
        out.contact = base.contact;
        out.spread = base.spread;
        out.growth.clone_from(&base.growth);
        out.offsets.clone_from(&base.offsets);
        out.track.sigma.clone_from(&base.track.sigma);
        let positions = &mut out.track.positions;
        positions.clear();
        positions.push(pos);
        for k in 1..=n {
            let robot = path[k - 1];
            let robot_velocity = (path[k] - path[k - 1]) / dt;
            let push = social_force_pair(pos, vel, robot, robot_velocity, social) * social.factor;
            let force = self.relax(desired, vel) + self.others[a * n + k - 1] + push;
            vel = capped_velocity(vel + force * dt, cap);
            pos += vel * dt;
            positions.push(pos);
        }
        let (lo, hi) = bounds(positions);
        let r = out.contact + out.spread;
        out.reach = (lo - vec2(r, r), hi + vec2(r, r));
    }
}
