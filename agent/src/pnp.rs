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
//! predictions with PGP's σ growth** ([`SigmaModel`], the PGP paper's σ0, β, γ, δ): sample j
//! of body i is its constant-velocity track shifted by ε_j·σ_i(t), with ε_j fixed standard
//! normal offsets. Every value the paper leaves open is a field of [`PnpParams`], with the
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
use crate::math::{Real, Vec2, clamp_norm, unit, vec2};

/// `u` turned by `angle` (rad, counter-clockwise).
fn rotate(u: Vec2, angle: Real) -> Vec2 {
    let (s, c) = angle.sin_cos();
    vec2(c * u.x - s * u.y, s * u.x + c * u.y)
}
use crate::model::{Command, EgoState, Neighbour, TrajectorySample};
use crate::prediction::{SigmaModel, predict};
use crate::visibility::Visibility;
use hidden::{Hidden, halton, hidden_risk, sample_hidden};
use predict::{Predicted, Scratch, body_risk, might_touch, social_force_rollout};
use react::Reaction;
pub use risk::cvar;
use risk::{Path, Scoring, bounds, near_any_segment};

/// The planner's parameters. The paper gives the cost's form and its tunable names; it gives
/// none of their values.
#[derive(Debug, Clone, PartialEq)]
pub struct PnpParams {
    /// The robot's top speed (m/s). The paper's robot: 3 m/s.
    pub v_max: Real,
    /// Largest linear acceleration the primitives use (m/s²): the simulated base's 1.5 m/s².
    pub a_max: Real,
    /// Largest turn rate (rad/s): the simulated base's 1 rad/s.
    pub omega_max: Real,
    /// Largest turn acceleration (rad/s²): the simulated base's 1.5 rad/s².
    pub yaw_accel_max: Real,
    /// t_f, the horizon (s). 3 s: a 3 m/s robot looks 9 m ahead, about what a person walking
    /// toward it covers in the time it needs to stop and more.
    pub horizon: Real,
    /// Speeds each segment may hold, as fractions of `v_max`.
    pub speeds: Vec<Real>,
    /// Speeds the first segment may hold instead, when not empty (fractions of `v_max`). The
    /// first segment is what the robot drives until the next plan; a finer set there lets it
    /// take the speed that people and the safety layer leave it (`pnp-fine`), while the
    /// second, a look-ahead, keeps `speeds`.
    pub first_speeds: Vec<Real>,
    /// Turn rates each segment may hold, as fractions of `omega_max`.
    pub turns: Vec<Real>,
    /// Constant segments per candidate: 2 (turn out, then straighten or hold), so that a
    /// candidate can change lanes within the horizon.
    pub segments: usize,
    /// The time grid on which paths are compared (s): PGP's 0.25 s, the step its σ growth δ is
    /// stated for. Collisions are checked exactly between grid points, each body moving
    /// straight in between (a 3 m/s robot turning at 1 rad/s strays 2 cm from the chord).
    pub step: Real,
    /// c1: weight of the squared distance to the local goal (1/m²); the unit.
    pub c1: Real,
    /// c2: weight of the collision risk. 1000: more than ten times the goal term of a
    /// standing 3 m/s robot (81 m²), so that a candidate with a likely collision never wins
    /// over a slower one.
    pub c2: Real,
    /// c3: weight of the peeking risk ρ. Chosen by the laned study ([`PEEK_C3`]).
    pub c3: Real,
    /// α of p_coll^i's CVaR: the worst tenth of a body's predicted futures.
    pub alpha: Real,
    /// α_peek of ρ's CVaR: the worst tenth of Ψ.
    pub alpha_peek: Real,
    /// ε_peek: peeking risk tolerated without cost (CVaR below it costs nothing).
    pub epsilon_peek: Real,
    /// Predicted-trajectory samples per perceived body: 32, so that α = 0.9's tail holds
    /// 3.2 of them.
    pub prediction_samples: usize,
    /// |Ψ|: hypothetical hidden people per plan (the benchmark uses 64).
    pub psi_samples: usize,
    /// The fastest a hidden person walks (m/s): the hallway's walking speed. 1.6 m/s, ISO
    /// 13855's approach speed, unless the study sets the trial's speed.
    pub hidden_speed: Real,
    /// Gap counted as contact between the robot and a body (m), beyond their radii: 0.1 m.
    /// Not in the paper; without it a path grazing a person at 0 m gap is "free", and people
    /// who step aside by a few centimetres (as the simulated ones do) are touched.
    pub clearance: Real,
    /// A hidden person's radius (m): the simulated people's 0.3 m.
    pub hidden_radius: Real,
    /// Neighbouring rays whose ranges differ by more than this bound an occlusion edge (m):
    /// a person's width, the least a shadow must have to hide one.
    pub edge_jump: Real,
    /// Sensor range used when the input carries no visibility profile (m).
    pub sensor_range: Real,
    /// x_g, the local goal: the goal, or the point this far toward it (m); `None` for
    /// v_max·t_f (the farthest a candidate reaches). The paper plans in a local costmap, and
    /// a goal 100 m away would make every other term negligible.
    pub goal_distance: Option<Real>,
    /// Weight of the mean squared distance to x_g over the grid, added to the goal term.
    /// Not in the paper: Eq. 3 scores only where a candidate ends, so within reach of the
    /// goal "wait, then drive" ends as close as "drive now" and a receding horizon keeps
    /// waiting (seen in the hallway: the robot stood 1–3 m from its goal). The mean over the
    /// path prefers arriving sooner; 0 is Eq. 3 as written.
    pub progress_weight: Real,
    /// Whether a candidate that comes within `goal_tolerance` of the goal itself has arrived
    /// and scores only its way there. Not in the paper: with the coarse speeds of a 3 m/s
    /// robot (1, 2, 3 m/s) no candidate stops within a metre of the goal, and the terminal
    /// cost punished passing through it (the robot stood 0.9 m short).
    pub arrival: bool,
    /// A candidate that comes this close to the goal (m) has arrived: the scenarios' goal
    /// tolerance, 0.5 m.
    pub goal_tolerance: Real,
    /// σ growth of the predictions (the PGP paper's values).
    pub sigma: SigmaModel,
    /// How people's mean futures are predicted.
    pub prediction: Prediction,
    /// Which speed at a predicted contact scales its loss.
    pub severity: Severity,
    /// When not empty, the candidates are a holonomic base's: each segment a world-frame
    /// velocity, its speed from `speeds` (or `first_speeds`) and its direction this far (rad)
    /// from the way to the local goal; `turns` is then unused. The paper's robot is a
    /// unicycle; the simulator's robots, and ORCA's, can step aside or back off without
    /// turning first.
    pub directions: Vec<Real>,
}

