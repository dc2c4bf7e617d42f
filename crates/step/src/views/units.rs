//! Units and uncertainty of a geometric representation context.

use super::Ctx;
use crate::document::Document;
use crate::error::{Error, Result};
use crate::read::param::{Body, Value};
use crate::EntityId;

/// A length unit: its name as the file gives it and its size in metres.
#[derive(Debug, Clone, PartialEq)]
pub struct LengthUnit {
    /// `"MILLI METRE"`, `"METRE"`, `"INCH"`, ...
    pub name: String,
    /// Metres per unit (0.001 for millimetres, 0.0254 for inches).
    pub metres: f64,
}

/// The units of a document's geometry.
#[derive(Debug, Clone, PartialEq)]
pub struct Units {
    /// The model's length unit: every coordinate the views return is in this unit.
    pub length: LengthUnit,
    /// Radians per plane-angle unit of the file (1 for radians, π/180 for degrees).
    pub plane_angle: f64,
    /// The file's distance uncertainty (`UNCERTAINTY_MEASURE_WITH_UNIT`) in model units.
    pub uncertainty: Option<f64>,
}

impl Default for Units {
    fn default() -> Self {
        Self { length: LengthUnit { name: "MILLI METRE".into(), metres: 1e-3 }, plane_angle: 1.0, uncertainty: None }
    }
}

fn si_prefix(p: &str) -> Option<f64> {
    Some(match p {
        "EXA" => 1e18,
        "PETA" => 1e15,
        "TERA" => 1e12,
        "GIGA" => 1e9,
        "MEGA" => 1e6,
        "KILO" => 1e3,
        "HECTO" => 1e2,
        "DECA" => 1e1,
        "DECI" => 1e-1,
        "CENTI" => 1e-2,
        "MILLI" => 1e-3,
        "MICRO" => 1e-6,
        "NANO" => 1e-9,
        "PICO" => 1e-12,
        "FEMTO" => 1e-15,
        "ATTO" => 1e-18,
        _ => return None,
    })
}

/// What kind of unit an instance is, and its size in SI base units (metres, radians).
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Unit {
    Length(String, f64),
    Angle(f64),
    Other,
}

impl Ctx<'_> {
    /// A unit instance, read once per context (a context's uncertainty names its length
    /// unit again, and the contexts of an assembly's parts often share their units).
    pub fn unit(&self, id: EntityId) -> Result<Unit> {
        let k = self.index(id)?;
        if let Some(u) = self.units.borrow().get(&k) {
            return Ok(u.clone());
        }
        let u = self.read_unit(id)?;
        self.units.borrow_mut().insert(k, u.clone());
        Ok(u)
    }

    fn read_unit(&self, id: EntityId) -> Result<Unit> {
        self.nested(id, || {
            let k = self.index(id)?;
            let body = self.doc.body_at(k)?;
            let leaves: &[crate::read::param::Record<'_>] = match &body {
                Body::Complex(l) => l,
                Body::Simple(r) => std::slice::from_ref(r),
            };
            let has = |n: &str| leaves.iter().any(|r| r.name == n);
            let length = has("LENGTH_UNIT");
            let angle = has("PLANE_ANGLE_UNIT");
            if !length && !angle {
                return Ok(Unit::Other);
            }
            let size;
            let name;
            if let Some(si) = leaves.iter().find(|r| r.name == "SI_UNIT") {
                let prefix = match si.params.first().map(|p| &p.value) {
                    Some(Value::Enumeration(p)) => Some(*p),
                    _ => None,
                };
                let base = match si.params.get(1).map(|p| &p.value) {
                    Some(Value::Enumeration(b)) => *b,
                    _ => "",
                };
                let f = match prefix {
                    Some(p) => si_prefix(p).ok_or_else(|| Error::Parameter {
                        at: self.doc.position_of(k, si.start),
                        entity: "SI_UNIT".into(),
                        index: 0,
                        expected: "an SI prefix",
                    })?,
                    None => 1.0,
                };
                size = f;
                name = match prefix {
                    Some(p) => format!("{p} {base}"),
                    None => base.to_owned(),
                };
            } else if let Some(cb) = leaves.iter().find(|r| r.name == "CONVERSION_BASED_UNIT") {
                let bad = |expected| Error::Parameter {
                    at: self.doc.position_of(k, cb.start),
                    entity: "CONVERSION_BASED_UNIT".into(),
                    index: 1,
                    expected,
                };
                name = match cb.params.first().map(|p| &p.value) {
                    Some(Value::String(s)) => crate::decode_string(s),
                    _ => String::new(),
                };
                let m = cb.params.get(1).and_then(|p| p.as_ref_id()).ok_or_else(|| bad("a measure with unit"))?;
                let (value, unit) = self.measure_with_unit(m)?;
                size = value
                    * match self.unit(unit)? {
                        Unit::Length(_, s) | Unit::Angle(s) => s,
                        Unit::Other => return Err(bad("a length or angle measure")),
                    };
            } else {
                return Ok(Unit::Other);
            }
            if !(size.is_finite() && size > 0.0) {
                return Err(Error::Parameter {
                    at: self.doc.position_of(k, 0),
                    entity: "NAMED_UNIT".into(),
                    index: 0,
                    expected: "a positive finite unit size",
                });
            }
            Ok(if length { Unit::Length(name, size) } else { Unit::Angle(size) })
        })
    }

    /// `*_MEASURE_WITH_UNIT(TYPED_MEASURE(v), unit, ...)` as (v, unit).
    pub fn measure_with_unit(&self, id: EntityId) -> Result<(f64, EntityId)> {
        let k = self.index(id)?;
        let body = self.doc.body_at(k)?;
        let rec = body
            .first()
            .into_iter()
            .chain(match &body {
                Body::Complex(l) => l.iter().collect::<Vec<_>>(),
                Body::Simple(_) => vec![],
            })
            .find(|r| r.name.ends_with("MEASURE_WITH_UNIT"))
            .cloned()
            .ok_or_else(|| Error::UnexpectedEntity {
                at: self.doc.position_of(k, 0),
                expected: "a measure with unit",
                found: self.doc.name_of(k).to_owned(),
            })?;
        let r = super::Rec::from_record(self.doc, k, rec);
        let v = r.real(0)?;
        let u = r.reference(1)?;
        Ok((v, u))
    }

    /// Units of a representation context: (length, angle scale, uncertainty in that length unit).
    pub fn context_units(&self, id: EntityId) -> Result<(Option<LengthUnit>, f64, Option<f64>)> {
        let k = self.index(id)?;
        let body = self.doc.body_at(k)?;
        let mut length = None;
        let mut angle = 1.0;
        let mut unc = None;
        if let Some(g) = body.record("GLOBAL_UNIT_ASSIGNED_CONTEXT") {
            if let Some(list) = g.params.first().and_then(|p| p.as_list()) {
                for p in list {
                    if let Some(u) = p.as_ref_id() {
                        match self.unit(u)? {
                            Unit::Length(name, metres) => length = Some(LengthUnit { name, metres }),
                            Unit::Angle(s) => angle = s,
                            Unit::Other => {}
                        }
                    }
                }
            }
        }
        if let Some(g) = body.record("GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT") {
            if let Some(list) = g.params.first().and_then(|p| p.as_list()) {
                for p in list {
                    if let Some(u) = p.as_ref_id() {
                        let (v, unit) = self.measure_with_unit(u)?;
                        if let Unit::Length(_, m) = self.unit(unit)? {
                            let model = length.as_ref().map_or(m, |l: &LengthUnit| l.metres);
                            let v = v * m / model;
                            unc = Some(unc.map_or(v, |x: f64| x.min(v)));
                        }
                    }
                }
            }
        }
        Ok((length, angle, unc))
    }
}

