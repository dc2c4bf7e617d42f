//! A propeller: `n` copies of a blade solid around the x axis and a cylindrical hub,
//! each a separate closed solid (BladeX `Propeller`, which unites nothing either: it
//! writes the blade faces and the shaft side by side).
//!
//! The blades are not united with the hub because a union needs the blade–hub
//! surface intersection (a boolean operation cadmorph does not have); instead each
//! blade's root section lies on the cylinder of the root radius and its root cap (ruled
//! between two curves on that cylinder) lies inside it, so with `hub_radius` = root
//! radius every blade solid meets the hub solid along the root section and overlaps it
//! only in the thin sliver between cap and cylinder. Every solid is exact and valid on
//! its own; a mesher or `BRepAlgoAPI_Fuse` unites them when one body is needed.

use std::f64::consts::FRAC_1_SQRT_2;

use cadmorph_nurbs::math::Point3;
use cadmorph_nurbs::{KnotVector, NurbsSurface};

use crate::blade::rotation;
use crate::solid::{face_volume, BladeSolid};
use crate::{Error, Result};

/// The unit circle `(cos t, sin t)` as a rational quadratic with 9 control points
/// (Piegl & Tiller §7.5, Ex. 7.2): control points and weights.
fn circle() -> (Vec<[f64; 2]>, Vec<f64>) {
    let p = vec![
        [1.0, 0.0],
        [1.0, 1.0],
        [0.0, 1.0],
        [-1.0, 1.0],
        [-1.0, 0.0],
        [-1.0, -1.0],
        [0.0, -1.0],
        [1.0, -1.0],
        [1.0, 0.0],
    ];
    let w = (0..9).map(|i| if i % 2 == 1 { FRAC_1_SQRT_2 } else { 1.0 }).collect();
    (p, w)
}

fn circle_knots() -> Result<KnotVector> {
    Ok(KnotVector::try_new(vec![0.0, 0.0, 0.0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1.0, 1.0, 1.0])?)
}

/// The closed cylinder `r ≤ radius`, `x0 ≤ x ≤ x1` about the x axis as three outward
/// NURBS faces: the lateral face (u around, v along x) and two discs (u around, v from
/// the rim to the centre).
///
/// # Errors
///
/// [`Error::Geometry`] for a non-positive radius or length.
pub fn hub_cylinder(radius: f64, x0: f64, x1: f64) -> Result<Vec<NurbsSurface>> {
    if !(radius > 0.0 && x1 > x0) {
        return Err(Error::Geometry(format!("hub radius {radius} and length {} must be positive", x1 - x0)));
    }
    let (c, w) = circle();
    let lin = KnotVector::try_new(vec![0.0, 0.0, 1.0, 1.0])?;
    // Lateral: point (x, r cos t, r sin t); S_u × S_v must point out: with u around
    // (+t, from y to z) and v along +x the normal (∂/∂t) × x̂ points radially out.
    let mut net = Vec::new();
    let mut wt = Vec::new();
    for (q, wi) in c.iter().zip(&w) {
        for x in [x0, x1] {
            net.push(Point3::new(x, radius * q[0], radius * q[1]));
            wt.push(*wi);
        }
    }
    let lateral = NurbsSurface::try_new((2, 1), (circle_knots()?, lin.clone()), (9, 2), net, Some(wt))?;
    let disc = |x: f64, outward_plus: bool| -> Result<NurbsSurface> {
        let mut net = Vec::new();
        let mut wt = Vec::new();
        for (q, wi) in c.iter().zip(&w) {
            // rim then centre; the centre point carries the same weight so the
            // rational form stays a straight ruling.
            net.push(Point3::new(x, radius * q[0], radius * q[1]));
            net.push(Point3::new(x, 0.0, 0.0));
            wt.push(*wi);
            wt.push(*wi);
        }
        let s = NurbsSurface::try_new((2, 1), (circle_knots()?, lin.clone()), (9, 2), net, Some(wt))?;
        // (∂/∂t) × (towards centre) = +x̂ for this layout.
        Ok(if outward_plus { s } else { s.u_reversed() })
    };
    Ok(vec![lateral, disc(x1, true)?, disc(x0, false)?])
}

/// A propeller: blade solids and hub faces.
#[derive(Debug, Clone)]
pub struct Propeller {
    /// One solid per blade, blade `k` turned by `2πk/n` about x.
    pub blades: Vec<BladeSolid>,
    /// The hub's faces (one closed solid).
    pub hub: Vec<NurbsSurface>,
}

impl Propeller {
    /// `n` copies of `blade` and a hub of `hub_radius` from `x0` to `x1`.
    ///
    /// # Errors
    ///
    /// [`Error::Geometry`] for zero blades or a bad hub.
    pub fn new(blade: &BladeSolid, n: usize, hub_radius: f64, x0: f64, x1: f64) -> Result<Self> {
        if n == 0 {
            return Err(Error::Geometry("a propeller needs at least one blade".into()));
        }
        // Each copy holds every pole (and weight) of the blade's faces.
        let poles: usize = blade.faces().iter().map(|f| f.control_points().len()).sum();
        cadmorph_morph::budget::check("propeller blades", &[n, poles, 4], 8)
            .map_err(|e| Error::Geometry(e.to_string()))?;
        let blades = (0..n)
            .map(|k| {
                let mut b = blade.clone();
                b.transform_by(&rotation(0, 2.0 * std::f64::consts::PI * k as f64 / n as f64));
                b
            })
            .collect();
        Ok(Self { blades, hub: hub_cylinder(hub_radius, x0, x1)? })
    }

    /// Every solid as a face list: the blades, then the hub.
    pub fn solids(&self) -> Vec<Vec<&NurbsSurface>> {
        let mut v: Vec<Vec<&NurbsSurface>> = self.blades.iter().map(|b| b.faces()).collect();
        v.push(self.hub.iter().collect());
        v
    }

    /// The hub volume (divergence theorem over its faces).
    pub fn hub_volume(&self) -> f64 {
        self.hub.iter().map(face_volume).sum()
    }
}
