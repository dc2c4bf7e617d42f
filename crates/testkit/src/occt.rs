//! The OCCT reference evaluations shipped as `samples/*.ref.json`.

use cadmorph_nurbs::math::Point3;
use cadmorph_nurbs::{KnotVector, NurbsCurve, NurbsSurface};
use serde::Deserialize;

/// One `*.ref.json` file.
#[derive(Debug, Deserialize)]
pub struct Reference {
    /// The data file it describes.
    pub file: String,
    /// `"M"` or `"MM"`: the unit of every length in the file.
    pub result_unit: String,
    /// Faces in OCCT order.
    pub faces: Vec<FaceRef>,
    /// Curves not bound to a face.
    pub free_curves: Vec<CurveRef>,
}

/// One face: its surface class and, for B-splines, the full definition.
#[derive(Debug, Deserialize)]
pub struct FaceRef {
    /// OCCT class, e.g. `Geom_BSplineSurface`, `Geom_Plane`.
    pub class: String,
    /// Face orientation reversed relative to the surface.
    pub reversed: bool,
    /// `[u0, u1, v0, v1]`.
    pub bounds: [f64; 4],
    /// Degree in u.
    pub u_degree: Option<usize>,
    /// Degree in v.
    pub v_degree: Option<usize>,
    /// Distinct u knots.
    pub u_knots: Option<Vec<f64>>,
    /// Their multiplicities.
    pub u_mults: Option<Vec<usize>>,
    /// Distinct v knots.
    pub v_knots: Option<Vec<f64>>,
    /// Their multiplicities.
    pub v_mults: Option<Vec<usize>>,
    /// Periodic in u.
    pub u_periodic: Option<bool>,
    /// Periodic in v.
    pub v_periodic: Option<bool>,
    /// `poles[i_u][i_v]`.
    pub poles: Option<Vec<Vec<[f64; 3]>>>,
    /// `weights[i_u][i_v]` when rational.
    pub weights: Option<Vec<Vec<f64>>>,
    /// Evaluations.
    #[serde(default)]
    pub samples: Vec<SurfaceSample>,
}

/// OCCT's evaluation at one `(u, v)`.
#[derive(Debug, Deserialize)]
pub struct SurfaceSample {
    /// u.
    pub u: f64,
    /// v.
    pub v: f64,
    /// S(u, v).
    pub p: [f64; 3],
    /// ∂S/∂u.
    pub du: [f64; 3],
    /// ∂S/∂v.
    pub dv: [f64; 3],
    /// normalize(du × dv), `None` where OCCT found none.
    pub n: Option<[f64; 3]>,
}

/// One free curve.
#[derive(Debug, Deserialize)]
pub struct CurveRef {
    /// OCCT class.
    pub class: String,
    /// Degree.
    pub degree: Option<usize>,
    /// Distinct knots.
    pub knots: Option<Vec<f64>>,
    /// Multiplicities.
    pub mults: Option<Vec<usize>>,
    /// Periodic.
    pub periodic: Option<bool>,
    /// Poles.
    pub poles: Option<Vec<[f64; 3]>>,
    /// Weights when rational.
    pub weights: Option<Vec<f64>>,
    /// Evaluations.
    #[serde(default)]
    pub samples: Vec<CurveSample>,
}

/// OCCT's evaluation at one `t`.
#[derive(Debug, Deserialize)]
pub struct CurveSample {
    /// t.
    pub t: f64,
    /// C(t).
    pub p: [f64; 3],
    /// C'(t).
    pub d1: [f64; 3],
}

/// Reads `samples/<name>.ref.json`.
pub fn reference(name: &str) -> Reference {
    let path = crate::sample(&format!("{name}.ref.json"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

impl FaceRef {
    /// The B-spline surface OCCT holds, built through cadmorph's checked constructors
    /// (periodic directions unrolled). `None` for analytic classes.
    pub fn to_nurbs(&self) -> Option<cadmorph_nurbs::Result<NurbsSurface>> {
        let poles = self.poles.as_ref()?;
        let (p, q) = (self.u_degree?, self.v_degree?);
        let mut pts: Vec<Vec<Point3<f64>>> =
            poles.iter().map(|row| row.iter().map(|&c| Point3::from(c)).collect()).collect();
        let mut w: Option<Vec<Vec<f64>>> = self.weights.clone();
        let build = |deg: usize, k: &[f64], m: &[usize], periodic: bool| {
            if periodic {
                KnotVector::periodic(deg, k, m)
            } else {
                KnotVector::from_multiplicities(k, m)
            }
        };
        let uper = self.u_periodic.unwrap_or(false);
        let vper = self.v_periodic.unwrap_or(false);
        let result = (|| {
            let uk = build(p, self.u_knots.as_ref()?, self.u_mults.as_ref()?, uper);
            let vk = build(q, self.v_knots.as_ref()?, self.v_mults.as_ref()?, vper);
            Some((uk, vk))
        })()?;
        let (uk, vk) = match result {
            (Ok(a), Ok(b)) => (a, b),
            (Err(e), _) | (_, Err(e)) => return Some(Err(e)),
        };
        if uper {
            let head: Vec<_> = pts[..p].to_vec();
            pts.extend(head);
            if let Some(w) = &mut w {
                let head: Vec<_> = w[..p].to_vec();
                w.extend(head);
            }
        }
        if vper {
            for row in &mut pts {
                let head: Vec<_> = row[..q].to_vec();
                row.extend(head);
            }
            if let Some(w) = &mut w {
                for row in w.iter_mut() {
                    let head: Vec<_> = row[..q].to_vec();
                    row.extend(head);
                }
            }
        }
        let n_u = pts.len();
        let n_v = pts.first().map_or(0, Vec::len);
        let flat: Vec<Point3<f64>> = pts.into_iter().flatten().collect();
        let wflat = w.map(|w| w.into_iter().flatten().collect());
        Some(NurbsSurface::try_new((p, q), (uk, vk), (n_u, n_v), flat, wflat))
    }
}

impl CurveRef {
    /// The B-spline curve OCCT holds; `None` for analytic classes.
    pub fn to_nurbs(&self) -> Option<cadmorph_nurbs::Result<NurbsCurve>> {
        let poles: Vec<Point3<f64>> = self.poles.as_ref()?.iter().map(|&c| Point3::from(c)).collect();
        let (k, m) = (self.knots.as_ref()?, self.mults.as_ref()?);
        let p = self.degree?;
        Some(if self.periodic.unwrap_or(false) {
            NurbsCurve::try_periodic(p, k, m, poles, self.weights.clone())
        } else {
            KnotVector::from_multiplicities(k, m).and_then(|kv| NurbsCurve::try_new(p, kv, poles, self.weights.clone()))
        })
    }
}
