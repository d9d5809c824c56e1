//! The safety layer under every planner: a protective field and a warning field, as a safety
//! laser scanner gives a warehouse robot, checked on the command the planner chose, and a
//! yield rule for when standing still is not safe either.
//!
//! Speed and separation monitoring (ISO/TS 15066, ISO 13855) keeps a protective separation
//! S = v_h·(T_r + T_s) + v_r·T_r + B + C + Z between robot and person: what the person covers
//! while the robot reacts and stops, what the robot covers before it brakes, its braking
//! distance B, and the intrusion and uncertainty allowances C + Z. Here the same budget is
//! checked along the commanded motion itself (the "equivalent braking-distance check along the
//! commanded arc"): the robot is rolled out as its base executes the command, for the reaction
//! time T_r, then braking at its guaranteed deceleration until it stands; every perceived body
//! either moves on at its perceived velocity meanwhile (v_h·(T_r + T_s)) or halts, whichever
//! comes closer, and walls stand still. A robot ahead halts by stopping dead where it is
//! (braking hard); a person walking at up to [`HALTING_MAX_SPEED`] halts no harder than a_h,
//! the bound on how hard people change their motion ([`SafetyParams::people_stop_dead`]).
//!
//! **The predicate.** A command is *admissible* ([`SafeSet::admits`]) when, at every instant
//! of that rollout at which the robot is moving toward a body, the gap stays above the margin
//! C + Z, people being allowed to swerve at up to a_h; and it never moves toward a wall or
//! shelf within the margin. Inside the margin an admissible command may therefore only keep
//! or open every gap: its velocity toward each body is ≤ 0.
//!
//! **The guarantee: passive safety** (Macek, Fraichard et al.): every command the layer lets
//! through is admissible, so the robot can always still brake to a stop before it moves into
//! anything it perceives and that keeps within the motion model (walking on, halting as above,
//! swerving at ≤ a_h); if a contact happens, the robot is not moving toward the other body at
//! its onset. This is the guarantee behind "robot-caused" contacts
//! (`world_sim::metrics::contact_cause`). It is not *passive-friendly* safety (the other body
//! could always have avoided the contact as well) and not the avoidance of inevitable
//! collision states: both need to know what people will do. The property tests in `tests`
//! pin it: every command out of the layer is admissible, or a stop.
//!
//! **Yielding.** Passive safety alone is met by standing still, and a robot standing in a
//! person's way is walked into. So when someone who walks on at their perceived velocity
//! would come within the margin of the robot were it to stop (within the yield horizon T_y),
//! the robot is *threatened* and the layer yields: among the admissible commands of a fixed
//! set (the planner's command and its fractions, and moves in every direction at half and
//! full speed, or for a unicycle base backing off, turning away and driving on) it takes the
//! one whose predicted clearance over T_y is largest, clearances beyond
//! [`SafetyParams::yield_clearance`] counting as equal, ties going to the command nearest
//! the planner's. It backs off, sidesteps or turns away, never toward anyone (admissible) and
//! never into a wall or shelf; with no admissible way out (cornered against a shelf) it
//! stands, and the contact is the person's.
//!
//! - **Protective field**: an unsafe command is scaled down (speed and turn rate alike, so an
//!   arc keeps its curvature) to the largest safe fraction on a fixed ladder, down to a stop.
//! - **Warning field**: a command that would become unsafe were the robot to keep it for the
//!   warning time T_w longer is first slowed to [`SafetyParams::warning_scale`] (ISO 3691-4's
//!   reduced speed near people).
//! - **Yield**: as above, only when threatened.
//! - A command that no field touches passes through bit-identical. Outside a yield the layer
//!   never adds speed.
//!
//! Planners plan inside the same set: the layer hands them a [`SafeSet`], and they rank or
//! restrict their candidates with its [`SafeSet::admits`], so that the layer rarely has to
//! override them (`crate::guard`).

