//! The Social Force Model as PySocialForce 1.1.2 implements it (Helbing & Molnár 1995 with
//! Moussaïd et al.'s 2009 interaction force and 2010 group forces): desired, social, obstacle,
//! group coherence, group repulsion and group gaze forces, and its velocity update.
//!
//! One implementation serves the simulated humans ([`Crowd`], used by world-sim) and the
//! Social Force planner ([`SocialForceAgent`]). The arithmetic follows PySocialForce's, quirks
//! included, because trajectories are cross-checked against it:
//! - the interaction angle θ is the plain difference of two `atan2` angles, not wrapped;
//! - walls act through points sampled along them (`resolution` per metre, end points
//!   included), each point within range pushing on its own;
//! - the desired force pulls towards `max_speed` (1.3 × the initial speed by default);
//! - an agent closer than 0.5 m to its goal stops.

use crate::grid::PointGrid;
use crate::map::StaticMap;
use crate::math::{Real, Vec2, angle_of, left_normal, vec2};
use crate::model::{EgoState, Neighbour};

/// `[desired_force]`
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DesiredForceParams {
    /// Weight.
    pub factor: Real,
    /// Relaxation time (s).
    pub relaxation_time: Real,
    /// Closer than this to the goal (m), the force only brakes.
    pub goal_threshold: Real,
}

/// `[social_force]`: Moussaïd et al. 2009.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SocialForceParams {
    /// A: weight.
    pub factor: Real,
    /// λ: weight of the relative velocity in the interaction direction.
    pub lambda_importance: Real,
    /// γ: B = γ·‖D‖.
    pub gamma: Real,
    /// n: angular decay of the sideways force.
    pub n: Real,
    /// n′: angular decay of the deceleration force.
    pub n_prime: Real,
}

/// `[obstacle_force]`
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObstacleForceParams {
    /// Weight.
    pub factor: Real,
    /// Decay length (m).
    pub sigma: Real,
    /// Range beyond the body radius (m).
    pub threshold: Real,
}

/// `[group_repulsive_force]`
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GroupRepulsiveParams {
    /// Weight.
    pub factor: Real,
    /// Members closer than this push apart (m).
    pub threshold: Real,
}

/// All of PySocialForce's parameters; `Default` is what PySocialForce 1.1.2 uses with its
/// `default.toml`, except `step_width`. (Its `PedState` reads `step_width`, `agent_radius` and
/// `max_speed_multiplier` from the top level of the config while `default.toml` puts them
/// under `[scene]`, so its effective step is the code default of 0.4 s; ours is the
/// simulation step, 0.1 s by default.)
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SfParams {
    /// Integration step (s).
    pub step_width: Real,
    /// Body radius used by the obstacle force (m).
    pub agent_radius: Real,
    /// Maximum speed = this × initial (preferred) speed.
    pub max_speed_multiplier: Real,
    /// Obstacle sampling points per metre.
    pub resolution: Real,
    /// Whether the three group forces act.
    pub enable_group: bool,
    /// Desired force.
    pub desired: DesiredForceParams,
    /// Pedestrian interaction force.
    pub social: SocialForceParams,
    /// Obstacle force.
    pub obstacle: ObstacleForceParams,
    /// Group coherence weight (alternative, pedsim_ros form).
    pub group_coherence_factor: Real,
    /// Group repulsion.
    pub group_repulsive: GroupRepulsiveParams,
    /// Group gaze weight (alternative form).
    pub group_gaze_factor: Real,
    /// An agent closer than this to its goal stops (m).
    pub arrival_distance: Real,
    /// `None`: every pair interacts, as in PySocialForce (O(N²)). `Some(r)`: only pairs
    /// closer than r (m), found through a grid (O(N)); for large crowds. Not a PySocialForce
    /// parameter.
    pub interaction_range: Option<Real>,
}

