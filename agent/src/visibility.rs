//! What a robot can see and what it cannot: a visibility profile, the free range along evenly
//! spaced bearings around the sensor (as a 2-D laser scanner reports it), ended by walls,
//! shelves and the bodies of people and robots.
//!
//! The unobserved region is everything beyond each ray's range. Where two neighbouring rays
//! end far apart, the near one was stopped by an occluder and the far one passes it: between
//! them runs an **occlusion edge**, a stretch of the boundary between what the robot sees and
//! a shadow somebody could step out of. The peek-and-pass planner ([`crate::pnp`]) samples its
//! hypothetical hidden people on these edges.

use crate::map::{LocalMap, StaticMap};
use crate::math::{Real, Vec2, angle_of, unit, vec2};
use std::f64::consts::TAU;

/// The free range along `ranges.len()` bearings spaced evenly around the full circle.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Visibility {
    /// Where the sensor is (world frame).
    pub origin: Vec2,
    /// World-frame bearing of ray 0 (rad); ray k points at `bearing0 + k·step`.
    pub bearing0: Real,
    /// The sensor's range (m): a ray that meets nothing reports it.
    pub range: Real,
    /// Free distance along each ray (m), at most `range`.
    pub ranges: Vec<Real>,
}

/// One occlusion edge: along the far ray `ray`, from `near` (where its neighbour on `side` is
/// blocked) to `far` (where it is blocked itself, or the range), with the shadow on `side`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OcclusionEdge {
    /// The ray the edge runs along.
    pub ray: usize,
    /// Where the edge begins and ends along that ray (m from the origin).
    pub near: Real,
    pub far: Real,
    /// +1 if the shadow lies counter-clockwise of the ray (at higher bearings), -1 otherwise.
    pub side: Real,
}

/// Rays per full circle by default: one degree apart, so a person (0.6 m wide) 10 m away
/// spans three rays.
pub const DEFAULT_RAYS: usize = 360;

impl Visibility {
    /// The profile seen from `origin` out to `range` along `rays` bearings (ray 0 along +x),
    /// with walls and shelves from `map` and `bodies` (centre, radius) as occluders. A body
    /// the origin lies inside (the sensor's own body, or one it overlaps) occludes nothing.
    pub fn scan(
        origin: Vec2,
        range: Real,
        rays: usize,
        map: &StaticMap,
        bodies: impl IntoIterator<Item = (Vec2, Real)>,
        local: &mut LocalMap,
    ) -> Self {
        let mut v = Self::default();
        v.rescan(origin, range, rays, map, bodies, local);
        v
    }

    /// [`scan`](Self::scan) into this profile, reusing its buffer (a planner's scratch).
    pub fn rescan(
        &mut self,
        origin: Vec2,
        range: Real,
        rays: usize,
        map: &StaticMap,
        bodies: impl IntoIterator<Item = (Vec2, Real)>,
        local: &mut LocalMap,
    ) {
        self.origin = origin;
        self.bearing0 = 0.0;
        self.range = range;
        self.ranges.clear();
        self.ranges.resize(rays.max(1), range);
        if !map.is_empty() {
            let r = vec2(range, range);
            map.gather(origin - r, origin + r, 0.0, local);
            for &(a, b) in local.segments() {
                self.occlude_segment(a, b);
            }
        }
        for (centre, radius) in bodies {
            self.occlude_disc(centre, radius);
        }
    }

    /// Angle between neighbouring rays (rad).
    pub fn step(&self) -> Real {
        TAU / self.ranges.len().max(1) as Real
    }

    /// The unit direction of ray `k`.
    pub fn direction(&self, k: usize) -> Vec2 {
        unit(self.bearing0 + k as Real * self.step())
    }

    /// The ray nearest to the bearing of `p` from the origin.
    pub fn ray_toward(&self, p: Vec2) -> usize {
        let n = self.ranges.len();
        let turns = (angle_of(&(p - self.origin)) - self.bearing0) / self.step();
        (turns.round() as i64).rem_euclid(n as i64) as usize
    }

    /// Whether `p` lies in view: within the free range of the ray toward it.
    pub fn sees(&self, p: Vec2) -> bool {
        if self.ranges.is_empty() {
            return false;
        }
        (p - self.origin).norm() <= self.ranges[self.ray_toward(p)]
    }

