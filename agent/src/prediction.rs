//! Where the neighbours will be: constant-velocity-constant-turn-rate extrapolation, or the
//! trajectory a robot announced, each with a growing positional uncertainty σ.
//!
//! The σ growth is the PGP paper's (Sec. IV-C.2):
//! σ_max = min(β·σ0, σ0 + γ·max_i v_i) and σ_i = min(σ_max, σ_{i-1} + δ·v_i).

use crate::math::{Real, Vec2, angle_of, unit};
use crate::model::{Neighbour, SharedIntent};

/// Parameters of the σ growth (PGP paper, Sec. IV-C.2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SigmaModel {
    /// σ0: initial standard deviation (m).
    pub sigma0: Real,
    /// β: cap as a multiple of σ0.
    pub beta: Real,
    /// γ: cap growth per m/s of the largest predicted speed (s).
    pub gamma: Real,
    /// δ: growth per step per m/s of predicted speed (s).
    pub delta: Real,
}

impl Default for SigmaModel {
    /// The paper's values: σ0 = 0.1666, β = 3.0, γ = 0.4, δ = 0.015.
    fn default() -> Self {
        Self {
            sigma0: 0.1666,
            beta: 3.0,
            gamma: 0.4,
            delta: 0.015,
        }
    }
}

impl SigmaModel {
    /// σ_max for a trajectory whose largest speed is `max_speed`.
    #[inline]
    pub fn sigma_max(&self, max_speed: Real) -> Real {
        (self.beta * self.sigma0).min(self.sigma0 + self.gamma * max_speed)
    }

    /// σ_max and the growth per step δ·speed of a constant speed: σ_i = min(σ_max, σ_{i-1} +
    /// δ·speed).
    #[inline]
    pub fn constant_speed_growth(&self, speed: Real) -> (Real, Real) {
        (self.sigma_max(speed), self.delta * speed)
    }

    /// σ_1, σ_2, … for a constant speed: each step grows σ by δ·speed up to σ_max(speed).
    pub fn constant_speed(&self, speed: Real) -> impl Iterator<Item = Real> + use<> {
        let (cap, growth) = self.constant_speed_growth(speed);
        std::iter::successors(Some(self.sigma0), move |s| Some(cap.min(s + growth))).skip(1)
    }

    /// Fills `sigma` with σ_0 = σ0 and [`constant_speed`](Self::constant_speed)'s σ_1, σ_2, …
    /// (the same numbers, without an iterator's per-item bookkeeping).
    pub fn fill_constant_speed(&self, speed: Real, sigma: &mut [Real]) {
        let (cap, growth) = self.constant_speed_growth(speed);
        let mut s = self.sigma0;
        for slot in sigma {
            *slot = s;
            s = cap.min(s + growth);
        }
    }

    /// Fills `sigma[0..=n]` for the speeds `speeds[1..=n]` (`speeds[0]` is ignored):
    /// σ_0 = σ0, σ_i = min(σ_max, σ_{i-1} + δ·v_i).
    #[inline]
    pub fn fill(&self, speeds: &[Real], sigma: &mut [Real]) {
        debug_assert_eq!(speeds.len(), sigma.len());
        let max_speed = speeds.iter().skip(1).fold(0.0, |m: Real, &v| m.max(v));
        let cap = self.sigma_max(max_speed);
        sigma[0] = self.sigma0;
        for i in 1..sigma.len() {
            sigma[i] = cap.min(sigma[i - 1] + self.delta * speeds[i]);
        }
    }
}

/// A predicted track sampled on the planner's time grid: `positions[i]` and `sigma[i]` at
/// t = i·dt, i = 0..=n.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Track {
    /// Mean positions.
    pub positions: Vec<Vec2>,
    /// Standard deviations.
    pub sigma: Vec<Real>,
}

/// Whether a turn rate counts as none: the motion is then a straight line.
#[inline]
pub fn goes_straight(yaw_rate: Real) -> bool {
    yaw_rate.abs() < 1e-9
}

/// Whether [`predict`] extrapolates `neighbour` on a straight line at constant speed (no
/// shared intent, no turn rate): position i·dt·velocity from its own, σ as
/// [`SigmaModel::fill_constant_speed`] for its speed.
#[inline]
pub fn predicts_straight(neighbour: &Neighbour) -> bool {
    neighbour.intent.is_none() && goes_straight(neighbour.yaw_rate)
}

