//! The Social Force Model as PySocialForce 1.1.2 implements it (Helbing & Molnár 1995 with
//! Moussaïd et al.'s 2009 interaction force and 2010 group forces): desired, social, obstacle,
//! group coherence, group repulsion and group gaze forces, and its velocity update.
//!
//! One implementation serves the simulated humans ([`Crowd`], used by world-sim) and the
//! Social Force planner ([`SocialForceAgent`]). The arithmetic follows PySocialForce's, quirks
//! included, because trajectories are cross-checked against it:
//! - the interaction angle θ is the plain difference of two `atan2` angles, not wrapped;
//! - walls act through points sampled along them (`resolution` per metre, end points
//!   included), each point within range pushing on its own;
//! - the desired force pulls towards `max_speed` (1.3 × the initial speed by default);
//! - an agent closer than 0.5 m to its goal stops.

use crate::fastmath;
use crate::grid::PointGrid;
use crate::map::StaticMap;
use crate::math::{Real, Vec2, left_normal, vec2};
use crate::model::{EgoState, Neighbour};

/// `[desired_force]`
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DesiredForceParams {
    /// Weight.
    pub factor: Real,
    /// Relaxation time (s).
    pub relaxation_time: Real,
    /// Closer than this to the goal (m), the force only brakes.
    pub goal_threshold: Real,
}

/// `[social_force]`: Moussaïd et al. 2009.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SocialForceParams {
    /// A: weight.
    pub factor: Real,
    /// λ: weight of the relative velocity in the interaction direction.
    pub lambda_importance: Real,
    /// γ: B = γ·‖D‖.
    pub gamma: Real,
    /// n: angular decay of the sideways force.
    pub n: Real,
    /// n′: angular decay of the deceleration force.
    pub n_prime: Real,
}

/// `[obstacle_force]`
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObstacleForceParams {
    /// Weight.
    pub factor: Real,
    /// Decay length (m).
    pub sigma: Real,
    /// Range beyond the body radius (m).
    pub threshold: Real,
}

/// `[group_repulsive_force]`
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GroupRepulsiveParams {
    /// Weight.
    pub factor: Real,
    /// Members closer than this push apart (m).
    pub threshold: Real,
}

/// All of PySocialForce's parameters; `Default` is what PySocialForce 1.1.2 uses with its
/// `default.toml`, except `step_width`. (Its `PedState` reads `step_width`, `agent_radius` and
/// `max_speed_multiplier` from the top level of the config while `default.toml` puts them
/// under `[scene]`, so its effective step is the code default of 0.4 s; ours is the
/// simulation step, 0.1 s by default.)
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SfParams {
    /// Integration step (s).
    pub step_width: Real,
    /// Body radius used by the obstacle force (m).
    pub agent_radius: Real,
    /// Maximum speed = this × initial (preferred) speed.
    pub max_speed_multiplier: Real,
    /// Obstacle sampling points per metre.
    pub resolution: Real,
    /// Whether the three group forces act.
    pub enable_group: bool,
    /// Desired force.
    pub desired: DesiredForceParams,
    /// Pedestrian interaction force.
    pub social: SocialForceParams,
    /// Obstacle force.
    pub obstacle: ObstacleForceParams,
    /// Group coherence weight (alternative, pedsim_ros form).
    pub group_coherence_factor: Real,
    /// Group repulsion.
    pub group_repulsive: GroupRepulsiveParams,
    /// Group gaze weight (alternative form).
    pub group_gaze_factor: Real,
    /// An agent closer than this to its goal stops (m).
    pub arrival_distance: Real,
    /// `None`: every pair interacts, as in PySocialForce (O(N²)). `Some(r)`: only pairs
    /// closer than r (m), found through a grid (O(N)); for large crowds. Not a PySocialForce
    /// parameter.
    pub interaction_range: Option<Real>,
}

impl Default for SfParams {
    fn default() -> Self {
        Self {
            step_width: 0.1,
            agent_radius: 0.35,
            max_speed_multiplier: 1.3,
            resolution: 10.0,
            enable_group: true,
            desired: DesiredForceParams {
                factor: 1.0,
                relaxation_time: 0.5,
                goal_threshold: 0.2,
            },
            social: SocialForceParams {
                factor: 5.1,
                lambda_importance: 2.0,
                gamma: 0.35,
                n: 2.0,
                n_prime: 3.0,
            },
            obstacle: ObstacleForceParams {
                factor: 10.0,
                sigma: 0.2,
                threshold: 3.0,
            },
            // PySocialForce looks a force's section up by its class name: the Alt group forces
            // it uses read `[group_coherence_force_alt]` and `[group_gaze_force_alt]`, which
            // default.toml does not have, so they act with factor 1.0, not its 3.0 and 4.0.
            group_coherence_factor: 1.0,
            group_repulsive: GroupRepulsiveParams {
                factor: 1.0,
                threshold: 0.55,
            },
            group_gaze_factor: 1.0,
            arrival_distance: 0.5,
            interaction_range: None,
        }
    }
}

/// `stateutils.normalize` for one vector: the unit vector and the norm, zero for zero. It
/// multiplies by 1/‖v‖ where numpy divides (one division instead of two; 1 ulp apart).
#[inline(always)]
fn normalize(v: Vec2) -> (Vec2, Real) {
    let n = v.norm();
    if n == 0.0 {
        (vec2(0.0, 0.0), 0.0)
    } else {
        (v * (1.0 / n), n)
    }
}