use crate::map::{LocalMap, StaticMap};
use crate::math::{Real, Vec2, clamp_norm, unit, vec2};
use crate::model::{AgentKind, Command, EgoState, Neighbour};
use std::cell::RefCell;

mod params;
pub use params::{ACROSS_MIN_SPEED, HALTING_MAX_SPEED, SafetyLimits, SafetyParams};

/// Which field acted on a command.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Zone {
    /// Neither: the command passed through unchanged.
    Clear,
    /// The warning field slowed it to [`SafetyParams::warning_scale`].
    Warning,
    /// The protective field slowed it further, or stopped the robot.
    Protective,
    /// The robot was threatened (someone would walk into it were it to stop) and the layer
    /// took another way out than the planner's command.
    Yield,
}

/// A command after the safety layer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Guarded {
    /// What the robot may execute.
    pub command: Command,
    /// Which field acted.
    pub zone: Zone,
    /// The fraction of the planner's command kept (1 when clear, 0 for a protective stop and
    /// for a yield's way out that is not a fraction of it).
    pub scale: Real,
}

/// Fractions of a command the protective field tries, largest first, before a stop.
pub const LADDER: [Real; 8] = [1.0, 0.8, 0.6, 0.45, 0.3, 0.2, 0.1, 0.05];

/// The safety layer: its parameters and scratch buffers reused between calls (it keeps no
/// other state; the same input gives the same bits).
#[derive(Debug, Clone)]
pub struct SafetyLayer {
    params: SafetyParams,
    /// Bodies that can come within reach during the rollouts.
    near: Vec<Body>,
    /// Those of them the yield watches.
    walkers: Vec<Walker>,
    /// Walls and shelves within reach.
    local: LocalMap,
    /// Per body of `near` and hypothesis (walking on, halting): if it has come within
    /// the margin of the robot in this rollout without the robot moving toward it, where and
    /// when, and how it goes on. A body that walks into the robot does not walk through it
    /// (its straight line through the robot afterwards means nothing): it slides along,
    /// keeping only the part of its velocity that does not close on the robot, and stays an
    /// obstacle the robot may not move toward later in the rollout. (A `RefCell` so that
    /// planners can ask [`SafeSet::admits`] through a shared reference.)
    arrived: RefCell<Vec<[Option<Arrival>; 2]>>,
    /// The robot the layer was last prepared for.
    ego: EgoState,
    /// Its distance to the nearest gathered wall or shelf edge (infinite with none).
    ego_wall: Real,
    /// Its base's limits.
    limits: SafetyLimits,
    /// The places where robots and people stop and turn, as boxes (lower and upper corners;
    /// a box may be a line or a point), when the site marks them
    /// ([`SafetyParams::person_accel_away`]).
    turn_places: Option<Vec<(Vec2, Vec2)>>,
}

/// The commands a robot may execute in one control period, as the layer sees them: what
/// [`SafetyLayer::prepare`] returns, and what planners consult to plan inside the safe set.
#[derive(Debug, Clone, Copy)]
pub struct SafeSet<'a> {
    layer: &'a SafetyLayer,
    map: &'a StaticMap,
}

/// A perceived body as the rollouts see it.
#[derive(Debug, Clone, Copy)]
struct Body {
    position: Vec2,
    velocity: Vec2,
    /// The centre distance kept: both radii and the margin.
    within: Real,
    /// How hard it may swerve in the protective check (a_h for people, 0 for robots).
    accel: Real,
    /// The way it walks (unit), when it may swerve less across it than along it
    /// ([`SafetyParams::person_accel_across`]); zero otherwise.
    along: Vec2,
    /// How hard it may swerve across `along`.
    accel_across: Real,
    /// How hard it halts on the second hypothesis (m/s²): infinite for stopping dead where it
    /// is; a_h for a person without [`SafetyParams::people_stop_dead`].
    halting: Real,
    /// Its speed (m/s), for halting.
    speed: Real,
    /// Per check (warning, protective) and hypothesis (walking on, halting): whether it can
    /// come within `within` of the robot at all in that check's rollout, and whether the check
    /// holds that hypothesis at all (a person halting at a_h adds nothing to the protective
    /// check's swerve). Those that cannot, or need not, are skipped.
    relevant: [[bool; 2]; 2],
}

