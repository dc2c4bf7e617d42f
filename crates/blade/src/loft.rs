//! Global surface interpolation of a grid of section points (Piegl & Tiller, *The NURBS
//! Book*, §9.2.5, algorithm A9.4), with centripetal parameters (eq. 9.6) averaged over
//! the rows (eq. 9.10 applied to 9.6) and knots by averaging (eq. 9.8).

use cadmorph_nurbs::math::Point3;
use cadmorph_nurbs::{KnotVector, NurbsCurve, NurbsSurface};
use nalgebra::{DMatrix, DVector};

use crate::linalg::{basis_row, solve_dense, BandLu};
use crate::{Error, Result};

/// Centripetal parameters `ū₀ = 0, ūₖ = ūₖ₋₁ + √|Qₖ − Qₖ₋₁| / Σ√|…|` of one row (P&T eq.
/// 9.6; Lee 1989), which keep the leading edge of an airfoil, where point spacing changes
/// fast, free of loops and overshoot.
pub fn centripetal(points: &[Point3<f64>]) -> Result<Vec<f64>> {
    let n = points.len();
    let d: Vec<f64> = points.windows(2).map(|w| (w[1] - w[0]).norm().sqrt()).collect();
    let total: f64 = d.iter().sum();
    if !(total > 0.0 && total.is_finite()) {
        return Err(Error::Geometry("all points of a row coincide".into()));
    }
    let mut u = Vec::with_capacity(n);
    u.push(0.0);
    let mut acc = 0.0;
    for (k, dk) in d.iter().enumerate() {
        acc += dk;
        u.push(if k + 2 == n { 1.0 } else { acc / total });
    }
    Ok(u)
}

/// Knots by averaging (P&T eq. 9.8): `p + 1` zeros, `u_{j+p} = (ū_j + … + ū_{j+p−1}) / p`
/// for `j = 1 … n − p`, `p + 1` ones.
pub fn averaged_knots(params: &[f64], p: usize) -> Result<KnotVector> {
    let n = params.len() - 1;
    let mut k = vec![0.0; p + 1];
    for j in 1..=n - p {
        k.push(params[j..j + p].iter().sum::<f64>() / p as f64);
    }
    k.extend(std::iter::repeat_n(1.0, p + 1));
    Ok(KnotVector::try_new(k)?)
}

/// The factorised collocation matrix of degree `p` over `knots` at `params` (A9.1's
/// system); banded LU, dense LU when a row falls outside the band.
pub(crate) enum Collocation {
    Band(BandLu),
    Dense(DMatrix<f64>),
}

impl Collocation {
    pub(crate) fn new(knots: &KnotVector, p: usize, params: &[f64]) -> Result<Self> {
        let rows: Vec<(usize, Vec<f64>)> = params.iter().map(|&t| basis_row(knots, p, t)).collect();
        match BandLu::factor(&rows, p, "curve interpolation") {
            Ok(b) => Ok(Collocation::Band(b)),
            Err(_) => {
                let n = params.len();
                let mut a = DMatrix::zeros(n, n);
                for (i, (s, v)) in rows.iter().enumerate() {
                    for (j, x) in v.iter().enumerate() {
                        a[(i, s + j)] = *x;
                    }
                }
                Ok(Collocation::Dense(a))
            }
        }
    }

    /// Solves for the control points through `q`.
    pub(crate) fn solve(&self, q: &[Point3<f64>]) -> Result<Vec<Point3<f64>>> {
        let n = q.len();
        let mut out = vec![Point3::origin(); n];
        for d in 0..3 {
            let mut b: Vec<f64> = q.iter().map(|p| p[d]).collect();
            match self {
                Collocation::Band(lu) => lu.solve(&mut b),
                Collocation::Dense(a) => {
                    let x = solve_dense(a.clone(), &DVector::from_vec(b.clone()), "curve interpolation")?;
                    b = x.iter().copied().collect();
                }
            }
            for (o, v) in out.iter_mut().zip(b) {
                o[d] = v;
            }
        }
        Ok(out)
    }
}

/// The degree-`p` curve through `points` at `params` over `knots` (P&T A9.1).
///
/// # Errors
///
/// [`Error::Singular`] for parameters that break Schoenberg–Whitney.
pub fn interpolate_curve(points: &[Point3<f64>], params: &[f64], knots: &KnotVector, p: usize) -> Result<NurbsCurve> {
    let cps = Collocation::new(knots, p, params)?.solve(points)?;
    Ok(NurbsCurve::try_new(p, knots.clone(), cps, None)?)
}

/// A surface through a grid of points and the parameters it passes them at.
#[derive(Debug, Clone)]
pub struct Lofted {
    /// The interpolating surface: `surface.eval(u[k], v[l]) == grid[l][k]`.
    pub surface: NurbsSurface,
    /// Parameter of each point along a row.
    pub u: Vec<f64>,
    /// Parameter of each row.
    pub v: Vec<f64>,
}

/// The surface of degrees `(p, q)` through `grid[l][k]` (`l` = section, `k` = point
/// along the section) at `(ū_k, v̄_l)` (P&T A9.4): centripetal parameters averaged
/// over all rows (u) and all columns (v), knots by averaging, then each row interpolated
/// in u and each column of the resulting control points in v. Degrees are lowered to
/// `points − 1` when there are too few points.
///
/// # Errors
///
/// [`Error::Geometry`] for rows of different lengths or fewer than 2 points/rows;
/// [`Error::Singular`] from the solves.
pub fn loft(grid: &[Vec<Point3<f64>>], p: usize, q: usize) -> Result<Lofted> {
    let m = grid.len();
    if m < 2 {
        return Err(Error::Geometry("a loft needs at least 2 sections".into()));
    }
    let n = grid[0].len();
    if let Some(l) = grid.iter().position(|r| r.len() != n) {
        return Err(Error::Geometry(format!("section {l} has {} points, section 0 has {n}", grid[l].len())));
    }
    if n < 2 {
        return Err(Error::Geometry("a section needs at least 2 points".into()));
    }
    let (p, q) = (p.min(n - 1).max(1), q.min(m - 1).max(1));
    let mut u = vec![0.0; n];
    for row in grid {
        for (a, b) in u.iter_mut().zip(centripetal(row)?) {
            *a += b / m as f64;
        }
    }
    u[0] = 0.0;
    u[n - 1] = 1.0;
    let mut v = vec![0.0; m];
    for k in 0..n {
        let col: Vec<Point3<f64>> = grid.iter().map(|r| r[k]).collect();
        for (a, b) in v.iter_mut().zip(centripetal(&col)?) {
            *a += b / n as f64;
        }
    }
    v[0] = 0.0;
    v[m - 1] = 1.0;
    let uk = averaged_knots(&u, p)?;
    let vk = averaged_knots(&v, q)?;
    let cu = Collocation::new(&uk, p, &u)?;
    let rows: Vec<Vec<Point3<f64>>> = grid.iter().map(|r| cu.solve(r)).collect::<Result<_>>()?;
    let cv = Collocation::new(&vk, q, &v)?;
    // Net layout of cadmorph-nurbs: index i * n_v + j with i along u.
    let mut net = vec![Point3::origin(); n * m];
    for i in 0..n {
        let col: Vec<Point3<f64>> = rows.iter().map(|r| r[i]).collect();
        for (j, pt) in cv.solve(&col)?.into_iter().enumerate() {
            net[i * m + j] = pt;
        }
    }
    let surface = NurbsSurface::try_new((p, q), (uk, vk), (n, m), net, None)?;
    Ok(Lofted { surface, u, v })
}
