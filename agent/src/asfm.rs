//! Anticipatory Social Force (`asfm`): the planner of "Anticipatory Robot Navigation:
//! Incorporating Estimated Obstacle Behaviors with the Social Force Model" (Liu et al.,
//! `../shared/papers/anticipatory-social-force.md`).
//!
//! Some people step aside for a robot and others do not. Per tracked body the robot filters the
//! noisy observed position (Kalman filter, Eqs. 7–10) and estimates how strongly that body
//! avoids it: a posterior over samples of the Social Force strength A_o (Eqs. 12–14), whose
//! mean is Â_o. It then chooses its desired velocity for the next H steps by minimising
//! J = J_t + P_v + P_d (Eqs. 15–19) over a Social Force rollout of itself and the bodies, each
//! with its Â_o, and drives with the Social Force control law (Eq. 11).
//!
//! Two cycles (Fig. 2): every control step the filter, the estimate and the control law; every
//! [`AsfmParams::update_period`] the desired-velocity optimisation, warm-started from the
//! previous solution.
//!
//! Beyond the paper (one point obstacle with a known goal, no walls): many bodies, each with its
//! own filter and posterior; bodies with radii (distances are between surfaces); walls and
//! shelves push the robot with Eq. 3; a body whose goal is unknown walks toward the velocity it
//! intends, estimated as a slow average of its filtered velocity.

use crate::map::{LocalMap, StaticMap};
use crate::math::{Real, Vec2, clamp_norm, vec2};
use crate::model::{EgoState, Neighbour, TrajectorySample};
use crate::prediction::SigmaModel;
use model::{attraction, repulsion};
use optimise::{Body, Scene, Solution, optimise, wall_push};
use track::{Heading, Tracked};

/// The planner's parameters. Table I and II of the paper where it gives them; every value it
/// leaves open is named here with its value and why.
#[derive(Debug, Clone, PartialEq)]
pub struct AsfmParams {
    /// Δt, the model's time slot and H's step (s). Table II: 0.1.
    pub dt: Real,
    /// A_r, the strength of the robot's repulsion (Eq. 3). Table II: 20.
    pub robot_strength: Real,
    /// B, the range of every repulsion (m). Table II: 2.
    pub range: Real,
    /// τ, the relaxation time (s). Table II: 0.1.
    pub tau: Real,
    /// v^max of the robot (m/s). Table I: 1.5. The robot's speed is capped at it (a base
    /// limit; Eq. 11 has no cap).
    pub v_max: Real,
    /// v^max of the people, for Eq. 5 toward a known goal (m/s). Table I: 1.5.
    pub people_speed: Real,
    /// H, the desired velocities optimised. Table II: 15.
    pub horizon: usize,
    /// a of Eq. 19. Table II: 20.
    pub distance_weight: Real,
    /// k_d of Eq. 19. Table II: 20.
    pub distance_sharpness: Real,
    /// d_min of Eq. 19 (m). Table II: 1. With bodies it is the gap between surfaces.
    pub d_min: Real,
    /// Σ of Eq. 13, per axis (m²). Table II: 0.1·I. (The paper's noise is N(0, 0.1²), variance
    /// 0.01; the table's 0.1 is used as written.)
    pub likelihood_variance: Real,
    /// σ of the prior N(0, σ²) over A_o. Open; 10: puts the paper's A_o = 20 at 2σ, so the
    /// prior leans toward "does not avoid" as the paper wants, yet 20 stays reachable.
    pub prior_sigma: Real,
    /// The samples A_o^i: `samples` values evenly from `-sample_span` to `sample_span`. Open;
    /// ±40 in steps of 1 (81): twice the paper's largest A_o, symmetric as N(0, σ²) is.
    pub sample_span: Real,
    /// How many samples.
    pub samples: usize,
    /// P at first sight (m²). Open; 0.01, the variance of the paper's noise.
    pub kalman_p0: Real,
    /// R of Eq. 8 (m²). Open; 0.01, the variance of the paper's noise.
    pub kalman_r: Real,
    /// Added to P after each update (m²). Eq. 9 has none: 0.
    pub process_noise: Real,
    /// The long cycle: how often Â_o is read and the desired velocity optimised (s). Open;
    /// 0.2 s: five updates in the paper's one-second encounter.
    pub update_period: Real,
    /// ε of Eqs. 16–17. Open; 1e-3 (m and m/s): small against every length and speed here.
    pub epsilon: Real,
    /// Within this distance the robot is "at" its goal: I(g ≠ r) of Eq. 16 is 0, and the
    /// robot stops (m). Open; 0.1.
    pub goal_tolerance: Real,
    /// L-BFGS iterations per optimisation. Open; 20: on the benchmark's scene J is then
    /// within 0.1 % of 40 iterations' in most updates (10 leave up to 11 %).
    pub max_iters: u64,
    /// L-BFGS memory. Open; 7.
    pub lbfgs_memory: usize,
    /// Time constant of a body's intended velocity when its goal is unknown (s). Ours; 2 s.
    pub intent_time: Real,
    /// A body unseen for this long is forgotten (s). Ours; 1 s.
    pub forget_after: Real,
    /// At most this many bodies, the nearest, enter the rollout. Ours; 10.
    pub rollout_bodies: usize,
    /// Walls farther than this do not push the robot (m). Ours; 3·B: e⁻³ of the push at 0.
    pub wall_reach: Real,
    /// A of Eq. 3 for walls and shelves; `None` for the robot's own A_r, as the paper reads
    /// ("for static obstacles, we only employ (3)").
    pub wall_strength: Option<Real>,
    /// J_t's time-to-go at the horizon's end (Eq. 16's first term).
    pub time_to_go: TimeToGo,
    /// Before each optimisation, also weigh the constant desired velocities of
    /// [`optimise::RESTART_TURNS`] × [`optimise::RESTART_SPEEDS`] and standing still against
    /// the warm start, and start from the one with the lowest J. Ours; off in the paper, which
    /// warm-starts only.
    pub restarts: bool,
}

