//! The desired velocity of Sec. III-D2: the robot and the tracked bodies rolled out with the
//! Social Force Model over H steps, the objective J = J_t + P_v + P_d (Eqs. 15–19), and its
//! minimisation over the H desired velocities with argmin's L-BFGS and a Moré–Thuente line
//! search. (A backtracking Armijo search needs half the rollouts, but in the paper's experiment
//! its solutions reach the goal in 61–77 % of runs instead of 93–99 %: measured in session 14.)

use super::AsfmParams;
use super::model::{attraction, desired_toward, repulsion, step, unit_repulsion};
use crate::fastmath::exp;
use crate::math::{Real, Vec2, clamp_norm, closest_on_segment, vec2};
use argmin::core::{CostFunction, Error, Executor, Gradient, State};
use argmin::solver::linesearch::MoreThuenteLineSearch;
use argmin::solver::quasinewton::LBFGS;
use std::cell::RefCell;

/// A tracked body in the rollout.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Body {
    /// r̂_o (filtered).
    pub position: Vec2,
    /// v̂_o.
    pub velocity: Vec2,
    /// Radius (m); 0 for the paper's point bodies.
    pub radius: Real,
    /// Â_o.
    pub strength: Real,
    /// A known goal (Eq. 5 at `people_speed`), else the intended velocity below.
    pub goal: Option<Vec2>,
    /// v⁰_o when no goal is known.
    pub intended: Vec2,
}

/// What the rollout starts from.
#[derive(Debug, Clone, Default)]
pub struct Scene {
    /// The robot's position, velocity and radius.
    pub robot: (Vec2, Vec2, Real),
    /// Its goal.
    pub goal: Vec2,
    /// The bodies it tracks (the nearest, at most the params' `rollout_bodies`).
    pub bodies: Vec<Body>,
    /// Wall and shelf segments near the robot.
    pub walls: Vec<(Vec2, Vec2)>,
}

/// The robot's repulsion from walls: Eq. 3 from the nearest point of each segment, with the
/// robot's strength A_r and range B ("for static obstacles, we only employ (3)").
pub fn wall_push(position: Vec2, radius: Real, walls: &[(Vec2, Vec2)], p: &AsfmParams) -> Vec2 {
    let mut f = vec2(0.0, 0.0);
    for &(a, b) in walls {
        let d = position - closest_on_segment(a, b, position);
        if d.norm() < p.wall_reach {
            f += repulsion(d, radius, p.robot_strength, p.range);
        }
    }
    f
}

/// The desired velocity the free parameter `u` stands for: v^max·u/√(1 + ‖u‖²), inside the
/// disc of radius v^max (smooth, so the gradient is defined everywhere).
#[inline]
pub fn squash(u: Vec2, v_max: Real) -> Vec2 {
    u * (v_max / (1.0 + u.norm_squared()).sqrt())
}

/// The inverse of [`squash`] for a desired velocity `v` (its speed capped at 0.99·v^max).
pub fn unsquash(v: Vec2, v_max: Real) -> Vec2 {
    let v = clamp_norm(v, 0.99 * v_max) / v_max;
    v / (1.0 - v.norm_squared()).sqrt()
}

/// The state of the rollout after each step, and the cost accumulated up to it.
#[derive(Debug, Clone, Default)]
struct Rollout {
    /// Per step k = 0..=H: robot position and velocity.
    robot: Vec<(Vec2, Vec2)>,
    /// Per step: each body's position and velocity (k·n + i).
    bodies: Vec<(Vec2, Vec2)>,
    /// Cost of steps 1..=k (P_v, P_d and the arrival term of J_t).
    running: Vec<Real>,
}

/// The terms of J for one sequence.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Terms {
    /// J_t (Eq. 16).
    pub time: Real,
    /// P_v (Eq. 18).
    pub speed: Real,
    /// P_d (Eq. 19).
    pub distance: Real,
}

impl Terms {
    /// J (Eq. 15).
    pub fn total(&self) -> Real {
        self.time + self.speed + self.distance
    }
}

/// V(v, g, r) of Eq. 17.
#[inline]
fn toward(v: Vec2, g: Vec2, r: Vec2, eps: Real) -> Real {
    let to = g - r;
    v.dot(&to) / (to.norm() + eps)
}

