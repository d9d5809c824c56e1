//! One way at a time in narrow aisles: where each robot stands with respect to the segments
//! ([`Want`]), segments released once empty, requests granted oldest first with the direction
//! following demand, robots found against a segment's flow turned round, and a segment's
//! robots turned round from people standing in their way.

use super::{PEOPLE_TURN_AWAY_SPEED, PolicyEvent, PolicyRobot, TrafficPolicy};
use agent::math::Real;

/// Where a robot is with respect to one segment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Want {
    pub(super) segment: usize,
    pub(super) dir: i8,
    pub(super) inside: bool,
    /// Along the route to the mouth (m); 0 inside.
    pub(super) distance: Real,
}

impl TrafficPolicy {
    /// Where robot `r` is with respect to the segments: inside one, or approaching one.
    pub(super) fn want(&self, r: &PolicyRobot<'_>) -> Option<Want> {
        let first = *r.route.first()?;
        if let Some(s) = self.segments.iter().find(|s| s.contains(r.position)) {
            let dir = if first.x >= r.position.x { 1 } else { -1 };
            return Some(Want {
                segment: s.id,
                dir,
                inside: true,
                distance: 0.0,
            });
        }
        // Walk the route: the first leg along an aisle that enters a segment.
        let mut at = r.position;
        let mut walked = 0.0;
        for &w in r.route {
            let leg = w - at;
            if leg.x.abs() > leg.y.abs() && walked <= self.params.request_distance_m {
                let dir: i8 = if leg.x > 0.0 { 1 } else { -1 };
                let entered = self
                    .segments
                    .iter()
                    .filter(|s| {
                        (at.y - s.y).abs() <= s.half_width && (w.y - s.y).abs() <= s.half_width
                    })
                    .filter_map(|s| {
                        let mouth = if dir > 0 { s.x0 } else { s.x1 };
                        let ahead = (mouth - at.x) * Real::from(dir);
                        let reaches = (w.x - mouth) * Real::from(dir) > 0.0;
                        (ahead >= 0.0 && reaches).then_some((ahead, s.id))
                    })
                    .min_by(|a, b| a.0.total_cmp(&b.0));
                if let Some((ahead, segment)) = entered {
                    let distance = walked + ahead;
                    return (distance <= self.params.request_distance_m).then_some(Want {
                        segment,
                        dir,
                        inside: false,
                        distance,
                    });
                }
            }
            walked += leg.norm();
            at = w;
            if walked > self.params.request_distance_m {
                break;
            }
        }
        None
    }

    pub(super) fn release(&mut self, wants: &[Option<Want>], events: &mut Vec<PolicyEvent>) {
        for (s, res) in self.reservations.iter_mut().enumerate() {
            let before = res.holders.len();
            res.holders.retain(|&i| {
                let keep = wants[i].is_some_and(|w| w.segment == s);
                if !keep {
                    events.push(PolicyEvent::Released {
                        robot: i,
                        segment: s,
                    });
                }
                keep
            });
            if res.holders.is_empty() && before > 0 {
                res.dir = None;
                res.against = false;
            }
            res.waiting
                .retain(|&(i, _, _)| wants[i].is_some_and(|w| w.segment == s && !w.inside));
        }
    }

    pub(super) fn admit(
        &mut self,
        now: Real,
        wants: &[Option<Want>],
        events: &mut Vec<PolicyEvent>,
    ) {
        // Robots inside a segment hold it, whatever happened before.
        for (i, w) in wants.iter().enumerate() {
            let Some(w) = w.filter(|w| w.inside) else {
                continue;
            };
            let res = &mut self.reservations[w.segment];
            if res.holders.contains(&i) {
                continue;
            }
            match res.dir {
                Some(d) if d != w.dir => self.totals.intrusions += 1,
                _ => res.dir = Some(w.dir),
            }
            res.holders.push(i);
            res.holders.sort_unstable();
            res.waiting.retain(|&(r, _, _)| r != i);
        }
        // The flow: the way every robot inside travels. Robots inside against it (pushed in,
        // turned round by a new route) stop further entries until they are out, and once only
        // they are left the segment turns to their way.
        for res in &mut self.reservations {
            let mut ways = res.holders.iter().filter_map(|&i| wants[i].map(|w| w.dir));
            let Some(first) = ways.next() else {
                continue;
            };
            let mixed = ways.any(|d| d != first);
            res.against = mixed;
            if !mixed {
                res.dir = Some(first);
            }
        }
        // Requests from outside, oldest first.
        for (i, w) in wants.iter().enumerate() {
            let Some(w) = w.filter(|w| !w.inside) else {
                continue;
            };
            let res = &mut self.reservations[w.segment];
            if res.holders.contains(&i) || res.waiting.iter().any(|&(r, _, _)| r == i) {
                continue;
            }
            res.waiting.push((i, w.dir, now));
            self.totals.waits += 1;
            events.push(PolicyEvent::Waiting {
                robot: i,
                segment: w.segment,
            });
        }
        for (s, res) in self.reservations.iter_mut().enumerate() {
            res.waiting
                .sort_by(|a, b| a.2.total_cmp(&b.2).then(a.0.cmp(&b.0)));
            let Some(&(_, first_dir, _)) = res.waiting.first() else {
                continue;
            };
            // Empty: it turns to the oldest request's direction. Else only its direction
            // enters, and only while nobody waits the other way.
            let dir = res.dir.unwrap_or(first_dir);
            let opposed = res.against || res.waiting.iter().any(|&(_, d, _)| d != dir);
            if res.dir.is_some() && opposed {
                continue;
            }
            let mut granted = Vec::new();
            for &(i, d, _) in &res.waiting {
                if d == dir {
                    granted.push(i);
                }
            }
            if granted.is_empty() {
                continue;
            }
            res.dir = Some(dir);
            res.waiting.retain(|&(i, _, _)| !granted.contains(&i));
            for i in granted {
                res.holders.push(i);
                self.totals.grants += 1;
                events.push(PolicyEvent::Granted {
                    robot: i,
                    segment: s,
                    dir,
                });
            }
            res.holders.sort_unstable();
        }
    }

