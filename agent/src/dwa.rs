//! Predictive Dynamic Window Approach (Fox, Burgard & Thrun 1997), as the PGP paper uses it:
//! unicycle arcs sampled from the dynamic window, collision-checked against the *linear
//! predictions* of the neighbours and against the static map.
//!
//! For every (v, ω) on a 10 × 10 grid over the dynamic window, the arc is simulated for
//! t^plan at dt. The paper's DWA is a pure collision-avoidance planner with collision checks
//! against linear predictions, so an arc predicted to overlap anything within t^plan is not
//! admissible. (Fox et al.'s weaker rule, admissible while the robot could still brake before
//! the hit, let our DWA drive at people whose paths then bent back.) The admissible arc with
//! the best G = α·heading + β·clearance + γ·velocity wins. If none is admissible (in a dense
//! crowd someone is nearly always predicted within reach), the arc whose predicted collision
//! comes latest is taken: braking to a standstill instead froze the robot in crowds. The
//! weights are ours: the PGP paper does not give them.

use crate::fastmath::LANES;
use crate::map::{LocalMap, StaticMap};
use crate::math::{Real, Vec2, unit, wrap_angle};
use crate::model::{Command, EgoState, Neighbour, TrajectorySample};
use crate::prediction::{SigmaModel, ctrv_offset};

/// DWA's parameters; `Default` is the PGP paper's Table I plus the objective weights, which
/// the paper does not give.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DwaParams {
    /// t^plan: horizon of each simulated arc (s).
    pub t_plan: Real,
    /// dt: sampling step along an arc (s).
    pub dt: Real,
    /// Time the dynamic window spans (s): the velocities reachable within it are sampled.
    /// Table I's dt; the body's own acceleration limits act at the control period.
    pub window_time: Real,
    /// v^min (m/s).
    pub v_min: Real,
    /// v^max (m/s).
    pub v_max: Real,
    /// |ψ̇|^max: largest yaw rate (rad/s).
    pub yaw_rate_max: Real,
    /// |ψ̈|^max: largest yaw acceleration (rad/s²).
    pub yaw_accel_max: Real,
    /// |a|^max: largest linear acceleration (m/s²).
    pub accel_max: Real,
    /// Velocities on the grid.
    pub v_samples: usize,
    /// Yaw rates on the grid.
    pub yaw_samples: usize,
    /// α: weight of the heading towards the target.
    pub heading_weight: Real,
    /// β: weight of the smallest clearance along the arc.
    pub clearance_weight: Real,
    /// γ: weight of the speed.
    pub velocity_weight: Real,
    /// Clearances above this (m) count as full clearance.
    pub clearance_cap: Real,
    /// An arc whose predicted clearance falls below this (m) counts as colliding: the usual
    /// inflation of DWA's collision check (not given in the paper; ours).
    pub safety_margin: Real,
    /// σ growth for the announced trajectory.
    pub sigma: SigmaModel,
}

impl Default for DwaParams {
    fn default() -> Self {
        Self {
            t_plan: 2.0,
            dt: 0.25,
            window_time: 0.25,
            v_min: 0.0,
            v_max: 1.0,
            yaw_rate_max: 1.0,
            yaw_accel_max: 1.5,
            accel_max: 1.5,
            v_samples: 10,
            yaw_samples: 10,
            heading_weight: 1.0,
            clearance_weight: 0.2,
            velocity_weight: 0.2,
            clearance_cap: 1.0,
            safety_margin: SAFETY_MARGIN,
            sigma: SigmaModel::default(),
        }
    }
}

const SAFETY_MARGIN: Real = 0.2;

/// The window of (v, ω) reachable within one control period.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Window {
    /// Lowest and highest forward speed (m/s).
    pub v: (Real, Real),
    /// Lowest and highest yaw rate (rad/s).
    pub yaw_rate: (Real, Real),
}

/// The chosen arc.
#[derive(Debug, Clone, PartialEq)]
pub struct DwaChoice {
    /// Forward speed (m/s).
    pub speed: Real,
    /// Yaw rate (rad/s).
    pub yaw_rate: Real,
    /// The arc as a trajectory with σ, t = dt..=t_plan.
    pub trajectory: Vec<TrajectorySample>,
    /// The window it was chosen from.
    pub window: Window,
    /// Whether any arc was admissible (false: the arc colliding latest was taken).
    pub admissible: bool,
}

