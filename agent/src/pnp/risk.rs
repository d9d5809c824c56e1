//! Contacts between paths on a common time grid, and the risk measures of peek-and-pass:
//! when two bodies moving straight between grid points first touch and how fast they close,
//! the loss of such a contact, and CVaR over equally likely losses.

use super::Severity;
use crate::math::{Real, Vec2, segment_distance, vec2};

/// Whether the chord `a`–`b` passes within `radius` of any of `segments`.
pub(super) fn near_any_segment(a: Vec2, b: Vec2, segments: &[(Vec2, Vec2)], radius: Real) -> bool {
    // Boxes further apart than the radius on either axis hold segments further apart than it
    // (the margin leaves the exact test every case rounding could decide).
    let reach = radius + 1e-9;
    let (lo, hi) = (a.inf(&b), a.sup(&b));
    segments.iter().any(|&(c, d)| {
        let (clo, chi) = (c.inf(&d), c.sup(&d));
        let apart = clo.x - hi.x > reach
            || lo.x - chi.x > reach
            || clo.y - hi.y > reach
            || lo.y - chi.y > reach;
        !apart && segment_distance(a, b, c, d) < radius
    })
}

/// A candidate's path on the time grid, with the smallest box holding it.
#[derive(Debug, Clone, Copy)]
pub(super) struct Path<'a> {
    pub(super) points: &'a [Vec2],
    pub(super) lo: Vec2,
    pub(super) hi: Vec2,
}

impl<'a> Path<'a> {
    pub(super) fn new(points: &'a [Vec2]) -> Self {
        let (lo, hi) = bounds(points);
        Self { points, lo, hi }
    }

    /// Whether the path's box and the box `lo`–`hi` share a point.
    pub(super) fn box_meets(&self, (lo, hi): (Vec2, Vec2)) -> bool {
        !(self.hi.x < lo.x || self.lo.x > hi.x || self.hi.y < lo.y || self.lo.y > hi.y)
    }
}

/// The smallest box holding `points`.
pub(super) fn bounds(points: &[Vec2]) -> (Vec2, Vec2) {
    points.iter().fold(
        (
            vec2(Real::INFINITY, Real::INFINITY),
            vec2(Real::NEG_INFINITY, Real::NEG_INFINITY),
        ),
        |(lo, hi), p| (lo.inf(p), hi.sup(p)),
    )
}

/// How fast relative position `d` shrinks when it changes by `e` per step (≥ 0).
fn closing(d: Vec2, e: Vec2) -> Real {
    let n = d.norm();
    if n > 0.0 {
        (-d.dot(&e) / n).max(0.0)
    } else {
        e.norm()
    }
}

/// The loss of one sampled future: 0 without collision; with a first contact at t_c closing
/// at speed u, (1 − t_c/t_f)·min(1, u / u_ref): the sooner and the harder, the worse (u_ref,
/// the fastest closing of note, is the robot's top speed plus the walking speed). The paper
/// does not say how it scores a collision. A 0/1 indicator, and imminence alone, were tried
/// first: once a person's predicted path runs into the robot wherever it goes (a constant-
/// velocity prediction does not give way), every candidate scores alike and progress decides,
/// so the robot drove into people it could have waited for. Closing speed tells "walked into
/// while standing" from "drove into", and still counts a fast walker from behind (the paper's
/// "rear-end panic"). [`Severity::Indicator`] scores every contact 1 (the paper's
/// "chance of collision").
pub(super) fn loss(contact: Option<Contact>, n: usize, scoring: Scoring) -> Real {
    contact.map_or(0.0, |c| {
        let speed = match scoring.severity {
            Severity::Indicator => return 1.0,
            Severity::Closing => c.closing,
            Severity::Driving => c.driving,
        };
        (1.0 - c.at / n as Real) * (speed / scoring.reference.max(1e-9)).min(1.0)
    })
}

/// How a contact's loss is scaled: by which speed, against what reference (m per grid step).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Scoring {
    pub(super) reference: Real,
    pub(super) severity: Severity,
}

/// CVaR_α of equally likely `losses` (reordered): the mean of the worst (1 − α) of them, the
/// last counted in part (Rockafellar–Uryasev for a discrete distribution).
pub fn cvar(losses: &mut [Real], alpha: Real) -> Real {
    let n = losses.len();
    if n == 0 {
        return 0.0;
    }
    if losses.iter().all(|&l| l == 0.0) {
        return 0.0;
    }
    let tail = tail_mass(alpha, n);
    // Only the ⌈tail⌉ largest count ([`tail_mean`]), and only they are put in order.
    let worst = tail_count(tail, n);
    if worst < n {
        losses.select_nth_unstable_by(worst - 1, |a, b| b.total_cmp(a));
    }
    let worst = &mut losses[..worst];
    worst.sort_unstable_by(|a, b| b.total_cmp(a));
    tail_mean(worst, tail)
}

