//! Optimal Reciprocal Collision Avoidance (van den Berg et al., "Reciprocal n-body collision
//! avoidance", 2011), ported line by line from RVO2 2.0 (`Agent::computeNewVelocity`,
//! `linearProgram1..3`), including its static-obstacle handling.
//!
//! The solver is generic over the float type so that it can run in `f32` with RVO2's exact
//! operation order (RVO2 computes in `float`, and divides a vector by multiplying with the
//! reciprocal); the cross-check against RVO2 relies on that. Planners use `f64`.

use crate::map::StaticMap;
use crate::math::{Real, Vec2};
use std::ops::{Add, Div, Mul, Neg, Sub};

/// The float operations the port needs; implemented for `f32` and `f64`.
pub trait Float:
    Copy
    + PartialOrd
    + std::fmt::Debug
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// Converts from `f64` (rounding to nearest).
    fn of(x: f64) -> Self;
    /// Converts to `f64`.
    fn to_f64(self) -> f64;
    /// Square root.
    fn sqrt(self) -> Self;
    /// Absolute value.
    fn abs(self) -> Self;
    /// Positive infinity.
    fn infinity() -> Self;
}

macro_rules! impl_float {
    ($t:ty) => {
        impl Float for $t {
            #[inline]
            fn of(x: f64) -> Self {
                x as $t
            }
            #[inline]
            fn to_f64(self) -> f64 {
                self as f64
            }
            #[inline]
            fn sqrt(self) -> Self {
                <$t>::sqrt(self)
            }
            #[inline]
            fn abs(self) -> Self {
                <$t>::abs(self)
            }
            #[inline]
            fn infinity() -> Self {
                <$t>::INFINITY
            }
        }
    };
}
impl_float!(f32);
impl_float!(f64);

/// RVO2's `Vector2`, generic over the float type, with RVO2's exact arithmetic.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct V<T> {
    /// x component.
    pub x: T,
    /// y component.
    pub y: T,
}

impl<T: Float> V<T> {
    /// Constructor.
    #[inline]
    pub fn new(x: T, y: T) -> Self {
        Self { x, y }
    }
    /// From a planner vector.
    #[inline]
    pub fn from_vec2(v: &Vec2) -> Self {
        Self::new(T::of(v.x), T::of(v.y))
    }
    /// To a planner vector.
    #[inline]
    pub fn to_vec2(self) -> Vec2 {
        Vec2::new(self.x.to_f64(), self.y.to_f64())
    }
    #[inline]
    fn zero() -> Self {
        Self::new(T::of(0.0), T::of(0.0))
    }
    /// Dot product (`operator*` between vectors in RVO2).
    #[inline]
    fn dot(self, o: Self) -> T {
        self.x * o.x + self.y * o.y
    }
    #[inline]
    fn scale(self, s: T) -> Self {
        Self::new(self.x * s, self.y * s)
    }
    /// RVO2's `operator/`: multiply by the reciprocal.
    #[inline]
    fn div(self, s: T) -> Self {
        let inv = T::of(1.0) / s;
        Self::new(self.x * inv, self.y * inv)
    }
}

impl<T: Float> Add for V<T> {
    type Output = Self;
    #[inline]
    fn add(self, o: Self) -> Self {
        Self::new(self.x + o.x, self.y + o.y)
    }
}
impl<T: Float> Sub for V<T> {
    type Output = Self;
    #[inline]
    fn sub(self, o: Self) -> Self {
        Self::new(self.x - o.x, self.y - o.y)
    }
}
impl<T: Float> Neg for V<T> {
    type Output = Self;
    #[inline]
    fn neg(self) -> Self {
        Self::new(-self.x, -self.y)
    }
}

#[inline]
fn abs_sq<T: Float>(v: V<T>) -> T {
    v.dot(v)
}
#[inline]
fn abs<T: Float>(v: V<T>) -> T {
    v.dot(v).sqrt()
}
#[inline]
fn det<T: Float>(a: V<T>, b: V<T>) -> T {
    a.x * b.y - a.y * b.x
}
#[inline]
fn normalize<T: Float>(v: V<T>) -> V<T> {
    v.div(abs(v))
}
#[inline]
fn sqr<T: Float>(a: T) -> T {
    a * a
}
#[inline]
fn left_of<T: Float>(a: V<T>, b: V<T>, c: V<T>) -> T {
    det(a - c, b - a)
}
fn dist_sq_point_line_segment<T: Float>(a: V<T>, b: V<T>, c: V<T>) -> T {
    let r = (c - a).dot(b - a) / abs_sq(b - a);
    if r < T::of(0.0) {
        abs_sq(c - a)
    } else if r > T::of(1.0) {
        abs_sq(c - b)
    } else {
        abs_sq(c - (a + (b - a).scale(r)))
    }
}