/// The predictive DWA with reusable buffers.
#[derive(Debug, Clone, Default)]
pub struct Dwa {
    params: DwaParams,
    /// Per sample time t = i·dt, i = 1..=steps, the linear predictions of the neighbours that
    /// any arc could come near (entries `mover_start[i − 1]..mover_start[i]`), with radii.
    mover_start: Vec<usize>,
    mover_x: Vec<Real>,
    mover_y: Vec<Real>,
    mover_radius: Vec<Real>,
    /// Per yaw rate of the grid and sample time, the displacement of a unit-speed arc
    /// (index iw·steps + i − 1): the same for every speed, so computed once per plan.
    unit_offsets: Vec<Vec2>,
    local: LocalMap,
}

impl Dwa {
    /// A planner with the given parameters.
    pub fn new(params: DwaParams) -> Self {
        Self {
            params,
            ..Self::default()
        }
    }

    /// The parameters in use.
    pub fn params(&self) -> &DwaParams {
        &self.params
    }

    /// The dynamic window: velocities reachable within `window_time`, or within the control
    /// period `control_dt` if that is longer.
    pub fn window(&self, ego: &EgoState, control_dt: Real) -> Window {
        let p = &self.params;
        let control_dt = control_dt.max(p.window_time);
        let v_now = ego.velocity.dot(&unit(ego.heading));
        let v_hi = p.v_max.min(v_now + p.accel_max * control_dt);
        let v_lo = p.v_min.max(v_now - p.accel_max * control_dt).min(v_hi);
        let w_hi = p
            .yaw_rate_max
            .min(ego.yaw_rate + p.yaw_accel_max * control_dt);
        let w_lo = (-p.yaw_rate_max)
            .max(ego.yaw_rate - p.yaw_accel_max * control_dt)
            .min(w_hi);
        Window {
            v: (v_lo, v_hi.max(v_lo)),
            yaw_rate: (w_lo, w_hi.max(w_lo)),
        }
    }

    /// One DWA step towards `target`.
    pub fn plan(
        &mut self,
        ego: &EgoState,
        neighbours: &[Neighbour],
        map: &StaticMap,
        target: Vec2,
        control_dt: Real,
    ) -> DwaChoice {
        self.plan_within(ego, neighbours, map, target, control_dt, None)
    }

    /// One DWA step towards `target`, restricted to the arcs `admits` allows (the safety
    /// layer's predicate) when any of DWA's admissible arcs is allowed; else as [`Dwa::plan`].
    pub fn plan_within(
        &mut self,
        ego: &EgoState,
        neighbours: &[Neighbour],
        map: &StaticMap,
        target: Vec2,
        control_dt: Real,
        admits: Option<&dyn Fn(Command) -> bool>,
    ) -> DwaChoice {
        let p = self.params;
        let window = self.window(ego, control_dt);
        let steps = (p.t_plan / p.dt).round() as usize;
        let reach = window.v.1 * p.t_plan + ego.radius;

        // Every arc's sample at time t lies within v_hi·t of the start, so only neighbours
        // predicted that close (plus radii and the clearance cap) can matter at t. Their
        // linear predictions are computed once for all arcs.
        self.mover_start.clear();
        self.mover_radius.clear();
        self.mover_x.clear();
        self.mover_y.clear();
        for i in 1..=steps {
            let t = i as Real * p.dt;
            self.mover_start.push(self.mover_x.len());
            for nb in neighbours {
                let q = nb.position + nb.velocity * t;
                let range = window.v.1 * t + ego.radius + nb.radius + p.clearance_cap;
                if (q - ego.position).norm_squared() < range * range {
                    self.mover_x.push(q.x);
                    self.mover_y.push(q.y);
                    self.mover_radius.push(nb.radius);
                }
            }
            // Whole blocks of `LANES`: padding movers lie at infinity, out of every reach.
            while !self.mover_x.len().is_multiple_of(LANES) {
                self.mover_x.push(Real::INFINITY);
                self.mover_y.push(Real::INFINITY);
                self.mover_radius.push(0.0);
            }
        }
        self.mover_start.push(self.mover_x.len());
        let corner = Vec2::new(reach, reach);
        map.gather(
            ego.position - corner,
            ego.position + corner,
            p.clearance_cap,
            &mut self.local,
        );

        self.unit_offsets.clear();
        for iw in 0..p.yaw_samples {
            let w = lerp(window.yaw_rate, iw, p.yaw_samples);
            for i in 1..=steps {
                self.unit_offsets
                    .push(ctrv_offset(1.0, ego.heading, w, i as Real * p.dt));
            }
        }

        let (best, latest_hit) = pulp::Arch::new().dispatch(ArcSearch {
            dwa: self,
            ego,
            map,
            target,
            window: &window,
            steps,
            admits,
        });
        let admissible = best.is_some();
        let (_, speed, yaw_rate) = best
            .or(latest_hit)
            .expect("the window has at least one arc");
        let trajectory = self.arc(ego, speed, yaw_rate, steps);
        DwaChoice {
            speed,
            yaw_rate,
            trajectory,
            window,
            admissible,
        }
    }

