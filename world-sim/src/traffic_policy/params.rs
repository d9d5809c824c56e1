//! The traffic policy's parameters ([`PolicyParams`]), with their defaults and how they are
//! read from `key=value,…`, and the constants the people rules use.

use agent::math::Real;

/// The policy's knobs. None of them is from a paper.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PolicyParams {
    /// An aisle is one-way at a time when narrower than two robot diameters plus this (m).
    /// 0.2 m: two robots side by side need room between them and to the shelves.
    pub passing_margin_m: Real,
    /// A robot asks for the next segment on its route this far (along the route) before the
    /// segment's mouth (m). 4 m: four seconds at top speed, time to stop short of it.
    pub request_distance_m: Real,
    /// A robot denied a segment waits this far (along its route) before the mouth (m), on
    /// the right-hand lane where the corridor is wide enough for two. 3.5 m: 2 m short of a
    /// 3 m cross-aisle's crossing, so robots leaving the segment turn past it on the other
    /// lane (at 2.5 m, on the centre line, they met face to face over Zenoh).
    pub hold_back_m: Real,
    /// Keep right along corridors (and hallways): the lane's centre is this fraction of the
    /// width right of the centre line. 0.25: the middle of the right half.
    pub lane_offset_fraction: Real,
    /// The same in cross-aisles, which aisles open off. 0.15: in a 3 m cross-aisle a 0.8 m
    /// robot's body then stays 0.65 m clear of the aisle mouths it passes. (0.25 pushed robots
    /// into the mouths, where they met robots leaving the aisle: 18 deadlocks in one of seeds
    /// 1–3 at 20 robots in `warehouse-narrow`, against 4 in seeds 1–4 with 0.15. Tuned on
    /// those seeds, so a choice, not a finding.)
    pub cross_aisle_lane_offset_fraction: Real,
    /// The lane goal leads the robot by this much (m). 3 m.
    pub lane_lookahead_m: Real,
    /// ... and by this much while the robot is across the centre line, in the oncoming lane
    /// (m): it changes lanes first. 1 m. (With 3 m, robots leaving the hallway's outer docks
    /// drove on in the oncoming lane while people filled the middle, and met robots coming
    /// the other way face to face: deadlocks in `hallway-fleet` seeds 3 and 14 at 20 robots.)
    pub lane_change_lookahead_m: Real,
    /// A wait-for cycle this old makes one member retreat (s). 4 s: well before the monitor
    /// calls it a deadlock (10 s).
    pub retreat_after_s: Real,
    /// How long a retreat lasts (s). 5 s.
    pub retreat_s: Real,
    /// How far back a robot retreats (m). 1.5 m.
    pub retreat_m: Real,
    /// A robot that has waited this long for a segment travelled against it (s), while no
    /// robot inside has made progress for as long, goes round to the far end, to enter with
    /// the flow. 8 s: most requests are granted at once (300 of 308 in `warehouse-narrow`
    /// seeds 1–4 at 20 robots); of the rest, those still waiting at 8 s waited 15–49 s, most
    /// behind a robot of the flow stuck at the mouth by people.
    pub detour_after_s: Real,
    /// ... when the way round is at most this much longer than the way in (m). 40 m: about
    /// the wait it saves, at the speeds robots make among people.
    pub detour_max_extra_m: Real,
    /// A two-way knot's robots giving way wait at most this long for the other direction to
    /// pass (s). 15 s: three retreats' worth; in the hallway at 20 robots a knot's members are
    /// a few metres apart, seconds of travel.
    pub give_way_s: Real,
    /// A robot asks for its station this far (along its route) before it (m). 6 m: the first
    /// in line stops 3 m short, and behind it two more fit before the request point.
    pub station_request_m: Real,
    /// The first robot in a station's line waits this far (along its route) before it (m).
    /// 3 m: the robot at the station turns and leaves without meeting the line.
    pub queue_back_m: Real,
    /// Room between robots in line (m). 0.4 m.
    pub queue_gap_m: Real,
    /// A station is granted again only once the robot that last reached it is this far from
    /// it (m). 2 m: a body length clear of the station, short of the line's head (3 m).
    pub station_clear_m: Real,
    /// Routes that know where people are: between two aisles a robot takes the cross-aisle
    /// whose route is shortest once each person within [`PEOPLE_ROUTE_REACH_M`] of its legs,
    /// standing or coming the other way, counts this much extra length (m); people walking the
    /// robot's way do not count. 0, the default, keeps the shortest route. 3 m, chosen on
    /// seeds 1–30 among 3 and 5 m, and 5 m counting everyone near: the most tasks, and people
    /// delayed a fifth less (results/people-routing). Not yet the default: the fleet studies
    /// were measured without it. (Absent from snapshots and journals written before it: 0.)
    #[serde(default)]
    pub people_route_weight_m: Real,
    /// People-aware aisle entry: a robot not yet inside the segment on its way waits at its
    /// hold point while someone inside walks along the aisle toward it faster than this
    /// (m/s). In an aisle too narrow for two robots a robot and a person meet where neither
    /// can pass, and the robot's safety layer backs it out ahead of them. 0, the default,
    /// turns it off. (Absent from snapshots and journals written before it: 0.)
    #[serde(default)]
    pub people_hold_speed_m_s: Real,
    /// Turn round from people in the way: when a person has stood or walked at the leading robot of
    /// a segment's robots for this long (s), in its way inside the aisle or at the mouth it makes
    /// for ([`TrafficPolicy::people_turn_reach`](super::TrafficPolicy::people_turn_reach), not
    /// walking away at [`PEOPLE_TURN_AWAY_SPEED`] or more), the robots inside are turned round to
    /// leave by the end they came in at. In an aisle too narrow for two robots a robot and a person
    /// cannot pass each other, and neither gives way: a person heading through the robot stands
    /// where the robot would step, and the robot's layer lets it step toward no one. Not when the
    /// leading robot's station is in the segment (it waits for it), nor when a robot inside is
    /// bound for a station farther along the same aisle row (the end behind it is no way out:
    /// turned, it would stay against the flow). 10 s, chosen on `warehouse-narrow` seeds 1–30 at 20
    /// and 40 robots among 3, 5, 10 and 20 s: the most tasks over both (results/people-turn). 0
    /// turns it off. (Absent from snapshots and journals written before it: 0, as they ran.)
    #[serde(default)]
    pub people_turn_after_s: Real,
    /// A robot that picks in a one-way segment leaves it by the far end of the flow, unless it
    /// is the segment's only holder and nobody is within this distance (m) of the segment or
    /// its mouths: then it takes its shortest route to the dock, by either end, and the
    /// segment turns to its way. Without people this gives 7–8 % more tasks
    /// (`warehouse-narrow`, 20 robots, seeds 1–30 and 101–130); among 40 people it seldom
    /// acts. 3 m, set before any run and not tuned (results/way-out). 0 turns it off. (Absent
    /// from snapshots and journals written before it: 0, as they ran.)
    #[serde(default)]
    pub alone_exit_clear_m: Real,
    /// Docks shared out by load: a new task whose drawn dock already has at least this many
    /// more robots' tasks bound for it than the least-loaded open dock drops at that
    /// least-loaded dock instead (the one nearest the drawn dock; ties to the lower id). The
    /// task stream's draws are unchanged, and one robot alone (the free flow) always keeps
    /// the drawn dock, as every dock then has no other task. 0 turns it off. (Absent from
    /// snapshots and journals written before it: 0, as they ran.)
    #[serde(default)]
    pub dock_balance_excess: Real,
    /// Lines keep crossings clear: a place in a station's line where the robot's body would
    /// come within this gap (m) of a crossing (where a cross-aisle meets a corridor or an
    /// aisle) is skipped, and the line goes on beyond it, as drivers keep a junction's box
    /// clear. The lines of the narrow warehouse's middle docks reach back into the crossing
    /// at the foot of its middle cross-aisle, where robots bound anywhere cross. 0 turns it
    /// off. (Absent from snapshots and journals written before it: 0, as they ran.)
    #[serde(default)]
    pub queue_crossing_gap_m: Real,
}

