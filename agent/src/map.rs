//! The static map: walls and shelves, with the distance, range and ray queries planners need.
//!
//! Geometry lives in a parry2d `Polyline` (with its bounding-volume hierarchy) so that queries
//! cost O(log n) in the size of a warehouse. Obstacles are also kept in RVO2's representation
//! (a ring of vertices per obstacle, each vertex owning the edge to its successor, with a
//! convexity flag), which ORCA needs. Edge `i` of the polyline is always the edge owned by
//! vertex `i`.

use crate::fastmath::LANES;
use crate::math::{Real, Vec2, closest_on_segment, det, dist_sq_point_segment};
use crate::obstacle_points::ObstaclePoints;
use parry2d_f64::bounding_volume::Aabb;
use parry2d_f64::math::{Isometry, Point, Vector};
use parry2d_f64::query::{PointQuery, Ray, RayCast};
use parry2d_f64::shape::Polyline;

/// A static obstacle as a user describes it.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Obstacle {
    /// A closed simple polygon (a shelf, a pillar). Any orientation; stored counter-clockwise.
    Polygon(Vec<Vec2>),
    /// A wall of zero thickness between two points; blocks from both sides.
    Wall(Vec2, Vec2),
}

/// Why a map could not be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MapError {
    /// A polygon needs at least three vertices.
    #[error("obstacle {index}: a polygon needs at least 3 vertices, got {got}")]
    TooFewVertices {
        /// Index of the obstacle in the input.
        index: usize,
        /// How many vertices it had.
        got: usize,
    },
    /// Coordinates must be finite.
    #[error("obstacle {index}: coordinates must be finite")]
    NonFinite {
        /// Index of the obstacle in the input.
        index: usize,
    },
    /// Zero-length edges or zero-area polygons cannot be used.
    #[error("obstacle {index}: degenerate (zero-length edge or zero area)")]
    Degenerate {
        /// Index of the obstacle in the input.
        index: usize,
    },
}

/// One vertex of an obstacle ring, in RVO2's representation; it owns the edge to `next`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObstacleVertex {
    /// The vertex position.
    pub point: Vec2,
    /// Index of the next vertex of the same obstacle (counter-clockwise).
    pub next: usize,
    /// Index of the previous vertex of the same obstacle.
    pub prev: usize,
    /// Unit direction of the edge from this vertex to `next`.
    pub unit_dir: Vec2,
    /// Whether the obstacle is convex at this vertex (always true for walls).
    pub convex: bool,
}

/// Walls and shelves, immutable once built.
#[derive(Debug, Clone, Default)]
pub struct StaticMap {
    obstacles: Vec<Obstacle>,
    vertices: Vec<ObstacleVertex>,
    polyline: Option<Polyline>,
    /// Counter-clockwise polygons with their bounding boxes, for inside tests.
    polygons: Vec<(Aabb, Vec<Vec2>)>,
    /// For each vertex, the index into `polygons` of its obstacle (`None` for walls).
    vertex_polygon: Vec<Option<usize>>,
    /// Social Force wall points, sampled on first use at the default resolution.
    sampled: std::sync::OnceLock<ObstaclePoints>,
}

/// How near an edge (m) a point along a wall must lie for the wall to run on there
/// ([`LocalMap::nearest_wall_runs_on`]): a wall traced from an occupancy grid zigzags by
/// half a cell (2.5 cm at Nav2's usual 5 cm).
pub const RUNS_ON_TOLERANCE: Real = 0.05;

/// The edges and polygons near a region, gathered once so that a planner can query many
/// points cheaply. Reuse one across plans to avoid allocation.
#[derive(Debug, Clone, Default)]
pub struct LocalMap {
    segments: Vec<(Vec2, Vec2)>,
    /// The segments again as columns (start, direction, squared length), padded with copies
    /// of the first to a multiple of `LANES` so that the nearest-edge search vectorises.
    columns: SegmentColumns,
    polygons: Vec<usize>,
    scratch: Vec<u32>,
}

/// Segments a→b as columns: a, b − a and |b − a|² (1 for a point, whose direction is 0).
#[derive(Debug, Clone, Default)]
struct SegmentColumns {
    ax: Vec<Real>,
    ay: Vec<Real>,
    abx: Vec<Real>,
    aby: Vec<Real>,
    len_sq: Vec<Real>,
}

