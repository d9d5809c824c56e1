//! A way round the static map for a robot whose goal is out of sight: the shortest path on a
//! visibility graph whose nodes ring each convex corner and wall end at a clearance.
//!
//! The local planners see walls only near the robot. A goal on the far side of a long wall
//! (in a recorded scene, the far side of a building's corner) pulls a robot straight into it,
//! and sliding along it leads nowhere. [`Router::steer`] gives the planner a goal toward the
//! next corner of the way round instead, and the goal itself whenever the straight line to it
//! is clear. Sites with routes of their own (the warehouse's aisles) do not need it.
//!
//! Cost: building a router is O(n²) in the map's corners (8 nodes each), so it is meant for
//! the few dozen edges of a recorded scene, not a warehouse of shelves.

use crate::map::StaticMap;
use crate::math::{Real, Vec2, segment_distance, vec2};

/// Nodes per corner, evenly round it.
const RING: usize = 8;

/// Shortest ways round one map's obstacles at one clearance. The graph is built on the
/// first goal out of sight.
#[derive(Debug, Clone)]
pub struct Router {
    clearance: Real,
    graph: std::cell::OnceCell<Graph>,
}

#[derive(Debug, Clone)]
struct Graph {
    nodes: Vec<Vec2>,
    /// `visible[i * n + j]`: the segment between nodes `i` and `j` keeps the clearance.
    visible: Vec<bool>,
}

impl Router {
    /// A router keeping `clearance` (m) from every edge, e.g. the robot's radius plus a
    /// margin. Every call must pass the same map.
    pub fn new(clearance: Real) -> Self {
        Self {
            clearance,
            graph: std::cell::OnceCell::new(),
        }
    }

    /// The clearance it keeps (m).
    pub fn clearance(&self) -> Real {
        self.clearance
    }

    /// The way from `from` to `to`: the corners to pass, then `to`; just `to` when the
    /// straight line keeps clear of the map, or when there is no way round (the planner then
    /// does what it can).
    ///
    /// A segment from `from` (or to `to`) need keep only as much clearance as that end has,
    /// so that a robot already near a wall can still leave it.
    pub fn route(&self, map: &StaticMap, from: Vec2, to: Vec2) -> Vec<Vec2> {
        let at_from = self.clearance.min(map.distance(&from)) * 0.99;
        let at_to = self.clearance.min(map.distance(&to)) * 0.99;
        let mut way = if keeps_clear(map, from, to, at_from.min(at_to)) {
            Vec::new()
        } else {
            self.path(map, from, to, at_from, at_to).unwrap_or_default()
        };
        way.push(to);
        way
    }

    /// The goal to give a local planner at `from` on the way to `to`: `to` when in clear
    /// sight; otherwise a point in the direction of the next corner as far away as the rest
    /// of the way is long, so that a planner that slows as it nears its goal does not slow
    /// for a corner. A corner within half the clearance counts as passed.
    pub fn steer(&self, map: &StaticMap, from: Vec2, to: Vec2) -> Vec2 {
        let way = self.route(map, from, to);
        let skip = way[..way.len() - 1]
            .iter()
            .take_while(|&&c| (c - from).norm() < (0.5 * self.clearance).max(1e-6))
            .count();
        let way = &way[skip..];
        if way.len() == 1 {
            return to;
        }
        let mut length = (way[0] - from).norm();
        for leg in way.windows(2) {
            length += (leg[1] - leg[0]).norm();
        }
        let ahead = way[0] - from;
        from + ahead * (length / ahead.norm())
    }

    /// The nodes of the shortest way from `from` to `to` (without either end), or `None`.
    fn path(
        &self,
        map: &StaticMap,
        from: Vec2,
        to: Vec2,
        at_from: Real,
        at_to: Real,
    ) -> Option<Vec<Vec2>> {
        let Graph { nodes, visible } = self.graph.get_or_init(|| Graph::new(map, self.clearance));
        let n = nodes.len();
        // Dijkstra on the dense graph: nodes 0..n, then `to` as node n.
        let target = n;
        let mut dist = vec![Real::INFINITY; n + 1];
        let mut prev = vec![usize::MAX; n + 1];
        let mut done = vec![false; n + 1];
        for (i, &node) in nodes.iter().enumerate() {
            if keeps_clear(map, from, node, at_from) {
                dist[i] = (node - from).norm();
            }
        }
        let to_target: Vec<bool> = nodes
            .iter()
            .map(|&node| keeps_clear(map, node, to, at_to))
            .collect();
        loop {
            let (u, du) = dist
                .iter()
                .enumerate()
                .filter(|(i, _)| !done[*i])
                .min_by(|a, b| a.1.total_cmp(b.1))
                .map(|(i, d)| (i, *d))?;
            if !du.is_finite() {
                return None;
            }
            if u == target {
                break;
            }
            done[u] = true;
            for v in 0..n {
                if !done[v] && visible[u * n + v] {
                    let dv = du + (nodes[v] - nodes[u]).norm();
                    if dv < dist[v] {
                        dist[v] = dv;
                        prev[v] = u;
                    }
                }
            }
            if to_target[u] {
                let dv = du + (to - nodes[u]).norm();
                if dv < dist[target] {
                    dist[target] = dv;
                    prev[target] = u;
                }
            }
        }
        let mut path = Vec::new();
        let mut at = prev[target];
        while at != usize::MAX {
            path.push(nodes[at]);
            at = prev[at];
        }
        path.reverse();
        Some(path)
    }
}