/// A person's radius as the turn from people counts it (m): the built-in scenarios' 0.3 m.
/// A person within the robot's radius, this and the traffic monitor's blocking gap
/// ([`crate::traffic::TrafficParams::blocking_gap_m`]) ahead of a segment's leading robot
/// (centre to centre, along the aisle) and within the aisle's width is in its way
/// ([`TrafficPolicy::people_turn_reach`](super::TrafficPolicy::people_turn_reach)).
pub const PEOPLE_TURN_PERSON_RADIUS_M: Real = 0.3;

/// ... unless they walk away along the aisle at least this fast (m/s): half a robot's top
/// speed, a person the robot can follow.
pub const PEOPLE_TURN_AWAY_SPEED: Real = 0.5;

/// A person this close to a route's legs (m, centre to line) counts against it: a robot's and
/// a person's radii and a body width to pass in.
pub const PEOPLE_ROUTE_REACH_M: Real = 1.2;

impl Default for PolicyParams {
    fn default() -> Self {
        Self {
            passing_margin_m: 0.2,
            request_distance_m: 4.0,
            hold_back_m: 3.5,
            lane_offset_fraction: 0.25,
            cross_aisle_lane_offset_fraction: 0.15,
            lane_lookahead_m: 3.0,
            lane_change_lookahead_m: 1.0,
            retreat_after_s: 4.0,
            retreat_s: 5.0,
            retreat_m: 1.5,
            detour_after_s: 8.0,
            detour_max_extra_m: 40.0,
            give_way_s: 15.0,
            station_request_m: 6.0,
            queue_back_m: 3.0,
            queue_gap_m: 0.4,
            station_clear_m: 2.0,
            people_route_weight_m: 0.0,
            people_hold_speed_m_s: 0.0,
            people_turn_after_s: 10.0,
            alone_exit_clear_m: 3.0,
            dock_balance_excess: 0.0,
            queue_crossing_gap_m: 0.0,
        }
    }
}

