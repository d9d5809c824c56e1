//! Procedural warehouses: parallel shelf rows cut into blocks by cross-aisles, a perimeter
//! wall, pick/drop stations, and routes through the aisle grid.
//!
//! ```text
//!  y ^  ┌──────────────────────────────────────────┐  top corridor (cross_aisle_width_m)
//!    |  │   ██████████    ██████████    ██████████ │  shelf row (rows-1)
//!    |  │ ·     ·     ·     ·     ·     ·          │  aisle (aisle_width_m), pick stations ·
//!    |  │   ██████████    ██████████    ██████████ │  shelf row 0
//!    |  │ ◦           ◦            ◦               │  bottom corridor: docks ◦ (drop stations)
//!    0  └──────────────────────────────────────────┘
//!        ^ cross-aisles (cross_aisle_width_m) before, between and after the blocks
//! ```
//!
//! The free space is a grid of corridors: horizontal ones (bottom corridor, aisles between
//! rows, top corridor) run the full width, cross-aisles run the full height, so every route
//! is at most: along a corridor to a cross-aisle, along it to the target corridor, along that.
//! Shelf ends at every crossing are blind corners: shelves block line of sight.

use crate::scenario::{FloorPlanSpec, Warehouse as Spec};
use agent::map::{Obstacle, StaticMap};
use agent::math::{Real, Vec2, vec2};

/// What a station is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum StationKind {
    /// A shelf face in an aisle or the top corridor, where goods are picked (`"pick"` in a
    /// floor plan's table).
    #[serde(alias = "pick")]
    Pick,
    /// A dock on the bottom corridor, where goods are dropped (`"dock"`).
    #[serde(alias = "dock")]
    Dock,
}

/// A pick or drop location.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Station {
    /// Index in [`Site::stations`].
    pub id: usize,
    /// Where robots and people stop.
    pub position: Vec2,
    /// Pick or dock.
    pub kind: StationKind,
}

/// A stretch of aisle between two cross-aisles too narrow for two robots to pass: the unit
/// the traffic policy reserves one direction at a time.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Segment {
    /// Index in [`Site::narrow_segments`]' answer.
    pub id: usize,
    /// The aisle's centre line (y) and half width.
    pub y: Real,
    /// Half the aisle's width.
    pub half_width: Real,
    /// Its ends along x: the faces of the cross-aisles on either side.
    pub x0: Real,
    /// See `x0`.
    pub x1: Real,
    /// The cross-aisles at its ends (indices, left and right).
    pub ends: (usize, usize),
}

impl Segment {
    /// Whether `p` is inside (between its ends, within its width).
    pub fn contains(&self, p: Vec2) -> bool {
        p.x >= self.x0 && p.x <= self.x1 && (p.y - self.y).abs() <= self.half_width
    }
}

/// A fleet site: geometry, stations and what routes are made on: the corridor grid of a
/// generated warehouse or hallway, or a floor plan's router.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Site {
    /// Outer size (width along x, height along y), metres, from [`Site::origin`].
    pub size: Vec2,
    /// Shelves (as polygons) and the perimeter walls.
    pub obstacles: Vec<Obstacle>,
    /// Stations; docks first.
    pub stations: Vec<Station>,
    /// y of each horizontal corridor's centre line, bottom to top, with its half width.
    corridors: Vec<(Real, Real)>,
    /// x of each cross-aisle's centre line, left to right, with its half width.
    cross_aisles: Vec<(Real, Real)>,
    /// The lower-left corner: (0, 0) for generated sites, a floor plan's map origin.
    #[serde(default)]
    pub origin: Vec2,
    /// The walls robots keep to, when a floor plan's keep-out mask takes floor from them
    /// that people may use ([`crate::floor_plan::FloorPlan::with_keepout`]); `None`: the
    /// same as `obstacles`.
    #[serde(default)]
    pub robot_obstacles: Option<Vec<Obstacle>>,
    /// A floor plan's routes (none on a generated site). Not in snapshots: a restored fleet
    /// takes it from the scenario's ([`Site::adopt_router`]).
    #[serde(skip)]
    router: Option<std::sync::Arc<crate::floor_plan::router::Router>>,
    /// The routes people walk by, when a keep-out mask gives them floor the robots do not
    /// have (`None`: people walk by `router`). Not in snapshots, as `router`.
    #[serde(skip)]
    people_router: Option<std::sync::Arc<crate::floor_plan::router::Router>>,
    /// A floor plan's speed zones ([`crate::floor_plan::speed`]). Not in snapshots, as
    /// `router`.
    #[serde(skip)]
    speed_zones: Option<std::sync::Arc<crate::floor_plan::speed::SpeedZones>>,
    /// Whether a corner on a narrow aisle may be cut when the way on clears the shelves
    /// (`Warehouse::cut_clear_corners`; `Fleet::step`).
    #[serde(default = "crate::scenario::yes")]
    pub cut_clear_corners: bool,
}

