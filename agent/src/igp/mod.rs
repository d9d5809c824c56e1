//! First-order interacting Gaussian processes (foIGP; Trautman & Patel, AAAI 2020,
//! `shared/papers/foigp-first-order-interacting-gps.md`).
//!
//! The robot and every person are Gaussian processes over their future positions: the mean is
//! the *intent*, the covariance the *flexibility* (Defs. 2–3). They interact only through the
//! decoupling Λ (Def. 5): for every pair of times (t, τ) the robot at t and a person at τ should
//! not meet, with a width given by the (t, τ) element of the summed covariances. The planner
//! maximises log λ (Eq. 6.1) over the robot's and the people's trajectories with Newton's
//! method from the paper's seeds μ ± {0, 1, 2, 3}σ (the robot and the people shifted apart,
//! [`SeedRule`]), on the people that the effective sample size of the first Newton steps
//! singles out (Defs. 10–11), and drives towards the robot's optimised position one step
//! ahead.
//!
//! Every person is a GP mixture with one intent per destination of the scene (Eq. 3.1;
//! [`mixture`]), and the joint is optimised over combinations of intents (Eq. 5.3) in
//! [`IgpVariant::Mixture`], the paper's foIGP (`foigp`). The other variants model each person
//! as one GP. Named as in the paper's Tables 1–2: [`IgpVariant::Full`] (IGP_Full with one GP
//! per person, `foigp-1`; all (t, τ) pairs), [`IgpVariant::Diagonal`] (IGP_Diag, t = τ only),
//! [`IgpVariant::Linear`] (IGP_Lin: a person's GP is their constant-velocity line instead of a
//! regression on their history) and [`IgpVariant::MonteCarlo`] (MC_1e5: the best of 10⁵ joint
//! samples instead of Newton). The objective log λ and its maximisation are in `objective`,
//! the agent GPs in `gp`; this module selects the people and intents and plans.
//!
//! What the paper leaves open, and what we chose (all in [`GpParams`] / [`IgpParams`]):
//! the GP kernel (a constant-velocity prior mean with a linear-in-time and a squared-exponential
//! kernel on the deviation from it), the horizon (12 samples at the recordings' 0.4 s), the
//! robot's prior (a straight line to its goal at its preferred speed), and a damped Newton step
//! with backtracking where the Hessian is not negative definite (log λ is not concave).

use crate::math::{Real, Vec2, clamp_norm};
use crate::model::{Command, EgoState, Neighbour, TrajectorySample};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::collections::{BTreeMap, VecDeque};

mod gp;
pub mod mixture;
mod objective;
#[cfg(test)]
mod tests;

pub use gp::{GpParams, TrajectoryGp};
pub use mixture::Component;
pub use objective::{Coupling, NewtonOptions, Objective, SeedRule, Trajectories};

/// The effective sample size of the first Newton steps of the robot–(person, intent) pairs
/// (Def. 10) and the pairs it keeps: the round(ESS) with the longest steps, longest first.
pub fn ess_selection(steps: &[Real]) -> (Real, Vec<usize>) {
    let total: Real = steps.iter().sum();
    if total <= 0.0 || !total.is_finite() {
        return (0.0, Vec::new());
    }
    let ess = 1.0 / steps.iter().map(|s| (s / total).powi(2)).sum::<Real>();
    let mut order: Vec<usize> = (0..steps.len()).filter(|&i| steps[i] > 0.0).collect();
    order.sort_by(|&a, &b| steps[b].total_cmp(&steps[a]).then(a.cmp(&b)));
    order.truncate((ess.round() as usize).max(1));
    (ess, order)
}

/// The planners of the foIGP paper's tables.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum IgpVariant {
    /// foIGP as the paper defines it: IGP_Full with every person a GP mixture, one intent per
    /// destination of the scene ([`mixture`]), the joint optimised over intent combinations.
    /// Without destinations it is [`IgpVariant::Full`].
    Mixture,
    /// IGP_Full with one GP per person (`foigp-1`): regressed on their history, every (t, τ)
    /// pair coupled.
    Full,
    /// IGP_Diag: as Full, but only t = τ coupled.
    Diagonal,
    /// IGP_Lin: people's constant-velocity lines, every pair coupled.
    Linear,
    /// MC_1e5: the best of 10⁵ joint samples instead of Newton's method.
    MonteCarlo,
}

/// The planner's parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IgpParams {
    /// The agent models.
    pub gp: GpParams,
    /// The robot's prior speed along the line to its goal (m/s): the study robot's 1 m/s.
    pub preferred_speed: Real,
    /// Commands are capped at this speed (m/s).
    pub max_speed: Real,
    /// At most this many people enter the optimisation (the top of the ESS ranking).
    pub max_people: usize,
    /// People farther than this are not modelled at all (m).
    pub range_m: Real,
    /// Newton stopping rules.
    pub newton: NewtonOptions,
    /// Joint samples for MC_1e5.
    pub samples: usize,
    /// Seed of MC_1e5's random stream.
    pub seed: u64,
    /// Where Newton's multi-start seeds lie.
    pub seeds: SeedRule,
}

