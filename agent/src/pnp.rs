//! Peek-and-pass: the hallway planner of "Look Before You Leap" (Sharma et al.), Sec. IV.
//!
//! A motion-primitive planner for a unicycle (Eq. 1). Every candidate is a sequence of
//! constant (v, ω) segments over the horizon t_f, executed within the base's speed,
//! acceleration and turn limits. The candidate minimising Eq. 3 wins:
//!
//! J = c1·‖x(t_f) − x_g‖² + c2·p_coll + c3·ρ,
//!
//! - p_coll = Σ_i p_coll^i (Eq. 5): p_coll⁰ is 1 if the path comes within the robot's radius of
//!   a wall or shelf (the static map inflated by the robot's radius), else 0; such candidates
//!   are dropped, since the paper avoids static obstacles deterministically (if all are, the
//!   robot brakes). p_coll^i for each perceived body is CVaR_α of collision over samples of its
//!   predicted trajectory.
//! - ρ = max(0, CVaR_{α_peek}(Ψ) − ε_peek) (Eq. 6): Ψ is a set of hypothetical people stepping
//!   out of the space the robot cannot see, sampled uniformly: positions on the occlusion
//!   edges of its visibility profile ([`crate::visibility`]), headings into view, speeds up to
//!   the walking speed.
//!
//! The paper predicts people with an S-GAN; this planner samples **constant-velocity
//! predictions with PGP's σ growth** ([`SigmaModel`](crate::prediction::SigmaModel), the PGP
//! paper's σ0, β, γ, δ): sample j of body i is its constant-velocity track shifted by
//! ε_j·σ_i(t), with ε_j fixed standard normal offsets. Every value the paper leaves open is a field of [`PnpParams`], with the
//! reason for its value.
//!
//! A sampled future's loss is 0 without collision and, with a first contact at t_c, 1 in the
//! paper's variant ([`PnpParams::paper`], `pnp-paper`) or (1 − t_c/t_f) scaled by the closing
//! speed in the tuned ones ([`cvar`] takes the mean of the worst (1 − α) of them). The tuned
//! variants (`pnp`, `pnp-react`) also count 0.1 m of clearance as contact, score the path's way
//! to the goal and not only its end, and let a candidate arrive; `pnp-react` scores each
//! candidate against predictions that react to it ([`Prediction::Reactive`]). `pnp-omni`
//! ([`PnpParams::omni`]) plans a holonomic base's velocities instead of a unicycle's
//! (v, ω) segments ([`PnpParams::directions`]).

use crate::map::{LocalMap, StaticMap};
use crate::math::{Real, Vec2, clamp_norm, vec2};

use crate::model::{Command, EgoState, Neighbour, TrajectorySample};
use crate::prediction::predict;
use crate::visibility::Visibility;
use candidates::Candidates;
use hidden::{Hidden, braking_path, halton, hidden_risk, sample_hidden};
pub use params::{NO_PEEK_C3, PEEK_C3, PnpParams, Prediction, SIDE_RUNS_ON, SIDE_WEIGHT, Severity};
use predict::{Predicted, Scratch, Shared, body_risk, might_touch, social_force_rollout};
use react::Reaction;
pub use risk::cvar;
use risk::{Path, Scoring, bounds, near_any_segment};

/// What the safety layer would do with a candidate's first segment, worst first.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Admission {
    /// Not admitted (`SafeSet::admits` refuses it).
    Refused,
    /// Admitted, but the layer would still slow it or replace it (a warning, or a yield).
    Admitted,
    /// Let through untouched.
    Passes,
}

/// The cost terms of one candidate.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Cost {
    /// ‖x(t_f) − x_g‖² (m²).
    pub goal: Real,
    /// p_coll = p_coll⁰ + Σ_i p_coll^i.
    pub collision: Real,
    /// ρ.
    pub peek: Real,
    /// J.
    pub total: Real,
}

/// The decision of one plan.
#[derive(Debug, Clone, PartialEq)]
pub struct PnpDecision {
    /// The first segment of the best candidate.
    pub command: Command,
    /// Its path on the time grid, at most 0.25 s apart (t from then to t_f).
    pub trajectory: Vec<TrajectorySample>,
    /// Its cost terms.
    pub cost: Cost,
    /// How many occlusion edges Ψ was sampled on.
    pub edges: usize,
}

