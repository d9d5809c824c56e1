//! Routes on a floor plan: shortest ways for a robot's body through a Nav2 map's free space,
//! as waypoints joined by straight legs.
//!
//! - **Clearance.** Every map cell holds its distance to the nearest cell off the main floor
//!   (occupied, unknown, or a free pocket apart from the floor; an exact Euclidean distance
//!   transform, Felzenszwalb and Huttenlocher's), the map's edge counting as occupied.
//! - **Routing grid.** Cells of [`ROUTE_CELL_M`] hold the least clearance of the map cells
//!   they cover; a robot may pass one when that is at least its radius and [`PASS_MARGIN_M`].
//!   Moves go to the 8 neighbours, diagonals only between two passable sides. A move into a
//!   cell costs its length times `1 + WALL_COST · max(0, 1 − clearance / preferred)`, so routes
//!   keep to the middle of aisles where they can.
//! - **Cost-to-go fields.** Dijkstra from every station once, when the site is built; a route
//!   to a station walks down its field. A route to anywhere else computes that point's field.
//! - **Smoothing.** The walked cells become straight legs: from each waypoint, the farthest
//!   later cell reachable in a straight line that keeps the clearance of the cells it skips
//!   (at most [`SHORTCUT_CLEARANCE_M`] beyond the body), looking past a few cells out of
//!   sight for more in sight.

use super::nav2::OccupancyGrid;
use agent::math::{Real, Vec2, vec2};
use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::sync::Arc;

/// Side of a routing cell (m).
pub const ROUTE_CELL_M: Real = 0.2;
/// Clearance beyond its radius a robot needs to pass a routing cell (m).
pub const PASS_MARGIN_M: Real = 0.05;
/// Clearance beyond its radius at which a cell costs no more than its length (m).
pub const PREFERRED_MARGIN_M: Real = 0.6;
/// How much a cell at a wall costs more than one in the open: `1 + WALL_COST` times.
pub const WALL_COST: Real = 4.0;
/// Clearance beyond the body a shortcut keeps, where the cells it skips had that much (m).
pub const SHORTCUT_CLEARANCE_M: Real = 0.25;

/// Cells out of sight a shortcut may look past for more in sight.
const SMOOTHING_LOOKAHEAD: usize = 8;

const BIG: Real = 1e12;

/// The routing structure of one floor plan for robots of one radius.
#[derive(Clone, PartialEq)]
pub struct Router {
    radius: Real,
    // The map's cells.
    width: usize,
    height: usize,
    resolution: Real,
    origin: Vec2,
    /// Metres from each map cell's centre to the nearest blocked cell's edge (0 if blocked).
    clearance: Vec<f32>,
    // The routing grid.
    step: usize,
    cols: usize,
    rows: usize,
    cell: Real,
    /// Least clearance of the map cells each routing cell covers.
    cell_clearance: Vec<f32>,
    /// Cost to go to each station (its position and field).
    fields: Vec<(Vec2, Arc<[f32]>)>,
}

impl std::fmt::Debug for Router {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Router")
            .field("radius", &self.radius)
            .field("routing_cells", &(self.cols, self.rows))
            .field("stations", &self.fields.len())
            .finish_non_exhaustive()
    }
}