impl SegmentColumns {
    fn fill(&mut self, segments: &[(Vec2, Vec2)]) {
        for v in [
            &mut self.ax,
            &mut self.ay,
            &mut self.abx,
            &mut self.aby,
            &mut self.len_sq,
        ] {
            v.clear();
        }
        let padded = segments.len().next_multiple_of(LANES);
        for (a, b) in segments
            .iter()
            .chain(std::iter::repeat_n(&segments[0], padded - segments.len()))
        {
            let ab = b - a;
            let len_sq = ab.x * ab.x + ab.y * ab.y;
            self.ax.push(a.x);
            self.ay.push(a.y);
            self.abx.push(ab.x);
            self.aby.push(ab.y);
            self.len_sq.push(if len_sq > 0.0 { len_sq } else { 1.0 });
        }
    }
}

/// The smallest squared distance from `p` to the segments of `columns`: exactly
/// [`crate::math::dist_sq_point_segment`]'s arithmetic per segment, `LANES` segments at a time
/// (a minimum does not depend on the order it is taken in).
struct NearestEdge<'a> {
    columns: &'a SegmentColumns,
    p: Vec2,
}

impl pulp::WithSimd for NearestEdge<'_> {
    type Output = Real;

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _: S) -> Real {
        let Self { columns: c, p } = self;
        let mut best = [Real::INFINITY; LANES];
        let blocks = c.ax.chunks_exact(LANES).zip(c.ay.chunks_exact(LANES));
        let dirs = c.abx.chunks_exact(LANES).zip(c.aby.chunks_exact(LANES));
        for (((ax, ay), (abx, aby)), len_sq) in blocks.zip(dirs).zip(c.len_sq.chunks_exact(LANES)) {
            for l in 0..LANES {
                let (apx, apy) = (p.x - ax[l], p.y - ay[l]);
                let t = ((apx * abx[l] + apy * aby[l]) / len_sq[l]).clamp(0.0, 1.0);
                let (qx, qy) = (p.x - (ax[l] + abx[l] * t), p.y - (ay[l] + aby[l] * t));
                best[l] = best[l].min(qx * qx + qy * qy);
            }
        }
        best.iter().fold(Real::INFINITY, |m, &d| m.min(d))
    }
}

impl LocalMap {
    /// True when no edge was gathered.
    pub fn is_empty(&self) -> bool {
        self.segments.is_empty()
    }

    /// The gathered edges.
    pub fn segments(&self) -> &[(Vec2, Vec2)] {
        &self.segments
    }

    /// Distance from `p` to the nearest gathered edge (0 inside a gathered polygon,
    /// `Real::INFINITY` when nothing was gathered). Exact for points whose true nearest edge
    /// was gathered.
    pub fn distance(&self, map: &StaticMap, p: &Vec2) -> Real {
        let best = self.edge_distance(p);
        if best.is_finite()
            && self
                .polygons
                .iter()
                .any(|&i| in_polygon(&map.polygons[i], p))
        {
            0.0
        } else {
            best
        }
    }

    /// Whether the gathered wall or shelf face nearest `p` runs on for `length` both ways
    /// along itself. Four points, `length` and `length`/2 either side of the nearest point
    /// along the nearest edge, are looked at from just off that point, on `p`'s side: each
    /// lies within [`RUNS_ON_TOLERANCE`] of a gathered edge (the wall goes on), or another
    /// wall cuts the way to it (the wall turns a concave corner). A hallway's walls run on;
    /// shelves' end faces broken by aisle mouths, or a wall beside a doorway, do not. False
    /// when nothing was gathered.
    pub fn nearest_wall_runs_on(&self, map: &StaticMap, p: &Vec2, length: Real) -> bool {
        // The first of the nearest edges of non-zero length.
        let Some((d_sq, (a, b))) = self
            .segments
            .iter()
            .filter(|(a, b)| (b - a).norm_squared() > 0.0)
            .map(|ab| (dist_sq_point_segment(&ab.0, &ab.1, p), ab))
            .min_by(|x, y| x.0.total_cmp(&y.0))
        else {
            return false;
        };
        let at = closest_on_segment(*a, *b, *p);
        let along = (b - a).normalize();
        let off = if d_sq > 0.0 {
            (p - at) * (RUNS_ON_TOLERANCE.min(d_sq.sqrt()) / d_sq.sqrt())
        } else {
            Vec2::zeros()
        };
        [-1.0, -0.5, 0.5, 1.0].iter().all(|s| {
            let step = along * (s * length);
            self.edge_distance(&(at + step)) <= RUNS_ON_TOLERANCE
                || !map.line_of_sight(at + off, at + off + step)
        })
    }