impl Document {
    /// The model's units: those of the first representation context that assigns a
    /// length unit (the context of the shape representation holding the geometry in
    /// every file OCCT, CATIA or NX writes). Without one: millimetres, radians, no
    /// uncertainty (OCCT's defaults).
    ///
    /// # Errors
    ///
    /// Malformed unit instances ([`Error::Parameter`], [`Error::UnexpectedEntity`]),
    /// unit definitions that refer to themselves ([`Error::ReferenceCycle`]).
    ///
    /// # Examples
    ///
    /// ```
    /// let doc = cadmorph_step::Document::parse(&std::fs::read(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../samples/hull3.stp")).unwrap()).unwrap();
    /// let units = doc.units().unwrap();
    /// assert_eq!((units.length.name.as_str(), units.length.metres), ("METRE", 1.0));
    /// assert_eq!(units.uncertainty, Some(1e-7));
    /// ```
    pub fn units(&self) -> Result<Units> {
        if let Some((u, _)) = self.units_cache.get() {
            return Ok(u.clone());
        }
        let found = self.find_units()?;
        let u = found.0.clone();
        let _ = self.units_cache.set(found);
        Ok(u)
    }

    /// The context instance [`units`](Self::units) read the model units from, with its
    /// length unit in metres (`None` for the defaults, or if they cannot be read).
    pub(crate) fn units_context(&self) -> Option<(u64, f64)> {
        self.units().ok()?;
        self.units_cache.get().and_then(|(u, id)| id.map(|id| (id, u.length.metres)))
    }

    /// The model units and the context they come from.
    fn find_units(&self) -> Result<(Units, Option<u64>)> {
        let ctx = Ctx::new(self, 1.0);
        let global = memchr::memmem::Finder::new(b"GLOBAL_UNIT_ASSIGNED_CONTEXT");
        for k in 0..self.instances.len() {
            if !self.instances[k].complex {
                continue;
            }
            // Cheap test on the text before parsing a complex instance.
            let text = self.text(k);
            if global.find(text).is_none() {
                continue;
            }
            let (length, angle, uncertainty) = ctx.context_units(EntityId(self.instances[k].id))?;
            if let Some(length) = length {
                return Ok((Units { length, plane_angle: angle, uncertainty }, Some(self.instances[k].id)));
            }
        }
        Ok((Units::default(), None))
    }
}
