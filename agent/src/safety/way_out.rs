//! The yield: when someone walking on would come into the robot were it to stop, the way out
//! (back off, sidestep, turn away, or the planner's command) that keeps the robot clearest
//! over the yield horizon, among the admissible ones (see the parent module's doc).

use super::{Guarded, LADDER, Motion, SafeSet, SafetyLayer, WallWatch, Zone, scaled, step_toward};
use crate::map::StaticMap;
use crate::math::{Real, unit};
use crate::model::Command;

/// Headings of the holonomic ways out (a full turn in 30° steps) and their speeds (fractions
/// of the top speed).
const YIELD_HEADINGS: usize = 12;
const YIELD_SPEEDS: [Real; 2] = [0.5, 1.0];
/// A unicycle's ways out: speeds (fractions of the top speed; negative backs off) × turn
/// rates (fractions of the largest).
const YIELD_UNICYCLE_SPEEDS: [Real; 4] = [-0.5, 0.0, 0.5, 1.0];
const YIELD_UNICYCLE_TURNS: [Real; 5] = [-1.0, -0.5, 0.0, 0.5, 1.0];
/// The most candidates a yield compares: the ladder, the ways out and a stop.
const MAX_CANDIDATES: usize = LADDER.len() + YIELD_HEADINGS * YIELD_SPEEDS.len() + 1;
/// The clearance rollout's step (s): it ranks ways out; admissibility, checked at the
/// protective check's finer step, is the guarantee.
const CLEARANCE_STEP: Real = 0.1;

impl SafetyLayer {
    /// How clear the robot executing `command` over the yield horizon T_y stays of every body
    /// walking on at its perceived velocity: the smallest gap (m, surface to surface) when
    /// nobody touches it, else t − T_y − one step (< 0) for a first touch at t, so that a
    /// later touch ranks above an earlier one (a body does not pass through the robot, so
    /// how deep its straight line would go means nothing). A stop command brakes; any other
    /// is driven for the whole horizon, except that the robot halts where it would come
    /// within the margin of a wall or shelf. With `bound` ≥ 0 the rollout ends once the gap
    /// falls below it (the result is then below `bound`).
    fn clearance(&self, command: Command, map: &StaticMap, bound: Real) -> Real {
        let p = &self.params;
        let steps = (p.yield_time / CLEARANCE_STEP).ceil() as usize;
        let mut m = Motion::of(&self.ego);
        let mut lowest = Real::INFINITY;
        let mut t = 0.0;
        let walls = !self.local.is_empty();
        let mut watch = WallWatch::new(m.position, self.ego_wall, self.ego.radius, p.margin);
        let mut halted = false;
        for _ in 0..steps {
            if !halted {
                let before = m;
                step_toward(&mut m, command, &self.limits, CLEARANCE_STEP);
                if walls && watch.approached(&self.local, map, before.position, m.position) {
                    m = before;
                    halted = true;
                }
            }
            t += CLEARANCE_STEP;
            for w in &self.walkers {
                let d_sq = (w.position + w.velocity * t - m.position).norm_squared();
                // A body farther than the lowest gap so far plus its reach cannot lower it:
                // no square root for it (the slack keeps the result bit for bit).
                let limit = lowest + w.touching;
                if limit > 0.0 && d_sq > limit * limit * (1.0 + 1e-12) {
                    continue;
                }
                lowest = lowest.min(d_sq.sqrt() - w.touching);
            }
            if lowest < 0.0 {
                return t - p.yield_time - CLEARANCE_STEP;
            }
            if bound >= 0.0 && lowest < bound {
                break;
            }
        }
        lowest
    }
}

