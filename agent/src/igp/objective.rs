//! The robot–crowd objective of foIGP, log λ (Eq. 6.1), and its maximisation: the decoupling
//! terms over (t, τ) pairs, the hand-derived gradient and Hessian in their arrow structure,
//! damped Newton with backtracking (Levenberg–Marquardt style) through the Schur complement on
//! the robot block, the paper's multi-start seeds, and MC_1e5's sampling.

use super::gp::TrajectoryGp;
use crate::math::{Real, Vec2};
use nalgebra::{DMatrix, DVector};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

/// Which (t, τ) pairs couple the robot with a person.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Coupling {
    /// Every pair (Eq. 5.1): IGP_Full.
    Full,
    /// t = τ only ("the diagonals of Equation 5.1"): IGP_Diag.
    Diagonal,
}

/// Pairs farther apart than this many (normalised, squared) widths contribute less than e⁻³⁰
/// to the decoupling and are skipped.
const U_MAX: Real = 30.0;
/// Where two means coincide exactly, log(1 − e⁻ᵘ) is −∞; the objective treats u below this as
/// this, so it stays finite and differentiable.
const U_MIN: Real = 1e-12;

/// The robot–crowd objective log λ (Eq. 6.1) for one robot and the people it interacts with.
#[derive(Debug, Clone)]
pub struct Objective {
    pub(super) bodies: Vec<TrajectoryGp>,
    /// Per person: 1 / σ^{t,τ}_{ℓ+k} (0 where the pair does not couple).
    inv_width: Vec<DMatrix<Real>>,
}

/// A point in the objective's domain: the robot's trajectory first, then each person's.
pub type Trajectories = Vec<Vec<Vec2>>;

impl Objective {
    /// log λ for `robot` and `people` with the given coupling.
    pub fn new(robot: TrajectoryGp, people: Vec<TrajectoryGp>, coupling: Coupling) -> Self {
        let t = robot.steps();
        let inv_width = people
            .iter()
            .map(|p| {
                DMatrix::from_fn(t, t, |a, b| {
                    let width = robot.cov[(a, b)] + p.cov[(a, b)];
                    let coupled = coupling == Coupling::Full || a == b;
                    if coupled && width > 0.0 {
                        1.0 / width
                    } else {
                        0.0
                    }
                })
            })
            .collect();
        let mut bodies = Vec::with_capacity(people.len() + 1);
        bodies.push(robot);
        bodies.extend(people);
        Self { bodies, inv_width }
    }

    /// The number of people.
    pub fn people(&self) -> usize {
        self.bodies.len() - 1
    }

    /// The means (μ^R, μ^f).
    pub fn means(&self) -> Trajectories {
        self.bodies.iter().map(|b| b.mean.clone()).collect()
    }

    /// A Newton seed k σ from the means (Sec. 6: "(μ^R, μ^f) ± (0, [σ^R, σ^f], 2[…], 3[…])").
    ///
    /// [`SeedRule::PerBody`]: the robot at μ^R + k σ^R n and every person at μ^f − k σ^f n,
    /// n the unit normal to the left of the robot's mean path; seeds with k > 0 pass everyone
    /// on the robot's left, k < 0 on its right. [`SeedRule::Common`]: every body at μ + k σ
    /// in x and in y (the notation read literally; robot–person offsets then barely change
    /// between seeds).
    pub fn seed(&self, k: Real, rule: SeedRule) -> Trajectories {
        let robot = &self.bodies[0].mean;
        let heading = match (robot.first(), robot.last()) {
            (Some(a), Some(b)) if (b - a).norm() > 1e-9 => (b - a).normalize(),
            _ => Vec2::new(1.0, 0.0),
        };
        let left = Vec2::new(-heading.y, heading.x);
        self.bodies
            .iter()
            .enumerate()
            .map(|(i, b)| {
                let direction = match (rule, i) {
                    (SeedRule::Common, _) => Vec2::new(1.0, 1.0),
                    (SeedRule::PerBody, 0) => left,
                    (SeedRule::PerBody, _) => -left,
                };
                b.mean
                    .iter()
                    .zip(b.sigma())
                    .map(|(m, s)| m + direction * (k * s))
                    .collect()
            })
            .collect()
    }

