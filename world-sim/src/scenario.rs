//! Scenarios: TOML files describing a world and its robots. Parsing rejects unknown fields;
//! validation rejects out-of-range values naming the field, so a typo never silently becomes a
//! default.

use agent::math::Real;
use serde::Deserialize;

pub use crate::floor_plan::{FloorPlanSpec, StationSpec};

/// Most robots a fleet site may have: the wire contract's bound (`schemas::MAX_ROBOTS`, which
/// the coordinator checks is the same), so that every robot of a valid scenario can be on the
/// wire.
pub const MAX_ROBOTS: usize = 4096;

/// The scenarios shipped with gapfleet, by name.
pub const BUILTIN: &[(&str, &str)] = &[
    ("open-space", include_str!("../scenarios/open-space.toml")),
    ("hallway", include_str!("../scenarios/hallway.toml")),
    (
        "open-space-walled",
        include_str!("../scenarios/open-space-walled.toml"),
    ),
    ("warehouse", include_str!("../scenarios/warehouse.toml")),
    (
        "warehouse-narrow",
        include_str!("../scenarios/warehouse-narrow.toml"),
    ),
    (
        "hallway-fleet",
        include_str!("../scenarios/hallway-fleet.toml"),
    ),
    (
        "warehouse-large",
        include_str!("../scenarios/warehouse-large.toml"),
    ),
    (
        "aws-small-warehouse",
        include_str!("../scenarios/aws-small-warehouse.toml"),
    ),
];

/// Why a scenario could not be used.
#[derive(Debug, thiserror::Error)]
pub enum ScenarioError {
    /// Not valid TOML, an unknown field, or a value of the wrong type.
    #[error("scenario {source_name}: {message}")]
    Parse {
        /// File name or built-in name.
        source_name: String,
        /// The parser's message (it names the field and the line).
        message: String,
    },
    /// A value out of range.
    #[error("scenario {source_name}: field `{field}` {reason}")]
    Invalid {
        /// File name or built-in name.
        source_name: String,
        /// Dotted path of the field.
        field: String,
        /// What is wrong with it.
        reason: String,
    },
    /// A scenario file that exists but could not be read.
    #[error("reading {path}: {message}")]
    Read {
        /// The file's path, as given.
        path: String,
        /// The system's reason.
        message: String,
    },
    /// No built-in scenario of that name.
    #[error(
        "unknown scenario {0:?}; built in: open-space, open-space-walled, hallway, hallway-fleet, warehouse, warehouse-narrow, warehouse-large, aws-small-warehouse, or give a path to a .toml file"
    )]
    Unknown(String),
}

/// A whole scenario file.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// Name, for reports.
    pub name: String,
    /// Seed of every random choice in the world.
    pub seed: u64,
    /// Simulation step (s).
    pub dt_s: Real,
    /// A run ends unsuccessfully after this long (s).
    pub max_time_s: Real,
    /// The paper's open stage.
    pub open_space: Option<OpenSpace>,
    /// A straight corridor with two-way traffic.
    pub hallway: Option<Hallway>,
    /// A procedural warehouse with pick/drop tasks.
    pub warehouse: Option<Warehouse>,
    /// A site from a real floor plan (a Nav2 map) with pick/drop tasks.
    pub floor_plan: Option<FloorPlanSpec>,
    /// The people.
    pub humans: Humans,
    /// The robots' bodies and sensors.
    pub robot: RobotSpec,
}

/// A square stage without walls, as in the PGP paper's study.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OpenSpace {
    /// Side of the square stage (m).
    pub size_m: Real,
    /// People per m²; the stage holds max(1, round(density · size²)) people.
    pub density: Real,
    /// Groups have 1 to this many members.
    pub max_group_size: usize,
    /// Encloses the stage in walls this far (m) outside its edges, so nobody can leave it;
    /// absent: no walls (the PGP paper does not mention any).
    #[serde(default)]
    pub walls_margin_m: Option<Real>,
}