/// The peek-and-pass planner: its parameters, fixed sample sets and scratch.
#[derive(Debug, Clone)]
pub struct Pnp {
    params: PnpParams,
    /// The candidates and, in each plan, their paths.
    candidates: Candidates,
    /// Standard normal offsets ε_j of the prediction samples, and their lengths.
    offsets: Vec<(Vec2, Real)>,
    /// Points of the unit cube for Ψ (edge position, heading, speed).
    psi_units: Vec<[Real; 3]>,
    // Scratch, reused between plans.
    predicted: Vec<Predicted>,
    /// The shared rollout of reactive predictions, and one body's reaction to a candidate.
    reaction: Reaction,
    reacting: Predicted,
    hidden: Vec<Hidden>,
    /// A candidate's path braking as a hidden person steps out (`hidden_braking`), and per
    /// prefix of siblings Ψ's risk against it, once asked in this plan.
    braking: Vec<Vec2>,
    braking_psi: Vec<Option<Real>>,
    scratch: Scratch,
    /// Per candidate, its goal term in this plan.
    goal_terms: Vec<Real>,
    /// The candidates in scoring order, each as [`ordered`] of its goal term, then its index.
    order: Vec<u128>,
    /// Per prefix of siblings (candidates that differ only in their last segment): whether
    /// its shared path meets a wall or shelf, once asked in this plan.
    walled: Vec<Option<bool>>,
    /// Per (run of siblings, perceived body): what their shared path meets of the body, and
    /// the plan it was filled in (counted in `plans`).
    shared: Vec<Shared>,
    shared_plan: Vec<u64>,
    plans: u64,
    /// Per candidate: whether the safety layer's judgement of its first segment is the best
    /// any candidate has (all true without a judge, or when it admits none).
    allowed: Vec<bool>,
    /// (first segment, the layer's judgement) as asked in this plan.
    first_segments: Vec<((Real, Real), Admission)>,
    local: LocalMap,
    own: Visibility,
    /// The candidate the last plan chose, scored first in the next: usually still good, it
    /// sets a low best total early and cuts most others short. Which candidate wins does not
    /// depend on the order they are scored in.
    warm: Option<usize>,
    /// Score every candidate in full, without cutting any short or taking what siblings share
    /// from the one scored before (the tests' reference).
    exhaustive: bool,
    /// The perceived bodies in the order they are asked about a candidate's risk, and each
    /// one's p_coll^i for the candidate being scored.
    body_order: Vec<usize>,
    risks: Vec<Real>,
}

impl Pnp {
    /// A planner with `params`.
    pub fn new(params: PnpParams) -> Self {
        let offsets = (0..params.prediction_samples)
            .map(|j| {
                // Box–Muller on a Halton (2, 3) point: fixed, evenly spread normals.
                let (u1, u2) = (halton(j + 1, 2), halton(j + 1, 3));
                let r = (-2.0 * u1.ln()).sqrt();
                let a = std::f64::consts::TAU * u2;
                let o = vec2(r * a.cos(), r * a.sin());
                (o, o.norm())
            })
            .collect();
        let psi_units = (0..params.psi_samples)
            .map(|j| [halton(j + 1, 2), halton(j + 1, 3), halton(j + 1, 5)])
            .collect();
        Self {
            candidates: Candidates::new(&params),
            params,
            offsets,
            psi_units,
            predicted: Vec::new(),
            reaction: Reaction::default(),
            reacting: Predicted::default(),
            hidden: Vec::new(),
            braking: Vec::new(),
            braking_psi: Vec::new(),
            scratch: Scratch::default(),
            goal_terms: Vec::new(),
            order: Vec::new(),
            walled: Vec::new(),
            shared: Vec::new(),
            shared_plan: Vec::new(),
            plans: 0,
            allowed: Vec::new(),
            first_segments: Vec::new(),
            local: LocalMap::default(),
            own: Visibility::default(),
            warm: None,
            exhaustive: false,
            body_order: Vec::new(),
            risks: Vec::new(),
        }
    }