impl Graph {
    fn new(map: &StaticMap, clearance: Real) -> Self {
        // A ring of RING nodes whose edges stay outside the clearance circle.
        let reach = clearance / (std::f64::consts::PI / RING as Real).cos() * 1.01;
        let mut nodes = Vec::new();
        for v in map.vertices().iter().filter(|v| v.convex) {
            for k in 0..RING {
                let angle = k as Real * std::f64::consts::TAU / RING as Real;
                let node = v.point + vec2(angle.cos(), angle.sin()) * reach;
                if !map.is_inside(&node) && map.distance(&node) >= clearance {
                    nodes.push(node);
                }
            }
        }
        let n = nodes.len();
        let mut visible = vec![false; n * n];
        for i in 0..n {
            for j in i + 1..n {
                let clear = keeps_clear(map, nodes[i], nodes[j], clearance * 0.99);
                visible[i * n + j] = clear;
                visible[j * n + i] = clear;
            }
        }
        Self { nodes, visible }
    }
}

/// Whether the segment `a`–`b` crosses no edge of `map` and keeps at least `clearance` from
/// every edge.
fn keeps_clear(map: &StaticMap, a: Vec2, b: Vec2, clearance: Real) -> bool {
    if !map.line_of_sight(a, b) {
        return false;
    }
    let mut near = Vec::new();
    map.edges_near_box(a.inf(&b), a.sup(&b), clearance, &mut near);
    near.iter().all(|&e| {
        let (p, q) = map.edge(e as usize);
        segment_distance(a, b, p, q) >= clearance
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::Obstacle;

    /// seq_eth's building front: a long wall whose west end a person walks round.
    fn front() -> StaticMap {
        StaticMap::new(vec![Obstacle::Wall(
            vec2(-0.793, -0.595),
            vec2(14.167, -0.727),
        )])
        .expect("a valid wall")
    }

    #[test]
    fn a_goal_in_clear_sight_is_the_whole_way() {
        let map = front();
        let router = Router::new(0.6);
        let goal = vec2(8.0, 3.0);
        assert_eq!(router.route(&map, vec2(1.0, 2.0), goal), [goal]);
    }

    /// The replay's pedestrian 222 (seq_eth, from t = 581 s): the straight line from start to
    /// goal passes 0.1 m from the wall's end; a robot pushed a little east of it slid along
    /// the wall's underside for good.
    #[test]
    fn behind_a_wall_it_heads_round_the_near_end() {
        let map = front();
        let router = Router::new(0.6);
        let goal = vec2(4.66, 2.87);
        for from in [vec2(-3.51, -2.43), vec2(1.0, -1.3), vec2(4.7, -1.05)] {
            let w = router.route(&map, from, goal)[0];
            assert!(w != goal, "from {from:?}");
            assert!(
                w.x < -0.793 + 0.7,
                "from {from:?}: heads to {w:?}, not the west end"
            );
            assert!(map.line_of_sight(from, w), "from {from:?} to {w:?}");
        }
    }

    /// Following the way's corners reaches the goal: every leg is in sight and keeps the
    /// clearance the leg's ends allow, and the walk ends at the goal.
    #[test]
    fn following_the_corners_arrives() {
        let map = StaticMap::new(vec![
            Obstacle::Wall(vec2(-0.793, -0.595), vec2(14.167, -0.727)),
            Obstacle::Polygon(vec![
                vec2(-4.0, 2.0),
                vec2(-2.0, 2.0),
                vec2(-2.0, 6.0),
                vec2(-4.0, 6.0),
            ]),
        ])
        .expect("a valid map");
        let router = Router::new(0.6);
        let goal = vec2(-3.0, 8.0);
        let mut at = vec2(6.0, -3.0);
        for _ in 0..10 {
            let w = router.route(&map, at, goal)[0];
            assert!(map.line_of_sight(at, w));
            at = w;
            if at == goal {
                return;
            }
        }
        panic!("no arrival: stopped at {at:?}");
    }

    /// The planner's goal points at the next corner, as far off as the way is long.
    #[test]
    fn the_steering_goal_points_at_the_corner_from_the_way_s_length_off() {
        let map = front();
        let router = Router::new(0.6);
        let (from, goal) = (vec2(1.0, -1.3), vec2(4.66, 2.87));
        let way = router.route(&map, from, goal);
        assert!(way.len() >= 2, "{way:?}");
        let steer = router.steer(&map, from, goal);
        let length =
            (way[0] - from).norm() + way.windows(2).map(|l| (l[1] - l[0]).norm()).sum::<Real>();
        assert!(((steer - from).norm() - length).abs() < 1e-9);
        let (a, b) = ((steer - from).normalize(), (way[0] - from).normalize());
        assert!((a - b).norm() < 1e-9, "{a:?} against {b:?}");
        // In clear sight the goal is the goal.
        assert_eq!(router.steer(&map, vec2(1.0, 2.0), goal), goal);
    }

    #[test]
    fn an_enclosed_goal_falls_back_to_itself() {
        let map = StaticMap::new(vec![Obstacle::Polygon(vec![
            vec2(0.0, 0.0),
            vec2(4.0, 0.0),
            vec2(4.0, 4.0),
            vec2(0.0, 4.0),
        ])])
        .expect("a valid map");
        let router = Router::new(0.6);
        let goal = vec2(2.0, 2.0);
        assert_eq!(router.route(&map, vec2(-3.0, 2.0), goal), [goal]);
    }

    #[test]
    fn an_empty_map_routes_straight() {
        let map = StaticMap::empty();
        let router = Router::new(0.6);
        assert_eq!(
            router.route(&map, vec2(0.0, 0.0), vec2(5.0, 5.0)),
            [vec2(5.0, 5.0)]
        );
    }
}
