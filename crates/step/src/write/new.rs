//! New AP214/AP242 documents from NURBS surfaces.

use cadmorph_nurbs::math::Point3;
use cadmorph_nurbs::{Curve, NurbsCurve, NurbsSurface, Side, Surface};

use super::{format_real, knot_lists, real_list};
use crate::document::Document;
use crate::error::{Error, Position, Result};
use crate::read::param::encode_string;

/// The application protocol of a new document.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Schema {
    /// AP214 (`AUTOMOTIVE_DESIGN`), what OCCT writes by default.
    Ap214,
    /// AP242 (`AP242_MANAGED_MODEL_BASED_3D_ENGINEERING_MIM_LF`).
    Ap242,
}

/// Builds a new STEP document: one product whose shape representation holds shells of
/// NURBS faces, with units and uncertainty.
///
/// Each surface becomes an `ADVANCED_FACE` bounded by its four boundary curves; within a
/// shell, vertices and edges that coincide within `tol` are shared, so patches that meet
/// along whole boundaries form a connected shell. Collapsed boundaries (poles) are left
/// out of the loop.
///
/// # Examples
///
/// ```
/// use cadmorph_nurbs::NurbsSurface;
/// use cadmorph_step::{DocumentBuilder, Schema, SurfaceKind};
/// let a = NurbsSurface::bilinear([[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [1., 1., 0.]]);
/// let b = NurbsSurface::bilinear([[1., 0., 0.], [2., 0., 0.], [1., 1., 0.], [2., 1., 0.]]);
/// let mut builder = DocumentBuilder::new(Schema::Ap214, "two patches", 1e-3, 1e-7).unwrap();
/// builder.add_shell(&[a, b], 1e-7);
/// let doc = builder.build().unwrap();
/// let faces = doc.faces().unwrap();
/// assert_eq!(faces.len(), 2);
/// assert!(matches!(faces[0].kind, SurfaceKind::BSpline { u_degree: 1, .. }));
/// // The shared edge joins both faces.
/// assert!(doc.edges(&faces).unwrap().iter().any(|e| e.faces == [0, 1]));
/// assert_eq!(doc.units().unwrap().length.metres, 1e-3);
/// ```
#[derive(Debug, Clone)]
pub struct DocumentBuilder {
    schema: Schema,
    name: String,
    unit: String,
    uncertainty: f64,
    bodies: Vec<String>,
    items: Vec<u64>,
}

/// Conversion-based length units the builder writes: name and millimetres per unit.
const CONVERSION_UNITS: [(&str, f64); 5] =
    [("INCH", 25.4), ("FOOT", 304.8), ("MILE", 1_609_344.0), ("MIL", 0.0254), ("MICROINCH", 2.54e-5)];

impl DocumentBuilder {
    /// A builder for a product called `name` whose length unit is `metres_per_unit`
    /// (SI: 1 metre, 0.01 centimetre, 0.001 millimetre, 1e-6 micrometre, 1000 kilometre;
    /// conversion-based, ISO 10303-41 `CONVERSION_BASED_UNIT` over the millimetre: inch,
    /// foot, mile, mil, microinch) and
    /// whose distance uncertainty is `uncertainty` (model units).
    ///
    /// # Errors
    ///
    /// [`Error::Edit`] for another unit size or a non-positive uncertainty.
    pub fn new(schema: Schema, name: &str, metres_per_unit: f64, uncertainty: f64) -> Result<Self> {
        let nowhere = Position { line: 0, column: 0, id: None };
        let close = |x: f64| (metres_per_unit - x).abs() <= 1e-12 * x;
        let unit = if close(1.0) {
            "( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT($,.METRE.) )".to_owned()
        } else if close(1e-2) {
            "( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.CENTI.,.METRE.) )".to_owned()
        } else if close(1e-3) {
            "( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.) )".to_owned()
        } else if close(1e-6) {
            "( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MICRO.,.METRE.) )".to_owned()
        } else if close(1e3) {
            "( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.KILO.,.METRE.) )".to_owned()
        } else if let Some((name, _)) = CONVERSION_UNITS.iter().find(|(_, mm)| close(mm * 1e-3)) {
            (*name).to_owned()
        } else {
            return Err(Error::Edit { at: nowhere, reason: format!("unsupported length unit {metres_per_unit} m") });
        };
        if !(uncertainty.is_finite() && uncertainty > 0.0) {
            return Err(Error::Edit { at: nowhere, reason: "uncertainty must be positive".into() });
        }
        Ok(Self { schema, name: name.to_owned(), unit, uncertainty, bodies: Vec::new(), items: Vec::new() })
    }

