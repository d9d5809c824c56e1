//! The fleet's traffic policy: constraints the coordinator puts on the goals it gives robots,
//! so that a fleet in narrow two-way aisles keeps moving. Agents keep planning locally toward
//! the goal they are given; the policy only decides which goal that is.
//!
//! - **One way at a time in narrow aisles.** An aisle stretch between two cross-aisles that is
//!   narrower than two robots plus [`PolicyParams::passing_margin_m`] is a
//!   [`Segment`]. A robot asks for the next segment on its route
//!   [`PolicyParams::request_distance_m`] before its mouth. The segment is granted when it is
//!   empty, or already travelled the same way and nobody waits to go the other way (openTCS's
//!   SAME_DIRECTION_ONLY, but the direction follows demand). Otherwise the robot's goal becomes
//!   a hold point short of the mouth, clear of the crossing, until granted (a robot already
//!   nearer, coming along a cross-aisle, backs up to it). Once someone waits
//!   for the other direction, no one more enters the current way; the segment drains and turns.
//!   Waiting requests are served oldest first (ties: lower robot index).
//! - **Against the flow.** A robot found inside a segment against its direction (pushed in
//!   by the crowd, or off its route into the wrong aisle) stops further entries until it is
//!   out, and once only such robots are left the segment turns to their way. While a robot of
//!   the flow comes at it, it is **turned round**: its new route leaves by the end the flow
//!   leads to, and so does the route of any robot pushed into a segment off its route.
//! - **Round a blocked segment.** A robot that has waited [`PolicyParams::detour_after_s`]
//!   for a segment travelled against it, while no robot inside has made progress for as long
//!   (blocked, not busy: most often a robot of the flow held at the robot's own mouth by
//!   people), is sent round to the segment's far end, along the nearest wide corridor, to
//!   enter with the flow, when that way is at most [`PolicyParams::detour_max_extra_m`]
//!   longer; once per leg. Leaving the line also clears the crossing for the robot stuck at
//!   the mouth, and lets the flow keep coming. (openTCS "does not route around slower or
//!   stopped vehicles".)
//! - **Turn round from people in the way.** When a person has stood or walked at a
//!   segment's leading robot, in its way, for [`PolicyParams::people_turn_after_s`], the
//!   robots inside turn round, each with a route out by the end it came in at, and robots
//!   granted on their way in wait again. In an aisle too narrow for two robots a robot and a
//!   person cannot pass each other, and neither gives way of itself.
//! - **In at one end, out at the other.** A robot that picks inside a segment leaves it by the
//!   far end (the fleet routes its next leg through that end's cross-aisle), and a robot bound
//!   for a station in an aisle enters it from the cross-aisle nearer to where it comes from.
//!   The segment's only holder, with nobody near ([`PolicyParams::alone_exit_clear_m`]),
//!   leaves by either end, and the segment turns to its way: no other robot holds it, so none
//!   meets it there.
//! - **Keep right** in corridors and cross-aisles wide enough for two robots: the goal leads
//!   the robot [`PolicyParams::lane_lookahead_m`] along the lane right of the centre line
//!   ([`PolicyParams::lane_change_lookahead_m`] from the oncoming lane: change lanes first).
//!   Not while a held robot stands on the lane within that lookahead and a body length ahead:
//!   the robot then drives to its waypoint, round the lost robot.
//! - **One robot at a time at a station.** A station outside every segment (a dock on a
//!   corridor, a pick face on a wide corridor, a hallway's end) is granted to one robot at a
//!   time. A robot asks for it [`PolicyParams::station_request_m`] (along its route) before it,
//!   when no segment lies ahead, or earlier when the line reaches further back: where it can
//!   still stop short of the line's first free place, so that it joins at the tail.
//!   The others wait in line on the right-hand lane, the first
//!   [`PolicyParams::queue_back_m`] back along its route, each next one a body length plus
//!   [`PolicyParams::queue_gap_m`] further back (a robot nearer than its place backs up to
//!   it). A free station goes to the robot in line nearest to it, so the robot let through
//!   never has to pass the line; newcomers join behind. The station is granted again only
//!   once the robot that reached it has moved [`PolicyParams::station_clear_m`] away, so the
//!   next one does not drive at it while it turns to leave. A robot in line that comes
//!   0.3 m nearer to the station than its holder (pushed ahead, or come from the
//!   far side) takes it over, and the holder waits in line.
//! - **Retreat when a cycle lasts.** If two robots of a wait-for cycle (the traffic monitor's
//!   graph) have been in cycles for [`PolicyParams::retreat_after_s`], the
//!   lowest-priority member with room behind it (not holding a segment; then the highest
//!   index) backs off [`PolicyParams::retreat_m`] for [`PolicyParams::retreat_s`]. A member
//!   with another robot within that distance behind it does not back into it; when every
//!   member has one, the first that has room backs off sideways or half as far (to a point
//!   its body fits at, clear of shelves and robots).
//! - **Give way in two-way knots.** When the members of such a cycle all travel along one
//!   two-lane hallway, both ways (robots pushed out of their lanes by people meet face to
//!   face, and more join from both sides), the direction with fewer members in it stops where it
//!   stands until every member of the other direction is past it, at most
//!   [`PolicyParams::give_way_s`]; the retreat rule leaves the cycle alone meanwhile, and
//!   takes over for as long again if the knot is given up unpassed. Robots that stand still
//!   are easy to move round; robots that dodge back are not. Only in hallways, corridors no
//!   cross-aisle crosses (robots stopped in a warehouse's corridors stand in its crossings).
//!
//! Why each rule is as it is, with the seeds and figures that decided it and what was tried
//! and dropped: results/traffic/REPORT.md, "Why the rules are as they are".
//!
//! **Why reserved segments cannot deadlock.** A robot waits for a segment only while it is
//! outside every segment (it asks only from the cross-aisles and corridors), so a robot never
//! holds one segment while waiting for another: there is no hold-and-wait, the condition every
//! deadlock needs. Inside a segment every robot travels the same way toward an exit into a
//! cross-aisle, which no one reserves, so the robots inside never wait on the policy, and
//! those outside wait only on robots inside. The wait-for edges the policy creates therefore
//! all point from outside robots to inside ones, and inside robots have none of their own: no
//! cycle can pass through a reservation. Stations add one level above: a robot waits in line
//! for a station only while outside every segment with none ahead, and the robot holding the
//! station waits at most for a segment (then on robots inside it, who wait on nothing). Every
//! wait the policy creates goes down these levels (station line → station holder or segment
//! request → segment holder), so none closes a cycle. A robot that has just left a station
//! is waited for by that station's line until it is clear, and it waits on nothing there;
//! once it waits in another station's line it is no longer waited for, so line waits never
//! chain from line to line. A robot against the flow of a segment is one more holder that
//! requests wait on; it waits on no reservation itself (turned round, it drives with the
//! flow to the exit). Robots turned round from people become the segment's flow, toward
//! the end they came in at, and the robots they would meet there are outside it, waiting:
//! the same as a segment that drained and turned. A robot sent round a blocked segment drops its request and is outside
//! every segment on its way, so it holds nothing while it goes round. Giving way holds no
//! reservation, and lasts at most [`PolicyParams::give_way_s`]. Starvation is excluded by the closing rule: once a
//! request for the other direction waits, entries stop, the robots inside (a finite set moving
//! toward the exit) leave, and the oldest request is served next. A station's line is served
//! nearest first and its holder gives the station up when it reaches it (its leg ends).
//! Newcomers normally join behind those in line; one arriving from the station's other side
//! could be nearer and go first, and nothing bounds how often that happens (the stuck count
//! would show it). What the policy cannot
//! exclude is physical blocking in the open areas (people, robots jostling at a crossing);
//! that is what the retreat rule and the measured deadlock count are for.

