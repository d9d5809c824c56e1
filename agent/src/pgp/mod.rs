//! The Probabilistic Gap Planner (PGP paper, Sec. III): a fan of candidate trajectories around
//! the straight line to the goal, each scored by its expected utility under the cooperative
//! collision risk, and a subgoal along the initial heading of the best one.
//!
//! Per plan: neighbours are predicted once (`prediction`), then for every candidate and step
//! the hazard Σ_k p^coll,coop + p^coll,static + p^escape is accumulated into the survival
//! probability (Eq. 5) that discounts the utility (Eqs. 6–8).

use crate::fastmath::LANES;
use crate::map::{LocalMap, StaticMap};
use crate::math::{Real, Vec2, angle_of, rotate, unit, wrap_angle};
use crate::model::{Command, EgoState, Neighbour, TrajectorySample};
use crate::prediction::{SigmaModel, Track, predict, predicts_straight};
mod hazard;

use crate::risk::static_collision_probability;
use hazard::{EgoTerms, dynamic_hazard, ln_upper_bound};
/// Edges farther than this many σ_max from every sample add less than erfc(7) ≈ 4·10⁻²³
/// static risk, so they are not gathered.
const STATIC_RANGE_SIGMAS: Real = 10.0;

/// PGP's parameters; `Default` gives the paper's (Sec. IV-C).
#[derive(Debug, Clone, PartialEq)]
pub struct PgpParams {
    /// Time between trajectory samples (s): 4 Hz.
    pub dt: Real,
    /// Number of samples: 8 s horizon at 4 Hz = 32.
    pub steps: usize,
    /// v^max: the ego's maximum speed (m/s), used in Eq. 6.
    pub v_max: Real,
    /// v: speed of the candidate trajectories (m/s).
    pub speed: Real,
    /// α: fan-out angles (radians), relative to the line to the goal.
    pub fan_angles: Vec<Real>,
    /// d_turned: length of the first, outward segment (m).
    pub d_turned: Real,
    /// The second segment is this share of the remaining distance (0.9), or absent.
    pub outside_fraction: Real,
    /// Turning more than this (radians, 30°) slows the start of a candidate.
    pub turn_threshold: Real,
    /// γ̇^max: maximal turn rate (rad/s).
    pub max_turn_rate: Real,
    /// Speed factor while turning (0.5).
    pub turn_slowdown: Real,
    /// σ growth for the ego and every neighbour.
    pub sigma: SigmaModel,
    /// p^escape per step. The paper only bounds it, 0 < p^escape < 1; 0.01 per 0.25 s step
    /// (survival 0.73 at 8 s with nothing around) is our choice.
    pub p_escape: Real,
    /// Distance of the subgoal along the best candidate's initial heading (m):
    /// v^max,CCA · t^plan,CCA of the short-term planner.
    pub subgoal_distance: Real,
    /// Terms of Eq. 3 that are provably smaller than this are skipped (their exponent is
    /// bounded by ln(factor / floor)). 0 evaluates every term. The default, 10⁻⁹, is 10⁻⁷ of
    /// p^escape: far below anything that can change which candidate wins.
    pub risk_floor: Real,
    /// Whether to return the evaluated fan with each plan.
    pub record_fan: bool,
}

impl Default for PgpParams {
    fn default() -> Self {
        Self {
            dt: 0.25,
            steps: 32,
            v_max: 1.0,
            speed: 1.0,
            fan_angles: (-5..=5).map(|i| (16.0 * i as Real).to_radians()).collect(),
            d_turned: 2.5,
            outside_fraction: 0.9,
            turn_threshold: 30f64.to_radians(),
            max_turn_rate: 1.0,
            turn_slowdown: 0.5,
            sigma: SigmaModel::default(),
            p_escape: 0.01,
            subgoal_distance: 2.0,
            risk_floor: 1e-9,
            record_fan: true,
        }
    }
}

