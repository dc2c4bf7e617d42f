//! Typed views of the entities cadmorph understands.
//!
//! A view is read from an entity's parameters on demand ([`Document::view`]); it holds
//! the numbers and pointers of the record, in the entity's own definition space (no
//! transformation applied). Conversions to NURBS live in [`crate::convert`].

mod geometry;
mod topology;

pub use geometry::*;
pub use topology::*;

use nalgebra::{Point3, Vector3};

use crate::document::{Document, Entity, EntityId, Param};
use crate::error::{Error, Result};
use crate::read::tokens::Reals;

/// Entity types with a typed view.
pub const KNOWN_TYPES: [u32; 37] = [
    100, 102, 104, 106, 108, 110, 112, 114, 116, 118, 120, 122, 123, 124, 126, 128, 140, 141, 142, 143, 144, 186, 190,
    192, 194, 196, 198, 308, 314, 402, 406, 408, 502, 504, 508, 510, 514,
];

/// Whether `t` has a typed view.
pub(crate) fn is_known_type(t: u32) -> bool {
    KNOWN_TYPES.contains(&t)
}

/// Reads an entity's parameters in order, with positions for errors.
pub(crate) struct Cursor<'a> {
    doc: &'a Document,
    e: &'a Entity,
    i: usize,
    /// When kept, the index of every parameter read as a pointer (see
    /// [`Document::pointer_slots`]).
    slots: Option<Vec<usize>>,
}

impl<'a> Cursor<'a> {
    pub(crate) fn new(doc: &'a Document, e: &'a Entity) -> Self {
        Self { doc, e, i: 1, slots: None }
    }

    fn next(&mut self) -> Option<Param<'a>> {
        let p = self.e.param(self.i);
        self.i += 1;
        p
    }

    fn err(&self, i: usize, what: &'static str, expected: &'static str) -> Error {
        Error::Parameter { at: self.e.position(i), index: i, what, expected }
    }

    /// Parameters left.
    pub(crate) fn remaining(&self) -> usize {
        self.e.param_count().saturating_sub(self.i)
    }

    /// An integer; defaulted gives 0.
    pub(crate) fn int(&mut self, what: &'static str) -> Result<i64> {
        let i = self.i;
        match self.next() {
            Some(Param::Default) => Ok(0),
            Some(p) => p.as_integer().ok_or_else(|| self.err(i, what, "an integer")),
            None => Err(self.err(i, what, "an integer (the record ends)")),
        }
    }

    /// An integer, or `default` if the record ends here.
    pub(crate) fn int_or(&mut self, what: &'static str, default: i64) -> Result<i64> {
        if self.remaining() == 0 {
            self.i += 1;
            return Ok(default);
        }
        self.int(what)
    }

    /// A real; defaulted gives 0.
    pub(crate) fn real(&mut self, what: &'static str) -> Result<f64> {
        let i = self.i;
        match self.next() {
            Some(Param::Default) => Ok(0.0),
            Some(p) => p.as_real().ok_or_else(|| self.err(i, what, "a real")),
            None => Err(self.err(i, what, "a real (the record ends)")),
        }
    }

    /// A real, or `default` if defaulted or the record ends here.
    pub(crate) fn real_or(&mut self, what: &'static str, default: f64) -> Result<f64> {
        let i = self.i;
        match self.next() {
            Some(Param::Default) | None => Ok(default),
            Some(p) => p.as_real().ok_or_else(|| self.err(i, what, "a real")),
        }
    }

    /// Three reals.
    pub(crate) fn point(&mut self, what: &'static str) -> Result<Point3<f64>> {
        Ok(Point3::new(self.real(what)?, self.real(what)?, self.real(what)?))
    }

    /// Three reals as a vector.
    pub(crate) fn vector(&mut self, what: &'static str) -> Result<Vector3<f64>> {
        Ok(self.point(what)?.coords)
    }

    /// A string; defaulted gives the empty string.
    pub(crate) fn string(&mut self, what: &'static str) -> Result<String> {
        let i = self.i;
        match self.next() {
            Some(Param::Default) | None => Ok(String::new()),
            Some(Param::Text(t)) => Ok(String::from_utf8_lossy(t).into_owned()),
            Some(_) => Err(self.err(i, what, "a string")),
        }
    }

    /// A pointer to a directory entry; 0 or defaulted gives `None`. Negative pointers
    /// are accepted (their absolute value is checked).
    pub(crate) fn pointer(&mut self, what: &'static str) -> Result<Option<EntityId>> {
        let i = self.i;
        let v = self.int(what)?;
        if let Some(s) = &mut self.slots {
            s.push(i);
        }
        if v == 0 {
            return Ok(None);
        }
        let a = v.unsigned_abs();
        let n = self.doc.entities.len() as u64;
        if a % 2 == 1 && (a - 1) / 2 < n {
            Ok(Some(EntityId(a as u32)))
        } else {
            Err(Error::DanglingPointer { at: self.e.position(i), target: v, entries: n as usize })
        }
    }

    /// A pointer that must be present.
    pub(crate) fn required(&mut self, what: &'static str) -> Result<EntityId> {
        let i = self.i;
        self.pointer(what)?.ok_or_else(|| self.err(i, what, "a pointer to an entity"))
    }

    /// A count of items of `per_item` parameters each, checked against what is left.
    pub(crate) fn count(&mut self, what: &'static str, per_item: usize) -> Result<usize> {
        let i = self.i;
        let c = self.int(what)?;
        let left = self.remaining();
        match usize::try_from(c) {
            Ok(n) if n.checked_mul(per_item).is_some_and(|m| m <= left) => Ok(n),
            _ => Err(Error::Count { at: self.e.position(i), what, count: c, remaining: left }),
        }
    }

    /// `n` items of `per_item` parameters each must remain.
    pub(crate) fn need(&self, what: &'static str, n: usize, per_item: usize) -> Result<()> {
        let left = self.remaining();
        if n.checked_mul(per_item).is_some_and(|m| m <= left) {
            Ok(())
        } else {
            Err(Error::Count { at: self.e.position(self.i), what, count: n as i64, remaining: left })
        }
    }

    /// `n` reals.
    pub(crate) fn reals(&mut self, what: &'static str, n: usize) -> Result<Vec<f64>> {
        self.need(what, n, 1)?;
        (0..n).map(|_| self.real(what)).collect()
    }

    /// `n` reals appended to `out` (a tight loop over the tokens: the bulk of 126/128
    /// records).
    pub(crate) fn reals_into(&mut self, what: &'static str, n: usize, out: &mut Vec<f64>) -> Result<()> {
        let reals = self.real_tokens(what, n)?;
        out.reserve(n);
        out.extend((0..n).map(|k| reals.get(k)));
        Ok(())
    }

    /// The `n` reals ahead (checked to be numbers or defaults, which read as 0), then
    /// skipped: for callers that place them themselves.
    pub(crate) fn real_tokens(&mut self, what: &'static str, n: usize) -> Result<Reals<'a>> {
        self.need(what, n, 1)?;
        let range = self.i..self.i + n;
        // Records without strings (the bulk of a file) need no look.
        if self.e.strings {
            if let Some(k) = self.e.tokens.text_in(range.clone()) {
                return Err(self.err(k, what, "a real"));
            }
        }
        self.i += n;
        Ok(self.e.tokens.reals(range))
    }

    /// `n` pointers.
    pub(crate) fn pointers(&mut self, what: &'static str, n: usize) -> Result<Vec<EntityId>> {
        self.need(what, n, 1)?;
        (0..n).map(|_| self.required(what)).collect()
    }
}