use crate::traffic::TrafficMonitor;
use crate::warehouse::{Segment, Site};
use agent::map::StaticMap;
use agent::math::{Real, Vec2, vec2};
pub use params::{
    PEOPLE_ROUTE_REACH_M, PEOPLE_TURN_AWAY_SPEED, PEOPLE_TURN_PERSON_RADIUS_M, PolicyParams,
};
use segments::Want;

/// One robot as the policy sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PolicyRobot<'a> {
    /// Position.
    pub position: Vec2,
    /// Its route's waypoints left (the first is the point it drives to), empty when idle.
    pub route: &'a [Vec2],
    /// The station its route ends at (the site's station index), `None` when idle.
    pub station: Option<usize>,
    /// Whether the coordinator holds it where it stands (no agent, or a real robot whose
    /// reports stopped): it keeps its task, but no station line holds it or waits for it,
    /// and it is never the one sent to back off.
    pub held: bool,
}

/// What the policy asks of one robot now.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Constraint {
    /// Drive to the route's waypoint.
    Free,
    /// Drive along the right lane, toward this point.
    Lane(Vec2),
    /// Wait at this point for segment `segment`.
    Hold {
        /// Where to wait.
        at: Vec2,
        /// The segment it waits for.
        segment: usize,
    },
    /// Wait at this point, in line for station `station`.
    Queue {
        /// Where to wait.
        at: Vec2,
        /// The station it waits for.
        station: usize,
    },
    /// Back off to this point.
    Retreat(Vec2),
    /// Stop at this point (where the robot stood) and let a two-way knot's other direction
    /// pass.
    GiveWay(Vec2),
}