impl PgpParams {
    /// d_goal = T · v^max (Sec. III-B): how far along the line to the map goal PGP places its
    /// own goal, T seconds at top speed. The paper's 8 s at 1 m/s give its 8 m (Sec. IV-C); a
    /// robot with another top speed gets its own (11.8 m at ETH's 1.47 m/s).
    pub fn d_goal(&self) -> Real {
        self.steps as Real * self.dt * self.v_max
    }
}

/// One evaluated candidate, as debug data for dashboards.
#[derive(Debug, Clone, PartialEq)]
pub struct Candidate {
    /// α: initial angle relative to the line to the goal (radians).
    pub alpha: Real,
    /// d_outside: length of the parallel segment (m).
    pub d_outside: Real,
    /// Positions at t = i·dt, i = 0..=steps.
    pub positions: Vec<Vec2>,
    /// p^surv at t = i·dt, i = 0..=steps (Eq. 5).
    pub survival: Vec<Real>,
    /// u^expected (Eq. 8).
    pub expected_utility: Real,
}

/// The evaluated fan of one PGP step.
#[derive(Debug, Clone, PartialEq)]
pub struct Fan {
    /// PGP's own goal, d_goal along the line to the map goal.
    pub pgp_goal: Vec2,
    /// Every candidate, in order of α then d_outside.
    pub candidates: Vec<Candidate>,
    /// Index of the chosen candidate.
    pub best: usize,
}

/// What one PGP step decides.
#[derive(Debug, Clone, PartialEq)]
pub struct PgpDecision {
    /// Where the short-term planner should go.
    pub subgoal: Vec2,
    /// The chosen candidate as a trajectory with the ego's σ (t = i·dt, i = 1..=steps).
    pub trajectory: Vec<TrajectorySample>,
    /// The evaluated fan, if recording is on.
    pub fan: Option<Fan>,
}

/// Every candidate sampled at t = i·dt, i = 0..=steps, flattened candidate-major
/// (index l·(steps + 1) + i): positions, per-interval speeds, utilities, ego σ.
#[derive(Debug, Clone, Default)]
struct Sampled {
    positions: Vec<Vec2>,
    speeds: Vec<Real>,
    utility: Vec<Real>,
    sigma: Vec<Real>,
    /// Speed profile (index into `Pgp::profiles`) of each candidate.
    profile: Vec<usize>,
    /// Scratch of one candidate: arc length and direction of travel at each sample.
    arcs: Vec<Real>,
    headings: Vec<Vec2>,
}

/// What Eqs. 1–3 need besides positions, split so that tables stay small: per profile and
/// step (index g·steps + j) the ego's σ², σ_0/σ_j and cull term; per step, for the neighbours
/// that can matter at that step (entries `start[j]..start[j + 1]`; the columns run longer, as
/// they are never shrunk), the neighbour's position, σ², σ_0/σ_j, cull term and σ_0².
///
/// A term factor · exp(−d²/(2σ̃)) with factor = (σ̃_0/σ̃)·τ ≤ (σ_0,ego/σ_j,ego)·(σ_0,k/σ_j,k)
/// is below `risk_floor` once d² ≥ 2σ̃·(ego_cull + nb_cull), where ego_cull and nb_cull are
/// upper bounds of ln((σ_0,ego/σ_j,ego)/floor) and ln(σ_0,k/σ_j,k). A neighbour that is that
/// far from the bounding box of every candidate's sample at step j is left out of step j.
#[derive(Debug, Clone, Default)]
struct PairTables {
    ego_var: Vec<Real>,
    ego_ratio: Vec<Real>,
    ego_cull: Vec<Real>,
    start: Vec<usize>,
    nb_x: Vec<Real>,
    nb_y: Vec<Real>,
    nb_var: Vec<Real>,
    nb_ratio: Vec<Real>,
    nb_cull: Vec<Real>,
    nb_var0: Vec<Real>,
}

/// Neighbours per pass of `build_tables`' vectorised loop.
const TABLE_CHUNK: usize = 64;