    /// The best admissible arc (G, v, ω), among those `admits` allows when it allows any;
    /// and the arc whose predicted collision comes latest (hit time, v, ω; ties: the slower
    /// arc, which the loop meets first). Runs inside [`ArcSearch`], compiled for the widest
    /// instruction set the CPU has (the predicate is a call out of it).
    #[inline(always)]
    fn search<S: pulp::Simd>(&self, simd: S, task: &ArcSearch<'_>) -> (Pick, Pick) {
        let ArcSearch {
            ego,
            map,
            target,
            window,
            steps,
            admits,
            ..
        } = *task;
        let p = &self.params;
        let mut best: Pick = None;
        let mut best_allowed: Pick = None;
        let mut latest_hit: Pick = None;
        for iv in 0..p.v_samples {
            let v = lerp(window.v, iv, p.v_samples);
            for iw in 0..p.yaw_samples {
                let w = lerp(window.yaw_rate, iw, p.yaw_samples);
                let offsets = &self.unit_offsets[iw * steps..(iw + 1) * steps];
                match self.score(simd, ego, map, target, (v, w), offsets) {
                    Ok(score) => {
                        if best.is_none_or(|b| score > b.0) {
                            best = Some((score, v, w));
                        }
                        if best_allowed.is_none_or(|b| score > b.0)
                            && admits.is_none_or(|f| {
                                f(Command::Unicycle {
                                    speed: v,
                                    yaw_rate: w,
                                })
                            })
                        {
                            best_allowed = Some((score, v, w));
                        }
                    }
                    Err(hit_time) => {
                        if latest_hit.is_none_or(|b| hit_time > b.0) {
                            latest_hit = Some((hit_time, v, w));
                        }
                    }
                }
            }
        }
        (best_allowed.or(best), latest_hit)
    }

    /// G(v, ω), or, for an arc that is not admissible, the time of its first predicted
    /// collision (clearance below the safety margin).
    #[inline(always)]
    fn score<S: pulp::Simd>(
        &self,
        simd: S,
        ego: &EgoState,
        map: &StaticMap,
        target: Vec2,
        (v, w): (Real, Real),
        unit_offsets: &[Vec2],
    ) -> Result<Real, Real> {
        let p = &self.params;
        let mut min_clearance = Real::INFINITY;
        let mut reaches_target = false;
        let mut end = (ego.position, ego.heading);
        for (i, offset) in (1..).zip(unit_offsets) {
            let t = i as Real * p.dt;
            // ctrv_offset scales linearly with speed.
            let pos = ego.position + offset * v;
            let mut clearance = if self.local.is_empty() {
                Real::INFINITY
            } else {
                self.local.distance(map, &pos) - ego.radius
            };
            let row = self.mover_start[i - 1]..self.mover_start[i];
            clearance = clearance.min(mover_clearance(
                simd,
                pos,
                ego.radius,
                p.clearance_cap,
                &self.mover_x[row.clone()],
                &self.mover_y[row.clone()],
                &self.mover_radius[row],
            ));
            if clearance <= p.safety_margin {
                return Err(t);
            }
            min_clearance = min_clearance.min(clearance);
            reaches_target |= (pos - target).norm() < 0.2;
            end = (pos, ego.heading + w * t);
        }
        let to_target = target - end.0;
        let heading = if reaches_target || to_target.norm() < 1e-9 {
            1.0
        } else {
            let error = wrap_angle(to_target.y.atan2(to_target.x) - end.1).abs();
            1.0 - error / std::f64::consts::PI
        };
        let clearance = min_clearance.clamp(0.0, p.clearance_cap) / p.clearance_cap;
        let velocity = if p.v_max > 0.0 { v / p.v_max } else { 0.0 };
        Ok(p.heading_weight * heading
            + p.clearance_weight * clearance
            + p.velocity_weight * velocity)
    }

    fn arc(&self, ego: &EgoState, v: Real, w: Real, steps: usize) -> Vec<TrajectorySample> {
        let p = &self.params;
        (1..=steps)
            .zip(p.sigma.constant_speed(v))
            .map(|(i, sigma)| {
                let t = i as Real * p.dt;
                TrajectorySample {
                    t,
                    position: ego.position + ctrv_offset(v, ego.heading, w, t),
                    sigma,
                }
            })
            .collect()
    }
}