/// A straight corridor along x, walled on both long sides and open at the ends, with people
/// walking end to end in both directions. The robot drives from one end to the other.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Hallway {
    /// Length (m): 25, 50 or 100 in the product's standard set; any positive value works.
    pub length_m: Real,
    /// Width between the walls (m).
    pub width_m: Real,
    /// Number of people.
    pub humans: usize,
    /// Groups have 1 to this many members.
    pub max_group_size: usize,
    /// Lanes: absent for two-way traffic; with N lanes every person walks alone along +x in
    /// one of N evenly spaced lanes, out of the far end and on, each at their own speed
    /// (uniform in ½–1½ × `humans.speed`): the peek-and-pass paper's laned hallway (Fig. 3).
    #[serde(default)]
    pub lanes: Option<usize>,
    /// A fleet hallway: with N robots the hallway is a fleet site (`warehouse::Site::hallway`):
    /// closed ends, `stations_per_end` docks across the left end and as many pick stations
    /// across the right end, the robots spread along the centre line doing pick/drop tasks in
    /// both directions, people walking to points anywhere on its floor. Absent: one robot
    /// crosses once (the studies' hallway).
    #[serde(default)]
    pub robots: Option<usize>,
    /// Stations across each end of a fleet hallway (default 3).
    #[serde(default)]
    pub stations_per_end: Option<usize>,
}

impl Hallway {
    /// Stations across each end of a fleet hallway.
    pub fn stations(&self) -> usize {
        self.stations_per_end.unwrap_or(3)
    }
}

/// A procedural warehouse (see `world_sim::warehouse`): `rows` parallel shelf rows along x,
/// each cut into `blocks` by cross-aisles, a perimeter wall, docks on the bottom corridor and
/// pick stations at the shelf faces. People walk between stations in groups; robots do
/// pick/drop tasks.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Warehouse {
    /// Shelf rows (≥ 1).
    pub rows: usize,
    /// Shelf blocks per row (≥ 1); cross-aisles separate them and run along both ends.
    pub blocks: usize,
    /// Length of one shelf block (m).
    pub shelf_length_m: Real,
    /// Depth of a shelf row (m).
    pub shelf_depth_m: Real,
    /// Width of the aisles between rows (m).
    pub aisle_width_m: Real,
    /// Width of the cross-aisles and of the bottom and top corridors (m).
    pub cross_aisle_width_m: Real,
    /// Drop stations (docks) on the bottom corridor (≥ 1).
    pub docks: usize,
    /// Number of people.
    pub humans: usize,
    /// Groups have 1 to this many members.
    pub max_group_size: usize,
    /// Number of robots (≥ 1); they start along the bottom corridor.
    pub robots: usize,
    /// Whether a route's corner on an aisle too narrow for two robots is passed within the
    /// fleet's 1 m when the straight way on clears every shelf (default), or only within
    /// what the aisle leaves beside the robot, as before results/corner-cut.
    #[serde(default = "yes")]
    pub cut_clear_corners: bool,
}

/// The simulated people.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Humans {
    /// Preferred walking speed (m/s); PySocialForce lets people reach 1.3× this.
    pub speed: Real,
    /// Body radius (m).
    pub radius_m: Real,
    /// Whether people treat robots as other pedestrians (Social Force), or ignore them.
    pub react_to_robots: bool,
    /// With `react_to_robots`: the share of people who react (the others ignore robots), each
    /// person drawn from the seed's own stream. Default 1: everyone reacts. A crowd of both
    /// kinds is what `asfm`'s estimate of who avoids the robot is checked on.
    #[serde(default = "everyone")]
    pub react_share: Real,
    /// People farther apart than this (m) do not interact; absent: everyone interacts with
    /// everyone, as in PySocialForce (O(N²), fine up to a few hundred people).
    #[serde(default)]
    pub interaction_range_m: Option<Real>,
    /// How walls and shelves push people: `"points"` (default), PySocialForce's sum over
    /// points sampled along them; `"field"`, the same force read from a table of its potential
    /// built once per scenario (`crowd::WallField`): much faster, within 0.3 % of
    /// the point sum a body's width from the walls, but not PySocialForce's arithmetic.
    #[serde(default)]
    pub walls: WallModel,
    /// Grid spacing of the `"field"` table (m).
    #[serde(default = "default_wall_field_spacing")]
    pub wall_field_spacing_m: Real,
    /// On a fleet site (a warehouse, a fleet hallway): a group none of whose members has come
    /// 0.5 m nearer its goal for this long (s) gives that goal up and picks a new one, as on
    /// arriving (`World`'s goal rule). Absent: a group keeps its goal until it arrives.
    #[serde(default)]
    pub regoal_stalled_s: Option<Real>,
}