    /// How far the ray from `p` in direction `dir` (not necessarily unit) goes before it
    /// meets a gathered edge, in units of `dir`'s length (`Real::INFINITY` when it meets none).
    pub fn ray_distance(&self, p: &Vec2, dir: &Vec2) -> Real {
        self.segments
            .iter()
            .filter_map(|(a, b)| {
                // p + t·dir = a + s·(b − a), t ≥ 0, 0 ≤ s ≤ 1.
                let e = b - a;
                let denom = det(dir, &e);
                if denom == 0.0 {
                    return None;
                }
                let ap = a - p;
                let t = det(&ap, &e) / denom;
                let s = det(&ap, dir) / denom;
                (t >= 0.0 && (0.0..=1.0).contains(&s)).then_some(t)
            })
            .fold(Real::INFINITY, Real::min)
    }

    /// Distance from `p` to the nearest gathered edge, inside a polygon or not
    /// (`Real::INFINITY` when nothing was gathered).
    pub fn edge_distance(&self, p: &Vec2) -> Real {
        if self.segments.is_empty() {
            return Real::INFINITY;
        }
        pulp::Arch::new()
            .dispatch(NearestEdge {
                columns: &self.columns,
                p: *p,
            })
            .sqrt()
    }
}

fn point(v: &Vec2) -> Point<Real> {
    Point::new(v.x, v.y)
}

fn signed_area(poly: &[Vec2]) -> Real {
    let n = poly.len();
    (0..n)
        .map(|i| det(&poly[i], &poly[(i + 1) % n]))
        .sum::<Real>()
        * 0.5
}

fn aabb_of(points: &[Vec2]) -> Aabb {
    Aabb::from_points(points.iter().map(point))
}

impl StaticMap {
    /// An empty map (open space).
    pub fn empty() -> Self {
        Self::default()
    }

    /// Builds a map from obstacles, validating them.
    pub fn new(obstacles: Vec<Obstacle>) -> Result<Self, MapError> {
        let mut vertices = Vec::new();
        let mut polygons = Vec::new();
        let mut vertex_polygon = Vec::new();
        let mut stored = Vec::with_capacity(obstacles.len());
        for (index, obstacle) in obstacles.into_iter().enumerate() {
            let ring = match obstacle {
                Obstacle::Polygon(mut poly) => {
                    if poly.len() < 3 {
                        return Err(MapError::TooFewVertices {
                            index,
                            got: poly.len(),
                        });
                    }
                    if poly.iter().any(|p| !(p.x.is_finite() && p.y.is_finite())) {
                        return Err(MapError::NonFinite { index });
                    }
                    let area = signed_area(&poly);
                    if area.abs() < 1e-12 {
                        return Err(MapError::Degenerate { index });
                    }
                    if area < 0.0 {
                        poly.reverse();
                    }
                    polygons.push((aabb_of(&poly), poly.clone()));
                    Obstacle::Polygon(poly)
                }
                Obstacle::Wall(a, b) => Obstacle::Wall(a, b),
            };
            let ring_points: Vec<Vec2> = match &ring {
                Obstacle::Polygon(p) => p.clone(),
                Obstacle::Wall(a, b) => vec![*a, *b],
            };
            if ring_points
                .iter()
                .any(|p| !(p.x.is_finite() && p.y.is_finite()))
            {
                return Err(MapError::NonFinite { index });
            }
            push_ring(&mut vertices, &ring_points).ok_or(MapError::Degenerate { index })?;
            let owner = matches!(ring, Obstacle::Polygon(_)).then(|| polygons.len() - 1);
            vertex_polygon.resize(vertices.len(), owner);
            stored.push(ring);
        }
        let polyline = (!vertices.is_empty()).then(|| {
            let pts = vertices.iter().map(|v| point(&v.point)).collect();
            let idx = vertices
                .iter()
                .enumerate()
                .map(|(i, v)| [i as u32, v.next as u32])
                .collect();
            Polyline::new(pts, Some(idx))
        });
        Ok(Self {
            obstacles: stored,
            vertices,
            polyline,
            polygons,
            vertex_polygon,
            sampled: Default::default(),
        })
    }

