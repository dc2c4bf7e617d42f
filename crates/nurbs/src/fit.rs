//! Curves through points: interpolation at the Greville abscissae of given knots, and an
//! adaptive fit of a function of one parameter (an edge traced on a morphed face).

use crate::math::Point3;
use crate::{basis_funs, Error, KnotVector, NurbsCurve, Result};

/// The Greville abscissae of degree `p` over `knots`: `(t[i+1] + … + t[i+p]) / p`, one
/// per control point, where each basis function peaks roughly.
pub fn greville(knots: &KnotVector, p: usize) -> Vec<f64> {
    let k = knots.as_slice();
    let n = k.len().saturating_sub(p + 1);
    (0..n).map(|i| k[i + 1..=i + p].iter().sum::<f64>() / p.max(1) as f64).collect()
}

/// The non-rational curve of degree `p` on `knots` through `targets`, one per control
/// point, at the Greville abscissae (The NURBS Book A9.1 with the knots given).
///
/// Row `i` of the collocation matrix holds the `p + 1` basis functions that are non-zero
/// at abscissa `i`, so the matrix is banded (`p` sub- and super-diagonals); it is also
/// totally positive (de Boor, "Total positivity of the spline collocation matrix", 1976),
/// so Gaussian elimination without pivoting is stable on it. The solve is a band LU in
/// `O(n·p²)` time and `O(n·p)` memory (an edge of thousands of poles costs what a dense
/// LU of tens did).
///
/// # Errors
///
/// [`Error::Fit`] when `targets` does not have one point per control point or the
/// collocation matrix is singular (repeated abscissae).
pub fn interpolate(p: usize, knots: &KnotVector, targets: &[Point3<f64>]) -> Result<NurbsCurve> {
    let g = greville(knots, p);
    let n = g.len();
    if targets.len() != n || n == 0 {
        return Err(Error::Fit {
            reason: format!("{} points to interpolate with {n} control points", targets.len()),
            reached: f64::INFINITY,
        });
    }
    let singular = || Error::Fit {
        reason: "singular collocation matrix at the Greville abscissae".to_owned(),
        reached: f64::INFINITY,
    };
    // Band storage: entry (r, c) at band[r * w + (c + p - r)], |c - r| <= p.
    let w = 2 * p + 1;
    let mut band = vec![0.0; n * w];
    for (row, &t) in g.iter().enumerate() {
        let span = knots.find_span(p, t);
        for (j, b) in basis_funs(knots, p, t).iter().enumerate() {
            let col = span + j - p;
            if col < n {
                if col + p < row || col > row + p {
                    return Err(singular());
                }
                band[row * w + col + p - row] = *b;
            }
        }
    }
    let mut rhs: Vec<[f64; 3]> = targets.iter().map(|q| [q.x, q.y, q.z]).collect();
    // Forward elimination without pivoting.
    for k in 0..n {
        let pivot = band[k * w + p];
        if !pivot.is_finite() || pivot.abs() <= f64::MIN_POSITIVE {
            return Err(singular());
        }
        let last = (k + p).min(n - 1);
        for r in k + 1..=last {
            let f = band[r * w + k + p - r] / pivot;
            if f == 0.0 {
                continue;
            }
            band[r * w + k + p - r] = 0.0;
            for c in k + 1..=last.max(k + p).min(n - 1) {
                if c + p < r || c > r + p {
                    continue;
                }
                band[r * w + c + p - r] -= f * band[k * w + c + p - k];
            }
            let (head, tail) = rhs.split_at_mut(r);
            for d in 0..3 {
                tail[0][d] -= f * head[k][d];
            }
        }
    }
    // Back substitution.
    let mut poles = vec![Point3::origin(); n];
    for k in (0..n).rev() {
        let mut acc = rhs[k];
        for c in k + 1..=(k + p).min(n - 1) {
            let a = band[k * w + c + p - k];
            for d in 0..3 {
                acc[d] -= a * poles[c][d];
            }
        }
        let pivot = band[k * w + p];
        for d in 0..3 {
            poles[k][d] = acc[d] / pivot;
        }
    }
    if poles.iter().any(|q| !q.coords.iter().all(|c| c.is_finite())) {
        return Err(singular());
    }
    NurbsCurve::try_new(p, knots.clone(), poles, None)
}

