//! Round a blocked segment (see the parent module's docs).

use super::{PolicyEvent, PolicyRobot, TrafficPolicy, route_length};
use crate::traffic::TrafficMonitor;
use agent::math::Real;

impl TrafficPolicy {
    /// Sends each robot that has waited [`PolicyParams::detour_after_s`] for a segment
    /// travelled against it, while no robot inside made progress for as long (the segment is
    /// blocked, not busy), round to the segment's far end, to enter with the flow, when the
    /// way round is at most [`PolicyParams::detour_max_extra_m`] longer. Once per leg.
    ///
    /// [`PolicyParams::detour_after_s`]: super::PolicyParams::detour_after_s
    /// [`PolicyParams::detour_max_extra_m`]: super::PolicyParams::detour_max_extra_m
    pub(super) fn go_round(
        &mut self,
        now: Real,
        robots: &[PolicyRobot<'_>],
        monitor: &TrafficMonitor,
        events: &mut Vec<PolicyEvent>,
    ) {
        let after = self.params.detour_after_s - 1e-9;
        self.detours.iter_mut().for_each(|d| *d = None);
        for (done, r) in self.detoured_for.iter_mut().zip(robots) {
            if *done != r.station {
                *done = None;
            }
        }
        for (s, (res, seg)) in self.reservations.iter().zip(&self.segments).enumerate() {
            let blocked = res.holders.iter().all(|&h| {
                monitor
                    .without_progress(h, now)
                    .is_none_or(|idle| idle >= after)
            });
            if !blocked {
                continue;
            }
            for &(i, dir, since) in &res.waiting {
                let r = &robots[i];
                let Some(station) = r.station else {
                    continue;
                };
                let long = now - since >= after;
                if !long || res.dir != Some(-dir) || self.detoured_for[i] == Some(station) {
                    continue;
                }
                let to = self.lanes.site.stations[station].position;
                if !seg.contains(to) {
                    continue;
                }
                let far = if dir > 0 { seg.ends.1 } else { seg.ends.0 };
                let Some(round) =
                    self.lanes
                        .site
                        .route_round(r.position, to, far, self.lanes.min_width)
                else {
                    continue;
                };
                let extra = route_length(r.position, &round) - route_length(r.position, r.route);
                if extra > self.params.detour_max_extra_m {
                    continue;
                }
                self.detours[i] = Some(round);
                self.detoured_for[i] = Some(station);
                self.totals.detours += 1;
                events.push(PolicyEvent::Detour {
                    robot: i,
                    segment: s,
                });
            }
        }
    }
}
