//! One interface for every planner: [`PlannerStack`] runs an optional long-term planner (PGP)
//! and a short-term planner (DWA, ORCA, Social Force, one of the foIGP paper's planners,
//! peek-and-pass or anticipatory Social Force); PGP's subgoal becomes the short-term planner's
//! goal. Planners are named as on the command line: `dwa`, `orca`, `orca-nr` (ORCA taking all of
//! the avoidance of people), `sf`, `foigp` (GP mixtures),
//! `foigp-1` (one GP per person), `igp-diag`, `igp-lin`, `mc`, `pnp`, `pnp-nopeek` (and the variants `pnp-paper`, `pnp-react`, each with a
//! `-nopeek`), `asfm`, `asfm-q`, `asfm-crowd`, each optionally behind `pgp+` (the PGP
//! paper's study uses `pgp+dwa`, `pgp+orca`, `pgp+sf`).

use crate::asfm::{Asfm, AsfmParams};
use crate::dwa::{Dwa, DwaParams};
use crate::igp::{IgpParams, IgpPlanner};
use crate::map::StaticMap;
use crate::math::{Real, Vec2, clamp_norm};
use crate::model::{AgentKind, Command, EgoState, Intent, Neighbour, TrajectorySample};
use crate::orca::{Body, Orca, OrcaParams, V};
use crate::pgp::{Pgp, PgpParams};
use crate::pnp::{Admission, Pnp, PnpParams};
use crate::prediction::SigmaModel;
use crate::safety::SafeSet;
use crate::social_force::{SfAgentParams, SocialForceAgent};
use crate::visibility::Visibility;
use std::fmt;

mod spec;
pub use spec::{LocalKind, PlannerSpec, PnpVariant, UnknownPlanner};

/// Output of one planning step.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// The command to execute.
    pub command: Command,
    /// The intent to announce to the fleet.
    pub intent: Intent,
    /// PGP's evaluated candidate fan, when a PGP planner ran and recording was on.
    pub fan: Option<crate::pgp::Fan>,
}

/// Everything a planner sees in one step.
#[derive(Debug, Clone, Copy)]
pub struct PlanningInput<'a> {
    /// The robot.
    pub ego: &'a EgoState,
    /// What it perceives around it.
    pub neighbours: &'a [Neighbour],
    /// Walls and shelves.
    pub map: &'a StaticMap,
    /// Where it wants to go.
    pub goal: Vec2,
    /// Control period: time until the next plan (s).
    pub dt: Real,
    /// What the sensor sees and what it cannot, when the world reports it (body occlusion
    /// on); planners that reason about hidden people compute it from `map` and `neighbours`
    /// otherwise.
    pub visibility: Option<&'a Visibility>,
    /// The safety layer's set of admissible commands, when the robot runs the layer
    /// ([`crate::guard::Guard::plan`]): planners rank or restrict their candidates with
    /// [`SafeSet::admits`] so that the layer rarely has to override them.
    pub safety: Option<&'a SafeSet<'a>>,
}

/// Turns from a velocity command that the safe set does not admit, nearest first (rad), and
/// the speeds tried along each (fractions of the command's).
const DETOUR_TURNS: [Real; 11] = [
    0.0, 0.26, -0.26, 0.52, -0.52, 0.79, -0.79, 1.05, -1.05, 1.57, -1.57,
];
const DETOUR_SPEEDS: [Real; 3] = [1.0, 0.7, 0.4];

/// The admissible velocity command nearest `command`, for the planners whose output is one
/// velocity (ORCA, Social Force, the foIGP family, anticipatory SF): `command` itself when
/// admissible or when no safe set is given; else the first admissible of the command turned
/// by up to 90° either way and slowed to 70 % and 40 %, nearest the command first; else
/// `command` (the layer then slows it). What these planners would prefer next to their own
/// command is the velocity closest to it, as ORCA's linear program and Social Force's
/// desired velocity both rank velocities.
pub fn nearest_admissible(input: &PlanningInput<'_>, command: Command) -> Command {
    let (Some(set), Command::Velocity(v)) = (input.safety, command) else {
        return command;
    };
    if v.norm() < 1e-9 || set.admits(command) {
        return command;
    }
    let mut tried: [(Real, Vec2); DETOUR_TURNS.len() * DETOUR_SPEEDS.len()] =
        [(0.0, Vec2::zeros()); DETOUR_TURNS.len() * DETOUR_SPEEDS.len()];
    let mut n = 0;
    for turn in DETOUR_TURNS {
        let (sin, cos) = turn.sin_cos();
        let turned = Vec2::new(cos * v.x - sin * v.y, sin * v.x + cos * v.y);
        for s in DETOUR_SPEEDS {
            let candidate = turned * s;
            tried[n] = ((candidate - v).norm(), candidate);
            n += 1;
        }
    }
    // Stable: equal distances keep the order above (left before right).
    tried.sort_by(|a, b| a.0.total_cmp(&b.0));
    tried
        .iter()
        .skip(1)
        .map(|&(_, c)| Command::Velocity(c))
        .find(|&c| set.admits(c))
        .unwrap_or(command)
}