/// A B-spline of degree `p` over `domain` that follows `f` within `tol`: each piece
/// between consecutive `breaks` (parameters where `f` may have a kink, such as where an
/// edge crosses a knot line of the surface it is traced on; knots of multiplicity `p`
/// there) is cut into equal spans, the curve interpolates `f` at the Greville abscissae,
/// and the check at the quarter points of every span doubles the spans of the pieces
/// that miss until all pass or `max_poles` would be exceeded. Returns the curve and the
/// largest deviation found at the check points.
///
/// # Errors
///
/// [`Error::Fit`] when `max_poles` poles do not reach `tol` (with the deviation reached)
/// or `f` is not finite; [`Error::EmptyDomain`] for an empty domain.
pub fn fit_curve(
    f: impl Fn(f64) -> Point3<f64>,
    domain: (f64, f64),
    breaks: &[f64],
    p: usize,
    tol: f64,
    max_poles: usize,
) -> Result<(NurbsCurve, f64)> {
    let kinks: Vec<FitBreak> = breaks.iter().map(|&at| FitBreak { at, continuity: 0 }).collect();
    fit_curve_with_breaks(f, domain, &kinks, p, tol, max_poles)
}

/// A parameter where a fitted function's smoothness may drop (see
/// [`fit_curve_with_breaks`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitBreak {
    /// The parameter.
    pub at: f64,
    /// The order of continuity `f` keeps there: 0 for a kink (C0), 1 where it keeps its
    /// tangent (C1), and so on. The fit puts a knot of multiplicity `p − continuity`
    /// there (at least 1, P&T §2.2: a knot of multiplicity `m` leaves a degree-`p`
    /// B-spline C^(p−m) across it).
    pub continuity: usize,
}