    /// The obstacles as given (polygons counter-clockwise).
    pub fn obstacles(&self) -> &[Obstacle] {
        &self.obstacles
    }

    /// True when there is nothing to collide with.
    pub fn is_empty(&self) -> bool {
        self.vertices.is_empty()
    }

    /// All obstacle vertices in RVO2's representation; vertex `i` owns edge `i`.
    pub fn vertices(&self) -> &[ObstacleVertex] {
        &self.vertices
    }

    /// Edge `i` as its two end points.
    pub fn edge(&self, i: usize) -> (Vec2, Vec2) {
        let v = &self.vertices[i];
        (v.point, self.vertices[v.next].point)
    }

    /// Whether `p` is inside a polygonal obstacle.
    pub fn is_inside(&self, p: &Vec2) -> bool {
        self.polygons.iter().any(|polygon| in_polygon(polygon, p))
    }

    /// Distance from `p` to the nearest obstacle surface; 0 inside a polygon;
    /// `Real::INFINITY` on an empty map.
    pub fn distance(&self, p: &Vec2) -> Real {
        let Some(polyline) = &self.polyline else {
            return Real::INFINITY;
        };
        if self.is_inside(p) {
            return 0.0;
        }
        polyline.distance_to_local_point(&point(p), false)
    }

    /// Appends to `out` the indices of all edges whose bounding box comes within `radius` of
    /// the box `[min, max]`. A superset of the edges within that distance.
    pub fn edges_near_box(&self, min: Vec2, max: Vec2, radius: Real, out: &mut Vec<u32>) {
        let Some(polyline) = &self.polyline else {
            return;
        };
        let query = Aabb::new(
            Point::new(min.x - radius, min.y - radius),
            Point::new(max.x + radius, max.y + radius),
        );
        out.extend(polyline.bvh().intersect_aabb(&query));
    }

    /// Gathers into `local` every edge (and its polygon) that may lie within `radius` of the
    /// box `[min, max]`, replacing what `local` held.
    pub fn gather(&self, min: Vec2, max: Vec2, radius: Real, local: &mut LocalMap) {
        local.segments.clear();
        local.polygons.clear();
        local.scratch.clear();
        self.edges_near_box(min, max, radius, &mut local.scratch);
        local.scratch.sort_unstable();
        for &i in &local.scratch {
            let i = i as usize;
            let v = &self.vertices[i];
            // A wall is stored as two opposite edges; one is enough for distances.
            if self.vertex_polygon[i].is_none() && v.next < i {
                continue;
            }
            local.segments.push((v.point, self.vertices[v.next].point));
            if let Some(p) = self.vertex_polygon[i]
                && !local.polygons.contains(&p)
            {
                local.polygons.push(p);
            }
        }
        if !local.segments.is_empty() {
            local.columns.fill(&local.segments);
        }
    }