impl Router {
    /// The router of `grid` whose main floor is `floor` ([`super::main_floor`]) for robots
    /// of `radius`, with fields to `stations`. Free pockets off the floor are as solid as the
    /// walls round them.
    pub fn new(grid: &OccupancyGrid, floor: &[bool], radius: Real, stations: &[Vec2]) -> Self {
        let (width, height) = (grid.width, grid.height);
        let blocked: Vec<bool> = floor.iter().map(|f| !f).collect();
        let clearance = clearance(&blocked, width, height, grid.resolution);
        let step = ((ROUTE_CELL_M / grid.resolution).round() as usize).max(1);
        let (cols, rows) = (width.div_ceil(step), height.div_ceil(step));
        let mut cell_clearance = vec![f32::INFINITY; cols * rows];
        for y in 0..height {
            for x in 0..width {
                let c = &mut cell_clearance[(y / step) * cols + x / step];
                *c = c.min(clearance[y * width + x]);
            }
        }
        let mut router = Self {
            radius,
            width,
            height,
            resolution: grid.resolution,
            origin: grid.origin,
            clearance,
            step,
            cols,
            rows,
            cell: grid.resolution * step as Real,
            cell_clearance,
            fields: Vec::new(),
        };
        router.fields = stations
            .iter()
            .map(|&p| {
                let field = router
                    .nearest_passable(p, None)
                    .map_or_else(|| vec![f32::INFINITY; cols * rows], |c| router.field(c));
                (p, field.into())
            })
            .collect();
        router
    }

    /// The radius of the robots this router plans for.
    pub fn radius(&self) -> Real {
        self.radius
    }

    /// Clearance at `p`: metres to the nearest occupied or unknown cell (0 inside one or off
    /// the map).
    pub fn clearance(&self, p: Vec2) -> Real {
        let q = (p - self.origin) / self.resolution;
        if q.x < 0.0 || q.y < 0.0 {
            return 0.0;
        }
        let (x, y) = (q.x as usize, q.y as usize);
        if x >= self.width || y >= self.height {
            return 0.0;
        }
        Real::from(self.clearance[y * self.width + x])
    }

    /// Whether a robot standing at `p` is clear of walls with [`PASS_MARGIN_M`] to spare.
    pub fn fits(&self, p: Vec2) -> bool {
        self.clearance(p) >= self.radius + PASS_MARGIN_M
    }

    /// Whether station `k`'s field reaches `p` (a robot at `p` can get to station `k`).
    pub fn reaches(&self, k: usize, p: Vec2) -> bool {
        self.fields.get(k).is_some_and(|(_, field)| {
            self.nearest_passable(p, Some(field))
                .is_some_and(|c| field[c].is_finite())
        })
    }

    /// Whether the straight line from `a` to `b` keeps a body's clearance: at every point at
    /// least the least of the robot's passing clearance and the clearances at `a` and `b`.
    pub fn straight(&self, a: Vec2, b: Vec2) -> bool {
        let need = (self.radius + PASS_MARGIN_M)
            .min(self.clearance(a))
            .min(self.clearance(b));
        self.clear_line(a, b, need)
    }

    /// Waypoints from `from` to `to`, ending with `to`: `[to]` when the straight line will do
    /// or no way is known.
    pub fn route(&self, from: Vec2, to: Vec2) -> Vec<Vec2> {
        if self.straight(from, to) {
            return vec![to];
        }
        let owned;
        let field: &[f32] = match self.fields.iter().find(|(p, _)| *p == to) {
            Some((_, field)) => field,
            None => {
                let Some(goal) = self.nearest_passable(to, None) else {
                    return vec![to];
                };
                owned = self.field(goal);
                &owned
            }
        };
        let Some(start) = self.nearest_passable(from, Some(field)) else {
            return vec![to];
        };
        if !field[start].is_finite() {
            return vec![to];
        }
        let cells = self.descend(start, field);
        self.smooth(from, to, &cells)
    }

    /// Free floor (m²): every cell of the main floor ([`super::main_floor`]), whether a
    /// robot's centre may reach it or not.
    pub fn free_area(&self) -> Real {
        let free = self.clearance.iter().filter(|&&c| c > 0.0).count();
        free as Real * self.resolution * self.resolution
    }