/// The Probabilistic Gap Planner with its reusable buffers.
#[derive(Debug, Clone, Default)]
pub struct Pgp {
    params: PgpParams,
    tracks: Vec<Track>,
    /// Per neighbour, for straight-line prediction: displacement per step (x, y), σ_max and
    /// σ growth per step.
    straight: Vec<[Real; 4]>,
    /// Neighbour positions and σ flattened step-major (index j·K + k).
    nb_x: Vec<Real>,
    nb_y: Vec<Real>,
    nb_sigma: Vec<Real>,
    local: LocalMap,
    sampled: Sampled,
    /// Distinct ego σ profiles, each `steps + 1` long.
    profiles: Vec<Vec<Real>>,
    tables: PairTables,
    /// Hazards per candidate (index l·steps + j) and survival per candidate (l·(steps+1) + i).
    hazards: Vec<Real>,
    survival: Vec<Real>,
}

impl Pgp {
    /// A planner with the given parameters.
    pub fn new(params: PgpParams) -> Self {
        Self {
            params,
            ..Self::default()
        }
    }

    /// The parameters in use.
    pub fn params(&self) -> &PgpParams {
        &self.params
    }

    /// Turns recording of the evaluated fan on or off (debug data only: decisions do not
    /// depend on it, and off saves its allocations).
    pub fn set_record_fan(&mut self, on: bool) {
        self.params.record_fan = on;
    }

    /// One PGP step: evaluate the fan and return the subgoal.
    pub fn plan(
        &mut self,
        ego: &EgoState,
        neighbours: &[Neighbour],
        map: &StaticMap,
        goal: Vec2,
    ) -> PgpDecision {
        self.plan_within(ego, neighbours, map, goal, None)
    }

    /// One PGP step whose subgoal lies on the best candidate that the robot may set out along
    /// now: `admits` (the safety layer's predicate) allows a velocity at PGP's speed along the
    /// candidate's initial heading. When it allows none, the best candidate as in
    /// [`Pgp::plan`].
    pub fn plan_within(
        &mut self,
        ego: &EgoState,
        neighbours: &[Neighbour],
        map: &StaticMap,
        goal: Vec2,
        admits: Option<&dyn Fn(Command) -> bool>,
    ) -> PgpDecision {
        let p0 = ego.position;
        let to_goal = goal - p0;
        let dist_goal = to_goal.norm();
        if dist_goal < 1e-6 {
            return PgpDecision {
                subgoal: goal,
                trajectory: Vec::new(),
                fan: None,
            };
        }
        let dir = to_goal / dist_goal;
        let pgp_goal = p0 + dir * self.params.d_goal().min(dist_goal);
        let geometries = self.candidate_geometries(p0, dir, pgp_goal);
        let expected = pulp::Arch::new().dispatch(PlanPass {
            pgp: self,
            ego,
            neighbours,
            map,
            geometries: &geometries,
            pgp_goal,
        });

        // The first best wins ties, so the result does not depend on float noise order.
        let mut best = 0;
        for (l, &u) in expected.iter().enumerate() {
            if u > expected[best] {
                best = l;
            }
        }
        if let Some(admits) = admits {
            let speed = self.params.speed;
            let sets_out = |l: usize| {
                let ahead = geometries[l].point_at(0.1) - p0;
                let n = ahead.norm();
                n > 0.0 && admits(Command::Velocity(ahead / n * speed))
            };
            let mut allowed: Option<usize> = None;
            for (l, &u) in expected.iter().enumerate() {
                if allowed.is_none_or(|b| u > expected[b]) && sets_out(l) {
                    allowed = Some(l);
                }
            }
            best = allowed.unwrap_or(best);
        }
        let stride = self.params.steps + 1;
        let fan = self.params.record_fan.then(|| Fan {
            pgp_goal,
            candidates: geometries
                .iter()
                .enumerate()
                .map(|(l, g)| Candidate {
                    alpha: g.alpha,
                    d_outside: g.d_outside,
                    positions: self.sampled.positions[l * stride..(l + 1) * stride].to_vec(),
                    survival: self.survival[l * stride..(l + 1) * stride].to_vec(),
                    expected_utility: expected[l],
                })
                .collect(),
            best,
        });
        // The paper puts the subgoal d_subgoal along the best candidate's initial heading, which
        // is on the candidate's first segment while d_turned ≥ d_subgoal. We take the point
        // d_subgoal along the candidate's path: the same point then, and still on the path when
        // a near goal has shrunk the fan (a point along the heading could lie behind a wall).
        let subgoal = geometries[best].point_at(self.params.subgoal_distance.min(dist_goal));
        PgpDecision {
            subgoal,
            trajectory: self.trajectory(best),
            fan,
        }
    }