    /// Robots inside a segment against its flow with a robot of the flow ahead of them (they
    /// would meet face to face where neither can pass) turn round: each gets the cross-aisle
    /// the flow leads to, to leave by.
    pub(super) fn turn_round(&mut self, robots: &[PolicyRobot<'_>], wants: &[Option<Want>]) {
        self.turns.iter_mut().for_each(|t| *t = None);
        for (res, seg) in self.reservations.iter().zip(&self.segments) {
            let Some(flow) = res.dir.filter(|_| res.against) else {
                continue;
            };
            let way = |i: usize| wants[i].map(|w| w.dir);
            for &i in &res.holders {
                let Some(d) = way(i).filter(|&d| d != flow) else {
                    continue;
                };
                let x = robots[i].position.x;
                let met = res.holders.iter().any(|&j| {
                    way(j) == Some(flow) && (robots[j].position.x - x) * Real::from(d) > 0.0
                });
                if met {
                    self.turns[i] = Some(if flow < 0 { seg.ends.0 } else { seg.ends.1 });
                    self.totals.turns += 1;
                }
            }
        }
    }

    /// The robots inside a segment whose leading robot inside has had a person in its way
    /// for [`PolicyParams::people_turn_after_s`](super::PolicyParams::people_turn_after_s)
    /// turn round: each gets the cross-aisle it came in from, to leave by. Not while one of
    /// them is bound for a station ahead along the same aisle row.
    pub(super) fn turn_from_people(&mut self, now: Real, robots: &[PolicyRobot<'_>]) {
        let after = self.params.people_turn_after_s;
        if after <= 0.0 {
            return;
        }
        self.people_in_way_since.resize(self.segments.len(), None);
        for s in 0..self.segments.len() {
            let (res, seg) = (&self.reservations[s], &self.segments[s]);
            let lead = res
                .dir
                .filter(|_| !res.against)
                .and_then(|flow| {
                    let ahead = |i: usize| robots[i].position.x * Real::from(flow);
                    let lead = res
                        .holders
                        .iter()
                        .copied()
                        .filter(|&i| seg.contains(robots[i].position))
                        .max_by(|&a, &b| ahead(a).total_cmp(&ahead(b)))?;
                    Some((lead, flow))
                })
                .filter(|&(lead, _)| {
                    let station = robots[lead].station;
                    !station.is_some_and(|st| seg.contains(self.lanes.site.stations[st].position))
                })
                // A robot whose station lies ahead along the same aisle row has no way out
                // by the end behind it (its route there would lead straight back in): turned,
                // it would stay against the flow.
                .filter(|&(_, flow)| {
                    !res.holders.iter().any(|&i| {
                        let p = robots[i].position;
                        robots[i].station.is_some_and(|st| {
                            let q = self.lanes.site.stations[st].position;
                            seg.contains(p)
                                && (q.y - seg.y).abs() <= seg.half_width
                                && (q.x - p.x) * Real::from(flow) > 0.0
                        })
                    })
                });
            let reach = self.people_turn_reach();
            let blocked = lead.is_some_and(|(lead, flow)| {
                let p = robots[lead].position;
                let dir = Real::from(flow);
                self.people.iter().any(|&(q, v)| {
                    let along = (q.x - p.x) * dir;
                    along > 0.0
                        && along <= reach
                        && (q.y - seg.y).abs() <= seg.half_width
                        && v.x * dir < PEOPLE_TURN_AWAY_SPEED
                })
            });
            if !blocked {
                self.people_in_way_since[s] = None;
                continue;
            }
            let since = *self.people_in_way_since[s].get_or_insert(now);
            if now - since < after {
                continue;
            }
            let Some((_, flow)) = lead else { continue };
            let back = if flow > 0 { seg.ends.0 } else { seg.ends.1 };
            // The robots inside turn; those granted on their way in wait again for the
            // segment to drain and turn back (else the way they still want would count as the
            // flow, and the robots inside as against it, to be turned back).
            let res = &mut self.reservations[s];
            let (inside, outside): (Vec<usize>, Vec<usize>) = res
                .holders
                .iter()
                .partition(|&&i| seg.contains(robots[i].position));
            for &i in &inside {
                self.turns[i] = Some(back);
            }
            res.holders = inside;
            res.dir = Some(-flow);
            for i in outside {
                res.waiting.push((i, flow, now));
            }
            self.totals.people_turns += 1;
            self.people_in_way_since[s] = None;
        }
    }
}
