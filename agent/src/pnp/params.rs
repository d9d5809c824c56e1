//! Peek-and-pass's parameters: the values the paper leaves open, each with its reason, and
//! the named variants (`pnp-paper`, `pnp`, `pnp-fine`, `pnp-agile`, `pnp-omni`,
//! `pnp-omni-across`, `pnp-react`).

use crate::math::Real;
use crate::prediction::SigmaModel;

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
    /// How far a walking person's prediction samples spread across their way, as a share of
    /// how far they spread along it (PGP's σ is round: 1). Not in either paper. People stray
    /// across their way about half as far as along it: at 0.8–0.9 s at most 2.4 m/s² across
    /// against 4.0–4.8 m/s² in all, in ETH, UCY and the simulated crowds
    /// (results/fleet-one-robot/layer-sensitivity). A person at [`ACROSS_MIN_SPEED`](crate::safety::ACROSS_MIN_SPEED) or
    /// more has a way; a slower one, and robots, keep the round spread.
    pub across_spread: Real,
    /// Keeping to the side: weight (per metre) of how far from the nearest wall or shelf a
    /// candidate ends, counted up to [`PnpParams::side_reach`], added to the goal term. Not
    /// in either paper; 0 leaves it out. A robot in a hallway that keeps to one side leaves
    /// the middle, where people walk, to them (Pacchierotti, Christensen and Jensfelt, 2006,
    /// robots passing people in corridors). With no wall within reach every candidate pays
    /// the same, so open ground is unchanged.
    pub side_weight: Real,
    /// Walls farther than this from where a candidate ends count as this far (m).
    pub side_reach: Real,
    /// Within this distance of the goal (m) the side term fades linearly to nothing, so that
    /// a goal away from the walls can still be reached.
    pub side_fade: Real,
    /// The side term counts only while the wall or shelf face nearest the robot runs on this
    /// far (m) both ways along itself ([`LocalMap::nearest_wall_runs_on`](crate::map::LocalMap::nearest_wall_runs_on));
    /// 0 counts every wall. Beside walls broken by openings (shelves' end faces between aisle
    /// mouths) keeping to the side drives the robot past blind corners.
    pub side_runs_on: Real,
    /// Whether the side term measures the wall on the robot's right instead of the nearest
    /// one: how far a ray from where a candidate ends, at right angles to the right of the
    /// way to the local goal, goes before it meets a wall or shelf. Not in either paper.
    /// Robots that each keep to the nearest wall meet head-on beside the same wall whenever
    /// both started nearer it, and a keep-right rule is how traffic avoids that.
    pub side_right: bool,
    /// Whether Ψ's hidden people are scored against the robot braking once they step out
    /// (`pnp::hidden::braking_path`) instead of against the candidate
    /// driven to its end. Not in the paper. A hidden person steps out of a shadow into view:
    /// a robot that can stop before they reach it is passively safe toward them whatever it
    /// meant to do next. Scored against the whole candidate, a hypothetical person crossing
    /// the robot's way costs every candidate that drives on, and nothing the robot does while
    /// standing changes what it sees, so it stands for good (on the real floor plan a robot
    /// alone stood 288 s at a pick face).
    pub hidden_braking: bool,
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
            across_spread: 1.0,
            side_weight: 0.0,
            side_reach: 2.0,
            side_fade: 3.0,
            side_runs_on: 0.0,
            side_right: false,
            hidden_braking: false,
        }
    }
}

/// c3 with peeking on: the laned study's choice (`results/laned/REPORT.md`). The robot's
/// median average speed rose from 1.20 m/s at 1/(c1·c3) = 10⁻⁴ to a plateau of 1.35–1.37 m/s
/// from 10⁻² on; 10⁻² (c3 = 100) was the smallest ratio on the plateau (within 0.02 m/s of
/// the best median), and the one with the fewest robot-caused contacts there. With the
/// hallway closed behind the robot's start the plateau is 1.34–1.37 m/s and 10⁻² lies 0.03
/// below the best; c3 is kept (the report says why).
pub const PEEK_C3: Real = 100.0;
/// c3 with peeking off ("c3 high", as the paper turns it off).
pub const NO_PEEK_C3: Real = 10_000.0;

/// `pnp-side`'s [`PnpParams::side_weight`] (m² of goal term per metre from the nearest wall).
pub const SIDE_WEIGHT: Real = 4.0;