    /// The Social Force model's wall points at `resolution` per metre; cached for
    /// PySocialForce's default of 10.
    pub fn sampled_points(&self, resolution: Real) -> std::borrow::Cow<'_, ObstaclePoints> {
        const DEFAULT_RESOLUTION: Real = 10.0;
        if resolution == DEFAULT_RESOLUTION {
            std::borrow::Cow::Borrowed(self.sampled.get_or_init(|| {
                ObstaclePoints::from_segments(self.boundary_segments(), resolution)
            }))
        } else {
            std::borrow::Cow::Owned(ObstaclePoints::from_segments(
                self.boundary_segments(),
                resolution,
            ))
        }
    }

    /// The obstacle outlines as drawn: each wall once, each polygon edge once.
    pub fn boundary_segments(&self) -> impl Iterator<Item = (Vec2, Vec2)> + '_ {
        self.vertices
            .iter()
            .enumerate()
            .filter(|(i, v)| self.vertex_polygon[*i].is_some() || v.next > *i)
            .map(|(_, v)| (v.point, self.vertices[v.next].point))
    }

    /// Distance along the ray from `origin` in unit direction `dir` to the first obstacle
    /// surface, if one is hit within `max_dist`.
    pub fn cast_ray(&self, origin: Vec2, dir: Vec2, max_dist: Real) -> Option<Real> {
        let polyline = self.polyline.as_ref()?;
        let ray = Ray::new(point(&origin), Vector::new(dir.x, dir.y));
        polyline.cast_ray(&Isometry::identity(), &ray, max_dist, false)
    }

    /// Whether the straight segment `a`–`b` is free of obstacle edges (line of sight).
    pub fn line_of_sight(&self, a: Vec2, b: Vec2) -> bool {
        let d = b - a;
        let len = d.norm();
        if len <= 0.0 {
            return true;
        }
        self.cast_ray(a, d / len, len).is_none()
    }
}

/// Appends one obstacle ring in RVO2's layout (`RVOSimulator::addObstacle`). Returns `None`
/// for a zero-length edge.
fn push_ring(vertices: &mut Vec<ObstacleVertex>, ring: &[Vec2]) -> Option<()> {
    let first = vertices.len();
    let n = ring.len();
    for i in 0..n {
        let next_point = ring[(i + 1) % n];
        let dir = next_point - ring[i];
        let len = dir.norm();
        if len <= 1e-12 {
            return None;
        }
        let prev_point = ring[(i + n - 1) % n];
        // RVO2: a two-vertex obstacle is convex everywhere; otherwise convex where the ring
        // turns left (leftOf(prev, this, next) >= 0).
        let convex = n == 2 || det(&(ring[i] - prev_point), &(next_point - prev_point)) >= 0.0;
        vertices.push(ObstacleVertex {
            point: ring[i],
            next: first + (i + 1) % n,
            prev: first + (i + n - 1) % n,
            unit_dir: dir / len,
            convex,
        });
    }
    Some(())
}

/// Even-odd point-in-polygon test.
/// Whether `p` lies inside a stored polygon, its bounding box checked first.
fn in_polygon((aabb, poly): &(Aabb, Vec<Vec2>), p: &Vec2) -> bool {
    aabb.contains_local_point(&point(p)) && inside(poly, p)
}