    fn add(&mut self, body: String) -> u64 {
        self.bodies.push(body);
        self.bodies.len() as u64
    }

    fn point(&mut self, p: &Point3<f64>) -> u64 {
        self.add(format!("CARTESIAN_POINT('',{})", real_list(p.coords.iter().copied())))
    }

    fn curve(&mut self, c: &NurbsCurve) -> u64 {
        let ids: Vec<u64> = c.control_points().iter().map(|p| self.point(p)).collect();
        let cps = ids.iter().map(|i| format!("#{i}")).collect::<Vec<_>>().join(",");
        let (m, k) = knot_lists(c.knots());
        match c.weights() {
            None => self.add(format!("B_SPLINE_CURVE_WITH_KNOTS('',{},({cps}),.UNSPECIFIED.,.F.,.F.,{m},{k},.UNSPECIFIED.)", c.degree())),
            Some(w) => self.add(format!(
                "( BOUNDED_CURVE() B_SPLINE_CURVE({},({cps}),.UNSPECIFIED.,.F.,.F.) B_SPLINE_CURVE_WITH_KNOTS({m},{k},.UNSPECIFIED.) CURVE() GEOMETRIC_REPRESENTATION_ITEM() RATIONAL_B_SPLINE_CURVE({}) REPRESENTATION_ITEM('') )",
                c.degree(),
                real_list(w.iter().copied())
            )),
        }
    }

    fn surface(&mut self, s: &NurbsSurface) -> u64 {
        let ids: Vec<u64> = s.control_points().iter().map(|p| self.point(p)).collect();
        let (n_u, n_v) = (s.n_u(), s.n_v());
        let rows = (0..n_u)
            .map(|i| format!("({})", (0..n_v).map(|j| format!("#{}", ids[i * n_v + j])).collect::<Vec<_>>().join(",")))
            .collect::<Vec<_>>()
            .join(",");
        let (um, uk) = knot_lists(s.u_knots());
        let (vm, vk) = knot_lists(s.v_knots());
        match s.weights() {
            None => self.add(format!(
                "B_SPLINE_SURFACE_WITH_KNOTS('',{},{},({rows}),.UNSPECIFIED.,.F.,.F.,.F.,{um},{vm},{uk},{vk},.UNSPECIFIED.)",
                s.u_degree(),
                s.v_degree()
            )),
            Some(w) => {
                let wt = (0..n_u).map(|i| real_list(w[i * n_v..(i + 1) * n_v].iter().copied())).collect::<Vec<_>>().join(",");
                self.add(format!(
                    "( BOUNDED_SURFACE() B_SPLINE_SURFACE({},{},({rows}),.UNSPECIFIED.,.F.,.F.,.F.) B_SPLINE_SURFACE_WITH_KNOTS({um},{vm},{uk},{vk},.UNSPECIFIED.) GEOMETRIC_REPRESENTATION_ITEM() RATIONAL_B_SPLINE_SURFACE(({wt})) REPRESENTATION_ITEM('') SURFACE() )",
                    s.u_degree(),
                    s.v_degree()
                ))
            }
        }
    }