impl Default for AsfmParams {
    fn default() -> Self {
        Self {
            dt: 0.1,
            robot_strength: 20.0,
            range: 2.0,
            tau: 0.1,
            v_max: 1.5,
            people_speed: 1.5,
            horizon: 15,
            distance_weight: 20.0,
            distance_sharpness: 20.0,
            d_min: 1.0,
            likelihood_variance: 0.1,
            prior_sigma: 10.0,
            sample_span: 40.0,
            samples: 81,
            kalman_p0: 0.01,
            kalman_r: 0.01,
            process_noise: 0.0,
            update_period: 0.2,
            epsilon: 1e-3,
            goal_tolerance: 0.1,
            max_iters: 20,
            lbfgs_memory: 7,
            intent_time: 2.0,
            forget_after: 1.0,
            rollout_bodies: 10,
            wall_reach: 6.0,
            wall_strength: None,
            time_to_go: TimeToGo::Paper,
            restarts: false,
        }
    }
}

/// J_t's time-to-go at the horizon's end.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TimeToGo {
    /// Eq. 16: |‖g − r‖ / (V + ε)|, V the speed toward the goal (Eq. 17).
    Paper,
    /// ‖g − r‖ / v^max: the time left at top speed. Smooth and bounded, and it falls only
    /// as the robot gets nearer; Eq. 16's falls as well when the robot drives away fast
    /// (V < −ε) and has a pole at V = −ε.
    AtTopSpeed,
}

/// The named variants of the planner (agent/README.md).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum AsfmVariant {
    /// `asfm`: the paper's equations and parameters ([`AsfmParams::default`]).
    Paper,
    /// `asfm-q`: the paper's, with [`ASFM_Q_PROCESS_NOISE`] added to the filter's P.
    ProcessNoise,
    /// `asfm-crowd`: made to work among many people ([`AsfmParams::crowd`]).
    Crowd,
}

impl AsfmVariant {
    /// The variant's parameters.
    pub fn params(self) -> AsfmParams {
        match self {
            Self::Paper => AsfmParams::default(),
            Self::ProcessNoise => AsfmParams {
                process_noise: ASFM_Q_PROCESS_NOISE,
                ..AsfmParams::default()
            },
            Self::Crowd => AsfmParams::crowd(),
        }
    }
}

impl AsfmParams {
    /// A of Eq. 3 for walls and shelves: the field `wall_strength` when set, else A_r.
    pub fn wall_strength(&self) -> Real {
        self.wall_strength.unwrap_or(self.robot_strength)
    }

