//! Normals at degenerate points against closed forms: a sphere's poles and a cone's apex,
//! where one partial derivative of the exact NURBS form vanishes and the cross product of
//! the other with its rounding noise would point anywhere in the tangent plane.

use cadmorph_nurbs::analytic::{AnalyticSurface, Cone, Placement, Sphere};
use cadmorph_nurbs::math::{Point3, Vector3};
use cadmorph_nurbs::Surface;
use std::f64::consts::{FRAC_PI_2, FRAC_PI_6, TAU};

fn turned() -> Placement {
    // An off-axis frame with 12-digit directions, as STEP files give them.
    Placement::try_new(
        Point3::new(109.30455269801, -51.109746446, 34.805193747989),
        Vector3::new(-0.450325192715, 0.293553317572, -0.843228124856),
        Vector3::new(-0.843228124856, -0.450325192715, 0.293553317572),
    )
    .unwrap()
}

fn angle(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}

/// At either pole of a sphere (whole and octant faces, every longitude, knots between
/// the quarter arcs included) the normal is the outward axis: ±Z of the placement.
#[test]
fn a_sphere_pole_has_the_axis_as_its_normal() {
    let f = turned();
    let sphere = Sphere::try_new(f, 3.0).unwrap();
    for (u0, u1) in [(0.0, TAU), (-FRAC_PI_2, 0.0), (1.0, 2.5)] {
        let exact = sphere.to_nurbs(u0..=u1, -FRAC_PI_2..=FRAC_PI_2).unwrap();
        let s = &exact.surface;
        for pole in [-1.0f64, 1.0] {
            for k in 0..=16 {
                let u = u0 + (u1 - u0) * k as f64 / 16.0;
                let (su, sv) = exact.nurbs_params(u, pole * FRAC_PI_2);
                let n = s.normal(su, sv).expect("a normal at the pole");
                let err = angle(&n, &(f.z_dir() * pole));
                assert!(err < 1e-12, "u {u}, pole {pole}: {err:e} rad off the axis");
                // Just off the pole the direct cross product is used; it agrees to its
                // rounding, ~ε·|origin| / (1e-6 r) (the frame sits 125 from the world origin).
                let v = pole * (FRAC_PI_2 - 1e-6);
                let (su, sv) = exact.nurbs_params(u, v);
                let radial = exact.surface.eval(su, sv) - f.origin();
                let err = angle(&s.normal(su, sv).unwrap(), &radial);
                assert!(err < 1e-7, "u {u}, 1e-6 from the pole {pole}: {err:e} rad");
            }
        }
    }
}

/// At a cone's apex the normal along each generator is that generator's own (constant
/// along it): the limit taken from the side of the face.
#[test]
fn a_cone_apex_has_each_generators_normal() {
    let f = turned();
    let cone = Cone::try_new(f, 0.0, FRAC_PI_6).unwrap();
    let exact = cone.to_nurbs(0.0..=TAU, 0.0..=2.0).unwrap();
    for k in 0..=24 {
        let u = TAU * k as f64 / 24.0;
        let (su, apex) = exact.nurbs_params(u, 0.0);
        let (_, mid) = exact.nurbs_params(u, 1.0);
        let at_apex = exact.surface.normal(su, apex).expect("a normal at the apex");
        let along = exact.surface.normal(su, mid).unwrap();
        let err = angle(&at_apex, &along);
        assert!(err < 1e-12, "u {u}: {err:e} rad");
        // The closed form, up to the orientation the revolution gives the NURBS form.
        let closed_form = cone.normal(u, 1.0).unwrap();
        let err = angle(&along, &closed_form);
        assert!(err.min(std::f64::consts::PI - err) < 1e-12, "u {u}: {err:e} rad from the cone's normal");
    }
}
