//! In-place edits: only the edited entities' parameter records are rewritten; sequence
//! numbers, directory pointers and line counts, and the Terminate record follow.

use cadmorph_nurbs::{NurbsCurve, NurbsSurface};
use nalgebra::{Matrix4, Point3};

use crate::document::{Document, EntityId, Value};
use crate::entity::View;
use crate::error::{Error, Result};
use crate::read::lexer::{tokenize, Raw};
use crate::read::tokens::Tokens;
use crate::read::P_WIDTH;
use crate::write::layout_record;

fn edit_err(id: EntityId, reason: impl Into<String>) -> Error {
    Error::Edit { de: id.0, reason: reason.into() }
}

fn same(a: &[Value], b: &[Value]) -> bool {
    a.len() == b.len()
        && a.iter().zip(b).all(|(x, y)| match (x, y) {
            (Value::Real(p), Value::Real(q)) => p.to_bits() == q.to_bits(),
            _ => x == y,
        })
}

fn check_finite(id: EntityId, values: &[Value]) -> Result<()> {
    for (i, v) in values.iter().enumerate() {
        if let Value::Real(x) = v {
            if !x.is_finite() {
                return Err(edit_err(id, format!("parameter {i} is not finite ({x})")));
            }
        }
    }
    Ok(())
}

/// The parameters of a 128 entity for `s` (cadmorph order converted to IGES order, u
/// index fastest).
pub(crate) fn bspline_surface_values(s: &NurbsSurface) -> Vec<Value> {
    let (n_u, n_v) = (s.n_u(), s.n_v());
    let rational = s.is_rational();
    let mut v = Vec::with_capacity(14 + s.u_knots().len() + s.v_knots().len() + 4 * n_u * n_v);
    v.push(Value::Integer(128));
    for x in [n_u - 1, n_v - 1, s.u_degree(), s.v_degree()] {
        v.push(Value::Integer(x as i64));
    }
    for x in [0, 0, i64::from(!rational), 0, 0] {
        v.push(Value::Integer(x));
    }
    v.extend(s.u_knots().as_slice().iter().map(|&k| Value::Real(k)));
    v.extend(s.v_knots().as_slice().iter().map(|&k| Value::Real(k)));
    for j in 0..n_v {
        for i in 0..n_u {
            v.push(Value::Real(s.weights().map_or(1.0, |w| w[i * n_v + j])));
        }
    }
    for j in 0..n_v {
        for i in 0..n_u {
            let p = s.control_point(i, j);
            v.extend([Value::Real(p.x), Value::Real(p.y), Value::Real(p.z)]);
        }
    }
    let (ud, vd) = cadmorph_nurbs::Surface::domain(s);
    v.extend([*ud.start(), *ud.end(), *vd.start(), *vd.end()].map(Value::Real));
    v
}

/// The parameters of a 126 entity for `c`.
pub(crate) fn bspline_curve_values(c: &NurbsCurve) -> Vec<Value> {
    let n = c.control_points().len();
    let mut v = Vec::with_capacity(12 + c.knots().len() + 4 * n);
    v.push(Value::Integer(126));
    v.extend([n as i64 - 1, c.degree() as i64, 0, 0, i64::from(!c.is_rational()), 0].map(Value::Integer));
    v.extend(c.knots().as_slice().iter().map(|&k| Value::Real(k)));
    v.extend((0..n).map(|i| Value::Real(c.weights().map_or(1.0, |w| w[i]))));
    for p in c.control_points() {
        v.extend([Value::Real(p.x), Value::Real(p.y), Value::Real(p.z)]);
    }
    let d = cadmorph_nurbs::Curve::domain(c);
    v.extend([*d.start(), *d.end(), 0.0, 0.0, 0.0].map(Value::Real));
    v
}

impl Document {
    /// Replaces every parameter of entity `id` (entity type first). Returns `false`, and
    /// leaves the record untouched, when the values equal the current ones (reals compared
    /// bit for bit).
    ///
    /// The first value may name another entity type; the directory entry then follows
    /// (form `form`, or unchanged if `None`).
    ///
    /// # Errors
    ///
    /// [`Error::NoEntity`]; [`Error::Edit`] for an empty list, a first value that is not
    /// a non-negative integer, or non-finite reals.
    pub fn set_values(&mut self, id: EntityId, values: Vec<Value>, form: Option<i64>) -> Result<bool> {
        let k = self.index_of(id)?;
        let ty = match values.first() {
            Some(Value::Integer(t)) => u32::try_from(*t).map_err(|_| edit_err(id, "negative entity type"))?,
            _ => return Err(edit_err(id, "the first value must be the entity type")),
        };
        check_finite(id, &values)?;
        let e = &self.entities[k];
        let form_changes = form.is_some_and(|f| f != e.form());
        if !form_changes && ty == e.entity_type() && same(&e.values(), &values) {
            return Ok(false);
        }
        self.write_record(k, ty, values, form)?;
        Ok(true)
    }