impl Body {
    /// Where the body stands on the halting hypothesis `t` s on, and its velocity then:
    /// braking along its way at [`Body::halting`] (stopping dead where it is when that is
    /// infinite).
    fn halt(&self, t: Real) -> (Vec2, Vec2) {
        if !self.halting.is_finite() {
            return (self.position, vec2(0.0, 0.0));
        }
        let speed = self.speed;
        if speed == 0.0 {
            return (self.position, self.velocity);
        }
        let braking = t.min(speed / self.halting);
        let way = speed * braking - 0.5 * self.halting * braking * braking;
        let left = (speed - self.halting * t).max(0.0);
        let along = self.velocity / speed;
        (self.position + along * way, along * left)
    }

    /// Whether `d` (from the robot to where the body would be) is within `within` of the
    /// ellipse the body may stray in after a time whose ½·t² is `half_tt`: ½·a_h·t² along its
    /// way, ½·a_⊥·t² across. Conservative: it tests the ellipse's extent toward the robot
    /// (its support function), which holds every point of the ellipse, so it never says
    /// "outside" of a point within. A body that strays alike every way is within whenever the
    /// round test says so.
    fn within_ellipse(&self, d: Vec2, half_tt: Real) -> bool {
        if self.along == vec2(0.0, 0.0) {
            return true;
        }
        let n = d.norm();
        if n == 0.0 {
            return true;
        }
        let (c, s) = (
            d.dot(&self.along) / n,
            (d.x * self.along.y - d.y * self.along.x) / n,
        );
        let (a, a_across) = (self.accel * c, self.accel_across * s);
        let reach = half_tt * (a * a + a_across * a_across).sqrt();
        n < self.within + reach
    }
}

/// A body that, walking on, can come within the yield clearance of the robot over the yield
/// horizon: where it is, how it walks, and the centre distance at which it touches the
/// robot (both radii).
#[derive(Debug, Clone, Copy)]
struct Walker {
    position: Vec2,
    velocity: Vec2,
    touching: Real,
}

/// A check's rollout: its sub-step (s), the sub-steps driving the command, and the most
/// sub-steps it takes until the robot stands.
#[derive(Debug, Clone, Copy)]
struct Rollout {
    h: Real,
    drive_steps: usize,
    max_steps: usize,
}

/// Where and when a body came to the robot in a rollout, and its velocity from then on.
#[derive(Debug, Clone, Copy)]
struct Arrival {
    at: Vec2,
    t: Real,
    sliding: Vec2,
}

/// The robot along a rollout: position, velocity, heading, turn rate.
#[derive(Debug, Clone, Copy)]
struct Motion {
    position: Vec2,
    velocity: Vec2,
    heading: Real,
    yaw_rate: Real,
}

impl Default for SafetyLayer {
    fn default() -> Self {
        Self::new(SafetyParams::default())
    }
}

impl SafetyLayer {
    /// A layer with the given parameters.
    pub fn new(params: SafetyParams) -> Self {
        Self {
            params,
            near: Vec::new(),
            walkers: Vec::new(),
            local: LocalMap::default(),
            arrived: RefCell::new(Vec::new()),
            ego: EgoState {
                position: Vec2::zeros(),
                heading: 0.0,
                velocity: Vec2::zeros(),
                yaw_rate: 0.0,
                radius: 0.0,
            },
            ego_wall: Real::INFINITY,
            limits: SafetyLimits::SIMULATED_ROBOT,
            turn_places: None,
        }
    }

