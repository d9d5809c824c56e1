//! Peek-and-pass's candidates: sequences of constant segments, a unicycle's (v, ω) or a
//! holonomic base's velocities, and each one's path on the plan's time grid as the base
//! would execute it.

use super::PnpParams;
use crate::math::{Real, Vec2, unit, vec2};
use crate::model::{Command, EgoState};

/// The candidates, fixed by the parameters, and their paths in the current plan.
#[derive(Debug, Clone)]
pub(super) struct Candidates {
    /// Per candidate, per segment: (v, ω) as fractions of the top speed and turn rate, or
    /// for a holonomic base (v, direction in rad from the way to the goal).
    pub(super) primitives: Vec<Vec<(Real, Real)>>,
    /// The distinct sequences of turn fractions among the candidates, and each candidate's.
    /// A candidate's heading depends on its turns alone, so candidates that differ only in
    /// speed share one heading track.
    turn_sequences: Vec<Vec<Real>>,
    turns_of: Vec<usize>,
    /// Per candidate, its prefix: which run of siblings (consecutive candidates that differ
    /// only in their last segment) it belongs to.
    prefix_of: Vec<usize>,
    /// Every candidate's path on the grid, n + 1 points each, from the last `roll_out`.
    paths: Vec<Vec2>,
    /// Per turn sequence, the unit heading after each integration substep.
    headings: Vec<Vec2>,
    /// (direction, its unit vector) for a holonomic base, in this plan.
    ways: Vec<(Real, Vec2)>,
    /// The way to the goal (unit), which holonomic candidates' directions are from.
    toward: Vec2,
}

impl Candidates {
    /// Every sequence of `p.segments` segments from `p`'s speeds and turns (or directions),
    /// prefix-major.
    pub(super) fn new(p: &PnpParams) -> Self {
        let segment_set = |speeds: &[Real]| -> Vec<(Real, Real)> {
            if p.directions.is_empty() {
                speeds
                    .iter()
                    .flat_map(|&v| p.turns.iter().map(move |&w| (v, w)))
                    .collect()
            } else {
                // Standing still has no direction: once.
                speeds
                    .iter()
                    .flat_map(|&v| {
                        let ways = if v == 0.0 {
                            &p.directions[..1]
                        } else {
                            &p.directions[..]
                        };
                        ways.iter().map(move |&a| (v, a))
                    })
                    .collect()
            }
        };
        let later = segment_set(&p.speeds);
        let first = if p.first_speeds.is_empty() {
            later.clone()
        } else {
            segment_set(&p.first_speeds)
        };
        let mut primitives: Vec<Vec<(Real, Real)>> = vec![Vec::new()];
        for k in 0..p.segments.max(1) {
            let set = if k == 0 { &first } else { &later };
            primitives = primitives
                .iter()
                .flat_map(|prefix| {
                    set.iter().map(move |&seg| {
                        let mut p = prefix.clone();
                        p.push(seg);
                        p
                    })
                })
                .collect();
        }
        let mut turn_sequences: Vec<Vec<Real>> = Vec::new();
        let turns_of = primitives
            .iter()
            .map(|primitive| {
                let turns: Vec<Real> = primitive.iter().map(|&(_, w)| w).collect();
                turn_sequences
                    .iter()
                    .position(|seq| *seq == turns)
                    .unwrap_or_else(|| {
                        turn_sequences.push(turns);
                        turn_sequences.len() - 1
                    })
            })
            .collect();
        let last = p.segments.max(1) - 1;
        let mut prefix_of = Vec::with_capacity(primitives.len());
        for (c, primitive) in primitives.iter().enumerate() {
            let same = c > 0 && primitives[c - 1][..last] == primitive[..last];
            let before = prefix_of.last().copied();
            prefix_of.push(match before {
                Some(g) if same => g,
                Some(g) => g + 1,
                None => 0,
            });
        }
        Self {
            primitives,
            turn_sequences,
            turns_of,
            prefix_of,
            paths: Vec::new(),
            headings: Vec::new(),
            ways: Vec::new(),
            toward: vec2(1.0, 0.0),
        }
    }

    /// Candidate `c`'s path in the last roll-out on an n-step grid.
    pub(super) fn path(&self, c: usize, n: usize) -> &[Vec2] {
        &self.paths[c * (n + 1)..(c + 1) * (n + 1)]
    }

    /// How many runs of siblings there are (see [`Candidates::prefix_of`]).
    pub(super) fn prefixes(&self) -> usize {
        self.prefix_of.last().map_or(0, |g| g + 1)
    }