/// `DesiredForce`: relax towards `max_speed` along the direction to `goal`.
#[inline(always)]
pub fn desired_force(
    pos: Vec2,
    vel: Vec2,
    goal: Vec2,
    max_speed: Real,
    p: &DesiredForceParams,
) -> Vec2 {
    let (direction, dist) = normalize(goal - pos);
    let f = if dist > p.goal_threshold {
        direction * max_speed - vel
    } else {
        -vel
    };
    f / p.relaxation_time * p.factor
}

/// `SocialForce` exerted on `a` by `b` (without the overall factor). Straight-line code
/// (`exp` and `atan2` from [`fastmath`], selects for PySocialForce's special cases) so that
/// the crowd's loops over it vectorise.
#[inline(always)]
pub fn social_force_pair(
    pos_a: Vec2,
    vel_a: Vec2,
    pos_b: Vec2,
    vel_b: Vec2,
    p: &SocialForceParams,
) -> Vec2 {
    // The reaction is dead code here and is not computed.
    mutual_social_forces(pos_a, vel_a, pos_b, vel_b, p).0
}

/// The social forces of a pair on each other: on `a` by `b`, and on `b` by `a`.
///
/// Exchanging a and b negates D (the normalised position difference plus λ times the velocity
/// difference) and e (the direction between them) exactly, and keeps ‖D‖, B, and the angle w
/// from e to D. Only θ can differ, by ±2π, where PySocialForce's unwrapped difference of two
/// `atan2` angles jumps (see [`pysf_theta`]). So the pair shares two square roots, three
/// divisions and the arctangent, and each side pays for its two exponentials. Where θ is the
/// same both ways, the reaction is exactly minus the action.
///
/// The reaction is exactly [`social_force_pair`]`(pos_b, vel_b, pos_a, vel_a, p)` whenever
/// the two positions differ. For coincident positions (e = 0), θ is measured from the x axis
/// instead, which w does not give; callers recompute that case with [`social_force_pair`].
#[inline(always)]
fn mutual_social_forces(
    pos_a: Vec2,
    vel_a: Vec2,
    pos_b: Vec2,
    vel_b: Vec2,
    p: &SocialForceParams,
) -> (Vec2, Vec2) {
    let (diff_direction, diff_length) = normalize(pos_a - pos_b);
    let vel_diff = vel_b - vel_a;
    let (interaction_direction, interaction_length) =
        normalize(vel_diff * p.lambda_importance + diff_direction);
    let b = p.gamma * interaction_length;
    let w = pysf_angle(diff_direction, interaction_direction);
    let decay = -diff_length / b;
    let normal = left_normal(&interaction_direction);
    let theta_a = pysf_wrap(w, diff_direction, interaction_direction);
    let (velocity_on_a, angle_on_a) = force_amounts(decay, b, theta_a, p);
    let theta_b = pysf_wrap(w, -diff_direction, -interaction_direction);
    let (velocity_on_b, angle_on_b) = force_amounts(decay, b, theta_b, p);
    let on_a = interaction_direction * velocity_on_a + normal * angle_on_a;
    let on_b = -(interaction_direction * velocity_on_b + normal * angle_on_b);
    // PySocialForce divides by B = 0 when ‖D‖ = 0; numpy's exp(−inf) makes the force zero.
    if b == 0.0 {
        (vec2(0.0, 0.0), vec2(0.0, 0.0))
    } else {
        (on_a, on_b)
    }
}

/// The deceleration and sideways amounts of the social force for e^(−d/B) = e^`decay`, B and
/// θ (a plain function, not a closure, so that it is compiled into the vectorised loops).
#[inline(always)]
fn force_amounts(decay: Real, b: Real, theta: Real, p: &SocialForceParams) -> (Real, Real) {
    let velocity_amount = fastmath::exp(decay - (p.n_prime * b * theta).powi(2));
    let sign = if theta > 0.0 {
        1.0
    } else if theta < 0.0 {
        -1.0
    } else {
        0.0
    };
    let angle_amount = -sign * fastmath::exp(decay - (p.n * b * theta).powi(2));
    (velocity_amount, angle_amount)
}

/// θ = atan2(i) − atan2(e), not wrapped into (−π, π], as PySocialForce computes the
/// interaction angle (`vec_diff_angle`), with one `atan2` instead of two: the angle w from e to
/// i in [−π, π], moved by 2π when the turn from e to i crosses the negative x axis, where the
/// two angles jump (e in the upper half-plane and i in the lower one with w > 0, or the
/// reverse with w < 0; the half-planes are told apart by sign bits, as `atan2` does). For
/// e = 0, `atan2(e)` = 0 and θ = atan2(i); for i = 0, θ = −atan2(e).
#[inline(always)]
pub fn pysf_theta(e: Vec2, i: Vec2) -> Real {
    pysf_wrap(pysf_angle(e, i), e, i)
}

/// The `atan2` of [`pysf_theta`]: the angle w from e to i, or the special cases' angles.
#[inline(always)]
fn pysf_angle(e: Vec2, i: Vec2) -> Real {
    let e_zero = (e.x == 0.0) & (e.y == 0.0);
    let i_zero = (i.x == 0.0) & (i.y == 0.0);
    let (y, x) = if e_zero {
        (i.y, i.x)
    } else if i_zero {
        (-e.y, e.x)
    } else {
        (e.x * i.y - e.y * i.x, e.x * i.x + e.y * i.y)
    };
    fastmath::atan2(y, x)
}