    /// Sec. III-B: three-segment paths, 11 angles × d_outside ∈ {0, 0.9·remaining}.
    ///
    /// The paper sizes the fan for a goal d_goal away. When the map goal is nearer, the fan is
    /// scaled down with it (d_turned · distance / d_goal), so that the straight candidate ends
    /// at the goal instead of overshooting it by up to d_turned; at d_goal or more it is exactly
    /// the paper's.
    fn candidate_geometries(&self, p0: Vec2, dir: Vec2, pgp_goal: Vec2) -> Vec<Geometry> {
        let p = &self.params;
        let scale = ((pgp_goal - p0).norm() / p.d_goal()).min(1.0);
        let d_turned = p.d_turned * scale;
        let mut out = Vec::with_capacity(2 * p.fan_angles.len());
        for &alpha in &p.fan_angles {
            let p_out = p0 + rotate(&dir, alpha) * d_turned;
            let remaining = (pgp_goal - p_out).norm();
            for d_outside in [0.0, p.outside_fraction * remaining] {
                let p_back = p_out + dir * d_outside;
                out.push(Geometry {
                    alpha,
                    d_outside,
                    waypoints: [p0, p_out, p_back, pgp_goal],
                });
            }
        }
        out
    }

    /// Samples every candidate and groups them by ego σ profile.
    #[inline(always)]
    fn sample_all(&mut self, ego: &EgoState, geometries: &[Geometry], pgp_goal: Vec2) {
        let n = self.params.steps;
        let s = &mut self.sampled;
        s.positions.clear();
        s.speeds.clear();
        s.utility.clear();
        s.sigma.clear();
        s.profile.clear();
        self.profiles.clear();
        for g in geometries {
            sample(&self.params, ego, g, pgp_goal, s);
            let sigma = &s.sigma[s.sigma.len() - (n + 1)..];
            let profile = match self.profiles.iter().position(|q| q.as_slice() == sigma) {
                Some(i) => i,
                None => {
                    self.profiles.push(sigma.to_vec());
                    self.profiles.len() - 1
                }
            };
            s.profile.push(profile);
        }
    }