/// How walls push people (`humans.walls`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum WallModel {
    /// PySocialForce: every sampled wall point within reach pushes on its own.
    #[default]
    Points,
    /// The points' potential tabulated on a grid and interpolated (bicubic Hermite).
    Field,
}

impl WallModel {
    /// The name used in scenario files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Self::Points => "points",
            Self::Field => "field",
        }
    }
}

impl std::str::FromStr for WallModel {
    type Err = String;

    fn from_str(name: &str) -> Result<Self, String> {
        [Self::Points, Self::Field]
            .into_iter()
            .find(|m| m.name() == name)
            .ok_or_else(|| format!("unknown wall model {name:?} (points or field)"))
    }
}

fn everyone() -> Real {
    1.0
}

fn default_wall_field_spacing() -> Real {
    0.1
}

/// A robot's body, limits and sensor.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct RobotSpec {
    /// Body radius (m).
    pub radius_m: Real,
    /// Largest speed (m/s).
    pub max_speed: Real,
    /// Largest linear acceleration (m/s²).
    pub max_accel: Real,
    /// Largest turn rate (rad/s).
    pub max_yaw_rate: Real,
    /// Largest turn acceleration (rad/s²).
    pub max_yaw_accel: Real,
    /// The goal is reached within this distance (m).
    pub goal_tolerance_m: Real,
    /// Bodies farther than this are not perceived (m).
    pub sensor_range_m: Real,
    /// Standard deviation of perceived positions (m).
    pub position_noise_m: Real,
    /// Standard deviation of perceived velocities (m/s).
    pub velocity_noise: Real,
    /// Whether walls and shelves hide what is behind them (line of sight to a body's centre).
    #[serde(default = "yes")]
    pub occlusion: bool,
    /// Whether people and robots hide what is behind them too (line of sight to a body's
    /// centre past every other body's disc), and observations carry the sensor's visibility
    /// profile (`agent::visibility`). Off by default; on in the hallway studies.
    #[serde(default)]
    pub body_occlusion: bool,
    /// Whether `agent::safety` checks every command the planner gives (on unless a scenario
    /// says `safety = false`, as the papers' studies ran; `--no-safety` on the commands).
    #[serde(default = "yes")]
    pub safety: bool,
    /// The layer's parameters on this site (`[robot.safety_layer]`; each left out keeps its
    /// default, `agent::safety::SafetyParams`).
    #[serde(default)]
    pub safety_layer: agent::safety::SafetyParams,
}

impl RobotSpec {
    /// The safety layer this robot runs, commanded every `control_period` s (0 where each
    /// plan gives its own period), or none when the scenario turns it off.
    pub fn guard(&self, control_period: Real) -> Option<agent::guard::Guard> {
        self.safety.then(|| {
            agent::guard::Guard::with_params(self.safety_limits(control_period), self.safety_layer)
        })
    }

    /// What the safety layer may assume of this base, commanded every `control_period` s: it
    /// brakes as hard as it accelerates (the simulator's limit both ways).
    pub fn safety_limits(&self, control_period: Real) -> agent::safety::SafetyLimits {
        agent::safety::SafetyLimits {
            max_speed: self.max_speed,
            max_accel: self.max_accel,
            max_braking: self.max_accel,
            max_yaw_rate: self.max_yaw_rate,
            max_yaw_accel: self.max_yaw_accel,
            control_period,
        }
    }
}