impl Constraint {
    /// The goal it puts in place of the route's waypoint, if any.
    pub fn goal(&self) -> Option<Vec2> {
        match *self {
            Constraint::Free => None,
            Constraint::Lane(p)
            | Constraint::Retreat(p)
            | Constraint::GiveWay(p)
            | Constraint::Hold { at: p, .. }
            | Constraint::Queue { at: p, .. } => Some(p),
        }
    }
}

/// Something the policy did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum PolicyEvent {
    /// A robot was granted a segment in a direction (+1 along x, −1 against).
    Granted {
        /// Robot index.
        robot: usize,
        /// Segment index.
        segment: usize,
        /// Direction.
        dir: i8,
    },
    /// A robot left a segment.
    Released {
        /// Robot index.
        robot: usize,
        /// Segment index.
        segment: usize,
    },
    /// A robot began to wait for a segment.
    Waiting {
        /// Robot index.
        robot: usize,
        /// Segment index.
        segment: usize,
    },
    /// A robot was granted its station.
    StationGranted {
        /// Robot index.
        robot: usize,
        /// Station index.
        station: usize,
    },
    /// A robot began to wait in line for its station.
    Queued {
        /// Robot index.
        robot: usize,
        /// Station index.
        station: usize,
    },
    /// A robot in a lasting wait-for cycle began to retreat.
    Retreat {
        /// Robot index.
        robot: usize,
    },
    /// A robot of a two-way knot in a corridor stopped to let the other direction pass.
    GiveWay {
        /// Robot index.
        robot: usize,
    },
    /// A robot that waited long for a segment travelled against it was sent round to the
    /// far end.
    Detour {
        /// Robot index.
        robot: usize,
        /// Segment index.
        segment: usize,
    },
}

/// A segment's reservation.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Reservation {
    /// The direction it is travelled now (+1 along x, −1 against), `None` when empty.
    pub dir: Option<i8>,
    /// The robots holding it, ascending.
    pub holders: Vec<usize>,
    /// Requests waiting: robot, direction, since (s).
    pub waiting: Vec<(usize, i8, Real)>,
    /// Some robot inside travels against `dir`: no one more enters until it is out.
    pub against: bool,
}

/// Counts over a run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub struct PolicyTotals {
    /// Segments granted.
    pub grants: u64,
    /// Times a robot began to wait for a segment.
    pub waits: u64,
    /// Retreats ordered.
    pub retreats: u64,
    /// Robots found inside a segment against its direction (pushed in, or there at the start).
    pub intrusions: u64,
    /// Stations granted.
    pub station_grants: u64,
    /// Times a robot began to wait in line for a station.
    pub queued: u64,
    /// Robot-steps in which a robot inside a segment against its flow, with the flow coming
    /// at it, was turned round (given a route out by the flow's exit; a robot counts again
    /// every step until it no longer meets the flow).
    pub turns: u64,
    /// Robots sent round to a segment's far end, to enter with its flow.
    pub detours: u64,
    /// Two-way knots untangled by one direction giving way.
    pub give_ways: u64,
    /// Segments' robots turned round from people in their way
    /// ([`PolicyParams::people_turn_after_s`]).
    #[serde(default)]
    pub people_turns: u64,
}

