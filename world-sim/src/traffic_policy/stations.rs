//! Station lines: one robot at a time at a station outside every segment, the rest waiting
//! in line on the right-hand lane (see the parent module's docs).

use super::{Constraint, PolicyEvent, PolicyRobot, TrafficPolicy, Want, along, route_length};
use agent::math::{Real, Vec2, vec2};

/// A robot in a station's line nearer to it than its holder by more than this (m) takes the
/// station over. 0.3 m: more than robots jostling in place move, less than a body.
const STATION_SWAP_M: Real = 0.3;

impl TrafficPolicy {
    /// Station lines: holders that reached their station (or changed it) let go; robots near
    /// a queued station with no segment ahead join its line; a free station goes to the
    /// oldest in line.
    pub(super) fn serve_stations(
        &mut self,
        now: Real,
        robots: &[PolicyRobot<'_>],
        wants: &[Option<Want>],
        events: &mut Vec<PolicyEvent>,
    ) {
        let request = self.params.station_request_m;
        // Robots in a line (as of the last step). A robot that has left a station and waits
        // in another's line no longer keeps the first: a robot in line is never waited for.
        let mut in_line = vec![false; robots.len()];
        for line in self.lines.iter().flatten() {
            line.waiting.iter().for_each(|&(i, _)| in_line[i] = true);
        }
        for (s, line) in self.lines.iter_mut().enumerate() {
            let Some(line) = line else {
                continue;
            };
            // A held robot is in no line: one lost on its way to the station, or leaving it,
            // would keep the station from everyone else for as long as it is lost (robots
            // stood in line for good behind a lost holder: `lost_robots` example, warehouse,
            // 4 robots, seed 3).
            let bound_here = |i: usize| robots[i].station == Some(s) && !robots[i].held;
            let at = self.lanes.site.stations[s].position;
            let near = |i: usize| (robots[i].position - at).norm() <= self.params.station_clear_m;
            if let Some(h) = line.holder.filter(|&h| !bound_here(h)) {
                line.holder = None;
                line.leaving = near(h).then_some(h);
            }
            line.leaving = line
                .leaving
                .filter(|&l| near(l) && !bound_here(l) && !in_line[l] && !robots[l].held);
            line.waiting
                .retain(|&(i, _)| bound_here(i) && wants[i].is_none() && Some(i) != line.holder);
        }
        // Places taken in lines (as of the last step): a robot joins a line at its tail, and
        // asks for its station where it can still stop short of its place there.
        let taken: Vec<Vec2> = self
            .constraints
            .iter()
            .filter_map(|c| match *c {
                Constraint::Queue { at, .. } => Some(at),
                _ => None,
            })
            .collect();
        let stop_short = request - self.params.queue_back_m;
        // A place taken rules out at most three consecutive places of a robot's own line (two
        // along a straight stretch, three round a right-angled corner), so its first free
        // place is at most this far back: robots further away need no look.
        let furthest =
            self.params.queue_back_m + 3.0 * taken.len() as Real * self.queue_spacing + stop_short;
        for (i, r) in robots.iter().enumerate() {
            let Some(s) = r.station.filter(|_| !r.held) else {
                continue;
            };
            let Some(line) = self.lines.get(s).and_then(Option::as_ref) else {
                continue;
            };
            let listed = line.holder == Some(i) || line.waiting.iter().any(|&(w, _)| w == i);
            if listed || wants[i].is_some() {
                continue;
            }
            let to_go = route_length(r.position, r.route);
            if to_go > request
                && (to_go > furthest || to_go > self.free_place(r, &taken).0 + stop_short)
            {
                continue;
            }
            let Some(line) = self.lines[s].as_mut() else {
                continue;
            };
            line.waiting.push((i, now));
            self.totals.queued += 1;
            events.push(PolicyEvent::Queued {
                robot: i,
                station: s,
            });
        }
        let to_go = |i: usize| route_length(robots[i].position, robots[i].route);
        for (s, line) in self.lines.iter_mut().enumerate() {
            let Some(line) = line else {
                continue;
            };
            // A robot in line nearer to the station than its holder (pushed ahead, or come
            // from the far side) would block it: the station passes to the nearest in line and
            // the holder waits in line instead.
            if let Some(h) = line.holder {
                let ahead = line
                    .waiting
                    .iter()
                    .enumerate()
                    .filter(|&(_, &(w, _))| to_go(w) + STATION_SWAP_M < to_go(h))
                    .min_by(|a, b| {
                        to_go(a.1.0)
                            .total_cmp(&to_go(b.1.0))
                            .then(a.1.0.cmp(&b.1.0))
                    })
                    .map(|(k, _)| k);
                if let Some(k) = ahead {
                    let (robot, _) = line.waiting.remove(k);
                    line.waiting.push((h, now));
                    line.holder = Some(robot);
                    self.totals.station_grants += 1;
                    events.push(PolicyEvent::StationGranted { robot, station: s });
                }
            }
            if line.holder.is_some() || line.leaving.is_some() || line.waiting.is_empty() {
                continue;
            }
            // The nearest in line (along its route; ties: the oldest, then the lower index),
            // so that the robot let through never has to pass the line: robots join it
            // behind those already in it.
            let next = (0..line.waiting.len())
                .min_by(|&a, &b| {
                    let (ra, sa) = line.waiting[a];
                    let (rb, sb) = line.waiting[b];
                    to_go(ra)
                        .total_cmp(&to_go(rb))
                        .then(sa.total_cmp(&sb))
                        .then(ra.cmp(&rb))
                })
                .expect("not empty");
            let (robot, _) = line.waiting.remove(next);
            line.holder = Some(robot);
            self.totals.station_grants += 1;
            events.push(PolicyEvent::StationGranted { robot, station: s });
        }
    }

    /// Robots in a station's line wait at distinct points back along their routes from the
    /// station: the oldest first, each at the first place from [`PolicyParams::queue_back_m`]
    /// back, in steps of a body length plus the gap, at least that far from every place
    /// taken and every held robot. A robot nearer than its place backs up to it, along its
    /// last leg's line.
    pub(super) fn line_up(&mut self, robots: &[PolicyRobot<'_>]) {
        let mut queue: Vec<(Real, usize, usize)> = self
            .lines
            .iter()
            .enumerate()
            .filter_map(|(s, l)| Some((s, l.as_ref()?)))
            .flat_map(|(s, l)| l.waiting.iter().map(move |&(i, since)| (since, i, s)))
            .collect();
        queue.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        // A held robot stands where it stands: no place in line falls on it.
        let mut taken: Vec<Vec2> = robots
            .iter()
            .filter(|r| r.held)
            .map(|r| r.position)
            .collect();
        for (_, i, station) in queue {
            let (_, place) = self.free_place(&robots[i], &taken);
            taken.push(place);
            self.constraints[i] = Constraint::Queue { at: place, station };
        }
    }

    /// The first place back along `r`'s route from its station, from
    /// [`PolicyParams::queue_back_m`] in steps of a body length plus the gap, at least that
    /// far from every place `taken`: how far back it is (m), and where.
    fn free_place(&self, r: &PolicyRobot<'_>, taken: &[Vec2]) -> (Real, Vec2) {
        let spacing = self.queue_spacing;
        let to_go = route_length(r.position, r.route);
        (0..)
            .map(|k| {
                let back = self.params.queue_back_m + Real::from(k) * spacing;
                let (at, heading) = back_along(r.position, r.route, back);
                (back, self.right_of(at, heading))
            })
            .find(|&(back, p)| {
                back > to_go + 20.0
                    || (taken.iter().all(|q| (p - q).norm() >= spacing - 1e-9)
                        && !self.in_crossing(p))
            })
            .unwrap_or((to_go, r.position))
    }

    /// Whether a robot at `p` would come within [`PolicyParams::queue_crossing_gap_m`] of a
    /// crossing; never when that is 0.
    fn in_crossing(&self, p: Vec2) -> bool {
        let gap = self.params.queue_crossing_gap_m;
        gap > 0.0 && self.lanes.site.in_crossing(p, self.robot_radius + gap)
    }
}

/// The point `back` (m) before the route's end, along the route from `from`; nearer than that,
/// straight back from the end along the axis (x or y) the last leg runs closest to (`from`
/// itself on an empty route), and the direction of travel there (a unit vector, or zero).
pub(super) fn back_along(from: Vec2, route: &[Vec2], back: Real) -> (Vec2, Vec2) {
    let to_go = route_length(from, route);
    if back <= to_go {
        return along(from, route, to_go - back);
    }
    let Some(&end) = route.last() else {
        return (from, vec2(0.0, 0.0));
    };
    let start = if route.len() >= 2 {
        route[route.len() - 2]
    } else {
        from
    };
    // Back along the corridor the last leg runs in: its axis, not the leg itself (a
    // hallway's legs run straight at the station, often at a slant, and extended back past
    // the robot a slanted leg leaves the hallway).
    let leg = end - start;
    let heading = if leg.x.abs() >= leg.y.abs() {
        vec2(leg.x.signum(), 0.0)
    } else {
        vec2(0.0, leg.y.signum())
    };
    if leg == vec2(0.0, 0.0) {
        return (from, vec2(0.0, 0.0));
    }
    (end - heading * back, heading)
}