    /// Candidate `c`'s run of siblings: candidates that differ only in their last segment,
    /// whose paths are the same up to grid point [`Candidates::shared_until`].
    pub(super) fn prefix_of(&self, c: usize) -> usize {
        self.prefix_of[c]
    }

    /// The last grid point siblings' paths share on an n-step grid.
    pub(super) fn shared_until(&self, n: usize) -> usize {
        let segments = self.primitives.first().map_or(1, Vec::len);
        ((segments - 1) * n.div_ceil(segments)).min(n)
    }

    /// Sets the way to `goal` from where the robot stands (its heading if there).
    pub(super) fn aim(&mut self, ego: &EgoState, goal: Vec2) {
        let to_goal = goal - ego.position;
        self.toward = if to_goal.norm() > 1e-9 {
            to_goal / to_goal.norm()
        } else {
            unit(ego.heading)
        };
    }

    /// The command that drives segment `(v, w)` (fractions; a direction in rad if holonomic).
    pub(super) fn command(&self, p: &PnpParams, (v, w): (Real, Real)) -> Command {
        if p.directions.is_empty() {
            Command::Unicycle {
                speed: v * p.v_max,
                yaw_rate: w * p.omega_max,
            }
        } else {
            Command::Velocity(rotate(self.toward, w) * (v * p.v_max))
        }
    }

    /// Every candidate's path on the grid, executed as the base executes unicycle commands
    /// (speed and turn rate approach each segment's within the acceleration limits).
    pub(super) fn roll_out(&mut self, p: &PnpParams, ego: &EgoState, n: usize, dt: Real) {
        if !p.directions.is_empty() {
            self.roll_out_holonomic(p, ego, n, dt);
            return;
        }
        let segments = self.primitives.first().map_or(1, Vec::len);
        let per_segment = n.div_ceil(segments);
        // Integrated at 50 ms, at most (the simulator steps at 0.1 s).
        let substeps = (dt / 0.05 - 1e-9).ceil().max(1.0) as usize;
        let h = dt / substeps as Real;
        // The turn rate and heading do not depend on the speed: one heading track per
        // sequence of turns.
        let track = n * substeps;
        self.headings.clear();
        self.headings.reserve(self.turn_sequences.len() * track);
        for turns in &self.turn_sequences {
            let (mut heading, mut w) = (ego.heading, ego.yaw_rate);
            for k in 0..n {
                let tw = turns[(k / per_segment).min(segments - 1)] * p.omega_max;
                for _ in 0..substeps {
                    w += (tw - w).clamp(-p.yaw_accel_max * h, p.yaw_accel_max * h);
                    heading += w * h;
                    self.headings.push(unit(heading));
                }
            }
        }
        self.paths.clear();
        self.paths.reserve(self.primitives.len() * (n + 1));
        // Candidates come prefix-major: one that shares its first segments with the one before
        // starts from where that one stood at the end of them (same bits, half the work).
        let start = (ego.position, ego.velocity.dot(&unit(ego.heading)));
        let mut boundary = vec![start; segments + 1];
        let grid = (n, per_segment);
        for (c, primitive) in self.primitives.iter().enumerate() {
            let (shared, from) =
                start_path(&mut self.paths, &self.primitives, c, grid, ego.position);
            let headings = &self.headings[self.turns_of[c] * track..][..track];
            let (mut position, mut v) = boundary[shared.min(segments)];
            for k in from..n {
                let segment = (k / per_segment).min(segments - 1);
                if k % per_segment == 0 {
                    boundary[segment] = (position, v);
                }
                let tv = primitive[segment].0 * p.v_max;
                for heading in &headings[k * substeps..(k + 1) * substeps] {
                    v += (tv - v).clamp(-p.a_max * h, p.a_max * h);
                    position += heading * (v * h);
                }
                self.paths.push(position);
            }
        }
    }