/// A station's line: who holds it and who waits, oldest first.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct StationLine {
    /// The robot granted it.
    pub holder: Option<usize>,
    /// The robot that last reached it, while still within
    /// [`PolicyParams::station_clear_m`] of it: the station is not granted again before it
    /// has left (else the next robot drives at it face to face).
    pub leaving: Option<usize>,
    /// Robots waiting, with the time each began to (s).
    pub waiting: Vec<(usize, Real)>,
}

/// The policy's state.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct TrafficPolicy {
    /// Its knobs.
    pub params: PolicyParams,
    segments: Vec<Segment>,
    reservations: Vec<Reservation>,
    /// Per station of the site: its line, `None` for stations inside a segment (the
    /// segment's reservation already admits one direction at a time).
    lines: Vec<Option<StationLine>>,
    /// Spacing of robots in line (m): a body length plus the gap.
    queue_spacing: Real,
    constraints: Vec<Constraint>,
    turns: Vec<Option<usize>>,
    /// This step's detours: robot `i`'s new route, round to a segment's far end.
    detours: Vec<Option<Vec<Vec2>>>,
    /// The station each robot was last sent round for (one detour per leg).
    detoured_for: Vec<Option<usize>>,
    retreat_until: Vec<Real>,
    retreat_at: Vec<Vec2>,
    /// Two-way knots being untangled.
    knots: Vec<knots::Knot>,
    /// Until when each robot is left to the retreat rule, its last knot given up unpassed.
    knot_given_up: Vec<Real>,
    lanes: LaneGeometry,
    /// The site's shelves and walls, for room to back off into (not in a snapshot:
    /// [`Fleet::restore`](crate::fleet::Fleet::restore) takes them from the
    /// scenario).
    #[serde(skip)]
    map: StaticMap,
    robot_radius: Real,
    totals: PolicyTotals,
    /// Per segment: since when (s) a person has been in its leading robot's way.
    #[serde(default)]
    people_in_way_since: Vec<Option<Real>>,
    /// The people's positions and velocities this step ([`TrafficPolicy::set_people`]). In a
    /// snapshot (last, so that older snapshots read: none), since
    /// [`TrafficPolicy::exit_of`] reads them between steps, before the next `set_people`.
    #[serde(default)]
    people: Vec<(Vec2, Vec2)>,
}

/// What keep-right needs of the site: wide corridors' axes.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
struct LaneGeometry {
    site: Site,
    min_width: Real,
}

impl TrafficPolicy {
    /// The policy for `site` with robots of `robot_radius` (m).
    pub fn new(site: &Site, robots: usize, robot_radius: Real, params: PolicyParams) -> Self {
        let min_width = 4.0 * robot_radius + params.passing_margin_m;
        let segments = site.narrow_segments(min_width);
        let lines = site
            .stations
            .iter()
            .map(|st| {
                let inside = segments.iter().any(|s| s.contains(st.position));
                (!inside).then(StationLine::default)
            })
            .collect();
        Self {
            params,
            reservations: vec![Reservation::default(); segments.len()],
            segments,
            lines,
            queue_spacing: 2.0 * robot_radius + params.queue_gap_m,
            constraints: vec![Constraint::Free; robots],
            turns: vec![None; robots],
            detours: vec![None; robots],
            detoured_for: vec![None; robots],
            retreat_until: vec![Real::NEG_INFINITY; robots],
            retreat_at: vec![vec2(0.0, 0.0); robots],
            knots: Vec::new(),
            knot_given_up: vec![Real::NEG_INFINITY; robots],
            lanes: LaneGeometry {
                site: site.clone(),
                min_width,
            },
            map: site.map(),
            robot_radius,
            totals: PolicyTotals::default(),
            people: Vec::new(),
            people_in_way_since: Vec::new(),
        }
    }

    /// Takes the shelves and walls a snapshot leaves out from the site.
    pub(crate) fn adopt_static(&mut self, site: &Site) {
        self.map = site.map();
        self.lanes.site.adopt_router(site);
    }