/// What a short-term planner returns: the command and the trajectory it expects.
#[derive(Debug, Clone, PartialEq)]
pub struct LocalPlan {
    /// The command.
    pub command: Command,
    /// The short-term trajectory with σ.
    pub trajectory: Vec<TrajectorySample>,
}

/// A short-term (cooperative) collision-avoidance planner driving towards a target.
pub trait LocalPlanner: Send + fmt::Debug {
    /// v^max,CCA · t^plan,CCA: where PGP should put the subgoal (m).
    fn subgoal_distance(&self) -> Real;
    /// One step towards `target`.
    fn plan(&mut self, input: &PlanningInput<'_>, target: Vec2) -> LocalPlan;
    /// Where people go in this scene (foIGP's intents); planners that do not model intents
    /// ignore it.
    fn set_destinations(&mut self, _destinations: &[Vec2]) {}
}

impl LocalPlanner for Dwa {
    fn subgoal_distance(&self) -> Real {
        self.params().v_max * self.params().t_plan
    }

    fn plan(&mut self, input: &PlanningInput<'_>, target: Vec2) -> LocalPlan {
        let admits = input.safety.map(|set| move |c: Command| set.admits(c));
        let c = Dwa::plan_within(
            self,
            input.ego,
            input.neighbours,
            input.map,
            target,
            input.dt,
            admits.as_ref().map(|f| f as &dyn Fn(Command) -> bool),
        );
        LocalPlan {
            command: Command::Unicycle {
                speed: c.speed,
                yaw_rate: c.yaw_rate,
            },
            trajectory: c.trajectory,
        }
    }
}

/// ORCA as a planner: RVO2's preferred velocity towards the target, capped at v^max, with
/// the ego's radius inflated by a safety margin.
#[derive(Debug, Clone)]
pub struct OrcaPlanner {
    orca: Orca<f64>,
    others: Vec<Body<f64>>,
    sigma: SigmaModel,
    /// Added to the ego's radius (m). ORCA leaves exactly the combined radius between agents
    /// that both follow it; people do not, so a robot needs some room. Not in the paper; ours.
    pub safety_margin: Real,
    /// The robot's share of avoiding a person (RVO2's ½, reciprocal, for `orca`).
    pub human_responsibility: Real,
}

impl OrcaPlanner {
    /// A planner with the given parameters.
    pub fn new(params: OrcaParams) -> Self {
        Self {
            orca: Orca::new(params),
            others: Vec::new(),
            sigma: SigmaModel::default(),
            safety_margin: 0.1,
            human_responsibility: 0.5,
        }
    }
}

impl LocalPlanner for OrcaPlanner {
    fn subgoal_distance(&self) -> Real {
        self.orca.params().max_speed * self.orca.params().time_horizon
    }