    /// Eq. 6.1: Σᵢ Σ_t Σ_τ log(1 − Z⁻¹) minus the quadratic prior terms.
    pub fn value(&self, x: &[Vec<Vec2>]) -> Real {
        let prior: Real = self
            .bodies
            .iter()
            .zip(x)
            .map(|(b, xb)| b.log_prior(xb))
            .sum();
        prior + self.coupling(x)
    }

    /// The coupling part of Eq. 6.1: Σᵢ Σ_t Σ_τ log(1 − Z⁻¹) (never positive).
    fn coupling(&self, x: &[Vec<Vec2>]) -> Real {
        let mut f = 0.0;
        self.for_each_coupled_pair(x, |_, _, _, _, _, u| f += (-(-u).exp_m1()).ln());
        f
    }

    /// Calls `visit(person, t, τ, 1/σ^{t,τ}, Δ = x_R,t − x_person,τ, u)` for every coupled pair
    /// close enough to count (u < U_MAX), u clamped below at U_MIN.
    #[inline]
    fn for_each_coupled_pair(
        &self,
        x: &[Vec<Vec2>],
        mut visit: impl FnMut(usize, usize, usize, Real, Vec2, Real),
    ) {
        let t = self.bodies[0].steps();
        for (i, inv) in self.inv_width.iter().enumerate() {
            let person = &x[i + 1];
            for a in 0..t {
                for b in 0..t {
                    let c = inv[(a, b)];
                    if c == 0.0 {
                        continue;
                    }
                    let delta = x[0][a] - person[b];
                    let u = 0.5 * c * delta.norm_squared();
                    if u < U_MAX {
                        visit(i, a, b, c, delta, u.max(U_MIN));
                    }
                }
            }
        }
    }

    /// Gradient and the negated Hessian of log λ at `x`, in the arrow structure the robot–person
    /// coupling gives it (people do not couple with each other).
    fn derivatives(&self, x: &[Vec<Vec2>], d: &mut Derivatives) {
        let t = self.bodies[0].steps();
        let n = 2 * t;
        d.reset(self.people(), n);
        for (k, body) in self.bodies.iter().enumerate() {
            let block = if k == 0 {
                &mut d.a_rr
            } else {
                &mut d.a_pp[k - 1]
            };
            for a in 0..t {
                let mut g = Vec2::zeros();
                for b in 0..t {
                    let p = body.precision[(a, b)];
                    g -= (x[k][b] - body.mean[b]) * p;
                    block[(2 * a, 2 * b)] += p;
                    block[(2 * a + 1, 2 * b + 1)] += p;
                }
                d.grad[k][2 * a] += g.x;
                d.grad[k][2 * a + 1] += g.y;
            }
        }
        self.for_each_coupled_pair(x, |i, a, b, c, delta, u| {
            // g(u) = log(1 − e⁻ᵘ): g' = 1 / (eᵘ − 1), g'' = −eᵘ / (eᵘ − 1)².
            let em1 = u.exp_m1();
            let g1 = 1.0 / em1;
            let g2 = -(em1 + 1.0) / (em1 * em1);
            // ∇_Δ g = g' c Δ; ∇²_Δ g = g'' c² Δ Δᵀ + g' c I  (=: M).
            let grad = delta * (g1 * c);
            let m =
                delta * delta.transpose() * (g2 * c * c) + nalgebra::Matrix2::identity() * (g1 * c);
            d.grad[0][2 * a] += grad.x;
            d.grad[0][2 * a + 1] += grad.y;
            d.grad[i + 1][2 * b] -= grad.x;
            d.grad[i + 1][2 * b + 1] -= grad.y;
            // A = −H: the robot and person diagonal blocks get −M, the cross block +M.
            for r in 0..2 {
                for s in 0..2 {
                    d.a_rr[(2 * a + r, 2 * a + s)] -= m[(r, s)];
                    d.a_pp[i][(2 * b + r, 2 * b + s)] -= m[(r, s)];
                    d.b[i][(2 * a + r, 2 * b + s)] += m[(r, s)];
                }
            }
        });
    }