impl Site {
    /// Lays out the warehouse `spec` describes.
    pub fn generate(spec: &Spec) -> Self {
        let c = spec.cross_aisle_width_m;
        let (len, depth, aisle) = (spec.shelf_length_m, spec.shelf_depth_m, spec.aisle_width_m);
        let width = (spec.blocks + 1) as Real * c + spec.blocks as Real * len;
        let height = 2.0 * c + spec.rows as Real * depth + (spec.rows - 1) as Real * aisle;

        let corners = [
            vec2(0.0, 0.0),
            vec2(width, 0.0),
            vec2(width, height),
            vec2(0.0, height),
        ];
        let mut obstacles: Vec<Obstacle> = (0..4)
            .map(|i| Obstacle::Wall(corners[i], corners[(i + 1) % 4]))
            .collect();
        let block_x = |b: usize| c + b as Real * (c + len);
        let row_y = |r: usize| c + r as Real * (depth + aisle);
        for r in 0..spec.rows {
            for b in 0..spec.blocks {
                let (x0, y0) = (block_x(b), row_y(r));
                obstacles.push(Obstacle::Polygon(vec![
                    vec2(x0, y0),
                    vec2(x0 + len, y0),
                    vec2(x0 + len, y0 + depth),
                    vec2(x0, y0 + depth),
                ]));
            }
        }

        let mut corridors = vec![(c / 2.0, c / 2.0)];
        corridors.extend((1..spec.rows).map(|k| (row_y(k) - aisle / 2.0, aisle / 2.0)));
        corridors.push((height - c / 2.0, c / 2.0));
        let cross_aisles = (0..=spec.blocks)
            .map(|j| (j as Real * (c + len) + c / 2.0, c / 2.0))
            .collect();

        // Docks spread along the bottom corridor; pick stations at the middle of every block's
        // shelf faces in the aisles and the top corridor.
        let mut stations = Vec::new();
        for d in 0..spec.docks {
            let x = width * (d as Real + 0.5) / spec.docks as Real;
            stations.push((vec2(x, corridors[0].0), StationKind::Dock));
        }
        for &(y, _) in &corridors[1..] {
            for b in 0..spec.blocks {
                stations.push((vec2(block_x(b) + len / 2.0, y), StationKind::Pick));
            }
        }
        let stations = stations
            .into_iter()
            .enumerate()
            .map(|(id, (position, kind))| Station { id, position, kind })
            .collect();
        Self {
            size: vec2(width, height),
            obstacles,
            stations,
            corridors,
            cross_aisles,
            origin: Vec2::zeros(),
            robot_obstacles: None,
            router: None,
            people_router: None,
            speed_zones: None,
            cut_clear_corners: spec.cut_clear_corners,
        }
    }

    /// The site of a floor plan (`[floor_plan]`) for robots of `radius`: the map's solid
    /// cells as obstacles, the table's stations (docks first), routes from the map's free
    /// space. `None` before the map is loaded.
    pub fn floor_plan(spec: &FloorPlanSpec, radius: Real) -> Option<Self> {
        let plan = spec.plan.as_ref()?;
        let g = &plan.grid;
        let stations = spec
            .stations()
            .into_iter()
            .enumerate()
            .map(|(id, (position, kind))| Station { id, position, kind })
            .collect();
        Some(Self {
            size: g.far_corner() - g.origin,
            obstacles: plan.obstacles.clone(),
            stations,
            corridors: Vec::new(),
            cross_aisles: Vec::new(),
            origin: g.origin,
            robot_obstacles: plan.robot_obstacles.clone(),
            router: spec.router(radius),
            people_router: spec.people_router(radius),
            speed_zones: plan.speed_zones.clone(),
            cut_clear_corners: true,
        })
    }

