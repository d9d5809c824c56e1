//! Scalar and vector aliases, so the rest of the crate never spells out nalgebra generics.
//!
//! Everything is `f64`: the simulator must give the same numbers for the same seed on every
//! machine, and 2-D planning gains nothing from `f32`.

/// The scalar type of all geometry.
pub type Real = f64;
/// A 2-D vector or position in metres (world frame unless a name says otherwise).
pub type Vec2 = nalgebra::Vector2<Real>;

/// Shorthand constructor.
#[inline]
pub fn vec2(x: Real, y: Real) -> Vec2 {
    Vec2::new(x, y)
}

/// The 2-D cross product (determinant of `[a b]`); positive when `b` is left of `a`.
#[inline]
pub fn det(a: &Vec2, b: &Vec2) -> Real {
    a.x * b.y - a.y * b.x
}

/// Unit vector pointing at `angle` radians from the x axis.
#[inline]
pub fn unit(angle: Real) -> Vec2 {
    let (s, c) = angle.sin_cos();
    vec2(c, s)
}

/// Angle of `v` from the x axis, in (-π, π].
#[inline]
pub fn angle_of(v: &Vec2) -> Real {
    v.y.atan2(v.x)
}

/// `v` rotated by +90°.
#[inline]
pub fn left_normal(v: &Vec2) -> Vec2 {
    vec2(-v.y, v.x)
}

/// `v` rotated by `angle` radians.
#[inline]
pub fn rotate(v: &Vec2, angle: Real) -> Vec2 {
    let (s, c) = angle.sin_cos();
    vec2(c * v.x - s * v.y, s * v.x + c * v.y)
}

/// Wraps an angle into (-π, π].
#[inline]
pub fn wrap_angle(angle: Real) -> Real {
    let two_pi = std::f64::consts::TAU;
    let mut a = angle % two_pi;
    if a <= -std::f64::consts::PI {
        a += two_pi;
    } else if a > std::f64::consts::PI {
        a -= two_pi;
    }
    a
}

/// `v` scaled down to length `max` if it is longer.
#[inline]
pub fn clamp_norm(v: Vec2, max: Real) -> Vec2 {
    let n2 = v.norm_squared();
    if n2 > max * max {
        v * (max / n2.sqrt())
    } else {
        v
    }
}

/// Squared distance from `p` to the segment `a`–`b`.
#[inline]
pub fn dist_sq_point_segment(a: &Vec2, b: &Vec2, p: &Vec2) -> Real {
    let ab = b - a;
    let len_sq = ab.norm_squared();
    if len_sq <= 0.0 {
        return (p - a).norm_squared();
    }
    let t = ((p - a).dot(&ab) / len_sq).clamp(0.0, 1.0);
    (p - (a + ab * t)).norm_squared()
}

/// The point of the segment `a`–`b` nearest to `p` (`a` for a degenerate segment).
#[inline]
pub fn closest_on_segment(a: Vec2, b: Vec2, p: Vec2) -> Vec2 {
    let e = b - a;
    let len_sq = e.norm_squared();
    let s = if len_sq > 0.0 {
        ((p - a).dot(&e) / len_sq).clamp(0.0, 1.0)
    } else {
        0.0
    };
    a + e * s
}

/// The smallest axis-aligned box holding `points` (corners min, max); both zero when empty.
pub fn bounds(points: &[Vec2]) -> (Vec2, Vec2) {
    let first = points.first().copied().unwrap_or_else(|| vec2(0.0, 0.0));
    points
        .iter()
        .fold((first, first), |(min, max), p| (min.inf(p), max.sup(p)))
}

/// The distance from `p` to the segment `a`–`b`.
pub fn distance_to_segment(a: Vec2, b: Vec2, p: Vec2) -> Real {
    (closest_on_segment(a, b, p) - p).norm()
}

/// The distance between segments `a`–`b` and `c`–`d` (0 if they cross).
pub fn segment_distance(a: Vec2, b: Vec2, c: Vec2, d: Vec2) -> Real {
    let cross = |u: Vec2, v: Vec2| u.x * v.y - u.y * v.x;
    let (r, s) = (b - a, d - c);
    let denom = cross(r, s);
    if denom != 0.0 {
        let t = cross(c - a, s) / denom;
        let u = cross(c - a, r) / denom;
        if (0.0..=1.0).contains(&t) && (0.0..=1.0).contains(&u) {
            return 0.0;
        }
    }
    distance_to_segment(c, d, a)
        .min(distance_to_segment(c, d, b))
        .min(distance_to_segment(a, b, c))
        .min(distance_to_segment(a, b, d))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn wrap_angle_stays_in_half_open_interval() {
        assert!((wrap_angle(3.0 * PI) - PI).abs() < 1e-12);
        assert!((wrap_angle(-3.0 * PI) - PI).abs() < 1e-12);
        assert!((wrap_angle(0.5) - 0.5).abs() < 1e-15);
        assert!((wrap_angle(-PI / 2.0 - 2.0 * PI) + PI / 2.0).abs() < 1e-12);
    }

    #[test]
    fn segment_distance_handles_ends_and_interior() {
        let a = vec2(0.0, 0.0);
        let b = vec2(2.0, 0.0);
        assert_eq!(dist_sq_point_segment(&a, &b, &vec2(1.0, 1.0)), 1.0);
        assert_eq!(dist_sq_point_segment(&a, &b, &vec2(-1.0, 0.0)), 1.0);
        assert_eq!(dist_sq_point_segment(&a, &b, &vec2(3.0, 1.0)), 2.0);
        assert_eq!(dist_sq_point_segment(&a, &a, &vec2(3.0, 4.0)), 25.0);
    }

    #[test]
    fn det_sign_says_left_or_right() {
        assert!(det(&vec2(1.0, 0.0), &vec2(0.0, 1.0)) > 0.0);
        assert!(det(&vec2(1.0, 0.0), &vec2(0.0, -1.0)) < 0.0);
    }
}