    /// How wide a corridor must be for two robots to pass (m): aisles narrower are one-way
    /// segments.
    pub fn passing_width(&self) -> Real {
        self.lanes.min_width
    }

    /// The one-way segments.
    pub fn segments(&self) -> &[Segment] {
        &self.segments
    }

    /// Segment `s`'s reservation.
    pub fn reservation(&self, s: usize) -> &Reservation {
        &self.reservations[s]
    }

    /// Station `s`'s line, `None` when the station is inside a segment (not queued).
    pub fn station_line(&self, s: usize) -> Option<&StationLine> {
        self.lines.get(s)?.as_ref()
    }

    /// What robot `i` is asked to do now.
    pub fn constraint(&self, i: usize) -> Constraint {
        self.constraints[i]
    }

    /// Counts so far.
    pub fn totals(&self) -> PolicyTotals {
        self.totals
    }

    /// The wait-for edges the policy's holds and lines create: each waiting robot on each
    /// holder of the segment or station it waits for.
    pub fn wait_edges(&self) -> Vec<(usize, usize)> {
        let mut edges = Vec::new();
        for (i, c) in self.constraints.iter().enumerate() {
            match *c {
                Constraint::Hold { segment, .. } => {
                    edges.extend(self.reservations[segment].holders.iter().map(|&h| (i, h)));
                }
                Constraint::Queue { station, .. } => {
                    let line = self.lines[station].as_ref();
                    let holder = line.and_then(|l| l.holder.or(l.leaving));
                    edges.extend(holder.map(|h| (i, h)));
                }
                _ => {}
            }
        }
        edges
    }

    /// The cross-aisle at the far end of the flow of the segment robot `i` holds (the way
    /// out), if it holds one and must leave with the flow: not when it is the segment's only
    /// holder with nobody near ([`PolicyParams::alone_exit_clear_m`]).
    pub fn exit_of(&self, i: usize) -> Option<usize> {
        let (r, s) = self
            .reservations
            .iter()
            .zip(&self.segments)
            .find(|(r, _)| r.holders.contains(&i))?;
        let clear = self.params.alone_exit_clear_m;
        let near = |q: Vec2| {
            (q.y - s.y).abs() <= s.half_width + clear && q.x >= s.x0 - clear && q.x <= s.x1 + clear
        };
        if clear > 0.0 && r.holders == [i] && !self.people.iter().any(|&(q, _)| near(q)) {
            return None;
        }
        Some(match r.dir {
            Some(d) if d < 0 => s.ends.0,
            _ => s.ends.1,
        })
    }

    /// The cross-aisle robot `i` is to leave its segment by, when it was found inside against
    /// the flow with the flow coming at it (this step): its route must turn round.
    pub fn turned(&self, i: usize) -> Option<usize> {
        self.turns[i]
    }

    /// Robot `i`'s new route when the policy sent it round to a segment's far end (this step).
    pub fn detour(&self, i: usize) -> Option<&[Vec2]> {
        self.detours[i].as_deref()
    }

    /// The cross-aisle the flow of the segment containing `at` leads to, if `at` is inside a
    /// segment travelled one way now.
    pub fn flow_exit(&self, at: Vec2) -> Option<usize> {
        let s = self.segments.iter().position(|s| s.contains(at))?;
        let d = self.reservations[s].dir?;
        let ends = self.segments[s].ends;
        Some(if d < 0 { ends.0 } else { ends.1 })
    }

    /// How far ahead of a segment's leading robot a person is in its way (m, centre to
    /// centre, along the aisle): its radius, a person's ([`PEOPLE_TURN_PERSON_RADIUS_M`]) and
    /// the traffic monitor's blocking gap; 1.7 m for the built-in scenarios' robots.
    pub fn people_turn_reach(&self) -> Real {
        self.robot_radius
            + PEOPLE_TURN_PERSON_RADIUS_M
            + crate::traffic::TrafficParams::default().blocking_gap_m
    }

    /// Whether the policy looks at people ([`PolicyParams::people_hold_speed_m_s`],
    /// [`PolicyParams::people_turn_after_s`], [`PolicyParams::alone_exit_clear_m`]).
    pub fn watches_people(&self) -> bool {
        self.params.people_hold_speed_m_s > 0.0
            || self.params.people_turn_after_s > 0.0
            || self.params.alone_exit_clear_m > 0.0
    }

