//! A 2-D laser scan as the planners and the safety layer see it. On a real robot the protective
//! field is the scanner's: returns that neither the static map nor the people tracker explain
//! become bodies, so that a person the tracker missed still stops or diverts the robot.
//!
//! Such a body is taken to be a person standing still (`AgentKind::Human`, zero velocity):
//! the layer then keeps the robot able to stop even if it starts walking within the motion
//! model, the most careful reading of an unknown return. Returns are grouped in ray order into
//! clusters no wider than [`ScanParams::max_cluster_width`], each cluster one body.

use crate::map::StaticMap;
use crate::math::{Real, Vec2};
use crate::model::{AgentKind, Neighbour};

/// One scan, in the world frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Scan {
    /// The scanner's position.
    pub origin: Vec2,
    /// World-frame bearing of ray 0 (rad).
    pub bearing0: Real,
    /// Angle between rays (rad, counter-clockwise positive).
    pub increment: Real,
    /// Returns nearer than this are not measurements (m).
    pub range_min: Real,
    /// Returns at or beyond this are not measurements (m).
    pub range_max: Real,
    /// Ranges (m); REP 117's infinities and NaN are not returns.
    pub ranges: Vec<f32>,
}

/// How returns become bodies.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScanParams {
    /// Returns farther than this from the scanner are left out (m): the layer and the planners
    /// act on what is near.
    pub max_range: Real,
    /// A return this close to a mapped wall or shelf is the wall (m): the map's own error plus
    /// the scanner's.
    pub wall_margin: Real,
    /// A return this far beyond a tracked body's radius is that body (m): the tracker's error.
    pub tracked_margin: Real,
    /// Neighbouring returns farther apart than this start a new cluster (m).
    pub cluster_gap: Real,
    /// A cluster wider than this is split (m): a person is about 0.6 m across.
    pub max_cluster_width: Real,
    /// Smallest radius of a body (m): a leg or a post.
    pub min_radius: Real,
}

impl Default for ScanParams {
    fn default() -> Self {
        Self {
            max_range: 5.0,
            wall_margin: 0.15,
            tracked_margin: 0.25,
            cluster_gap: 0.25,
            max_cluster_width: 0.7,
            min_radius: 0.1,
        }
    }
}

/// Ids of scan bodies start here, far above any tracked or simulated body's id.
pub const SCAN_BODY_ID_BASE: u64 = 1 << 48;

/// The returns of `scan` within range that neither `map` nor `tracked` explains, as bodies.
pub fn unexplained_bodies(
    scan: &Scan,
    map: &StaticMap,
    tracked: &[Neighbour],
    params: &ScanParams,
) -> Vec<Neighbour> {
    let mut bodies = Vec::new();
    let mut cluster: Vec<Vec2> = Vec::new();
    let reach = params.max_range.min(scan.range_max);
    for (k, &r) in scan.ranges.iter().enumerate() {
        let r = Real::from(r);
        let returned = r.is_finite() && r >= scan.range_min && r < reach;
        let point = returned.then(|| {
            let bearing = scan.bearing0 + scan.increment * k as Real;
            scan.origin + Vec2::new(bearing.cos(), bearing.sin()) * r
        });
        let unexplained = point.filter(|p| {
            map.distance(p) > params.wall_margin
                && tracked
                    .iter()
                    .all(|n| (n.position - p).norm() > n.radius + params.tracked_margin)
        });
        match unexplained {
            Some(p) => {
                let joins = cluster
                    .last()
                    .is_some_and(|last| (p - last).norm() <= params.cluster_gap)
                    && cluster
                        .first()
                        .is_some_and(|first| (p - first).norm() <= params.max_cluster_width);
                if !joins {
                    close_cluster(&mut cluster, scan.origin, params, &mut bodies);
                }
                cluster.push(p);
            }
            None => close_cluster(&mut cluster, scan.origin, params, &mut bodies),
        }
    }
    close_cluster(&mut cluster, scan.origin, params, &mut bodies);
    bodies
}