impl PolicyParams {
    /// Every parameter by its name (the field's).
    fn fields_mut(&mut self) -> [(&'static str, &mut Real); 23] {
        [
            ("passing_margin_m", &mut self.passing_margin_m),
            ("request_distance_m", &mut self.request_distance_m),
            ("hold_back_m", &mut self.hold_back_m),
            ("lane_offset_fraction", &mut self.lane_offset_fraction),
            (
                "cross_aisle_lane_offset_fraction",
                &mut self.cross_aisle_lane_offset_fraction,
            ),
            ("lane_lookahead_m", &mut self.lane_lookahead_m),
            ("lane_change_lookahead_m", &mut self.lane_change_lookahead_m),
            ("retreat_after_s", &mut self.retreat_after_s),
            ("retreat_s", &mut self.retreat_s),
            ("retreat_m", &mut self.retreat_m),
            ("detour_after_s", &mut self.detour_after_s),
            ("detour_max_extra_m", &mut self.detour_max_extra_m),
            ("give_way_s", &mut self.give_way_s),
            ("station_request_m", &mut self.station_request_m),
            ("queue_back_m", &mut self.queue_back_m),
            ("queue_gap_m", &mut self.queue_gap_m),
            ("station_clear_m", &mut self.station_clear_m),
            ("people_route_weight_m", &mut self.people_route_weight_m),
            ("people_hold_speed_m_s", &mut self.people_hold_speed_m_s),
            ("people_turn_after_s", &mut self.people_turn_after_s),
            ("alone_exit_clear_m", &mut self.alone_exit_clear_m),
            ("dock_balance_excess", &mut self.dock_balance_excess),
            ("queue_crossing_gap_m", &mut self.queue_crossing_gap_m),
        ]
    }

    /// These parameters with some changed, as `key=value,key=value` (the field names), each
    /// finite and not negative; an empty text changes nothing.
    pub fn with_overrides(mut self, text: &str) -> Result<Self, String> {
        for pair in text.split(',').map(str::trim).filter(|p| !p.is_empty()) {
            let (key, value) = pair
                .split_once('=')
                .ok_or_else(|| format!("`{pair}`: expected key=value"))?;
            let (_, field) = self
                .fields_mut()
                .into_iter()
                .find(|(name, _)| *name == key)
                .ok_or_else(|| format!("`{key}` is not a traffic-policy parameter"))?;
            let v: Real = value.parse().map_err(|e| format!("`{pair}`: {e}"))?;
            if !v.is_finite() || !(0.0..=1e4).contains(&v) {
                return Err(format!("`{pair}`: {key} must be in [0, 10000]"));
            }
            *field = v;
        }
        Ok(self)
    }

    /// The parameters that differ from the defaults, as `key=value,…` ([`Self::with_overrides`]
    /// of the defaults reads it back); empty for the defaults.
    pub fn changes(&self) -> String {
        let (mut this, mut base) = (*self, Self::default());
        this.fields_mut()
            .into_iter()
            .zip(base.fields_mut())
            .filter(|((_, v), (_, d))| v.to_bits() != d.to_bits())
            .map(|((name, v), _)| format!("{name}={v}"))
            .collect::<Vec<_>>()
            .join(",")
    }
}