/// How a predicted contact is scored: by which speed its loss is scaled, if any.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Severity {
    /// Every contact loses 1, whenever it comes and however fast: p_coll^i is CVaR_α of the
    /// collision indicator, the paper's "chance of collision" (Eq. 5).
    Indicator,
    /// How fast the two close (a fast walker from behind counts: the paper's "rear-end
    /// panic").
    Closing,
    /// How fast the robot itself drives toward the other (the product's "robot-caused"):
    /// people who would walk into a standing robot cost nothing.
    Driving,
}

/// How perceived people's mean futures are predicted (the paper uses an S-GAN, which is not
/// available here). Robots are extrapolated at constant velocity, or along their shared
/// intents, either way.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Prediction {
    /// Each person walks on at their perceived velocity.
    ConstantVelocity,
    /// A Social Force rollout (PySocialForce's force law, `social_force`): each person relaxes
    /// toward their perceived velocity (0.5 s) and is pushed by the others and by the robot,
    /// which is assumed to keep its present velocity; walls are left out. On the 0.25 s grid
    /// (PySocialForce's own effective step is 0.4 s).
    SocialForce,
    /// Predictions that react to each candidate (`react`): every person near a candidate's
    /// path is rolled out against the robot driving that candidate, pushed by the others as
    /// in a shared rollout of the people among themselves. People give way to a robot that
    /// commits to passing; constant-velocity predictions never do.
    Reactive,
}