    /// The gradient of log λ at `x`, flattened body by body as (x₁, y₁, x₂, y₂, …).
    pub fn gradient(&self, x: &[Vec<Vec2>]) -> Vec<Real> {
        let mut d = Derivatives::default();
        self.derivatives(x, &mut d);
        d.grad.iter().flat_map(|g| g.iter().copied()).collect()
    }

    /// The Hessian of log λ at `x` as a dense matrix in the order of [`Objective::gradient`].
    pub fn hessian(&self, x: &[Vec<Vec2>]) -> DMatrix<Real> {
        let mut d = Derivatives::default();
        self.derivatives(x, &mut d);
        let n = d.a_rr.nrows();
        let size = n * self.bodies.len();
        let mut h = DMatrix::zeros(size, size);
        h.view_mut((0, 0), (n, n)).copy_from(&(-&d.a_rr));
        for i in 0..self.people() {
            let o = n * (i + 1);
            h.view_mut((o, o), (n, n)).copy_from(&(-&d.a_pp[i]));
            h.view_mut((0, o), (n, n)).copy_from(&(-&d.b[i]));
            h.view_mut((o, 0), (n, n)).copy_from(&(-d.b[i].transpose()));
        }
        h
    }

    /// The damped Newton step p solving (A + λI) p = ∇ with A = −H, by the Schur complement on
    /// the robot block: with A_ii + λI = L Lᵀ and W = L⁻¹ B_iᵀ, the robot block is
    /// S = A_RR + λI − Σ WᵀW. `None` if A + λI is not positive definite.
    fn newton_step(d: &Derivatives, lambda: Real) -> Option<Vec<DVector<Real>>> {
        let mut schur = d.a_rr.clone();
        add_to_diagonal(&mut schur, lambda);
        let mut rhs = d.grad[0].clone();
        let mut factors = Vec::with_capacity(d.a_pp.len());
        for (i, a_pp) in d.a_pp.iter().enumerate() {
            let mut c = a_pp.clone();
            add_to_diagonal(&mut c, lambda);
            let l = c.cholesky()?.unpack();
            let mut w = d.b[i].transpose();
            forward_substitute(&l, &mut w);
            let mut v = d.grad[i + 1].clone();
            l.solve_lower_triangular_mut(&mut v);
            // S −= WᵀW through a transposed copy: nalgebra's `gemm_tr` works dot product by dot
            // product, the product operator goes through matrixmultiply's kernels.
            let wt = w.transpose();
            schur -= &wt * &w;
            rhs.gemv_tr(-1.0, &w, &v, 1.0);
            factors.push((l, w, v));
        }
        let p_robot = schur.cholesky()?.solve(&rhs);
        let mut step = Vec::with_capacity(factors.len() + 1);
        step.push(p_robot);
        for (l, w, mut v) in factors {
            // p_i = L⁻ᵀ (v − W p_R)
            v.gemv(-1.0, &w, &step[0], 1.0);
            l.tr_solve_lower_triangular_mut(&mut v);
            step.push(v);
        }
        Some(step)
    }