const RVO_EPSILON: f64 = 0.00001;

/// ORCA's parameters; `Default` gives the PGP paper's Table I.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrcaParams {
    /// Neighbours farther than this are ignored (m).
    pub neighbor_dist: Real,
    /// At most this many nearest neighbours are considered.
    pub max_neighbors: usize,
    /// τ: time horizon against other agents (s).
    pub time_horizon: Real,
    /// Time horizon against static obstacles (s).
    pub time_horizon_obst: Real,
    /// Maximum speed (m/s).
    pub max_speed: Real,
    /// Time step of the velocity update (s), used when bodies already overlap.
    pub time_step: Real,
}

impl Default for OrcaParams {
    /// Table I: t^plan = 2.5 s, dt = 0.25 s, v^max = 1 m/s, d^neighbor = 4 m, n^neighbors = 5.
    /// The paper gives one horizon; we use it for obstacles too.
    fn default() -> Self {
        Self {
            neighbor_dist: 4.0,
            max_neighbors: 5,
            time_horizon: 2.5,
            time_horizon_obst: 2.5,
            max_speed: 1.0,
            time_step: 0.25,
        }
    }
}

/// A body as ORCA sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Body<T> {
    /// Position.
    pub position: V<T>,
    /// Current velocity.
    pub velocity: V<T>,
    /// Radius.
    pub radius: T,
    /// The ego's share of avoiding this body: RVO2's ½ when both follow ORCA (the default
    /// everywhere, and what the cross-check with RVO2 uses); 1 for a body that does not
    /// avoid at all.
    pub responsibility: T,
}

/// A half-plane constraint: velocities to the left of the directed line are allowed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Line<T> {
    /// A point on the line.
    pub point: V<T>,
    /// Unit direction of the line.
    pub direction: V<T>,
}

/// An ORCA solver with its reusable buffers.
#[derive(Debug, Clone, Default)]
pub struct Orca<T = f64> {
    params: OrcaParams,
    lines: Vec<Line<T>>,
    proj_lines: Vec<Line<T>>,
    agent_neighbors: Vec<(T, usize)>,
    obstacle_neighbors: Vec<(T, usize)>,
    edges: Vec<u32>,
    feasible: bool,
}

impl<T: Float> Orca<T> {
    /// A solver with the given parameters.
    pub fn new(params: OrcaParams) -> Self {
        Self {
            params,
            lines: Vec::new(),
            proj_lines: Vec::new(),
            agent_neighbors: Vec::new(),
            obstacle_neighbors: Vec::new(),
            edges: Vec::new(),
            feasible: true,
        }
    }

    /// Whether the last computation satisfied every constraint (no fall-back to the
    /// least-violation program).
    pub fn last_was_feasible(&self) -> bool {
        self.feasible
    }

    /// The parameters in use.
    pub fn params(&self) -> &OrcaParams {
        &self.params
    }

    /// The ORCA lines of the last computation (obstacle lines first), for debugging.
    pub fn lines(&self) -> &[Line<T>] {
        &self.lines
    }

    /// The new velocity for `ego`, which prefers `pref_velocity`, among `others` (candidates;
    /// the nearest `max_neighbors` within `neighbor_dist` are used, RVO2's insertion order)
    /// and the obstacles of `map`.
    pub fn new_velocity(
        &mut self,
        ego: &Body<T>,
        pref_velocity: V<T>,
        others: &[Body<T>],
        map: &StaticMap,
    ) -> V<T> {
        self.compute_obstacle_neighbors(ego, map);
        self.compute_agent_neighbors(ego, others);
        self.lines.clear();
        self.add_obstacle_lines(ego, map);
        let num_obst_lines = self.lines.len();
        self.add_agent_lines(ego, others);
        let max_speed = T::of(self.params.max_speed);
        let mut result = V::zero();
        let line_fail = linear_program2(&self.lines, max_speed, pref_velocity, false, &mut result);
        self.feasible = line_fail == self.lines.len();
        if line_fail < self.lines.len() {
            linear_program3(
                &self.lines,
                &mut self.proj_lines,
                num_obst_lines,
                line_fail,
                max_speed,
                &mut result,
            );
        }
        result
    }

