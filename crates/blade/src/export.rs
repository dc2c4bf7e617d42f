//! Writing blade and propeller solids: STEP through `cadmorph_step::DocumentBuilder`
//! (`MANIFOLD_SOLID_BREP` of a `CLOSED_SHELL` of `ADVANCED_FACE`s) and IGES through
//! `cadmorph_iges::write::DocumentBuilder` (186 manifold solid → 514 shell → 510 faces on
//! 128 surfaces, 508 loops, 504 edges on 126 curves, 502 vertices).

use cadmorph_iges::write::DocumentBuilder as IgesBuilder;
use cadmorph_iges::{EntityId, Status, Units, Value};
use cadmorph_nurbs::math::Point3;
use cadmorph_nurbs::{Curve, NurbsCurve, NurbsSurface, Side, Surface};
use cadmorph_step::{DocumentBuilder as StepBuilder, Schema};

use crate::Result;

/// Length unit of a written file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LengthUnit {
    /// Metres.
    #[default]
    M,
    /// Millimetres.
    Mm,
}

impl LengthUnit {
    fn metres(self) -> f64 {
        match self {
            LengthUnit::M => 1.0,
            LengthUnit::Mm => 1e-3,
        }
    }
    fn iges(self) -> Units {
        match self {
            LengthUnit::M => Units::Metre,
            LengthUnit::Mm => Units::Millimetre,
        }
    }
}

/// The STEP text of one or more solids, each a list of closed, outward faces.
///
/// # Errors
///
/// Those of the STEP builder (the generated text is parsed back and checked).
pub fn step_solids(name: &str, solids: &[Vec<&NurbsSurface>], unit: LengthUnit, tol: f64) -> Result<Vec<u8>> {
    let mut b = StepBuilder::new(Schema::Ap214, name, unit.metres(), tol)?;
    for s in solids {
        let faces: Vec<NurbsSurface> = s.iter().map(|f| (*f).clone()).collect();
        b.add_solid(&faces, tol);
    }
    Ok(b.build()?.write())
}

/// The topology of one closed shell, found as the STEP builder finds it: vertices that
/// coincide within `tol`, edges with the same end vertices and midpoint, loops
/// `VMin(+) UMax(+) VMax(−) UMin(−)` without collapsed sides.
pub(crate) struct Shell {
    pub(crate) vertices: Vec<Point3<f64>>,
    /// (start vertex, end vertex, curve)
    pub(crate) edges: Vec<(usize, usize, NurbsCurve)>,
    /// per face: (edge, agrees with the edge's curve direction)
    pub(crate) loops: Vec<Vec<(usize, bool)>>,
    /// per edge: the (face, side) boundaries that use it
    pub(crate) uses: Vec<Vec<(usize, Side)>>,
}

pub(crate) fn shell_topology(faces: &[&NurbsSurface], tol: f64) -> Shell {
    let tol_sq = tol * tol;
    let mut vertices: Vec<Point3<f64>> = Vec::new();
    let mut edges: Vec<(usize, usize, NurbsCurve)> = Vec::new();
    let mut mids: Vec<Point3<f64>> = Vec::new();
    let mut loops = Vec::new();
    let mut uses: Vec<Vec<(usize, Side)>> = Vec::new();
    for (fi, s) in faces.iter().enumerate() {
        let (ud, vd) = s.domain();
        let (u0, u1, v0, v1) = (*ud.start(), *ud.end(), *vd.start(), *vd.end());
        let corners = [s.eval(u0, v0), s.eval(u1, v0), s.eval(u1, v1), s.eval(u0, v1)];
        let vid: Vec<usize> = corners
            .iter()
            .map(|c| match vertices.iter().position(|p| (p - c).norm_squared() <= tol_sq) {
                Some(i) => i,
                None => {
                    vertices.push(*c);
                    vertices.len() - 1
                }
            })
            .collect();
        let sides =
            [(Side::VMin, 0, 1, true), (Side::UMax, 1, 2, true), (Side::VMax, 3, 2, false), (Side::UMin, 0, 3, false)];
        let mut lp = Vec::new();
        for (side, a, b, forward) in sides {
            let c = s.boundary(side);
            if c.control_points().iter().all(|p| (p - corners[a]).norm_squared() <= tol_sq) {
                continue;
            }
            let cd = c.domain();
            let mid = c.eval((cd.start() + cd.end()) / 2.0);
            let (va, vb) = (vid[a], vid[b]);
            let found = edges.iter().zip(&mids).position(|(e, m)| {
                ((e.0 == va && e.1 == vb) || (e.0 == vb && e.1 == va)) && (m - mid).norm_squared() <= tol_sq * 100.0
            });
            let (k, same) = match found {
                Some(k) => (k, edges[k].0 == va),
                None => {
                    edges.push((va, vb, c));
                    mids.push(mid);
                    uses.push(Vec::new());
                    (edges.len() - 1, true)
                }
            };
            uses[k].push((fi, side));
            lp.push((k, same == forward));
        }
        loops.push(lp);
    }
    Shell { vertices, edges, loops, uses }
}

/// The IGES text of one or more solids (see the module docs), each a list of closed,
/// outward faces; `stamp` fixes the file dates for reproducible output.
pub fn iges_solids(solids: &[Vec<&NurbsSurface>], unit: LengthUnit, tol: f64, stamp: Option<&str>) -> Vec<u8> {
    let mut b = IgesBuilder::new(unit.iges()).resolution(tol).file_name("cadmorph-blade");
    if let Some(s) = stamp {
        b = b.timestamp(s);
    }
    let dependent = Status { subordinate: 1, ..Status::default() };
    let ptr = |id: EntityId| Value::Integer(i64::from(id.0));
    let int = |i: usize| Value::Integer(i as i64);
    for faces in solids {
        let shell = shell_topology(faces, tol);
        let surf: Vec<EntityId> = faces.iter().map(|s| b.add_surface(s)).collect();
        let curves: Vec<EntityId> = shell.edges.iter().map(|e| b.add_curve(&e.2)).collect();
        for id in surf.iter().chain(&curves) {
            b.set_status(*id, dependent);
        }
        let mut vl = vec![Value::Integer(502), int(shell.vertices.len())];
        for p in &shell.vertices {
            vl.extend([Value::Real(p.x), Value::Real(p.y), Value::Real(p.z)]);
        }
        let vlist = b.add_entity(1, dependent, vl);
        let mut el = vec![Value::Integer(504), int(shell.edges.len())];
        for (k, e) in shell.edges.iter().enumerate() {
            el.extend([ptr(curves[k]), ptr(vlist), int(e.0 + 1), ptr(vlist), int(e.1 + 1)]);
        }
        let elist = b.add_entity(1, dependent, el);
        let mut face_ids = Vec::new();
        for (f, lp) in shell.loops.iter().enumerate() {
            let mut l = vec![Value::Integer(508), int(lp.len())];
            for (k, agrees) in lp {
                l.extend([int(0), ptr(elist), int(k + 1), int(usize::from(*agrees)), int(0)]);
            }
            let loop_id = b.add_entity(1, dependent, l);
            face_ids.push(b.add_entity(
                1,
                dependent,
                vec![Value::Integer(510), ptr(surf[f]), int(1), int(1), ptr(loop_id)],
            ));
        }
        let mut sh = vec![Value::Integer(514), int(face_ids.len())];
        for f in &face_ids {
            sh.extend([ptr(*f), int(1)]);
        }
        let shell_id = b.add_entity(1, dependent, sh);
        b.add_entity(0, Status::default(), vec![Value::Integer(186), ptr(shell_id), int(1), int(0)]);
    }
    b.to_bytes()
}
