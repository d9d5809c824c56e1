//! What the journal holds: the run's header (site, scenario, intent sharing, traffic policy,
//! real robots), each tick's inputs, the intents shared, the end record and the event log's
//! lines.

use super::{FORMAT, JournalError};
use agent::runtime::wire;
use schemas::{Motion, Sample};
use serde::{Deserialize, Serialize};
use world_sim::fleet::Fleet;
use world_sim::scenario::Scenario;
use world_sim::traffic_policy::PolicyParams;

/// Where a run's scenario came from, enough to build it again.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ScenarioSource {
    /// Its name (a built-in's, or the file's path) for messages.
    pub name: String,
    /// Its TOML text.
    pub toml: String,
    /// Robots, when overridden.
    pub robots: Option<usize>,
    /// People, when overridden.
    pub humans: Option<usize>,
    /// Seed, when overridden.
    pub seed: Option<u64>,
    /// Whether the safety layer was turned off.
    pub no_safety: bool,
    /// A floor plan's map fingerprint (`FloorPlan::fingerprint`): a map given by path is read
    /// again when the run is rebuilt, and must be the one the run had.
    #[serde(default)]
    pub map_fingerprint: Option<u64>,
}

impl ScenarioSource {
    /// The built-in scenario `name` with these overrides (None: no such built-in).
    pub fn builtin(
        name: &str,
        robots: Option<usize>,
        humans: Option<usize>,
        seed: Option<u64>,
    ) -> Option<Self> {
        let (_, toml) = world_sim::scenario::BUILTIN
            .iter()
            .find(|(n, _)| *n == name)?;
        Some(Self {
            name: name.to_owned(),
            toml: (*toml).to_owned(),
            robots,
            humans,
            seed,
            no_safety: false,
            map_fingerprint: None,
        })
    }

    /// The scenario as a fleet site, with the overrides applied and validated (the one place
    /// both the command line and a journal build it).
    pub fn scenario(&self) -> Result<Scenario, JournalError> {
        let bad = |e: String| JournalError::Scenario(format!("{}: {e}", self.name));
        let mut s = Scenario::from_toml(&self.toml, &self.name).map_err(|e| bad(e.to_string()))?;
        let plan = s.floor_plan.as_ref().and_then(|f| f.plan.as_ref());
        if let (Some(want), Some(plan)) = (self.map_fingerprint, plan)
            && plan.fingerprint != want
        {
            return Err(bad(format!(
                "its map {} is not the one the run had (fingerprint {:016x}, the run's {want:016x})",
                plan.source, plan.fingerprint
            )));
        }
        if !s.set_fleet_size(self.robots, self.humans) {
            return Err(bad(
                "not a fleet site (it needs a [warehouse] or [floor_plan] table, or a [hallway] with robots = N)"
                    .to_owned(),
            ));
        }
        if let Some(seed) = self.seed {
            s.seed = seed;
        }
        if self.no_safety {
            s.robot.safety = false;
        }
        s.validate(&self.name).map_err(|e| bad(e.to_string()))?;
        Ok(s)
    }
}

/// What a run is: written once, first.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Header {
    /// The journal's format.
    pub format: u32,
    /// Site name.
    pub site: String,
    /// The scenario.
    pub scenario: ScenarioSource,
    /// Whether observations carried other robots' intents (no effect on the world; kept for
    /// the record).
    pub share_intents: bool,
    /// Whether the traffic policy ran.
    pub traffic_policy: bool,
    /// Its parameters, where it ran; journals older than this field ran the defaults of
    /// their day, before robots turned round from people ([`Header::policy`]).
    #[serde(default)]
    pub policy_params: Option<PolicyParams>,
    /// The real robots the coordinator did not simulate: their bodies moved only where their
    /// agents reported them ([`TickInput::placed`]).
    #[serde(default)]
    pub live: Vec<u32>,
}

impl Header {
    /// A run of `scenario` on `site`, with the traffic policy `policy` (`None`: off).
    pub fn new(
        site: &str,
        scenario: ScenarioSource,
        share_intents: bool,
        policy: Option<PolicyParams>,
    ) -> Self {
        Self {
            format: FORMAT,
            site: site.to_owned(),
            scenario,
            share_intents,
            traffic_policy: policy.is_some(),
            policy_params: policy,
            live: Vec::new(),
        }
    }

    /// The traffic policy the run ran: its parameters, or `None` where it was off. A journal
    /// older than `policy_params` ran the defaults of its day: those of now without
    /// [`PolicyParams::people_turn_after_s`] and [`PolicyParams::alone_exit_clear_m`], the
    /// defaults changed since.
    pub fn policy(&self) -> Option<PolicyParams> {
        self.traffic_policy.then(|| {
            self.policy_params.unwrap_or(PolicyParams {
                people_turn_after_s: 0.0,
                alone_exit_clear_m: 0.0,
                ..PolicyParams::default()
            })
        })
    }

    /// The traffic policy in words: off, on with the defaults, or on with the parameters
    /// that differ from them.
    pub fn policy_text(&self) -> String {
        match self.policy() {
            None => "off".to_owned(),
            Some(p) if p.changes().is_empty() => "on, default parameters".to_owned(),
            Some(p) => format!("on, parameters changed: {}", p.changes()),
        }
    }