    /// [`Pnp::roll_out`] for a holonomic base: the velocity approaches each segment's within
    /// the acceleration limit, as the simulator's robots execute velocity commands, in
    /// closed form ([`Ramp`]).
    fn roll_out_holonomic(&mut self, p: &PnpParams, ego: &EgoState, n: usize, dt: Real) {
        let segments = self.primitives.first().map_or(1, Vec::len);
        let per_segment = n.div_ceil(segments);
        let substeps = (dt / 0.05 - 1e-9).ceil().max(1.0) as usize;
        let h = dt / substeps as Real;
        self.paths.clear();
        self.paths.reserve(self.primitives.len() * (n + 1));
        // Each direction's unit vector once per plan (the candidates hold the angle).
        self.ways.clear();
        let toward = self.toward;
        self.ways
            .extend(p.directions.iter().map(|&a| (a, rotate(toward, a))));
        let ways = &self.ways;
        let way = |a: Real| {
            ways.iter()
                .find(|w| w.0 == a)
                .map_or_else(|| rotate(toward, a), |w| w.1)
        };
        // Segment s holds grid steps `start(s)..end(s)`; the last one runs to the horizon.
        let start = |s: usize| (s * per_segment).min(n);
        let end = |s: usize| {
            if s + 1 == segments { n } else { start(s + 1) }
        };
        let mut boundary = vec![(ego.position, ego.velocity); segments + 1];
        let grid = (n, per_segment);
        for (c, primitive) in self.primitives.iter().enumerate() {
            let (shared, _) = start_path(&mut self.paths, &self.primitives, c, grid, ego.position);
            let (mut position, mut v) = boundary[shared.min(segments)];
            for (s, &(fv, a)) in primitive.iter().enumerate().skip(shared) {
                let steps = end(s).saturating_sub(start(s));
                if steps == 0 {
                    continue;
                }
                boundary[s] = (position, v);
                let ramp = Ramp::new(v, way(a) * (fv * p.v_max), p.a_max * h);
                let from = position;
                for k in 1..=steps {
                    position = from + ramp.displacement(k * substeps) * h;
                    self.paths.push(position);
                }
                v = ramp.velocity(steps * substeps);
            }
        }
    }
}

/// A velocity approaching `target` within the acceleration limit, integrated in substeps of
/// h: each substep the velocity moves `m` (the limit times h) straight toward the target, or
/// onto it once within `m`, and the position moves by the new velocity times h. Along a
/// straight line the sums have a closed form; substep by substep the same values come out
/// to rounding (the tests check 1e-9 m).
#[derive(Debug, Clone, Copy)]
struct Ramp {
    v0: Vec2,
    /// The way to the target (unit; 0 if there).
    way: Vec2,
    /// How far the velocity is from the target (m/s), and the step `m`.
    gap: Real,
    m: Real,
    /// Substeps before the last one that reaches the target: ⌊gap / m⌋.
    full: Real,
}

impl Ramp {
    fn new(v0: Vec2, target: Vec2, m: Real) -> Self {
        let d = target - v0;
        let gap = d.norm();
        let way = if gap > 0.0 {
            d * (1.0 / gap)
        } else {
            vec2(0.0, 0.0)
        };
        // ≥ 0: truncation is the floor (a cast, not a call).
        let full = if m > 0.0 {
            (gap / m) as u64 as Real
        } else {
            0.0
        };
        Self {
            v0,
            way,
            gap,
            m,
            full,
        }
    }

    /// The velocity after `i` substeps.
    fn velocity(&self, i: usize) -> Vec2 {
        self.v0 + self.way * (i as Real * self.m).min(self.gap)
    }

    /// The sum of the velocities after substeps 1 to `k` (times h, how far the body moved).
    fn displacement(&self, k: usize) -> Vec2 {
        let k = k as Real;
        let gained = if self.m <= 0.0 {
            0.0
        } else if k <= self.full {
            self.m * k * (k + 1.0) / 2.0
        } else {
            self.m * self.full * (self.full + 1.0) / 2.0 + (k - self.full) * self.gap
        };
        self.v0 * k + self.way * gained
    }
}

/// Starts candidate `c`'s path in `paths` (n + 1 points per candidate, prefix-major, each
/// segment `per_segment` grid steps): the segments it shares with candidate c − 1 end at grid
/// point `from`, and the path up to there is copied from c − 1's (the start alone if none).
/// Returns (shared segments, `from`).
fn start_path(
    paths: &mut Vec<Vec2>,
    primitives: &[Vec<(Real, Real)>],
    c: usize,
    (n, per_segment): (usize, usize),
    start: Vec2,
) -> (usize, usize) {
    let shared = match c.checked_sub(1) {
        None => 0,
        Some(before) => primitives[c]
            .iter()
            .zip(&primitives[before])
            .take_while(|(a, b)| a == b)
            .count(),
    };
    let from = (shared * per_segment).min(n);
    if c == 0 || from == 0 {
        paths.push(start);
    } else {
        let previous = paths.len() - (n + 1);
        paths.extend_from_within(previous..previous + from + 1);
    }
    (shared, from)
}

/// `u` turned by `angle` (rad, counter-clockwise).
pub(super) fn rotate(u: Vec2, angle: Real) -> Vec2 {
    let (s, c) = angle.sin_cos();
    vec2(c * u.x - s * u.y, s * u.x + c * u.y)
}