    /// Predicts the neighbours and gathers the static geometry around the fan.
    #[inline(always)]
    fn predict(
        &mut self,
        neighbours: &[Neighbour],
        map: &StaticMap,
        p0: Vec2,
        geometries: &[Geometry],
    ) {
        let p = &self.params;
        let n = p.steps;
        let k_count = neighbours.len();
        for column in [&mut self.nb_x, &mut self.nb_y, &mut self.nb_sigma] {
            column.resize((n + 1) * k_count, 0.0);
        }
        // Everyone as if `predicts_straight` (every perceived person is), all at once and
        // step-major so that the loops run across neighbours and vectorise: the bits of
        // `extrapolate_ctrv`'s straight line and `fill_constant_speed`.
        for (k, nb) in neighbours.iter().enumerate() {
            self.nb_x[k] = nb.position.x;
            self.nb_y[k] = nb.position.y;
            self.nb_sigma[k] = p.sigma.sigma0;
        }
        self.straight.clear();
        for nb in neighbours {
            let step = nb.velocity * p.dt;
            let (cap, growth) = p.sigma.constant_speed_growth(nb.velocity.norm());
            self.straight.push([step.x, step.y, cap, growth]);
        }
        for j in 1..=n {
            let (done, rest) = self.nb_x.split_at_mut(j * k_count);
            let (x_prev, x) = (&done[(j - 1) * k_count..], &mut rest[..k_count]);
            let (done, rest) = self.nb_y.split_at_mut(j * k_count);
            let (y_prev, y) = (&done[(j - 1) * k_count..], &mut rest[..k_count]);
            let (done, rest) = self.nb_sigma.split_at_mut(j * k_count);
            let (s_prev, s) = (&done[(j - 1) * k_count..], &mut rest[..k_count]);
            for k in 0..k_count {
                let [step_x, step_y, cap, growth] = self.straight[k];
                x[k] = x_prev[k] + step_x;
                y[k] = y_prev[k] + step_y;
                s[k] = cap.min(s_prev[k] + growth);
            }
        }
        // The rest (shared intents, turning neighbours) one by one, over the straight guess.
        self.tracks.resize_with(k_count, Track::default);
        for (k, (nb, track)) in neighbours.iter().zip(&mut self.tracks).enumerate() {
            if predicts_straight(nb) {
                continue;
            }
            predict(nb, p.dt, n, &p.sigma, track);
            debug_assert!(track.positions.len() == n + 1 && track.sigma.len() == n + 1);
            for (j, (q, &sigma)) in track.positions.iter().zip(&track.sigma).enumerate() {
                self.nb_x[j * k_count + k] = q.x;
                self.nb_y[j * k_count + k] = q.y;
                self.nb_sigma[j * k_count + k] = sigma;
            }
        }
        let (mut min, mut max) = (p0, p0);
        for g in geometries {
            for w in &g.waypoints {
                min = min.inf(w);
                max = max.sup(w);
            }
        }
        let sigma_cap = p.sigma.sigma_max(p.speed.max(p.v_max));
        map.gather(min, max, STATIC_RANGE_SIGMAS * sigma_cap, &mut self.local);
    }

    /// Everything of Eqs. 1–3 that does not depend on where the candidate is, and per step
    /// the neighbours that can matter.
    #[inline(always)]
    fn build_tables(&mut self, k_count: usize) {
        let n = self.params.steps;
        let stride = n + 1;
        let candidates = self.sampled.profile.len();
        let floor = self.params.risk_floor;
        let t = &mut self.tables;
        for v in [&mut t.ego_var, &mut t.ego_ratio, &mut t.ego_cull] {
            v.clear();
        }
        t.start.clear();
        // The neighbour columns are written in place and never shrunk (rows are read only
        // through `start`); a row holds at most every neighbour plus padding.
        for column in [
            &mut t.nb_x,
            &mut t.nb_y,
            &mut t.nb_var,
            &mut t.nb_ratio,
            &mut t.nb_cull,
            &mut t.nb_var0,
        ] {
            if column.len() < n * (k_count + LANES) {
                column.resize(n * (k_count + LANES), 0.0);
            }
        }
        let mut row = 0;
        for profile in &self.profiles {
            for &se in &profile[..n] {
                let ratio = profile[0] / se;
                t.ego_var.push(se * se);
                t.ego_ratio.push(ratio);
                t.ego_cull.push(if floor > 0.0 {
                    ln_upper_bound(ratio / floor)
                } else {
                    Real::INFINITY
                });
            }
        }
        let profiles = self.profiles.len();
        for j in 0..n {
            t.start.push(row);
            // Bounding box of every candidate's sample j, and the largest ego terms at j.
            let (mut min, mut max) = (self.sampled.positions[j], self.sampled.positions[j]);
            for l in 1..candidates {
                let q = self.sampled.positions[l * stride + j];
                min = min.inf(&q);
                max = max.sup(&q);
            }
            let ego_var = (0..profiles)
                .map(|g| t.ego_var[g * n + j])
                .fold(0.0, Real::max);
            let ego_cull = (0..profiles)
                .map(|g| t.ego_cull[g * n + j])
                .fold(Real::NEG_INFINITY, Real::max);
            // Per chunk of neighbours, straight-line loops into local columns (they
            // vectorise), then the neighbours that can matter appended in order, branch-free.
            let step = j * k_count..(j + 1) * k_count;
            let (xs, ys) = (&self.nb_x[step.clone()], &self.nb_y[step.clone()]);
            let sigma = &self.nb_sigma[step];
            let sigma0 = &self.nb_sigma[..k_count];
            for lo in (0..k_count).step_by(TABLE_CHUNK) {
                let hi = (lo + TABLE_CHUNK).min(k_count);
                let mut var = [0.0; TABLE_CHUNK];
                let mut ratio = [0.0; TABLE_CHUNK];
                let mut cull = [0.0; TABLE_CHUNK];
                let mut near = [false; TABLE_CHUNK];
                let columns = xs[lo..hi]
                    .iter()
                    .zip(&ys[lo..hi])
                    .zip(&sigma[lo..hi])
                    .zip(&sigma0[lo..hi]);
                for (c, (((&x, &y), &sj), &s0)) in columns.enumerate() {
                    let nb_ratio = s0 / sj;
                    let nb_cull = ln_upper_bound(nb_ratio);
                    let dx = (min.x - x).max(x - max.x).max(0.0);
                    let dy = (min.y - y).max(y - max.y).max(0.0);
                    var[c] = sj * sj;
                    ratio[c] = nb_ratio;
                    cull[c] = nb_cull;
                    // As the hazard loop's test: a NaN is kept.
                    let far = dx * dx + dy * dy >= 2.0 * (ego_var + sj * sj) * (ego_cull + nb_cull);
                    near[c] = !far;
                }
                for c in 0..hi - lo {
                    let k = lo + c;
                    t.nb_x[row] = xs[k];
                    t.nb_y[row] = ys[k];
                    t.nb_var[row] = var[c];
                    t.nb_ratio[row] = ratio[c];
                    t.nb_cull[row] = cull[c];
                    t.nb_var0[row] = sigma0[k] * sigma0[k];
                    row += usize::from(near[c]);
                }
            }
            // Whole blocks of `LANES`: the padding neighbours lie at infinity and are culled.
            while !row.is_multiple_of(LANES) {
                t.nb_x[row] = Real::INFINITY;
                t.nb_y[row] = Real::INFINITY;
                t.nb_var[row] = 1.0;
                t.nb_ratio[row] = 0.0;
                t.nb_cull[row] = 0.0;
                t.nb_var0[row] = 0.0;
                row += 1;
            }
        }
        t.start.push(row);
    }