    /// [`set_values`](Self::set_values) without its form; with `force`, the record is
    /// rewritten even when the values are the current ones (a fresh copy's record).
    pub(crate) fn write_values(&mut self, id: EntityId, values: Vec<Value>, force: bool) -> Result<()> {
        if !force {
            return self.set_values(id, values, None).map(|_| ());
        }
        let k = self.index_of(id)?;
        let ty = match values.first() {
            Some(Value::Integer(t)) => u32::try_from(*t).map_err(|_| edit_err(id, "negative entity type"))?,
            _ => return Err(edit_err(id, "the first value must be the entity type")),
        };
        check_finite(id, &values)?;
        self.write_record(k, ty, values, None)
    }

    /// Lays out and stores entity `k`'s new record (type `ty`, form `form` if given).
    fn write_record(&mut self, k: usize, ty: u32, values: Vec<Value>, form: Option<i64>) -> Result<()> {
        let id = self.entities[k].id;
        let form_changes = form.is_some_and(|f| f != self.entities[k].form());
        let (pd, rd) = (self.global.parameter_delimiter, self.global.record_delimiter);
        let lines = layout_record(&values, pd, rd, P_WIDTH);
        let mut text = Vec::with_capacity(lines.len() * P_WIDTH);
        for l in &lines {
            text.extend_from_slice(l);
            text.resize(text.len() + P_WIDTH - l.len(), b' ');
        }
        let mut tokens = Tokens::with_capacity(values.len());
        tokenize(&text, 0, pd, rd, &mut tokens).map_err(|e| edit_err(id, format!("unreadable record: {e:?}")))?;
        debug_assert_eq!(tokens.first(), Some(Raw::Integer(i64::from(ty))));
        let e = &mut self.entities[k];
        if ty != e.directory.entity_type || form_changes {
            e.directory.entity_type = ty;
            if let Some(f) = form {
                e.directory.form = f;
            }
            e.directory_changed = true;
        }
        e.text = crate::document::RecordText::owned(text);
        e.strings = tokens.has_text();
        e.tokens = tokens;
        e.new_lines = Some(lines);
        e.p_line = 0;
        self.edited = true;
        Ok(())
    }

    /// Maps model-space points back to the entity's definition space; a point equal (bit
    /// for bit) to the image of the stored one keeps the stored value.
    fn to_local(&self, id: EntityId, new: &[Point3<f64>], old: &[Point3<f64>]) -> Result<Vec<Point3<f64>>> {
        let m = self.transform(id)?;
        if m == Matrix4::identity() {
            return Ok(new.to_vec());
        }
        let inv = m.try_inverse().ok_or(Error::Transform { de: id.0, reason: "singular transformation matrix" })?;
        Ok(new
            .iter()
            .zip(old)
            .map(|(p, o)| if m.transform_point(o) == *p { *o } else { inv.transform_point(p) })
            .collect())
    }