    /// `asfm-crowd`: the paper's model and objective with the lengths of a crowd. The paper
    /// has one obstacle; summed over a crowd, its repulsion (A_r = 20 reaching B = 2 m) and
    /// d_min = 1 m between surfaces leave no way through (open space: 25 % success at 0.1
    /// people/m², none from 0.2). Each change, with its reason:
    /// - `range` B = 0.5 m: a person 1 m away pushes e⁻² of the push at contact (e^−0.5 with
    ///   the paper's B), so only the people next to the robot shape its path;
    /// - `d_min` = 0.3 m between surfaces: a person's personal space, where the paper's 1 m
    ///   is more than the gaps of a crowd at 0.2 people/m²;
    /// - `wall_reach` = 3·B as in the paper;
    /// - J_t's time-to-go [`TimeToGo::AtTopSpeed`]: Eq. 16's also falls when the robot
    ///   drives away from its goal fast (V < −ε), with a pole at V = −ε; with one obstacle
    ///   the optimum never goes there, among many people it can;
    /// - `process_noise` [`ASFM_Q_PROCESS_NOISE`] (as `asfm-q`): with Eq. 9 as written the
    ///   gain falls as 1/(n + 1), so after a few seconds a track follows the filter's model
    ///   rather than what is seen. A person whose Â_o came out negative is drawn toward the
    ///   robot by that model, and the track ends up on the robot while the person walks
    ///   away: a ghost in every rollout, whose P_d (10⁶–10⁷) the optimiser flees for the rest
    ///   of the run (open space, 0.2 people/m², seed 3: the robot drifts away from its goal
    ///   with nobody within 3 m);
    /// - `wall_strength` A_w = 2.0: with A_r = 20 and B = 0.5 m a shelf pushes harder
    ///   than the attraction can pull (v^max/τ = 10 m/s² at 1 m/s) within 0.35 m of it, so in
    ///   a 2.5 m aisle the robot cannot pass a person who walks its middle at d_min, and
    ///   retreats ahead of them (results/pnp-warehouse/REPORT.md). Chosen in the default
    ///   warehouse among 1, 2 and 3 (seeds 1–20: the same work within 2 %, the fewest
    ///   person-caused contacts at 2) and 5, 10 and 20 (seeds 1–10: less work);
    /// - `restarts`: the warm start is a local optimum's neighbourhood, and after a crowd has
    ///   pushed the robot about it can be the wrong one (driving away from the goal). Weighing
    ///   a fan of straight starts against it is the fallback when the way it was taking has
    ///   closed.
    ///
    /// Process noise and restarts were chosen on open-space seeds 1–100 at 0.1–0.6 people/m²
    /// (results/open-space/REPORT.md).
    pub fn crowd() -> Self {
        let range = 0.5;
        Self {
            range,
            d_min: 0.3,
            wall_reach: 3.0 * range,
            wall_strength: Some(2.0),
            time_to_go: TimeToGo::AtTopSpeed,
            process_noise: ASFM_Q_PROCESS_NOISE,
            restarts: true,
            ..Self::default()
        }
    }
}

/// The process noise of the `asfm-q` variant (m² per observation, equal to R): P grows by it
/// after each update, so the gain settles at 0.62 instead of falling as 1/(n + 1) (Eq. 9 as
/// written), and the filter keeps following a person who turns (within 0.5 m of one walking a
/// 5 m circle at 1.2 m/s, seen every 0.4 s; 11 m off without it, after 24 s).
pub const ASFM_Q_PROCESS_NOISE: Real = 1e-2;

/// How Â_o is set.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Estimation {
    /// The Bayesian estimate (the paper's method).
    Estimated,
    /// Fixed at this value (the paper's comparison methods, Â_o = 0 and Â_o = 20).
    Fixed(Real),
}

/// One control step's output.
#[derive(Debug, Clone, PartialEq)]
pub struct AsfmStep {
    /// v_r(t + Δt) of Eq. 11, capped at v^max (the velocity command).
    pub command: Vec2,
    /// The desired velocity v⁰_r in use.
    pub desired: Vec2,
    /// The robot's rolled-out path from the last optimisation, from now on.
    pub trajectory: Vec<TrajectorySample>,
    /// Whether this step ran the long cycle.
    pub updated: bool,
}

