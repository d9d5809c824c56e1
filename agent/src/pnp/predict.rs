//! What the perceived bodies may do (their predicted tracks, sampled) and the collision risk
//! p_coll^i a path runs with each (Eq. 5).

use super::risk::{
    Contact, Path, Scoring, cvar, first_contact_from, loss, step_gaps, step_gaps_from, tail_count,
    tail_mass, tail_mean,
};
use crate::math::{Real, Vec2, vec2};
use crate::model::{AgentKind, EgoState, Neighbour};
use crate::prediction::{SigmaModel, Track};
use crate::social_force::{SfParams, capped_velocity, social_force_pair};

/// One perceived body's prediction on the grid.
#[derive(Debug, Clone, Default)]
pub(super) struct Predicted {
    pub(super) track: Track,
    /// Centre distance that counts as collision.
    pub(super) contact: Real,
    /// How far a sample strays from the mean at most (m).
    pub(super) spread: Real,
    /// The box around the mean track, widened by `contact + spread`.
    pub(super) reach: (Vec2, Vec2),
    /// How far a sample with a unit offset strays from the mean at most during each grid
    /// step: `growth[k - 1]` = max(σ(k − 1), σ(k)) − σ(0).
    pub(super) growth: Vec<Real>,
    /// Each sample's offset for this body: the fixed offsets, squeezed across the body's way
    /// by [`PnpParams::across_spread`](super::PnpParams::across_spread) when it walks; no
    /// longer than the fixed ones, so every bound taken with their lengths still holds.
    pub(super) offsets: Vec<Vec2>,
}

impl Predicted {
    /// Sets this body's sample offsets from the fixed `offsets`: across `heading` (a unit
    /// vector) scaled by `across`, or as they are without a heading.
    pub(super) fn shape(&mut self, offsets: &[(Vec2, Real)], heading: Option<Vec2>, across: Real) {
        self.offsets.clear();
        self.offsets
            .extend(offsets.iter().map(|&(o, _)| match heading {
                Some(h) => {
                    let n = vec2(-h.y, h.x);
                    h * o.dot(&h) + n * (across * o.dot(&n))
                }
                None => o,
            }));
    }
}

/// Replaces the people's tracks in `predicted` with a Social Force rollout
/// ([`Prediction::SocialForce`]); σ grows with each step's speed as PGP's does.
pub(super) fn social_force_rollout(
    ego: &EgoState,
    neighbours: &[Neighbour],
    n: usize,
    dt: Real,
    sigma: &SigmaModel,
    predicted: &mut [Predicted],
) {
    let sf = SfParams::default();
    let people: Vec<usize> = (0..neighbours.len())
        .filter(|&i| neighbours[i].kind == AgentKind::Human)
        .collect();
    if people.is_empty() {
        return;
    }
    let mut pos: Vec<Vec2> = people.iter().map(|&i| neighbours[i].position).collect();
    let mut vel: Vec<Vec2> = people.iter().map(|&i| neighbours[i].velocity).collect();
    // Each keeps walking the way they walk: the desired velocity is the perceived one.
    let desired: Vec<Vec2> = vel.clone();
    // Per person, the speed at each grid point (the first, at t = 0, is not used by σ).
    let mut speeds = vec![vec![0.0]; people.len()];
    let mut force = vec![vec2(0.0, 0.0); people.len()];
    for (slot, &i) in people.iter().enumerate() {
        predicted[i].track.positions.clear();
        predicted[i].track.positions.push(pos[slot]);
    }
    for k in 1..=n {
        let robot = ego.position + ego.velocity * ((k - 1) as Real * dt);
        for a in 0..people.len() {
            let mut f = (desired[a] - vel[a]) / sf.desired.relaxation_time * sf.desired.factor;
            let mut social = social_force_pair(pos[a], vel[a], robot, ego.velocity, &sf.social);
            for b in 0..people.len() {
                if b != a {
                    social += social_force_pair(pos[a], vel[a], pos[b], vel[b], &sf.social);
                }
            }
            f += social * sf.social.factor;
            force[a] = f;
        }
        for a in 0..people.len() {
            let cap = desired[a].norm() * sf.max_speed_multiplier;
            vel[a] = capped_velocity(vel[a] + force[a] * dt, cap);
            pos[a] += vel[a] * dt;
            speeds[a].push(vel[a].norm());
            predicted[people[a]].track.positions.push(pos[a]);
        }
    }
    for (slot, &i) in people.iter().enumerate() {
        let track = &mut predicted[i].track;
        track.sigma.resize(n + 1, 0.0);
        sigma.fill(&speeds[slot], &mut track.sigma);
    }
}

/// Whether any of body's samples may come within contact of `path`: no sample comes closer
/// than the mean minus the largest offset, checked first by boxes, then along the tracks
/// (whose gap per grid step is left in `gaps`). With `shared`, the gaps over the path's first
/// `tail` grid steps are taken from its siblings' [`Shared`] entry.
pub(super) fn might_touch(
    path: Path,
    body: &Predicted,
    shared: Option<(&Shared, usize)>,
    gaps: &mut Vec<Real>,
) -> bool {
    if !path.box_meets(body.reach) {
        return false;
    }
    let mean = |k: usize| body.track.positions[k];
    let closest = match shared {
        Some((s, tail)) => {
            gaps.clear();
            gaps.extend_from_slice(&s.gaps);
            s.closest.min(step_gaps_from(path.points, tail, mean, gaps))
        }
        None => step_gaps(path.points, mean, gaps),
    };
    closest <= body.contact + body.spread
}