    /// Routing-cell centres near `docks`, in order of their distance from them, at least
    /// `spacing` apart and `spacing` from every station in `keep_clear`, where a robot has
    /// [`PREFERRED_MARGIN_M`] beyond its radius: `n` of them, or fewer if the floor has no
    /// more.
    pub fn places_near(
        &self,
        docks: &[Vec2],
        keep_clear: &[Vec2],
        n: usize,
        spacing: Real,
    ) -> Vec<Vec2> {
        let mut field = vec![f32::INFINITY; self.cols * self.rows];
        let mut heap = BinaryHeap::new();
        for &d in docks {
            if let Some(c) = self.nearest_passable(d, None) {
                field[c] = 0.0;
                heap.push(Reverse((0_u32, c)));
            }
        }
        self.dijkstra(&mut field, heap);
        let mut order: Vec<usize> = (0..field.len()).filter(|&c| field[c].is_finite()).collect();
        order.sort_by(|&a, &b| field[a].total_cmp(&field[b]).then(a.cmp(&b)));
        let roomy = self.radius + PREFERRED_MARGIN_M;
        let mut out: Vec<Vec2> = Vec::new();
        for c in order {
            if out.len() == n {
                break;
            }
            let p = self.centre(c);
            let apart = |q: &Vec2| (p - q).norm() >= spacing;
            if Real::from(self.cell_clearance[c]) >= roomy
                && out.iter().all(apart)
                && keep_clear.iter().all(apart)
            {
                out.push(p);
            }
        }
        out
    }

    fn centre(&self, c: usize) -> Vec2 {
        let (x, y) = (c % self.cols, c / self.cols);
        self.origin + vec2(x as Real + 0.5, y as Real + 0.5) * self.cell
    }

    fn passable(&self, c: usize) -> bool {
        Real::from(self.cell_clearance[c]) >= self.radius + PASS_MARGIN_M
    }

    /// What entering cell `c` costs per metre.
    fn weight(&self, c: usize) -> Real {
        let preferred = self.radius + PREFERRED_MARGIN_M;
        1.0 + WALL_COST * (1.0 - Real::from(self.cell_clearance[c]) / preferred).max(0.0)
    }