    /// The people's positions and velocities for the next [`TrafficPolicy::step`].
    pub fn set_people(&mut self, people: impl IntoIterator<Item = (Vec2, Vec2)>) {
        self.people.clear();
        self.people.extend(people);
    }

    /// Whether someone inside `segment` walks along it toward a robot entering it in
    /// direction `dir` (people-aware aisle entry).
    fn oncoming_person(&self, segment: usize, dir: i8) -> bool {
        let limit = self.params.people_hold_speed_m_s;
        let seg = &self.segments[segment];
        limit > 0.0
            && self
                .people
                .iter()
                .any(|&(p, v)| seg.contains(p) && -v.x * Real::from(dir) > limit)
    }

    /// One policy step at time `now`, after the monitor has seen the fleet's state.
    pub fn step(
        &mut self,
        now: Real,
        robots: &[PolicyRobot<'_>],
        monitor: &TrafficMonitor,
    ) -> Vec<PolicyEvent> {
        let mut events = Vec::new();
        let wants: Vec<Option<Want>> = robots.iter().map(|r| self.want(r)).collect();
        self.release(&wants, &mut events);
        self.admit(now, &wants, &mut events);
        self.turn_round(robots, &wants);
        self.turn_from_people(now, robots);
        self.go_round(now, robots, monitor, &mut events);
        self.serve_stations(now, robots, &wants, &mut events);
        let held: Vec<Vec2> = robots
            .iter()
            .filter(|r| r.held)
            .map(|r| r.position)
            .collect();
        for (i, r) in robots.iter().enumerate() {
            self.constraints[i] = self.constraint_for(i, r, &wants[i], &held);
        }
        self.line_up(robots);
        self.give_way(now, robots, monitor, &mut events);
        self.retreat(now, robots, monitor, &mut events);
        events
    }

    fn constraint_for(
        &self,
        i: usize,
        r: &PolicyRobot<'_>,
        want: &Option<Want>,
        held: &[Vec2],
    ) -> Constraint {
        if let Some(w) = want
            && !w.inside
            && (!self.reservations[w.segment].holders.contains(&i)
                || self.oncoming_person(w.segment, w.dir))
        {
            let short = w.distance - self.params.hold_back_m;
            let (mut at, heading) = along(r.position, r.route, short.max(0.0));
            // Nearer than the hold point while driving along a cross-aisle toward the mouth's
            // crossing (refused late, or pushed on): back up along the cross-aisle to it, out
            // of the crossing the segment's robots come out into. (Staying put, robots stood
            // in front of the mouth of the segment they waited for, and its robots could not
            // get out: `warehouse-narrow` seed 79 at 20 robots.)
            if short < 0.0 && heading.y.abs() > heading.x.abs() {
                at -= heading * (-short);
            }
            return Constraint::Hold {
                at: self.right_of(at, heading),
                segment: w.segment,
            };
        }
        if want.is_some_and(|w| w.inside) {
            return Constraint::Free;
        }
        self.lane(r, held)
            .map_or(Constraint::Free, Constraint::Lane)
    }
}

/// The length of the route from `from` through every waypoint (m).
pub(crate) fn route_length<'a>(from: Vec2, route: impl IntoIterator<Item = &'a Vec2>) -> Real {
    let mut at = from;
    let mut total = 0.0;
    for &w in route {
        total += (w - at).norm();
        at = w;
    }
    total
}

/// The point `distance` along the route from `from`, and the direction of travel there (a
/// unit vector; zero on an empty route).
fn along(from: Vec2, route: &[Vec2], distance: Real) -> (Vec2, Vec2) {
    let mut at = from;
    let mut left = distance;
    let mut heading = vec2(0.0, 0.0);
    for &w in route {
        let leg = (w - at).norm();
        if leg > 0.0 {
            heading = (w - at) / leg;
        }
        if leg >= left {
            return (at + heading * left, heading);
        }
        left -= leg;
        at = w;
    }
    (at, heading)
}

mod detours;
mod knots;
mod lanes;
mod params;
mod retreat;
mod segments;
mod stations;
#[cfg(test)]
mod tests;