/// The first grid step (0-based, from k to k + 1) during which a sample offset by `r` (its
/// offset's length) may be within contact: during step k it is at least
/// `gaps[k] − r·growth[k]` from the path (the triangle inequality). The margin keeps steps
/// whose bound only rounding could bring within contact.
fn first_step_within(gaps: &[Real], body: &Predicted, r: Real) -> Option<usize> {
    gaps.iter()
        .zip(&body.growth)
        .position(|(g, s)| g - r * s <= body.contact * (1.0 + 1e-9) + 1e-9)
}

/// What a run of siblings' shared path (grid points 0 to `tail`, see
/// [`Candidates::shared_until`](super::candidates::Candidates::shared_until)) meets of one
/// body: the gaps over its steps, each sample's first contact within them, and the CVaR of
/// those contacts' losses (the rest taken as 0), a lower bound of every sibling's p_coll^i.
#[derive(Debug, Clone, Default)]
pub(super) struct Shared {
    gaps: Vec<Real>,
    closest: Real,
    contacts: Vec<Option<Contact>>,
    bound: Real,
    losses: Vec<Real>,
}

impl Shared {
    /// Fills the entry for the shared path `prefix` of candidates on an n-step grid, their
    /// p_coll^i a CVaR_α.
    pub(super) fn fill(
        &mut self,
        prefix: &[Vec2],
        body: &Predicted,
        offsets: &[(Vec2, Real)],
        alpha: Real,
        n: usize,
        scoring: Scoring,
    ) {
        let track = &body.track;
        self.closest = step_gaps(prefix, |k| track.positions[k], &mut self.gaps);
        self.contacts.clear();
        self.losses.clear();
        for (&(_, r), &o) in offsets.iter().zip(&body.offsets) {
            let contact = first_step_within(&self.gaps, body, r).and_then(|from| {
                first_contact_from(
                    prefix,
                    body.contact,
                    |k| track.positions[k] + o * (track.sigma[k] - track.sigma[0]),
                    from + 1,
                )
            });
            self.contacts.push(contact);
            self.losses.push(loss(contact, n, scoring));
        }
        let tail = tail_mass(alpha, offsets.len());
        self.losses.sort_unstable_by(|a, b| b.total_cmp(a));
        self.losses.truncate(tail_count(tail, offsets.len()));
        self.bound = tail_mean(&self.losses, tail);
    }
}

/// p_coll^i: CVaR_α of the collision loss over body i's prediction samples (each offset
/// with its length), for one path. `None` as soon as the samples traced so far put it above
/// `budget` (a candidate that cannot win then needs no more of them); a finite budget only
/// cuts the work short, never changes a value returned. With `shared`, what the path's first
/// `tail` grid steps meet of the body, as [`Shared::fill`] left it for this path's siblings,
/// is taken from there: the same values, with the work of one sibling.
pub(super) fn body_risk(
    path: Path,
    body: &Predicted,
    offsets: &[(Vec2, Real)],
    (alpha, scoring): (Real, Scoring),
    budget: Real,
    shared: Option<(&Shared, usize)>,
    scratch: &mut Scratch,
) -> Option<Real> {
    let track = &body.track;
    if !might_touch(path, body, shared, &mut scratch.gaps) {
        return Some(0.0);
    }
    if let Some((s, _)) = shared
        && s.bound > budget
    {
        return None;
    }
    let path = path.points;
    let n = path.len() - 1;
    let tail = tail_mass(alpha, offsets.len());
    let Scratch {
        gaps,
        losses,
        worst,
    } = scratch;
    losses.clear();
    worst.clear();
    for (j, (&(_, r), &o)) in offsets.iter().zip(&body.offsets).enumerate() {
        // The scan starts at the first step where the sample may be within contact, and a
        // sample with none scores 0 untraced.
        let Some(from) = first_step_within(gaps, body, r) else {
            losses.push(0.0);
            continue;
        };
        let sample = |k| track.positions[k] + o * (track.sigma[k] - track.sigma[0]);
        let contact = match shared {
            // The shared steps were scanned from the same step: their first contact, or the
            // scan goes on after them.
            Some((s, tail)) if from < tail => {
                s.contacts[j].or_else(|| first_contact_from(path, body.contact, sample, tail + 1))
            }
            _ => first_contact_from(path, body.contact, sample, from + 1),
        };
        let l = loss(contact, n, scoring);
        losses.push(l);
        if l > 0.0 && budget.is_finite() {
            // The largest losses so far, largest first: the CVaR is at least their tail mean.
            if worst.len() < tail_count(tail, offsets.len()) {
                worst.push(l);
            } else if let Some(last) = worst.last_mut().filter(|last| l > **last) {
                *last = l;
            } else {
                continue;
            }
            let mut i = worst.len() - 1;
            while i > 0 && worst[i - 1] < worst[i] {
                worst.swap(i - 1, i);
                i -= 1;
            }
            if tail_mean(worst, tail) > budget {
                return None;
            }
        }
    }
    Some(cvar(losses, alpha))
}

/// Buffers [`body_risk`] reuses between calls.
#[derive(Debug, Clone, Default)]
pub(super) struct Scratch {
    pub(super) gaps: Vec<Real>,
    pub(super) losses: Vec<Real>,
    pub(super) worst: Vec<Real>,
}