    fn plan(&mut self, input: &PlanningInput<'_>, target: Vec2) -> LocalPlan {
        let p = *self.orca.params();
        let body = |position: &Vec2, velocity: &Vec2, radius: Real, responsibility| Body {
            position: V::from_vec2(position),
            velocity: V::from_vec2(velocity),
            radius,
            responsibility,
        };
        let ego = body(
            &input.ego.position,
            &input.ego.velocity,
            input.ego.radius + self.safety_margin,
            0.5,
        );
        self.others.clear();
        let human = self.human_responsibility;
        self.others.extend(input.neighbours.iter().map(|n| {
            let share = if n.kind == AgentKind::Human {
                human
            } else {
                0.5
            };
            body(&n.position, &n.velocity, n.radius, share)
        }));
        let pref = clamp_norm(target - input.ego.position, p.max_speed);
        let v = self
            .orca
            .new_velocity(&ego, V::from_vec2(&pref), &self.others, input.map)
            .to_vec2();
        let command = nearest_admissible(input, Command::Velocity(v));
        LocalPlan {
            command,
            trajectory: straight(input.ego.position, v, p.time_horizon, 0.25, &self.sigma),
        }
    }
}

/// The Social Force agent as a planner.
#[derive(Debug, Clone)]
pub struct SfPlanner {
    agent: SocialForceAgent,
    sigma: SigmaModel,
    /// t^plan for the subgoal distance; Table I gives none for SF, so DWA's 2 s is used.
    t_plan: Real,
}

impl SfPlanner {
    /// A planner with the given parameters.
    pub fn new(params: SfAgentParams) -> Self {
        Self {
            agent: SocialForceAgent::new(params),
            sigma: SigmaModel::default(),
            t_plan: 2.0,
        }
    }
}

impl LocalPlanner for SfPlanner {
    fn subgoal_distance(&self) -> Real {
        self.agent.params().max_speed * self.t_plan
    }

    fn plan(&mut self, input: &PlanningInput<'_>, target: Vec2) -> LocalPlan {
        let v = self
            .agent
            .command(input.ego, input.neighbours, input.map, target, input.dt);
        LocalPlan {
            command: nearest_admissible(input, Command::Velocity(v)),
            trajectory: straight(input.ego.position, v, self.t_plan, 0.25, &self.sigma),
        }
    }
}

impl LocalPlanner for IgpPlanner {
    /// The robot's reach over the GP horizon at its preferred speed.
    fn subgoal_distance(&self) -> Real {
        let p = self.params();
        p.preferred_speed * p.gp.dt * p.gp.steps as Real
    }

    fn plan(&mut self, input: &PlanningInput<'_>, target: Vec2) -> LocalPlan {
        let d = IgpPlanner::plan(self, input.ego, input.neighbours, target, input.dt);
        LocalPlan {
            command: nearest_admissible(input, d.command),
            trajectory: d.trajectory,
        }
    }

    fn set_destinations(&mut self, destinations: &[Vec2]) {
        IgpPlanner::set_destinations(self, destinations);
    }
}

impl LocalPlanner for Pnp {
    /// The robot's reach over the horizon at top speed.
    fn subgoal_distance(&self) -> Real {
        self.params().v_max * self.params().horizon
    }

    fn plan(&mut self, input: &PlanningInput<'_>, target: Vec2) -> LocalPlan {
        let judge = input.safety.map(|set| {
            move |c: Command| {
                if !set.admits(c) {
                    Admission::Refused
                } else if set.passes(c) {
                    Admission::Passes
                } else {
                    Admission::Admitted
                }
            }
        });
        let d = Pnp::plan_within(
            self,
            input.ego,
            input.neighbours,
            input.map,
            target,
            input.visibility,
            judge.as_ref().map(|f| f as &dyn Fn(Command) -> Admission),
        );
        LocalPlan {
            command: d.command,
            trajectory: d.trajectory,
        }
    }
}

impl LocalPlanner for Asfm {
    /// The robot's reach over the optimisation horizon H·Δt at top speed.
    fn subgoal_distance(&self) -> Real {
        let p = self.params();
        p.v_max * p.horizon as Real * p.dt
    }

    fn plan(&mut self, input: &PlanningInput<'_>, target: Vec2) -> LocalPlan {
        let s = Asfm::step(
            self,
            input.ego,
            input.neighbours,
            input.map,
            target,
            input.dt,
        );
        LocalPlan {
            command: nearest_admissible(input, Command::Velocity(s.command)),
            trajectory: s.trajectory,
        }
    }
}

/// A constant-velocity trajectory with σ growth, t = dt..=horizon.
fn straight(
    start: Vec2,
    v: Vec2,
    horizon: Real,
    dt: Real,
    sigma: &SigmaModel,
) -> Vec<TrajectorySample> {
    let steps = (horizon / dt).round() as usize;
    (1..=steps)
        .zip(sigma.constant_speed(v.norm()))
        .map(|(i, sigma)| {
            let t = i as Real * dt;
            TrajectorySample {
                t,
                position: start + v * t,
                sigma,
            }
        })
        .collect()
}

/// A full planner stack: optional PGP on top of one short-term planner.
#[derive(Debug)]
pub struct PlannerStack {
    spec: PlannerSpec,
    pgp: Option<Pgp>,
    local: Box<dyn LocalPlanner>,
}

impl PlannerStack {
    /// The stack `spec` with the PGP paper's parameters.
    pub fn new(spec: PlannerSpec) -> Self {
        Self::build(spec, None)
    }

