//! The Probabilistic Gap Planner (PGP paper, Sec. III): a fan of candidate trajectories around
//! the straight line to the goal, each scored by its expected utility under the cooperative
//! collision risk, and a subgoal along the initial heading of the best one.
//!
//! Per plan: neighbours are predicted once (`prediction`), then for every candidate and step
//! the hazard Σ_k p^coll,coop + p^coll,static + p^escape is accumulated into the survival
//! probability (Eq. 5) that discounts the utility (Eqs. 6–8).

use crate::map::{LocalMap, StaticMap};
use crate::math::{Real, Vec2, angle_of, rotate, unit, wrap_angle};
use crate::model::{EgoState, Neighbour, TrajectorySample};
use crate::prediction::{SigmaModel, Track, predict};
use crate::risk::static_collision_probability;

/// Terms of Eq. 1 whose exponent is below −40 (≈ 4·10⁻¹⁸, under half an ulp of p^escape) are
/// skipped: they cannot change the hazard sum.
const EXPONENT_CUTOFF: Real = 40.0;
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
    /// d_goal: distance of PGP's own goal along the line to the map goal (m).
    pub d_goal: Real,
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
            d_goal: 8.0,
            fan_angles: (-5..=5).map(|i| (16.0 * i as Real).to_radians()).collect(),
            d_turned: 2.5,
            outside_fraction: 0.9,
            turn_threshold: 30f64.to_radians(),
            max_turn_rate: 1.0,
            turn_slowdown: 0.5,
            sigma: SigmaModel::default(),
            p_escape: 0.01,
            subgoal_distance: 2.0,
            record_fan: true,
        }
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

/// A sampled candidate: positions, per-interval speeds, utilities and ego σ, i = 0..=steps.
#[derive(Debug, Clone, Default)]
struct Sampled {
    positions: Vec<Vec2>,
    speeds: Vec<Real>,
    utility: Vec<Real>,
    sigma: Vec<Real>,
}

/// The Probabilistic Gap Planner with its reusable buffers.
#[derive(Debug, Clone, Default)]
pub struct Pgp {
    params: PgpParams,
    tracks: Vec<Track>,
    /// Neighbour predictions flattened step-major: index j·K + k.
    nb_pos: Vec<Vec2>,
    nb_var: Vec<Real>,
    nb_sigma_ratio: Vec<Real>,
    nb_var0: Vec<Real>,
    local: LocalMap,
    sampled: Sampled,
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

    /// One PGP step: evaluate the fan and return the subgoal.
    pub fn plan(
        &mut self,
        ego: &EgoState,
        neighbours: &[Neighbour],
        map: &StaticMap,
        goal: Vec2,
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
        let pgp_goal = p0 + dir * self.params.d_goal.min(dist_goal);
        let geometries = self.candidate_geometries(p0, dir, pgp_goal);
        self.prepare(neighbours, map, p0, &geometries);

        let mut best = (0, Real::NEG_INFINITY);
        let mut fan = Vec::with_capacity(if self.params.record_fan {
            geometries.len()
        } else {
            0
        });
        let mut best_trajectory = Vec::new();
        for (c, geometry) in geometries.iter().enumerate() {
            self.sample(ego, geometry, pgp_goal);
            let expected = self.evaluate(neighbours.len(), map);
            if expected > best.1 {
                best = (c, expected);
                best_trajectory = self.trajectory();
            }
            if self.params.record_fan {
                fan.push(Candidate {
                    alpha: geometry.alpha,
                    d_outside: geometry.d_outside,
                    positions: self.sampled.positions.clone(),
                    survival: self.survival.clone(),
                    expected_utility: expected,
                });
            }
        }
        let alpha = geometries[best.0].alpha;
        let subgoal = p0 + rotate(&dir, alpha) * self.params.subgoal_distance.min(dist_goal);
        let fan = self.params.record_fan.then_some(Fan {
            pgp_goal,
            candidates: fan,
            best: best.0,
        });
        PgpDecision {
            subgoal,
            trajectory: best_trajectory,
            fan,
        }
    }