/// The planner.
#[derive(Debug, Clone)]
pub struct Asfm {
    params: AsfmParams,
    estimation: Estimation,
    samples: Vec<Real>,
    tracks: Vec<Tracked>,
    goals: Vec<(u64, Vec2)>,
    /// The H desired velocities of the last optimisation and how many steps ago it ran.
    sequence: Vec<Vec2>,
    path: Vec<Vec2>,
    since_update: Option<usize>,
    /// The robot's position and radius at the last step.
    before: Option<(Vec2, Real)>,
    scene: Scene,
    local: LocalMap,
    sigma: SigmaModel,
    last: Option<Solution>,
}

impl Asfm {
    /// A planner estimating Â_o (the paper's method).
    pub fn new(params: AsfmParams) -> Self {
        Self::with_estimation(params, Estimation::Estimated)
    }

    /// A planner whose Â_o is set by `estimation`.
    pub fn with_estimation(params: AsfmParams, estimation: Estimation) -> Self {
        let n = params.samples.max(2);
        let span = params.sample_span;
        let samples = (0..n)
            .map(|i| -span + 2.0 * span * i as Real / (n - 1) as Real)
            .collect();
        Self {
            params,
            estimation,
            samples,
            tracks: Vec::new(),
            goals: Vec::new(),
            sequence: Vec::new(),
            path: Vec::new(),
            since_update: None,
            before: None,
            scene: Scene::default(),
            local: LocalMap::default(),
            sigma: SigmaModel::default(),
            last: None,
        }
    }

    /// The parameters in use.
    pub fn params(&self) -> &AsfmParams {
        &self.params
    }

    /// Tells the planner where body `id` is going (the paper assumes goals are known).
    pub fn know_goal(&mut self, id: u64, goal: Vec2) {
        self.goals.retain(|(i, _)| *i != id);
        self.goals.push((id, goal));
    }

