//! Affine maps `x ↦ A x + t`.

use nalgebra::{Matrix3, Point3, Vector3};

use crate::Deformation;

/// An affine map `φ(x) = A x + t` (paper §2.1: the ψ of the FFD, or a global scaling or
/// rotation of a part).
///
/// # Examples
///
/// ```
/// use cadmorph_morph::{Affine, Deformation};
/// use cadmorph_morph::math::{Point3, Vector3};
/// // 90° about z, counter-clockwise, PyGeM angle convention.
/// let rot = Affine::rotation_degrees(Vector3::new(0.0, 0.0, 90.0));
/// let p = rot.deform_point(&Point3::new(1.0, 0.0, 0.0));
/// assert!((p - Point3::new(0.0, 1.0, 0.0)).norm() < 1e-15);
/// assert_eq!(rot.jacobian(&p).unwrap(), rot.linear);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Affine {
    /// The linear part A.
    pub linear: Matrix3<f64>,
    /// The translation t.
    pub translation: Vector3<f64>,
}

impl Affine {
    /// `x ↦ A x + t`.
    pub fn new(linear: Matrix3<f64>, translation: Vector3<f64>) -> Self {
        Affine { linear, translation }
    }

    /// The identity map.
    pub fn identity() -> Self {
        Affine::new(Matrix3::identity(), Vector3::zeros())
    }

    /// `x ↦ x + t`.
    pub fn translation(t: Vector3<f64>) -> Self {
        Affine::new(Matrix3::identity(), t)
    }

    /// `x ↦ diag(s) x`, scaling about the origin.
    pub fn scaling(s: Vector3<f64>) -> Self {
        Affine::new(Matrix3::from_diagonal(&s), Vector3::zeros())
    }

    /// Rotation about the origin by angles (degrees) about x, y and z, composed as PyGeM's
    /// FFD box rotation does: `R = Rx · Ry · Rz` (see [`rotation_matrix`]).
    pub fn rotation_degrees(angles: Vector3<f64>) -> Self {
        Affine::new(rotation_matrix(&angles), Vector3::zeros())
    }

    /// The inverse map, or `None` when A is singular.
    pub fn try_inverse(&self) -> Option<Affine> {
        let inv = self.linear.try_inverse()?;
        Some(Affine::new(inv, -(inv * self.translation)))
    }
}

impl Default for Affine {
    fn default() -> Self {
        Affine::identity()
    }
}

impl Deformation for Affine {
    fn deform_point(&self, p: &Point3<f64>) -> Point3<f64> {
        Point3::from(self.linear * p.coords + self.translation)
    }
    fn jacobian(&self, _p: &Point3<f64>) -> Option<Matrix3<f64>> {
        Some(self.linear)
    }
}

/// The rotation matrix for angles in degrees about x, y and z, `R = Rx · Ry · Rz`, each
/// counter-clockwise (right-hand rule). This is PyGeM's `angles2matrix(rz, ry, rx)`
/// (`pygem/utils.py`), which multiplies its list `[Rz, Ry, Rx]` in reverse order; PyGeM
/// converts degrees with `np.radians`, as [`f64::to_radians`] does here.
pub fn rotation_matrix(angles_deg: &Vector3<f64>) -> Matrix3<f64> {
    let (sx, cx) = angles_deg.x.to_radians().sin_cos();
    let (sy, cy) = angles_deg.y.to_radians().sin_cos();
    let (sz, cz) = angles_deg.z.to_radians().sin_cos();
    // PyGeM skips a factor whose angle is zero; a zero angle gives the exact identity here too
    // (sin 0 = 0, cos 0 = 1), so the products are the same.
    let rx = Matrix3::new(1.0, 0.0, 0.0, 0.0, cx, -sx, 0.0, sx, cx);
    let ry = Matrix3::new(cy, 0.0, sy, 0.0, 1.0, 0.0, -sy, 0.0, cy);
    let rz = Matrix3::new(cz, -sz, 0.0, sz, cz, 0.0, 0.0, 0.0, 1.0);
    (rx * ry) * rz
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotation_order_is_x_then_y_then_z_matrices() {
        // Rx(90)·Ry(90) applied to e_z: Ry(90) e_z = e_x, then Rx(90) e_x = e_x.
        let r = rotation_matrix(&Vector3::new(90.0, 90.0, 0.0));
        let v = r * Vector3::z();
        assert!((v - Vector3::x()).norm() < 1e-15, "{v}");
        // The other order would give Ry(90)·Rx(90) e_z = Ry(90)(-e_y) = -e_y.
        assert!((v + Vector3::y()).norm() > 1.0);
    }

    #[test]
    fn inverse_composes_to_identity() {
        let a = Affine::new(Matrix3::new(2.0, 0.1, 0.0, 0.0, 1.0, 0.3, 0.2, 0.0, 3.0), Vector3::new(1.0, -2.0, 0.5));
        let b = a.try_inverse().unwrap();
        let p = Point3::new(0.3, 0.7, -1.1);
        assert!((b.deform_point(&a.deform_point(&p)) - p).norm() < 1e-14);
        assert!(Affine::scaling(Vector3::new(1.0, 0.0, 1.0)).try_inverse().is_none());
    }
}
