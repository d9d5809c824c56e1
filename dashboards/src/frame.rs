//! The plain data a caller hands the dashboard: the static map and one [`Frame`] per tick.

use crate::P;

/// The static site.
#[derive(Debug, Clone, Default)]
pub struct MapFrame {
    /// Closed polygons (shelves).
    pub shelves: Vec<Vec<P>>,
    /// Wall segments.
    pub walls: Vec<[P; 2]>,
    /// Stations with labels.
    pub stations: Vec<(P, String)>,
    /// The edges of keep-out zones: walls to robots, open to people.
    pub keepout: Vec<[P; 2]>,
}

/// One robot as drawn.
#[derive(Debug, Clone)]
pub struct RobotView {
    /// Robot id.
    pub id: u32,
    /// Position.
    pub position: P,
    /// Heading (rad).
    pub heading: f32,
    /// Body radius (m).
    pub radius: f32,
    /// Label suffix, e.g. the planner name.
    pub planner: String,
    /// Agent alive.
    pub alive: bool,
}

/// Which of a robot's safety fields acted on its newest command.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FieldState {
    /// Neither (or no layer).
    #[default]
    Clear,
    /// The warning field slowed it.
    Warning,
    /// The protective field slowed it further or stopped it.
    Protective,
    /// The layer yielded: someone would have walked into the stopped robot, and it took a
    /// way out.
    Yield,
}

/// A robot's protective and warning fields as outlines on the floor.
#[derive(Debug, Clone)]
pub struct FieldView {
    /// Robot id.
    pub robot: u32,
    /// The protective field's outline (closed).
    pub protective: Vec<P>,
    /// The warning field's outline (closed).
    pub warning: Vec<P>,
    /// Which field acted on the robot's newest command.
    pub state: FieldState,
}

/// A robot's announced intent.
#[derive(Debug, Clone)]
pub struct IntentView {
    /// Robot id.
    pub robot: u32,
    /// Planned path.
    pub path: Vec<P>,
    /// Subgoal.
    pub subgoal: P,
}

/// A PGP candidate fan.
#[derive(Debug, Clone)]
pub struct FanView {
    /// Robot id.
    pub robot: u32,
    /// Each candidate's path and final survival probability.
    pub candidates: Vec<(Vec<P>, f32)>,
}

/// Something that happened.
#[derive(Debug, Clone)]
pub struct EventView {
    /// Text for the log.
    pub text: String,
    /// Where to put a marker, if it happened somewhere.
    pub position: Option<P>,
    /// Whether it is bad news (collision, crash).
    pub warning: bool,
}

/// A one-way aisle segment and its reservation.
#[derive(Debug, Clone)]
pub struct SegmentView {
    /// Segment index.
    pub id: u32,
    /// Lower-left corner.
    pub min: P,
    /// Upper-right corner.
    pub max: P,
    /// The direction it is reserved in (+1 along x, −1 against), `None` when free.
    pub direction: Option<i8>,
    /// Robots holding it.
    pub holders: Vec<u32>,
    /// Robots waiting for it.
    pub waiting: Vec<u32>,
}

/// A robot's goal as the traffic policy set it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TrafficGoal {
    /// Waiting short of a segment.
    Hold,
    /// Waiting in line for a station.
    Queue,
    /// Backing off out of a wait-for cycle.
    Retreat,
    /// Pulled over, letting a two-way knot's other direction pass.
    GiveWay,
}

/// The fleet's traffic: reservations, who waits on whom, stuck robots.
#[derive(Debug, Clone, Default)]
pub struct TrafficView {
    /// One-way segments (empty where aisles are wide).
    pub segments: Vec<SegmentView>,
    /// Wait-for edges: from the waiting robot's position to the one it waits on, and whether
    /// the edge is part of a cycle.
    pub waits: Vec<(P, P, bool)>,
    /// Stuck robots: id, position, radius.
    pub stuck: Vec<(u32, P, f32)>,
    /// Goals the policy set: robot, point, kind.
    pub goals: Vec<(u32, P, TrafficGoal)>,
}