    /// Marks the places where robots and people stop and turn (boxes, lower and upper
    /// corners), or that none are known (`None`: everyone may swerve at `person_accel`,
    /// wherever they are).
    pub fn set_turn_places(&mut self, places: Option<Vec<(Vec2, Vec2)>>) {
        self.turn_places = places;
    }

    /// a_h for a person at `p`: [`SafetyParams::person_accel_away`] when the site marks the
    /// places where robots and people turn and `p` is farther than
    /// [`SafetyParams::turn_reach`] from every one of them (along either axis), else
    /// `person_accel`. Never more than `person_accel`.
    fn person_accel_at(&self, p: Vec2) -> Real {
        let full = self.params.person_accel;
        let away = self.params.person_accel_away;
        let Some(places) = self.turn_places.as_ref().filter(|_| away < full) else {
            return full;
        };
        let reach = self.params.turn_reach;
        let near = |&(lo, hi): &(Vec2, Vec2)| {
            let dx = (lo.x - p.x).max(p.x - hi.x);
            let dy = (lo.y - p.y).max(p.y - hi.y);
            dx <= reach && dy <= reach
        };
        if places.iter().any(near) { full } else { away }
    }

    /// The parameters in use.
    pub fn params(&self) -> &SafetyParams {
        &self.params
    }

    /// Runs on `params` from the next check on (a site's setting, served with its map).
    pub fn set_params(&mut self, params: SafetyParams) {
        self.params = params;
    }

    /// The command the robot may execute instead of `command` (see the module doc):
    /// `command` itself when it is safe, outside the warning field and the robot is not
    /// threatened; else a slower fraction of it, else a stop; or, when threatened, the best
    /// admissible way out.
    pub fn guard(
        &mut self,
        command: Command,
        ego: &EgoState,
        limits: &SafetyLimits,
        bodies: &[Neighbour],
        map: &StaticMap,
    ) -> Guarded {
        self.prepare(ego, limits, bodies, map).guard(command)
    }

