//! Radial laws as B-splines (BladeX `Deformation`, paper §3.1.2): each radial
//! distribution (chord, pitch, rake, skew, camber against radius) is fitted by a planar
//! clamped uniform B-spline whose end control points are the end data points and whose
//! inner control points solve a least-squares problem; moving the control points' y by
//! the parameter file's deformations and sampling the curve again gives the deformed
//! distribution.

use cadmorph_nurbs::KnotVector;
use nalgebra::{DMatrix, DVector};

use crate::linalg::{basis_row, least_squares};
use crate::prm::{LawParam, ParamFile};
use crate::spline1d::{bladex_bspline, bladex_knots, bladex_parameters, linspace};
use crate::wendland::reconstruct;
use crate::{Error, Result};

fn law_error(p: LawParam, reason: impl Into<String>) -> Error {
    Error::RadialLaw { param: p.name().to_owned(), reason: reason.into() }
}

/// The control points of the B-spline law through the radial distribution `(x, y)`
/// (BladeX `Deformation._optimum_control_points`): when `rbf_points > 0` the data is
/// first re-sampled at `rbf_points` equally spaced radii by Wendland C² RBF of radius 2;
/// the basis matrix `A` holds the `nbasis` clamped uniform basis functions of `degree`
/// at the uniform parameters `linspace(0, nbasis − degree, len)`; the first and last
/// control points are the first and last samples and the inner ones minimise
/// `‖A [P₀, P̃, Pₙ] − Q‖` (constrained least squares, P&T §9.4.1 with fixed ends).
///
/// # Errors
///
/// [`Error::RadialLaw`] when `degree ≥ nbasis`, `nbasis < 3`, or the least-squares
/// problem is rank deficient (fewer samples than control points).
pub fn optimum_control_points(
    param: LawParam,
    x: &[f64],
    y: &[f64],
    degree: usize,
    nbasis: usize,
    rbf_points: usize,
) -> Result<Vec<[f64; 2]>> {
    if nbasis < 3 || degree == 0 || degree >= nbasis {
        return Err(law_error(
            param,
            format!("degree {degree} with {nbasis} control points (need 0 < degree < nbasis, nbasis ≥ 3)"),
        ));
    }
    if x.len() != y.len() || x.len() < 2 {
        return Err(law_error(param, format!("{} radii for {} values", x.len(), y.len())));
    }
    let (xs, ys) = if rbf_points > 0 {
        let xx = linspace(x[0], x[x.len() - 1], rbf_points);
        let yy = reconstruct(x, y, &xx, 2.0)?;
        (xx, yy)
    } else {
        (x.to_vec(), y.to_vec())
    };
    let m = xs.len();
    let knots = bladex_knots(nbasis, degree)?;
    let mut a = DMatrix::<f64>::zeros(m, nbasis);
    for (row, u) in bladex_parameters(nbasis, degree, m).into_iter().enumerate() {
        let (s, vals) = basis_row(&knots, degree, u);
        for (j, v) in vals.iter().enumerate() {
            a[(row, s + j)] = *v;
        }
    }
    let inner = a.columns(1, nbasis - 2).into_owned();
    let solve = |q: &[f64]| -> Result<DVector<f64>> {
        let rhs = DVector::from_fn(m, |i, _| q[i] - a[(i, 0)] * q[0] - a[(i, nbasis - 1)] * q[m - 1]);
        least_squares(&inner, &rhs, "radial law least squares").map_err(|e| law_error(param, e.to_string()))
    };
    let (cx, cy) = (solve(&xs)?, solve(&ys)?);
    let mut cv = vec![[xs[0], ys[0]]];
    cv.extend((0..nbasis - 2).map(|k| [cx[k], cy[k]]));
    cv.push([xs[m - 1], ys[m - 1]]);
    Ok(cv)
}

/// One radial law: its B-spline control points `(r, value)` and degree.
#[derive(Debug, Clone, PartialEq)]
pub struct RadialLaw {
    /// Which parameter.
    pub param: LawParam,
    /// Degree.
    pub degree: usize,
    /// Control points `(radius, value)`.
    pub control_points: Vec<[f64; 2]>,
}

impl RadialLaw {
    /// Fits the law (see [`optimum_control_points`]).
    ///
    /// # Errors
    ///
    /// As [`optimum_control_points`].
    pub fn fit(
        param: LawParam,
        radii: &[f64],
        values: &[f64],
        degree: usize,
        nbasis: usize,
        rbf_points: usize,
    ) -> Result<Self> {
        Ok(Self {
            param,
            degree,
            control_points: optimum_control_points(param, radii, values, degree, nbasis, rbf_points)?,
        })
    }

    /// Adds `dy[i]` to the value of control point `i` (BladeX `update_control_points`).
    ///
    /// # Errors
    ///
    /// [`Error::RadialLaw`] when the count differs from the number of control points.
    pub fn deform(&mut self, dy: &[f64]) -> Result<()> {
        if dy.len() != self.control_points.len() {
            return Err(law_error(
                self.param,
                format!("{} deformations for {} control points", dy.len(), self.control_points.len()),
            ));
        }
        for (c, d) in self.control_points.iter_mut().zip(dy) {
            c[1] += d;
        }
        Ok(())
    }