impl Warehouse {
    /// The first out-of-range field and why.
    fn validate(&self) -> Option<(&'static str, &'static str)> {
        let metres = |v: Real, lo: Real, hi: Real| v.is_finite() && v >= lo && v <= hi;
        let checks = [
            (
                "warehouse.rows",
                (1..=200).contains(&self.rows),
                "must be in [1, 200]",
            ),
            (
                "warehouse.blocks",
                (1..=50).contains(&self.blocks),
                "must be in [1, 50]",
            ),
            (
                "warehouse.shelf_length_m",
                metres(self.shelf_length_m, 1.0, 500.0),
                "must be in [1, 500] m",
            ),
            (
                "warehouse.shelf_depth_m",
                metres(self.shelf_depth_m, 0.2, 10.0),
                "must be in [0.2, 10] m",
            ),
            (
                "warehouse.aisle_width_m",
                metres(self.aisle_width_m, 1.0, 20.0),
                "must be in [1, 20] m",
            ),
            (
                "warehouse.cross_aisle_width_m",
                metres(self.cross_aisle_width_m, 1.0, 20.0),
                "must be in [1, 20] m",
            ),
            (
                "warehouse.docks",
                (1..=1000).contains(&self.docks),
                "must be in [1, 1000]",
            ),
            (
                "warehouse.max_group_size",
                self.max_group_size >= 1,
                "must be at least 1",
            ),
            (
                "warehouse.robots",
                (1..=MAX_ROBOTS).contains(&self.robots),
                "must be in [1, 4096]",
            ),
        ];
        checks.into_iter().find(|c| !c.1).map(|c| (c.0, c.2))
    }
}

pub(crate) fn yes() -> bool {
    true
}

impl Scenario {
    /// Parses and validates TOML text; `source_name` names it in errors.
    pub fn from_toml(text: &str, source_name: &str) -> Result<Self, ScenarioError> {
        let mut scenario: Scenario = toml::from_str(text).map_err(|e| ScenarioError::Parse {
            source_name: source_name.to_string(),
            message: e.to_string(),
        })?;
        if let Some(plan) = &mut scenario.floor_plan {
            // A map's and its masks' paths are relative to the scenario file's folder.
            let folder = std::path::Path::new(source_name)
                .parent()
                .unwrap_or(std::path::Path::new("."));
            plan.load(folder)
                .map_err(|(field, reason)| ScenarioError::Invalid {
                    source_name: source_name.to_string(),
                    field,
                    reason,
                })?;
        }
        scenario.validate(source_name)?;
        Ok(scenario)
    }

    /// A fleet site's robot and people counts: a warehouse's, or a fleet hallway's (`[hallway]`
    /// with `robots`); `None` for the other layouts.
    pub fn fleet_size(&self) -> Option<(usize, usize)> {
        if let Some(f) = &self.floor_plan {
            return Some((f.robots, f.humans));
        }
        match (&self.warehouse, &self.hallway) {
            (Some(w), _) => Some((w.robots, w.humans)),
            (None, Some(h)) => h.robots.map(|r| (r, h.humans)),
            (None, None) => None,
        }
    }

    /// Sets a fleet site's counts (`None` keeps one); false when the scenario is no fleet site.
    pub fn set_fleet_size(&mut self, robots: Option<usize>, humans: Option<usize>) -> bool {
        let (r, h) = match (&mut self.warehouse, &mut self.hallway, &mut self.floor_plan) {
            (_, _, Some(f)) => (&mut f.robots, &mut f.humans),
            (Some(w), _, None) => (&mut w.robots, &mut w.humans),
            (
                None,
                Some(Hallway {
                    robots: Some(r),
                    humans,
                    ..
                }),
                None,
            ) => (r, humans),
            _ => return false,
        };
        if let Some(robots) = robots {
            *r = robots;
        }
        if let Some(humans) = humans {
            *h = humans;
        }
        true
    }

