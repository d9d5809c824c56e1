//! What the safety layer is told: what the robot's base guarantees ([`SafetyLimits`]) and the
//! layer's own parameters ([`SafetyParams`]), with their ranges, defaults and the reasons
//! for them.

use crate::math::Real;

/// What the robot's base guarantees, and how often it is commanded.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SafetyLimits {
    /// Largest speed the base executes (m/s).
    pub max_speed: Real,
    /// Largest acceleration towards a commanded velocity (m/s²).
    pub max_accel: Real,
    /// Deceleration the base guarantees when stopping (m/s²): the braking a safety-rated stop
    /// achieves. Never more than the base can do.
    pub max_braking: Real,
    /// Largest turn rate (rad/s), for unicycle bases.
    pub max_yaw_rate: Real,
    /// Largest turn-rate change (rad/s²), for unicycle bases.
    pub max_yaw_accel: Real,
    /// How long a command holds before the next one (s): the control period.
    pub control_period: Real,
}

impl SafetyLimits {
    /// The simulator's default robot (`world-sim/scenarios/*.toml`, `[robot]`): 1 m/s,
    /// 1.5 m/s² both ways, 1 rad/s, 1.5 rad/s², commanded at 10 Hz.
    pub const SIMULATED_ROBOT: Self = Self {
        max_speed: 1.0,
        max_accel: 1.5,
        max_braking: 1.5,
        max_yaw_rate: 1.0,
        max_yaw_accel: 1.5,
        control_period: 0.1,
    };

    /// The deceleration a stop may count on: the guaranteed braking, never more than the
    /// base's acceleration limit (which is how it executes a stop command).
    pub fn braking(&self) -> Real {
        self.max_braking.min(self.max_accel)
    }
}