    /// Survival (Eq. 5) and expected utility (Eqs. 7–8) of `count` candidates from their
    /// hazards. Runs inside [`PlanPass`].
    #[inline(always)]
    fn expected_utilities(&mut self, count: usize) -> Vec<Real> {
        let n = self.params.steps;
        let stride = n + 1;
        let s = &self.sampled;
        self.survival.resize(count * stride, 0.0);
        // Plain loops: a closure here would be compiled outside the dispatch, without its
        // instruction set.
        let mut expected = Vec::with_capacity(count);
        for l in 0..count {
            let surv = &mut self.survival[l * stride..(l + 1) * stride];
            crate::risk::survival(&self.hazards[l * n..(l + 1) * n], surv);
            // Eqs. 7–8: Σ_i p^surv_i · u_i over the planned samples i = 1..=steps.
            let mut sum = 0.0;
            for (p, u) in surv[1..]
                .iter()
                .zip(&s.utility[l * stride + 1..(l + 1) * stride])
            {
                sum += p * u;
            }
            expected.push(sum);
        }
        expected
    }

    /// Every candidate's per-step hazard (Eqs. 1–4 plus p^escape) into `self.hazards`. A
    /// candidate that starts like the previous one (same α, same first segment) reuses that
    /// one's hazards over the shared samples. Runs inside [`PlanPass`].
    #[inline(always)]
    fn fill_hazards(&mut self, geometries: &[Geometry], map: &StaticMap) {
        let n = self.params.steps;
        let stride = n + 1;
        let s = &self.sampled;
        self.hazards.clear();
        self.hazards.resize(geometries.len() * n, 0.0);
        for l in 0..geometries.len() {
            let shared = if l > 0 && s.profile[l] == s.profile[l - 1] {
                let (a, b) = (
                    &s.positions[(l - 1) * stride..l * stride],
                    &s.positions[l * stride..(l + 1) * stride],
                );
                a.iter().zip(b).take(n).take_while(|(x, y)| x == y).count()
            } else {
                0
            };
            if shared > 0 {
                self.hazards
                    .copy_within((l - 1) * n..(l - 1) * n + shared, l * n);
            }
            let g = s.profile[l];
            for j in shared..n {
                let pos = s.positions[l * stride + j];
                let t = &self.tables;
                let ego = EgoTerms {
                    pos,
                    var: t.ego_var[g * n + j],
                    var0: self.profiles[g][0] * self.profiles[g][0],
                    ratio: t.ego_ratio[g * n + j],
                    cull: t.ego_cull[g * n + j],
                };
                let row = t.start[j]..t.start[j + 1];
                let dynamic = dynamic_hazard(
                    &ego,
                    &t.nb_x[row.clone()],
                    &t.nb_y[row.clone()],
                    &t.nb_var[row.clone()],
                    &t.nb_ratio[row.clone()],
                    &t.nb_cull[row.clone()],
                    &t.nb_var0[row],
                );
                let p_static = if self.local.is_empty() {
                    0.0
                } else {
                    // Eq. 4 with the distance from the ego's mean to the nearest surface.
                    static_collision_probability(
                        self.local.distance(map, &pos),
                        s.sigma[l * stride + j],
                    )
                };
                self.hazards[l * n + j] = dynamic + p_static + self.params.p_escape;
            }
        }
    }