    /// The first Newton step's length at the means (Δx of the ESS, Def. 10).
    pub fn first_step_length(&self) -> Real {
        let x = self.means();
        let mut d = Derivatives::default();
        self.derivatives(&x, &mut d);
        // A person whose pull on the pair is below this is not worth a factorisation: their
        // step would be ~1e-9 m, nothing next to the steps of people who matter.
        if d.grad.iter().all(|g| g.amax() < NEGLIGIBLE_GRADIENT) {
            return 0.0;
        }
        DAMPING
            .iter()
            .find_map(|&lambda| Self::newton_step(&d, lambda))
            .map_or(0.0, |p| {
                p.iter().map(|v| v.norm_squared()).sum::<Real>().sqrt()
            })
    }

    /// Newton's method from `x` (damped where the Hessian is not negative definite, with
    /// backtracking): a local maximum of log λ and its value.
    pub fn maximise(&self, mut x: Trajectories, options: &NewtonOptions) -> (Trajectories, Real) {
        let mut d = Derivatives::default();
        let mut f = self.value(&x);
        let mut lambda: Real = 0.0;
        for _ in 0..options.max_iterations {
            self.derivatives(&x, &mut d);
            let grad_max = d
                .grad
                .iter()
                .flat_map(|g| g.iter())
                .fold(0.0, |m: Real, v| m.max(v.abs()));
            if grad_max < options.gradient_tolerance {
                break;
            }
            // Levenberg–Marquardt damping carried across iterations: λ shrinks after a step
            // that climbs and grows while A + λI is indefinite or the step does not climb
            // within a few halvings.
            let mut moved = None;
            while moved.is_none() && lambda <= MAX_DAMPING {
                if let Some(p) = Self::newton_step(&d, lambda) {
                    let slope: Real = p.iter().zip(&d.grad).map(|(p, g)| p.dot(g)).sum();
                    let mut alpha = 1.0;
                    while alpha >= MIN_STEP_FRACTION {
                        let candidate = step_by(&x, &p, alpha);
                        let fc = self.value(&candidate);
                        if fc >= f + 1e-4 * alpha * slope {
                            let length = alpha * p.iter().map(|v| v.amax()).fold(0.0, Real::max);
                            moved = Some((candidate, fc, length));
                            break;
                        }
                        alpha *= 0.5;
                    }
                }
                if moved.is_some() {
                    lambda = if lambda > 1e-3 { lambda / 10.0 } else { 0.0 };
                } else {
                    lambda = (lambda * 10.0).max(1e-3);
                }
            }
            let Some((candidate, fc, length)) = moved else {
                break;
            };
            x = candidate;
            f = fc;
            if length < options.step_tolerance {
                break;
            }
        }
        (x, f)
    }

    /// The best of `samples` joint draws from the bodies' GPs (MC_1e5).
    ///
    /// A draw x = μ + L z (Σ = L Lᵀ) has prior term −½ |z|², and the coupling terms are never
    /// positive, so a draw whose −½ |z|² is already below the best value cannot win: its
    /// coupling is not evaluated. The result is the same as evaluating every draw.
    pub fn best_sample(&self, samples: usize, rng: &mut ChaCha8Rng) -> (Trajectories, Real) {
        let mut best = (self.means(), Real::NEG_INFINITY);
        let mut x = self.means();
        let mut z: Vec<Vec<Vec2>> = self.means();
        for _ in 0..samples {
            let mut prior = 0.0;
            for zb in z.iter_mut() {
                for v in zb.iter_mut() {
                    let zx: Real = StandardNormal.sample(rng);
                    let zy: Real = StandardNormal.sample(rng);
                    *v = Vec2::new(zx, zy);
                    prior -= 0.5 * v.norm_squared();
                }
            }
            if prior <= best.1 {
                continue;
            }
            for ((body, xb), zb) in self.bodies.iter().zip(x.iter_mut()).zip(&z) {
                for (a, xa) in xb.iter_mut().enumerate() {
                    let mut p = body.mean[a];
                    for (b, zv) in zb.iter().enumerate().take(a + 1) {
                        p += zv * body.chol[(a, b)];
                    }
                    *xa = p;
                }
            }
            let f = prior + self.coupling(&x);
            if f > best.1 {
                best = (x.clone(), f);
            }
        }
        best
    }
}