    /// Whether `other` records the same run: the same fields, a journal without policy
    /// parameters counting as one with the defaults.
    pub fn same_run(&self, other: &Self) -> bool {
        let plain = |h: &Self| Self {
            policy_params: h.policy(),
            ..h.clone()
        };
        plain(self) == plain(other)
    }

    /// The same run with `live` as its real robots.
    pub fn with_live(mut self, live: Vec<u32>) -> Self {
        self.live = live;
        self
    }
}

/// One tick's inputs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TickInput {
    /// The tick (0 = the first step).
    pub tick: u64,
    /// Robots whose held flag changed before this tick's step, with the new flag.
    pub held: Vec<(u32, bool)>,
    /// The command each moving robot drove on (robots not listed stood still).
    pub commands: Vec<(u32, Motion)>,
    /// Intents taken from agents since the previous tick's step, in the order they were set.
    pub intents: Vec<IntentInput>,
    /// Robots whose safety layer held back the command they drove on (a protective stop or
    /// slow-down, or a yield): the fleet counts what held its stuck robots by it.
    pub layer_held: Vec<u32>,
    /// The world's fingerprint after this tick's step, every [`FINGERPRINT_EVERY`](super::FINGERPRINT_EVERY) ticks.
    pub fingerprint: Option<u64>,
    /// Real robots placed where their agents reported them, before this tick's step (only
    /// robots with a report new since the last tick).
    #[serde(default)]
    pub placed: Vec<(u32, schemas::RobotState)>,
}

/// An intent as the coordinator set it in the fleet.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IntentInput {
    /// The robot.
    pub robot: u32,
    /// The intent's stamp (s).
    pub stamp: f64,
    /// Its trajectory, as it came over the wire.
    pub trajectory: Vec<Sample>,
}

impl IntentInput {
    /// Sets the intent in `fleet` as the coordinator did.
    pub(super) fn apply(&self, fleet: &mut Fleet) -> Result<(), JournalError> {
        let n = fleet.robots();
        if self.robot as usize >= n {
            return Err(JournalError::Record(format!("robot {} of {n}", self.robot)));
        }
        let samples = wire::samples_from_wire(&self.trajectory);
        fleet.set_intent(self.robot as usize, self.stamp, samples);
        Ok(())
    }
}

/// How a run ended.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct End {
    /// Ticks run.
    pub ticks: u64,
    /// The world's fingerprint at the end.
    pub fingerprint: u64,
    /// Tasks done.
    pub tasks_done: u64,
    /// Records the queue dropped (0 for a journal that replays to the end).
    pub lost: u64,
}

/// A line of the event log.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EventRecord {
    /// The tick it happened at.
    pub tick: u64,
    /// Simulated time (s).
    pub sim_time: f64,
    /// What happened, as the coordinator logs it.
    pub event: String,
}

#[cfg(test)]
mod tests {
    use super::super::{pack, unpack};
    use super::*;

    fn header(policy: Option<PolicyParams>) -> Header {
        let source =
            ScenarioSource::builtin("warehouse", Some(2), Some(3), Some(1)).expect("built in");
        Header::new("site", source, true, policy)
    }

    #[test]
    fn the_policy_parameters_travel_in_the_header() {
        let tuned = PolicyParams::default()
            .with_overrides("people_route_weight_m=3")
            .expect("a known parameter");
        let h: Header = unpack(&pack(&header(Some(tuned)))).expect("reads back");
        assert_eq!(h.policy(), Some(tuned));
        assert!(!h.same_run(&header(Some(PolicyParams::default()))));
        assert!(!h.same_run(&header(None)));
        assert_eq!(header(None).policy(), None);
        assert_eq!(header(None).policy_text(), "off");
        assert_eq!(
            header(Some(PolicyParams::default())).policy_text(),
            "on, default parameters"
        );
        assert_eq!(
            h.policy_text(),
            "on, parameters changed: people_route_weight_m=3"
        );
    }

    #[test]
    fn a_header_from_before_the_parameters_ran_the_defaults_of_its_day() {
        /// The header as journals wrote it before `policy_params`.
        #[derive(Serialize)]
        struct Older {
            format: u32,
            site: String,
            scenario: ScenarioSource,
            share_intents: bool,
            traffic_policy: bool,
            live: Vec<u32>,
        }
        let now = header(Some(PolicyParams::default()));
        let older = Older {
            format: now.format,
            site: now.site.clone(),
            scenario: now.scenario.clone(),
            share_intents: now.share_intents,
            traffic_policy: true,
            live: Vec::new(),
        };
        let h: Header = unpack(&pack(&older)).expect("an older header reads");
        assert_eq!(h.policy_params, None);
        let of_its_day = PolicyParams {
            people_turn_after_s: 0.0,
            alone_exit_clear_m: 0.0,
            ..PolicyParams::default()
        };
        assert_eq!(h.policy(), Some(of_its_day));
        assert!(
            h.same_run(&header(Some(of_its_day))),
            "an older journal of the default policy goes on as it ran"
        );
        assert!(
            !h.same_run(&now),
            "today's defaults turn robots round from people; that journal's run did not"
        );
    }
}
