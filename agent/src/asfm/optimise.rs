//! The desired velocity of Sec. III-D2: the robot and the tracked bodies rolled out with the
//! Social Force Model over H steps, the objective J = J_t + P_v + P_d (Eqs. 15–19), and its
//! minimisation over the H desired velocities with argmin's L-BFGS and a Moré–Thuente line
//! search. The gradient is the rollout's adjoint (one backward sweep, checked against central
//! differences in the tests): forward differences cost 2·H partial rollouts. (A backtracking Armijo search needs half the rollouts, but in the paper's experiment
//! its solutions reach the goal in 61–77 % of runs instead of 93–99 %, measured.)

use super::model::{attraction, desired_toward, repulsion, step};
use super::{AsfmParams, TimeToGo};
use crate::fastmath::exp;
use crate::math::{Real, Vec2, clamp_norm, closest_on_segment, vec2};
use nalgebra::Matrix2;

type Mat2 = Matrix2<Real>;
use argmin::core::{CostFunction, Error, Executor, Gradient, State};
use argmin::solver::linesearch::MoreThuenteLineSearch;
use argmin::solver::quasinewton::LBFGS;
use std::cell::RefCell;
use std::f64::consts::{FRAC_PI_2, FRAC_PI_3, FRAC_PI_4, FRAC_PI_6, PI};

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
/// walls' strength (A_r in the paper: "for static obstacles, we only employ (3)") and range B.
pub fn wall_push(position: Vec2, radius: Real, walls: &[(Vec2, Vec2)], p: &AsfmParams) -> Vec2 {
    let strength = p.wall_strength();
    let mut f = vec2(0.0, 0.0);
    for &(a, b) in walls {
        let d = position - closest_on_segment(a, b, position);
        if d.norm() < p.wall_reach {
            f += repulsion(d, radius, strength, p.range);
        }
    }
    f
}