    /// `Agent::insertAgentNeighbor` over all candidates in order.
    fn compute_agent_neighbors(&mut self, ego: &Body<T>, others: &[Body<T>]) {
        self.agent_neighbors.clear();
        let max = self.params.max_neighbors;
        if max == 0 {
            return;
        }
        let mut range_sq = sqr(T::of(self.params.neighbor_dist));
        for (index, other) in others.iter().enumerate() {
            let dist_sq = abs_sq(ego.position - other.position);
            if dist_sq < range_sq {
                if self.agent_neighbors.len() < max {
                    self.agent_neighbors.push((dist_sq, index));
                }
                let mut i = self.agent_neighbors.len() - 1;
                while i != 0 && dist_sq < self.agent_neighbors[i - 1].0 {
                    self.agent_neighbors[i] = self.agent_neighbors[i - 1];
                    i -= 1;
                }
                self.agent_neighbors[i] = (dist_sq, index);
                if self.agent_neighbors.len() == max {
                    range_sq = self.agent_neighbors[max - 1].0;
                }
            }
        }
    }

    /// `KdTree::computeObstacleNeighbors`: edges the agent is right of (outside), in range,
    /// sorted by distance.
    fn compute_obstacle_neighbors(&mut self, ego: &Body<T>, map: &StaticMap) {
        self.obstacle_neighbors.clear();
        if map.is_empty() {
            return;
        }
        let range = self.params.time_horizon_obst * self.params.max_speed + ego.radius.to_f64();
        let range_sq = sqr(T::of(range));
        let p = ego.position.to_vec2();
        self.edges.clear();
        map.edges_near_box(p, p, range, &mut self.edges);
        self.edges.sort_unstable();
        let vertices = map.vertices();
        for &e in &self.edges {
            let v1 = &vertices[e as usize];
            let a = V::from_vec2(&v1.point);
            let b = V::from_vec2(&vertices[v1.next].point);
            let agent_left_of_line = left_of(a, b, ego.position);
            if agent_left_of_line >= T::of(0.0) {
                continue;
            }
            let dist_sq = dist_sq_point_line_segment(a, b, ego.position);
            if dist_sq < range_sq {
                self.obstacle_neighbors.push((dist_sq, e as usize));
                let mut i = self.obstacle_neighbors.len() - 1;
                while i != 0 && dist_sq < self.obstacle_neighbors[i - 1].0 {
                    self.obstacle_neighbors[i] = self.obstacle_neighbors[i - 1];
                    i -= 1;
                }
                self.obstacle_neighbors[i] = (dist_sq, e as usize);
            }
        }
    }

