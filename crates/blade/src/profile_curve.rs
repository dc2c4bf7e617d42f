//! A profile as one NURBS curve with a round leading edge.

use cadmorph_nurbs::math::Point3;
use cadmorph_nurbs::NurbsCurve;

use crate::loft::{averaged_knots, centripetal, interpolate_curve};
use crate::profile::Profile;
use crate::{Error, Result};

/// A profile's interpolating curve and where its leading edge is.
#[derive(Debug, Clone)]
pub struct ProfileCurve {
    /// The curve in the z = 0 plane, trailing edge (upper) → upper side → leading edge →
    /// lower side → trailing edge (lower).
    pub curve: NurbsCurve,
    /// Parameter of the leading edge.
    pub leading_edge: f64,
    /// Parameter of every input point, upper points reversed first.
    pub params: Vec<f64>,
}

impl Profile {
    /// The profile as one interpolating B-spline of degree `p` (P&T A9.1, centripetal
    /// parameters eq. 9.6, knots by averaging eq. 9.8) through all points of both sides,
    /// run from the upper trailing edge round the leading edge to the lower one. The
    /// leading edge is an ordinary (simple or no) knot of the curve, so the curve is
    /// C^(p−1) there: the leading edge stays round, with no kink between the sides
    /// (splitting at [`ProfileCurve::leading_edge`] gives the two sides as curves that
    /// meet with the same tangent).
    ///
    /// # Errors
    ///
    /// [`Error::Profile`] when the sides do not meet at the leading edge (within 1e-6 of
    /// the chord); the interpolation's errors.
    pub fn to_curve(&self, p: usize) -> Result<ProfileCurve> {
        let le = self.leading_edge()?;
        let chord = self.parameters(crate::Convention::British).map(|q| q.chord_length).unwrap_or(1.0);
        if (self.xdown[0] - le[0]).hypot(self.ydown[0] - le[1]) > 1e-6 * chord {
            return Err(Error::profile("ydown[0]", "the sides do not meet at the leading edge"));
        }
        let mut pts: Vec<Point3<f64>> =
            self.xup.iter().zip(&self.yup).rev().map(|(x, y)| Point3::new(*x, *y, 0.0)).collect();
        let k = pts.len() - 1;
        pts.extend(self.xdown.iter().zip(&self.ydown).skip(1).map(|(x, y)| Point3::new(*x, *y, 0.0)));
        let p = p.clamp(1, pts.len() - 1);
        let params = centripetal(&pts)?;
        let knots = averaged_knots(&params, p)?;
        let curve = interpolate_curve(&pts, &params, &knots, p)?;
        Ok(ProfileCurve { curve, leading_edge: params[k], params })
    }
}