/// [`wall_push`] and its Jacobian ∂f/∂r: A_w·∂U/∂d·(I − t̂t̂ᵀ) for a nearest point inside a
/// segment (it slides along it as r moves), A_w·∂U/∂d for one at an end (A_w the walls' strength).
fn wall_push_and_jacobian(
    position: Vec2,
    radius: Real,
    walls: &[(Vec2, Vec2)],
    p: &AsfmParams,
) -> (Vec2, Mat2) {
    let mut f = vec2(0.0, 0.0);
    let mut jacobian = Mat2::zeros();
    let strength = p.wall_strength();
    for &(a, b) in walls {
        let d = position - closest_on_segment(a, b, position);
        let norm = d.norm();
        if norm < p.wall_reach {
            f += repulsion(d, radius, strength, p.range);
            if norm > 0.0 {
                let decay = exp(-(norm - radius) / p.range);
                let mut jac = unit_repulsion_jacobian(d, decay, p.range) * strength;
                let e = b - a;
                let len_sq = e.norm_squared();
                let along = if len_sq > 0.0 {
                    (position - a).dot(&e) / len_sq
                } else {
                    0.0
                };
                if along > 0.0 && along < 1.0 {
                    let t = e / len_sq.sqrt();
                    jac -= (jac * t) * t.transpose();
                }
                jacobian += jac;
            }
        }
    }
    (f, jacobian)
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

/// One rollout: the state after each step, and what the adjoint sweep needs of it.
#[derive(Debug, Clone, Default)]
struct Rollout {
    /// The free parameters it rolled out, and their J.
    u: Vec<Real>,
    cost: Real,
    /// Per step k = 0..=H: robot position and velocity.
    robot: Vec<(Vec2, Vec2)>,
    /// Per step: each body's position and velocity (k·n + i).
    bodies: Vec<(Vec2, Vec2)>,
    /// Per step k < H: the robot's velocity before the speed clamp.
    free: Vec<Vec2>,
    /// Per step k < H: ∂(wall push)/∂r of the robot at step k.
    wall_jacobian: Vec<Mat2>,
    /// Per step k < H and body i: Eq. 3's decay e^{−(‖d‖ − radii)/B} between them (k·n + i).
    decay: Vec<Real>,
    /// Per step k < H and body i: its P_d term on the state after step k (k·n + i).
    near: Vec<Real>,
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
}

impl<'a> Objective<'a> {
    /// J for `scene` under `p`.
    pub fn new(scene: &'a Scene, p: &'a AsfmParams) -> Self {
        Self {
            scene,
            p,
            base: RefCell::new(Rollout::default()),
        }
    }

    /// Rolls `u` out into `r` and returns J.
    fn roll(&self, u: &[Real], r: &mut Rollout) -> Real {
        let p = self.p;
        let s = self.scene;
        let h = p.horizon;
        let n = s.bodies.len();
        let radius = s.robot.2;
        r.u.clear();
        r.u.extend_from_slice(u);
        r.robot.clear();
        r.robot.push((s.robot.0, s.robot.1));
        r.bodies.clear();
        r.bodies
            .extend(s.bodies.iter().map(|b| (b.position, b.velocity)));
        r.free.clear();
        r.wall_jacobian.clear();
        r.decay.clear();
        r.near.clear();
        let mut running = 0.0;
        for k in 0..h {
            let (pos, vel) = r.robot[k];
            let desired = squash(vec2(u[2 * k], u[2 * k + 1]), p.v_max);
            // Eq. 2 on the robot: Eq. 3 from every body and wall, Eq. 4 toward v⁰_k.
            let (walls, wall_jacobian) = wall_push_and_jacobian(pos, radius, &s.walls, p);
            r.wall_jacobian.push(wall_jacobian);
            let mut a = attraction(desired, vel, p.tau) + walls;
            for (i, b) in s.bodies.iter().enumerate() {
                let (bp, bv) = r.bodies[k * n + i];
                // Eq. 3 both ways: one decay, the robot's A_r and the body's Â_o.
                let d = pos - bp;
                let norm = d.norm();
                let (push, decay) = if norm == 0.0 {
                    (vec2(0.0, 0.0), 0.0)
                } else {
                    let decay = exp(-(norm - (radius + b.radius)) / p.range);
                    (d * (decay / norm), decay)
                };
                r.decay.push(decay);
                a += push * p.robot_strength;
                // The body: Eq. 3 from the robot with Â_o, Eq. 4 toward Eq. 5 or its intent.
                let desired = match b.goal {
                    Some(g) => desired_toward(g, bp, p.people_speed),
                    None => b.intended,
                };
                let ab = attraction(desired, bv, p.tau) - push * b.strength;
                r.bodies.push(step(bp, bv, ab, p.dt));
            }
            let (np, free) = step(pos, vel, a, p.dt);
            r.free.push(free);
            let nv = clamp_norm(free, p.v_max);
            r.robot.push((np, nv));
            let t = self.step_terms(np, nv, &r.bodies[(k + 1) * n..], &mut r.near);
            running += t.speed + t.distance + t.time;
        }
        let (end, vend) = r.robot[h];
        r.cost = running + self.time_to_go(end, vend);
        r.cost
    }

    /// A step's share of J on the state after it: its P_v and P_d terms, and Δt·I(g ≠ r) of
    /// J_t. Each body's P_d term is pushed onto `near`.
    fn step_terms(
        &self,
        at: Vec2,
        v: Vec2,
        bodies: &[(Vec2, Vec2)],
        near: &mut Vec<Real>,
    ) -> Terms {
        let p = self.p;
        let s = self.scene;
        let radius = s.robot.2;
        let mut distance = 0.0;
        for (b, (q, _)) in s.bodies.iter().zip(bodies) {
            let gap = (at - q).norm() - (radius + b.radius);
            let term = p.distance_weight * exp(p.distance_sharpness * (p.d_min - gap));
            near.push(term);
            distance += term;
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

    /// J_t's first term at the horizon's end: |‖g − r‖ / (V + ε)| (the paper), or
    /// ‖g − r‖ / v^max ([`TimeToGo::AtTopSpeed`]).
    fn time_to_go(&self, end: Vec2, v: Vec2) -> Real {
        let p = self.p;
        let g = self.scene.goal;
        match p.time_to_go {
            TimeToGo::Paper => {
                ((g - end).norm() / (toward(v, g, end, p.epsilon) + p.epsilon)).abs()
            }
            TimeToGo::AtTopSpeed => (g - end).norm() / p.v_max,
        }
    }

    /// J's terms for `u` and the robot's rolled-out positions (steps 0..=H).
    pub fn terms(&self, u: &[Real]) -> (Terms, Vec<Vec2>) {
        let mut r = Rollout::default();
        self.roll(u, &mut r);
        let n = self.scene.bodies.len();
        let mut t = Terms::default();
        let mut near = Vec::new();
        for k in 1..=self.p.horizon {
            let (at, v) = r.robot[k];
            let step = self.step_terms(at, v, &r.bodies[k * n..(k + 1) * n], &mut near);
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
        if base.u == *u {
            return Ok(base.cost);
        }
        Ok(self.roll(u, &mut base))
    }
}

impl Gradient for Objective<'_> {
    type Param = Vec<Real>;
    type Gradient = Vec<Real>;

    /// ∂J/∂u by the adjoint of the rollout: one forward rollout (none when the line search
    /// has just rolled out `u` for its cost), then one backward sweep.
    fn gradient(&self, u: &Self::Param) -> Result<Vec<Real>, Error> {
        let mut base = self.base.borrow_mut();
        if base.u != *u {
            self.roll(u, &mut base);
        }
        Ok(self.adjoint(&base))
    }
}

/// ∂U/∂d of the unit repulsion U(d) = E·d/‖d‖, E = e^{−(‖d‖ − radii)/B} given as `decay`
/// (symmetric): E·[(I − d̂d̂ᵀ)/‖d‖ − d̂d̂ᵀ/B].
#[inline]
fn unit_repulsion_jacobian(d: Vec2, decay: Real, range: Real) -> Mat2 {
    let n = d.norm();
    if n == 0.0 {
        return Mat2::zeros();
    }
    let e = decay;
    let dd = (d / n) * (d / n).transpose();
    (Mat2::identity() - dd) * (e / n) - dd * (e / range)
}

/// ∂V/∂v and ∂V/∂(g − r) of V(v, g, r) of Eq. 17.
#[inline]
fn toward_partials(v: Vec2, g: Vec2, r: Vec2, eps: Real) -> (Vec2, Vec2) {
    let z = g - r;
    let m = z.norm();
    let den = m + eps;
    let dz = if m == 0.0 {
        v / den
    } else {
        v / den - (z / m) * (v.dot(&z) / (den * den))
    };
    (z / den, dz)
}

impl Objective<'_> {
    /// The adjoint sweep over the rollout `r`: λ for each state, from the horizon's end back
    /// to step 0, and ∂J/∂u_k = (∂v⁰_k/∂u_k)ᵀ·λ_a/τ at each step. The indicator of J_t and
    /// the wall reach cut-off are flat almost everywhere; their gradient is 0.
    fn adjoint(&self, r: &Rollout) -> Vec<Real> {
        let p = self.p;
        let s = self.scene;
        let h = p.horizon;
        let n = s.bodies.len();
        let dt = p.dt;
        let half = 0.5 * dt * dt;
        let u = &r.u;
        let mut grad = vec![0.0; 2 * h];
        // J_t's first term, |F| with F = ‖g − r‖/(V + ε).
        let (end, vend) = r.robot[h];
        let (mut lx, mut lv) = if p.time_to_go == TimeToGo::AtTopSpeed {
            let z = s.goal - end;
            let m = z.norm();
            let zhat = if m == 0.0 { vec2(0.0, 0.0) } else { z / m };
            (-zhat / p.v_max, vec2(0.0, 0.0))
        } else {
            let z = s.goal - end;
            let m = z.norm();
            let (dv, dz) = toward_partials(vend, s.goal, end, p.epsilon);
            let den = toward(vend, s.goal, end, p.epsilon) + p.epsilon;
            let sign = if m / den < 0.0 { -1.0 } else { 1.0 };
            let zhat = if m == 0.0 { vec2(0.0, 0.0) } else { z / m };
            let df_dz = zhat / den - dz * (m / (den * den));
            let df_dv = -dv * (m / (den * den));
            (-df_dz * sign, df_dv * sign)
        };
        let mut lq = vec![vec2(0.0, 0.0); n];
        let mut lw = vec![vec2(0.0, 0.0); n];
        for k in (0..h).rev() {
            let (x1, v1) = r.robot[k + 1];
            let next = &r.bodies[(k + 1) * n..(k + 2) * n];
            // Step k's cost, on the state after it: P_v …
            let (dv, dz) = toward_partials(v1, s.goal, x1, p.epsilon);
            lv -= dv;
            lx += dz;
            // … and P_d.
            for (i, &(q1, _)) in next.iter().enumerate() {
                let e = x1 - q1;
                let dist = e.norm();
                if dist > 0.0 {
                    let push = e * (p.distance_sharpness * r.near[k * n + i] / dist);
                    lx -= push;
                    lq[i] += push;
                }
            }
            // Through the robot's step: the speed clamp, then Eq. 1 and Eq. 11.
            let (x0, _) = r.robot[k];
            let free = r.free[k];
            let l_free = if free.norm_squared() > p.v_max * p.v_max {
                let norm = free.norm();
                let fhat = free / norm;
                (lv - fhat * fhat.dot(&lv)) * (p.v_max / norm)
            } else {
                lv
            };
            let la = lx * half + l_free * dt;
            // Eq. 4 and the walls' Eq. 3 on the robot.
            let mut lx0 = lx + r.wall_jacobian[k].transpose() * la;
            let lv0 = lx * dt + l_free - la / p.tau;
            // ∂J/∂u_k through v⁰_k = squash(u_k): v^max/√(1+‖u‖²)·(I − u uᵀ/(1 + ‖u‖²)).
            let uk = vec2(u[2 * k], u[2 * k + 1]);
            let q = 1.0 + uk.norm_squared();
            let ld = la / p.tau;
            let gu = (ld - uk * (uk.dot(&ld) / q)) * (p.v_max / q.sqrt());
            grad[2 * k] = gu.x;
            grad[2 * k + 1] = gu.y;
            // Bodies: their step, Eq. 4 toward Eq. 5 (or their intent), and Eq. 3 both ways.
            let bodies = &r.bodies[k * n..(k + 1) * n];
            for (i, (b, &(q0, _))) in s.bodies.iter().zip(bodies).enumerate() {
                let lab = lq[i] * half + lw[i] * dt;
                let mut lq0 = lq[i];
                lw[i] += lq[i] * dt - lab / p.tau;
                if let Some(g) = b.goal {
                    let to = g - q0;
                    let m = to.norm();
                    if m > 0.0 {
                        let zhat = to / m;
                        let l = lab / p.tau;
                        lq0 -= (l - zhat * zhat.dot(&l)) * (p.people_speed / m);
                    }
                }
                let lu = la * p.robot_strength - lab * b.strength;
                let jacobian = unit_repulsion_jacobian(x0 - q0, r.decay[k * n + i], p.range);
                let le = jacobian * lu;
                lx0 += le;
                lq0 -= le;
                lq[i] = lq0;
            }
            lx = lx0;
            lv = lv0;
        }
        grad
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

/// The restarts' directions, turned from the way to the goal (rad): straight on, ±30°, ±60°,
/// ±90°, ±135° and back.
pub const RESTART_TURNS: [Real; 10] = [
    0.0,
    FRAC_PI_6,
    -FRAC_PI_6,
    FRAC_PI_3,
    -FRAC_PI_3,
    FRAC_PI_2,
    -FRAC_PI_2,
    3.0 * FRAC_PI_4,
    -3.0 * FRAC_PI_4,
    PI,
];
/// The restarts' speeds, fractions of v^max (0.9 as the first warm start's).
pub const RESTART_SPEEDS: [Real; 2] = [0.9, 0.45];

/// Where the optimisation starts, and its J: `start`, or with [`AsfmParams::restarts`] the
/// lowest-J of `start`, the constant sequences of [`RESTART_TURNS`] × [`RESTART_SPEEDS`] and
/// standing still (ties keep the earlier, `start` first).
fn initial(
    objective: &Objective<'_>,
    scene: &Scene,
    start: &[Vec2],
    p: &AsfmParams,
) -> (Vec<Real>, Real) {
    let mut best: Vec<Real> = start
        .iter()
        .flat_map(|&v| {
            let u = unsquash(v, p.v_max);
            [u.x, u.y]
        })
        .collect();
    let mut f_best = objective.cost(&best).unwrap_or(Real::INFINITY);
    if !p.restarts {
        return (best, f_best);
    }
    let to = scene.goal - scene.robot.0;
    let heading = to.y.atan2(to.x);
    let fan = RESTART_TURNS.iter().flat_map(|&turn| {
        let (sin, cos) = (heading + turn).sin_cos();
        RESTART_SPEEDS
            .iter()
            .map(move |&s| vec2(cos, sin) * (s * p.v_max))
    });
    // One buffer for the candidates: the loser of each comparison is overwritten.
    let mut candidate = vec![0.0; best.len()];
    for v in fan.chain(std::iter::once(vec2(0.0, 0.0))) {
        let u = unsquash(v, p.v_max);
        for c in candidate.chunks_exact_mut(2) {
            c.copy_from_slice(&[u.x, u.y]);
        }
        let f = objective.cost(&candidate).unwrap_or(Real::INFINITY);
        if f < f_best {
            std::mem::swap(&mut best, &mut candidate);
            f_best = f;
        }
    }
    (best, f_best)
}

/// Minimises J over the desired velocities, from `start` (H of them), or from a restart
/// with a lower J ([`AsfmParams::restarts`]).
pub fn optimise(scene: &Scene, start: &[Vec2], p: &AsfmParams) -> Solution {
    let objective = Objective::new(scene, p);
    let (init, f_init) = initial(&objective, scene, start, p);
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