    /// Gathers what can come within reach of `ego` during the layer's rollouts, and returns
    /// the safe set it bounds.
    pub fn prepare<'a>(
        &'a mut self,
        ego: &EgoState,
        limits: &SafetyLimits,
        bodies: &[Neighbour],
        map: &'a StaticMap,
    ) -> SafeSet<'a> {
        self.prepare_remembering(ego, limits, bodies, &[], map)
    }

    /// [`Self::prepare`] for the bodies perceived now and those `remembered`: no longer
    /// perceived, where they would be now (the [`Guard`](crate::guard::Guard)'s memory). Both
    /// are checked alike, the perceived ones first.
    pub fn prepare_remembering<'a>(
        &'a mut self,
        ego: &EgoState,
        limits: &SafetyLimits,
        bodies: &[Neighbour],
        remembered: &[Neighbour],
        map: &'a StaticMap,
    ) -> SafeSet<'a> {
        let p = self.params;
        self.ego = *ego;
        self.limits = *limits;
        let dt = limits.control_period;
        let braking = limits.braking();
        // The farthest the robot can get before it stands, at any fraction of the command,
        // or along a way out.
        let top = limits.max_speed.max(ego.velocity.norm());
        let stop_horizon = dt + p.reaction_time + p.warning_time + top / braking.max(1e-9);
        let horizon = if p.yielding {
            stop_horizon.max(p.yield_time)
        } else {
            stop_horizon
        };
        let reach = top * horizon;
        self.gather(ego, bodies.iter().chain(remembered), map, reach, horizon);
        self.ego_wall = self.local.distance(map, &ego.position);
        self.mark_relevant(ego, limits);
        SafeSet { layer: self, map }
    }

    /// Keeps the bodies and wall edges that can come within reach of the robot before the
    /// longest rollout ends.
    fn gather<'b>(
        &mut self,
        ego: &EgoState,
        bodies: impl Iterator<Item = &'b Neighbour>,
        map: &StaticMap,
        reach: Real,
        horizon: Real,
    ) {
        let m = self.params.margin;
        let slack = if self.params.yielding {
            m.max(self.params.yield_clearance)
        } else {
            m
        };
        // Taken out for the fill, so that each body's a_h can be read from the layer.
        let mut near = std::mem::take(&mut self.near);
        near.clear();
        let accel_at = |p: Vec2| self.person_accel_at(p);
        near.extend(
            bodies
                .filter(|b| {
                    let travel = reach
                        + b.velocity.norm() * horizon
                        + 0.5 * self.params.person_accel * horizon * horizon;
                    (b.position - ego.position).norm() < travel + ego.radius + b.radius + slack
                })
                .map(|b| {
                    let human = b.kind == AgentKind::Human;
                    // a_h for this person where they are; robots do not swerve.
                    let a_h = if human { accel_at(b.position) } else { 0.0 };
                    let speed = b.velocity.norm();
                    Body {
                        position: b.position,
                        velocity: b.velocity,
                        within: ego.radius + b.radius + m,
                        accel: a_h,
                        along: if human
                            && self.params.person_accel_across < self.params.person_accel
                            && speed >= ACROSS_MIN_SPEED
                        {
                            b.velocity / speed
                        } else {
                            vec2(0.0, 0.0)
                        },
                        accel_across: self.params.person_accel_across.min(if human {
                            a_h
                        } else {
                            self.params.person_accel
                        }),
                        halting: if human
                            && !self.params.people_stop_dead
                            && a_h > 0.0
                            && speed <= HALTING_MAX_SPEED
                        {
                            a_h
                        } else {
                            Real::INFINITY
                        },
                        speed,
                        relevant: [[true; 2]; 2],
                    }
                }),
        );
        self.near = near;
        let r = vec2(reach, reach);
        map.gather(
            ego.position - r,
            ego.position + r,
            ego.radius + m,
            &mut self.local,
        );
    }

    /// The rollout of a check that drives the command for one control period plus `extra`.
    fn rollout_steps(&self, extra: Real) -> Rollout {
        let limits = &self.limits;
        // As many equal sub-steps per control period as it takes (the small slack keeps an
        // exact multiple from rounding up to one more).
        let substeps = (limits.control_period / self.params.check_step - 1e-9)
            .ceil()
            .max(1.0);
        let h = limits.control_period / substeps;
        let drive_steps = ((limits.control_period + extra) / h).ceil() as usize;
        // Until the robot stands (at most its speed over the deceleration, plus the drive).
        let max_steps = drive_steps
            + (limits.max_speed.max(self.ego.velocity.norm()) / (limits.braking() * h)).ceil()
                as usize
            + 1;
        Rollout {
            h,
            drive_steps,
            max_steps,
        }
    }

    /// Marks, per check and hypothesis, the bodies that can come within reach at all: the
    /// robot stays within its top speed times the rollout's length of where it is, a body
    /// walking on stays on its line, a swerving person within ½·a_h·T² of it.
    fn mark_relevant(&mut self, ego: &EgoState, limits: &SafetyLimits) {
        let top = limits.max_speed.max(ego.velocity.norm());
        let extras = [self.params.warning_time, self.params.reaction_time];
        let closest = |b: &Body, duration: Real| {
            let from = b.position - ego.position;
            let speed_sq = b.velocity.norm_squared();
            let closest_t = if speed_sq > 0.0 {
                (-from.dot(&b.velocity) / speed_sq).clamp(0.0, duration)
            } else {
                0.0
            };
            ((from + b.velocity * closest_t).norm(), from.norm())
        };
        for (check, extra) in extras.into_iter().enumerate() {
            let Rollout { h, max_steps, .. } = self.rollout_steps(extra);
            let duration = h * max_steps as Real;
            let robot_reach = top * duration;
            let swerve = check == 1;
            for b in &mut self.near {
                let stray = if swerve {
                    0.5 * b.accel * duration * duration
                } else {
                    0.0
                };
                let (walking, standing) = closest(b, duration);
                let reach = robot_reach + b.within + stray;
                // Halting at a finite rate, it stands at most its stopping distance on.
                let halt_way = (b.halt(Real::INFINITY).0 - b.position).norm();
                // A person who halts no harder than a_h stays within the swerve's reach of
                // walking on: in the protective check halting adds nothing to it.
                let halts_within_swerve = swerve && b.halting.is_finite();
                b.relevant[check] = [
                    walking < reach,
                    standing - halt_way < reach && !halts_within_swerve,
                ];
            }
        }
        let yield_time = self.params.yield_time;
        let cap = self.params.yield_clearance.max(self.params.margin);
        let margin = self.params.margin;
        self.walkers.clear();
        self.walkers.extend(
            self.near
                .iter()
                .filter(|b| closest(b, yield_time).0 < top * yield_time + b.within + cap)
                .map(|b| Walker {
                    position: b.position,
                    velocity: b.velocity,
                    touching: b.within - margin,
                }),
        );
    }

    /// Whether the robot, executing `command` for one control period plus `extra` seconds and
    /// then braking to a stop, keeps more than the margin from every body and wall it moves
    /// toward (with people swerving at up to a_h when `swerve`).
    fn safe(&self, command: Command, map: &StaticMap, extra: Real, swerve: bool) -> bool {
        let Rollout {
            h,
            drive_steps,
            max_steps,
        } = self.rollout_steps(extra);
        let p = &self.params;
        let limits = &self.limits;
        let braking = limits.braking();
        let mut m = Motion::of(&self.ego);
        let mut t = 0.0;
        let mut walls = WallWatch::new(m.position, self.ego_wall, self.ego.radius, p.margin);
        let mut arrived = self.arrived.borrow_mut();
        arrived.clear();
        arrived.resize(self.near.len(), [None; 2]);
        let check = usize::from(swerve);
        for k in 0..max_steps {
            let before = m.position;
            let driving = k < drive_steps;
            if driving {
                step_toward(&mut m, command, limits, h);
            } else {
                brake(&mut m, braking, limits, h);
            }
            t += h;
            if m.velocity == vec2(0.0, 0.0) && !driving {
                break;
            }
            // Bodies the robot moves toward: walking on at their velocity (v_h·(T_r + T_s)), or
            // halting (a robot ahead that brakes stops dead; a person brakes at ≤ a_h).
            // People may swerve in the protective check (a_h, `person_accel`); the warning field
            // looks ahead on the hypotheses alone.
            let half_tt = if swerve { 0.5 * t * t } else { 0.0 };
            for (b, arrived) in self.near.iter().zip(arrived.iter_mut()) {
                let within_sq = (b.within + b.accel * half_tt).powi(2);
                for (k, (arrival, relevant)) in
                    arrived.iter_mut().zip(b.relevant[check]).enumerate()
                {
                    if !relevant {
                        continue;
                    }
                    let (at, moving) = if k == 0 {
                        (b.position + b.velocity * t, b.velocity)
                    } else {
                        b.halt(t)
                    };
                    let at = arrival.map_or(at, |a| a.at + a.sliding * (t - a.t));
                    let d = at - m.position;
                    // The gap is under the margin: no square root needed (and, for a
                    // walking person who strays less across their way, within the ellipse's
                    // reach toward the robot too).
                    if d.norm_squared() < within_sq && b.within_ellipse(d, half_tt) {
                        if d.dot(&m.velocity) > 0.0 {
                            return false;
                        }
                        if arrival.is_none() {
                            // Its velocity less what closes on the robot.
                            let n = unit_or_zero(d);
                            let sliding = moving - n * moving.dot(&n).min(0.0);
                            *arrival = Some(Arrival { at, t, sliding });
                        }
                    }
                }
            }
            // Walls the robot moves toward.
            if walls.approached(&self.local, map, before, m.position) {
                return false;
            }
        }
        true
    }
}