/// The layer's own parameters. None comes from the papers; each is named with its source or
/// the reason for its value. A scenario may set them (`[robot.safety_layer]`), as a safety
/// scanner is given a field set per site.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default, deny_unknown_fields))]
pub struct SafetyParams {
    /// T_r (s), ISO 13855's response time beyond the control period: from a body appearing
    /// in an observation to the base acting on the stop. Safety laser scanners respond in
    /// 60–120 ms; gapfleet's observation → command round trip is under 10 ms at p99.
    pub reaction_time: Real,
    /// C + Z (m): the gap kept at every instant of the rollout, for perception uncertainty
    /// (Z) and what the bodies' constant-velocity extrapolation misses (C). 5 cm: the
    /// simulator's perception is exact by default; a real scanner's tolerance is a few cm.
    pub margin: Real,
    /// T_w (s): the warning field looks this much further, as if the command were kept this
    /// long before braking. One second: a person at walking speed covers about 1.3 m. The
    /// `warehouse` and `hallway-fleet` scenarios set 0.5 s (results/warning-time/REPORT.md).
    pub warning_time: Real,
    /// The speed fraction a command is slowed to in the warning field (ISO 3691-4's reduced
    /// speed in a warning zone; half is a common scanner-field setting).
    pub warning_scale: Real,
    /// Whether the warning field slows a command only as far as it must (Nav2's collision
    /// monitor's *approach* model): to the largest fraction of it, between 1 and
    /// `warning_scale` on the [`LADDER`](crate::safety::LADDER), that the warning check passes,
    /// and to `warning_scale` when none does. Graded, it tries `warning_scale` before the
    /// ladder's fractions below it, so it never keeps less of a command than the fixed field.
    /// `false`, the default: every warned command goes to `warning_scale`. Either way the
    /// protective check follows, so the guarantee is the same.
    pub warning_graded: bool,
    /// a_h (m/s²): how hard a perceived *person* may change their motion. In the protective
    /// check a person may stray ½·a_h·t² from both hypotheses, in any direction: a person who
    /// walks beside the robot and swerves across its path after its last safe command. Robots
    /// do not swerve (their own layers hold them), so they keep the two hypotheses alone.
    /// 3 m/s²: about the simulated people's 99th-percentile acceleration (3.3 m/s²), and the
    /// swerve behind the last robot-caused contact that 2 m/s² left in the intent-sharing
    /// study (seed 4). ISO 13855's v_h = 1.6 m/s from anywhere would freeze robots in a crowd
    /// (agent/README.md, "The safety layer", has the sweep).
    pub person_accel: Real,
    /// a_h across a walking person's way (m/s²): a person walking at
    /// [`ACROSS_MIN_SPEED`] or more may stray ½·a_h·t² along their way and only this much
    /// (½·a_⊥·t²) across it, an ellipse; a standing person a_h every way. At or above
    /// `person_accel` (the default equals it), the check is round, as shipped. People stray across
    /// their way about half as far as along it: at the stop's horizon (0.9 s) at most
    /// 2.2 m/s² in the simulated crowds and 2.4 m/s² in ETH and UCY
    /// (results/fleet-one-robot/layer-sensitivity). Opt-in, and not safe enough as it stands:
    /// over shorter times people stray across harder (4.9 m/s² at 0.4 s on seq_eth), and
    /// under a_⊥ = 2.4 foIGP causes a contact in the seq_eth replay (measured there).
    pub person_accel_across: Real,
    /// a_h away from the places where people stop and turn (m/s²): a person farther than
    /// [`turn_reach`](Self::turn_reach) from every such place the site marks (the stations of
    /// a warehouse whose people walk station to station; `Guard::set_turn_places`) may swerve
    /// at this much, everyone else at `person_accel`. With no places marked (open ground,
    /// recorded crowds, the fleet hallway, floor plans), or at or above `person_accel`, the
    /// check is a_h everywhere. 2 m/s²: the robot-caused contacts that a_h = 2 everywhere lets
    /// through in the fleets were all people whose goal had changed 0.3–0.4 s before, turning
    /// back or setting off at up to 8 m/s² over 0.3 s; chosen on fleet seeds 1–60 and checked
    /// on seeds 101–160 and the intent-sharing study, with no robot-caused contact and more
    /// tasks (results/swerve-allowance). 3 (= a_h) is the layer before.
    pub person_accel_away: Real,
    /// How near a place where people stop and turn a person keeps the full a_h (m, along
    /// each axis from the place's box). 3 m: people turn within about 0.5 m of their goal,
    /// and the turn is over within about three relaxation times of PySocialForce's people
    /// (τ = 0.5 s), in which they walk under 2 m.
    pub turn_reach: Real,
    /// The rollout's time step, at most (s): the check's time resolution; each control
    /// period is cut into as many equal sub-steps as it takes. 50 ms (two per period at
    /// 10 Hz, eight for the replays' 0.4 s): bodies closing at 3 m/s move 15 cm between
    /// samples, far less than two bodies' width, so no conflict passes between samples
    /// unseen.
    pub check_step: Real,
    /// T_y (s): how far ahead the layer looks for someone who walks into the robot were it to
    /// stop, and over which it compares the ways out. 2 s: a person walking at 1.3 m/s from
    /// 2.6 m away; farther threats are the planner's to avoid. Ours (1.5 s saw a group of
    /// three coming down an aisle too late to back off; 3 s had a robot overtaken in an
    /// aisle race ahead of the person instead of stepping aside: `tests`).
    pub yield_time: Real,
    /// The body clearance (m, surface to surface) a way out aims at: clearances beyond it
    /// count as equal, and the way out nearest the planner's command is taken. 0.2 m: room
    /// for a person walking on to pass without touching, small enough that a way out near
    /// the planner's command usually reaches it (with no cap the robot would turn whichever
    /// way keeps it clearest, away from its task). Ours.
    pub yield_clearance: Real,
    /// Whether the layer yields at all (off: it only slows and stops, as before issue 43).
    pub yielding: bool,
    /// T_m (s): how long the robot's [`Guard`](crate::guard::Guard) keeps a body it no longer
    /// perceives, walking on at its last perceived velocity, in what the layer checks. A
    /// person hidden for a moment behind someone else, or behind a shelf's end, is still
    /// there; a layer that checks only what it sees drives into them as they step out. 0
    /// keeps nothing. 1 s: in the hallway study's tuning runs (seeds 1–30, people at
    /// 2–3 m/s, who hid each other for 0.3–0.5 s before the contacts the layer let through)
    /// robot-caused contacts fell from 25 to 12 at 0.5 s and to 5 at 1 s, with median times
    /// within 2–6 % (results/safety/REPORT.md, "Memory").
    pub memory_time: Real,
    /// Whether a perceived *person* may stop dead, from walking to a standstill at once, as a
    /// robot ahead may (its hypothesis: braking hard). `false`, the default: a person walking
    /// at up to [`HALTING_MAX_SPEED`] changes their motion only as `person_accel` allows,
    /// braking included. In the protective check that is ½·a_h·t² from walking on, which
    /// holds every way of halting at ≤ a_h; the warning field looks at them braking at a_h.
    /// Faster people, robots, and people when `person_accel` is 0 may still stop dead.
    /// Stopping dead sat outside the layer's own motion model (people change their motion at
    /// ≤ a_h, the simulated and recorded people's p99.9 stray at the stop's horizon) and held
    /// robots a second's walk behind anyone walking their way: on the tuning seeds (fleets
    /// 1–10, the hallway study 1–12, open space 1–20, seq_eth) `false` did more work in every
    /// fleet cell with fewer person-caused contacts and no robot-caused contact
    /// (results/halting/REPORT.md, with the held-out seeds). `true` is the layer before.
    pub people_stop_dead: bool,
}