    /// Sec. III-B: three-segment paths, 11 angles × d_outside ∈ {0, 0.9·remaining}.
    fn candidate_geometries(&self, p0: Vec2, dir: Vec2, pgp_goal: Vec2) -> Vec<Geometry> {
        let p = &self.params;
        let mut out = Vec::with_capacity(2 * p.fan_angles.len());
        for &alpha in &p.fan_angles {
            let p_out = p0 + rotate(&dir, alpha) * p.d_turned;
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

    /// Predicts the neighbours and gathers the static geometry around the fan.
    fn prepare(
        &mut self,
        neighbours: &[Neighbour],
        map: &StaticMap,
        p0: Vec2,
        geometries: &[Geometry],
    ) {
        let p = &self.params;
        let n = p.steps;
        let k_count = neighbours.len();
        self.tracks.resize_with(k_count, Track::default);
        for (nb, track) in neighbours.iter().zip(&mut self.tracks) {
            predict(nb, p.dt, n, &p.sigma, track);
        }
        self.nb_pos.clear();
        self.nb_var.clear();
        self.nb_sigma_ratio.clear();
        self.nb_var0.clear();
        for j in 0..=n {
            for track in &self.tracks[..k_count] {
                let s = track.sigma[j];
                self.nb_pos.push(track.positions[j]);
                self.nb_var.push(s * s);
                self.nb_sigma_ratio.push(track.sigma[0] / s);
            }
        }
        self.nb_var0.extend(
            self.tracks[..k_count]
                .iter()
                .map(|t| t.sigma[0] * t.sigma[0]),
        );

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

    /// Samples one candidate at t = i·dt with the turn slow-down, and its utility (Eq. 6).
    fn sample(&mut self, ego: &EgoState, g: &Geometry, pgp_goal: Vec2) {
        let p = &self.params;
        let n = p.steps;
        let s = &mut self.sampled;
        s.positions.clear();
        s.speeds.clear();
        s.utility.clear();
        s.sigma.resize(n + 1, 0.0);

        let seg_len = [
            (g.waypoints[1] - g.waypoints[0]).norm(),
            (g.waypoints[2] - g.waypoints[1]).norm(),
            (g.waypoints[3] - g.waypoints[2]).norm(),
        ];
        let total = seg_len[0] + seg_len[1] + seg_len[2];
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

        s.positions.push(g.waypoints[0]);
        s.speeds.push(0.0);
        s.utility.push(0.0);
        let mut prev = 0.0;
        for i in 1..=n {
            let arc = travelled(i as Real * p.dt).min(total);
            let (pos, heading) = point_on_path(&g.waypoints, &seg_len, arc);
            let v = (arc - prev) / p.dt;
            prev = arc;
            s.positions.push(pos);
            s.speeds.push(v);
            let to_goal = pgp_goal - pos;
            let d = to_goal.norm();
            // Once PGP's goal is reached the rest of the horizon is spent there; the paper does
            // not say what that earns (it places its goal a full horizon away). We give full
            // utility, so that a goal nearer than d_goal does not make detours look better.
            let u = if arc >= total - 1e-9 || d < 1e-9 {
                1.0
            } else {
                let cos_beta = heading.dot(&to_goal) / d;
                // Eq. 6: u = v / v^max · (cos β + 1) / 2.
                v / p.v_max * (cos_beta + 1.0) / 2.0
            };
            s.utility.push(u);
        }
        p.sigma.fill(&s.speeds, &mut s.sigma);
    }

    /// Hazards (Eqs. 1–4 plus p^escape), survival (Eq. 5) and expected utility (Eqs. 7–8) of
    /// the sampled candidate.
    fn evaluate(&mut self, k_count: usize, map: &StaticMap) -> Real {
        let p = &self.params;
        let n = p.steps;
        let s = &self.sampled;
        let sigma0 = s.sigma[0];
        self.hazards.clear();
        for j in 0..n {
            let pos = s.positions[j];
            let se = s.sigma[j];
            let se2 = se * se;
            let ego_ratio = sigma0 / se;
            let base = j * k_count;
            let mut dynamic = 0.0;
            for k in 0..k_count {
                let d = pos - self.nb_pos[base + k];
                let d2 = d.x * d.x + d.y * d.y;
                let var = se2 + self.nb_var[base + k];
                if d2 >= 2.0 * EXPONENT_CUTOFF * var {
                    continue;
                }
                let var0 = sigma0 * sigma0 + self.nb_var0[k];
                // Eq. 1 · Eq. 2 = Eq. 3.
                let p_coll = (-d2 / (2.0 * var)).exp() * var0 / var;
                let tau = ego_ratio * self.nb_sigma_ratio[base + k];
                dynamic += p_coll * tau;
            }
            let p_static = if self.local.is_empty() {
                0.0
            } else {
                // Eq. 4 with the distance from the ego's mean to the nearest surface.
                static_collision_probability(self.local.distance(map, &pos), se)
            };
            self.hazards.push(dynamic + p_static + p.p_escape);
        }
        self.survival.resize(n + 1, 0.0);
        crate::risk::survival(&self.hazards, &mut self.survival);
        // Eqs. 7–8: Σ_i p^surv_i · u_i over the planned samples i = 1..=steps.
        (1..=n).map(|i| self.survival[i] * s.utility[i]).sum()
    }

    fn trajectory(&self) -> Vec<TrajectorySample> {
        let s = &self.sampled;
        (1..s.positions.len())
            .map(|i| TrajectorySample {
                t: i as Real * self.params.dt,
                position: s.positions[i],
                sigma: s.sigma[i],
            })
            .collect()
    }
}

#[derive(Debug, Clone, Copy)]
struct Geometry {
    alpha: Real,
    d_outside: Real,
    waypoints: [Vec2; 4],
}

/// Position and unit direction of travel at arc length `arc` along the three-segment path.
fn point_on_path(w: &[Vec2; 4], seg_len: &[Real; 3], arc: Real) -> (Vec2, Vec2) {
    let mut rest = arc;
    let mut last_dir = unit(0.0);
    for k in 0..3 {
        if seg_len[k] <= 1e-12 {
            continue;
        }
        let dir = (w[k + 1] - w[k]) / seg_len[k];
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