    /// A built-in scenario by name.
    pub fn builtin(name: &str) -> Result<Self, ScenarioError> {
        let (_, text) = BUILTIN
            .iter()
            .find(|(n, _)| *n == name)
            .ok_or_else(|| ScenarioError::Unknown(name.to_string()))?;
        Self::from_toml(text, name)
    }

    /// A scenario as the command line names it: a built-in by name, else the TOML file at that
    /// path; with its TOML text (a journal keeps it, to build the scenario again). Neither a
    /// built-in nor an existing file: the error lists the built-ins.
    pub fn load(name_or_path: &str) -> Result<(Self, String), ScenarioError> {
        if let Some((_, text)) = BUILTIN.iter().find(|(n, _)| *n == name_or_path) {
            return Ok((Self::from_toml(text, name_or_path)?, (*text).to_owned()));
        }
        let path = std::path::Path::new(name_or_path);
        if !path.exists() {
            return Err(ScenarioError::Unknown(name_or_path.to_string()));
        }
        let text = std::fs::read_to_string(path).map_err(|e| ScenarioError::Read {
            path: name_or_path.to_string(),
            message: e.to_string(),
        })?;
        Ok((Self::from_toml(&text, name_or_path)?, text))
    }

    /// Checks every value's range, naming the first bad field.
    pub fn validate(&self, source_name: &str) -> Result<(), ScenarioError> {
        let bad = |field: &str, reason: &str| {
            Err(ScenarioError::Invalid {
                source_name: source_name.to_string(),
                field: field.to_string(),
                reason: reason.to_string(),
            })
        };
        let positive = |v: Real| v.is_finite() && v > 0.0;
        let non_negative = |v: Real| v.is_finite() && v >= 0.0;
        if !positive(self.dt_s) || self.dt_s > 1.0 {
            return bad("dt_s", "must be in (0, 1] s");
        }
        if !positive(self.max_time_s) {
            return bad("max_time_s", "must be positive");
        }
        let layouts = [
            ("open_space", self.open_space.is_some()),
            ("hallway", self.hallway.is_some()),
            ("warehouse", self.warehouse.is_some()),
            ("floor_plan", self.floor_plan.is_some()),
        ];
        let given: Vec<&str> = layouts.iter().filter(|l| l.1).map(|l| l.0).collect();
        if given.is_empty() {
            return bad(
                "open_space",
                "is missing: a scenario needs one layout table ([open_space], [hallway], [warehouse] or [floor_plan])",
            );
        }
        if given.len() > 1 {
            return bad(
                given[1],
                &format!("conflicts with [{}]: give one layout table", given[0]),
            );
        }
        if let Some(w) = &self.warehouse {
            w.validate()
                .map_or(Ok(()), |(field, reason)| bad(field, reason))?;
        }
        match (&self.open_space, &self.hallway) {
            (None, None) | (Some(_), Some(_)) => {}
            (Some(open), None) => {
                if !positive(open.size_m) || open.size_m > 1000.0 {
                    return bad("open_space.size_m", "must be in (0, 1000] m");
                }
                if !positive(open.density) || open.density > 3.0 {
                    return bad("open_space.density", "must be in (0, 3] people per m²");
                }
                if open.max_group_size == 0 {
                    return bad("open_space.max_group_size", "must be at least 1");
                }
                if open
                    .walls_margin_m
                    .is_some_and(|m| !(m.is_finite() && m > 0.0))
                {
                    return bad("open_space.walls_margin_m", "must be positive");
                }
            }
            (None, Some(hall)) => {
                if !positive(hall.length_m) || hall.length_m < 2.0 || hall.length_m > 10_000.0 {
                    return bad("hallway.length_m", "must be in [2, 10000] m");
                }
                if !positive(hall.width_m) || hall.width_m < 1.0 || hall.width_m > 100.0 {
                    return bad("hallway.width_m", "must be in [1, 100] m");
                }
                if hall.max_group_size == 0 {
                    return bad("hallway.max_group_size", "must be at least 1");
                }
                if let Some(lanes) = hall.lanes
                    && (lanes == 0 || hall.width_m / (lanes as Real) < 2.0 * self.humans.radius_m)
                {
                    return bad("hallway.lanes", "must be at least 1, each lane a body wide");
                }
                if let Some(robots) = hall.robots {
                    if !(1..=MAX_ROBOTS).contains(&robots) {
                        return bad("hallway.robots", "must be in [1, 4096]");
                    }
                    if hall.lanes.is_some() {
                        return bad(
                            "hallway.robots",
                            "a fleet hallway has two-way traffic: no lanes",
                        );
                    }
                }
                if hall.stations_per_end.is_some() && hall.robots.is_none() {
                    return bad(
                        "hallway.stations_per_end",
                        "only a fleet hallway (robots = N) has stations",
                    );
                }
                if !(1..=100).contains(&hall.stations()) {
                    return bad("hallway.stations_per_end", "must be in [1, 100]");
                }
            }
        }
        let h = &self.humans;
        // 0 (people stand) to 3.5 m/s: the peek-and-pass paper's hallway study's range.
        if !(h.speed.is_finite() && (0.0..=3.5).contains(&h.speed)) {
            return bad("humans.speed", "must be in [0, 3.5] m/s");
        }
        if !positive(h.radius_m) || h.radius_m > 1.0 {
            return bad("humans.radius_m", "must be in (0, 1] m");
        }
        if !(0.0..=1.0).contains(&h.react_share) {
            return bad("humans.react_share", "must be in [0, 1]");
        }
        if h.interaction_range_m.is_some_and(|r| !positive(r)) {
            return bad("humans.interaction_range_m", "must be positive");
        }
        if !(h.wall_field_spacing_m >= 0.01 && h.wall_field_spacing_m <= 1.0) {
            return bad("humans.wall_field_spacing_m", "must be in [0.01, 1] m");
        }
        if h.regoal_stalled_s
            .is_some_and(|t| !(t > 0.0 && t.is_finite()))
        {
            return bad(
                "humans.regoal_stalled_s",
                "must be a positive number of seconds",
            );
        }
        let r = &self.robot;
        for (field, value) in [
            ("robot.radius_m", r.radius_m),
            ("robot.max_speed", r.max_speed),
            ("robot.max_accel", r.max_accel),
            ("robot.max_yaw_rate", r.max_yaw_rate),
            ("robot.max_yaw_accel", r.max_yaw_accel),
            ("robot.goal_tolerance_m", r.goal_tolerance_m),
            ("robot.sensor_range_m", r.sensor_range_m),
        ] {
            if !positive(value) {
                return bad(field, "must be positive");
            }
        }
        for (field, value) in [
            ("robot.position_noise_m", r.position_noise_m),
            ("robot.velocity_noise", r.velocity_noise),
        ] {
            if !non_negative(value) {
                return bad(field, "must be zero or positive");
            }
        }
        if let Err((field, reason)) = r.safety_layer.validate() {
            return bad(&format!("robot.safety_layer.{field}"), &reason);
        }
        if let Some(plan) = &self.floor_plan {
            plan.validate(r.radius_m)
                .map_or(Ok(()), |(field, reason)| bad(&field, &reason))?;
        }
        Ok(())
    }

    /// The built-in open stage resized to hold `people` at `density` (for benchmarks and
    /// sizing studies), with a 6 m interaction range so that large crowds step in O(N).
    pub fn sized_for(people: usize, density: Real) -> Result<Self, ScenarioError> {
        let mut s = Self::builtin("open-space")?;
        let open = s.open_space.as_mut().expect("the built-in has a layout");
        open.density = density;
        open.size_m = (people as Real / density).sqrt();
        s.humans.interaction_range_m = Some(6.0);
        s.validate("sized open-space")?;
        Ok(s)
    }

    /// Number of people on the open stage: max(1, round(density · size²)).
    pub fn human_count(&self) -> usize {
        self.open_space.map_or(0, |o| {
            ((o.density * o.size_m * o.size_m).round() as usize).max(1)
        })
    }
}

#[cfg(test)]
mod tests;