/// The 2π move of [`pysf_theta`], for w = [`pysf_angle`]`(e, i)`.
#[inline(always)]
fn pysf_wrap(w: Real, e: Vec2, i: Vec2) -> Real {
    use std::f64::consts::TAU;
    let (e_lower, i_lower) = (e.y.is_sign_negative(), i.y.is_sign_negative());
    // Parallel vectors on the negative x axis with zeros of opposite sign: π vs −π.
    let on_the_cut = (w == 0.0) & (e.x < 0.0);
    if !e_lower & i_lower & ((w > 0.0) | on_the_cut) {
        w - TAU
    } else if e_lower & !i_lower & ((w < 0.0) | on_the_cut) {
        w + TAU
    } else {
        w
    }
}

// Sums over people and wall points are kept as `LANES` partial sums, item i adding to partial
// sum i mod `LANES`, which are added in a fixed order at the end. The loops then vectorise,
// give the same bits at every vector width, and give the same bits for any superset of the
// items that act (the others add exact zeros).
use fastmath::LANES;

mod wall_field;
pub use wall_field::WallField;

/// `LANES` partial sums of 2-D forces.
#[derive(Debug, Clone, Copy)]
struct Partial {
    x: [Real; LANES],
    y: [Real; LANES],
}

impl Partial {
    const ZERO: Self = Self {
        x: [0.0; LANES],
        y: [0.0; LANES],
    };

    #[inline(always)]
    fn total(&self) -> Vec2 {
        vec2(
            fastmath::lanes_total(&self.x),
            fastmath::lanes_total(&self.y),
        )
    }
}

/// Items per pass of the vectorised loops (a multiple of `LANES`).
const CHUNK: usize = 64;

/// Adds `fx[k]`, `fy[k]` to partial sum k mod `LANES` (lengths are multiples of `LANES`).
#[inline(always)]
fn accumulate(acc: &mut Partial, fx: &[Real], fy: &[Real]) {
    for (x, y) in fx.chunks_exact(LANES).zip(fy.chunks_exact(LANES)) {
        for l in 0..LANES {
            acc.x[l] += x[l];
            acc.y[l] += y[l];
        }
    }
}

/// Positions and velocities of a crowd as columns, and the neighbours of one agent gathered
/// from them: the agents that act, packed, so that the vectorised force loop wastes no lanes.
///
/// Each pair is evaluated once, from its lower column: the agent at column k packs only the
/// columns after k, and what it does to them is added to their `reactions`, which are complete
/// by the time their own turn comes.
#[derive(Debug, Clone, Default)]
struct Columns {
    x: Vec<Real>,
    y: Vec<Real>,
    vx: Vec<Real>,
    vy: Vec<Real>,
    /// The packed neighbours of the agent being summed: positions, velocities, and room to
    /// pack one more item past the last.
    near: [Vec<Real>; 4],
    /// The packed neighbours' columns.
    near_columns: Vec<usize>,
    /// Per column, the social force of the agents at lower columns.
    reactions: Vec<Vec2>,
}

impl Columns {
    /// `positions[order[k]]` and `velocities[order[k]]` at k.
    fn gather(
        &mut self,
        positions: &[Vec2],
        velocities: &[Vec2],
        order: impl Iterator<Item = usize>,
    ) {
        for column in [&mut self.x, &mut self.y, &mut self.vx, &mut self.vy] {
            column.clear();
        }
        for i in order {
            self.x.push(positions[i].x);
            self.y.push(positions[i].y);
            self.vx.push(velocities[i].x);
            self.vy.push(velocities[i].y);
        }
        for column in &mut self.near {
            column.resize(self.x.len() + CHUNK, 0.0);
        }
        self.near_columns.resize(self.x.len() + CHUNK, 0);
        self.reactions.clear();
        self.reactions.resize(self.x.len(), vec2(0.0, 0.0));
    }

    /// Packs every agent in `runs` (ascending, disjoint ranges of columns) closer to `pa` than
    /// √`range_sq`, and returns how many. Branch-free: each candidate is written, and the
    /// count advances only past those that act.
    #[inline(always)]
    fn pack(&mut self, pa: Vec2, runs: &[(usize, usize)], range_sq: Real) -> usize {
        let mut m = 0;
        let [nx, ny, nvx, nvy] = &mut self.near;
        // Plain slices, so that the loop keeps their bounds in registers.
        let (nx, ny, nvx, nvy) = (&mut nx[..], &mut ny[..], &mut nvx[..], &mut nvy[..]);
        let nk = &mut self.near_columns[..];
        for &(lo, hi) in runs {
            let candidates = self.x[lo..hi]
                .iter()
                .zip(&self.y[lo..hi])
                .zip(&self.vx[lo..hi])
                .zip(&self.vy[lo..hi]);
            for (k, (((&x, &y), &vx), &vy)) in (lo..hi).zip(candidates) {
                nx[m] = x;
                ny[m] = y;
                nvx[m] = vx;
                nvy[m] = vy;
                nk[m] = k;
                let (dx, dy) = (x - pa.x, y - pa.y);
                m += usize::from(dx * dx + dy * dy < range_sq);
            }
        }
        m
    }