    /// The parameters in use.
    pub fn params(&self) -> &PnpParams {
        &self.params
    }

    /// How many candidates each plan weighs.
    pub fn candidates(&self) -> usize {
        self.candidates.primitives.len()
    }

    /// Marks the candidates whose first segment (what the robot executes until the next plan)
    /// the safety layer judges best: those it lets through untouched if any, else those it
    /// admits if any, else all of them (the layer then acts on the best). All of them without
    /// a judge.
    fn mark_allowed(&mut self, judge: Option<&dyn Fn(Command) -> Admission>) {
        self.allowed.clear();
        self.allowed.resize(self.candidates.primitives.len(), true);
        let Some(judge) = judge else {
            return;
        };
        self.first_segments.clear();
        let mut best = Admission::Refused;
        for primitive in &self.candidates.primitives {
            let Some(&first) = primitive.first() else {
                continue;
            };
            if !self.first_segments.iter().any(|(seg, _)| *seg == first) {
                let a = judge(self.candidates.command(&self.params, first));
                best = best.max(a);
                self.first_segments.push((first, a));
            }
        }
        if best == Admission::Refused {
            return;
        }
        for (c, primitive) in self.candidates.primitives.iter().enumerate() {
            let a = primitive.first().and_then(|first| {
                self.first_segments
                    .iter()
                    .find(|(seg, _)| seg == first)
                    .map(|&(_, a)| a)
            });
            self.allowed[c] = a == Some(best);
        }
    }

    /// One plan toward `goal`. `visibility` is what the sensor saw; without it the planner
    /// derives the shadows of the map and of the bodies it perceives.
    pub fn plan(
        &mut self,
        ego: &EgoState,
        neighbours: &[Neighbour],
        map: &StaticMap,
        goal: Vec2,
        visibility: Option<&Visibility>,
    ) -> PnpDecision {
        self.plan_within(ego, neighbours, map, goal, visibility, None)
    }