    /// Takes `built`'s floor-plan routers and speed zones (a snapshot leaves them out).
    pub fn adopt_router(&mut self, built: &Site) {
        self.router.clone_from(&built.router);
        self.people_router.clone_from(&built.people_router);
        self.speed_zones.clone_from(&built.speed_zones);
    }

    /// The speed limit (m/s) a floor plan's speed mask sets at `p`, if any.
    pub fn speed_limit(&self, p: Vec2) -> Option<Real> {
        self.speed_zones.as_ref()?.limit_at(p)
    }

    /// Whether a body of `radius` at `p` can walk to the site's stations: everywhere on a
    /// generated site; on a floor plan, where the router reaches the first station from a
    /// point in sight of `p`.
    pub fn walkable(&self, p: Vec2, radius: Real) -> bool {
        self.people_router
            .as_ref()
            .or(self.router.as_ref())
            .is_none_or(|r| r.clearance(p) >= radius && r.reaches(0, p))
    }

    /// Waypoints people walk from `from` to `to`: [`Site::route`], except on a floor plan
    /// whose keep-out zones close floor to robots only, where people route across them.
    pub fn people_route(&self, from: Vec2, to: Vec2) -> Vec<Vec2> {
        match &self.people_router {
            Some(router) => router.route(from, to),
            None => self.route(from, to),
        }
    }

    /// A fleet hallway (`[hallway]` with robots): one corridor `length` by `width` with closed
    /// ends, `per_end` docks across the left end and as many pick stations across the right
    /// end, each 1 m in from its end wall.
    pub fn hallway(length: Real, width: Real, per_end: usize) -> Self {
        let corners = [
            vec2(0.0, 0.0),
            vec2(length, 0.0),
            vec2(length, width),
            vec2(0.0, width),
        ];
        let obstacles = (0..4)
            .map(|i| Obstacle::Wall(corners[i], corners[(i + 1) % 4]))
            .collect();
        let inset = 1.0_f64.min(length / 4.0);
        let across = |k: usize| width * (k as Real + 0.5) / per_end as Real;
        let stations = (0..per_end)
            .map(|k| (vec2(inset, across(k)), StationKind::Dock))
            .chain((0..per_end).map(|k| (vec2(length - inset, across(k)), StationKind::Pick)))
            .enumerate()
            .map(|(id, (position, kind))| Station { id, position, kind })
            .collect();
        Self {
            size: vec2(length, width),
            obstacles,
            stations,
            corridors: vec![(width / 2.0, width / 2.0)],
            cross_aisles: Vec::new(),
            origin: Vec2::zeros(),
            robot_obstacles: None,
            router: None,
            people_router: None,
            speed_zones: None,
            cut_clear_corners: true,
        }
    }

    /// The static map of the site.
    pub fn map(&self) -> StaticMap {
        StaticMap::new(self.obstacles.clone())
            .expect("generated rectangles and perimeter walls are valid obstacles")
    }

    /// The map robots plan, guard and route on, when it differs from [`Site::map`]: a keep-out
    /// mask's zones are walls in it.
    pub fn robot_map(&self) -> Option<StaticMap> {
        let walls = self.robot_obstacles.as_ref()?;
        Some(StaticMap::new(walls.clone()).expect("a floor plan's walls are valid obstacles"))
    }