    /// Sets the control points (and optionally the weights) of a 126 or 128 entity, in
    /// the coordinates [`curve`](Self::curve) and [`surface`](Self::surface) return
    /// (its own transformation applied; it is undone here) and cadmorph's order
    /// (`i * n_v + j`, `i` along u). Knots, degrees and everything else stay. Returns
    /// whether the record changed.
    ///
    /// # Errors
    ///
    /// [`Error::Unsupported`] for other entity types; [`Error::Edit`] for wrong counts,
    /// non-finite values or non-positive weights.
    ///
    /// # Examples
    ///
    /// ```
    /// use cadmorph_iges::{Document, EntityId};
    /// let bytes = std::fs::read(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../samples/hull3_bare.igs")).unwrap();
    /// let mut doc = Document::parse(&bytes).unwrap();
    /// let id = EntityId(1);
    /// let mut pts = doc.surface(id).unwrap().surface.control_points().to_vec();
    /// assert!(!doc.set_control_points(id, &pts, None).unwrap()); // unchanged: not rewritten
    /// pts[0].z += 0.5;
    /// assert!(doc.set_control_points(id, &pts, None).unwrap());
    /// let again = Document::parse(&doc.write()).unwrap();
    /// assert_eq!(again.surface(id).unwrap().surface.control_points()[0], pts[0]);
    /// ```
    pub fn set_control_points(
        &mut self,
        id: EntityId,
        points: &[Point3<f64>],
        weights: Option<&[f64]>,
    ) -> Result<bool> {
        let e = self.entity(id)?;
        let mut values = e.values();
        let (n, w_start, old, prop3) = match self.view(id)? {
            View::BSplineSurface(b) => {
                let n = b.n_u * b.n_v;
                (n, 10 + b.u_knots.len() + b.v_knots.len(), b.points, 7)
            }
            View::BSplineCurve(b) => {
                let n = b.points.len();
                (n, 7 + b.knots.len(), b.points, 5)
            }
            _ => {
                return Err(Error::Unsupported {
                    de: id.0,
                    entity_type: e.entity_type(),
                    form: e.form(),
                    reason: "control points can be set on 126 and 128 entities only",
                })
            }
        };
        if points.len() != n {
            return Err(edit_err(id, format!("expected {n} control points, found {}", points.len())));
        }
        if let Some(w) = weights {
            if w.len() != n {
                return Err(edit_err(id, format!("expected {n} weights, found {}", w.len())));
            }
            if let Some((i, x)) = w.iter().enumerate().find(|(_, x)| !(x.is_finite() && **x > 0.0)) {
                return Err(edit_err(id, format!("weight {i} is not positive and finite ({x})")));
            }
        }
        let local = self.to_local(id, points, &old)?;
        let surface = matches!(self.entity(id)?.entity_type(), 128);
        let (n_u, n_v) = match self.view(id)? {
            View::BSplineSurface(b) => (b.n_u, b.n_v),
            _ => (n, 1),
        };
        // File order: u fastest; cadmorph order: i * n_v + j.
        let file_index = |i: usize, j: usize| if surface { j * n_u + i } else { i };
        let p_start = w_start + n;
        for i in 0..n_u {
            for j in 0..n_v {
                let c = i * n_v + j;
                let f = file_index(i, j);
                let p = local[c];
                values[p_start + 3 * f] = Value::Real(p.x);
                values[p_start + 3 * f + 1] = Value::Real(p.y);
                values[p_start + 3 * f + 2] = Value::Real(p.z);
                if let Some(w) = weights {
                    values[w_start + f] = Value::Real(w[c]);
                }
            }
        }
        if let Some(w) = weights {
            if w.iter().any(|&x| x != w[0]) {
                values[prop3] = Value::Integer(0);
            }
        }
        self.set_values(id, values, None)
    }

    /// Rewrites surface entity `id` as a 128 holding `s` (given in the coordinates
    /// [`surface`](Self::surface) returns; the entity's transformation is kept and undone
    /// here). A non-128 entity becomes a 128, form 0, under the same DE number, so
    /// every pointer to it stays valid. Returns whether the record changed.
    ///
    /// # Errors
    ///
    /// [`Error::NoEntity`], [`Error::Transform`] for a singular matrix, [`Error::Edit`]
    /// for non-finite values.
    pub fn set_bspline_surface(&mut self, id: EntityId, s: &NurbsSurface) -> Result<bool> {
        let m = self.transform(id)?;
        let local = if m == Matrix4::identity() {
            s.clone()
        } else {
            let inv = m.try_inverse().ok_or(Error::Transform { de: id.0, reason: "singular transformation matrix" })?;
            s.transformed(&inv)
        };
        let form = (self.entity(id)?.entity_type() != 128).then_some(0);
        self.set_values(id, bspline_surface_values(&local), form)
    }

    /// Rewrites curve entity `id` as a 126 holding `c` (coordinates as
    /// [`curve`](Self::curve) returns them). Returns whether the record changed.
    ///
    /// # Errors
    ///
    /// As [`set_bspline_surface`](Self::set_bspline_surface).
    pub fn set_bspline_curve(&mut self, id: EntityId, c: &NurbsCurve) -> Result<bool> {
        let m = self.transform(id)?;
        let local = if m == Matrix4::identity() {
            c.clone()
        } else {
            let inv = m.try_inverse().ok_or(Error::Transform { de: id.0, reason: "singular transformation matrix" })?;
            c.transformed(&inv)
        };
        let form = (self.entity(id)?.entity_type() != 126).then_some(0);
        self.set_values(id, bspline_curve_values(&local), form)
    }