    /// One plan toward `goal` among the candidates whose first segment the safety layer's
    /// `judge` ranks best (see [`Admission`]); without a judge as [`Pnp::plan`].
    pub fn plan_within(
        &mut self,
        ego: &EgoState,
        neighbours: &[Neighbour],
        map: &StaticMap,
        goal: Vec2,
        visibility: Option<&Visibility>,
        judge: Option<&dyn Fn(Command) -> Admission>,
    ) -> PnpDecision {
        self.candidates.aim(ego, goal);
        self.mark_allowed(judge);
        let p = &self.params;
        let n = (p.horizon / p.step).round().max(1.0) as usize;
        let dt = p.horizon / n as Real;
        self.candidates.roll_out(&self.params, ego, n, dt);
        self.predict(ego, neighbours, n, dt);
        let visibility = match visibility {
            Some(v) => v,
            None => {
                self.own.rescan(
                    ego.position,
                    self.params.sensor_range,
                    crate::visibility::DEFAULT_RAYS,
                    map,
                    neighbours.iter().map(|b| (b.position, b.radius)),
                    &mut self.local,
                );
                &self.own
            }
        };
        let edges = sample_hidden(
            &self.params,
            &self.psi_units,
            visibility,
            map,
            neighbours,
            ego,
            &mut self.hidden,
        );
        let p = &self.params;
        let reach = p.goal_distance.unwrap_or(p.v_max * p.horizon);
        let local_goal = ego.position + clamp_norm(goal - ego.position, reach);
        // Walls within 1 m of where any candidate ends, or within the side term's reach.
        let margin = if p.side_weight > 0.0 {
            p.side_reach.max(1.0)
        } else {
            1.0
        };
        let r = vec2(reach + margin, reach + margin);
        map.gather(
            ego.position - r,
            ego.position + r,
            ego.radius,
            &mut self.local,
        );

        // The fastest closing of note, per grid step (the losses' unit).
        let scoring = Scoring {
            reference: (p.v_max + p.hidden_speed) * dt,
            severity: p.severity,
        };
        // Candidates are scored in order of their goal term, so that a good one is found
        // early and the rest are mostly cut short; ties in J go to the lower index, as they
        // would scoring them in index order.
        self.goal_terms.clear();
        let there = (ego.position - goal).norm() < self.params.goal_tolerance;
        let side_weight = if p.side_weight > 0.0
            && p.side_runs_on > 0.0
            && !self
                .local
                .nearest_wall_runs_on(map, &ego.position, p.side_runs_on)
        {
            0.0
        } else if p.side_fade > 0.0 {
            p.side_weight * ((goal - ego.position).norm() / p.side_fade).min(1.0)
        } else {
            p.side_weight
        };
        // Keeping right: the unit vector at right angles to the right of the way to the
        // local goal (none where the robot stands on it: the nearest wall then counts).
        let right = (p.side_right && side_weight > 0.0)
            .then(|| local_goal - ego.position)
            .filter(|way| way.norm() > 1e-9)
            .map(|way| vec2(way.y, -way.x) / way.norm());
        for c in 0..self.candidates.primitives.len() {
            let path = self.candidates.path(c, n);
            // A candidate that arrives (within the tolerance of the goal itself) is done there:
            // it scores what it cost to get there, nothing for overshooting afterwards. Not
            // once the robot stands within the tolerance and still has the goal: whoever set
            // it wants the robot closer (a route's corner in a narrow aisle is reached nearer
            // than a station), and counting every candidate as arrived would leave it standing.
            let arrives = if p.arrival && local_goal == goal && !there {
                path.iter()
                    .position(|q| (q - goal).norm() < p.goal_tolerance)
            } else {
                None
            };
            let until = arrives.unwrap_or(n + 1);
            let running = path[1..until.max(1)]
                .iter()
                .map(|q| (q - local_goal).norm_squared())
                .sum::<Real>()
                / n as Real;
            let terminal = if arrives.is_some() {
                0.0
            } else {
                (path[n] - local_goal).norm_squared()
            };
            let side = if side_weight > 0.0 {
                let wall = if let Some(right) = right {
                    self.local.ray_distance(&path[n], &right)
                } else {
                    self.local.edge_distance(&path[n])
                };
                side_weight * wall.min(p.side_reach)
            } else {
                0.0
            };
            let goal_term = terminal + p.progress_weight * running + side;
            self.goal_terms.push(goal_term);
        }
        self.order.clear();
        self.order.extend(
            self.goal_terms
                .iter()
                .enumerate()
                .map(|(c, &g)| u128::from(ordered(g)) << 64 | c as u128),
        );
        self.order.sort_unstable();
        if let Some(warm) = self.warm.filter(|&c| self.allowed.get(c) == Some(&true))
            && let Some(at) = self
                .order
                .iter()
                .position(|&key| key as u64 as usize == warm)
        {
            self.order[..=at].rotate_right(1);
        }
        let prune = !self.exhaustive;
        self.body_order.clear();
        self.body_order.extend(0..self.predicted.len());
        let mut best = (Real::INFINITY, usize::MAX, Cost::default());
        // Whether a candidate whose cost is at least `partial` cannot win.
        let loses = |partial: Real, c: usize, best: &(Real, usize, Cost)| {
            partial > best.0 || (partial == best.0 && c > best.1)
        };
        // The most of p_coll^i a candidate may still run and win, given its goal term and
        // the risk counted so far: with a margin far above rounding (1e-9 of the best total),
        // so that a candidate cut short for exceeding it would have lost scored in full.
        let budget = |goal_term: Real, collision: Real, best: Real| {
            if prune && best.is_finite() && p.c2 > 0.0 {
                (best - p.c1 * goal_term + 1e-9 * best.abs() + 1e-12) / p.c2 - collision
            } else {
                Real::INFINITY
            }
        };
        let tail = if self.exhaustive {
            0
        } else {
            self.candidates.shared_until(n)
        };
        self.walled.clear();
        self.walled.resize(self.candidates.prefixes(), None);
        self.braking_psi.clear();
        self.braking_psi.resize(self.candidates.prefixes(), None);
        self.plans += 1;
        let entries = self.candidates.prefixes() * self.predicted.len();
        if self.shared.len() < entries {
            self.shared.resize_with(entries, Shared::default);
            self.shared_plan.resize(entries, 0);
        }
        for &key in &self.order {
            let c = key as u64 as usize;
            let goal_term = self.goal_terms[c];
            if !self.allowed[c] {
                continue;
            }
            let path = self.candidates.path(c, n);
            // The rest cannot beat the best even without risk (the warm candidate, scored
            // first, is the only one out of order).
            if prune && loses(p.c1 * goal_term, c, &best) {
                if p.c1 * goal_term > best.0 {
                    break;
                }
                continue;
            }
            // Static obstacles are avoided deterministically (the paper's aim): p_coll⁰ = 1
            // rules a candidate out.
            // Siblings share their path up to `tail`: its part of the check once for them all.
            let walls = self.local.segments();
            let hits = |points: &[Vec2]| {
                points
                    .windows(2)
                    .any(|w| near_any_segment(w[0], w[1], walls, ego.radius))
            };
            let prefix = self.candidates.prefix_of(c);
            let walled = *self.walled[prefix].get_or_insert_with(|| hits(&path[..=tail]));
            if walled || hits(&path[tail..]) {
                continue;
            }
            // Every term is ≥ 0: once the risk so far, with a margin far above rounding (as
            // in `budget`), takes the total past the best, the candidate cannot win. Bodies
            // are asked in the order of which last ruled a candidate out (neighbouring
            // candidates in goal order tend to meet the same person); p_coll is summed in
            // their own order, so its bits do not depend on it.
            let swept = Path::new(path);
            let mut so_far = 0.0;
            let mut beaten = None;
            let reactive = p.prediction == Prediction::Reactive;
            self.risks.clear();
            self.risks.resize(self.predicted.len(), 0.0);
            let prefix = self.candidates.prefix_of(c);
            for (at, &i) in self.body_order.iter().enumerate() {
                let body = &self.predicted[i];
                let mut shared = None;
                let body = if reactive && self.reaction.reacts(i) {
                    // People the candidate does not come near without their reaction are
                    // left out: the robot's push is taken to move them away, not closer.
                    if !might_touch(swept, body, None, &mut self.scratch.gaps) {
                        continue;
                    }
                    self.reaction.respond(i, path, body, &mut self.reacting);
                    &self.reacting
                } else {
                    // What the siblings' shared path meets of the body, once per plan.
                    if tail > 0 && swept.box_meets(body.reach) {
                        let e = prefix * self.predicted.len() + i;
                        if self.shared_plan[e] != self.plans {
                            let (points, offsets) = (&path[..=tail], &self.offsets);
                            self.shared[e].fill(points, body, offsets, p.alpha, n, scoring);
                            self.shared_plan[e] = self.plans;
                        }
                        shared = Some((&self.shared[e], tail));
                    }
                    body
                };
                let Some(risk) = body_risk(
                    swept,
                    body,
                    &self.offsets,
                    (p.alpha, scoring),
                    budget(goal_term, so_far, best.0),
                    shared,
                    &mut self.scratch,
                ) else {
                    beaten = Some(at);
                    break;
                };
                self.risks[i] = risk;
                so_far += risk;
                if risk > 0.0 && budget(goal_term, so_far, best.0) < 0.0 {
                    beaten = Some(at);
                    break;
                }
            }
            if let Some(at) = beaten {
                self.body_order[..=at].rotate_right(1);
                continue;
            }
            let collision = self.risks.iter().fold(0.0, |sum, &r| sum + r);
            if prune && loses(p.c1 * goal_term + p.c2 * collision, c, &best) {
                continue;
            }
            let contact = ego.radius + p.hidden_radius + p.clearance;
            let (hidden, losses) = (&self.hidden, &mut self.scratch.losses);
            let psi = if p.hidden_braking {
                // The braking path follows the path's first two grid steps alone: once for
                // siblings that share them.
                let braking = &mut self.braking;
                let mut risk = || {
                    braking_path(path, dt, p.a_max, braking);
                    hidden_risk(
                        Path::new(braking),
                        hidden,
                        dt,
                        contact,
                        p.alpha_peek,
                        scoring,
                        losses,
                    )
                };
                if tail >= 2 {
                    *self.braking_psi[prefix].get_or_insert_with(risk)
                } else {
                    risk()
                }
            } else {
                hidden_risk(swept, hidden, dt, contact, p.alpha_peek, scoring, losses)
            };
            let peek = (psi - p.epsilon_peek).max(0.0);
            let total = p.c1 * goal_term + p.c2 * collision + p.c3 * peek;
            if !loses(total, c, &best) {
                best = (
                    total,
                    c,
                    Cost {
                        goal: goal_term,
                        collision,
                        peek,
                        total,
                    },
                );
            }
        }
        let (total, c, cost) = best;
        self.warm = (total < Real::INFINITY).then_some(c);
        if total == Real::INFINITY {
            // Every candidate meets a wall or shelf: brake, holding the heading.
            return PnpDecision {
                command: Command::Unicycle {
                    speed: 0.0,
                    yaw_rate: 0.0,
                },
                trajectory: Vec::new(),
                cost: Cost {
                    collision: 1.0,
                    total,
                    ..Cost::default()
                },
                edges,
            };
        }
        let first = self.candidates.primitives[c][0];
        let command = self.candidates.command(p, first);
        let v = first.0;
        let path = self.candidates.path(c, n);
        // Samples at most 0.25 s apart, on the grid.
        let every = ((0.25 / dt + 1e-9).floor() as usize).max(1);
        let speed = (v * p.v_max).abs();
        let trajectory = path
            .iter()
            .enumerate()
            .skip(every)
            .step_by(every)
            .zip(p.sigma.constant_speed(speed))
            .map(|((k, &position), sigma)| TrajectorySample {
                t: k as Real * dt,
                position,
                sigma,
            })
            .collect();
        PnpDecision {
            command,
            trajectory,
            cost,
            edges,
        }
    }