impl Default for IgpParams {
    fn default() -> Self {
        Self {
            gp: GpParams::default(),
            preferred_speed: 1.0,
            max_speed: 1.0,
            max_people: 8,
            range_m: 12.0,
            newton: NewtonOptions::default(),
            samples: 100_000,
            seed: 0x1F16_0000,
            seeds: SeedRule::PerBody,
        }
    }
}

/// What one foIGP plan found, for tests and dashboards.
#[derive(Debug, Clone, PartialEq)]
pub struct IgpDecision {
    /// The velocity command.
    pub command: Command,
    /// The robot's optimised trajectory with σ.
    pub trajectory: Vec<TrajectorySample>,
    /// Neighbour ids that entered the optimisation, most significant first.
    pub selected: Vec<u64>,
    /// The effective sample size (over robot–(person, intent) pairs).
    pub ess: Real,
    /// log λ at the optimum.
    pub log_lambda: Real,
    /// Per selected person (in `selected`'s order): the index, among that person's kept
    /// intents, of the one in the winning combination (0 without mixtures).
    pub intents: Vec<usize>,
    /// How many intent combinations were optimised.
    pub combinations: usize,
}

/// The foIGP planner. It keeps each perceived person's recent positions (keyed by neighbour
/// id, dropped when the person is no longer perceived) for the GP regression, so its plans
/// depend on the sequence of inputs, deterministically.
#[derive(Debug, Clone)]
pub struct IgpPlanner {
    variant: IgpVariant,
    params: IgpParams,
    /// Seconds since the first plan (the sum of the control periods).
    clock: Real,
    tracks: BTreeMap<u64, VecDeque<(Real, Vec2)>>,
    rng: ChaCha8Rng,
    /// Where people go in this scene: one intent each ([`IgpVariant::Mixture`]).
    destinations: Vec<Vec2>,
}

impl IgpPlanner {
    /// A planner of the given variant.
    pub fn new(variant: IgpVariant, params: IgpParams) -> Self {
        Self {
            variant,
            params,
            clock: 0.0,
            tracks: BTreeMap::new(),
            rng: ChaCha8Rng::seed_from_u64(params.seed),
            destinations: Vec::new(),
        }
    }

    /// Where people go in this scene (a recording's `destinations.txt`, a site's stations):
    /// the intents of [`IgpVariant::Mixture`]'s mixtures. Other variants ignore them.
    pub fn set_destinations(&mut self, destinations: &[Vec2]) {
        self.destinations = destinations.to_vec();
    }

    /// Its parameters.
    pub fn params(&self) -> &IgpParams {
        &self.params
    }

    /// Which variant it is.
    pub fn variant(&self) -> IgpVariant {
        self.variant
    }

    /// Remembers where the perceived people are now; forgets the others.
    fn track(&mut self, neighbours: &[Neighbour]) {
        let now = self.clock;
        let dt = self.params.gp.dt;
        let keep = self.params.gp.history;
        self.tracks
            .retain(|id, _| neighbours.iter().any(|n| n.id == *id));
        for n in neighbours {
            let track = self.tracks.entry(n.id).or_default();
            if track.back().is_none_or(|&(t, _)| now - t >= dt - 1e-9) {
                track.push_back((now, n.position));
                while track.len() > keep {
                    track.pop_front();
                }
            }
        }
    }

    /// A person's intents: the mixture over the scene's destinations for
    /// [`IgpVariant::Mixture`], otherwise (or without destinations) one GP of weight 1.
    fn person_components(&self, n: &Neighbour) -> Vec<Component> {
        let gp = &self.params.gp;
        if self.variant == IgpVariant::Linear {
            let gp = TrajectoryGp::linear(gp, n.position, n.velocity);
            return vec![Component { weight: 1.0, gp }];
        }
        let past: Vec<(Real, Vec2)> = self
            .tracks
            .get(&n.id)
            .into_iter()
            .flatten()
            .filter(|(t, _)| *t < self.clock - 1e-9)
            .map(|&(t, p)| (t - self.clock, p))
            .collect();
        let single = TrajectoryGp::person(gp, n.position, n.velocity, &past);
        if self.variant == IgpVariant::Mixture {
            let mut seen = past;
            seen.push((0.0, n.position));
            if let Some(mixture) =
                mixture::person_mixture(gp, &single, &seen, n.velocity, &self.destinations)
            {
                return mixture;
            }
        }
        vec![Component {
            weight: 1.0,
            gp: single,
        }]
    }