/// A typed view of one entity.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum View {
    /// 100.
    CircularArc(CircularArc),
    /// 102.
    CompositeCurve(CompositeCurve),
    /// 104.
    ConicArc(ConicArc),
    /// 106.
    CopiousData(CopiousData),
    /// 108.
    Plane(Plane),
    /// 110.
    Line(Line),
    /// 112.
    ParametricSplineCurve(ParametricSplineCurve),
    /// 114.
    ParametricSplineSurface(ParametricSplineSurface),
    /// 116.
    Point(Point),
    /// 118.
    RuledSurface(RuledSurface),
    /// 120.
    SurfaceOfRevolution(SurfaceOfRevolution),
    /// 122.
    TabulatedCylinder(TabulatedCylinder),
    /// 123.
    Direction(Direction),
    /// 124.
    TransformationMatrix(TransformationMatrix),
    /// 126.
    BSplineCurve(BSplineCurve),
    /// 128.
    BSplineSurface(BSplineSurface),
    /// 140.
    OffsetSurface(OffsetSurface),
    /// 141.
    Boundary(Boundary),
    /// 142.
    CurveOnSurface(CurveOnSurface),
    /// 143.
    BoundedSurface(BoundedSurface),
    /// 144.
    TrimmedSurface(TrimmedSurface),
    /// 186.
    ManifoldSolid(ManifoldSolid),
    /// 190.
    PlaneSurface(PlaneSurface),
    /// 192.
    CylindricalSurface(CylindricalSurface),
    /// 194.
    ConicalSurface(ConicalSurface),
    /// 196.
    SphericalSurface(SphericalSurface),
    /// 198.
    ToroidalSurface(ToroidalSurface),
    /// 308.
    SubfigureDefinition(SubfigureDefinition),
    /// 314.
    Color(Color),
    /// 402.
    Associativity(Associativity),
    /// 406.
    Property(Property),
    /// 408.
    SubfigureInstance(SubfigureInstance),
    /// 502.
    VertexList(VertexList),
    /// 504.
    EdgeList(EdgeList),
    /// 508.
    Loop(Loop),
    /// 510.
    Face(Face),
    /// 514.
    Shell(Shell),
    /// Any other type: kept verbatim, parameters through [`Entity::params`].
    Unknown {
        /// Its type.
        entity_type: u32,
        /// Its form.
        form: i64,
    },
}