    /// The social force of the crowd on the agent at `column`, (pa, va), whose `m` neighbours
    /// at later columns are packed: theirs, as partial sums, plus the reactions of the earlier
    /// ones. Each packed neighbour's reaction is added to its entry of `reactions`.
    #[inline(always)]
    fn social(
        &mut self,
        column: usize,
        pa: Vec2,
        va: Vec2,
        m: usize,
        p: &SocialForceParams,
    ) -> Vec2 {
        let mut acc = Partial::ZERO;
        let (mut fx, mut fy) = ([0.0; CHUNK], [0.0; CHUNK]);
        let (mut gx, mut gy) = ([0.0; CHUNK], [0.0; CHUNK]);
        let [nx, ny, nvx, nvy] = &self.near;
        for start in (0..m).step_by(CHUNK) {
            // Whole blocks, so that the loop has no scalar remainder; the items past the
            // packed ones are left-overs, zeroed below.
            let len = (m - start).min(CHUNK);
            let whole = len.div_ceil(LANES) * LANES;
            let columns = nx[start..start + whole]
                .iter()
                .zip(&ny[start..start + whole])
                .zip(&nvx[start..start + whole])
                .zip(&nvy[start..start + whole]);
            let forces = fx
                .iter_mut()
                .zip(fy.iter_mut())
                .zip(gx.iter_mut().zip(&mut gy));
            // Whether some item stands exactly at pa (e = 0 as `normalize` finds it; the
            // left-overs may raise it needlessly, which only costs the check below).
            let mut coincident = false;
            for (((fx, fy), (gx, gy)), (((&x, &y), &vx), &vy)) in forces.zip(columns) {
                coincident |= (pa - vec2(x, y)).norm_squared() == 0.0;
                let (on_a, on_b) = mutual_social_forces(pa, va, vec2(x, y), vec2(vx, vy), p);
                *fx = on_a.x;
                *fy = on_a.y;
                *gx = on_b.x;
                *gy = on_b.y;
            }
            fx[len..whole].fill(0.0);
            fy[len..whole].fill(0.0);
            accumulate(&mut acc, &fx[..whole], &fy[..whole]);
            if coincident {
                // e = 0 (as `normalize` finds it): θ of the reaction is not the shared angle.
                for t in 0..len {
                    let (pb, vb) = (
                        vec2(nx[start + t], ny[start + t]),
                        vec2(nvx[start + t], nvy[start + t]),
                    );
                    if (pa - pb).norm_squared() == 0.0 {
                        let reaction = social_force_pair(pb, vb, pa, va, p);
                        (gx[t], gy[t]) = (reaction.x, reaction.y);
                    }
                }
            }
            let reactions = gx
                .iter()
                .zip(&gy)
                .zip(&self.near_columns[start..start + len]);
            for ((&x, &y), &column) in reactions {
                self.reactions[column] += vec2(x, y);
            }
        }
        acc.total() + self.reactions[column]
    }
}

/// Wall points as PySocialForce samples them: `int(length · resolution)` points from start to
/// end inclusive, per obstacle line. Optionally indexed ([`indexed`](Self::indexed)) so that
/// the obstacle force visits only nearby points; the result is bit-identical to the full scan.
#[derive(Debug, Clone, Default)]
pub struct ObstaclePoints {
    points: Vec<Vec2>,
    /// The points as columns padded with NaN to whole blocks of `LANES`.
    xs: Vec<Real>,
    ys: Vec<Real>,
    index: Option<WallIndex>,
    /// The tabulated potential ([`with_field`](Self::with_field)), used instead of the points
    /// for the radius and parameters it was built for.
    field: Option<std::sync::Arc<WallField>>,
}

impl PartialEq for ObstaclePoints {
    fn eq(&self, other: &Self) -> bool {
        self.points == other.points
    }
}

/// For each cell of a square grid, the blocks of `LANES` points that hold every point within
/// `reach` of the cell, as ascending, disjoint runs of block numbers.
#[derive(Debug, Clone)]
struct WallIndex {
    reach: Real,
    cell: Real,
    min: Vec2,
    cols: usize,
    rows: usize,
    /// `starts[c]..starts[c + 1]` indexes `runs` for cell c.
    starts: Vec<u32>,
    runs: Vec<(u32, u32)>,
}

impl WallIndex {
    /// Cell side (m): smaller cells visit fewer points that do not act but take more memory.
    const CELL: Real = 1.0;

    fn build(points: &[Vec2], reach: Real) -> Self {
        // A little slack so that rounding in a body's distance test cannot drop a point.
        let slack = 1e-9 * (1.0 + reach);
        let cell = Self::CELL;
        let (mut min, mut max) = crate::math::bounds(points);
        let margin = vec2(reach + cell, reach + cell);
        min -= margin;
        max += margin;
        let cols = ((max.x - min.x) / cell) as usize + 1;
        let rows = ((max.y - min.y) / cell) as usize + 1;
        // Per cell, the blocks (ascending, since points are visited in order).
        let mut blocks: Vec<Vec<u32>> = vec![Vec::new(); cols * rows];
        for (i, p) in points.iter().enumerate() {
            let block = (i / LANES) as u32;
            let lo = ((p - min).add_scalar(-reach - slack) / cell).map(|v| v.floor().max(0.0));
            let hi = ((p - min).add_scalar(reach + slack) / cell).map(|v| v.floor());
            for cy in lo.y as usize..=(hi.y as usize).min(rows - 1) {
                for cx in lo.x as usize..=(hi.x as usize).min(cols - 1) {
                    // Distance from p to the cell's square.
                    let corner = min + vec2(cx as Real, cy as Real) * cell;
                    let dx = (corner.x - p.x).max(p.x - (corner.x + cell)).max(0.0);
                    let dy = (corner.y - p.y).max(p.y - (corner.y + cell)).max(0.0);
                    let list = &mut blocks[cy * cols + cx];
                    if dx * dx + dy * dy <= (reach + slack) * (reach + slack)
                        && list.last() != Some(&block)
                    {
                        list.push(block);
                    }
                }
            }
        }
        let mut starts = Vec::with_capacity(blocks.len() + 1);
        let mut runs: Vec<(u32, u32)> = Vec::new();
        for list in &blocks {
            starts.push(runs.len() as u32);
            let first_run = runs.len();
            for &b in list {
                match runs[first_run..].last_mut() {
                    Some(run) if run.1 == b => run.1 = b + 1,
                    _ => runs.push((b, b + 1)),
                }
            }
        }
        starts.push(runs.len() as u32);
        Self {
            reach,
            cell,
            min,
            cols,
            rows,
            starts,
            runs,
        }
    }