    /// The stack `spec` with the papers' parameters except the robot's top speed (m/s), which
    /// every planner of the stack uses instead of its default (PGP's candidate speed and v^max,
    /// DWA's v^max, ORCA's and SF's maximum speed, foIGP's preferred and maximum speed).
    pub fn with_max_speed(spec: PlannerSpec, max_speed: Real) -> Self {
        Self::build(spec, Some(max_speed))
    }

    fn build(spec: PlannerSpec, max_speed: Option<Real>) -> Self {
        let local: Box<dyn LocalPlanner> = match spec.local {
            LocalKind::Dwa => {
                let d = DwaParams::default();
                let v_max = max_speed.unwrap_or(d.v_max);
                Box::new(Dwa::new(DwaParams { v_max, ..d }))
            }
            LocalKind::Orca | LocalKind::OrcaNonReciprocal => {
                let d = OrcaParams::default();
                let max_speed = max_speed.unwrap_or(d.max_speed);
                let mut orca = OrcaPlanner::new(OrcaParams { max_speed, ..d });
                if spec.local == LocalKind::OrcaNonReciprocal {
                    orca.human_responsibility = 1.0;
                }
                Box::new(orca)
            }
            LocalKind::SocialForce => {
                let d = SfAgentParams::default();
                let max_speed = max_speed.unwrap_or(d.max_speed);
                Box::new(SfPlanner::new(SfAgentParams { max_speed, ..d }))
            }
            LocalKind::Igp(variant) => {
                let d = IgpParams::default();
                let params = match max_speed {
                    Some(v) => IgpParams {
                        preferred_speed: v,
                        max_speed: v,
                        ..d
                    },
                    None => d,
                };
                Box::new(IgpPlanner::new(variant, params))
            }
            LocalKind::Pnp { variant, peek } => {
                let d = variant.params(peek);
                let v_max = max_speed.unwrap_or(d.v_max);
                Box::new(Pnp::new(PnpParams { v_max, ..d }))
            }
            LocalKind::Asfm(variant) => {
                let d = variant.params();
                let v_max = max_speed.unwrap_or(d.v_max);
                Box::new(Asfm::new(AsfmParams { v_max, ..d }))
            }
        };
        let pgp = spec.pgp.then(|| {
            let d = PgpParams::default();
            Pgp::new(PgpParams {
                subgoal_distance: local.subgoal_distance(),
                v_max: max_speed.unwrap_or(d.v_max),
                speed: max_speed.unwrap_or(d.speed),
                ..d
            })
        });
        Self { spec, pgp, local }
    }

    /// The peek-and-pass planner alone with explicit parameters (named `pnp` when c3 is below
    /// [`crate::pnp::NO_PEEK_C3`], `pnp-nopeek` otherwise).
    pub fn pnp(params: PnpParams) -> Self {
        let peek = params.c3 < crate::pnp::NO_PEEK_C3;
        Self {
            spec: PlannerSpec {
                pgp: false,
                local: LocalKind::Pnp {
                    variant: PnpVariant::Tuned,
                    peek,
                },
            },
            pgp: None,
            local: Box::new(Pnp::new(params)),
        }
    }

    /// A stack of `local` alone (no PGP), named `spec` (a planner with parameters or
    /// instrumentation of its own, as the studies use).
    pub fn with_local(spec: PlannerSpec, local: Box<dyn LocalPlanner>) -> Self {
        Self {
            spec: PlannerSpec { pgp: false, ..spec },
            pgp: None,
            local,
        }
    }

    /// The stack with its short-term planner wrapped by `wrap` (instrumentation, or the
    /// runtime's fault injection); PGP and the name stay.
    pub fn wrap_local(
        mut self,
        wrap: impl FnOnce(Box<dyn LocalPlanner>) -> Box<dyn LocalPlanner>,
    ) -> Self {
        self.local = wrap(self.local);
        self
    }