/// Extrapolates a neighbour with constant speed and constant turn rate onto t = i·dt,
/// i = 0..=n, writing into `track` (reusing its buffers).
pub fn extrapolate_ctrv(
    neighbour: &Neighbour,
    dt: Real,
    n: usize,
    model: &SigmaModel,
    track: &mut Track,
) {
    let speed = neighbour.velocity.norm();
    let omega = neighbour.yaw_rate;
    track.positions.resize(n + 1, neighbour.position);
    if goes_straight(omega) {
        // Constant velocity: no trigonometry per sample. Sample 0 is written too: the track
        // may hold another neighbour's samples from an earlier plan.
        track.positions[0] = neighbour.position;
        let step = neighbour.velocity * dt;
        let mut p = neighbour.position;
        for slot in &mut track.positions[1..] {
            p += step;
            *slot = p;
        }
    } else {
        let heading = angle_of(&neighbour.velocity);
        for (i, slot) in track.positions.iter_mut().enumerate() {
            *slot = neighbour.position + ctrv_offset(speed, heading, omega, i as Real * dt);
        }
    }
    track.sigma.resize(n + 1, 0.0);
    model.fill_constant_speed(speed, &mut track.sigma);
}

/// Displacement after time `t` driving at `speed` from `heading` while turning at `omega`.
#[inline]
pub fn ctrv_offset(speed: Real, heading: Real, omega: Real, t: Real) -> Vec2 {
    if goes_straight(omega) {
        return unit(heading) * (speed * t);
    }
    let r = speed / omega;
    let (s0, c0) = heading.sin_cos();
    let (s1, c1) = (heading + omega * t).sin_cos();
    Vec2::new(r * (s1 - s0), r * (c0 - c1))
}

/// Resamples an announced trajectory onto t = i·dt, i = 0..=n. Sample 0 is the neighbour's
/// observed position with σ0 (the paper's normalisation needs σ at i = 0). Between announced
/// samples positions and σ are interpolated linearly; before the first sample the track blends
/// from the observed position; after the last it continues at the last segment's velocity with
/// σ growing by the model.
pub fn resample_intent(
    neighbour: &Neighbour,
    intent: &SharedIntent,
    dt: Real,
    n: usize,
    model: &SigmaModel,
    track: &mut Track,
) {
    track.positions.clear();
    track.sigma.clear();
    let samples = &intent.samples;
    let first_t = samples.first().map_or(0.0, |s| s.t);
    let (tail_velocity, last) = match samples.len() {
        0 => (neighbour.velocity, None),
        1 => (neighbour.velocity, samples.last()),
        len => {
            let (a, b) = (&samples[len - 2], &samples[len - 1]);
            let span = (b.t - a.t).max(1e-6);
            ((b.position - a.position) / span, Some(b))
        }
    };
    let tail_speed = tail_velocity.norm();
    let mut seg = 0;
    for i in 0..=n {
        let t = i as Real * dt;
        let (p, s) = if i == 0 {
            (neighbour.position, model.sigma0)
        } else if samples.is_empty() {
            (
                neighbour.position + tail_velocity * t,
                model.sigma0 + model.delta * tail_speed * i as Real,
            )
        } else if t <= first_t {
            let w = if first_t > 0.0 { t / first_t } else { 1.0 };
            let s0 = &samples[0];
            (
                neighbour.position + (s0.position - neighbour.position) * w,
                model.sigma0 + (s0.sigma - model.sigma0) * w,
            )
        } else if let Some(last) = last.filter(|l| t >= l.t) {
            let extra_steps = (t - last.t) / dt;
            (
                last.position + tail_velocity * (t - last.t),
                last.sigma + model.delta * tail_speed * extra_steps,
            )
        } else {
            while seg + 1 < samples.len() && samples[seg + 1].t < t {
                seg += 1;
            }
            let (a, b) = (&samples[seg], &samples[(seg + 1).min(samples.len() - 1)]);
            let span = b.t - a.t;
            let w = if span > 0.0 {
                ((t - a.t) / span).clamp(0.0, 1.0)
            } else {
                0.0
            };
            (
                a.position + (b.position - a.position) * w,
                a.sigma + (b.sigma - a.sigma) * w,
            )
        };
        track.positions.push(p);
        // Announced σ may exceed the model's cap; the announcement wins, but never below σ0.
        track.sigma.push(s.max(model.sigma0));
    }
}