/// The objective over the free parameters (2·H numbers), for argmin.
#[derive(Debug)]
pub struct Objective<'a> {
    scene: &'a Scene,
    p: &'a AsfmParams,
    base: RefCell<Rollout>,
    scratch: RefCell<Rollout>,
}

impl<'a> Objective<'a> {
    /// J for `scene` under `p`.
    pub fn new(scene: &'a Scene, p: &'a AsfmParams) -> Self {
        Self {
            scene,
            p,
            base: RefCell::new(Rollout::default()),
            scratch: RefCell::new(Rollout::default()),
        }
    }

    /// Rolls out from step `from` (the states up to it and the running cost up to it already
    /// in `r`) and returns J.
    fn roll(&self, u: &[Real], from: usize, r: &mut Rollout) -> Real {
        let p = self.p;
        let s = self.scene;
        let h = p.horizon;
        let n = s.bodies.len();
        let radius = s.robot.2;
        if from == 0 {
            r.robot.clear();
            r.robot.push((s.robot.0, s.robot.1));
            r.bodies.clear();
            r.bodies
                .extend(s.bodies.iter().map(|b| (b.position, b.velocity)));
            r.running.clear();
            r.running.push(0.0);
        }
        let mut running = r.running[from];
        for k in from..h {
            let (pos, vel) = r.robot[k];
            let desired = squash(vec2(u[2 * k], u[2 * k + 1]), p.v_max);
            // Eq. 2 on the robot: Eq. 3 from every body and wall, Eq. 4 toward v⁰_k.
            let mut a = attraction(desired, vel, p.tau) + wall_push(pos, radius, &s.walls, p);
            for (i, b) in s.bodies.iter().enumerate() {
                let (bp, bv) = r.bodies[k * n + i];
                // Eq. 3 both ways: one decay, the robot's A_r and the body's Â_o.
                let push = unit_repulsion(pos - bp, radius + b.radius, p.range);
                a += push * p.robot_strength;
                // The body: Eq. 3 from the robot with Â_o, Eq. 4 toward Eq. 5 or its intent.
                let desired = match b.goal {
                    Some(g) => desired_toward(g, bp, p.people_speed),
                    None => b.intended,
                };
                let ab = attraction(desired, bv, p.tau) - push * b.strength;
                r.bodies.push(step(bp, bv, ab, p.dt));
            }
            let (np, nv) = step(pos, vel, a, p.dt);
            let nv = clamp_norm(nv, p.v_max);
            r.robot.push((np, nv));
            running += self.step_cost(np, nv, &r.bodies[(k + 1) * n..]);
            r.running.push(running);
        }
        let (end, vend) = r.robot[h];
        running + self.time_to_go(end, vend)
    }

    /// Step i's share of J: its P_v and P_d terms, and Δt·I(g ≠ r) of J_t.
    fn step_cost(&self, at: Vec2, v: Vec2, bodies: &[(Vec2, Vec2)]) -> Real {
        let t = self.step_terms(at, v, bodies);
        t.speed + t.distance + t.time
    }

    fn step_terms(&self, at: Vec2, v: Vec2, bodies: &[(Vec2, Vec2)]) -> Terms {
        let p = self.p;
        let s = self.scene;
        let radius = s.robot.2;
        let mut distance = 0.0;
        for (b, (q, _)) in s.bodies.iter().zip(bodies) {
            let gap = (at - q).norm() - (radius + b.radius);
            distance += p.distance_weight * exp(p.distance_sharpness * (p.d_min - gap));
        }
        Terms {
            // I(g ≠ r): "at the goal" is within the goal tolerance.
            time: if (s.goal - at).norm() > p.goal_tolerance {
                p.dt
            } else {
                0.0
            },
            speed: p.v_max - toward(v, s.goal, at, p.epsilon),
            distance,
        }
    }

    /// J_t's first term: |‖g − r‖ / (V + ε)| at the horizon's end.
    fn time_to_go(&self, end: Vec2, v: Vec2) -> Real {
        let p = self.p;
        let g = self.scene.goal;
        ((g - end).norm() / (toward(v, g, end, p.epsilon) + p.epsilon)).abs()
    }