    fn add_obstacle_lines(&mut self, ego: &Body<T>, map: &StaticMap) {
        let zero = T::of(0.0);
        let one = T::of(1.0);
        let eps = T::of(RVO_EPSILON);
        let verts = map.vertices();
        let point = |i: usize| V::<T>::from_vec2(&verts[i].point);
        let unit_dir = |i: usize| normalize(point(verts[i].next) - point(i));
        let radius = ego.radius;
        let position = ego.position;
        let velocity = ego.velocity;
        let inv_time_horizon_obst = one / T::of(self.params.time_horizon_obst);

        for n in 0..self.obstacle_neighbors.len() {
            let mut obstacle1 = self.obstacle_neighbors[n].1;
            let mut obstacle2 = verts[obstacle1].next;
            let relative_position1 = point(obstacle1) - position;
            let relative_position2 = point(obstacle2) - position;

            // Already covered by a previous obstacle's line?
            let already_covered = self.lines.iter().any(|l| {
                det(
                    relative_position1.scale(inv_time_horizon_obst) - l.point,
                    l.direction,
                ) - inv_time_horizon_obst * radius
                    >= -eps
                    && det(
                        relative_position2.scale(inv_time_horizon_obst) - l.point,
                        l.direction,
                    ) - inv_time_horizon_obst * radius
                        >= -eps
            });
            if already_covered {
                continue;
            }

            let dist_sq1 = abs_sq(relative_position1);
            let dist_sq2 = abs_sq(relative_position2);
            let radius_sq = sqr(radius);
            let obstacle_vector = point(obstacle2) - point(obstacle1);
            let s = (-relative_position1).dot(obstacle_vector) / abs_sq(obstacle_vector);
            let dist_sq_line = abs_sq(-relative_position1 - obstacle_vector.scale(s));

            let origin = V::zero();
            if s < zero && dist_sq1 <= radius_sq {
                // Collision with left vertex.
                if verts[obstacle1].convex {
                    let direction = normalize(V::new(-relative_position1.y, relative_position1.x));
                    self.lines.push(Line {
                        point: origin,
                        direction,
                    });
                }
                continue;
            } else if s > one && dist_sq2 <= radius_sq {
                // Collision with right vertex.
                if verts[obstacle2].convex && det(relative_position2, unit_dir(obstacle2)) >= zero {
                    let direction = normalize(V::new(-relative_position2.y, relative_position2.x));
                    self.lines.push(Line {
                        point: origin,
                        direction,
                    });
                }
                continue;
            } else if s >= zero && s < one && dist_sq_line <= radius_sq {
                // Collision with the obstacle segment.
                self.lines.push(Line {
                    point: origin,
                    direction: -unit_dir(obstacle1),
                });
                continue;
            }

            // No collision: compute the legs.
            let mut left_leg_direction;
            let mut right_leg_direction;
            let legs_from = |rel: V<T>, dist_sq: T| {
                let leg = (dist_sq - radius_sq).sqrt();
                let left =
                    V::new(rel.x * leg - rel.y * radius, rel.x * radius + rel.y * leg).div(dist_sq);
                let right = V::new(rel.x * leg + rel.y * radius, -rel.x * radius + rel.y * leg)
                    .div(dist_sq);
                (left, right)
            };
            if s < zero && dist_sq_line <= radius_sq {
                // Obliquely viewed: both legs from the left vertex.
                if !verts[obstacle1].convex {
                    continue;
                }
                obstacle2 = obstacle1;
                (left_leg_direction, right_leg_direction) = legs_from(relative_position1, dist_sq1);
            } else if s > one && dist_sq_line <= radius_sq {
                // Obliquely viewed: both legs from the right vertex.
                if !verts[obstacle2].convex {
                    continue;
                }
                obstacle1 = obstacle2;
                (left_leg_direction, right_leg_direction) = legs_from(relative_position2, dist_sq2);
            } else {
                left_leg_direction = if verts[obstacle1].convex {
                    legs_from(relative_position1, dist_sq1).0
                } else {
                    -unit_dir(obstacle1)
                };
                right_leg_direction = if verts[obstacle2].convex {
                    legs_from(relative_position2, dist_sq2).1
                } else {
                    unit_dir(obstacle1)
                };
            }

            // Legs pointing into a neighbouring edge are replaced by that edge ("foreign").
            let left_neighbor = verts[obstacle1].prev;
            let mut is_left_leg_foreign = false;
            let mut is_right_leg_foreign = false;
            if verts[obstacle1].convex && det(left_leg_direction, -unit_dir(left_neighbor)) >= zero
            {
                left_leg_direction = -unit_dir(left_neighbor);
                is_left_leg_foreign = true;
            }
            if verts[obstacle2].convex && det(right_leg_direction, unit_dir(obstacle2)) <= zero {
                right_leg_direction = unit_dir(obstacle2);
                is_right_leg_foreign = true;
            }

            // Project the current velocity on the velocity obstacle.
            let left_cutoff = (point(obstacle1) - position).scale(inv_time_horizon_obst);
            let right_cutoff = (point(obstacle2) - position).scale(inv_time_horizon_obst);
            let cutoff_vec = right_cutoff - left_cutoff;
            let t = if obstacle1 == obstacle2 {
                T::of(0.5)
            } else {
                (velocity - left_cutoff).dot(cutoff_vec) / abs_sq(cutoff_vec)
            };
            let t_left = (velocity - left_cutoff).dot(left_leg_direction);
            let t_right = (velocity - right_cutoff).dot(right_leg_direction);

            if (t < zero && t_left < zero)
                || (obstacle1 == obstacle2 && t_left < zero && t_right < zero)
            {
                // Project on the left cut-off circle.
                let unit_w = normalize(velocity - left_cutoff);
                let direction = V::new(unit_w.y, -unit_w.x);
                let point = left_cutoff + unit_w.scale(radius * inv_time_horizon_obst);
                self.lines.push(Line { point, direction });
                continue;
            } else if t > one && t_right < zero {
                // Project on the right cut-off circle.
                let unit_w = normalize(velocity - right_cutoff);
                let direction = V::new(unit_w.y, -unit_w.x);
                let point = right_cutoff + unit_w.scale(radius * inv_time_horizon_obst);
                self.lines.push(Line { point, direction });
                continue;
            }

            // Project on the left leg, right leg or cut-off line, whichever is closest.
            let inf = T::infinity();
            let dist_sq_cutoff = if t < zero || t > one || obstacle1 == obstacle2 {
                inf
            } else {
                abs_sq(velocity - (left_cutoff + cutoff_vec.scale(t)))
            };
            let dist_sq_left = if t_left < zero {
                inf
            } else {
                abs_sq(velocity - (left_cutoff + left_leg_direction.scale(t_left)))
            };
            let dist_sq_right = if t_right < zero {
                inf
            } else {
                abs_sq(velocity - (right_cutoff + right_leg_direction.scale(t_right)))
            };

            let offset = |d: V<T>| V::new(-d.y, d.x).scale(radius * inv_time_horizon_obst);
            if dist_sq_cutoff <= dist_sq_left && dist_sq_cutoff <= dist_sq_right {
                let direction = -unit_dir(obstacle1);
                self.lines.push(Line {
                    point: left_cutoff + offset(direction),
                    direction,
                });
            } else if dist_sq_left <= dist_sq_right {
                if is_left_leg_foreign {
                    continue;
                }
                let direction = left_leg_direction;
                self.lines.push(Line {
                    point: left_cutoff + offset(direction),
                    direction,
                });
            } else {
                if is_right_leg_foreign {
                    continue;
                }
                let direction = -right_leg_direction;
                self.lines.push(Line {
                    point: right_cutoff + offset(direction),
                    direction,
                });
            }
        }
    }