/// Turns the points of one cluster into a body: a circle through its extremes, its centre
/// pushed away from the scanner by the radius (a scanner sees a body's near side only).
fn close_cluster(
    cluster: &mut Vec<Vec2>,
    origin: Vec2,
    params: &ScanParams,
    out: &mut Vec<Neighbour>,
) {
    let (Some(&first), Some(&last)) = (cluster.first(), cluster.last()) else {
        return;
    };
    let radius = ((last - first).norm() / 2.0).max(params.min_radius);
    let nearest = cluster
        .iter()
        .copied()
        .min_by(|a, b| (a - origin).norm().total_cmp(&(b - origin).norm()))
        .unwrap_or(first);
    let away = nearest - origin;
    let centre = match away.try_normalize(1e-9) {
        Some(dir) => nearest + dir * radius,
        None => nearest,
    };
    let id = SCAN_BODY_ID_BASE + out.len() as u64;
    out.push(Neighbour::new(
        id,
        centre,
        Vec2::zeros(),
        radius,
        AgentKind::Human,
    ));
    cluster.clear();
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::Obstacle;

    /// A 360-ray scan from `origin` of circles and an optional wall along y = `wall_y`.
    fn scan_of(origin: Vec2, circles: &[(Vec2, Real)], wall_y: Option<Real>) -> Scan {
        let n = 360;
        let ranges = (0..n)
            .map(|k| {
                let b = k as Real * std::f64::consts::TAU / n as Real;
                let d = Vec2::new(b.cos(), b.sin());
                let mut best = Real::INFINITY;
                for &(c, r) in circles {
                    let oc = origin - c;
                    let bq = oc.dot(&d);
                    let disc = bq * bq - (oc.norm_squared() - r * r);
                    if disc >= 0.0 {
                        let t = -bq - disc.sqrt();
                        if t > 0.0 {
                            best = best.min(t);
                        }
                    }
                }
                if let Some(y) = wall_y
                    && d.y.abs() > 1e-9
                {
                    let t = (y - origin.y) / d.y;
                    if t > 0.0 {
                        best = best.min(t);
                    }
                }
                if best < 20.0 {
                    best as f32
                } else {
                    f32::INFINITY
                }
            })
            .collect();
        Scan {
            origin,
            bearing0: 0.0,
            increment: std::f64::consts::TAU / n as Real,
            range_min: 0.05,
            range_max: 20.0,
            ranges,
        }
    }

    fn wall_map(y: Real) -> StaticMap {
        let wall = Obstacle::Wall(Vec2::new(-20.0, y), Vec2::new(20.0, y));
        StaticMap::new(vec![wall]).expect("map")
    }

    #[test]
    fn an_untracked_person_becomes_one_body_where_they_stand() {
        let person = Vec2::new(2.0, 0.5);
        let scan = scan_of(Vec2::zeros(), &[(person, 0.3)], None);
        let bodies = unexplained_bodies(&scan, &StaticMap::empty(), &[], &ScanParams::default());
        assert_eq!(bodies.len(), 1, "{bodies:?}");
        let b = &bodies[0];
        assert_eq!(b.kind, AgentKind::Human);
        assert!((b.position - person).norm() < 0.15, "{:?}", b.position);
        assert!(b.radius >= 0.2 && b.radius <= 0.4, "{}", b.radius);
    }

    #[test]
    fn mapped_walls_and_tracked_people_are_not_bodies() {
        let person = Vec2::new(2.0, 0.0);
        let scan = scan_of(Vec2::zeros(), &[(person, 0.3)], Some(1.5));
        let tracked = [Neighbour::new(
            7,
            person + Vec2::new(0.1, 0.05),
            Vec2::zeros(),
            0.3,
            AgentKind::Human,
        )];
        let bodies = unexplained_bodies(&scan, &wall_map(1.5), &tracked, &ScanParams::default());
        assert!(bodies.is_empty(), "{bodies:?}");
        // Without the map, the wall within range is split into person-sized bodies.
        let unmapped =
            unexplained_bodies(&scan, &StaticMap::empty(), &tracked, &ScanParams::default());
        assert!(unmapped.len() > 3);
        assert!(unmapped.iter().all(|b| b.radius <= 0.36));
    }

    #[test]
    fn non_returns_and_far_returns_are_ignored() {
        let mut scan = scan_of(Vec2::zeros(), &[(Vec2::new(8.0, 0.0), 0.3)], None);
        assert!(
            unexplained_bodies(&scan, &StaticMap::empty(), &[], &ScanParams::default()).is_empty()
        );
        scan.ranges = vec![f32::NAN, f32::NEG_INFINITY, 0.01, f32::INFINITY];
        assert!(
            unexplained_bodies(&scan, &StaticMap::empty(), &[], &ScanParams::default()).is_empty()
        );
    }
}
