//! Surfaces and OCCT evaluations from the `*.ref.json` files of `samples/`.
//!
//! These files hold, for each B-spline face of a sample, OCCT's own data (degrees,
//! knots, poles, weights) and OCCT's evaluation at 50 parameter pairs. Reading them
//! lets `cadmorph eval` (and the tests) compare cadmorph's evaluation with OCCT's before the IGES and
//! STEP readers exist.

use anyhow::{bail, Context, Result};
use cadmorph_nurbs::math::{Point3, Vector3};
use cadmorph_nurbs::{KnotVector, NurbsSurface};
use serde_json::Value;

/// A face of a reference file.
#[derive(Debug)]
pub struct RefFace {
    /// Position in the file's `faces` list.
    pub index: usize,
    /// OCCT class name.
    pub class: String,
    /// The surface, for B-spline faces.
    pub surface: Option<NurbsSurface>,
    /// OCCT's evaluations.
    pub samples: Vec<RefSample>,
}

/// OCCT's evaluation of a face at one parameter pair.
#[derive(Debug, Clone, Copy)]
pub struct RefSample {
    /// u.
    pub u: f64,
    /// v.
    pub v: f64,
    /// S(u, v).
    pub point: Point3<f64>,
    /// normalize(S_u × S_v), `None` where OCCT gave none.
    pub normal: Option<Vector3<f64>>,
}

fn num(v: &Value, what: &str) -> Result<f64> {
    v.as_f64().with_context(|| format!("{what}: expected a number, found {v}"))
}

fn nums(v: &Value, what: &str) -> Result<Vec<f64>> {
    v.as_array().with_context(|| format!("{what}: expected a list"))?.iter().map(|x| num(x, what)).collect()
}

fn point(v: &Value, what: &str) -> Result<Point3<f64>> {
    match nums(v, what)?.as_slice() {
        &[x, y, z] => Ok(Point3::new(x, y, z)),
        other => bail!("{what}: expected 3 coordinates, found {}", other.len()),
    }
}

fn knots(face: &Value, dir: &str, degree: usize, periodic: bool) -> Result<KnotVector> {
    let values = nums(&face[format!("{dir}_knots")], "knots")?;
    let mults: Vec<usize> = nums(&face[format!("{dir}_mults")], "mults")?.into_iter().map(|m| m as usize).collect();
    Ok(if periodic {
        KnotVector::periodic(degree, &values, &mults)?
    } else {
        KnotVector::from_multiplicities(&values, &mults)?
    })
}

fn bspline(face: &Value) -> Result<NurbsSurface> {
    let p = num(&face["u_degree"], "u_degree")? as usize;
    let q = num(&face["v_degree"], "v_degree")? as usize;
    let uper = face["u_periodic"].as_bool().unwrap_or(false);
    let vper = face["v_periodic"].as_bool().unwrap_or(false);
    if uper || vper {
        bail!("periodic reference surfaces are not read by this preview");
    }
    let uk = knots(face, "u", p, uper)?;
    let vk = knots(face, "v", q, vper)?;
    let rows = face["poles"].as_array().context("poles: expected a list of rows")?;
    let n_u = rows.len();
    let n_v = rows.first().and_then(Value::as_array).map_or(0, Vec::len);
    let mut pts = Vec::with_capacity(n_u * n_v);
    for row in rows {
        for c in row.as_array().context("poles: expected rows")? {
            pts.push(point(c, "pole")?);
        }
    }
    let weights = match &face["weights"] {
        Value::Null => None,
        w => Some(
            w.as_array()
                .context("weights: expected rows")?
                .iter()
                .map(|r| nums(r, "weights"))
                .collect::<Result<Vec<_>>>()?
                .concat(),
        ),
    };
    Ok(NurbsSurface::try_new((p, q), (uk, vk), (n_u, n_v), pts, weights)?)
}

/// Reads the faces of a `*.ref.json` file.
///
/// # Errors
///
/// If the file is not JSON or a B-spline face's data is malformed (naming the face).
pub fn read_faces(text: &str) -> Result<Vec<RefFace>> {
    let doc: Value = serde_json::from_str(text).context("not a JSON document")?;
    let faces = doc["faces"].as_array().context("no `faces` list")?;
    let mut out = Vec::with_capacity(faces.len());
    for (index, face) in faces.iter().enumerate() {
        let class = face["class"].as_str().unwrap_or("?").to_string();
        let surface = if class == "Geom_BSplineSurface" {
            Some(bspline(face).with_context(|| format!("face {index}"))?)
        } else {
            None
        };
        let mut samples = Vec::new();
        for s in face["samples"].as_array().into_iter().flatten() {
            let n = match &s["n"] {
                Value::Null => None,
                n => Some(point(n, "normal")?.coords),
            };
            samples.push(RefSample {
                u: num(&s["u"], "u")?,
                v: num(&s["v"], "v")?,
                point: point(&s["p"], "point")?,
                normal: n,
            });
        }
        out.push(RefFace { index, class, surface, samples });
    }
    Ok(out)
}