    fn trajectory(&self, l: usize) -> Vec<TrajectorySample> {
        let s = &self.sampled;
        let stride = self.params.steps + 1;
        (1..stride)
            .map(|i| TrajectorySample {
                t: i as Real * self.params.dt,
                position: s.positions[l * stride + i],
                sigma: s.sigma[l * stride + i],
            })
            .collect()
    }
}

/// Samples one candidate at t = i·dt with the turn slow-down, and its utility (Eq. 6),
/// appending to `s`.
#[inline(always)]
fn sample(p: &PgpParams, ego: &EgoState, g: &Geometry, pgp_goal: Vec2, s: &mut Sampled) {
    let n = p.steps;
    let seg_len = [
        (g.waypoints[1] - g.waypoints[0]).norm(),
        (g.waypoints[2] - g.waypoints[1]).norm(),
        (g.waypoints[3] - g.waypoints[2]).norm(),
    ];
    let total = seg_len[0] + seg_len[1] + seg_len[2];
    let dirs = segment_directions(&g.waypoints, &seg_len);
    // t^turn = γ^turn / γ̇^max at 0.5·v when the first segment needs more than 30° of turn.
    let turn = wrap_angle(angle_of(&(g.waypoints[1] - g.waypoints[0])) - ego.heading).abs();
    let t_turn = if turn > p.turn_threshold {
        turn / p.max_turn_rate
    } else {
        0.0
    };
    let slow = p.turn_slowdown * p.speed;
    let travelled = |t: Real| {
        if t <= t_turn {
            slow * t
        } else {
            slow * t_turn + p.speed * (t - t_turn)
        }
    };

    // The points on the path (branchy), then speeds and utilities in a straight-line loop
    // that vectorises.
    s.arcs.clear();
    s.headings.clear();
    s.arcs.push(0.0);
    s.headings.push(dirs[0]);
    let first = s.positions.len();
    s.positions.push(g.waypoints[0]);
    for i in 1..=n {
        let arc = travelled(i as Real * p.dt).min(total);
        let (pos, heading) = point_on_path_along(&g.waypoints, &seg_len, &dirs, arc);
        s.arcs.push(arc);
        s.headings.push(heading);
        s.positions.push(pos);
    }
    s.speeds.resize(first + n + 1, 0.0);
    s.utility.resize(first + n + 1, 0.0);
    let positions = &s.positions[first + 1..];
    let speeds = &mut s.speeds[first + 1..];
    let utility = &mut s.utility[first + 1..];
    for i in 0..n {
        let arc = s.arcs[i + 1];
        let v = (arc - s.arcs[i]) / p.dt;
        speeds[i] = v;
        let to_goal = pgp_goal - positions[i];
        let d = to_goal.norm();
        // Eq. 6: u = v / v^max · (cos β + 1) / 2.
        let cos_beta = s.headings[i + 1].dot(&to_goal) / d;
        let moving = v / p.v_max * (cos_beta + 1.0) / 2.0;
        // Once PGP's goal is reached the rest of the horizon is spent there; the paper does
        // not say what that earns (it places its goal a full horizon away). We give full
        // utility, so that a goal nearer than d_goal does not make detours look better.
        let arrived = arc >= total - 1e-9 || d < 1e-9;
        utility[i] = if arrived { 1.0 } else { moving };
    }
    s.sigma.resize(first + n + 1, 0.0);
    p.sigma.fill(&s.speeds[first..], &mut s.sigma[first..]);
}