impl Default for SfParams {
    fn default() -> Self {
        Self {
            step_width: 0.1,
            agent_radius: 0.35,
            max_speed_multiplier: 1.3,
            resolution: 10.0,
            enable_group: true,
            desired: DesiredForceParams {
                factor: 1.0,
                relaxation_time: 0.5,
                goal_threshold: 0.2,
            },
            social: SocialForceParams {
                factor: 5.1,
                lambda_importance: 2.0,
                gamma: 0.35,
                n: 2.0,
                n_prime: 3.0,
            },
            obstacle: ObstacleForceParams {
                factor: 10.0,
                sigma: 0.2,
                threshold: 3.0,
            },
            // PySocialForce looks a force's section up by its class name: the Alt group forces
            // it uses read `[group_coherence_force_alt]` and `[group_gaze_force_alt]`, which
            // default.toml does not have, so they act with factor 1.0, not its 3.0 and 4.0.
            group_coherence_factor: 1.0,
            group_repulsive: GroupRepulsiveParams {
                factor: 1.0,
                threshold: 0.55,
            },
            group_gaze_factor: 1.0,
            arrival_distance: 0.5,
            interaction_range: None,
        }
    }
}

/// `stateutils.normalize` for one vector: the unit vector and the norm, zero for zero.
#[inline]
fn normalize(v: Vec2) -> (Vec2, Real) {
    let n = v.norm();
    if n == 0.0 {
        (vec2(0.0, 0.0), 0.0)
    } else {
        (v / n, n)
    }
}

/// `DesiredForce`: relax towards `max_speed` along the direction to `goal`.
#[inline]
pub fn desired_force(
    pos: Vec2,
    vel: Vec2,
    goal: Vec2,
    max_speed: Real,
    p: &DesiredForceParams,
) -> Vec2 {
    let (direction, dist) = normalize(goal - pos);
    let f = if dist > p.goal_threshold {
        direction * max_speed - vel
    } else {
        -vel
    };
    f / p.relaxation_time * p.factor
}

/// `SocialForce` exerted on `a` by `b` (without the overall factor).
#[inline]
pub fn social_force_pair(
    pos_a: Vec2,
    vel_a: Vec2,
    pos_b: Vec2,
    vel_b: Vec2,
    p: &SocialForceParams,
) -> Vec2 {
    let (diff_direction, diff_length) = normalize(pos_a - pos_b);
    let vel_diff = vel_b - vel_a;
    let (interaction_direction, interaction_length) =
        normalize(vel_diff * p.lambda_importance + diff_direction);
    let b = p.gamma * interaction_length;
    if b == 0.0 {
        // PySocialForce divides by B = 0 here; numpy's exp(−inf) makes the force zero.
        return vec2(0.0, 0.0);
    }
    // Not wrapped into (−π, π], as in PySocialForce.
    let theta = angle_of(&interaction_direction) - angle_of(&diff_direction);
    let velocity_amount = (-diff_length / b - (p.n_prime * b * theta).powi(2)).exp();
    let sign = if theta > 0.0 {
        1.0
    } else if theta < 0.0 {
        -1.0
    } else {
        0.0
    };
    let angle_amount = -sign * (-diff_length / b - (p.n * b * theta).powi(2)).exp();
    interaction_direction * velocity_amount + left_normal(&interaction_direction) * angle_amount
}

/// Wall points as PySocialForce samples them: `int(length · resolution)` points from start to
/// end inclusive, per obstacle line. Optionally indexed by a grid ([`indexed`](Self::indexed))
/// so that the obstacle force visits only nearby points; the result is bit-identical to the
/// full scan (same points, same order).
#[derive(Debug, Clone, Default)]
pub struct ObstaclePoints {
    points: Vec<Vec2>,
    /// Cell side and grid, when indexed.
    grid: Option<(Real, PointGrid)>,
}

impl PartialEq for ObstaclePoints {
    fn eq(&self, other: &Self) -> bool {
        self.points == other.points
    }
}

impl ObstaclePoints {
    /// Samples the given lines.
    pub fn from_segments(
        segments: impl IntoIterator<Item = (Vec2, Vec2)>,
        resolution: Real,
    ) -> Self {
        let mut points = Vec::new();
        for (a, b) in segments {
            let samples = ((b - a).norm() * resolution) as usize;
            match samples {
                0 => {}
                1 => points.push(a),
                _ => points.extend(
                    (0..samples).map(|i| a + (b - a) * (i as Real / (samples - 1) as Real)),
                ),
            }
        }
        Self { points, grid: None }
    }

    /// Points given directly (tests, hand-made scenes).
    pub fn from_points(points: Vec<Vec2>) -> Self {
        Self { points, grid: None }
    }