impl Document {
    /// The typed view of entity `id`.
    ///
    /// # Errors
    ///
    /// [`Error::NoEntity`]; [`Error::Parameter`], [`Error::Count`] or
    /// [`Error::DanglingPointer`] (with the parameter's position) when the record does
    /// not fit its type.
    ///
    /// # Examples
    ///
    /// ```
    /// use cadmorph_iges::{Document, EntityId, View};
    /// let bytes = std::fs::read(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../samples/nurbs_arc.igs")).unwrap();
    /// let doc = Document::parse(&bytes).unwrap();
    /// let View::BSplineCurve(c) = doc.view(EntityId(1)).unwrap() else { panic!() };
    /// assert_eq!((c.degree, c.points.len(), c.weights.is_some()), (2, 3, true));
    /// ```
    pub fn view(&self, id: EntityId) -> Result<View> {
        let e = self.entity(id)?;
        self.read_view(&mut Cursor::new(self, e))
    }

    /// Where entity `id`'s record holds pointers: the indices in [`Entity::params`] (the
    /// entity type at 0) of the parameters its typed view reads as pointers, then those
    /// of the additional pointer groups after the view's parameters (IGES 5.3
    /// §2.2.4.5.2: NV associativity pointers, then NP property pointers). `None` for an
    /// entity type without a view, whose pointers are not known.
    ///
    /// # Errors
    ///
    /// Those of [`view`](Self::view).
    pub(crate) fn pointer_slots(&self, id: EntityId) -> Result<Option<Vec<usize>>> {
        let e = self.entity(id)?;
        if !is_known_type(e.entity_type()) {
            return Ok(None);
        }
        let mut c = Cursor::new(self, e);
        c.slots = Some(Vec::new());
        if let View::Unknown { .. } = self.read_view(&mut c)? {
            return Ok(None);
        }
        let mut slots = c.slots.take().unwrap_or_default();
        let mut i = c.i.min(e.param_count());
        for _ in 0..2 {
            let Some(n) = e.param(i).and_then(|p| p.as_integer()).and_then(|n| usize::try_from(n).ok()) else {
                break;
            };
            if i + 1 + n > e.param_count() {
                break;
            }
            slots.extend(i + 1..i + 1 + n);
            i += 1 + n;
        }
        Ok(Some(slots))
    }

    /// The typed view read through `c`.
    fn read_view(&self, c: &mut Cursor<'_>) -> Result<View> {
        let e = c.e;
        let form = e.form();
        Ok(match e.entity_type() {
            100 => View::CircularArc(CircularArc::read(c)?),
            102 => View::CompositeCurve(CompositeCurve::read(c)?),
            104 => View::ConicArc(ConicArc::read(c, form)?),
            106 => View::CopiousData(CopiousData::read(c, form)?),
            108 => View::Plane(Plane::read(c, form)?),
            110 => View::Line(Line::read(c, form)?),
            112 => View::ParametricSplineCurve(ParametricSplineCurve::read(c)?),
            114 => View::ParametricSplineSurface(ParametricSplineSurface::read(c)?),
            116 => View::Point(Point::read(c)?),
            118 => View::RuledSurface(RuledSurface::read(c, form)?),
            120 => View::SurfaceOfRevolution(SurfaceOfRevolution::read(c)?),
            122 => View::TabulatedCylinder(TabulatedCylinder::read(c)?),
            123 => View::Direction(Direction::read(c)?),
            124 => View::TransformationMatrix(TransformationMatrix::read(c, form)?),
            126 => View::BSplineCurve(BSplineCurve::read(c, form)?),
            128 => View::BSplineSurface(BSplineSurface::read(c, form)?),
            140 => View::OffsetSurface(OffsetSurface::read(c)?),
            141 => View::Boundary(Boundary::read(c)?),
            142 => View::CurveOnSurface(CurveOnSurface::read(c)?),
            143 => View::BoundedSurface(BoundedSurface::read(c)?),
            144 => View::TrimmedSurface(TrimmedSurface::read(c)?),
            186 => View::ManifoldSolid(ManifoldSolid::read(c)?),
            190 => View::PlaneSurface(PlaneSurface::read(c, form)?),
            192 => View::CylindricalSurface(CylindricalSurface::read(c, form)?),
            194 => View::ConicalSurface(ConicalSurface::read(c, form)?),
            196 => View::SphericalSurface(SphericalSurface::read(c, form)?),
            198 => View::ToroidalSurface(ToroidalSurface::read(c, form)?),
            308 => View::SubfigureDefinition(SubfigureDefinition::read(c)?),
            314 => View::Color(Color::read(c)?),
            402 => View::Associativity(Associativity::read(c, form)?),
            406 => View::Property(Property::read(c, form)?),
            408 => View::SubfigureInstance(SubfigureInstance::read(c)?),
            502 => View::VertexList(VertexList::read(c)?),
            504 => View::EdgeList(EdgeList::read(c)?),
            508 => View::Loop(Loop::read(c)?),
            510 => View::Face(Face::read(c)?),
            514 => View::Shell(Shell::read(c)?),
            t => View::Unknown { entity_type: t, form },
        })
    }
}