    /// Stations of one kind.
    pub fn stations_of(&self, kind: StationKind) -> impl Iterator<Item = &Station> + '_ {
        self.stations.iter().filter(move |s| s.kind == kind)
    }

    /// Index of the horizontal corridor containing `p`, if any.
    fn corridor_of(&self, p: Vec2) -> Option<usize> {
        self.corridors
            .iter()
            .position(|&(y, half)| (p.y - y).abs() <= half)
    }

    /// Index of the cross-aisle containing `p`, if any.
    fn cross_aisle_of(&self, p: Vec2) -> Option<usize> {
        self.cross_aisles
            .iter()
            .position(|&(x, half)| (p.x - x).abs() <= half)
    }

    /// Where robots and people stop, turn and set off, as points (degenerate boxes): the
    /// stations. `None` on a floor plan, whose people walk its router's routes.
    pub fn turn_places(&self) -> Option<Vec<(Vec2, Vec2)>> {
        if self.router.is_some() {
            return None;
        }
        Some(
            self.stations
                .iter()
                .map(|s| (s.position, s.position))
                .collect(),
        )
    }

    /// How many cross-aisles cross the corridors (none in a hallway).
    pub fn cross_aisle_count(&self) -> usize {
        self.cross_aisles.len()
    }

    /// Cross-aisle `j`'s centre line (x) and half width.
    pub fn cross_aisle(&self, j: usize) -> (Real, Real) {
        self.cross_aisles[j]
    }

    /// Whether `p` is in a cross-aisle.
    pub fn in_cross_aisle(&self, p: Vec2) -> bool {
        self.cross_aisle_of(p).is_some()
    }

    /// Whether `p` lies within `grow` (m) of a crossing: the box where a cross-aisle meets a
    /// corridor or an aisle. Never on a site with no cross-aisles (a hallway, a floor plan).
    pub fn in_crossing(&self, p: Vec2, grow: Real) -> bool {
        let near = |c: Real, half: Real, v: Real| (v - c).abs() < half + grow;
        self.cross_aisles
            .iter()
            .any(|&(x, half)| near(x, half, p.x))
            && self.corridors.iter().any(|&(y, half)| near(y, half, p.y))
    }

    /// The horizontal corridor nearest to `p` (for points pushed off the grid, e.g. into a
    /// shelf's edge).
    fn nearest_corridor(&self, p: Vec2) -> usize {
        nearest(self.corridors.iter().map(|&(y, _)| (p.y - y).abs()))
    }

    /// Waypoints from `from` to `to` through the corridor grid, ending with `to`. Each leg is a
    /// straight line inside one corridor or cross-aisle; on a floor plan, one that keeps the
    /// body clear of walls ([`crate::floor_plan::router::Router::route`]).
    pub fn route(&self, from: Vec2, to: Vec2) -> Vec<Vec2> {
        if let Some(router) = &self.router {
            return router.route(from, to);
        }
        let (fc, tc) = (self.corridor_of(from), self.corridor_of(to));
        let (fa, ta) = (self.cross_aisle_of(from), self.cross_aisle_of(to));
        let shared_corridor = matches!((fc, tc), (Some(a), Some(b)) if a == b);
        let shared_aisle = matches!((fa, ta), (Some(a), Some(b)) if a == b);
        if shared_corridor || shared_aisle {
            return vec![to];
        }
        let y = |k: usize| self.corridors[k].0;
        let x = |j: usize| self.cross_aisles[j].0;
        match (fc, tc, fa, ta) {
            // Cross-aisle to corridor: down the aisle, then along the corridor.
            (None, Some(k), Some(j), _) => vec![vec2(x(j), y(k)), to],
            // Corridor to cross-aisle.
            (Some(k), None, _, Some(j)) => vec![vec2(x(j), y(k)), to],
            // Cross-aisle to another cross-aisle: through the corridor with the least detour.
            (None, None, Some(a), Some(b)) => {
                let k = nearest(
                    self.corridors
                        .iter()
                        .map(|&(cy, _)| (from.y - cy).abs() + (to.y - cy).abs()),
                );
                vec![vec2(x(a), y(k)), vec2(x(b), y(k)), to]
            }
            // Corridor to corridor (the common case), or off-grid points snapped to one.
            _ => {
                let k_from = fc.unwrap_or_else(|| self.nearest_corridor(from));
                let k_to = tc.unwrap_or_else(|| self.nearest_corridor(to));
                if k_from == k_to {
                    return vec![to];
                }
                let j = nearest(
                    self.cross_aisles
                        .iter()
                        .map(|&(cx, _)| (from.x - cx).abs() + (to.x - cx).abs()),
                );
                vec![vec2(x(j), y(k_from)), vec2(x(j), y(k_to)), to]
            }
        }
    }

    /// Whether `to` is one straight leg from `from` (what [`Site::route`] would answer with
    /// `[to]`), without building a route: on a floor plan, a route to a point that is no
    /// station computes a cost-to-go field over the whole map.
    pub fn in_one_leg(&self, from: Vec2, to: Vec2) -> bool {
        match &self.router {
            Some(router) => router.straight(from, to),
            None => self.route(from, to).len() <= 1,
        }
    }

    /// The aisle stretches narrower than `min_width` (m), left to right within each aisle,
    /// aisles bottom to top. The bottom and top corridors are never narrow segments.
    pub fn narrow_segments(&self, min_width: Real) -> Vec<Segment> {
        let mut out = Vec::new();
        let aisles = self.corridors.len().saturating_sub(1);
        for &(y, half) in self.corridors.iter().take(aisles).skip(1) {
            if 2.0 * half >= min_width {
                continue;
            }
            for j in 0..self.cross_aisles.len().saturating_sub(1) {
                let (a, ha) = self.cross_aisles[j];
                let (b, hb) = self.cross_aisles[j + 1];
                out.push(Segment {
                    id: out.len(),
                    y,
                    half_width: half,
                    x0: a + ha,
                    x1: b - hb,
                    ends: (j, j + 1),
                });
            }
        }
        out
    }

    /// The centre line and half width of the corridor (`horizontal`: its y) or cross-aisle
    /// (its x) containing `p`.
    pub fn lane_axis(&self, p: Vec2, horizontal: bool) -> Option<(Real, Real)> {
        if horizontal {
            self.corridor_of(p).map(|k| self.corridors[k])
        } else {
            self.cross_aisle_of(p).map(|j| self.cross_aisles[j])
        }
    }

    /// Like [`Site::route`], but a leg that leaves or enters an aisle does it through
    /// cross-aisle `j` (so a robot leaves a one-way segment by its far end, or enters the aisle
    /// next to its station). Falls back to [`Site::route`] when `from` and `to` share a
    /// corridor, or either is in a cross-aisle.
    pub fn route_via(&self, from: Vec2, to: Vec2, j: usize) -> Vec<Vec2> {
        let (Some(k_from), Some(k_to)) = (self.corridor_of(from), self.corridor_of(to)) else {
            return self.route(from, to);
        };
        if k_from == k_to || j >= self.cross_aisles.len() {
            return self.route(from, to);
        }
        let x = self.cross_aisles[j].0;
        vec![
            vec2(x, self.corridors[k_from].0),
            vec2(x, self.corridors[k_to].0),
            to,
        ]
    }

    /// A route that leaves `from`'s aisle through cross-aisle `j` (the one way out of a
    /// one-way segment) on its way to `to`. When `to` lies in the same aisle row on the other
    /// side of `from`, the route goes out by `j`, along the nearest other corridor at least
    /// `min_width` wide (m), and back into the row through the cross-aisle next to `to` on
    /// the side away from `j`, or the nearer one when it is not `j`. Otherwise as
    /// [`Site::route_via`]; also when no corridor is that wide.
    pub fn route_out(&self, from: Vec2, to: Vec2, j: usize, min_width: Real) -> Vec<Vec2> {
        let (Some(k), Some(k_to)) = (self.corridor_of(from), self.corridor_of(to)) else {
            return self.route_via(from, to, j);
        };
        let Some(&(x_j, _)) = self.cross_aisles.get(j) else {
            return self.route_via(from, to, j);
        };
        // Elsewhere, or on the way out (or beyond it): the usual route.
        if k != k_to || (to.x - from.x) * (x_j - from.x) >= 0.0 {
            return self.route_via(from, to, j);
        }
        let cost = |e: usize| {
            let x_e = self.cross_aisles[e].0;
            (x_j - x_e).abs() + (x_e - to.x).abs()
        };
        let entry = self.cross_aisles_around(to).and_then(|(left, right)| {
            [left, right]
                .into_iter()
                .filter(|&e| e != j)
                .min_by(|&a, &b| cost(a).total_cmp(&cost(b)))
        });
        let y_k = self.corridors[k].0;
        let corridor = self.wide_corridor(k, min_width, |y| (y - y_k).abs());
        let (Some(e), Some(c)) = (entry, corridor) else {
            return self.route_via(from, to, j);
        };
        let (x_e, y_c) = (self.cross_aisles[e].0, self.corridors[c].0);
        vec![
            vec2(x_j, y_k),
            vec2(x_j, y_c),
            vec2(x_e, y_c),
            vec2(x_e, y_k),
            to,
        ]
    }

    /// A way round: from `from` in a cross-aisle to `to` in an aisle, entering the aisle
    /// through cross-aisle `j` and getting there along the corridor at least `min_width` wide
    /// (m) with the least climb (so through no narrow aisle). `None` when `from` is not in a
    /// cross-aisle, `to` not in a corridor, or no other corridor is that wide.
    pub fn route_round(
        &self,
        from: Vec2,
        to: Vec2,
        j: usize,
        min_width: Real,
    ) -> Option<Vec<Vec2>> {
        let a = self.cross_aisle_of(from)?;
        let k = self.corridor_of(to)?;
        let (x_a, x_j) = (self.cross_aisles[a].0, self.cross_aisles.get(j)?.0);
        let c = self.wide_corridor(k, min_width, |y| (from.y - y).abs() + (y - to.y).abs())?;
        let (y_c, y_k) = (self.corridors[c].0, self.corridors[k].0);
        Some(vec![vec2(x_a, y_c), vec2(x_j, y_c), vec2(x_j, y_k), to])
    }

    /// The corridor other than `k` at least `min_width` wide (m) whose centre line `y` has the
    /// least `climb(y)`, if any.
    fn wide_corridor(
        &self,
        k: usize,
        min_width: Real,
        climb: impl Fn(Real) -> Real,
    ) -> Option<usize> {
        self.corridors
            .iter()
            .enumerate()
            .filter(|&(c, &(_, half))| c != k && 2.0 * half >= min_width)
            .min_by(|(_, p), (_, q)| climb(p.0).total_cmp(&climb(q.0)))
            .map(|(c, _)| c)
    }

    /// How close a robot of `radius` must come to route corner `p` before it heads for the
    /// next waypoint: `default` (m), unless `p` lies on an aisle too narrow for two robots to
    /// pass (4·radius + `margin`), where cutting the corner would aim the robot at the shelf's
    /// end: then what the aisle leaves beside the robot, half its width minus the radius (at
    /// least 0.25 m).
    pub fn corner_reach(&self, p: Vec2, radius: Real, margin: Real, default: Real) -> Real {
        match self.corridor_of(p) {
            Some(k) if 2.0 * self.corridors[k].1 < 4.0 * radius + margin => {
                (self.corridors[k].1 - radius).clamp(0.25, default)
            }
            _ => default,
        }
    }

    /// The cross-aisles on either side of `p` (left, right), if it is between two.
    pub fn cross_aisles_around(&self, p: Vec2) -> Option<(usize, usize)> {
        let right = self.cross_aisles.iter().position(|&(x, _)| x > p.x)?;
        (right > 0).then_some((right - 1, right))
    }

    /// Free floor area (m²): the site minus its shelves.
    pub fn free_area(&self) -> Real {
        if let Some(router) = &self.router {
            return router.free_area();
        }
        let shelves: Real = self
            .obstacles
            .iter()
            .map(|o| match o {
                Obstacle::Polygon(p) => polygon_area(p),
                Obstacle::Wall(..) => 0.0,
            })
            .sum();
        self.size.x * self.size.y - shelves
    }
}

