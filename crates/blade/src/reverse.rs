//! Reverse engineering (BladeX `ReversePropeller`): sections of a blade's upper and
//! lower faces cut by cylinders about the x axis, unwrapped to the plane, and the
//! chord, pitch, rake and skew that place them (the inverse of
//! `Blade::apply_transformations`).

use cadmorph_nurbs::math::Point3;
use cadmorph_nurbs::{NurbsSurface, Surface};

use crate::{Error, Result};

/// One recovered section.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct RecoveredSection {
    /// Cylinder radius.
    pub radius: f64,
    /// Chord length (leading edge to the trailing-edge midpoint, in the unwrapped plane).
    pub chord: f64,
    /// Pitch `2πr tan φ`.
    pub pitch: f64,
    /// Pitch angle φ, radians.
    pub pitch_angle: f64,
    /// Rake (without the rake induced by skew).
    pub rake: f64,
    /// Skew angle, degrees.
    pub skew: f64,
    /// Unwrapped upper side `(x, r θ)`, leading edge first.
    pub upper: Vec<[f64; 2]>,
    /// Unwrapped lower side, leading edge first.
    pub lower: Vec<[f64; 2]>,
}

fn rho(p: &Point3<f64>) -> f64 {
    p.y.hypot(p.z)
}

/// The parameter `v` where the iso-curve `v ↦ S(u, v)` crosses the cylinder of radius
/// `r`, by bisection (the radius grows monotonically from root to tip on a blade face).
fn cut(s: &NurbsSurface, u: f64, r: f64) -> Result<Point3<f64>> {
    let (_, vd) = s.domain();
    let (mut a, mut b) = (*vd.start(), *vd.end());
    let (ra, rb) = (rho(&s.eval(u, a)) - r, rho(&s.eval(u, b)) - r);
    // The end sections lie on their cylinders to round-off (and to the file precision
    // for faces read back): accept the ends within 1e-6 relative.
    if ra.abs() <= 1e-6 * r {
        return Ok(s.eval(u, a));
    }
    if rb.abs() <= 1e-6 * r {
        return Ok(s.eval(u, b));
    }
    if ra * rb > 0.0 {
        return Err(Error::Geometry(format!(
            "radius {r} does not cut the face (its radii run {} to {})",
            ra + r,
            rb + r
        )));
    }
    let up = rb > ra;
    for _ in 0..200 {
        let m = 0.5 * (a + b);
        if (rho(&s.eval(u, m)) < r) == up {
            a = m;
        } else {
            b = m;
        }
        if b - a <= 1e-16 {
            break;
        }
    }
    Ok(s.eval(u, 0.5 * (a + b)))
}

fn unwrap(p: &Point3<f64>, r: f64) -> [f64; 2] {
    [p.x, r * p.y.atan2(p.z)]
}

/// Which u end of `upper` is the leading edge: the end where upper and lower meet with
/// the same normal direction (a round leading edge) rather than at an angle (the
/// trailing edge); returns (LE u of upper, TE u of upper, LE u of lower, TE u of lower).
fn edge_params(upper: &NurbsSurface, lower: &NurbsSurface) -> (f64, f64, f64, f64) {
    let (ud, vd) = upper.domain();
    let (ld, _) = lower.domain();
    let v = (vd.start() + vd.end()) / 2.0;
    let (u0, u1, l0, l1) = (*ud.start(), *ud.end(), *ld.start(), *ld.end());
    let n = |s: &NurbsSurface, u: f64| s.normal(u, v).map(|n| n.into_inner());
    let meet = |a: f64, b: f64| (upper.eval(a, v) - lower.eval(b, v)).norm();
    // Pair each end of upper with the end of lower it touches.
    let l_of = |u: f64| if meet(u, l0) <= meet(u, l1) { l0 } else { l1 };
    let align = |u: f64| match (n(upper, u), n(lower, l_of(u))) {
        (Some(a), Some(b)) => a.dot(&b).abs(),
        _ => 0.0,
    };
    if align(u0) >= align(u1) {
        (u0, u1, l_of(u0), l_of(u1))
    } else {
        (u1, u0, l_of(u1), l_of(u0))
    }
}

/// Sections of the blade faces at `radii`, each sampled at `n_points` parameters per
/// side, and the placement parameters that `Blade::apply_transformations(reflect)`
/// would have used: with `M` the chord midpoint and `d` = TE − LE in the unwrapped plane,
/// `π/2 − φ = atan2(±d)` (− when reflected), `skew = −M_y / r`, `rake = −M_x − r·skew·tan φ`.
///
/// # Errors
///
/// [`Error::Geometry`] when a radius does not cut the faces.
pub fn reverse(
    upper: &NurbsSurface,
    lower: &NurbsSurface,
    radii: &[f64],
    reflect: bool,
    n_points: usize,
) -> Result<Vec<RecoveredSection>> {
    let (ule, ute, lle, lte) = edge_params(upper, lower);
    let n = n_points.max(2);
    radii
        .iter()
        .map(|&r| {
            let side = |s: &NurbsSurface, a: f64, b: f64| -> Result<Vec<[f64; 2]>> {
                (0..n).map(|i| cut(s, a + (b - a) * i as f64 / (n - 1) as f64, r).map(|p| unwrap(&p, r))).collect()
            };
            let up = side(upper, ule, ute)?;
            let low = side(lower, lle, lte)?;
            let le = [(up[0][0] + low[0][0]) / 2.0, (up[0][1] + low[0][1]) / 2.0];
            let te = [(up[n - 1][0] + low[n - 1][0]) / 2.0, (up[n - 1][1] + low[n - 1][1]) / 2.0];
            let d = [te[0] - le[0], te[1] - le[1]];
            let chord = d[0].hypot(d[1]);
            let sign = if reflect { -1.0 } else { 1.0 };
            let alpha = (sign * d[1]).atan2(sign * d[0]);
            let phi = std::f64::consts::FRAC_PI_2 - alpha;
            let m = [(le[0] + te[0]) / 2.0, (le[1] + te[1]) / 2.0];
            let skew_rad = -m[1] / r;
            let rake = -m[0] - r * skew_rad * phi.tan();
            Ok(RecoveredSection {
                radius: r,
                chord,
                pitch: 2.0 * std::f64::consts::PI * r * phi.tan(),
                pitch_angle: phi,
                rake,
                skew: skew_rad.to_degrees(),
                upper: up,
                lower: low,
            })
        })
        .collect()
}