    /// The runs of blocks for a body at `pos`; empty when no point is within `reach`.
    #[inline(always)]
    fn runs_at(&self, pos: Vec2) -> &[(u32, u32)] {
        let fx = ((pos.x - self.min.x) / self.cell).floor();
        let fy = ((pos.y - self.min.y) / self.cell).floor();
        // Outside the grid (which extends `reach` beyond every point) nothing acts; NaN too.
        if !(fx >= 0.0 && fy >= 0.0 && fx < self.cols as Real && fy < self.rows as Real) {
            return &[];
        }
        let c = fy as usize * self.cols + fx as usize;
        &self.runs[self.starts[c] as usize..self.starts[c + 1] as usize]
    }
}

impl ObstaclePoints {
    /// Samples the given lines.
    pub fn from_segments(
        segments: impl IntoIterator<Item = (Vec2, Vec2)>,
        resolution: Real,
    ) -> Self {
        let mut points = Vec::new();
        for (a, b) in segments {
            let samples = ((b - a).norm() * resolution) as usize;
            match samples {
                0 => {}
                1 => points.push(a),
                _ => points.extend(
                    (0..samples).map(|i| a + (b - a) * (i as Real / (samples - 1) as Real)),
                ),
            }
        }
        Self::from_points(points)
    }

    /// Points given directly (tests, hand-made scenes).
    pub fn from_points(points: Vec<Vec2>) -> Self {
        let padded = points.len().div_ceil(LANES) * LANES;
        let column = |axis: usize| {
            let mut c: Vec<Real> = points.iter().map(|p| p[axis]).collect();
            c.resize(padded, Real::NAN);
            c
        };
        Self {
            xs: column(0),
            ys: column(1),
            points,
            index: None,
            field: None,
        }
    }

    /// Indexes the points by a grid for bodies on which a point acts only within `reach` of
    /// their centre (PySocialForce's test is `‖pos − o‖ − r < threshold + r`, so that is
    /// `threshold + 2r`): each cell lists the blocks of points within `reach` of it, and a body
    /// visits only those of its cell instead of every point of the map.
    pub fn indexed(mut self, reach: Real) -> Self {
        self.index = Some(WallIndex::build(&self.points, reach));
        self
    }

    /// Tabulates the points' potential for a body of `radius` under `params` on a grid of
    /// `spacing` (m) ([`WallField`]): from then on [`obstacle_force`] for that radius and those
    /// parameters interpolates the table instead of summing the points. A separately named
    /// model (walls = "field"), not PySocialForce's arithmetic; index the points first.
    pub fn with_field(mut self, radius: Real, params: &ObstacleForceParams, spacing: Real) -> Self {
        self.field = Some(std::sync::Arc::new(WallField::build(
            &self, radius, params, spacing,
        )));
        self
    }

    /// The tabulated potential, if [`with_field`](Self::with_field) built one.
    pub fn field(&self) -> Option<&WallField> {
        self.field.as_deref()
    }

    /// Samples every wall and polygon edge of a map.
    pub fn from_map(map: &StaticMap, resolution: Real) -> Self {
        Self::from_segments(map.boundary_segments(), resolution)
    }

    /// The sampled points.
    pub fn points(&self) -> &[Vec2] {
        &self.points
    }

    /// Adds to `acc` the pushes of the points in blocks `blocks.0..blocks.1`.
    #[inline(always)]
    fn add_pushes(
        &self,
        acc: &mut Partial,
        pos: Vec2,
        radius: Real,
        threshold: Real,
        sigma: Real,
        blocks: (u32, u32),
    ) {
        let (mut fx, mut fy) = ([0.0; CHUNK], [0.0; CHUNK]);
        let inv_sigma = 1.0 / sigma;
        let (first, end) = (blocks.0 as usize * LANES, blocks.1 as usize * LANES);
        for start in (first..end).step_by(CHUNK) {
            let len = (end - start).min(CHUNK);
            let points = self.xs[start..start + len]
                .iter()
                .zip(&self.ys[start..start + len]);
            for ((fx, fy), (&x, &y)) in fx.iter_mut().zip(fy.iter_mut()).zip(points) {
                let (dx, dy) = (pos.x - x, pos.y - y);
                let norm = (dx * dx + dy * dy).sqrt();
                let dist = norm - radius;
                // (d / ‖d‖) · e^(−dist/σ) with one division: the divisions, not the
                // exponential, bound this loop.
                let push = fastmath::exp(-dist * inv_sigma) / norm;
                // normalize(): a point at the body's centre has no direction and adds nothing.
                let acts = (dist < threshold) & (norm != 0.0);
                *fx = if acts { dx * push } else { 0.0 };
                *fy = if acts { dy * push } else { 0.0 };
            }
            accumulate(acc, &fx[..len], &fy[..len]);
        }
    }
}

