//! Scalar B-splines of one variable as BladeX uses them: the interpolating spline of
//! `scipy.interpolate.splrep(x, y)` (FITPACK `curfit` with `s = 0`) and the clamped
//! uniform B-spline of `bladex.ndinterpolator.scipy_bspline`.

use cadmorph_nurbs::KnotVector;
use nalgebra::{DMatrix, DVector};

use crate::linalg::{basis_row, solve_dense};
use crate::{Error, Result};

/// An interpolating spline `y(x)` of degree `k` through data points, with FITPACK's knots
/// for `s = 0`: `k + 1` end knots at `x₀` and `xₘ₋₁`, and for odd `k` interior knots at
/// the data abscissae `x[(k+1)/2 .. m−(k+1)/2]` (for `k = 3`, a not-a-knot cubic).
#[derive(Debug, Clone)]
pub struct InterpolatingSpline {
    k: usize,
    knots: KnotVector,
    coefs: Vec<f64>,
}

impl InterpolatingSpline {
    /// `scipy.interpolate.splrep(x, y, k=k)` with the default `s = 0`.
    ///
    /// # Errors
    ///
    /// [`Error::Geometry`] unless `k` is odd, `x` strictly increases and `m > k`.
    pub fn splrep(x: &[f64], y: &[f64], k: usize) -> Result<Self> {
        let m = x.len();
        if k.is_multiple_of(2) || m <= k || y.len() != m {
            return Err(Error::Geometry(format!("splrep: need odd k < m = {m} and as many y as x (k = {k})")));
        }
        if x.windows(2).any(|w| w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater)) {
            return Err(Error::Geometry("splrep: x must increase strictly".into()));
        }
        let h = k.div_ceil(2);
        let mut t = vec![x[0]; k + 1];
        t.extend_from_slice(&x[h..m - h]);
        t.extend(std::iter::repeat_n(x[m - 1], k + 1));
        let knots = KnotVector::try_new(t)?;
        let mut a = DMatrix::<f64>::zeros(m, m);
        for (row, &xi) in x.iter().enumerate() {
            let (s, vals) = basis_row(&knots, k, xi);
            for (j, v) in vals.iter().enumerate() {
                a[(row, s + j)] = *v;
            }
        }
        let c = solve_dense(a, &DVector::from_column_slice(y), "splrep collocation")?;
        Ok(Self { k, knots, coefs: c.iter().copied().collect() })
    }

    /// `scipy.interpolate.splev(t, tck)`: the spline at `t` (outside the data range the
    /// end polynomial pieces are extrapolated, FITPACK's `ext = 0`).
    pub fn eval(&self, t: f64) -> f64 {
        let (s, vals) = basis_row(&self.knots, self.k, t);
        vals.iter().enumerate().map(|(j, v)| v * self.coefs[s + j]).sum()
    }
}

/// The knots `clip(arange(c + p + 1) − p, 0, c − p)` of BladeX `scipy_bspline`: clamped,
/// uniform, integer-valued on `[0, c − p]` for `c` control points of degree `p`.
pub fn bladex_knots(c: usize, p: usize) -> Result<KnotVector> {
    if p == 0 || c <= p {
        return Err(Error::Geometry(format!("{c} control points cannot carry degree {p}")));
    }
    let top = (c - p) as f64;
    let t: Vec<f64> = (0..c + p + 1).map(|i| (i as f64 - p as f64).clamp(0.0, top)).collect();
    Ok(KnotVector::try_new(t)?)
}

/// The `npoints` parameters `linspace(0, c − p, npoints)` at which `scipy_bspline`
/// evaluates.
pub fn bladex_parameters(c: usize, p: usize, npoints: usize) -> Vec<f64> {
    let top = c.saturating_sub(p) as f64;
    linspace(0.0, top, npoints)
}

/// `numpy.linspace(a, b, n)`: `a + i·(b − a)/(n − 1)`, the last value exactly `b`.
pub fn linspace(a: f64, b: f64, n: usize) -> Vec<f64> {
    match n {
        0 => Vec::new(),
        1 => vec![a],
        _ => {
            let step = (b - a) / (n - 1) as f64;
            let mut v: Vec<f64> = (0..n).map(|i| a + i as f64 * step).collect();
            v[n - 1] = b;
            v
        }
    }
}

/// `bladex.ndinterpolator.scipy_bspline(cv, npoints, degree)` for 2D control points:
/// the clamped uniform B-spline of [`bladex_knots`] evaluated at [`bladex_parameters`].
///
/// # Errors
///
/// As [`bladex_knots`].
pub fn bladex_bspline(cv: &[[f64; 2]], npoints: usize, p: usize) -> Result<Vec<[f64; 2]>> {
    let knots = bladex_knots(cv.len(), p)?;
    Ok(bladex_parameters(cv.len(), p, npoints)
        .into_iter()
        .map(|u| {
            let (s, vals) = basis_row(&knots, p, u);
            let mut q = [0.0; 2];
            for (j, v) in vals.iter().enumerate() {
                q[0] += v * cv[s + j][0];
                q[1] += v * cv[s + j][1];
            }
            q
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splrep_reproduces_a_cubic() {
        // A not-a-knot cubic spline reproduces any cubic exactly.
        let f = |x: f64| 1.0 - 2.0 * x + 0.5 * x * x * x;
        let x = [0.05, 0.1, 0.15, 0.2, 0.25];
        let y: Vec<f64> = x.iter().map(|&x| f(x)).collect();
        let s = InterpolatingSpline::splrep(&x, &y, 3).unwrap();
        for t in [0.05, 0.07, 0.13, 0.2, 0.25, 0.3] {
            assert!((s.eval(t) - f(t)).abs() < 1e-12, "{t}");
        }
    }

    #[test]
    fn bladex_knots_are_clamped_integers() {
        assert_eq!(bladex_knots(5, 3).unwrap().as_slice(), &[0., 0., 0., 0., 1., 2., 2., 2., 2.]);
    }
}