impl Default for PnpParams {
    fn default() -> Self {
        Self {
            v_max: 1.0,
            a_max: 1.5,
            omega_max: 1.0,
            yaw_accel_max: 1.5,
            horizon: 3.0,
            speeds: vec![0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0],
            first_speeds: Vec::new(),
            turns: vec![-1.0, -0.5, 0.0, 0.5, 1.0],
            segments: 2,
            step: 0.25,
            c1: 1.0,
            c2: 1000.0,
            c3: PEEK_C3,
            alpha: 0.9,
            alpha_peek: 0.9,
            epsilon_peek: 0.1,
            prediction_samples: 32,
            psi_samples: 64,
            hidden_speed: 1.6,
            clearance: 0.1,
            hidden_radius: 0.3,
            edge_jump: 0.6,
            sensor_range: 10.0,
            goal_distance: None,
            progress_weight: 1.0,
            arrival: true,
            goal_tolerance: 0.5,
            sigma: SigmaModel::default(),
            prediction: Prediction::ConstantVelocity,
            severity: Severity::Closing,
            directions: Vec::new(),
        }
    }
}

/// c3 with peeking on: the laned study's choice (`results/laned/REPORT.md`). The robot's
/// median average speed rises from 1.20 m/s at 1/(c1·c3) = 10⁻⁴ to a plateau of 1.35–1.37 m/s
/// from 10⁻² on; 10⁻² (c3 = 100) is the smallest ratio on the plateau (within 0.02 m/s of the
/// best median), and the one with the fewest robot-caused contacts there.
pub const PEEK_C3: Real = 100.0;
/// c3 with peeking off ("c3 high", as the paper turns it off).
pub const NO_PEEK_C3: Real = 10_000.0;

impl PnpParams {
    /// The defaults with peeking on or off.
    pub fn peeking(on: bool) -> Self {
        Self {
            c3: if on { PEEK_C3 } else { NO_PEEK_C3 },
            ..Self::default()
        }
    }

    /// Eq. 3 as written (`pnp-paper`): a collision costs its indicator, contact is touching,
    /// and only where a candidate ends counts toward the goal. The values the paper leaves
    /// open are the defaults'.
    pub fn paper(peek: bool) -> Self {
        Self {
            severity: Severity::Indicator,
            clearance: 0.0,
            progress_weight: 0.0,
            arrival: false,
            ..Self::peeking(peek)
        }
    }

    /// The defaults with the first segment's speed in sixths of `v_max` (`pnp-fine`): 7 × 5
    /// first segments, each followed by the 4 × 5 second ones, 700 candidates. With a third
    /// of `v_max` between speeds (1 m/s for the hallway's 3 m/s robot) the robot either
    /// drives at a speed that carries it into people or one that holds it back, and under
    /// the safety layer, whose separation grows with speed, the speed it may keep is often
    /// between them. On hallway tuning seeds 1–6 (50 m, people at 0.5–3 m/s, the layer on),
    /// sixths gave a median 79 s against 94 s and 40 % fewer person-caused contacts;
    /// ninths for both segments (2,500 candidates) 72.5 s (results/hallway-layer-heldout).
    pub fn fine(peek: bool) -> Self {
        Self {
            first_speeds: (0..=6).map(|i| Real::from(i) / 6.0).collect(),
            ..Self::peeking(peek)
        }
    }