    /// A stack with explicit PGP parameters (its subgoal distance is used as given).
    pub fn with_pgp(spec: PlannerSpec, pgp: PgpParams) -> Self {
        let mut stack = Self::new(spec);
        if stack.pgp.is_some() {
            stack.pgp = Some(Pgp::new(pgp));
        }
        stack
    }

    /// Whether PGP returns its evaluated fan with each plan (on by default; debug data).
    pub fn set_record_fan(&mut self, on: bool) {
        if let Some(pgp) = &mut self.pgp {
            pgp.set_record_fan(on);
        }
    }

    /// Where people go in this scene: the intents of foIGP's mixtures (other planners
    /// ignore them).
    pub fn set_destinations(&mut self, destinations: &[Vec2]) {
        self.local.set_destinations(destinations);
    }

    /// Which planners run.
    pub fn spec(&self) -> PlannerSpec {
        self.spec
    }

    /// One planning step.
    pub fn plan(&mut self, input: &PlanningInput<'_>) -> Plan {
        match &mut self.pgp {
            Some(pgp) => {
                let admits = input.safety.map(|set| move |c: Command| set.admits(c));
                let decision = pgp.plan_within(
                    input.ego,
                    input.neighbours,
                    input.map,
                    input.goal,
                    admits.as_ref().map(|f| f as &dyn Fn(Command) -> bool),
                );
                let local = self.local.plan(input, decision.subgoal);
                Plan {
                    command: local.command,
                    intent: Intent {
                        subgoal: decision.subgoal,
                        trajectory: decision.trajectory,
                    },
                    fan: decision.fan,
                }
            }
            None => {
                let local = self.local.plan(input, input.goal);
                Plan {
                    command: local.command,
                    intent: Intent {
                        subgoal: input.goal,
                        trajectory: local.trajectory,
                    },
                    fan: None,
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A person walking head-on at the robot: `orca` counts on them taking half of the
    /// avoidance, `orca-nr` takes all of it, so its first plan turns aside twice as hard (the
    /// projection onto the velocity obstacle's edge is u, and the new velocity v + u instead
    /// of v + u/2). Toward another robot both share it reciprocally.
    #[test]
    fn orca_nr_takes_all_of_the_avoidance_of_a_person() {
        let first_plan = |name: &str, kind: AgentKind| {
            let spec: PlannerSpec = name.parse().expect("known");
            let ego = EgoState {
                position: Vec2::new(0.0, 0.0),
                heading: 0.0,
                velocity: Vec2::new(1.0, 0.0),
                yaw_rate: 0.0,
                radius: 0.3,
            };
            let n = [Neighbour::new(
                1,
                Vec2::new(3.0, 0.2),
                Vec2::new(-1.0, 0.0),
                0.3,
                kind,
            )];
            let map = StaticMap::empty();
            let input = PlanningInput {
                ego: &ego,
                neighbours: &n,
                map: &map,
                goal: Vec2::new(10.0, 0.0),
                dt: 0.4,
                visibility: None,
                safety: None,
            };
            match PlannerStack::new(spec).plan(&input).command {
                Command::Velocity(v) => v,
                other => panic!("ORCA commands velocities, not {other:?}"),
            }
        };
        let half = first_plan("orca", AgentKind::Human);
        let whole = first_plan("orca-nr", AgentKind::Human);
        // Both turn away from the person (who is at +y): down.
        assert!(half.y < -0.05, "orca {half:?}");
        assert!(
            (whole - Vec2::new(1.0, 0.0) - (half - Vec2::new(1.0, 0.0)) * 2.0).norm() < 1e-9,
            "orca {half:?} orca-nr {whole:?}"
        );
        assert_eq!(
            first_plan("orca", AgentKind::Robot),
            first_plan("orca-nr", AgentKind::Robot)
        );
    }

    #[test]
    fn pgp_subgoal_distance_is_the_short_term_planners_reach() {
        // Table I: DWA 1 m/s · 2 s, ORCA 1 m/s · 2.5 s.
        assert_eq!(Dwa::new(DwaParams::default()).subgoal_distance(), 2.0);
        assert_eq!(
            OrcaPlanner::new(OrcaParams::default()).subgoal_distance(),
            2.5
        );
    }
}