    /// Â_o per tracked body id.
    pub fn estimates(&self) -> impl Iterator<Item = (u64, Real)> + '_ {
        self.tracks.iter().map(|t| (t.id, self.strength(t)))
    }

    /// Per tracked body: its id, Â_o and how long it has been tracked (s).
    pub fn tracked(&self) -> impl Iterator<Item = (u64, Real, Real)> + '_ {
        self.tracks.iter().map(|t| (t.id, self.strength(t), t.age))
    }

    /// The posterior over the samples for body `id`, with the samples.
    pub fn posterior(&self, id: u64) -> Option<(Vec<Real>, Vec<Real>)> {
        self.tracks
            .iter()
            .find(|t| t.id == id)
            .map(|t| (self.samples.clone(), t.posterior()))
    }

    /// The filtered position and velocity of body `id`.
    pub fn filtered(&self, id: u64) -> Option<(Vec2, Vec2)> {
        self.tracks
            .iter()
            .find(|t| t.id == id)
            .map(|t| (t.filtered, t.velocity))
    }

    /// The last optimisation's result.
    pub fn last_solution(&self) -> Option<&Solution> {
        self.last.as_ref()
    }

    fn strength(&self, t: &Tracked) -> Real {
        match self.estimation {
            Estimation::Estimated => t.estimate,
            Estimation::Fixed(a) => a,
        }
    }

    /// One control step: `neighbours` as perceived now (positions possibly noisy), `dt` since
    /// the last step.
    pub fn step(
        &mut self,
        ego: &EgoState,
        neighbours: &[Neighbour],
        map: &StaticMap,
        goal: Vec2,
        dt: Real,
    ) -> AsfmStep {
        self.track(ego, neighbours, dt);
        let p = &self.params;
        let h = p.horizon.max(1);
        let every = ((p.update_period / p.dt).round() as usize).max(1);
        let due = match self.since_update {
            None => true,
            Some(k) => k >= every || k >= h,
        };
        let mut updated = false;
        if due {
            self.update(ego, map, goal);
            updated = true;
        }
        let k = self.since_update.unwrap_or(0).min(h - 1);
        let p = &self.params;
        let desired = self.sequence.get(k).copied().unwrap_or_default();
        // Eq. 11 with Eq. 2: Eq. 3 from every tracked body and wall, Eq. 4 toward v⁰_r.
        let mut a = attraction(desired, ego.velocity, p.tau)
            + wall_push(ego.position, ego.radius, &self.scene.walls, p);
        for t in &self.tracks {
            if t.unseen == 0.0 {
                a += repulsion(
                    ego.position - t.filtered,
                    ego.radius + t.radius,
                    p.robot_strength,
                    p.range,
                );
            }
        }
        let command = if (goal - ego.position).norm() <= p.goal_tolerance {
            vec2(0.0, 0.0)
        } else {
            clamp_norm(ego.velocity + a * dt, p.v_max)
        };
        let trajectory = self
            .path
            .iter()
            .skip(k + 1)
            .enumerate()
            .zip(self.sigma.constant_speed(command.norm()))
            .map(|((i, &position), sigma)| TrajectorySample {
                t: (i + 1) as Real * p.dt,
                position,
                sigma,
            })
            .collect();
        self.since_update = Some(self.since_update.unwrap_or(0) + 1);
        self.before = Some((ego.position, ego.radius));
        AsfmStep {
            command,
            desired,
            trajectory,
            updated,
        }
    }

    /// Filters and estimates every perceived body; forgets those unseen too long.
    fn track(&mut self, ego: &EgoState, neighbours: &[Neighbour], dt: Real) {
        let p = &self.params;
        let fixed = match self.estimation {
            Estimation::Estimated => None,
            Estimation::Fixed(a) => Some(a),
        };
        let now = (ego.position, ego.radius);
        let before = self.before.unwrap_or(now);
        for t in &mut self.tracks {
            t.unseen += dt;
            t.age += dt;
        }
        for nb in neighbours {
            let goal = self.goals.iter().find(|(i, _)| *i == nb.id).map(|g| g.1);
            match self.tracks.iter_mut().find(|t| t.id == nb.id) {
                Some(t) if dt > 0.0 => {
                    if let Some(g) = goal {
                        t.heading = Heading::Goal(g);
                    }
                    t.observe(nb.position, dt, before, &self.samples, fixed, p);
                }
                Some(_) => {}
                None => {
                    let heading = match goal {
                        Some(g) => Heading::Goal(g),
                        None => Heading::Intended(nb.velocity),
                    };
                    self.tracks
                        .push(Tracked::new(nb, heading, &self.samples, p));
                }
            }
        }
        let forget = p.forget_after;
        self.tracks.retain(|t| t.unseen <= forget);
    }

    /// The long cycle: Â_o read, the desired velocities optimised from the shifted previous
    /// solution.
    fn update(&mut self, ego: &EgoState, map: &StaticMap, goal: Vec2) {
        let p = &self.params;
        let h = p.horizon.max(1);
        let reach = vec2(p.wall_reach, p.wall_reach);
        map.gather(
            ego.position - reach,
            ego.position + reach,
            0.0,
            &mut self.local,
        );
        self.scene.walls.clear();
        self.scene.walls.extend_from_slice(self.local.segments());
        self.scene.robot = (ego.position, ego.velocity, ego.radius);
        self.scene.goal = goal;
        // The nearest perceived bodies (ties by id).
        let mut order: Vec<(Real, u64, usize)> = self
            .tracks
            .iter()
            .enumerate()
            .filter(|(_, t)| t.unseen == 0.0)
            .map(|(i, t)| ((t.filtered - ego.position).norm(), t.id, i))
            .collect();
        order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        order.truncate(p.rollout_bodies);
        self.scene.bodies.clear();
        for &(_, _, i) in &order {
            let t = &self.tracks[i];
            let (goal, intended) = match t.heading {
                Heading::Goal(g) => (Some(g), vec2(0.0, 0.0)),
                Heading::Intended(v) => (None, v),
            };
            self.scene.bodies.push(Body {
                position: t.filtered,
                velocity: t.velocity,
                radius: t.radius,
                strength: self.strength(t),
                goal,
                intended,
            });
        }
        // Warm start: the previous sequence shifted by the steps since it was computed, its
        // last repeated; the first time, v^max toward the goal.
        let shift = self.since_update.unwrap_or(0);
        let start: Vec<Vec2> = if self.sequence.len() == h {
            (0..h)
                .map(|i| self.sequence[(i + shift).min(h - 1)])
                .collect()
        } else {
            let to = goal - ego.position;
            let v = if to.norm() > 0.0 {
                to * (0.9 * p.v_max / to.norm())
            } else {
                vec2(0.0, 0.0)
            };
            vec![v; h]
        };
        let solution = optimise(&self.scene, &start, p);
        self.sequence.clone_from(&solution.desired);
        self.path.clone_from(&solution.path);
        self.last = Some(solution);
        self.since_update = Some(0);
    }
}

pub mod model;
pub mod optimise;
#[cfg(test)]
mod tests;
pub mod track;
