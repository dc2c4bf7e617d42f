//! NURBS curves and surfaces: evaluation, derivatives, refinement and projection.
//!
//! `cadmorph-nurbs` owns the geometry of cadmorph: knot vectors, B-spline basis
//! functions, [`NurbsCurve`] and [`NurbsSurface`] with rational and non-rational
//! evaluation, derivatives of any order, knot insertion (up to multiplicity p + 1),
//! refinement and removal, degree elevation (periodic splines stay periodic), degree
//! reduction and removal of every removable knot within a tolerance (with deviation
//! bounds), Bézier decomposition, splitting, reversal, iso and boundary curves, control
//! points at infinity (weight 0, evaluated in homogeneous form), and the exact extremes of
//! a polynomial curve's coordinate ([`NurbsCurve::extreme_params`], Bernstein root
//! isolation). It knows nothing of files or deformations; see `cadmorph-iges`,
//! `cadmorph-step` and `cadmorph-morph`.
//!
//! The algorithms are those of Piegl & Tiller, *The NURBS Book* (2nd ed.), cited by
//! number (A2.1 … A5.11, A12.1) where they are implemented. They are written here rather than
//! taken from a crate because cadmorph needs all of them on one representation with
//! OCCT-grade accuracy and typed errors: `truck-geometry` lacks knot removal and
//! rational surface derivatives of arbitrary order, and `curvo` (used as a test oracle)
//! works on homogeneous `OPoint` types we do not want as vocabulary.
//!
//! Points and vectors are nalgebra's `Point3<f64>` / `Vector3<f64>`, re-exported as
//! [`math`].
//!
//! ```
//! use cadmorph_nurbs::{NurbsSurface, Surface};
//! let plane = NurbsSurface::bilinear([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]]);
//! assert_eq!(plane.eval(0.5, 0.5).z, 0.0);
//! ```
//!
//! The crate has no feature flags.

use std::ops::RangeInclusive;

use nalgebra::{Point3, Unit, Vector3};

mod algo;
pub mod analytic;
mod basis;
mod compose;
mod curve;
mod error;
mod extrema;
mod fit;
mod knots;
mod project;
mod reduce;
mod surface;
mod surface_reduce;
mod tessellate;
pub mod tol;
mod unclamp;

pub use basis::{basis_funs, ders_basis_funs};
pub use compose::BezierVolume;
pub use curve::NurbsCurve;
pub use error::{Error, Result};
pub use fit::{fit_curve, fit_curve_with_breaks, greville, interpolate, FitBreak};
pub use knots::KnotVector;
pub use project::{CurveProject, CurveProjection, CurveProjector, Projection, SurfaceProject};
pub use reduce::KnotRemoval;
pub use surface::{NurbsSurface, Side, SurfaceDerivs, SurfacePointD1};
pub use tessellate::{Aabb, Mesh};

/// The vocabulary types of cadmorph (nalgebra).
pub mod math {
    pub use nalgebra::{Matrix3, Matrix4, Point3, Rotation3, Unit, Vector3, Vector4};

    /// The inverse of the affine map `m` (last row `0 0 0 1`), with the last row exactly
    /// `0 0 0 1` again (a general 4×4 inverse may leave it at `1 + ε`, which
    /// [`NurbsSurface::transform_by`](crate::NurbsSurface::transform_by) refuses):
    /// `[A t; 0 1]⁻¹ = [A⁻¹ −A⁻¹t; 0 1]`. `None` when `A` is singular or `m` is not affine.
    ///
    /// ```
    /// use cadmorph_nurbs::math::{affine_inverse, Matrix4, Vector3};
    /// let m = Matrix4::new_translation(&Vector3::new(1.0, 2.0, 3.0)) * Matrix4::new_scaling(3.0);
    /// let i = affine_inverse(&m).unwrap();
    /// assert_eq!(i.row(3), Matrix4::<f64>::identity().row(3));
    /// assert!((i * m - Matrix4::identity()).norm() < 1e-15);
    /// ```
    pub fn affine_inverse(m: &Matrix4<f64>) -> Option<Matrix4<f64>> {
        if m.row(3) != Matrix4::<f64>::identity().row(3) {
            return None;
        }
        let a: Matrix3<f64> = m.fixed_view::<3, 3>(0, 0).into_owned();
        let ai = a.try_inverse()?;
        let t = -(ai * m.fixed_view::<3, 1>(0, 3));
        let mut out = Matrix4::identity();
        out.fixed_view_mut::<3, 3>(0, 0).copy_from(&ai);
        out.fixed_view_mut::<3, 1>(0, 3).copy_from(&t);
        Some(out)
    }
}