impl SafeSet<'_> {
    /// Whether the robot may execute `command` for the next control period: the protective
    /// check (see the module doc). The one predicate planners and the layer share.
    pub fn admits(&self, command: Command) -> bool {
        let p = self.layer.params;
        self.layer.safe(command, self.map, p.reaction_time, true)
    }

    /// Whether the layer lets `command` through untouched: admitted, with no warning and no
    /// yield. Planners that score their own candidates prefer these.
    pub fn passes(&self, command: Command) -> bool {
        self.guard(command).zone == Zone::Clear
    }

    /// What the robot may execute instead of `command`.
    pub fn guard(&self, command: Command) -> Guarded {
        let l = self.layer;
        let p = l.params;
        if l.near.is_empty() && l.local.is_empty() {
            return Guarded {
                command,
                zone: Zone::Clear,
                scale: 1.0,
            };
        }
        if self.threatened()
            && let Some(way_out) = self.yield_from(command)
        {
            return way_out;
        }
        let warned = !l.safe(command, self.map, p.warning_time, false);
        let start = if !warned {
            1.0
        } else if p.warning_graded {
            // The largest fraction above `warning_scale` the warning check passes.
            LADDER
                .into_iter()
                .filter(|&s| s < 1.0 && s > p.warning_scale)
                .find(|&s| l.safe(scaled(command, s), self.map, p.warning_time, false))
                .unwrap_or(p.warning_scale)
        } else {
            p.warning_scale
        };
        // Graded, the fixed field's `warning_scale` is tried before the ladder's fractions
        // below it: the graded field never keeps less than the fixed one would.
        let fixed =
            (p.warning_graded && warned && p.warning_scale < start).then_some(p.warning_scale);
        let below = |s: Real| s < start && s > 0.0 && fixed.is_none_or(|w| s != w);
        let tried = std::iter::once(start)
            .chain(
                LADDER
                    .into_iter()
                    .filter(move |&s| below(s) && fixed.is_none_or(|w| s > w)),
            )
            .chain(fixed)
            .chain(
                LADDER
                    .into_iter()
                    .filter(move |&s| below(s) && fixed.is_some_and(|w| s < w)),
            );
        for s in tried {
            let candidate = if s == 1.0 {
                command
            } else {
                scaled(command, s)
            };
            if self.admits(candidate) {
                let zone = match (s == start, warned) {
                    (true, false) => Zone::Clear,
                    (true, true) => Zone::Warning,
                    (false, _) => Zone::Protective,
                };
                // Untouched commands keep their bits.
                return Guarded {
                    command: candidate,
                    zone,
                    scale: s,
                };
            }
        }
        // A stop: the most the robot can do without a threat (it never adds speed).
        Guarded {
            command: scaled(command, 0.0),
            zone: Zone::Protective,
            scale: 0.0,
        }
    }
}