impl SafetyParams {
    /// The first parameter out of its range (its name) and why.
    pub fn validate(&self) -> Result<(), (&'static str, String)> {
        let within = |name: &'static str, v: Real, lo: Real, hi: Real| {
            if v.is_finite() && (lo..=hi).contains(&v) {
                Ok(())
            } else {
                Err((name, format!("is {v}; it must be in [{lo}, {hi}]")))
            }
        };
        within("reaction_time", self.reaction_time, 0.0, 2.0)?;
        within("margin", self.margin, 0.0, 2.0)?;
        within("warning_time", self.warning_time, 0.0, 10.0)?;
        within("warning_scale", self.warning_scale, 0.05, 1.0)?;
        within("person_accel", self.person_accel, 0.0, 20.0)?;
        within("person_accel_across", self.person_accel_across, 0.0, 20.0)?;
        within("person_accel_away", self.person_accel_away, 0.0, 20.0)?;
        within("turn_reach", self.turn_reach, 0.0, 100.0)?;
        within("check_step", self.check_step, 0.005, 0.5)?;
        within("yield_time", self.yield_time, 0.1, 10.0)?;
        within("yield_clearance", self.yield_clearance, 0.0, 3.0)?;
        within("memory_time", self.memory_time, 0.0, 10.0)
    }
}

impl SafetyParams {
    /// These parameters with some changed, as `key=value,key=value` (the field names,
    /// `yielding`, `people_stop_dead` and `warning_graded` taking `true` or `false`),
    /// validated; an empty text changes nothing.
    pub fn with_overrides(mut self, text: &str) -> Result<Self, String> {
        for pair in text.split(',').map(str::trim).filter(|p| !p.is_empty()) {
            let (key, value) = pair
                .split_once('=')
                .ok_or_else(|| format!("`{pair}`: expected key=value"))?;
            if let Some((_, flag)) = self.flags_mut().into_iter().find(|(k, _)| *k == key) {
                *flag = value
                    .parse()
                    .map_err(|_| format!("`{pair}`: {key} is true or false"))?;
                continue;
            }
            let Some((_, field)) = self.values_mut().into_iter().find(|(k, _)| *k == key) else {
                return Err(format!("`{key}` is not a safety-layer parameter"));
            };
            *field = value.parse().map_err(|e| format!("`{pair}`: {e}"))?;
        }
        self.validate()
            .map_err(|(field, why)| format!("{field} {why}"))?;
        Ok(self)
    }

    /// The parameters that differ from the defaults, as `key=value,…` ([`Self::with_overrides`]
    /// of the defaults reads it back); empty for the defaults.
    pub fn changes(&self) -> String {
        let (mut this, mut base) = (*self, Self::default());
        this.printed()
            .into_iter()
            .zip(base.printed())
            .filter(|(this, base)| this != base)
            .map(|((name, value), _)| format!("{name}={value}"))
            .collect::<Vec<_>>()
            .join(",")
    }

    /// Every parameter by name, written as [`Self::with_overrides`] reads it.
    fn printed(&mut self) -> Vec<(&'static str, String)> {
        let values = self.values_mut().map(|(name, v)| (name, v.to_string()));
        let flags = self.flags_mut().map(|(name, f)| (name, f.to_string()));
        values.into_iter().chain(flags).collect()
    }

    /// The numeric parameters by name.
    fn values_mut(&mut self) -> [(&'static str, &mut Real); 12] {
        [
            ("reaction_time", &mut self.reaction_time),
            ("margin", &mut self.margin),
            ("warning_time", &mut self.warning_time),
            ("warning_scale", &mut self.warning_scale),
            ("person_accel", &mut self.person_accel),
            ("person_accel_across", &mut self.person_accel_across),
            ("person_accel_away", &mut self.person_accel_away),
            ("turn_reach", &mut self.turn_reach),
            ("check_step", &mut self.check_step),
            ("yield_time", &mut self.yield_time),
            ("yield_clearance", &mut self.yield_clearance),
            ("memory_time", &mut self.memory_time),
        ]
    }

    /// The switches by name.
    fn flags_mut(&mut self) -> [(&'static str, &mut bool); 3] {
        [
            ("yielding", &mut self.yielding),
            ("people_stop_dead", &mut self.people_stop_dead),
            ("warning_graded", &mut self.warning_graded),
        ]
    }
}

impl Default for SafetyParams {
    fn default() -> Self {
        Self {
            reaction_time: 0.1,
            margin: 0.05,
            warning_time: 1.0,
            warning_scale: 0.5,
            warning_graded: false,
            person_accel: 3.0,
            person_accel_across: 3.0,
            person_accel_away: 2.0,
            turn_reach: 3.0,
            check_step: 0.05,
            yield_time: 2.0,
            yield_clearance: 0.2,
            yielding: true,
            memory_time: 1.0,
            people_stop_dead: false,
        }
    }
}

/// A person walking at least this fast (m/s) has a way to stray across
/// ([`SafetyParams::person_accel_across`]); a slower one's is not known.
pub const ACROSS_MIN_SPEED: Real = 0.3;

/// The fastest a person may walk (m/s) and still be taken to halt no harder than a_h
/// ([`SafetyParams::people_stop_dead`]); a faster one may still stop dead. a_h was measured on
/// people walking about 1 m/s (the simulated warehouse and hallway fleets, ETH and UCY:
/// results/fleet-one-robot/layer-sensitivity); simulated people at 2–3 m/s brake at up to
/// 15 m/s² when they run into others (results/halting).
pub const HALTING_MAX_SPEED: Real = 1.5;