    /// The passable neighbours of `c` with the length of the move.
    fn neighbours(&self, c: usize) -> impl Iterator<Item = (usize, Real)> + '_ {
        let (x, y) = ((c % self.cols) as isize, (c / self.cols) as isize);
        let (cols, rows) = (self.cols as isize, self.rows as isize);
        let at = move |dx: isize, dy: isize| {
            let (nx, ny) = (x + dx, y + dy);
            (nx >= 0 && ny >= 0 && nx < cols && ny < rows)
                .then(|| (ny * cols + nx) as usize)
                .filter(|&n| self.passable(n))
        };
        const MOVES: [(isize, isize); 8] = [
            (1, 0),
            (-1, 0),
            (0, 1),
            (0, -1),
            (1, 1),
            (1, -1),
            (-1, 1),
            (-1, -1),
        ];
        MOVES.into_iter().filter_map(move |(dx, dy)| {
            let n = at(dx, dy)?;
            if dx != 0 && dy != 0 {
                // No corner cutting: both sides of a diagonal must be passable.
                at(dx, 0)?;
                at(0, dy)?;
                Some((n, std::f64::consts::SQRT_2 * self.cell))
            } else {
                Some((n, self.cell))
            }
        })
    }

    /// Cost to go to cell `goal` from every cell.
    fn field(&self, goal: usize) -> Vec<f32> {
        let mut field = vec![f32::INFINITY; self.cols * self.rows];
        field[goal] = 0.0;
        let mut heap = BinaryHeap::new();
        heap.push(Reverse((0_u32, goal)));
        self.dijkstra(&mut field, heap);
        field
    }

    /// Dijkstra over reversed moves: a move from `n` into `m` costs `m`'s weight, so
    /// `field[n] = min over m of field[m] + length · weight(m)`. Keys are the costs' f32 bits,
    /// which order as the costs do (all non-negative); ties go to the lower cell.
    fn dijkstra(&self, field: &mut [f32], mut heap: BinaryHeap<Reverse<(u32, usize)>>) {
        while let Some(Reverse((bits, m))) = heap.pop() {
            let d = f32::from_bits(bits);
            if d > field[m] {
                continue;
            }
            let w = self.weight(m);
            for (n, len) in self.neighbours(m) {
                let nd = (Real::from(d) + len * w) as f32;
                if nd < field[n] {
                    field[n] = nd;
                    heap.push(Reverse((nd.to_bits(), n)));
                }
            }
        }
    }

    /// The passable cell nearest to `p` within 2 m and in sight of it (the straight line
    /// between keeps to the floor), preferring those `field` reaches.
    fn nearest_passable(&self, p: Vec2, field: Option<&[f32]>) -> Option<usize> {
        let q = (p - self.origin) / self.cell;
        let reach = (2.0 / self.cell).ceil() as isize;
        let margin = reach as Real + 1.0;
        let on_grid = |v: Real, n: usize| v.is_finite() && v > -margin && v < n as Real + margin;
        if !(on_grid(q.x, self.cols) && on_grid(q.y, self.rows)) {
            return None;
        }
        let (cx, cy) = (q.x.floor() as isize, q.y.floor() as isize);
        let mut near: Vec<(Real, usize)> = Vec::new();
        for dy in -reach..=reach {
            for dx in -reach..=reach {
                let (x, y) = (cx + dx, cy + dy);
                if x < 0 || y < 0 || x >= self.cols as isize || y >= self.rows as isize {
                    continue;
                }
                let c = y as usize * self.cols + x as usize;
                if !self.passable(c) || field.is_some_and(|f| !f[c].is_finite()) {
                    continue;
                }
                near.push(((self.centre(c) - p).norm(), c));
            }
        }
        near.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        // On the floor, the way to the cell must not leave it; from off the floor (a body
        // pushed into a wall's cells), any way will do.
        let need = if self.clearance(p) > 0.0 { 1e-6 } else { 0.0 };
        near.into_iter()
            .find(|&(_, c)| self.clear_line(p, self.centre(c), need))
            .map(|(_, c)| c)
    }

    /// The cells from `start` down `field` to its goal (field 0).
    fn descend(&self, start: usize, field: &[f32]) -> Vec<usize> {
        let mut cells = vec![start];
        let mut c = start;
        while field[c] > 0.0 && cells.len() <= field.len() {
            let next = self
                .neighbours(c)
                .map(|(n, len)| (Real::from(field[n]) + len * self.weight(n), n))
                .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            match next {
                Some((_, n)) if field[n] < field[c] => {
                    cells.push(n);
                    c = n;
                }
                _ => break,
            }
        }
        cells
    }

    /// Straight legs along `cells` from `from` to `to` (the waypoints after `from`).
    fn smooth(&self, from: Vec2, to: Vec2, cells: &[usize]) -> Vec<Vec2> {
        // Points: from, the cells between the first and last, to.
        let mut points = vec![from];
        let mut clear = vec![self.clearance(from)];
        for &c in cells.iter().skip(1).take(cells.len().saturating_sub(2)) {
            points.push(self.centre(c));
            clear.push(Real::from(self.cell_clearance[c]));
        }
        points.push(to);
        clear.push(self.clearance(to));
        let cap = self.radius + SHORTCUT_CLEARANCE_M;
        let mut out = Vec::new();
        let mut i = 0;
        while i + 1 < points.len() {
            let mut best = i + 1;
            let mut need = clear[i].min(clear[i + 1]).min(cap);
            let mut misses = 0;
            for j in i + 2..points.len() {
                need = need.min(clear[j]);
                if self.clear_line(points[i], points[j], need) {
                    best = j;
                    misses = 0;
                } else {
                    // A cell or two out of sight round a bend may be followed by more in
                    // sight; past a few, the corner is real.
                    misses += 1;
                    if misses > SMOOTHING_LOOKAHEAD {
                        break;
                    }
                }
            }
            out.push(points[best]);
            i = best;
        }
        out
    }

    /// Whether every point of segment `a`–`b` (sampled at half the map's resolution) has at
    /// least `need` clearance.
    fn clear_line(&self, a: Vec2, b: Vec2, need: Real) -> bool {
        let steps = ((b - a).norm() / (0.5 * self.resolution)).ceil().max(1.0) as usize;
        (0..=steps).all(|s| {
            let p = a + (b - a) * (s as Real / steps as Real);
            self.clearance(p) >= need - 1e-9
        })
    }
}