/// Predicts a neighbour: its shared intent when it has one, else CTRV extrapolation.
pub fn predict(neighbour: &Neighbour, dt: Real, n: usize, model: &SigmaModel, track: &mut Track) {
    match &neighbour.intent {
        Some(intent) => resample_intent(neighbour, intent, dt, n, model, track),
        None => extrapolate_ctrv(neighbour, dt, n, model, track),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::vec2;
    use crate::model::{AgentKind, TrajectorySample};

    #[test]
    fn filled_constant_speed_sigma_is_the_iterators() {
        let m = SigmaModel::default();
        for speed in [0.0, 0.3, 1.0, 1.7, 40.0] {
            let mut filled = vec![0.0; 33];
            m.fill_constant_speed(speed, &mut filled);
            let iterated: Vec<Real> = std::iter::once(m.sigma0)
                .chain(m.constant_speed(speed).take(32))
                .collect();
            assert_eq!(filled, iterated, "speed {speed}");
        }
    }

    #[test]
    fn sigma_grows_by_delta_v_and_caps_at_three_sigma0() {
        let m = SigmaModel::default();
        let speeds = vec![1.0; 33];
        let mut sigma = vec![0.0; 33];
        m.fill(&speeds, &mut sigma);
        assert_eq!(sigma[0], 0.1666);
        assert!((sigma[1] - (0.1666 + 0.015)).abs() < 1e-12);
        // σ_max = min(3·0.1666, 0.1666 + 0.4·1) = 0.4998.
        assert!((sigma[32] - 0.4998).abs() < 1e-12);
        assert!(sigma.windows(2).all(|w| w[1] >= w[0]));
    }

    #[test]
    fn sigma_stays_constant_at_standstill() {
        let m = SigmaModel::default();
        let mut sigma = vec![0.0; 33];
        m.fill(&[0.0; 33], &mut sigma);
        assert!(sigma.iter().all(|&s| s == m.sigma0));
    }

    #[test]
    fn ctrv_goes_straight_without_turn_rate_and_circles_with_it() {
        let d = ctrv_offset(1.0, 0.0, 0.0, 2.0);
        assert!((d - vec2(2.0, 0.0)).norm() < 1e-12);
        // Quarter circle of radius 1: speed 1, ω = 1, t = π/2.
        let d = ctrv_offset(1.0, 0.0, 1.0, std::f64::consts::FRAC_PI_2);
        assert!((d - vec2(1.0, 1.0)).norm() < 1e-12);
    }

    #[test]
    fn a_reused_track_holds_only_the_new_neighbours_samples() {
        let m = SigmaModel::default();
        let mut track = Track::default();
        for (position, omega) in [(vec2(5.0, -3.0), 0.0), (vec2(-1.0, 2.0), 0.7)] {
            let earlier =
                Neighbour::new(7, vec2(40.0, 40.0), vec2(0.5, 0.0), 0.3, AgentKind::Human);
            predict(&earlier, 0.25, 8, &m, &mut track);
            let mut n = Neighbour::new(1, position, vec2(1.0, 0.5), 0.3, AgentKind::Human);
            n.yaw_rate = omega;
            predict(&n, 0.25, 8, &m, &mut track);
            let mut fresh = Track::default();
            predict(&n, 0.25, 8, &m, &mut fresh);
            assert_eq!(track, fresh, "ω = {omega}");
            assert_eq!(track.positions[0], position);
        }
    }

    #[test]
    fn shared_intent_replaces_extrapolation() {
        let mut n = Neighbour::new(1, vec2(0.0, 0.0), vec2(1.0, 0.0), 0.3, AgentKind::Robot);
        n.intent = Some(SharedIntent {
            samples: (1..=4)
                .map(|i| TrajectorySample {
                    t: i as f64 * 0.5,
                    position: vec2(0.0, i as f64 * 0.5),
                    sigma: 0.2,
                })
                .collect(),
        });
        let mut track = Track::default();
        predict(&n, 0.25, 8, &SigmaModel::default(), &mut track);
        // The robot announced it drives up the y axis, although it currently moves along x.
        assert!((track.positions[4] - vec2(0.0, 1.0)).norm() < 1e-12);
        assert!((track.positions[8] - vec2(0.0, 2.0)).norm() < 1e-12);
        assert!((track.sigma[4] - 0.2).abs() < 1e-12);
    }
}