/// An arc picked by the search: (its G or hit time, v, ω).
type Pick = Option<(Real, Real, Real)>;

/// DWA's search over the window as one operation that `pulp` compiles once per instruction
/// set.
#[derive(Clone, Copy)]
struct ArcSearch<'a> {
    dwa: &'a Dwa,
    ego: &'a EgoState,
    map: &'a StaticMap,
    target: Vec2,
    window: &'a Window,
    steps: usize,
    admits: Option<&'a dyn Fn(Command) -> bool>,
}

impl pulp::WithSimd for ArcSearch<'_> {
    type Output = (Pick, Pick);

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, simd: S) -> Self::Output {
        self.dwa.search(simd, &self)
    }
}

/// The smallest clearance (distance between bodies) of a body at `pos` to the movers given as
/// columns of whole `LANES` blocks, counting only movers within `cap` of touching (beyond the
/// clearance cap the exact distance does not matter); ∞ if there are none. Branch-free, a
/// vector of movers at a time: the minimum of the same numbers as a loop that skips the far
/// ones (a minimum does not depend on order).
#[inline(always)]
fn mover_clearance<S: pulp::Simd>(
    simd: S,
    pos: Vec2,
    radius: Real,
    cap: Real,
    xs: &[Real],
    ys: &[Real],
    radii: &[Real],
) -> Real {
    // Whole `LANES` blocks split into whole vectors at every width pulp offers (1–8 lanes).
    let (xs, tail) = S::as_simd_f64s(xs);
    debug_assert!(tail.is_empty(), "mover rows are whole blocks");
    let (ys, _) = S::as_simd_f64s(ys);
    let (radii, _) = S::as_simd_f64s(radii);
    let (px, py) = (simd.splat_f64s(pos.x), simd.splat_f64s(pos.y));
    let (radius, cap) = (simd.splat_f64s(radius), simd.splat_f64s(cap));
    let infinity = simd.splat_f64s(Real::INFINITY);
    let mut nearest = infinity;
    for ((&x, &y), &r) in xs.iter().zip(ys).zip(radii) {
        let (dx, dy) = (simd.sub_f64s(px, x), simd.sub_f64s(py, y));
        let d2 = simd.add_f64s(simd.mul_f64s(dx, dx), simd.mul_f64s(dy, dy));
        let reach = simd.add_f64s(simd.add_f64s(radius, r), cap);
        let near = simd.less_than_f64s(d2, simd.mul_f64s(reach, reach));
        let clearance = simd.sub_f64s(simd.sub_f64s(simd.sqrt_f64s(d2), radius), r);
        nearest = simd.min_f64s(nearest, simd.select_f64s(near, clearance, infinity));
    }
    simd.reduce_min_f64s(nearest)
}