/// The body of a PGP step, from sampling the candidates to their expected utilities, as one
/// operation that `pulp` compiles once per instruction set, so that its straight-line loops
/// run at the widest vector width the CPU has.
struct PlanPass<'a> {
    pgp: &'a mut Pgp,
    ego: &'a EgoState,
    neighbours: &'a [Neighbour],
    map: &'a StaticMap,
    geometries: &'a [Geometry],
    pgp_goal: Vec2,
}

impl pulp::WithSimd for PlanPass<'_> {
    type Output = Vec<Real>;

    /// Samples (Eq. 6), predictions, per-step tables, hazards (Eqs. 1–4 plus p^escape),
    /// survival (Eq. 5) and expected utility (Eqs. 7–8) of every candidate.
    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _: S) -> Vec<Real> {
        let (pgp, geometries) = (self.pgp, self.geometries);
        pgp.sample_all(self.ego, geometries, self.pgp_goal);
        pgp.predict(self.neighbours, self.map, self.ego.position, geometries);
        pgp.build_tables(self.neighbours.len());
        pgp.fill_hazards(geometries, self.map);
        pgp.expected_utilities(geometries.len())
    }
}

#[derive(Debug, Clone, Copy)]
struct Geometry {
    alpha: Real,
    d_outside: Real,
    waypoints: [Vec2; 4],
}

impl Geometry {
    /// The point at arc length `arc` along the path (its end if the path is shorter).
    fn point_at(&self, arc: Real) -> Vec2 {
        let w = &self.waypoints;
        let seg_len = [
            (w[1] - w[0]).norm(),
            (w[2] - w[1]).norm(),
            (w[3] - w[2]).norm(),
        ];
        point_on_path(w, &seg_len, arc).0
    }
}

/// Position and unit direction of travel at arc length `arc` along the three-segment path.
fn point_on_path(w: &[Vec2; 4], seg_len: &[Real; 3], arc: Real) -> (Vec2, Vec2) {
    point_on_path_along(w, seg_len, &segment_directions(w, seg_len), arc)
}

/// The unit direction of each segment (unused for segments of length ≤ 10⁻¹²).
#[inline(always)]
fn segment_directions(w: &[Vec2; 4], seg_len: &[Real; 3]) -> [Vec2; 3] {
    std::array::from_fn(|k| (w[k + 1] - w[k]) / seg_len[k])
}

/// [`point_on_path`] with the segment directions computed once.
#[inline(always)]
fn point_on_path_along(
    w: &[Vec2; 4],
    seg_len: &[Real; 3],
    dirs: &[Vec2; 3],
    arc: Real,
) -> (Vec2, Vec2) {
    let mut rest = arc;
    let mut last_dir = unit(0.0);
    for k in 0..3 {
        if seg_len[k] <= 1e-12 {
            continue;
        }
        let dir = dirs[k];
        last_dir = dir;
        if rest <= seg_len[k] {
            return (w[k] + dir * rest, dir);
        }
        rest -= seg_len[k];
    }
    (w[3], last_dir)
}

#[cfg(test)]
mod tests;