    /// `pnp` with a 1.5 s horizon and the first segment's speed in twelfths of `v_max`
    /// (`pnp-agile`): 13 × 5 first segments of 0.75 s, each followed by the 4 × 5 second
    /// ones, 1,300 candidates on a 6-point grid. The paper leaves t_f open. Under the safety
    /// layer the near term is the layer's, and constant-velocity predictions 3 s out mostly
    /// foresee meetings that people resolve themselves, so the 3 s horizon holds the robot
    /// back for them. On hallway tuning seeds 1–12 (50 m, people at 0.5–3 m/s, the layer on)
    /// the median time to the end fell from `pnp-fine`'s 79.0 / 86.2 s (seeds 1–6 / 7–12) to
    /// 63.8 / 62.9 s; a 1.5 s horizon with `pnp-fine`'s sixths gave 66.9 / 73.5 s, with
    /// sixths for the second segment too 63.2 / 65.5 s (results/hallway-layer-heldout).
    pub fn agile(peek: bool) -> Self {
        Self {
            horizon: 1.5,
            first_speeds: (0..=12).map(|i| Real::from(i) / 12.0).collect(),
            ..Self::peeking(peek)
        }
    }

    /// `pnp-agile` for a holonomic base (`pnp-omni`): each segment a velocity, at 0, ±10°,
    /// ±20°, ±40°, ±90° or 180° from the way to the local goal, the first segment's speed in
    /// twelfths of `v_max` and the second's in thirds (standing still once): 121 first
    /// segments, each followed by 31 second ones, 3,751 candidates. The simulator's robots
    /// are holonomic and ORCA's velocities use that; `pnp-agile`'s unicycle candidates cannot
    /// step aside or back off without turning first, so when someone came at it the robot
    /// stopped and turned while they walked into it. In the default warehouse (tuning seeds
    /// 1–4) ten directions gave 4.90 tasks/min and 4.2 person-caused contacts per run against
    /// `pnp-agile`'s 4.30 and 39.0 (`pgp+orca`: 4.55 and 4.2); eight evenly spread, 4.65 and
    /// 5.2. In the hallway (tuning seeds 1–6 / 7–12, 50 m, the layer on) the median time was
    /// 57.4 / 60.1 s against `pnp-agile`'s 63.8 / 62.9 s; eight evenly spread gave 65.3 / 69.4 s
    /// and finer steps near ahead (±5°, ±10°, ±20°, ±40°) 59.5 / 59.5 s
    /// (results/pnp-warehouse/REPORT.md).
    pub fn omni(peek: bool) -> Self {
        Self {
            directions: [
                0.0, 10.0, -10.0, 20.0, -20.0, 40.0, -40.0, 90.0, -90.0, 180.0,
            ]
            .iter()
            .map(|d: &Real| d.to_radians())
            .collect(),
            ..Self::agile(peek)
        }
    }

    /// The defaults with predictions that react to each candidate (`pnp-react`).
    pub fn reactive(peek: bool) -> Self {
        Self {
            prediction: Prediction::Reactive,
            ..Self::peeking(peek)
        }
    }
}

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
    /// (v, ω) fractions per segment, per candidate.
    primitives: Vec<Vec<(Real, Real)>>,
    /// The distinct sequences of turn fractions among the candidates, and each candidate's.
    /// A candidate's heading depends on its turns alone, so candidates that differ only in
    /// speed share one heading track.
    turn_sequences: Vec<Vec<Real>>,
    turns_of: Vec<usize>,
    /// Standard normal offsets ε_j of the prediction samples, and their lengths.
    offsets: Vec<(Vec2, Real)>,
    /// Points of the unit cube for Ψ (edge position, heading, speed).
    psi_units: Vec<[Real; 3]>,
    // Scratch, reused between plans.
    paths: Vec<Vec2>,
    /// Per turn sequence, the unit heading after each integration substep.
    headings: Vec<Vec2>,
    predicted: Vec<Predicted>,
    /// The shared rollout of reactive predictions, and one body's reaction to a candidate.
    reaction: Reaction,
    reacting: Predicted,
    hidden: Vec<Hidden>,
    scratch: Scratch,
    /// (goal term, candidate), in scoring order.
    order: Vec<(Real, usize)>,
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
    /// The way to the local goal (unit), which holonomic candidates' directions are from.
    toward: Vec2,
    /// Score every candidate in full, without cutting any short (the tests' reference).
    exhaustive: bool,
    /// The perceived bodies in the order they are asked about a candidate's risk, and each
    /// one's p_coll^i for the candidate being scored.
    body_order: Vec<usize>,
    risks: Vec<Real>,
}