/// What a heatmap marks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HeatKind {
    /// A robot within 1 m of a person (weight: seconds).
    NearPeople = 0,
    /// A contact between a robot and a person began (weight: 1).
    Contact = 1,
    /// A robot stood stuck (weight: seconds).
    Stuck = 2,
    /// People lost time to robots (weight: person-seconds of delay).
    PeopleDelay = 3,
}

impl HeatKind {
    /// Every kind, in index order.
    pub const ALL: [HeatKind; 4] = [
        HeatKind::NearPeople,
        HeatKind::Contact,
        HeatKind::Stuck,
        HeatKind::PeopleDelay,
    ];

    /// The entity name.
    pub fn name(self) -> &'static str {
        match self {
            HeatKind::NearPeople => "near_people",
            HeatKind::Contact => "contacts",
            HeatKind::Stuck => "stuck",
            HeatKind::PeopleDelay => "people_delay",
        }
    }

    pub(crate) fn colour(self) -> [u8; 3] {
        match self {
            HeatKind::NearPeople => [240, 150, 0],
            HeatKind::Contact => [220, 20, 20],
            HeatKind::Stuck => [140, 40, 200],
            HeatKind::PeopleDelay => [30, 110, 230],
        }
    }
}

/// One heatmap event: something of `kind` at `at`, weighing `weight`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeatEvent {
    /// What.
    pub kind: HeatKind,
    /// Where (world frame, m).
    pub at: P,
    /// How much (seconds for durations, 1 for onsets).
    pub weight: f32,
}

/// One robot's row in the robot table.
#[derive(Debug, Clone, PartialEq)]
pub struct RobotRow {
    /// Robot id.
    pub id: u32,
    /// Planner stack.
    pub planner: String,
    /// "idle", "to pick", "to drop", "held", "crashed", "left", "stuck", ...
    pub state: String,
    /// Crashed, gone, stuck, or touched a person: listed first, in bold.
    pub trouble: bool,
    /// Tasks done.
    pub tasks_done: u64,
    /// Contacts with people so far (robot- and person-caused onsets).
    pub contacts: u64,
    /// Social space violation rate so far.
    pub svr: f64,
    /// Distance to the nearest person now, centre to centre (m), if anyone is in range.
    pub closest_person_m: Option<f32>,
    /// Its share of the delay robots caused people in the latest window, if measured.
    pub delay_share: Option<f32>,
}

/// Event markers stay on the map this long (s), fading out.
pub const EVENT_FADE_S: f64 = 10.0;

/// One frame of the world.
#[derive(Debug, Clone, Default)]
pub struct Frame {
    /// Simulation tick.
    pub tick: u64,
    /// Simulation time (s).
    pub sim_time: f64,
    /// People's positions.
    pub humans: Vec<P>,
    /// Each person's group.
    pub human_groups: Vec<u32>,
    /// People's body radius (m).
    pub human_radius: f32,
    /// Robots.
    pub robots: Vec<RobotView>,
    /// Intents.
    pub intents: Vec<IntentView>,
    /// Candidate fans (empty unless a planner shares them).
    pub fans: Vec<FanView>,
    /// Safety fields of the robots that run the layer.
    pub fields: Vec<FieldView>,
    /// Events since the last frame.
    pub events: Vec<EventView>,
    /// Traffic, when the fleet runs a policy or a monitor.
    pub traffic: Option<TrafficView>,
    /// Fleet-wide series: name → value.
    pub fleet_metrics: Vec<(&'static str, f64)>,
    /// Per-robot series: robot → (name → value).
    pub robot_metrics: Vec<(u32, Vec<(&'static str, f64)>)>,
    /// The robot table's rows (empty: no table this frame).
    pub robot_rows: Vec<RobotRow>,
    /// Heatmap events since the last frame.
    pub heat: Vec<HeatEvent>,
}