impl Motion {
    fn of(ego: &EgoState) -> Self {
        Self {
            position: ego.position,
            velocity: ego.velocity,
            heading: ego.heading,
            yaw_rate: ego.yaw_rate,
        }
    }
}

/// Watches a rollout for the robot coming within the margin of a wall or shelf while
/// moving toward it (its distance under `limit` and falling). Exact distances are taken only
/// where the robot may have come that close: the distance falls by at most the way
/// travelled from the last point it was taken at. Where it is taken, it is also taken at the
/// step before when that one was skipped, so the verdict is the one taking it at every step
/// would give, bit for bit.
#[derive(Debug, Clone, Copy)]
struct WallWatch {
    /// The exact distance at the step before, if it was taken.
    was: Option<Real>,
    /// A point and its exact distance.
    anchor: (Vec2, Real),
    /// The robot's radius and the margin: moving toward a wall stops where the distance less
    /// the radius is under the margin.
    radius: Real,
    margin: Real,
}

impl WallWatch {
    /// At the rollout's start, `distance` from the nearest edge.
    fn new(position: Vec2, distance: Real, radius: Real, margin: Real) -> Self {
        Self {
            was: Some(distance),
            anchor: (position, distance),
            radius,
            margin,
        }
    }

    /// Whether the step from `before` to `now` came within the limit, moving toward a wall.
    fn approached(&mut self, local: &LocalMap, map: &StaticMap, before: Vec2, now: Vec2) -> bool {
        let lower = self.anchor.1 - (now - self.anchor.0).norm();
        if lower - self.radius >= self.margin + 1e-9 {
            self.was = None;
            return false;
        }
        let to_wall = local.distance(map, &now);
        let was = self.was.unwrap_or_else(|| local.distance(map, &before));
        if to_wall - self.radius < self.margin && to_wall < was {
            return true;
        }
        self.was = Some(to_wall);
        self.anchor = (now, to_wall);
        false
    }
}