impl Pnp {
    /// A planner with `params`.
    pub fn new(params: PnpParams) -> Self {
        let segment_set = |speeds: &[Real]| -> Vec<(Real, Real)> {
            if params.directions.is_empty() {
                speeds
                    .iter()
                    .flat_map(|&v| params.turns.iter().map(move |&w| (v, w)))
                    .collect()
            } else {
                // Standing still has no direction: once.
                speeds
                    .iter()
                    .flat_map(|&v| {
                        let ways = if v == 0.0 {
                            &params.directions[..1]
                        } else {
                            &params.directions[..]
                        };
                        ways.iter().map(move |&a| (v, a))
                    })
                    .collect()
            }
        };
        let later = segment_set(&params.speeds);
        let first = if params.first_speeds.is_empty() {
            later.clone()
        } else {
            segment_set(&params.first_speeds)
        };
        let mut primitives: Vec<Vec<(Real, Real)>> = vec![Vec::new()];
        for k in 0..params.segments.max(1) {
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
            params,
            primitives,
            turn_sequences,
            turns_of,
            offsets,
            psi_units,
            paths: Vec::new(),
            headings: Vec::new(),
            predicted: Vec::new(),
            reaction: Reaction::default(),
            reacting: Predicted::default(),
            hidden: Vec::new(),
            scratch: Scratch::default(),
            order: Vec::new(),
            allowed: Vec::new(),
            first_segments: Vec::new(),
            local: LocalMap::default(),
            own: Visibility::default(),
            warm: None,
            toward: vec2(1.0, 0.0),
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
        self.primitives.len()
    }

    /// The command that drives segment `(v, w)` (fractions; a direction in rad if holonomic).
    fn segment_command(&self, (v, w): (Real, Real)) -> Command {
        let p = &self.params;
        if p.directions.is_empty() {
            Command::Unicycle {
                speed: v * p.v_max,
                yaw_rate: w * p.omega_max,
            }
        } else {
            Command::Velocity(rotate(self.toward, w) * (v * p.v_max))
        }
    }

    /// Marks the candidates whose first segment (what the robot executes until the next plan)
    /// the safety layer judges best: those it lets through untouched if any, else those it
    /// admits if any, else all of them (the layer then acts on the best). All of them without
    /// a judge.
    fn mark_allowed(&mut self, judge: Option<&dyn Fn(Command) -> Admission>) {
        self.allowed.clear();
        self.allowed.resize(self.primitives.len(), true);
        let Some(judge) = judge else {
            return;
        };
        self.first_segments.clear();
        let mut best = Admission::Refused;
        for primitive in &self.primitives {
            let Some(&first) = primitive.first() else {
                continue;
            };
            if !self.first_segments.iter().any(|(seg, _)| *seg == first) {
                let a = judge(self.segment_command(first));
                best = best.max(a);
                self.first_segments.push((first, a));
            }
        }
        if best == Admission::Refused {
            return;
        }
        for (c, primitive) in self.primitives.iter().enumerate() {
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
        let to_goal = goal - ego.position;
        self.toward = if to_goal.norm() > 1e-9 {
            to_goal / to_goal.norm()
        } else {
            unit(ego.heading)
        };
        self.mark_allowed(judge);
        let p = &self.params;
        let n = (p.horizon / p.step).round().max(1.0) as usize;
        let dt = p.horizon / n as Real;
        self.roll_out(ego, n, dt);
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
        let r = vec2(reach + 1.0, reach + 1.0);
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
        self.order.clear();
        for c in 0..self.primitives.len() {
            let path = &self.paths[c * (n + 1)..(c + 1) * (n + 1)];
            // A candidate that arrives (within the tolerance of the goal itself) is done there:
            // it scores what it cost to get there, nothing for overshooting afterwards.
            let arrives = if p.arrival && local_goal == goal {
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
            let goal_term = terminal + p.progress_weight * running;
            self.order.push((goal_term, c));
        }
        self.order
            .sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        if let Some(warm) = self.warm.filter(|&c| self.allowed.get(c) == Some(&true))
            && let Some(at) = self.order.iter().position(|&(_, c)| c == warm)
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
        for &(goal_term, c) in &self.order {
            if !self.allowed[c] {
                continue;
            }
            let path = &self.paths[c * (n + 1)..(c + 1) * (n + 1)];
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
            if path
                .windows(2)
                .any(|w| near_any_segment(w[0], w[1], self.local.segments(), ego.radius))
            {
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
            for (at, &i) in self.body_order.iter().enumerate() {
                let body = &self.predicted[i];
                let body = if reactive && self.reaction.reacts(i) {
                    // People the candidate does not come near without their reaction are
                    // left out: the robot's push is taken to move them away, not closer.
                    if !might_touch(swept, body, &mut self.scratch.gaps) {
                        continue;
                    }
                    self.reaction.respond(i, path, body, &mut self.reacting);
                    &self.reacting
                } else {
                    body
                };
                let Some(risk) = body_risk(
                    swept,
                    body,
                    &self.offsets,
                    p.alpha,
                    scoring,
                    budget(goal_term, so_far, best.0),
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
            let psi = hidden_risk(
                swept,
                &self.hidden,
                dt,
                contact,
                p.alpha_peek,
                scoring,
                &mut self.scratch.losses,
            );
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
        let first = self.primitives[c][0];
        let command = self.segment_command(first);
        let v = first.0;
        let path = &self.paths[c * (n + 1)..(c + 1) * (n + 1)];
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

    /// Every candidate's path on the grid, executed as the base executes unicycle commands
    /// (speed and turn rate approach each segment's within the acceleration limits).
    fn roll_out(&mut self, ego: &EgoState, n: usize, dt: Real) {
        if !self.params.directions.is_empty() {
            self.roll_out_holonomic(ego, n, dt);
            return;
        }
        let p = &self.params;
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
    fn roll_out_holonomic(&mut self, ego: &EgoState, n: usize, dt: Real) {
        let p = &self.params;
        let segments = self.primitives.first().map_or(1, Vec::len);
        let per_segment = n.div_ceil(segments);
        let substeps = (dt / 0.05 - 1e-9).ceil().max(1.0) as usize;
        let h = dt / substeps as Real;
        self.paths.clear();
        self.paths.reserve(self.primitives.len() * (n + 1));
        // Each direction's unit vector once per plan (the candidates hold the angle).
        let ways: Vec<(Real, Vec2)> = p
            .directions
            .iter()
            .map(|&a| (a, rotate(self.toward, a)))
            .collect();
        let way = |a: Real| {
            ways.iter()
                .find(|w| w.0 == a)
                .map_or_else(|| rotate(self.toward, a), |w| w.1)
        };
        let mut boundary = vec![(ego.position, ego.velocity); segments + 1];
        let grid = (n, per_segment);
        for (c, primitive) in self.primitives.iter().enumerate() {
            let (shared, from) =
                start_path(&mut self.paths, &self.primitives, c, grid, ego.position);
            let (mut position, mut v) = boundary[shared.min(segments)];
            for k in from..n {
                let segment = (k / per_segment).min(segments - 1);
                if k % per_segment == 0 {
                    boundary[segment] = (position, v);
                }
                let (fv, a) = primitive[segment];
                let target = way(a) * (fv * p.v_max);
                for _ in 0..substeps {
                    v += clamp_norm(target - v, p.a_max * h);
                    position += v * h;
                }
                self.paths.push(position);
            }
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
        for slot in &mut self.predicted {
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

mod hidden;
mod predict;
mod react;
mod risk;
#[cfg(test)]
mod tests;