    /// Newton from the paper's seeds; the best local maximum.
    fn multi_start(&self, objective: &Objective) -> (Trajectories, Real) {
        let p = &self.params;
        let mut best = objective.maximise(objective.means(), &p.newton);
        for k in [1.0, -1.0, 2.0, -2.0, 3.0, -3.0] {
            let run = objective.maximise(objective.seed(k, p.seeds), &p.newton);
            if run.1 > best.1 {
                best = run;
            }
        }
        best
    }

    /// One plan towards `goal`; `dt` is the time until the next plan.
    pub fn plan(
        &mut self,
        ego: &EgoState,
        neighbours: &[Neighbour],
        goal: Vec2,
        dt: Real,
    ) -> IgpDecision {
        self.track(neighbours);
        let p = self.params;
        let robot = TrajectoryGp::robot(&p.gp, ego.position, goal, p.preferred_speed);
        let coupling = if self.variant == IgpVariant::Diagonal {
            Coupling::Diagonal
        } else {
            Coupling::Full
        };
        let near: Vec<&Neighbour> = neighbours
            .iter()
            .filter(|n| (n.position - ego.position).norm() <= p.range_m)
            .collect();
        let people: Vec<Vec<Component>> = near.iter().map(|n| self.person_components(n)).collect();
        // Def. 10: the first Newton step of each robot–(person, intent) pair, then the ESS;
        // the people with a pair among the top round(ESS) enter, most significant first.
        let pairs: Vec<(usize, usize)> = people
            .iter()
            .enumerate()
            .flat_map(|(i, c)| (0..c.len()).map(move |k| (i, k)))
            .collect();
        let steps: Vec<Real> = pairs
            .iter()
            .map(|&(i, k)| {
                let person = people[i][k].gp.clone();
                Objective::new(robot.clone(), vec![person], coupling).first_step_length()
            })
            .collect();
        let (ess, order) = ess_selection(&steps);
        let mut entering: Vec<usize> = Vec::new();
        for &j in &order {
            let i = pairs[j].0;
            if !entering.contains(&i) && entering.len() < p.max_people {
                entering.push(i);
            }
        }
        let selected: Vec<u64> = entering.iter().map(|&i| near[i].id).collect();
        let mixtures: Vec<&[Component]> = entering.iter().map(|&i| &people[i][..]).collect();
        // Eq. 5.3: each combination η of intents scores log λ_η at its optimum plus
        // Σ log w. Start from every person's most preferred intent.
        let mut combination: Vec<usize> = mixtures
            .iter()
            .map(|c| {
                (0..c.len())
                    .max_by(|&a, &b| c[a].weight.total_cmp(&c[b].weight).then(b.cmp(&a)))
                    .unwrap_or(0)
            })
            .collect();
        let objective_of = |combination: &[usize]| {
            let chosen = combination
                .iter()
                .zip(&mixtures)
                .map(|(&k, c)| c[k].gp.clone())
                .collect();
            Objective::new(robot.clone(), chosen, coupling)
        };
        let preference = |combination: &[usize]| -> Real {
            combination
                .iter()
                .zip(&mixtures)
                .map(|(&k, c)| c[k].weight.ln())
                .sum()
        };
        let objective = objective_of(&combination);
        let (mut best, mut log_lambda) = match self.variant {
            IgpVariant::MonteCarlo => objective.best_sample(p.samples, &mut self.rng),
            // Sec. 6: seeds at (μ^R, μ^f) ± {0, 1, 2, 3}σ; the best local maximum wins.
            _ => self.multi_start(&objective),
        };
        // The paper seeks "the N* ≪ N_BIG modes that best capture Eq. 5.3" without saying
        // how; ours: one pass of coordinate ascent over the people, most significant first,
        // trying each of their other intents from the current optimum with that person moved
        // onto the intent's mean, keeping a change that raises the score.
        let mut score = log_lambda + preference(&combination);
        let mut combinations = 1;
        for (slot, intents) in mixtures.iter().enumerate() {
            for (k, intent) in intents.iter().enumerate() {
                if k == combination[slot] {
                    continue;
                }
                let mut trial = combination.clone();
                trial[slot] = k;
                let objective = objective_of(&trial);
                let mut start = best.clone();
                start[slot + 1] = intent.gp.mean.clone();
                let (x, f) = objective.maximise(start, &p.newton);
                combinations += 1;
                let trial_score = f + preference(&trial);
                if trial_score > score {
                    (best, log_lambda, score, combination) = (x, f, trial_score, trial);
                }
            }
        }
        self.clock += dt;
        // Def. 11: drive to the optimised position one sample ahead.
        let velocity = clamp_norm((best[0][0] - ego.position) / p.gp.dt, p.max_speed);
        let trajectory = best[0]
            .iter()
            .zip(objective.bodies[0].sigma())
            .zip(p.gp.times())
            .map(|((&position, sigma), t)| TrajectorySample { t, position, sigma })
            .collect();
        IgpDecision {
            command: Command::Velocity(velocity),
            trajectory,
            selected,
            ess,
            log_lambda,
            intents: combination,
            combinations,
        }
    }
}