    /// J's terms for `u` and the robot's rolled-out positions (steps 0..=H).
    pub fn terms(&self, u: &[Real]) -> (Terms, Vec<Vec2>) {
        let mut r = Rollout::default();
        self.roll(u, 0, &mut r);
        let n = self.scene.bodies.len();
        let mut t = Terms::default();
        for k in 1..=self.p.horizon {
            let (at, v) = r.robot[k];
            let step = self.step_terms(at, v, &r.bodies[k * n..(k + 1) * n]);
            t.time += step.time;
            t.speed += step.speed;
            t.distance += step.distance;
        }
        let (end, vend) = r.robot[self.p.horizon];
        t.time += self.time_to_go(end, vend);
        (t, r.robot.iter().map(|(q, _)| *q).collect())
    }
}

impl CostFunction for Objective<'_> {
    type Param = Vec<Real>;
    type Output = Real;

    fn cost(&self, u: &Self::Param) -> Result<Real, Error> {
        let mut base = self.base.borrow_mut();
        Ok(self.roll(u, 0, &mut base))
    }
}

impl Gradient for Objective<'_> {
    type Param = Vec<Real>;
    type Gradient = Vec<Real>;

    /// Forward differences. Desired velocity k only moves steps after k, so each perturbed
    /// rollout starts from the base rollout's state at step k.
    fn gradient(&self, u: &Self::Param) -> Result<Vec<Real>, Error> {
        let mut base = self.base.borrow_mut();
        let mut scratch = self.scratch.borrow_mut();
        let f0 = self.roll(u, 0, &mut base);
        let mut x = u.clone();
        let mut g = vec![0.0; u.len()];
        for j in 0..u.len() {
            let k = j / 2;
            scratch.robot.clear();
            scratch.robot.extend_from_slice(&base.robot[..=k]);
            let n = self.scene.bodies.len();
            scratch.bodies.clear();
            scratch
                .bodies
                .extend_from_slice(&base.bodies[..(k + 1) * n]);
            scratch.running.clear();
            scratch.running.extend_from_slice(&base.running[..=k]);
            let h = self.p.gradient_step * (1.0 + x[j].abs());
            let keep = x[j];
            x[j] = keep + h;
            let f = self.roll(&x, k, &mut scratch);
            x[j] = keep;
            g[j] = (f - f0) / h;
        }
        Ok(g)
    }
}

/// The result of one optimisation.
#[derive(Debug, Clone, PartialEq)]
pub struct Solution {
    /// The H desired velocities.
    pub desired: Vec<Vec2>,
    /// Their J's terms.
    pub terms: Terms,
    /// The robot's rolled-out positions, steps 0..=H.
    pub path: Vec<Vec2>,
    /// Iterations the optimiser ran.
    pub iterations: u64,
}

/// Minimises J over the desired velocities, from `start` (H of them).
pub fn optimise(scene: &Scene, start: &[Vec2], p: &AsfmParams) -> Solution {
    let objective = Objective::new(scene, p);
    let init: Vec<Real> = start
        .iter()
        .flat_map(|v| {
            let u = unsquash(*v, p.v_max);
            [u.x, u.y]
        })
        .collect();
    let f_init = objective.cost(&init).unwrap_or(Real::INFINITY);
    let linesearch = MoreThuenteLineSearch::new();
    let solver = LBFGS::new(linesearch, p.lbfgs_memory);
    let result = Executor::new(&objective, solver)
        .configure(|state| state.param(init.clone()).max_iters(p.max_iters))
        .run();
    // The optimiser's best, unless it failed or did worse than the start (then the start).
    let (best, iterations) = match &result {
        Ok(r) => {
            let state = r.state();
            let better = state.get_best_cost() < f_init;
            match state.get_best_param() {
                Some(b) if better && b.iter().all(|x| x.is_finite()) => {
                    (b.clone(), state.get_iter())
                }
                _ => (init, state.get_iter()),
            }
        }
        Err(_) => (init, 0),
    };
    let desired: Vec<Vec2> = best
        .chunks_exact(2)
        .map(|c| squash(vec2(c[0], c[1]), p.v_max))
        .collect();
    let (terms, path) = objective.terms(&best);
    Solution {
        desired,
        terms,
        path,
        iterations,
    }
}

impl CostFunction for &Objective<'_> {
    type Param = Vec<Real>;
    type Output = Real;

    fn cost(&self, u: &Self::Param) -> Result<Real, Error> {
        (*self).cost(u)
    }
}

impl Gradient for &Objective<'_> {
    type Param = Vec<Real>;
    type Gradient = Vec<Real>;

    fn gradient(&self, u: &Self::Param) -> Result<Vec<Real>, Error> {
        (*self).gradient(u)
    }
}