    /// Each perceived body's mean track and σ on the grid.
    fn predict(&mut self, ego: &EgoState, neighbours: &[Neighbour], n: usize, dt: Real) {
        self.predicted
            .resize_with(neighbours.len(), Predicted::default);
        for (slot, body) in self.predicted.iter_mut().zip(neighbours) {
            predict(body, dt, n, &self.params.sigma, &mut slot.track);
            slot.contact = ego.radius + body.radius + self.params.clearance;
        }
        match self.params.prediction {
            Prediction::ConstantVelocity => {}
            Prediction::SocialForce => social_force_rollout(
                ego,
                neighbours,
                n,
                dt,
                &self.params.sigma,
                &mut self.predicted,
            ),
            Prediction::Reactive => {
                self.reaction
                    .prepare(neighbours, n, dt, &self.params.sigma, &mut self.predicted)
            }
        }
        let largest = self.offsets.iter().map(|&(_, r)| r).fold(0.0, Real::max);
        let across = self.params.across_spread;
        for (slot, body) in self.predicted.iter_mut().zip(neighbours) {
            let speed = body.velocity.norm();
            let walking = across != 1.0
                && body.kind == crate::model::AgentKind::Human
                && speed >= crate::safety::ACROSS_MIN_SPEED;
            slot.shape(
                &self.offsets,
                walking.then(|| body.velocity / speed),
                across,
            );
            let sigma = &slot.track.sigma;
            slot.spread = largest * (sigma.iter().copied().fold(0.0, Real::max) - sigma[0]);
            slot.growth.clear();
            slot.growth
                .extend(sigma.windows(2).map(|w| w[0].max(w[1]) - sigma[0]));
            let (lo, hi) = bounds(&slot.track.positions);
            let r = slot.contact + slot.spread;
            slot.reach = (lo - vec2(r, r), hi + vec2(r, r));
        }
    }
}

/// `x` as a key whose unsigned order is `Real::total_cmp`'s.
fn ordered(x: Real) -> u64 {
    let bits = x.to_bits() as i64;
    // As `total_cmp` does: negative values' magnitude bits flipped, so that they order as
    // signed integers; then the sign bit flipped, so that they order unsigned.
    ((bits ^ ((((bits >> 63) as u64) >> 1) as i64)) as u64) ^ (1 << 63)
}

mod candidates;
mod hidden;
mod params;
mod predict;
mod react;
mod risk;
#[cfg(test)]
mod tests;