/// How far ahead of a robot moving at `speed` its two fields reach along its line of travel
/// (m, from its centre's path, margin included): the protective field covers the control
/// period and reaction time at that speed plus the braking distance, the warning field the
/// warning time more. These are the shapes a safety scanner's speed-switched fields take; the
/// layer itself checks the commanded motion against each body, and dashboards draw these.
pub fn field_reach(speed: Real, limits: &SafetyLimits, params: &SafetyParams) -> (Real, Real) {
    let speed = speed.abs();
    let braking = limits.braking().max(1e-9);
    let protective = speed * (limits.control_period + params.reaction_time)
        + speed * speed / (2.0 * braking)
        + params.margin;
    (protective, protective + speed * params.warning_time)
}

/// `v` scaled to length 1, or zero.
fn unit_or_zero(v: Vec2) -> Vec2 {
    let n = v.norm();
    if n > 0.0 { v / n } else { v }
}

/// The command with its speed (and turn rate) times `s`.
fn scaled(command: Command, s: Real) -> Command {
    match command {
        Command::Velocity(v) => Command::Velocity(v * s),
        Command::Unicycle { speed, yaw_rate } => Command::Unicycle {
            speed: speed * s,
            yaw_rate: yaw_rate * s,
        },
    }
}

/// One sub-step of the base executing `command`, as `world_sim::robot` executes it.
fn step_toward(m: &mut Motion, command: Command, lim: &SafetyLimits, h: Real) {
    match command {
        Command::Velocity(v) => {
            let target = clamp_norm(v, lim.max_speed);
            m.velocity += clamp_norm(target - m.velocity, lim.max_accel * h);
        }
        Command::Unicycle { speed, yaw_rate } => {
            let current = m.velocity.dot(&unit(m.heading));
            let target = speed.clamp(-lim.max_speed, lim.max_speed);
            let v = current + (target - current).clamp(-lim.max_accel * h, lim.max_accel * h);
            let yaw_rate = yaw_rate.clamp(-lim.max_yaw_rate, lim.max_yaw_rate);
            m.yaw_rate +=
                (yaw_rate - m.yaw_rate).clamp(-lim.max_yaw_accel * h, lim.max_yaw_accel * h);
            m.heading += m.yaw_rate * h;
            m.velocity = unit(m.heading) * v;
        }
    }
    m.position += m.velocity * h;
}

/// One sub-step of braking at `braking` along the current direction of travel.
fn brake(m: &mut Motion, braking: Real, lim: &SafetyLimits, h: Real) {
    m.velocity -= clamp_norm(m.velocity, braking * h);
    m.yaw_rate -= m
        .yaw_rate
        .clamp(-lim.max_yaw_accel * h, lim.max_yaw_accel * h);
    m.position += m.velocity * h;
}

mod way_out;

#[cfg(test)]
mod tests;