    /// Indexes the points in a grid of cell side `reach`: forces on bodies for which a point
    /// acts only within `reach` of their centre (PySocialForce's test is
    /// `‖pos − o‖ − r < threshold + r`, so that is `threshold + 2r`) then visit only the 3 × 3
    /// cells around the body instead of every point of the map.
    pub fn indexed(mut self, reach: Real) -> Self {
        let mut grid = PointGrid::default();
        grid.build(&self.points, reach);
        self.grid = Some((reach, grid));
        self
    }

    /// Samples every wall and polygon edge of a map.
    pub fn from_map(map: &StaticMap, resolution: Real) -> Self {
        Self::from_segments(map.boundary_segments(), resolution)
    }

    /// The sampled points.
    pub fn points(&self) -> &[Vec2] {
        &self.points
    }
}

thread_local! {
    /// Candidate wall points of one obstacle-force query, reused between queries.
    static NEAR: std::cell::RefCell<Vec<u32>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// `ObstacleForce` on a body at `pos`.
pub fn obstacle_force(
    pos: Vec2,
    obstacles: &ObstaclePoints,
    radius: Real,
    p: &ObstacleForceParams,
) -> Vec2 {
    let threshold = p.threshold + radius;
    let points = &obstacles.points;
    let mut force = vec2(0.0, 0.0);
    let mut add = |o: &Vec2| {
        let (direction, norm) = normalize(pos - o);
        let dist = norm - radius;
        if dist < threshold {
            force += direction * (-dist / p.sigma).exp();
        }
    };
    match &obstacles.grid {
        // Every point that acts (centre distance < threshold + radius) lies in the 3 × 3 cells
        // around `pos`; visiting those candidates in index order adds exactly what the full
        // scan adds, in its order.
        Some((reach, grid)) if threshold + radius <= *reach => NEAR.with_borrow_mut(|near| {
            near.clear();
            grid.for_each_near(pos, |i| near.push(i as u32));
            near.sort_unstable();
            for &i in near.iter() {
                add(&points[i as usize]);
            }
        }),
        _ => points.iter().for_each(add),
    }
    force * p.factor
}

/// `PedState.capped_velocity` for one agent.
#[inline]
pub fn capped_velocity(desired: Vec2, max_speed: Real) -> Vec2 {
    let speed = desired.norm();
    if speed == 0.0 {
        return vec2(0.0, 0.0);
    }
    desired * (max_speed / speed).min(1.0)
}

/// A crowd simulated exactly as PySocialForce's `Simulator` does.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Crowd {
    /// Positions (m).
    pub positions: Vec<Vec2>,
    /// Velocities (m/s).
    pub velocities: Vec<Vec2>,
    /// Goals.
    pub goals: Vec<Vec2>,
    /// Maximum speeds (m/s): 1.3 × the initial speeds in PySocialForce.
    pub max_speeds: Vec<Real>,
    /// Groups of member indices.
    pub groups: Vec<Vec<usize>>,
}

impl Crowd {
    /// A crowd whose maximum speeds derive from the initial velocities, as in PySocialForce.
    pub fn new(
        positions: Vec<Vec2>,
        velocities: Vec<Vec2>,
        goals: Vec<Vec2>,
        groups: Vec<Vec<usize>>,
        p: &SfParams,
    ) -> Self {
        let max_speeds = velocities
            .iter()
            .map(|v| v.norm() * p.max_speed_multiplier)
            .collect();
        Self {
            positions,
            velocities,
            goals,
            max_speeds,
            groups,
        }
    }

    /// Number of agents.
    pub fn len(&self) -> usize {
        self.positions.len()
    }