    fn add_agent_lines(&mut self, ego: &Body<T>, others: &[Body<T>]) {
        let one = T::of(1.0);
        let zero = T::of(0.0);
        let inv_time_horizon = one / T::of(self.params.time_horizon);
        for &(_, index) in &self.agent_neighbors {
            let other = &others[index];
            let relative_position = other.position - ego.position;
            let relative_velocity = ego.velocity - other.velocity;
            let dist_sq = abs_sq(relative_position);
            let combined_radius = ego.radius + other.radius;
            let combined_radius_sq = sqr(combined_radius);
            let direction;
            let u;
            if dist_sq > combined_radius_sq {
                // No collision.
                let w = relative_velocity - relative_position.scale(inv_time_horizon);
                let w_length_sq = abs_sq(w);
                let dot_product1 = w.dot(relative_position);
                if dot_product1 < zero && sqr(dot_product1) > combined_radius_sq * w_length_sq {
                    // Project on the cut-off circle.
                    let w_length = w_length_sq.sqrt();
                    let unit_w = w.div(w_length);
                    direction = V::new(unit_w.y, -unit_w.x);
                    u = unit_w.scale(combined_radius * inv_time_horizon - w_length);
                } else {
                    // Project on the legs.
                    let leg = (dist_sq - combined_radius_sq).sqrt();
                    let (rx, ry) = (relative_position.x, relative_position.y);
                    direction = if det(relative_position, w) > zero {
                        V::new(
                            rx * leg - ry * combined_radius,
                            rx * combined_radius + ry * leg,
                        )
                        .div(dist_sq)
                    } else {
                        -V::new(
                            rx * leg + ry * combined_radius,
                            -rx * combined_radius + ry * leg,
                        )
                        .div(dist_sq)
                    };
                    let dot_product2 = relative_velocity.dot(direction);
                    u = direction.scale(dot_product2) - relative_velocity;
                }
            } else {
                // Collision: project on the cut-off circle of the time step.
                let inv_time_step = one / T::of(self.params.time_step);
                let w = relative_velocity - relative_position.scale(inv_time_step);
                let w_length = abs(w);
                let unit_w = w.div(w_length);
                direction = V::new(unit_w.y, -unit_w.x);
                u = unit_w.scale(combined_radius * inv_time_step - w_length);
            }
            let point = ego.velocity + u.scale(other.responsibility);
            self.lines.push(Line { point, direction });
        }
    }
}