fn nearest(costs: impl Iterator<Item = Real>) -> usize {
    costs
        .enumerate()
        .fold(
            (0, Real::INFINITY),
            |best, (i, c)| {
                if c < best.1 { (i, c) } else { best }
            },
        )
        .0
}

fn polygon_area(p: &[Vec2]) -> Real {
    let n = p.len();
    (0..n)
        .map(|i| p[i].x * p[(i + 1) % n].y - p[(i + 1) % n].x * p[i].y)
        .sum::<Real>()
        .abs()
        / 2.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::Scenario;

    fn site() -> Site {
        let s = Scenario::builtin("warehouse").expect("valid");
        Site::generate(&s.warehouse.expect("layout"))
    }

    /// Every leg of every route between any two stations stays in free space with a person's
    /// clearance (checked at 5 cm steps).
    #[test]
    fn routes_between_all_stations_stay_in_corridors() {
        let site = site();
        let map = site.map();
        for a in &site.stations {
            for b in &site.stations {
                let mut at = a.position;
                for w in site.route(a.position, b.position) {
                    let steps = ((w - at).norm() / 0.05).ceil().max(1.0) as usize;
                    for s in 0..=steps {
                        let p = at + (w - at) * (s as Real / steps as Real);
                        assert!(
                            !map.is_inside(&p) && map.distance(&p) > 0.4,
                            "route {} -> {} passes {p:?}",
                            a.id,
                            b.id
                        );
                    }
                    at = w;
                }
                assert_eq!(at, b.position);
            }
        }
    }

    /// `warehouse-narrow`'s site, its map, its robots' radius and the width two of them pass in.
    fn narrow_site() -> (Site, StaticMap, Real, Real) {
        let narrow = Scenario::builtin("warehouse-narrow").expect("valid");
        let site = Site::generate(&narrow.warehouse.expect("layout"));
        let map = site.map();
        let radius = narrow.robot.radius_m;
        (site, map, radius, 4.0 * radius + 0.2)
    }

    /// Every point of `route` from `from`, every 5 cm, is in free space with `radius` of
    /// clearance.
    fn assert_clear(map: &StaticMap, from: Vec2, route: &[Vec2], radius: Real) {
        let mut at = from;
        for &w in route {
            let steps = ((w - at).norm() / 0.05).ceil().max(1.0) as usize;
            for s in 0..=steps {
                let p = at + (w - at) * (s as Real / steps as Real);
                assert!(
                    !map.is_inside(&p) && map.distance(&p) > radius,
                    "{p:?} on {route:?}"
                );
            }
            at = w;
        }
    }

    /// The way round to a pick in a narrow aisle's far end: down its cross-aisle to the
    /// nearest wide corridor, along it, and up the far cross-aisle into the aisle; every leg
    /// in free space with a robot's clearance, and through no narrow aisle.
    #[test]
    fn the_way_round_to_an_aisles_far_end_keeps_to_wide_corridors() {
        let (site, map, radius, min_width) = narrow_site();
        let (k, j) = (2, 1);
        let pick = site
            .stations
            .iter()
            .find(|s| {
                site.corridor_of(s.position) == Some(k)
                    && site.cross_aisles_around(s.position) == Some((j, j + 1))
            })
            .expect("a pick between cross-aisles 1 and 2");
        let from = vec2(site.cross_aisles[j + 1].0, site.corridors[k].0 - 1.5);
        let round = site
            .route_round(from, pick.position, j, min_width)
            .expect("a way round");
        assert_eq!(round.len(), 4);
        assert_eq!(*round.last().expect("legs"), pick.position);
        assert_eq!(round[2], vec2(site.cross_aisles[j].0, site.corridors[k].0));
        let wide = site.corridor_of(round[0]).expect("on a corridor");
        assert!(2.0 * site.corridors[wide].1 >= min_width, "{round:?}");
        assert_clear(&map, from, &round, radius);
        // Not from inside an aisle, and not when no other corridor is wide enough.
        assert!(
            site.route_round(pick.position, from, j, min_width)
                .is_none()
        );
        assert!(site.route_round(from, pick.position, j, 10.0).is_none());
    }

    /// Out of a narrow aisle through the end behind a robot, to a pick farther along the same
    /// row: out by that end, along the nearest wide corridor, and back into the row next to
    /// the pick on the far side (the same segment) or the near side (a later one); every leg
    /// in free space with a robot's clearance, through no narrow aisle. A pick on the way out,
    /// or in another row, keeps `route_via`'s route.
    #[test]
    fn the_way_out_to_a_pick_farther_along_the_row_goes_round() {
        let (site, map, radius, min_width) = narrow_site();
        let k = 2;
        let y_k = site.corridors[k].0;
        let pick_between = |j: usize| {
            site.stations
                .iter()
                .filter(|s| {
                    site.corridor_of(s.position) == Some(k)
                        && site.cross_aisles_around(s.position) == Some((j, j + 1))
                })
                .max_by(|a, b| a.position.x.total_cmp(&b.position.x))
                .expect("a pick between two cross-aisles")
                .position
        };
        let x = |j: usize| site.cross_aisles[j].0;
        // In segment 1–2, west of the pick, leaving west by cross-aisle 1.
        let from = vec2(x(1) + 2.0, y_k);
        for (pick, entry) in [
            (pick_between(1), 2),
            (pick_between(2), 2),
            (pick_between(3), 3),
        ] {
            let out = site.route_out(from, pick, 1, min_width);
            assert_eq!(out.len(), 5, "{out:?}");
            assert_eq!(out[0], vec2(x(1), y_k));
            assert_eq!(out[3], vec2(x(entry), y_k), "{out:?}");
            assert_eq!(out[4], pick);
            let wide = site.corridor_of(out[1]).expect("on a corridor");
            assert_ne!(wide, k);
            assert!(2.0 * site.corridors[wide].1 >= min_width, "{out:?}");
            assert_clear(&map, from, &out, radius);
        }
        // A pick on the way out (west), or in another row: route_via's route.
        let west = vec2(x(1) - 3.0, y_k);
        assert_eq!(site.route_out(from, west, 1, min_width), vec![west]);
        let other_row = pick_between(0) + vec2(0.0, site.corridors[k + 1].0 - y_k);
        assert_eq!(
            site.route_out(from, other_row, 1, min_width),
            site.route_via(from, other_row, 1)
        );
        // No corridor wide enough: route_via's straight route back in.
        let pick = pick_between(1);
        assert_eq!(site.route_out(from, pick, 1, 100.0), vec![pick]);
    }

    /// Corners on an aisle too narrow for two robots must be reached closely (cutting them
    /// aims the robot at the shelf's end); elsewhere the fleet's 1 m holds.
    #[test]
    fn corners_on_narrow_aisles_are_reached_closely() {
        let narrow = Scenario::builtin("warehouse-narrow").expect("valid");
        let spec = narrow.warehouse.expect("layout");
        let tight = Site::generate(&spec);
        let r = narrow.robot.radius_m;
        let aisle = vec2(tight.cross_aisles[1].0, tight.corridors[1].0);
        assert!((tight.corner_reach(aisle, r, 0.2, 1.0) - 0.35).abs() < 1e-9);
        let corridor = vec2(tight.cross_aisles[1].0, tight.corridors[0].0);
        assert_eq!(tight.corner_reach(corridor, r, 0.2, 1.0), 1.0);
        let wide = site();
        let aisle = vec2(wide.cross_aisles[1].0, wide.corridors[1].0);
        assert_eq!(wide.corner_reach(aisle, 0.3, 0.2, 1.0), 1.0);
    }

    #[test]
    fn layout_has_rows_blocks_docks_and_blind_corners() {
        let s = Scenario::builtin("warehouse").expect("valid");
        let spec = s.warehouse.expect("layout");
        let site = site();
        let shelves = site
            .obstacles
            .iter()
            .filter(|o| matches!(o, Obstacle::Polygon(_)))
            .count();
        assert_eq!(shelves, spec.rows * spec.blocks);
        assert_eq!(site.stations_of(StationKind::Dock).count(), spec.docks);
        assert_eq!(
            site.stations_of(StationKind::Pick).count(),
            spec.rows * spec.blocks
        );
        // A blind corner: from inside an aisle near a cross-aisle, a point around the shelf's
        // end in the next aisle is hidden.
        let map = site.map();
        let c = spec.cross_aisle_width_m;
        let aisle_y = site.corridors[1].0;
        let next_y = site.corridors[2].0;
        let here = vec2(c + 2.0, aisle_y);
        let around = vec2(c - 0.3, next_y);
        assert!(
            !map.line_of_sight(here, vec2(c + 2.0, next_y)),
            "shelf between aisles"
        );
        assert!(!map.line_of_sight(here, around), "blind corner");
        assert!(
            map.line_of_sight(here, vec2(c / 2.0, aisle_y)),
            "down the aisle"
        );
    }
}