/// `ObstacleForce` on a body at `pos`.
#[inline(always)]
pub fn obstacle_force(
    pos: Vec2,
    obstacles: &ObstaclePoints,
    radius: Real,
    p: &ObstacleForceParams,
) -> Vec2 {
    if let Some(field) = &obstacles.field
        && field.serves(radius, p)
    {
        return field.force(pos, p.factor);
    }
    let threshold = p.threshold + radius;
    let mut acc = Partial::ZERO;
    let all = [(0, (obstacles.xs.len() / LANES) as u32)];
    let runs = match &obstacles.index {
        // Every point that acts (centre distance < threshold + radius) is in the blocks listed
        // for the body's cell; the rest add exact zeros to the same partial sums as in the
        // full scan.
        Some(index) if threshold + radius <= index.reach => index.runs_at(pos),
        _ => &all,
    };
    for &run in runs {
        obstacles.add_pushes(&mut acc, pos, radius, threshold, p.sigma, run);
    }
    acc.total() * p.factor
}

/// `PedState.capped_velocity` for one agent.
#[inline]
pub fn capped_velocity(desired: Vec2, max_speed: Real) -> Vec2 {
    let speed = desired.norm();
    if speed == 0.0 {
        return vec2(0.0, 0.0);
    }
    desired * (max_speed / speed).min(1.0)
}

/// The grids and lists of a force pass with an interaction range.
#[derive(Debug, Clone, Default)]
struct Lookups {
    /// The people, by cell.
    people: PointGrid,
    /// The runs of columns around one person.
    runs: Vec<(usize, usize)>,
    /// The external agents' positions, and the agents by cell.
    external_positions: Vec<Vec2>,
    externals: PointGrid,
    /// The external agents in reach of one person: indices, then the agents.
    near_indices: Vec<u32>,
    near_externals: Vec<(Vec2, Vec2)>,
}

thread_local! {
    /// The crowd's columns and look-ups, reused between steps.
    static SCRATCH: std::cell::RefCell<(Columns, Lookups)> =
        std::cell::RefCell::new(Default::default());
}

/// Every force on every agent but the group forces: [`Crowd::forces_with_externals`] as one
/// operation that `pulp` compiles once per instruction set (everything it calls is inlined).
struct IndividualForces<'a> {
    crowd: &'a Crowd,
    obstacles: &'a ObstaclePoints,
    p: &'a SfParams,
    externals: &'a [(Vec2, Vec2)],
    columns: &'a mut Columns,
    lookups: &'a mut Lookups,
    out: &'a mut [Vec2],
}

impl pulp::WithSimd for IndividualForces<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _: S) {
        let Self {
            crowd,
            obstacles,
            p,
            externals,
            columns,
            lookups,
            out,
        } = self;
        let n = crowd.len();
        match p.interaction_range {
            // PySocialForce: every pair.
            None => {
                columns.gather(&crowd.positions, &crowd.velocities, 0..n);
                for (a, force) in out.iter_mut().enumerate() {
                    let (pa, va) = (crowd.positions[a], crowd.velocities[a]);
                    let m = columns.pack(pa, &[(a + 1, n)], Real::INFINITY);
                    let social = columns.social(a, pa, va, m, &p.social);
                    *force = crowd.force_on(a, social, obstacles, p, externals);
                }
            }
            // Pairs closer than the range: the agents sorted by grid cell, so that the 3 × 3
            // cells around an agent are three runs of consecutive columns.
            Some(range) => {
                let Lookups {
                    people,
                    runs,
                    external_positions,
                    externals: external_grid,
                    near_indices,
                    near_externals,
                } = lookups;
                people.build(&crowd.positions, range);
                let order = people.items();
                columns.gather(
                    &crowd.positions,
                    &crowd.velocities,
                    order.iter().map(|&i| i as usize),
                );
                // The external agents in reach of a person, from a grid of their own, in index
                // order as the full scan adds them (so the bits stay the scan's).
                external_positions.clear();
                external_positions.extend(externals.iter().map(|e| e.0));
                external_grid.build(external_positions, range);
                for (k, &a) in order.iter().enumerate() {
                    let a = a as usize;
                    runs.clear();
                    // Only the columns after k: the pairs with lower ones are done.
                    people.runs_near(crowd.positions[a], |lo, hi| {
                        if hi > k + 1 {
                            runs.push((lo.max(k + 1), hi));
                        }
                    });
                    let (pa, va) = (crowd.positions[a], crowd.velocities[a]);
                    let m = columns.pack(pa, runs, range * range);
                    let social = columns.social(k, pa, va, m, &p.social);
                    near_indices.clear();
                    external_grid.runs_near(pa, |lo, hi| {
                        near_indices.extend_from_slice(&external_grid.items()[lo..hi]);
                    });
                    near_indices.sort_unstable();
                    near_externals.clear();
                    for &i in near_indices.iter() {
                        near_externals.push(externals[i as usize]);
                    }
                    out[a] = crowd.force_on(a, social, obstacles, p, near_externals);
                }
            }
        }
    }
}