fn inside(poly: &[Vec2], p: &Vec2) -> bool {
    let mut result = false;
    let n = poly.len();
    let mut j = n - 1;
    for i in 0..n {
        let (a, b) = (poly[i], poly[j]);
        if (a.y > p.y) != (b.y > p.y) && p.x < (b.x - a.x) * (p.y - a.y) / (b.y - a.y) + a.x {
            result = !result;
        }
        j = i;
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::vec2;

    fn square() -> Obstacle {
        // Clockwise on purpose: the map must store it counter-clockwise.
        Obstacle::Polygon(vec![
            vec2(0.0, 0.0),
            vec2(0.0, 1.0),
            vec2(1.0, 1.0),
            vec2(1.0, 0.0),
        ])
    }

    /// A ray meets the nearest edge it crosses, in units of its direction's length; one
    /// that crosses none, or runs parallel to an edge, meets nothing.
    #[test]
    fn a_ray_meets_the_first_edge_it_crosses() {
        let mut local = LocalMap::default();
        let map = StaticMap::new(vec![Obstacle::Polygon(vec![
            vec2(-5.0, 1.0),
            vec2(5.0, 1.0),
            vec2(5.0, 2.0),
            vec2(-5.0, 2.0),
        ])])
        .expect("a map");
        map.gather(vec2(-10.0, -10.0), vec2(10.0, 10.0), 0.0, &mut local);
        let p = vec2(0.0, 0.0);
        assert!((local.ray_distance(&p, &vec2(0.0, 1.0)) - 1.0).abs() < 1e-12);
        assert!((local.ray_distance(&p, &vec2(0.0, 2.0)) - 0.5).abs() < 1e-12);
        assert!(local.ray_distance(&p, &vec2(0.0, -1.0)).is_infinite());
        assert!(
            local
                .ray_distance(&vec2(-6.0, 1.0), &vec2(1.0, 0.0))
                .is_finite()
        );
        assert!(
            local
                .ray_distance(&vec2(-6.0, 0.0), &vec2(1.0, 0.0))
                .is_infinite()
        );
    }

    #[test]
    fn distance_is_zero_inside_and_euclidean_outside() {
        let map = StaticMap::new(vec![square()]).expect("valid square");
        assert_eq!(map.distance(&vec2(0.5, 0.5)), 0.0);
        assert!((map.distance(&vec2(2.0, 0.5)) - 1.0).abs() < 1e-12);
        assert!((map.distance(&vec2(2.0, 2.0)) - 2f64.sqrt()).abs() < 1e-12);
        assert_eq!(StaticMap::empty().distance(&vec2(0.0, 0.0)), f64::INFINITY);
    }

    #[test]
    fn polygons_are_stored_counter_clockwise_and_convex() {
        let map = StaticMap::new(vec![square()]).expect("valid square");
        let Obstacle::Polygon(p) = &map.obstacles()[0] else {
            panic!("polygon expected")
        };
        assert!(signed_area(p) > 0.0);
        assert!(map.vertices().iter().all(|v| v.convex));
    }

    #[test]
    fn wall_blocks_from_both_sides_and_blocks_sight() {
        let map = StaticMap::new(vec![Obstacle::Wall(vec2(0.0, -1.0), vec2(0.0, 1.0))])
            .expect("valid wall");
        assert_eq!(map.vertices().len(), 2);
        assert!((map.distance(&vec2(-0.5, 0.0)) - 0.5).abs() < 1e-12);
        assert!(!map.line_of_sight(vec2(-1.0, 0.0), vec2(1.0, 0.0)));
        assert!(map.line_of_sight(vec2(-1.0, 2.0), vec2(1.0, 2.0)));
    }

    #[test]
    fn bad_obstacles_are_rejected_with_their_index() {
        let two = Obstacle::Polygon(vec![vec2(0.0, 0.0), vec2(1.0, 0.0)]);
        assert_eq!(
            StaticMap::new(vec![square(), two]).unwrap_err(),
            MapError::TooFewVertices { index: 1, got: 2 }
        );
        let nan = Obstacle::Wall(vec2(f64::NAN, 0.0), vec2(1.0, 0.0));
        assert_eq!(
            StaticMap::new(vec![nan]).unwrap_err(),
            MapError::NonFinite { index: 0 }
        );
        let flat = Obstacle::Polygon(vec![vec2(0.0, 0.0), vec2(1.0, 0.0), vec2(2.0, 0.0)]);
        assert_eq!(
            StaticMap::new(vec![flat]).unwrap_err(),
            MapError::Degenerate { index: 0 }
        );
    }

    #[test]
    fn a_wall_runs_on_and_shelf_ends_broken_by_aisle_mouths_do_not() {
        // A hallway wall along y = 0, and across from it shelf ends 1.2 m wide along y = 3
        // with 1.5 m mouths between them (the narrow warehouse's cross-aisle).
        let mut obstacles = vec![Obstacle::Wall(vec2(-10.0, 0.0), vec2(10.0, 0.0))];
        for k in 0..6 {
            let x = -8.0 + 2.7 * Real::from(k);
            obstacles.push(Obstacle::Polygon(vec![
                vec2(x, 3.0),
                vec2(x + 1.2, 3.0),
                vec2(x + 1.2, 10.0),
                vec2(x, 10.0),
            ]));
        }
        let map = StaticMap::new(obstacles).expect("valid map");
        let mut local = LocalMap::default();
        map.gather(vec2(-6.0, -1.0), vec2(6.0, 4.0), 0.4, &mut local);
        let runs_on = |p: Vec2| local.nearest_wall_runs_on(&map, &p, 1.5);
        assert!(runs_on(vec2(0.0, 0.6)));
        // Beside a shelf end's middle, and beside a mouth.
        assert!(!runs_on(vec2(-2.0, 2.4)));
        assert!(!runs_on(vec2(-0.05, 2.4)));
        // Near the wall's open end it no longer runs on.
        assert!(!runs_on(vec2(9.5, 0.6)));
        assert!(!LocalMap::default().nearest_wall_runs_on(&map, &vec2(0.0, 0.0), 1.5));
        // Into a concave corner it runs on: the wall turns, it does not open.
        let mut corner = LocalMap::default();
        let room = StaticMap::new(vec![
            Obstacle::Wall(vec2(-10.0, 0.0), vec2(10.0, 0.0)),
            Obstacle::Wall(vec2(10.0, 0.0), vec2(10.0, 3.0)),
        ])
        .expect("valid map");
        room.gather(vec2(6.0, -1.0), vec2(11.0, 4.0), 0.4, &mut corner);
        assert!(corner.nearest_wall_runs_on(&room, &vec2(9.5, 0.4), 1.5));
    }

    #[test]
    fn edges_near_box_finds_close_edges_only() {
        let far = Obstacle::Wall(vec2(100.0, 0.0), vec2(101.0, 0.0));
        let map = StaticMap::new(vec![square(), far]).expect("valid map");
        let mut out = Vec::new();
        map.edges_near_box(vec2(2.0, 0.0), vec2(3.0, 1.0), 1.5, &mut out);
        out.sort();
        // The square's left edge (x = 0) lies 2 m from the box: out of range.
        assert_eq!(out, vec![0, 1, 3]);
        out.clear();
        map.edges_near_box(vec2(2.0, 0.0), vec2(3.0, 1.0), 2.5, &mut out);
        out.sort();
        assert_eq!(out, vec![0, 1, 2, 3]);
    }

    proptest::proptest! {
        /// The vectorised nearest-edge search gives exactly the bits of the one-segment-at-a-
        /// time minimum of `dist_sq_point_segment`, for any number of edges (padding included).
        #[test]
        fn local_distance_has_the_bits_of_the_scalar_scan(
            walls in proptest::collection::vec((-20.0..20.0f64, -20.0..20.0f64, -5.0..5.0f64, -5.0..5.0f64), 1..40),
            points in proptest::collection::vec((-25.0..25.0f64, -25.0..25.0f64), 1..20),
        ) {
            let mut obstacles: Vec<Obstacle> = walls
                .iter()
                .filter(|w| w.2.abs() + w.3.abs() > 1e-3)
                .map(|&(x, y, dx, dy)| Obstacle::Wall(vec2(x, y), vec2(x + dx, y + dy)))
                .collect();
            obstacles.push(square());
            let map = StaticMap::new(obstacles).expect("valid map");
            let mut local = LocalMap::default();
            map.gather(vec2(-20.0, -20.0), vec2(20.0, 20.0), 10.0, &mut local);
            for (x, y) in points {
                let p = vec2(x, y);
                let scalar = local
                    .segments()
                    .iter()
                    .map(|(a, b)| crate::math::dist_sq_point_segment(a, b, &p))
                    .fold(Real::INFINITY, Real::min);
                let expected = if map.is_inside(&p) { 0.0 } else { scalar.sqrt() };
                proptest::prop_assert_eq!(local.distance(&map, &p).to_bits(), expected.to_bits());
            }
        }
    }

    #[test]
    fn local_map_agrees_with_global_distance() {
        let wall = Obstacle::Wall(vec2(-3.0, 2.0), vec2(3.0, 2.0));
        let map = StaticMap::new(vec![square(), wall]).expect("valid map");
        let mut local = LocalMap::default();
        map.gather(vec2(-2.0, -2.0), vec2(2.0, 2.0), 3.0, &mut local);
        assert_eq!(
            local.segments().len(),
            5,
            "wall counted once, square's four edges"
        );
        for p in [
            vec2(0.5, 0.5),
            vec2(-1.0, 0.3),
            vec2(0.2, 1.7),
            vec2(1.5, -0.5),
        ] {
            assert!(
                (local.distance(&map, &p) - map.distance(&p)).abs() < 1e-12,
                "at {p:?}"
            );
        }
        assert_eq!(map.boundary_segments().count(), 5);
    }
}
