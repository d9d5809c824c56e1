//! Ψ, the hypothetical people hidden in the robot's shadows (Eq. 6): where they step out of
//! the unobserved space, how they walk, and the risk a path runs of meeting them.

use super::PnpParams;
use super::risk::{Path, Scoring, cvar, first_contact, loss};
use crate::map::StaticMap;
use crate::math::{Real, Vec2, vec2};
use crate::model::{EgoState, Neighbour};
use crate::visibility::Visibility;

/// A hypothetical hidden person: where they step out and how they walk.
#[derive(Debug, Clone, Copy)]
pub(super) struct Hidden {
    pub(super) start: Vec2,
    pub(super) velocity: Vec2,
}

/// ρ before its threshold: CVaR_α of the collision loss over Ψ.
pub(super) fn hidden_risk(
    path: Path,
    hidden: &[Hidden],
    dt: Real,
    contact: Real,
    alpha: Real,
    scoring: Scoring,
    losses: &mut Vec<Real>,
) -> Real {
    // The box around the path, widened by the contact distance: hidden people whose whole
    // walk stays outside it cannot meet the robot.
    let (lo, hi) = (
        path.lo - vec2(contact, contact),
        path.hi + vec2(contact, contact),
    );
    let path = path.points;
    let n = path.len() - 1;
    let horizon = n as Real * dt;
    losses.clear();
    losses.extend(hidden.iter().map(|h| {
        let end = h.start + h.velocity * horizon;
        let outside = h.start.x.max(end.x) < lo.x
            || h.start.x.min(end.x) > hi.x
            || h.start.y.max(end.y) < lo.y
            || h.start.y.min(end.y) > hi.y;
        if outside {
            return 0.0;
        }
        loss(
            first_contact(path, contact, |k| h.start + h.velocity * (k as Real * dt)),
            n,
            scoring,
        )
    }));
    cvar(losses, alpha)
}

/// Where the robot goes on `path` (on a grid of `dt`) if a hidden person steps out as it
/// starts: it drives the path for one grid step (seeing them and reacting), then brakes at
/// `a_max` to a stop, straight on at the velocity it holds over the path's next step. Fills
/// `out` with as many points as `path`.
pub(super) fn braking_path(path: &[Vec2], dt: Real, a_max: Real, out: &mut Vec<Vec2>) {
    out.clear();
    out.extend(path.iter().take(2));
    let (Some(&seen), Some(&next)) = (path.get(1), path.get(2).or(path.get(1))) else {
        return;
    };
    let from = if path.len() > 2 { seen } else { path[0] };
    let velocity = (next - from) / dt;
    let speed = velocity.norm();
    let stop = if a_max > 0.0 { speed / a_max } else { 0.0 };
    for k in 2..path.len() {
        let t = ((k - 1) as Real * dt).min(stop);
        out.push(seen + velocity * t - velocity * (0.5 * a_max * t * t / speed.max(1e-12)));
    }
}

/// Fills `out` with Ψ: hypothetical people stepping out of the shadows of `visibility`,
/// spread uniformly over the occlusion edges within reach (their length), headings into view
/// (uniform over the half-plane facing away from the shadow), speeds uniform up to the
/// walking speed. Samples that would stand in a wall, behind one, or inside a perceived body
/// are dropped. Returns the number of edges.
pub(super) fn sample_hidden(
    p: &PnpParams,
    units: &[[Real; 3]],
    visibility: &Visibility,
    map: &StaticMap,
    neighbours: &[Neighbour],
    ego: &EgoState,
    out: &mut Vec<Hidden>,
) -> usize {
    out.clear();
    // Edges farther than the robot and a hidden person can close within the horizon are
    // out of reach.
    let reach = (p.v_max + p.hidden_speed) * p.horizon + ego.radius + p.hidden_radius;
    let edges: Vec<_> = visibility
        .edges(p.edge_jump)
        .filter_map(|e| {
            let near = e.near + p.hidden_radius;
            let far = e.far.min(reach);
            (far > near).then_some((e, near, far))
        })
        .collect();
    let total: Real = edges.iter().map(|(_, near, far)| far - near).sum();
    if edges.is_empty() || total <= 0.0 {
        return 0;
    }
    for u in units {
        // The edge and the distance along it: u[0] over the edges' total length.
        let mut at = u[0] * total;
        let mut chosen = edges[edges.len() - 1];
        for &e in &edges {
            let len = e.2 - e.1;
            if at < len {
                chosen = e;
                break;
            }
            at -= len;
        }
        let (edge, near, far) = chosen;
        let s = (near + at).min(far);
        let along = visibility.direction(edge.ray);
        // The shadow lies to the `side` of the ray: counter-clockwise normal times side.
        let into_shadow = vec2(-along.y, along.x) * edge.side;
        let on_edge = visibility.origin + along * s;
        let start = on_edge + into_shadow * p.hidden_radius;
        // Heading into view: uniform over the half-plane facing out of the shadow.
        let out_of_shadow = -into_shadow;
        let angle = (u[1] - 0.5) * std::f64::consts::PI;
        let (sin, cos) = angle.sin_cos();
        let heading = vec2(
            out_of_shadow.x * cos - out_of_shadow.y * sin,
            out_of_shadow.x * sin + out_of_shadow.y * cos,
        );
        let speed = u[2] * p.hidden_speed;
        let free_of_walls = map.is_empty()
            || (map.distance(&start) >= p.hidden_radius && map.line_of_sight(start, on_edge));
        let free_of_bodies = neighbours
            .iter()
            .all(|b| (b.position - start).norm() >= b.radius + p.hidden_radius);
        if free_of_walls && free_of_bodies {
            out.push(Hidden {
                start,
                velocity: heading * speed,
            });
        }
    }
    edges.len()
}

/// The radical inverse of `i` in `base`: the Halton sequence's i-th coordinate in (0, 1).
pub(super) fn halton(mut i: usize, base: usize) -> Real {
    let (mut f, mut r) = (1.0, 0.0);
    while i > 0 {
        f /= base as Real;
        r += f * (i % base) as Real;
        i /= base;
    }
    r
}