    /// Adds one open shell made of `surfaces`, sharing vertices and edges that coincide
    /// within `tol`, and returns the number of faces added.
    pub fn add_shell(&mut self, surfaces: &[NurbsSurface], tol: f64) -> usize {
        let tol_sq = tol * tol;
        let mut vertices: Vec<(Point3<f64>, u64)> = Vec::new();
        // (start vertex, end vertex, midpoint, edge id)
        let mut edges: Vec<(u64, u64, Point3<f64>, u64)> = Vec::new();
        let mut faces = Vec::new();
        for s in surfaces {
            let (ud, vd) = s.domain();
            let (u0, u1, v0, v1) = (*ud.start(), *ud.end(), *vd.start(), *vd.end());
            let corners = [s.eval(u0, v0), s.eval(u1, v0), s.eval(u1, v1), s.eval(u0, v1)];
            let mut vid = [0u64; 4];
            for (slot, c) in vid.iter_mut().zip(corners) {
                *slot = match vertices.iter().find(|(p, _)| (p - c).norm_squared() <= tol_sq) {
                    Some(&(_, id)) => id,
                    None => {
                        let p = self.point(&c);
                        let v = self.add(format!("VERTEX_POINT('',#{p})"));
                        vertices.push((c, v));
                        v
                    }
                };
            }
            // Loop S(u0,v0) → S(u1,v0) → S(u1,v1) → S(u0,v1): sides VMin (+), UMax (+),
            // VMax (−), UMin (−); each boundary curve runs in increasing parameter.
            let sides = [
                (Side::VMin, 0, 1, true),
                (Side::UMax, 1, 2, true),
                (Side::VMax, 3, 2, false),
                (Side::UMin, 0, 3, false),
            ];
            let mut oriented = Vec::new();
            for (side, a, b, forward) in sides {
                let c = s.boundary(side);
                let cd = c.domain();
                let mid = c.eval((cd.start() + cd.end()) / 2.0);
                let collapsed = c.control_points().iter().all(|p| (p - corners[a]).norm_squared() <= tol_sq);
                if collapsed {
                    continue;
                }
                let (va, vb) = (vid[a], vid[b]);
                let found = edges.iter().find(|e| {
                    ((e.0 == va && e.1 == vb) || (e.0 == vb && e.1 == va))
                        && (e.2 - mid).norm_squared() <= tol_sq * 100.0
                });
                let (edge, same_dir) = match found {
                    Some(e) => (e.3, e.0 == va),
                    None => {
                        let g = self.curve(&c);
                        let e = self.add(format!("EDGE_CURVE('',#{va},#{vb},#{g},.T.)"));
                        edges.push((va, vb, mid, e));
                        (e, true)
                    }
                };
                let along = same_dir == forward;
                oriented.push(self.add(format!("ORIENTED_EDGE('',*,*,#{edge},{})", if along { ".T." } else { ".F." })));
            }
            let list = oriented.iter().map(|i| format!("#{i}")).collect::<Vec<_>>().join(",");
            let lp = self.add(format!("EDGE_LOOP('',({list}))"));
            let bound = self.add(format!("FACE_OUTER_BOUND('',#{lp},.T.)"));
            let surf = self.surface(s);
            faces.push(self.add(format!("ADVANCED_FACE('',(#{bound}),#{surf},.T.)")));
        }
        let list = faces.iter().map(|i| format!("#{i}")).collect::<Vec<_>>().join(",");
        let shell = self.add(format!("OPEN_SHELL('',({list}))"));
        let model = self.add(format!("SHELL_BASED_SURFACE_MODEL('',(#{shell}))"));
        self.items.push(model);
        faces.len()
    }