fn add_to_diagonal(m: &mut DMatrix<Real>, value: Real) {
    if value != 0.0 {
        for k in 0..m.nrows() {
            m[(k, k)] += value;
        }
    }
}

/// Solves L X = X in place for a lower-triangular L, column by column in axpy form (both
/// operands contiguous in column-major storage; nalgebra's general multi-column solve was
/// most of a replan's time).
fn forward_substitute(l: &DMatrix<Real>, x: &mut DMatrix<Real>) {
    let n = l.nrows();
    let ls = l.as_slice();
    for col in x.as_mut_slice().chunks_mut(n) {
        for k in 0..n {
            let xk = col[k] / ls[k * n + k];
            col[k] = xk;
            if xk != 0.0 {
                let lk = &ls[k * n + k + 1..(k + 1) * n];
                for (xi, li) in col[k + 1..].iter_mut().zip(lk) {
                    *xi -= li * xk;
                }
            }
        }
    }
}

/// Gradients below this at the means count as no interaction in the ESS.
const NEGLIGIBLE_GRADIENT: Real = 1e-9;

/// Damping tried in turn for the ESS's first steps, until A + λI is positive definite.
const DAMPING: [Real; 9] = [0.0, 1e-3, 1e-2, 1e-1, 1.0, 10.0, 1e2, 1e3, 1e4];
/// Newton gives up (at a local maximum, as far as it can tell) beyond this damping.
const MAX_DAMPING: Real = 1e6;
/// Backtracking halves a step at most down to this fraction before raising the damping.
const MIN_STEP_FRACTION: Real = 1.0 / 16.0;

fn step_by(x: &[Vec<Vec2>], p: &[DVector<Real>], alpha: Real) -> Trajectories {
    x.iter()
        .zip(p)
        .map(|(xb, pb)| {
            xb.iter()
                .enumerate()
                .map(|(a, v)| v + Vec2::new(pb[2 * a], pb[2 * a + 1]) * alpha)
                .collect()
        })
        .collect()
}

/// Gradient and A = −H in blocks: robot, each person, and robot × person.
#[derive(Debug, Default)]
struct Derivatives {
    grad: Vec<DVector<Real>>,
    a_rr: DMatrix<Real>,
    a_pp: Vec<DMatrix<Real>>,
    b: Vec<DMatrix<Real>>,
}

impl Derivatives {
    /// Zeroes everything for `people` people and 2T = `n`, reusing the storage.
    fn reset(&mut self, people: usize, n: usize) {
        if self.a_rr.nrows() != n {
            *self = Self::default();
            self.a_rr = DMatrix::zeros(n, n);
        }
        self.grad.resize(people + 1, DVector::zeros(n));
        self.grad.iter_mut().for_each(|g| g.fill(0.0));
        self.a_rr.fill(0.0);
        self.a_pp.resize(people, DMatrix::zeros(n, n));
        self.a_pp.iter_mut().for_each(|m| m.fill(0.0));
        self.b.resize(people, DMatrix::zeros(n, n));
        self.b.iter_mut().for_each(|m| m.fill(0.0));
    }
}

/// When Newton's method stops.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonOptions {
    /// At most this many iterations.
    pub max_iterations: usize,
    /// Stop when every gradient component is below this.
    pub gradient_tolerance: Real,
    /// Stop when no coordinate moved more than this (m).
    pub step_tolerance: Real,
}

impl Default for NewtonOptions {
    fn default() -> Self {
        Self {
            max_iterations: 30,
            gradient_tolerance: 1e-6,
            step_tolerance: 1e-4,
        }
    }
}

/// Where Newton's multi-start seeds lie ([`Objective::seed`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SeedRule {
    /// The robot and the people shifted in opposite directions across the robot's path.
    PerBody,
    /// Every body shifted by the same +kσ in x and y.
    Common,
}