/// A crowd simulated exactly as PySocialForce's `Simulator` does.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Crowd {
    /// Positions (m).
    pub positions: Vec<Vec2>,
    /// Velocities (m/s).
    pub velocities: Vec<Vec2>,
    /// Goals.
    pub goals: Vec<Vec2>,
    /// Maximum speeds (m/s): 1.3 × the initial speeds in PySocialForce.
    pub max_speeds: Vec<Real>,
    /// Groups of member indices.
    pub groups: Vec<Vec<usize>>,
}

impl Crowd {
    /// A crowd whose maximum speeds derive from the initial velocities, as in PySocialForce.
    pub fn new(
        positions: Vec<Vec2>,
        velocities: Vec<Vec2>,
        goals: Vec<Vec2>,
        groups: Vec<Vec<usize>>,
        p: &SfParams,
    ) -> Self {
        let max_speeds = velocities
            .iter()
            .map(|v| v.norm() * p.max_speed_multiplier)
            .collect();
        Self {
            positions,
            velocities,
            goals,
            max_speeds,
            groups,
        }
    }

    /// Number of agents.
    pub fn len(&self) -> usize {
        self.positions.len()
    }

    /// True for an empty crowd.
    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }

    /// Sum of all forces on every agent (`Simulator.compute_forces`).
    pub fn forces(&self, obstacles: &ObstaclePoints, p: &SfParams, out: &mut Vec<Vec2>) {
        self.forces_with_externals(obstacles, p, &[], out);
    }

    /// As [`Crowd::forces`], with `externals` (position, velocity) pushing on every agent as
    /// further pedestrians would, without being moved themselves: how simulated people react
    /// to robots.
    pub fn forces_with_externals(
        &self,
        obstacles: &ObstaclePoints,
        p: &SfParams,
        externals: &[(Vec2, Vec2)],
        out: &mut Vec<Vec2>,
    ) {
        out.clear();
        out.resize(self.len(), vec2(0.0, 0.0));
        // Compiled for the best vector instructions this CPU has (AVX-512, AVX2 or SSE2),
        // chosen at run time; the arithmetic is IEEE throughout, so every choice gives the
        // same bits.
        SCRATCH.with_borrow_mut(|(columns, lookups)| {
            pulp::Arch::new().dispatch(IndividualForces {
                crowd: self,
                obstacles,
                p,
                externals,
                columns,
                lookups,
                out,
            })
        });
        if p.enable_group {
            self.add_group_forces(p, out);
        }
    }

    /// The force on agent `a`, given the social force of the rest of the crowd on it.
    #[inline(always)]
    fn force_on(
        &self,
        a: usize,
        mut social: Vec2,
        obstacles: &ObstaclePoints,
        p: &SfParams,
        externals: &[(Vec2, Vec2)],
    ) -> Vec2 {
        let (pa, va) = (self.positions[a], self.velocities[a]);
        for &(pb, vb) in externals {
            if p.interaction_range
                .is_none_or(|r| (pb - pa).norm_squared() < r * r)
            {
                social += social_force_pair(pa, va, pb, vb, &p.social);
            }
        }
        desired_force(pa, va, self.goals[a], self.max_speeds[a], &p.desired)
            + social * p.social.factor
            + obstacle_force(pa, obstacles, p.agent_radius, &p.obstacle)
    }

    fn add_group_forces(&self, p: &SfParams, out: &mut [Vec2]) {
        for group in &self.groups {
            let size = group.len();
            if size == 0 {
                continue;
            }
            let com = group.iter().map(|&i| self.positions[i]).sum::<Vec2>() / size as Real;
            // GroupCoherenceForceAlt: pull towards the centre of mass, softened by
            // (tanh(‖v‖ − threshold) + 1) / 2, except that PySocialForce measures ‖v‖ with
            // `stateutils.speeds`, which reads columns 2..4 of the 2-column array: always 0.
            let threshold = (size as Real - 1.0) / 2.0;
            let softened = ((-threshold).tanh() + 1.0) / 2.0;
            for &i in group {
                let v = com - self.positions[i];
                out[i] += v * softened * p.group_coherence_factor;
            }
            // GroupRepulsiveForce: members closer than the threshold push apart.
            for &i in group {
                let mut f = vec2(0.0, 0.0);
                for &j in group.iter().filter(|&&j| j != i) {
                    let d = self.positions[i] - self.positions[j];
                    if d.norm() <= p.group_repulsive.threshold {
                        f += d;
                    }
                }
                out[i] += f * p.group_repulsive.factor;
            }
            // GroupGazeForceAlt: turn towards the others' centre of mass.
            if size > 1 {
                for &i in group {
                    let others_com = group
                        .iter()
                        .filter(|&&j| j != i)
                        .map(|&j| self.positions[j])
                        .sum::<Vec2>()
                        / (size - 1) as Real;
                    let (com_direction, com_dist) = normalize(others_com - self.positions[i]);
                    let (direction, goal_dist) = normalize(self.goals[i] - self.positions[i]);
                    let element_prod = direction.dot(&com_direction);
                    out[i] +=
                        direction * (com_dist * element_prod / goal_dist) * p.group_gaze_factor;
                }
            }
        }
    }

    /// One `Simulator.step_once`: Euler step of the velocity, capped, zero near the goal.
    pub fn step(&mut self, obstacles: &ObstaclePoints, p: &SfParams, scratch: &mut Vec<Vec2>) {
        self.step_with_externals(obstacles, p, &[], scratch);
    }

    /// [`Crowd::step`] with external agents pushing (see [`Crowd::forces_with_externals`]).
    pub fn step_with_externals(
        &mut self,
        obstacles: &ObstaclePoints,
        p: &SfParams,
        externals: &[(Vec2, Vec2)],
        scratch: &mut Vec<Vec2>,
    ) {
        self.forces_with_externals(obstacles, p, externals, scratch);
        for (i, force) in scratch.iter().enumerate() {
            let mut v = capped_velocity(
                self.velocities[i] + force * p.step_width,
                self.max_speeds[i],
            );
            if (self.goals[i] - self.positions[i]).norm() < p.arrival_distance {
                v = vec2(0.0, 0.0);
            }
            self.positions[i] += v * p.step_width;
            self.velocities[i] = v;
        }
    }
}