impl SafeSet<'_> {
    /// Whether someone walking on at their perceived velocity would come within the margin
    /// of the robot, were it to stop now, within the yield horizon.
    pub fn threatened(&self) -> bool {
        let l = self.layer;
        l.params.yielding
            && !l.walkers.is_empty()
            && l.clearance(Command::STOP, self.map, l.params.margin) < l.params.margin
    }

    /// The predicted body clearance of `command` over the yield horizon (m, surface to
    /// surface; infinite with nobody near; negative for a predicted touch, the sooner the
    /// lower, as the yield ranks ways out).
    pub fn clearance(&self, command: Command) -> Real {
        self.layer.clearance(command, self.map, Real::NEG_INFINITY)
    }

    /// The yield: among the admissible candidates (the command, its fractions, the ways out,
    /// a stop), the one with the largest clearance capped at the yield clearance, ties to the
    /// one nearest the command; `None` when that is the command itself (the fields then act
    /// on it as usual).
    pub(super) fn yield_from(&self, command: Command) -> Option<Guarded> {
        let l = self.layer;
        let cap = l.params.yield_clearance;
        let mut candidates = [(0.0, Command::STOP, 0.0); MAX_CANDIDATES];
        let n = self.candidates(command, &mut candidates);
        let candidates = &mut candidates[..n];
        // Nearest the command first (stable: ties keep the order they were made in).
        candidates.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut best: Option<(Real, Command, Real)> = None;
        for (k, &(_, candidate, scale)) in candidates.iter().enumerate() {
            // A command already ranked (the fractions of a stop are all stops) ranks the same.
            if candidates[..k].iter().any(|c| c.1 == candidate) {
                continue;
            }
            let floor = best.map_or(Real::NEG_INFINITY, |b| b.0);
            let clearance = l.clearance(candidate, self.map, floor).min(cap);
            if clearance <= floor || !self.admits(candidate) {
                continue;
            }
            best = Some((clearance, candidate, scale));
            if clearance >= cap {
                // Nothing later is both clearer and nearer the command.
                break;
            }
        }
        match best {
            Some((_, c, scale)) if scale == 1.0 && c == command => None,
            Some((_, c, scale)) => Some(Guarded {
                command: c,
                zone: Zone::Yield,
                scale,
            }),
            // Cornered: nothing is admissible; the robot brakes where it is.
            None => Some(Guarded {
                command: scaled(command, 0.0),
                zone: Zone::Protective,
                scale: 0.0,
            }),
        }
    }

    /// Fills `out` with (distance to `command`, candidate, fraction of `command`, 0 for a
    /// way out) and returns how many.
    fn candidates(
        &self,
        command: Command,
        out: &mut [(Real, Command, Real); MAX_CANDIDATES],
    ) -> usize {
        let limits = &self.layer.limits;
        let mut n = 0;
        let mut push = |c: Command, scale: Real| {
            out[n] = (command_distance(command, c), c, scale);
            n += 1;
        };
        let within_limits = |c: Command| match c {
            Command::Velocity(v) => v.norm() <= limits.max_speed,
            Command::Unicycle { speed, .. } => speed.abs() <= limits.max_speed,
        };
        for s in LADDER {
            // A way out keeps within the base's limits (the command itself may not: it is
            // then the fields' to act on, as usual).
            if s < 1.0 && !within_limits(scaled(command, s)) {
                continue;
            }
            push(
                if s == 1.0 {
                    command
                } else {
                    scaled(command, s)
                },
                s,
            );
        }
        push(scaled(command, 0.0), 0.0);
        match command {
            Command::Velocity(_) => {
                for k in 0..YIELD_HEADINGS {
                    let heading = k as Real * std::f64::consts::TAU / YIELD_HEADINGS as Real;
                    for s in YIELD_SPEEDS {
                        push(
                            Command::Velocity(unit(heading) * (s * limits.max_speed)),
                            0.0,
                        );
                    }
                }
            }
            Command::Unicycle { .. } => {
                for v in YIELD_UNICYCLE_SPEEDS {
                    for w in YIELD_UNICYCLE_TURNS {
                        push(
                            Command::Unicycle {
                                speed: v * limits.max_speed,
                                yaw_rate: w * limits.max_yaw_rate,
                            },
                            0.0,
                        );
                    }
                }
            }
        }
        n
    }
}

/// How far apart two commands are: the velocity difference (m/s), or for unicycle commands
/// the speed difference and half the turn-rate difference (a 1 rad/s turn at a 0.5 m lever).
fn command_distance(a: Command, b: Command) -> Real {
    match (a, b) {
        (Command::Velocity(x), Command::Velocity(y)) => (x - y).norm(),
        (
            Command::Unicycle {
                speed: s1,
                yaw_rate: w1,
            },
            Command::Unicycle {
                speed: s2,
                yaw_rate: w2,
            },
        ) => ((s1 - s2).powi(2) + (0.5 * (w1 - w2)).powi(2)).sqrt(),
        _ => Real::INFINITY,
    }
}