    /// True for an empty crowd.
    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }

    /// Sum of all forces on every agent (`Simulator.compute_forces`).
    pub fn forces(&self, obstacles: &ObstaclePoints, p: &SfParams, out: &mut Vec<Vec2>) {
        self.forces_with_externals(obstacles, p, &[], out);
    }

    /// As [`Crowd::forces`], with `externals` (position, velocity) pushing on every agent as
    /// further pedestrians would, without being moved themselves: how simulated people react
    /// to robots.
    pub fn forces_with_externals(
        &self,
        obstacles: &ObstaclePoints,
        p: &SfParams,
        externals: &[(Vec2, Vec2)],
        out: &mut Vec<Vec2>,
    ) {
        let n = self.len();
        out.clear();
        out.resize(n, vec2(0.0, 0.0));
        let mut grid = PointGrid::default();
        if let Some(range) = p.interaction_range {
            grid.build(&self.positions, range);
        }
        for (a, force) in out.iter_mut().enumerate() {
            let (pa, va) = (self.positions[a], self.velocities[a]);
            let mut social = vec2(0.0, 0.0);
            let mut add = |pb: Vec2, vb: Vec2| {
                if p.interaction_range
                    .is_none_or(|r| (pb - pa).norm_squared() < r * r)
                {
                    social += social_force_pair(pa, va, pb, vb, &p.social);
                }
            };
            match p.interaction_range {
                None => (0..n)
                    .filter(|&b| b != a)
                    .for_each(|b| add(self.positions[b], self.velocities[b])),
                Some(_) => grid.for_each_near(pa, |b| {
                    if b != a {
                        add(self.positions[b], self.velocities[b]);
                    }
                }),
            }
            for (pb, vb) in externals {
                add(*pb, *vb);
            }
            *force = desired_force(pa, va, self.goals[a], self.max_speeds[a], &p.desired)
                + social * p.social.factor
                + obstacle_force(pa, obstacles, p.agent_radius, &p.obstacle);
        }
        if p.enable_group {
            self.add_group_forces(p, out);
        }
    }

    fn add_group_forces(&self, p: &SfParams, out: &mut [Vec2]) {
        for group in &self.groups {
            let size = group.len();
            if size == 0 {
                continue;
            }
            let com = group.iter().map(|&i| self.positions[i]).sum::<Vec2>() / size as Real;
            // GroupCoherenceForceAlt: pull towards the centre of mass, softened by
            // (tanh(‖v‖ − threshold) + 1) / 2, except that PySocialForce measures ‖v‖ with
            // `stateutils.speeds`, which reads columns 2..4 of the 2-column array: always 0.
            let threshold = (size as Real - 1.0) / 2.0;
            let softened = ((-threshold).tanh() + 1.0) / 2.0;
            for &i in group {
                let v = com - self.positions[i];
                out[i] += v * softened * p.group_coherence_factor;
            }
            // GroupRepulsiveForce: members closer than the threshold push apart.
            for &i in group {
                let mut f = vec2(0.0, 0.0);
                for &j in group.iter().filter(|&&j| j != i) {
                    let d = self.positions[i] - self.positions[j];
                    if d.norm() <= p.group_repulsive.threshold {
                        f += d;
                    }
                }
                out[i] += f * p.group_repulsive.factor;
            }
            // GroupGazeForceAlt: turn towards the others' centre of mass.
            if size > 1 {
                for &i in group {
                    let others_com = group
                        .iter()
                        .filter(|&&j| j != i)
                        .map(|&j| self.positions[j])
                        .sum::<Vec2>()
                        / (size - 1) as Real;
                    let (com_direction, com_dist) = normalize(others_com - self.positions[i]);
                    let (direction, goal_dist) = normalize(self.goals[i] - self.positions[i]);
                    let element_prod = direction.dot(&com_direction);
                    out[i] +=
                        direction * (com_dist * element_prod / goal_dist) * p.group_gaze_factor;
                }
            }
        }
    }

    /// One `Simulator.step_once`: Euler step of the velocity, capped, zero near the goal.
    pub fn step(&mut self, obstacles: &ObstaclePoints, p: &SfParams, scratch: &mut Vec<Vec2>) {
        self.step_with_externals(obstacles, p, &[], scratch);
    }

    /// [`Crowd::step`] with external agents pushing (see [`Crowd::forces_with_externals`]).
    pub fn step_with_externals(
        &mut self,
        obstacles: &ObstaclePoints,
        p: &SfParams,
        externals: &[(Vec2, Vec2)],
        scratch: &mut Vec<Vec2>,
    ) {
        self.forces_with_externals(obstacles, p, externals, scratch);
        for (i, force) in scratch.iter().enumerate() {
            let mut v = capped_velocity(
                self.velocities[i] + force * p.step_width,
                self.max_speeds[i],
            );
            if (self.goals[i] - self.positions[i]).norm() < p.arrival_distance {
                v = vec2(0.0, 0.0);
            }
            self.positions[i] += v * p.step_width;
            self.velocities[i] = v;
        }
    }
}