/// [`fit_curve`] with each break's continuity given: the fit is as smooth across a break
/// as `f` is. The image of a curve on a surface crosses the surface's knot lines with
/// the surface's continuity there (C1 across a simple knot of a quadratic), not with a
/// kink; a fit with full knots there would make the curve C0 where the geometry is
/// smooth, and readers that split edges at C0 points (OCCT's IGES reader) would find
/// edges the model does not have. Two breaks closer than 1e-9 of the domain are one, with
/// the lower continuity.
///
/// # Errors
///
/// As [`fit_curve`].
pub fn fit_curve_with_breaks(
    f: impl Fn(f64) -> Point3<f64>,
    domain: (f64, f64),
    breaks: &[FitBreak],
    p: usize,
    tol: f64,
    max_poles: usize,
) -> Result<(NurbsCurve, f64)> {
    let (t0, t1) = domain;
    if t1.partial_cmp(&t0) != Some(std::cmp::Ordering::Greater) {
        return Err(Error::EmptyDomain { start: t0, end: t1 });
    }
    let min_gap = 1e-9 * (t1 - t0);
    let mut ends = vec![t0];
    // The multiplicity of the knot at each interior end (`mults[i]` for `ends[i + 1]`).
    let mut mults: Vec<usize> = Vec::new();
    let mut inner: Vec<FitBreak> =
        breaks.iter().copied().filter(|b| b.at > t0 + min_gap && b.at < t1 - min_gap).collect();
    inner.sort_by(|a, b| a.at.total_cmp(&b.at));
    for b in inner {
        let m = p.saturating_sub(b.continuity).clamp(1, p.max(1));
        if b.at - ends.last().copied().unwrap_or(t0) > min_gap {
            ends.push(b.at);
            mults.push(m);
        } else if let Some(last) = mults.last_mut() {
            *last = (*last).max(m);
        }
    }
    ends.push(t1);
    let mut spans = vec![1usize; ends.len() - 1];
    let mut best = f64::INFINITY;
    loop {
        let mut k = vec![t0; p + 1];
        for (i, w) in ends.windows(2).enumerate() {
            if i > 0 {
                k.extend(std::iter::repeat_n(w[0], mults[i - 1]));
            }
            k.extend((1..spans[i]).map(|j| w[0] + (w[1] - w[0]) * j as f64 / spans[i] as f64));
        }
        k.extend(std::iter::repeat_n(t1, p + 1));
        let knots = KnotVector::try_new(k)?;
        let targets: Vec<Point3<f64>> = greville(&knots, p).into_iter().map(&f).collect();
        if targets.iter().any(|q| !q.coords.iter().all(|c| c.is_finite())) {
            return Err(Error::Fit { reason: "the function to fit is not finite".to_owned(), reached: f64::INFINITY });
        }
        let c = interpolate(p, &knots, &targets)?;
        let mut worst: f64 = 0.0;
        let mut missed = vec![false; spans.len()];
        for (i, w) in ends.windows(2).enumerate() {
            for s in 0..spans[i] {
                for q in [0.25, 0.5, 0.75] {
                    let t = w[0] + (w[1] - w[0]) * (s as f64 + q) / spans[i] as f64;
                    let e = (crate::Curve::eval(&c, t) - f(t)).norm();
                    worst = worst.max(e);
                    missed[i] |= e.is_nan() || e > tol;
                }
            }
        }
        best = best.min(worst);
        if !missed.iter().any(|m| *m) {
            return Ok((c, worst));
        }
        for (s, m) in spans.iter_mut().zip(&missed) {
            if *m {
                *s *= 2;
            }
        }
        if spans.iter().sum::<usize>() * p + 1 > max_poles {
            return Err(Error::Fit { reason: format!("{max_poles} poles do not reach {tol:e}"), reached: best });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Curve;

    #[test]
    fn interpolation_reproduces_a_cubic_exactly() {
        // A cubic B-spline sampled at its own Greville abscissae comes back pole for pole.
        let knots = KnotVector::try_new(vec![0., 0., 0., 0., 0.3, 0.6, 1., 1., 1., 1.]).unwrap();
        let poles: Vec<Point3<f64>> =
            (0..6).map(|i| Point3::new(i as f64, (i as f64 * 1.3).sin(), (i * i) as f64 * 0.1)).collect();
        let c = NurbsCurve::try_new(3, knots.clone(), poles.clone(), None).unwrap();
        let targets: Vec<_> = greville(&knots, 3).into_iter().map(|t| c.eval(t)).collect();
        let back = interpolate(3, &knots, &targets).unwrap();
        for (a, b) in back.control_points().iter().zip(&poles) {
            assert!((a - b).norm() < 1e-12);
        }
    }

    #[test]
    fn band_solve_reproduces_long_splines_of_every_degree() {
        // Thousands of poles, non-uniform knots, degrees 1 to 5: sampling a known spline at
        // its Greville abscissae and interpolating gives its poles back (the banded
        // elimination is exact up to rounding; a dense LU of this size took seconds).
        for p in 1..=5usize {
            let n = 3000;
            let mut k = vec![0.0; p + 1];
            let mut t = 0.0;
            for i in 1..n - p {
                t += 1.0 + 0.37 * ((i * 7) % 5) as f64;
                k.push(t);
            }
            k.extend(std::iter::repeat_n(t + 1.0, p + 1));
            let knots = KnotVector::try_new(k).unwrap();
            let poles: Vec<Point3<f64>> =
                (0..n).map(|i| Point3::new(i as f64 * 0.01, (i as f64 * 0.1).sin(), (i as f64 * 0.03).cos())).collect();
            let c = NurbsCurve::try_new(p, knots.clone(), poles.clone(), None).unwrap();
            let targets: Vec<_> = greville(&knots, p).into_iter().map(|t| c.eval(t)).collect();
            let back = interpolate(p, &knots, &targets).unwrap();
            let worst = back.control_points().iter().zip(&poles).map(|(a, b)| (a - b).norm()).fold(0.0, f64::max);
            assert!(worst < 1e-9, "degree {p}: {worst:e}");
        }
    }

    #[test]
    fn repeated_abscissae_are_refused() {
        // Degree 1 with a triple interior knot: two Greville abscissae coincide.
        let knots = KnotVector::try_new(vec![0., 0., 0.5, 0.5, 0.5, 1., 1.]).unwrap();
        let targets = vec![Point3::origin(); 5];
        assert!(matches!(interpolate(1, &knots, &targets), Err(Error::Fit { .. })));
    }

    #[test]
    fn breaks_get_the_multiplicity_of_their_continuity() {
        // A quadratic B-spline with a simple knot at 0.4 is C1 there (P&T §2.2); a cubic fit
        // told so puts a double knot there (C1), told of a kink a triple one (C0), and both
        // follow the quadratic within the tolerance.
        let knots = KnotVector::try_new(vec![0., 0., 0., 0.4, 1., 1., 1.]).unwrap();
        let poles = vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 2.0, 0.0),
            Point3::new(2.0, -1.0, 1.0),
            Point3::new(3.0, 0.5, 0.0),
        ];
        let q = NurbsCurve::try_new(2, knots, poles, None).unwrap();
        // (At 0.7 the quadratic is smooth: any continuity above p − 1 is a simple knot.)
        for (at, continuity, mult) in [(0.4, 1, 2), (0.4, 0, 3), (0.7, 5, 1)] {
            let b = [FitBreak { at: 0.4, continuity: continuity.min(1) }, FitBreak { at, continuity }];
            let (c, err) = fit_curve_with_breaks(|t| q.eval(t), (0.0, 1.0), &b, 3, 1e-9, 2000).unwrap();
            assert!(err <= 1e-9, "continuity {continuity}: {err:e}");
            assert_eq!(c.knots().multiplicity(at, 0.0), mult, "continuity {continuity}");
            for k in 0..=200 {
                let t = k as f64 / 200.0;
                assert!((c.eval(t) - q.eval(t)).norm() <= 1e-9, "continuity {continuity} at {t}");
            }
        }
        // Two breaks closer than 1e-9 of the domain are one, with the lower continuity.
        let b = [FitBreak { at: 0.4, continuity: 1 }, FitBreak { at: 0.4 + 1e-12, continuity: 0 }];
        let (c, _) = fit_curve_with_breaks(|t| q.eval(t), (0.0, 1.0), &b, 3, 1e-9, 2000).unwrap();
        assert_eq!(c.knots().multiplicity(0.4, 0.0), 3);
    }

    #[test]
    fn fit_follows_a_helix_within_tolerance() {
        let helix = |t: f64| Point3::new(t.cos(), t.sin(), 0.2 * t);
        let (c, err) = fit_curve(helix, (0.0, 6.0), &[], 3, 1e-7, 2000).unwrap();
        assert!(err <= 1e-7);
        for k in 0..=997 {
            let t = 6.0 * k as f64 / 997.0;
            assert!((c.eval(t) - helix(t)).norm() < 2e-7, "at {t}");
        }
        // Cubic convergence: a hundred times tighter costs about 100^(1/4) ≈ 3x the spans.
        let (coarse, _) = fit_curve(helix, (0.0, 6.0), &[], 3, 1e-5, 2000).unwrap();
        assert!(coarse.control_points().len() < c.control_points().len());
        assert!(matches!(fit_curve(helix, (0.0, 6.0), &[], 3, 1e-15, 20), Err(Error::Fit { .. })));
    }

    #[test]
    fn breaks_let_a_kinked_function_be_fitted_exactly() {
        // |t - 0.3| bends once: with a break there a cubic fits it to rounding, without one
        // uniform spans never converge.
        let f = |t: f64| Point3::new(t, (t - 0.3).abs(), 0.0);
        let (c, err) = fit_curve(f, (0.0, 1.0), &[0.3], 3, 1e-12, 200).unwrap();
        assert!(err < 1e-12, "{err}");
        assert_eq!(c.control_points().len(), 7);
        assert!(fit_curve(f, (0.0, 1.0), &[], 3, 1e-9, 200).is_err());
    }
}
