//! A deformation from a closure: object-specific laws (a hull's chine law, a blade's
//! radial law) written as plain Rust functions.

use nalgebra::Point3;

use crate::Deformation;

/// The deformation `p ↦ f(p)` of a closure (see [`from_fn`]). It has no Jacobian in
/// closed form ([`Deformation::jacobian`] is `None`), so a morph does not check it for
/// folds; make sure the law is one-to-one where the model lies.
#[derive(Clone, Copy)]
pub struct FromFn<F>(F);

impl<F> std::fmt::Debug for FromFn<F> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("FromFn(..)")
    }
}

/// The deformation that maps each point with `f`.
///
/// ```
/// use cadmorph_morph::{from_fn, Deformation};
/// use cadmorph_morph::math::Point3;
/// // Widen a hull by 5 % at mid-length (x = 72.5 m), nothing at the ends.
/// let law = from_fn(|p: &Point3<f64>| {
///     let s = (std::f64::consts::PI * p.x / 145.0).sin();
///     Point3::new(p.x, p.y * (1.0 + 0.05 * s), p.z)
/// });
/// let q = law.deform_point(&Point3::new(72.5, 10.0, 0.0));
/// assert!((q.y - 10.5).abs() < 1e-12);
/// ```
pub fn from_fn<F: Fn(&Point3<f64>) -> Point3<f64> + Sync>(f: F) -> FromFn<F> {
    FromFn(f)
}

impl<F: Fn(&Point3<f64>) -> Point3<f64> + Sync> Deformation for FromFn<F> {
    fn deform_point(&self, p: &Point3<f64>) -> Point3<f64> {
        (self.0)(p)
    }
}