/// The Social Force planner's parameters; `Default` is the PGP paper's Table I
/// (v^max = 1 m/s, A = 5.1, λ = 3.0, γ = 0.35, n = 1, n′ = 3.0) on PySocialForce's other
/// defaults.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SfAgentParams {
    /// Force model parameters (groups are not used by the planner).
    pub model: SfParams,
    /// v^max (m/s): the desired force pulls towards it and the velocity is capped at it.
    pub max_speed: Real,
}

impl Default for SfAgentParams {
    fn default() -> Self {
        let model = SfParams {
            social: SocialForceParams {
                factor: 5.1,
                lambda_importance: 3.0,
                gamma: 0.35,
                n: 1.0,
                n_prime: 3.0,
            },
            enable_group: false,
            ..SfParams::default()
        };
        Self {
            model,
            max_speed: 1.0,
        }
    }
}

/// A robot that moves like a Social Force pedestrian: one force evaluation per plan.
#[derive(Debug, Clone)]
pub struct SocialForceAgent {
    params: SfAgentParams,
}

impl SocialForceAgent {
    /// A planner with the given parameters.
    pub fn new(params: SfAgentParams) -> Self {
        Self { params }
    }

    /// The parameters in use.
    pub fn params(&self) -> &SfAgentParams {
        &self.params
    }

    /// The total force on the ego driving towards `target`.
    pub fn force(
        &mut self,
        ego: &EgoState,
        neighbours: &[Neighbour],
        map: &StaticMap,
        target: Vec2,
    ) -> Vec2 {
        let m = &self.params.model;
        let mut social = vec2(0.0, 0.0);
        for nb in neighbours {
            social += social_force_pair(
                ego.position,
                ego.velocity,
                nb.position,
                nb.velocity,
                &m.social,
            );
        }
        let points = map.sampled_points(m.resolution);
        desired_force(
            ego.position,
            ego.velocity,
            target,
            self.params.max_speed,
            &m.desired,
        ) + social * m.social.factor
            + obstacle_force(ego.position, &points, ego.radius, &m.obstacle)
    }

    /// The velocity command: v + dt·F, capped at v^max, zero within the arrival distance.
    pub fn command(
        &mut self,
        ego: &EgoState,
        neighbours: &[Neighbour],
        map: &StaticMap,
        target: Vec2,
        dt: Real,
    ) -> Vec2 {
        if (target - ego.position).norm() < self.params.model.arrival_distance {
            return vec2(0.0, 0.0);
        }
        let f = self.force(ego, neighbours, map, target);
        capped_velocity(ego.velocity + f * dt, self.params.max_speed)
    }
}
#[cfg(test)]
mod tests;

#[cfg(test)]
mod range_tests {
    use super::*;

    /// With a range longer than the stage, the grid path gives PySocialForce's all-pairs sums
    /// up to summation order.
    #[test]
    fn long_range_grid_matches_all_pairs() {
        let p = SfParams::default();
        let positions: Vec<Vec2> = (0..30)
            .map(|i| vec2((i % 6) as Real * 0.9, (i / 6) as Real * 1.1))
            .collect();
        let velocities: Vec<Vec2> = (0..30)
            .map(|i| {
                vec2(
                    ((i * 7) % 5) as Real * 0.2 - 0.4,
                    ((i * 3) % 4) as Real * 0.2 - 0.3,
                )
            })
            .collect();
        let goals: Vec<Vec2> = (0..30)
            .map(|i| vec2(10.0 - (i % 6) as Real, (i / 6) as Real))
            .collect();
        let crowd = Crowd::new(
            positions,
            velocities,
            goals,
            vec![vec![0, 1, 2], vec![3, 4]],
            &p,
        );
        let (mut exact, mut ranged) = (Vec::new(), Vec::new());
        crowd.forces(&ObstaclePoints::default(), &p, &mut exact);
        let far = SfParams {
            interaction_range: Some(100.0),
            ..p
        };
        crowd.forces(&ObstaclePoints::default(), &far, &mut ranged);
        for (e, r) in exact.iter().zip(&ranged) {
            assert!((e - r).norm() < 1e-12);
        }
        // A short range drops distant pairs, so some force must change.
        let near = SfParams {
            interaction_range: Some(1.0),
            ..p
        };
        crowd.forces(&ObstaclePoints::default(), &near, &mut ranged);
        assert!(
            exact
                .iter()
                .zip(&ranged)
                .any(|(e, r)| (e - r).norm() > 1e-9)
        );
    }
}