/// Metres from each cell's centre to the nearest blocked cell's edge (0 in blocked cells); the
/// ring outside the grid counts as blocked.
pub(crate) fn clearance(
    blocked: &[bool],
    width: usize,
    height: usize,
    resolution: Real,
) -> Vec<f32> {
    // Squared distances in cells on the grid with a blocked border.
    let (w, h) = (width + 2, height + 2);
    let mut d: Vec<Real> = vec![BIG; w * h];
    for y in 0..h {
        for x in 0..w {
            let border = x == 0 || y == 0 || x == w - 1 || y == h - 1;
            if border || blocked[(y - 1) * width + (x - 1)] {
                d[y * w + x] = 0.0;
            }
        }
    }
    let n = w.max(h);
    let (mut f, mut out, mut v, mut z) = (
        vec![0.0; n],
        vec![0.0; n],
        vec![0_usize; n],
        vec![0.0; n + 1],
    );
    for x in 0..w {
        for y in 0..h {
            f[y] = d[y * w + x];
        }
        distance_1d(&f[..h], &mut out[..h], &mut v, &mut z);
        for y in 0..h {
            d[y * w + x] = out[y];
        }
    }
    for y in 0..h {
        f[..w].copy_from_slice(&d[y * w..(y + 1) * w]);
        distance_1d(&f[..w], &mut out[..w], &mut v, &mut z);
        d[y * w..(y + 1) * w].copy_from_slice(&out[..w]);
    }
    let mut clearance = Vec::with_capacity(width * height);
    for y in 0..height {
        for x in 0..width {
            let cells = d[(y + 1) * w + x + 1].sqrt();
            // Centre to centre, less half a cell: to the blocked cell's near edge.
            clearance.push(((cells - 0.5).max(0.0) * resolution) as f32);
        }
    }
    clearance
}

/// The lower envelope of parabolas: `out[q] = min over p of (q − p)² + f[p]`
/// (Felzenszwalb and Huttenlocher, "Distance transforms of sampled functions", 2012).
fn distance_1d(f: &[Real], out: &mut [Real], v: &mut [usize], z: &mut [Real]) {
    let n = f.len();
    let meet = |q: usize, p: usize| {
        let (qf, pf) = (q as Real, p as Real);
        ((f[q] + qf * qf) - (f[p] + pf * pf)) / (2.0 * qf - 2.0 * pf)
    };
    let mut k = 0;
    v[0] = 0;
    z[0] = -BIG;
    z[1] = BIG;
    for q in 1..n {
        let mut s = meet(q, v[k]);
        while s <= z[k] {
            k -= 1;
            s = meet(q, v[k]);
        }
        k += 1;
        v[k] = q;
        z[k] = s;
        z[k + 1] = BIG;
    }
    k = 0;
    for (q, o) in out.iter_mut().enumerate() {
        while z[k + 1] < q as Real {
            k += 1;
        }
        let dq = q as Real - v[k] as Real;
        *o = dq * dq + f[v[k]];
    }
}

#[cfg(test)]
mod tests {
    use super::super::nav2::Cell;
    use super::*;

    /// A `w` × `h` grid at 0.1 m with the cells `wall` says blocked.
    fn grid(w: usize, h: usize, wall: impl Fn(usize, usize) -> bool) -> OccupancyGrid {
        let cells = (0..w * h)
            .map(|i| {
                if wall(i % w, i / w) {
                    Cell::Occupied
                } else {
                    Cell::Free
                }
            })
            .collect();
        OccupancyGrid {
            width: w,
            height: h,
            resolution: 0.1,
            origin: vec2(0.0, 0.0),
            cells,
        }
    }