/// `pnp-side`'s [`PnpParams::side_runs_on`] (m): about what the robot covers in its plan's
/// first 1.5 s at 1 m/s. A development build that did not yet count concave corners as
/// running on gave, at 1.5 m and 1 m, 35.5 and 37.5 tasks per run in the narrow warehouse
/// (20 robots, tuning seeds 1–4; without the rule 30.8) and 25.7 and 22.7 in the hallway
/// fleet (seeds 1–6; without the rule 26.2).
pub const SIDE_RUNS_ON: Real = 1.5;

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
    /// and finer steps near ahead (±5°, ±10°, ±20°, ±40°) 59.5 / 59.5 s. The committed code
    /// gives 5.05 tasks/min, 7.8 contacts and 58.1 / 59.8 s (results/pnp-warehouse/REPORT.md).
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

    /// `pnp-omni` with the prediction samples spread across a walking person's way half as
    /// far as along it (`pnp-omni-across`, [`PnpParams::across_spread`] 0.5). With PGP's round
    /// spread, people running by in the next lane at 2.5–3 m/s keep `pnp-omni` backing away
    /// from its goal (16 % of its plans at 3 m/s, ORCA's 5 %). On hallway tuning seeds 1–12
    /// (50 m, people at 0.5–3 m/s, the layer on) the median time to the end was 61.6 s at 1,
    /// 60.1 s at 0.7 and 59.2 s at 0.5 (ORCA 60.5 s), with personal-space entries 16.4, 17.6
    /// and 18.1 per run (ORCA 13.2): results/hallway-layer-heldout/REPORT.md.
    pub fn omni_across(peek: bool) -> Self {
        Self {
            across_spread: 0.5,
            ..Self::omni(peek)
        }
    }

    /// `pnp-omni-across` keeping to the side (`pnp-side`, [`PnpParams::side_weight`]
    /// [`SIDE_WEIGHT`]). In the hallway it rides the edge of the people's prediction
    /// samples, pulled toward the middle by a goal on the hallway's axis: 0.5–1 m from a wall
    /// where ORCA, pushed aside by the layer's yields, keeps within 0.5 m, and it enters
    /// personal space 1.3 times as often. The weight was chosen on hallway tuning seeds
    /// 1–36 (50 m, people at 0.5–3 m/s, the layer on): 1.5, 3, 4, 5 and 10 on seeds 1–12,
    /// then 3, 4 and 5 on 13–36. At 4 the robot was fastest on both sets (56.7 and 58.5 s
    /// against ORCA's 60.5 and 60.7 s) and entered personal space less often than ORCA (12.3
    /// and 13.2 per run against 13.2 and 13.8), with no robot-caused contact; at 3 it
    /// entered as often as ORCA, at 5 it was slower and caused 2 contacts, at 10 it
    /// reached the end in 65 of 72 runs (results/hallway-layer-heldout/REPORT.md). The term
    /// counts only beside walls that run on ([`SIDE_RUNS_ON`]): beside shelves' end faces
    /// broken by aisle mouths it drove the narrow warehouse's robots past blind corners
    /// (results/fleet-pnp/REPORT.md).
    pub fn side(peek: bool) -> Self {
        Self {
            side_weight: SIDE_WEIGHT,
            side_runs_on: SIDE_RUNS_ON,
            ..Self::omni_across(peek)
        }
    }

    /// `pnp-side` keeping to the wall on its right (`pnp-right`, [`PnpParams::side_right`]).
    /// In fleets `pnp-side`'s robots met head-on beside the same wall: in the hallway with no
    /// people (tuning seed 2) two of them faced each other at a pick station for over a
    /// minute while the station's line grew behind them (results/fleet-pnp-right/REPORT.md).
    pub fn right(peek: bool) -> Self {
        Self {
            side_right: true,
            ..Self::side(peek)
        }
    }

    /// `pnp-side` scoring Ψ against the robot braking once a hidden person steps out
    /// (`pnp-side-brake`, [`PnpParams::hidden_braking`]). On the real floor plan
    /// (`aws-small-warehouse`, tuning seeds 1–10) one robot alone with `pnp-side` did 0 tasks
    /// in 300 s on seed 6 and 76 over the ten seeds: at a pick face in a bay, one hypothetical
    /// person crossing the way out cost every candidate that drove on 20 times the goal term.
    /// With braking it did 99 (`pgp+orca` 97). Elsewhere, on tuning seeds, the same within
    /// what seeds vary by: the hallway (1–36, 50 and 100 m, people at 0.5–3 m/s) 58.0 and
    /// 112.1 s against 57.6 and 112.1 s, 13.1 and 24.9 personal-space entries per run
    /// against 12.9 and 25.1; the default warehouse (1–30) 24.9 tasks per run against 24.7
    /// (results/fleet-pnp/REPORT.md).
    pub fn side_brake(peek: bool) -> Self {
        Self {
            hidden_braking: true,
            ..Self::side(peek)
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