/// The Social Force planner's parameters; `Default` is the PGP paper's Table I
/// (v^max = 1 m/s, A = 5.1, λ = 3.0, γ = 0.35, n = 1, n′ = 3.0) on PySocialForce's other
/// defaults.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SfAgentParams {
    /// Force model parameters (groups are not used by the planner).
    pub model: SfParams,
    /// v^max (m/s): the desired force pulls towards it and the velocity is capped at it.
    pub max_speed: Real,
}

impl Default for SfAgentParams {
    fn default() -> Self {
        let model = SfParams {
            social: SocialForceParams {
                factor: 5.1,
                lambda_importance: 3.0,
                gamma: 0.35,
                n: 1.0,
                n_prime: 3.0,
            },
            enable_group: false,
            ..SfParams::default()
        };
        Self {
            model,
            max_speed: 1.0,
        }
    }
}

/// A robot that moves like a Social Force pedestrian: one force evaluation per plan.
#[derive(Debug, Clone)]
pub struct SocialForceAgent {
    params: SfAgentParams,
}

impl SocialForceAgent {
    /// A planner with the given parameters.
    pub fn new(params: SfAgentParams) -> Self {
        Self { params }
    }

    /// The parameters in use.
    pub fn params(&self) -> &SfAgentParams {
        &self.params
    }

    /// The total force on the ego driving towards `target`.
    pub fn force(
        &mut self,
        ego: &EgoState,
        neighbours: &[Neighbour],
        map: &StaticMap,
        target: Vec2,
    ) -> Vec2 {
        let m = &self.params.model;
        let mut social = vec2(0.0, 0.0);
        for nb in neighbours {
            social += social_force_pair(
                ego.position,
                ego.velocity,
                nb.position,
                nb.velocity,
                &m.social,
            );
        }
        let points = map.sampled_points(m.resolution);
        desired_force(
            ego.position,
            ego.velocity,
            target,
            self.params.max_speed,
            &m.desired,
        ) + social * m.social.factor
            + obstacle_force(ego.position, &points, ego.radius, &m.obstacle)
    }

    /// The velocity command: v + dt·F, capped at v^max, zero within the arrival distance.
    pub fn command(
        &mut self,
        ego: &EgoState,
        neighbours: &[Neighbour],
        map: &StaticMap,
        target: Vec2,
        dt: Real,
    ) -> Vec2 {
        if (target - ego.position).norm() < self.params.model.arrival_distance {
            return vec2(0.0, 0.0);
        }
        let f = self.force(ego, neighbours, map, target);
        capped_velocity(ego.velocity + f * dt, self.params.max_speed)
    }
}
#[cfg(test)]
mod tests;

#[cfg(test)]
mod range_tests {
    use super::*;

    /// With a range longer than the stage, the grid path gives PySocialForce's all-pairs sums
    /// up to summation order.
    #[test]
    fn long_range_grid_matches_all_pairs() {
        let p = SfParams::default();
        let positions: Vec<Vec2> = (0..30)
            .map(|i| vec2((i % 6) as Real * 0.9, (i / 6) as Real * 1.1))
            .collect();
        let velocities: Vec<Vec2> = (0..30)
            .map(|i| {
                vec2(
                    ((i * 7) % 5) as Real * 0.2 - 0.4,
                    ((i * 3) % 4) as Real * 0.2 - 0.3,
                )
            })
            .collect();
        let goals: Vec<Vec2> = (0..30)
            .map(|i| vec2(10.0 - (i % 6) as Real, (i / 6) as Real))
            .collect();
        let crowd = Crowd::new(
            positions,
            velocities,
            goals,
            vec![vec![0, 1, 2], vec![3, 4]],
            &p,
        );
        let (mut exact, mut ranged) = (Vec::new(), Vec::new());
        crowd.forces(&ObstaclePoints::default(), &p, &mut exact);
        let far = SfParams {
            interaction_range: Some(100.0),
            ..p
        };
        crowd.forces(&ObstaclePoints::default(), &far, &mut ranged);
        for (e, r) in exact.iter().zip(&ranged) {
            assert!((e - r).norm() < 1e-12);
        }
        // A short range drops distant pairs, so some force must change.
        let near = SfParams {
            interaction_range: Some(1.0),
            ..p
        };
        crowd.forces(&ObstaclePoints::default(), &near, &mut ranged);
        assert!(
            exact
                .iter()
                .zip(&ranged)
                .any(|(e, r)| (e - r).norm() > 1e-9)
        );
    }
}