/// The number of equally likely outcomes in CVaR_α's tail, (1 − α)·n (> 0).
pub(super) fn tail_mass(alpha: Real, n: usize) -> Real {
    ((1.0 - alpha) * n as Real).max(1e-12)
}

/// How many of n outcomes a tail of `tail` outcomes takes, whole or in part: ⌈tail⌉
/// (subtracting 1 from the mass is exact, so the count is too).
pub(super) fn tail_count(tail: Real, n: usize) -> usize {
    (tail.ceil() as usize).clamp(1, n)
}

/// The mean over a tail of `tail` outcomes whose largest losses are `worst`, largest first,
/// the rest 0: whole losses until less than one is left, then that part of the next. It
/// never falls when a loss grows, so over some of the losses, the others taken as 0, it is
/// a lower bound of the CVaR over all of them (bit for bit: each rounding is monotone).
pub(super) fn tail_mean(worst: &[Real], tail: Real) -> Real {
    let mut mass = tail;
    let mut sum = 0.0;
    for &l in worst {
        if mass <= 0.0 || l == 0.0 {
            break;
        }
        let w = mass.min(1.0);
        sum += w * l;
        mass -= w;
    }
    sum / tail
}

/// A first contact: when (in grid steps, fractional) and how fast the two close then (m per
/// grid step, along the line of centres).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Contact {
    pub(super) at: Real,
    pub(super) closing: Real,
    /// The robot's own speed toward the body then (m per grid step, ≥ 0).
    pub(super) driving: Real,
}

/// The smallest distance between the path and another body at `other(k)` on the same grid,
/// both moving straight between grid points, over each grid step: `gaps[k - 1]` for the step
/// from k − 1 to k. Returns the smallest of them.
pub(super) fn step_gaps(
    path: &[Vec2],
    other: impl Fn(usize) -> Vec2,
    gaps: &mut Vec<Real>,
) -> Real {
    gaps.clear();
    step_gaps_from(path, 0, other, gaps)
}

/// [`step_gaps`] for the steps after grid point `start`, appended to `gaps` (each step's gap
/// is its own two points' alone, so the bits are those of a scan from the start). Returns the
/// smallest of them.
pub(super) fn step_gaps_from(
    path: &[Vec2],
    start: usize,
    other: impl Fn(usize) -> Vec2,
    gaps: &mut Vec<Real>,
) -> Real {
    let mut best = Real::INFINITY;
    let mut d0 = other(start) - path[start];
    for (k, &at) in path.iter().enumerate().skip(start + 1) {
        let d1 = other(k) - at;
        let e = d1 - d0;
        let len_sq = e.norm_squared();
        let s = if len_sq > 0.0 {
            (-d0.dot(&e) / len_sq).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let gap = (d0 + e * s).norm();
        best = best.min(gap);
        gaps.push(gap);
        d0 = d1;
    }
    best
}

/// When the path first comes within `contact` of another body at `other(k)` on the same grid,
/// both moving straight between grid points; `None` if never.
pub(super) fn first_contact(
    path: &[Vec2],
    contact: Real,
    other: impl Fn(usize) -> Vec2,
) -> Option<Contact> {
    first_contact_from(path, contact, other, 1)
}

/// [`first_contact`] for a pair known not to touch before grid step `from` (from k − 1 to k)
/// begins: the scan starts there, and finds the same contact with the same bits.
pub(super) fn first_contact_from(
    path: &[Vec2],
    contact: Real,
    other: impl Fn(usize) -> Vec2,
    from: usize,
) -> Option<Contact> {
    let c2 = contact * contact;
    let mut d0 = other(from - 1) - path[from - 1];
    if from == 1 && d0.norm_squared() < c2 {
        // Touching already: closing as over the first step.
        let next = 1.min(path.len() - 1);
        let e = (other(next) - path[next]) - d0;
        return Some(Contact {
            at: 0.0,
            closing: closing(d0, e),
            driving: closing(d0, path[0] - path[next]),
        });
    }
    for (k, &at) in path.iter().enumerate().skip(from) {
        let d1 = other(k) - at;
        let e = d1 - d0;
        // |d0 + e·s|² = c² for s in [0, 1]: the smaller root.
        let a = e.norm_squared();
        let b = d0.dot(&e);
        let c = d0.norm_squared() - c2;
        if a > 0.0 {
            let disc = b * b - a * c;
            if disc >= 0.0 {
                let s = (-b - disc.sqrt()) / a;
                if (0.0..=1.0).contains(&s) {
                    let d = d0 + e * s;
                    return Some(Contact {
                        at: (k - 1) as Real + s,
                        closing: closing(d, e),
                        driving: closing(d, path[k - 1] - at),
                    });
                }
            }
        }
        d0 = d1;
    }
    None
}
