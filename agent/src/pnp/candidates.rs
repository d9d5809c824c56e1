//! Peek-and-pass's candidates: sequences of constant segments, a unicycle's (v, ω) or a
//! holonomic base's velocities, and each one's path on the plan's time grid as the base
//! would execute it.

use super::PnpParams;
use crate::math::{Real, Vec2, clamp_norm, unit, vec2};
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
    /// Scratch for the holonomic roll-out's sibling tails.
    lanes: Lanes,
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
            lanes: Lanes::default(),
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
    /// the acceleration limit, as the simulator's robots execute velocity commands.
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
        let mut boundary = vec![(ego.position, ego.velocity); segments + 1];
        let grid = (n, per_segment);
        let last = segments - 1;
        // Grid points up to `tail` are the same for candidates that differ only in their
        // last segment (siblings, consecutive in prefix-major order).
        let tail = (last * per_segment).min(n);
        let mut c = 0;
        while c < self.primitives.len() {
            let prefix = &self.primitives[c][..last];
            let siblings = 1 + self.primitives[c + 1..]
                .iter()
                .take_while(|q| q[..last] == *prefix)
                .count();
            // The first sibling's path up to `tail`, stepped as the tail is below.
            let (shared, from) =
                start_path(&mut self.paths, &self.primitives, c, grid, ego.position);
            let (mut position, mut v) = boundary[shared.min(segments)];
            for k in from.min(tail)..tail {
                let segment = k / per_segment;
                if k % per_segment == 0 {
                    boundary[segment] = (position, v);
                }
                let (fv, a) = self.primitives[c][segment];
                let target = way(a) * (fv * p.v_max);
                for _ in 0..substeps {
                    v += clamp_norm(target - v, p.a_max * h);
                    position += v * h;
                }
                self.paths.push(position);
            }
            if tail < n {
                boundary[last] = (position, v);
            }
            // Every sibling starts as the first; their tails are stepped side by side, which
            // keeps the processor busy while each one's square root and division are
            // under way (each value as `clamp_norm` gives it, bit for bit).
            let first = c * (n + 1);
            self.paths.resize(first + n + 1, position);
            for _ in 1..siblings {
                self.paths.extend_from_within(first..first + n + 1);
            }
            let lanes = &mut self.lanes;
            lanes.clear(siblings);
            for (j, primitive) in self.primitives[c..c + siblings].iter().enumerate() {
                let (fv, a) = primitive[last];
                lanes.set(j, position, v, way(a) * (fv * p.v_max));
            }
            let m = p.a_max * h;
            for k in tail..n {
                for _ in 0..substeps {
                    lanes.step(m, h);
                }
                for j in 0..siblings {
                    self.paths[first + j * (n + 1) + k + 1] = vec2(lanes.px[j], lanes.py[j]);
                }
            }
            c += siblings;
        }
    }
}

/// The siblings' states in [`Candidates::roll_out_holonomic`]'s side-by-side tails, one
/// array per coordinate so that the processor steps several at once.
#[derive(Debug, Clone, Default)]
struct Lanes {
    px: Vec<Real>,
    py: Vec<Real>,
    vx: Vec<Real>,
    vy: Vec<Real>,
    tx: Vec<Real>,
    ty: Vec<Real>,
}

impl Lanes {
    /// `count` lanes, all at 0.
    fn clear(&mut self, count: usize) {
        for a in [
            &mut self.px,
            &mut self.py,
            &mut self.vx,
            &mut self.vy,
            &mut self.tx,
            &mut self.ty,
        ] {
            a.clear();
            a.resize(count, 0.0);
        }
    }

    fn set(&mut self, j: usize, position: Vec2, v: Vec2, target: Vec2) {
        (self.px[j], self.py[j]) = (position.x, position.y);
        (self.vx[j], self.vy[j]) = (v.x, v.y);
        (self.tx[j], self.ty[j]) = (target.x, target.y);
    }

    /// One substep of `h` s for every lane: `v += clamp_norm(target − v, m)`, then
    /// `position += v·h`, each value bit for bit as those give it.
    fn step(&mut self, m: Real, h: Real) {
        let count = self.px.len();
        let (px, py) = (&mut self.px[..count], &mut self.py[..count]);
        let (vx, vy) = (&mut self.vx[..count], &mut self.vy[..count]);
        let (tx, ty) = (&self.tx[..count], &self.ty[..count]);
        for j in 0..count {
            let (dx, dy) = (tx[j] - vx[j], ty[j] - vy[j]);
            let n2 = dx * dx + dy * dy;
            // × 1 leaves a value as it is.
            let s = if n2 > m * m { m / n2.sqrt() } else { 1.0 };
            vx[j] += dx * s;
            vy[j] += dy * s;
            px[j] += vx[j] * h;
            py[j] += vy[j] * h;
        }
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