/// The i-th of n evenly spaced values over `[lo, hi]` (both ends included).
fn lerp((lo, hi): (Real, Real), i: usize, n: usize) -> Real {
    if n <= 1 {
        0.5 * (lo + hi)
    } else {
        lo + (hi - lo) * i as Real / (n - 1) as Real
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::vec2;
    use crate::model::AgentKind;
    use proptest::prelude::*;

    /// [`mover_clearance`] as the CPU's widest instruction set runs it.
    struct Clearance<'a> {
        pos: Vec2,
        columns: [&'a [Real]; 3],
    }

    impl pulp::WithSimd for Clearance<'_> {
        type Output = Real;

        fn with_simd<S: pulp::Simd>(self, simd: S) -> Real {
            let [xs, ys, radii] = self.columns;
            mover_clearance(simd, self.pos, 0.3, 1.0, xs, ys, radii)
        }
    }

    proptest! {
        /// The vectorised mover check finds the same clearance as the loop that skips movers
        /// beyond the cap, padded as `plan` pads its rows, at every vector width.
        #[test]
        fn vectorised_clearance_is_the_skipping_loops(
            pos in (-3.0..3.0f64, -3.0..3.0f64),
            movers in proptest::collection::vec((-4.0..4.0f64, -4.0..4.0f64, 0.1..0.5f64), 0..40),
        ) {
            let pos = vec2(pos.0, pos.1);
            let mut expected = Real::INFINITY;
            for &(x, y, r) in &movers {
                let (dx, dy) = (pos.x - x, pos.y - y);
                let reach = 0.3 + r + 1.0;
                if dx * dx + dy * dy < reach * reach {
                    expected = expected.min((dx * dx + dy * dy).sqrt() - 0.3 - r);
                }
            }
            let padded = movers.len().next_multiple_of(LANES);
            let column = |f: fn(&(Real, Real, Real)) -> Real, pad: Real| {
                let mut c: Vec<Real> = movers.iter().map(f).collect();
                c.resize(padded, pad);
                c
            };
            let (xs, ys, radii) = (
                column(|m| m.0, Real::INFINITY),
                column(|m| m.1, Real::INFINITY),
                column(|m| m.2, 0.0),
            );
            let widest = pulp::Arch::new().dispatch(Clearance { pos, columns: [&xs, &ys, &radii] });
            let scalar = mover_clearance(pulp::Scalar::new(), pos, 0.3, 1.0, &xs, &ys, &radii);
            prop_assert_eq!(widest, expected);
            prop_assert_eq!(scalar, expected);
        }
    }

    fn ego(v: Real, w: Real) -> EgoState {
        EgoState {
            position: vec2(0.0, 0.0),
            heading: 0.0,
            velocity: vec2(v, 0.0),
            yaw_rate: w,
            radius: 0.3,
        }
    }

    #[test]
    fn window_is_table_i_limits_over_one_control_period() {
        let dwa = Dwa::new(DwaParams::default());
        // Window over dt = 0.25 s: ±1.5 m/s² · 0.25 s, ±1.5 rad/s² · 0.25 s.
        let w = dwa.window(&ego(0.5, 0.0), 0.1);
        assert!((w.v.0 - 0.125).abs() < 1e-12 && (w.v.1 - 0.875).abs() < 1e-12);
        assert!((w.yaw_rate.0 + 0.375).abs() < 1e-12 && (w.yaw_rate.1 - 0.375).abs() < 1e-12);
        // A longer control period widens it.
        let w = dwa.window(&ego(0.5, 0.0), 0.3);
        assert!((w.v.1 - 0.95).abs() < 1e-12);
        let w = dwa.window(&ego(1.0, 1.0), 0.1);
        assert_eq!(
            (w.v.1, w.yaw_rate.1),
            (1.0, 1.0),
            "capped at v_max and |ψ̇|max"
        );
        let w = dwa.window(&ego(0.0, 0.0), 0.1);
        assert_eq!(w.v.0, 0.0, "no reversing: v_min = 0");
    }

    #[test]
    fn drives_straight_at_the_target_in_free_space() {
        let mut dwa = Dwa::new(DwaParams::default());
        let c = dwa.plan(
            &ego(0.5, 0.0),
            &[],
            &StaticMap::empty(),
            vec2(10.0, 0.0),
            0.1,
        );
        assert!(c.admissible);
        assert!((c.speed - 0.875).abs() < 1e-12, "accelerates");
        assert!(
            c.yaw_rate.abs() < 0.05,
            "keeps heading, got ω = {}",
            c.yaw_rate
        );
        assert_eq!(c.trajectory.len(), 8);
    }

    #[test]
    fn brakes_for_a_person_stepping_in_front() {
        let mut dwa = Dwa::new(DwaParams::default());
        let person = Neighbour::new(1, vec2(0.9, 0.0), vec2(0.0, 0.0), 0.35, AgentKind::Human);
        let c = dwa.plan(
            &ego(1.0, 0.0),
            &[person],
            &StaticMap::empty(),
            vec2(10.0, 0.0),
            0.1,
        );
        assert!(
            c.speed < 1.0,
            "must not keep full speed towards a person 0.25 m away"
        );
    }

    proptest! {
        #[test]
        fn commands_stay_inside_the_dynamic_window(
            v in 0.0..1.0f64, w in -1.0..1.0f64, tx in -10.0..10.0f64, ty in -10.0..10.0f64,
            people in proptest::collection::vec((-4.0..4.0f64, -4.0..4.0f64, -1.0..1.0f64, -1.0..1.0f64), 0..12),
        ) {
            let mut dwa = Dwa::new(DwaParams::default());
            let e = ego(v, w);
            let nbs: Vec<_> = people.iter().enumerate()
                .map(|(i, &(x, y, vx, vy))| Neighbour::new(i as u64, vec2(x, y), vec2(vx, vy), 0.35, AgentKind::Human))
                .collect();
            let c = dwa.plan(&e, &nbs, &StaticMap::empty(), vec2(tx, ty), 0.1);
            let win = dwa.window(&e, 0.1);
            prop_assert!(c.speed >= win.v.0 - 1e-12 && c.speed <= win.v.1 + 1e-12);
            prop_assert!(c.yaw_rate >= win.yaw_rate.0 - 1e-12 && c.yaw_rate <= win.yaw_rate.1 + 1e-12);
            prop_assert!(c.speed >= 0.0 && c.speed <= 1.0 && c.yaw_rate.abs() <= 1.0);
        }
    }
}