    /// The finished document (parsed back, so it is checked like any file).
    ///
    /// # Errors
    ///
    /// None in practice; the parse of the generated text is checked.
    pub fn build(self) -> Result<Document> {
        let (schema, apd, app) = match self.schema {
            Schema::Ap214 => (
                "AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }",
                "'international standard','automotive_design',2000",
                "core data for automotive mechanical design processes",
            ),
            Schema::Ap242 => (
                "AP242_MANAGED_MODEL_BASED_3D_ENGINEERING_MIM_LF { 1 0 10303 442 1 1 4 }",
                "'international standard','ap242_managed_model_based_3d_engineering',2011",
                "managed model based 3d engineering",
            ),
        };
        let name = encode_string(&self.name);
        let n = self.bodies.len() as u64;
        let id = |k: u64| n + k;
        let mut head = vec![
            format!("APPLICATION_PROTOCOL_DEFINITION({apd},#{})", id(2)),
            format!("APPLICATION_CONTEXT('{app}')"),
            format!("SHAPE_DEFINITION_REPRESENTATION(#{},#{})", id(4), id(10)),
            format!("PRODUCT_DEFINITION_SHAPE('','',#{})", id(5)),
            format!("PRODUCT_DEFINITION('design','',#{},#{})", id(6), id(9)),
            format!("PRODUCT_DEFINITION_FORMATION('','',#{})", id(7)),
            format!("PRODUCT('{name}','{name}','',(#{}))", id(8)),
            format!("PRODUCT_CONTEXT('',#{},'mechanical')", id(2)),
            format!("PRODUCT_DEFINITION_CONTEXT('part definition',#{},'design')", id(2)),
        ];
        let items =
            std::iter::once(id(11)).chain(self.items.iter().copied()).map(|i| format!("#{i}")).collect::<Vec<_>>();
        head.push(format!("MANIFOLD_SURFACE_SHAPE_REPRESENTATION('',({}),#{})", items.join(","), id(15)));
        head.push(format!("AXIS2_PLACEMENT_3D('',#{},#{},#{})", id(12), id(13), id(14)));
        head.push("CARTESIAN_POINT('',(0.,0.,0.))".into());
        head.push("DIRECTION('',(0.,0.,1.))".into());
        head.push("DIRECTION('',(1.,0.,0.))".into());
        head.push(format!(
            "( GEOMETRIC_REPRESENTATION_CONTEXT(3) GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT((#{})) GLOBAL_UNIT_ASSIGNED_CONTEXT((#{},#{},#{})) REPRESENTATION_CONTEXT('Context #1','3D Context with UNIT and UNCERTAINTY') )",
            id(19), id(16), id(17), id(18)
        ));
        let conversion = CONVERSION_UNITS.iter().find(|(name, _)| *name == self.unit);
        if let Some((name, _)) = conversion {
            head.push(format!("( CONVERSION_BASED_UNIT('{name}',#{}) LENGTH_UNIT() NAMED_UNIT(#{}) )", id(21), id(22)));
        } else {
            head.push(self.unit.clone());
        }
        head.push("( NAMED_UNIT(*) PLANE_ANGLE_UNIT() SI_UNIT($,.RADIAN.) )".into());
        head.push("( NAMED_UNIT(*) SI_UNIT($,.STERADIAN.) SOLID_ANGLE_UNIT() )".into());
        head.push(format!(
            "UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE({}),#{},'distance_accuracy_value','confusion accuracy')",
            format_real(self.uncertainty),
            id(16)
        ));
        head.push(format!("PRODUCT_RELATED_PRODUCT_CATEGORY('part',$,(#{}))", id(7)));
        if let Some((_, mm)) = conversion {
            head.push(format!("LENGTH_MEASURE_WITH_UNIT(LENGTH_MEASURE({}),#{})", format_real(*mm), id(23)));
            head.push("DIMENSIONAL_EXPONENTS(1.,0.,0.,0.,0.,0.,0.)".into());
            head.push("( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.) )".into());
        }
        let mut text = String::new();
        text.push_str("ISO-10303-21;\nHEADER;\n");
        text.push_str("FILE_DESCRIPTION(('cadmorph model'),'2;1');\n");
        text.push_str(&format!(
            "FILE_NAME('{name}','1970-01-01T00:00:00',(''),(''),'cadmorph-step {}','cadmorph','');\n",
            env!("CARGO_PKG_VERSION")
        ));
        text.push_str(&format!("FILE_SCHEMA(('{schema}'));\nENDSEC;\nDATA;\n"));
        for (i, b) in self.bodies.iter().enumerate() {
            text.push_str(&format!("#{} = {b};\n", i + 1));
        }
        for (i, b) in head.iter().enumerate() {
            text.push_str(&format!("#{} = {b};\n", id(i as u64 + 1)));
        }
        text.push_str("ENDSEC;\nEND-ISO-10303-21;\n");
        Document::parse(text.as_bytes())
    }
}

mod bounded;
mod solid;