/// The highest degree any curve or surface may have (OCCT's
/// `Geom_BSplineSurface::MaxDegree()` is 25 as well).
pub const MAX_DEGREE: usize = 25;

/// A curve C: [t₀, t₁] → ℝ³.
pub trait Curve {
    /// Parameter domain `t₀..=t₁`.
    fn domain(&self) -> RangeInclusive<f64>;
    /// The point C(t). Parameters outside the domain are evaluated on the nearest end
    /// span's polynomial (an extrapolation), never a panic.
    fn eval(&self, t: f64) -> Point3<f64>;
    /// Derivatives `d[k] = dᵏC/dtᵏ` for `k = 0..=n` (`d[0]` is the point as a vector).
    fn derivs(&self, t: f64, n: usize) -> Vec<Vector3<f64>>;
}

/// A surface S: [u₀, u₁] × [v₀, v₁] → ℝ³.
pub trait Surface {
    /// Parameter domain `(u₀..=u₁, v₀..=v₁)`.
    fn domain(&self) -> (RangeInclusive<f64>, RangeInclusive<f64>);
    /// The point S(u, v).
    fn eval(&self, u: f64, v: f64) -> Point3<f64>;
    /// All partials up to total order `n`: `d[(k, l)] = ∂^(k+l) S / ∂u^k ∂v^l`
    /// (Piegl & Tiller A3.6, rational form A4.4). `d[(0, 0)]` is the point.
    fn derivs(&self, u: f64, v: f64, n: usize) -> SurfaceDerivs;
    /// Unit normal `S_u × S_v / |S_u × S_v|`, or `None` where the cross product
    /// vanishes (poles, collapsed edges).
    fn normal(&self, u: f64, v: f64) -> Option<Unit<Vector3<f64>>> {
        let d = self.derivs(u, v, 1);
        Unit::try_new(d[(1, 0)].cross(&d[(0, 1)]), f64::EPSILON)
    }
}

impl<C: Curve + ?Sized> Curve for &C {
    fn domain(&self) -> RangeInclusive<f64> {
        (**self).domain()
    }
    fn eval(&self, t: f64) -> Point3<f64> {
        (**self).eval(t)
    }
    fn derivs(&self, t: f64, n: usize) -> Vec<Vector3<f64>> {
        (**self).derivs(t, n)
    }
}

impl<C: Curve + ?Sized> Curve for Box<C> {
    fn domain(&self) -> RangeInclusive<f64> {
        (**self).domain()
    }
    fn eval(&self, t: f64) -> Point3<f64> {
        (**self).eval(t)
    }
    fn derivs(&self, t: f64, n: usize) -> Vec<Vector3<f64>> {
        (**self).derivs(t, n)
    }
}

impl<S: Surface + ?Sized> Surface for &S {
    fn domain(&self) -> (RangeInclusive<f64>, RangeInclusive<f64>) {
        (**self).domain()
    }
    fn eval(&self, u: f64, v: f64) -> Point3<f64> {
        (**self).eval(u, v)
    }
    fn derivs(&self, u: f64, v: f64, n: usize) -> SurfaceDerivs {
        (**self).derivs(u, v, n)
    }
    fn normal(&self, u: f64, v: f64) -> Option<Unit<Vector3<f64>>> {
        (**self).normal(u, v)
    }
}

impl<S: Surface + ?Sized> Surface for Box<S> {
    fn domain(&self) -> (RangeInclusive<f64>, RangeInclusive<f64>) {
        (**self).domain()
    }
    fn eval(&self, u: f64, v: f64) -> Point3<f64> {
        (**self).eval(u, v)
    }
    fn derivs(&self, u: f64, v: f64, n: usize) -> SurfaceDerivs {
        (**self).derivs(u, v, n)
    }
    fn normal(&self, u: f64, v: f64) -> Option<Unit<Vector3<f64>>> {
        (**self).normal(u, v)
    }
}