    /// Replaces an analytic or spline surface (108, 114, 118, 120, 122, 190–198) by its
    /// exact B-spline form, a 128 under the same DE number with the same transformation.
    /// An offset surface (140) becomes its B-spline form too: exact over an analytic
    /// base, otherwise the fit within tolerance that [`surface`](Self::surface) gives.
    ///
    /// The parameter space changes (angles become rational-arc parameters), so trimming
    /// curves given in the old parameter space are dropped in favour of the model-space
    /// ones: each 142 on this surface gets `BPTR = 0, PREF = 2`, each 141 loses its
    /// parameter curves, and each 508 loop of a 510 face on it loses its parameter curves.
    /// Those entities' records are rewritten too; the old defining entities (axis,
    /// generatrix, points, directions) stay in the file, unused.
    ///
    /// # Errors
    ///
    /// Those of [`surface`](Self::surface) (unsupported or unbounded surfaces), and
    /// [`Error::Unsupported`] for 128 or non-surface entities.
    ///
    /// # Examples
    ///
    /// ```
    /// use cadmorph_iges::{Document, View};
    /// let bytes = std::fs::read(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../samples/mixed_solid_brep.igs")).unwrap();
    /// let mut doc = Document::parse(&bytes).unwrap();
    /// let cylinder = doc.entities().find(|e| e.entity_type() == 192).unwrap().id();
    /// let before = doc.surface(cylinder).unwrap().surface;
    /// doc.replace_with_bspline(cylinder).unwrap();
    /// let doc = Document::parse(&doc.write()).unwrap();
    /// assert!(matches!(doc.view(cylinder).unwrap(), View::BSplineSurface(_)));
    /// assert_eq!(doc.surface(cylinder).unwrap().surface, before);
    /// ```
    pub fn replace_with_bspline(&mut self, id: EntityId) -> Result<()> {
        let e = self.entity(id)?;
        if !matches!(e.entity_type(), 108 | 114 | 118 | 120 | 122 | 140 | 190..=198) {
            return Err(Error::Unsupported {
                de: id.0,
                entity_type: e.entity_type(),
                form: e.form(),
                reason:
                    "only analytic, spline and offset surfaces (108, 114, 118, 120, 122, 140, 190-198) are replaced",
            });
        }
        let world = self.surface(id)?.surface;
        // Parameter-space trimming curves of the old surface.
        let mut rewrites: Vec<(EntityId, Vec<Value>)> = Vec::new();
        for ent in &self.entities {
            let eid = ent.id();
            match ent.entity_type() {
                142 => {
                    if let Ok(View::CurveOnSurface(c)) = self.view(eid) {
                        if c.surface == id && c.parameter_curve.is_some() {
                            let mut v = ent.values();
                            v.resize(6, Value::Default);
                            v[3] = Value::Integer(0);
                            v[5] = Value::Integer(2);
                            rewrites.push((eid, v));
                        }
                    }
                }
                141 => {
                    if let Ok(View::Boundary(b)) = self.view(eid) {
                        if b.surface == id && b.curves.iter().any(|c| !c.parameter_curves.is_empty()) {
                            let mut v = vec![Value::Integer(141), Value::Integer(0), Value::Integer(2)];
                            v.push(Value::Integer(i64::from(id.0)));
                            v.push(Value::Integer(b.curves.len() as i64));
                            for c in &b.curves {
                                v.extend([i64::from(c.curve.0), c.sense, 0].map(Value::Integer));
                            }
                            rewrites.push((eid, v));
                        }
                    }
                }
                510 => {
                    if let Ok(View::Face(f)) = self.view(eid) {
                        if f.surface != id {
                            continue;
                        }
                        for l in f.loops {
                            if let Ok(View::Loop(lv)) = self.view(l) {
                                if lv.edges.iter().all(|e| e.parameter_curves.is_empty()) {
                                    continue;
                                }
                                let mut v = vec![Value::Integer(508), Value::Integer(lv.edges.len() as i64)];
                                for ed in &lv.edges {
                                    v.extend(
                                        [ed.kind, i64::from(ed.list.0), ed.index, i64::from(ed.same_orientation), 0]
                                            .map(Value::Integer),
                                    );
                                }
                                rewrites.push((l, v));
                            }
                        }
                    }
                }
                _ => {}
            }
        }
        self.set_bspline_surface(id, &world)?;
        for (eid, v) in rewrites {
            self.set_values(eid, v, None)?;
        }
        Ok(())
    }
}