    #[test]
    fn the_distance_transform_is_exact() {
        let g = grid(30, 20, |x, y| (x * 7 + y * 13) % 17 == 0);
        let blocked: Vec<bool> = g.cells.iter().map(|&c| c != Cell::Free).collect();
        let fast = clearance(&blocked, 30, 20, 0.1);
        for y in 0..20_isize {
            for x in 0..30_isize {
                // Brute force, the border ring included.
                let mut best = Real::INFINITY;
                for by in -1..=20_isize {
                    for bx in -1..=30_isize {
                        let border = bx < 0 || by < 0 || bx >= 30 || by >= 20;
                        if border || blocked[(by * 30 + bx) as usize] {
                            let d = (((x - bx).pow(2) + (y - by).pow(2)) as Real).sqrt();
                            best = best.min(d);
                        }
                    }
                }
                let want = ((best - 0.5).max(0.0) * 0.1) as f32;
                assert!((fast[(y * 30 + x) as usize] - want).abs() < 1e-5, "{x},{y}");
            }
        }
    }

    /// A wall across a 10 × 6 m room with a gap at its top: the route goes through the gap,
    /// every leg keeps the body clear of the wall, and the last waypoint is the goal.
    #[test]
    fn routes_go_round_walls_through_the_gap() {
        let g = grid(100, 60, |x, y| (48..52).contains(&x) && y < 45);
        let (from, to) = (vec2(2.0, 1.0), vec2(8.0, 1.0));
        let router = Router::new(&g, &super::super::main_floor(&g), 0.3, &[to]);
        let route = router.route(from, to);
        assert_eq!(*route.last().expect("waypoints"), to);
        assert!(route.len() >= 2, "{route:?}");
        let mut at = from;
        for &w in &route {
            assert!(router.clear_line(at, w, 0.3), "{at:?} -> {w:?}");
            at = w;
        }
        assert!(
            route.iter().any(|w| w.y > 4.5),
            "through the gap: {route:?}"
        );
        // A target that is no station gets a field of its own, and the same way.
        let elsewhere = router.route(from, vec2(8.0, 1.1));
        assert!(elsewhere.iter().any(|w| w.y > 4.5), "{elsewhere:?}");
        // In the open, straight.
        assert_eq!(
            router.route(vec2(1.0, 1.0), vec2(3.0, 4.0)),
            vec![vec2(3.0, 4.0)]
        );
    }

    /// A wall across the room: the smaller side is a pocket off the floor, solid for routes.
    #[test]
    fn a_walled_off_station_is_not_reached() {
        let g = grid(100, 60, |x, _| (30..34).contains(&x));
        let router = Router::new(&g, &super::super::main_floor(&g), 0.3, &[vec2(8.0, 1.0)]);
        assert!(router.reaches(0, vec2(9.0, 5.0)) && router.fits(vec2(9.0, 5.0)));
        assert_eq!(router.clearance(vec2(2.0, 1.0)), 0.0);
        assert!(!router.fits(vec2(2.0, 1.0)));
        assert!((router.free_area() - 6.6 * 6.0).abs() < 1e-9);
    }

    #[test]
    fn places_are_spaced_and_clear_of_stations() {
        let g = grid(100, 60, |_, _| false);
        let dock = vec2(1.0, 1.0);
        let router = Router::new(&g, &super::super::main_floor(&g), 0.3, &[dock]);
        let places = router.places_near(&[dock], &[dock], 5, 1.5);
        assert_eq!(places.len(), 5);
        for (i, p) in places.iter().enumerate() {
            assert!((p - dock).norm() >= 1.5 && router.clearance(*p) >= 0.9);
            for q in &places[..i] {
                assert!((p - q).norm() >= 1.5);
            }
        }
    }
}