    /// `npoints` samples `(r, value)` of the curve (BladeX `generate_spline`).
    ///
    /// # Errors
    ///
    /// As [`bladex_knots`].
    pub fn samples(&self, npoints: usize) -> Result<Vec<[f64; 2]>> {
        bladex_bspline(&self.control_points, npoints, self.degree)
    }

    /// The law's value at each radius as BladeX finds it (`compute_deformed_parameters`):
    /// the first of `npoints` samples whose radius is within `tol`.
    ///
    /// # Errors
    ///
    /// [`Error::RadialLaw`] naming the radius no sample is within `tol` of.
    pub fn sampled_values(&self, radii: &[f64], npoints: usize, tol: f64) -> Result<Vec<f64>> {
        let s = self.samples(npoints)?;
        radii
            .iter()
            .map(|&r| {
                s.iter().find(|q| (q[0] - r).abs() < tol).map(|q| q[1]).ok_or_else(|| {
                    law_error(
                        self.param,
                        format!("no sample within {tol} of radius {r}: increase the tolerance or spline npoints"),
                    )
                })
            })
            .collect()
    }

    /// The law's value at radius `r` exactly: the curve parameter where its radius is
    /// `r` (found by bisection, the radius being monotone when the control radii are),
    /// then the value there.
    ///
    /// # Errors
    ///
    /// [`Error::RadialLaw`] when `r` is outside the law's radii.
    pub fn value_at(&self, r: f64) -> Result<f64> {
        let n = self.control_points.len();
        let knots: KnotVector = bladex_knots(n, self.degree)?;
        let top = (n - self.degree) as f64;
        let at = |u: f64| {
            let (s, vals) = basis_row(&knots, self.degree, u);
            let mut q = [0.0; 2];
            for (j, v) in vals.iter().enumerate() {
                q[0] += v * self.control_points[s + j][0];
                q[1] += v * self.control_points[s + j][1];
            }
            q
        };
        let (r0, r1) = (self.control_points[0][0], self.control_points[n - 1][0]);
        let span = (r1 - r0).abs();
        if (r - r0) * (r - r1) > 1e-12 * span * span {
            return Err(law_error(self.param, format!("radius {r} outside [{r0}, {r1}]")));
        }
        let (mut lo, mut hi) = (0.0, top);
        let up = r1 > r0;
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if (at(mid)[0] < r) == up {
                lo = mid;
            } else {
                hi = mid;
            }
            if hi - lo < 1e-15 * top {
                break;
            }
        }
        Ok(at(0.5 * (lo + hi))[1])
    }
}

/// All five laws of a parameter file, fitted, deformed and sampled back at the file's
/// radii (BladeX `Deformation.compute_all`).
#[derive(Debug, Clone)]
pub struct Deformation {
    /// The parameter file.
    pub prm: ParamFile,
    /// The fitted laws (before deformation), by [`LawParam::index`].
    pub laws: Vec<RadialLaw>,
    /// The deformed laws.
    pub deformed_laws: Vec<RadialLaw>,
    /// The deformed distributions at the file's radii.
    pub deformed: [Vec<f64>; 5],
}

impl Deformation {
    /// Fits, deforms and samples every law (`rbf_points` as BladeX's default 1000; `tol`
    /// per parameter as in `compute_all`).
    ///
    /// # Errors
    ///
    /// As [`RadialLaw::fit`] and [`RadialLaw::sampled_values`].
    pub fn compute_all(prm: ParamFile, rbf_points: usize, tol: [f64; 5]) -> Result<Self> {
        let mut laws = Vec::new();
        let mut deformed_laws = Vec::new();
        let mut deformed: [Vec<f64>; 5] = Default::default();
        for p in LawParam::ALL {
            let s = &prm.settings[p.index()];
            let law = RadialLaw::fit(p, &prm.radii, &prm.parameters[p.index()], s.degree, s.nbasis, rbf_points)?;
            let mut d = law.clone();
            d.deform(&s.deformations)?;
            deformed[p.index()] = d.sampled_values(&prm.radii, s.npoints, tol[p.index()])?;
            laws.push(law);
            deformed_laws.push(d);
        }
        Ok(Self { prm, laws, deformed_laws, deformed })
    }

    /// The parameter file of the deformed blade (BladeX `export_param_file`): deformed
    /// distributions where a law was deformed, the original elsewhere, zero deformations.
    /// (BladeX writes `degree = nbasis` there, a slip this does not copy.)
    pub fn deformed_param_file(&self) -> ParamFile {
        let mut out = self.prm.clone();
        for p in LawParam::ALL {
            let s = &mut out.settings[p.index()];
            if s.deformations.iter().any(|d| *d != 0.0) {
                out.parameters[p.index()] = self.deformed[p.index()].clone();
            }
            s.deformations = vec![0.0; s.nbasis];
        }
        out
    }
}