    /// The occlusion edges: neighbouring rays whose ranges differ by more than `jump` (m).
    pub fn edges(&self, jump: Real) -> impl Iterator<Item = OcclusionEdge> + '_ {
        let n = self.ranges.len();
        (0..n).filter_map(move |k| {
            let next = (k + 1) % n;
            let (a, b) = (self.ranges[k], self.ranges[next]);
            if n < 2 || (a - b).abs() <= jump {
                None
            } else if a < b {
                // Ray `next` passes where ray k is blocked: the shadow is behind k, clockwise.
                Some(OcclusionEdge {
                    ray: next,
                    near: a,
                    far: b,
                    side: -1.0,
                })
            } else {
                Some(OcclusionEdge {
                    ray: k,
                    near: b,
                    far: a,
                    side: 1.0,
                })
            }
        })
    }

    /// Rays `k` with bearings within `half` of `bearing`, as indices (wrapping).
    fn rays_within(&self, bearing: Real, half: Real) -> impl Iterator<Item = usize> + use<> {
        let n = self.ranges.len() as i64;
        let step = self.step();
        let centre = (bearing - self.bearing0) / step;
        let lo = (centre - half / step).ceil() as i64;
        let hi = (centre + half / step).floor() as i64;
        let hi = hi.min(lo + n - 1);
        (lo..=hi).map(move |k| k.rem_euclid(n) as usize)
    }

    fn occlude_disc(&mut self, centre: Vec2, radius: Real) {
        let w = centre - self.origin;
        let d = w.norm();
        if d <= radius || d - radius >= self.range {
            return;
        }
        let half = (radius / d).asin();
        let bearing = angle_of(&w);
        for k in self.rays_within(bearing, half) {
            let u = self.direction(k);
            // The nearer root of |t·u − w|² = r².
            let b = u.dot(&w);
            let disc = b * b - (d * d - radius * radius);
            if disc >= 0.0 {
                let t = b - disc.sqrt();
                if t > 0.0 && t < self.ranges[k] {
                    self.ranges[k] = t;
                }
            }
        }
    }

    fn occlude_segment(&mut self, a: Vec2, b: Vec2) {
        let (pa, pb) = (a - self.origin, b - self.origin);
        if pa.norm().min(pb.norm()) >= self.range
            && crate::math::distance_to_segment(a, b, self.origin) >= self.range
        {
            return;
        }
        let (ta, tb) = (angle_of(&pa), angle_of(&pb));
        // The segment spans the shorter arc between its endpoints' bearings.
        let mut delta = (tb - ta).rem_euclid(TAU);
        if delta > std::f64::consts::PI {
            delta -= TAU;
        }
        let mid = ta + 0.5 * delta;
        let half = 0.5 * delta.abs() + 1e-12;
        let e = pb - pa;
        for k in self.rays_within(mid, half) {
            let u = self.direction(k);
            // origin + t·u = a + s·e: solve with 2-D cross products.
            let denom = cross(u, e);
            if denom == 0.0 {
                continue;
            }
            let t = cross(pa, e) / denom;
            let s = cross(pa, u) / denom;
            if t > 0.0 && (0.0..=1.0).contains(&s) && t < self.ranges[k] {
                self.ranges[k] = t;
            }
        }
    }
}

fn cross(a: Vec2, b: Vec2) -> Real {
    a.x * b.y - a.y * b.x
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::Obstacle;

    fn scan(map: &StaticMap, bodies: &[(Vec2, Real)]) -> Visibility {
        Visibility::scan(
            vec2(0.0, 0.0),
            10.0,
            DEFAULT_RAYS,
            map,
            bodies.iter().copied(),
            &mut LocalMap::default(),
        )
    }

    #[test]
    fn a_body_ahead_hides_what_is_behind_it_and_nothing_beside_it() {
        let v = scan(&StaticMap::empty(), &[(vec2(3.0, 0.0), 0.3)]);
        // Straight ahead the ray stops at the body's near surface.
        assert!((v.ranges[0] - 2.7).abs() < 1e-12, "{}", v.ranges[0]);
        assert!(!v.sees(vec2(5.0, 0.0)));
        assert!(v.sees(vec2(2.5, 0.0)));
        // 1 m to the side of the hidden point, and behind the sensor, all is free.
        assert!(v.sees(vec2(5.0, 1.0)));
        assert_eq!(v.ranges[180], 10.0);
        // asin(0.3 / 3) = 5.7°: rays 0..=5 and 355..360 are blocked, 6 and 354 pass.
        assert!(v.ranges[5] < 10.0 && v.ranges[355] < 10.0);
        assert_eq!((v.ranges[6], v.ranges[354]), (10.0, 10.0));
    }

    #[test]
    fn the_shadow_of_a_body_has_an_occlusion_edge_on_each_side() {
        let v = scan(&StaticMap::empty(), &[(vec2(3.0, 0.0), 0.3)]);
        let edges: Vec<_> = v.edges(0.6).collect();
        assert_eq!(edges.len(), 2, "{edges:?}");
        // Counter-clockwise side: ray 6 passes with the shadow clockwise of it (side -1).
        let ccw = edges.iter().find(|e| e.ray == 6).expect("edge along ray 6");
        assert_eq!(ccw.side, -1.0);
        assert!(
            ccw.near > 2.7 && ccw.near < 3.1 && ccw.far == 10.0,
            "{ccw:?}"
        );
        let cw = edges
            .iter()
            .find(|e| e.ray == 354)
            .expect("edge along ray 354");
        assert_eq!(cw.side, 1.0);
    }

    #[test]
    fn walls_stop_rays_and_the_sensors_own_body_does_not() {
        // A wall across x = 2 from y = -1 to y = 1, and a body around the sensor.
        let map = StaticMap::new(vec![Obstacle::Wall(vec2(2.0, -1.0), vec2(2.0, 1.0))])
            .expect("valid wall");
        let v = scan(&map, &[(vec2(0.0, 0.0), 0.3)]);
        assert!((v.ranges[0] - 2.0).abs() < 1e-12);
        // 45° passes above the wall's end (at 26.6°).
        assert_eq!(v.ranges[45], 10.0);
        assert!(!v.sees(vec2(3.0, 0.0)) && v.sees(vec2(-3.0, 0.0)));
    }
}