/// Solves a one-dimensional LP on line `line_no` subject to the lines before it and the
/// speed circle.
fn linear_program1<T: Float>(
    lines: &[Line<T>],
    line_no: usize,
    radius: T,
    opt_velocity: V<T>,
    direction_opt: bool,
    result: &mut V<T>,
) -> bool {
    let zero = T::of(0.0);
    let line = &lines[line_no];
    let dot_product = line.point.dot(line.direction);
    let discriminant = sqr(dot_product) + sqr(radius) - abs_sq(line.point);
    if discriminant < zero {
        // The speed circle fully invalidates this line.
        return false;
    }
    let sqrt_discriminant = discriminant.sqrt();
    let mut t_left = -dot_product - sqrt_discriminant;
    let mut t_right = -dot_product + sqrt_discriminant;
    for other in &lines[..line_no] {
        let denominator = det(line.direction, other.direction);
        let numerator = det(other.direction, line.point - other.point);
        if denominator.abs() <= T::of(RVO_EPSILON) {
            // Lines are (almost) parallel.
            if numerator < zero {
                return false;
            }
            continue;
        }
        let t = numerator / denominator;
        if denominator >= zero {
            // Line bounds on the right.
            if t < t_right {
                t_right = t;
            }
        } else if t > t_left {
            // Line bounds on the left.
            t_left = t;
        }
        if t_left > t_right {
            return false;
        }
    }
    *result = if direction_opt {
        if opt_velocity.dot(line.direction) > zero {
            line.point + line.direction.scale(t_right)
        } else {
            line.point + line.direction.scale(t_left)
        }
    } else {
        let t = line.direction.dot(opt_velocity - line.point);
        if t < t_left {
            line.point + line.direction.scale(t_left)
        } else if t > t_right {
            line.point + line.direction.scale(t_right)
        } else {
            line.point + line.direction.scale(t)
        }
    };
    true
}

/// Solves the two-dimensional LP; returns the index of the first line that failed, or
/// `lines.len()` on success.
fn linear_program2<T: Float>(
    lines: &[Line<T>],
    radius: T,
    opt_velocity: V<T>,
    direction_opt: bool,
    result: &mut V<T>,
) -> usize {
    if direction_opt {
        *result = opt_velocity.scale(radius);
    } else if abs_sq(opt_velocity) > sqr(radius) {
        *result = normalize(opt_velocity).scale(radius);
    } else {
        *result = opt_velocity;
    }
    for i in 0..lines.len() {
        if det(lines[i].direction, lines[i].point - *result) > T::of(0.0) {
            // The result does not satisfy constraint i: compute a new optimum.
            let temp_result = *result;
            if !linear_program1(lines, i, radius, opt_velocity, direction_opt, result) {
                *result = temp_result;
                return i;
            }
        }
    }
    lines.len()
}

/// Infeasible case: minimises the largest violation of the agent constraints while keeping
/// the obstacle constraints hard.
fn linear_program3<T: Float>(
    lines: &[Line<T>],
    proj_lines: &mut Vec<Line<T>>,
    num_obst_lines: usize,
    begin_line: usize,
    radius: T,
    result: &mut V<T>,
) {
    let zero = T::of(0.0);
    let mut distance = zero;
    for i in begin_line..lines.len() {
        if det(lines[i].direction, lines[i].point - *result) > distance {
            proj_lines.clear();
            proj_lines.extend_from_slice(&lines[..num_obst_lines]);
            for j in num_obst_lines..i {
                let determinant = det(lines[i].direction, lines[j].direction);
                let point = if determinant.abs() <= T::of(RVO_EPSILON) {
                    // Parallel lines.
                    if lines[i].direction.dot(lines[j].direction) > zero {
                        // Same direction.
                        continue;
                    }
                    // Opposite direction.
                    (lines[i].point + lines[j].point).scale(T::of(0.5))
                } else {
                    lines[i].point
                        + lines[i].direction.scale(
                            det(lines[j].direction, lines[i].point - lines[j].point) / determinant,
                        )
                };
                let direction = normalize(lines[j].direction - lines[i].direction);
                proj_lines.push(Line { point, direction });
            }
            let temp_result = *result;
            let opt = V::new(-lines[i].direction.y, lines[i].direction.x);
            if linear_program2(proj_lines, radius, opt, true, result) < proj_lines.len() {
                // Can in principle only happen through numerical error; keep the old result.
                *result = temp_result;
            }
            distance = det(lines[i].direction, lines[i].point - *result);
        }
    }
}

#[cfg(test)]
mod tests;
