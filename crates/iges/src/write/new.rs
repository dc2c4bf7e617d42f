//! New documents from NURBS curves and surfaces.

use cadmorph_nurbs::{NurbsCurve, NurbsSurface};

use super::{layout_record, put_number, seq};
use crate::document::{Document, EntityId, Status, Value};
use crate::edit::{bspline_curve_values, bspline_surface_values};
use crate::global::Units;
use crate::read::{G_WIDTH, P_WIDTH};

/// One entity to write.
#[derive(Debug, Clone)]
struct NewEntity {
    form: i64,
    status: Status,
    values: Vec<Value>,
}

/// Builds a new IGES 5.3 document (fixed ASCII form, `,` and `;` delimiters) from NURBS
/// curves (126) and surfaces (128), with a complete Global section: units flag and name,
/// model scale 1, minimum resolution, maximum coordinate, dates, version 11 (5.3).
///
/// # Examples
///
/// ```
/// use cadmorph_iges::write::DocumentBuilder;
/// use cadmorph_iges::{Document, Units};
/// use cadmorph_nurbs::NurbsSurface;
/// let patch = NurbsSurface::bilinear([[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [1., 1., 1.]]);
/// let mut b = DocumentBuilder::new(Units::Millimetre).timestamp("20250101.000000");
/// let id = b.add_surface(&patch);
/// let doc = b.build();
/// assert_eq!(doc.global().units(), Some(Units::Millimetre));
/// assert_eq!(doc.surface(id).unwrap().surface, patch);
/// // Deterministic: the same input gives the same bytes.
/// assert_eq!(doc.write(), b.to_bytes());
/// ```
#[derive(Debug, Clone)]
pub struct DocumentBuilder {
    units: Units,
    unit_name: String,
    file_name: String,
    author: String,
    organization: String,
    timestamp: Option<String>,
    resolution: f64,
    entities: Vec<NewEntity>,
    max_coordinate: f64,
}

impl DocumentBuilder {
    /// An empty document in `units` ([`Units::Named`] is written as millimetres).
    pub fn new(units: Units) -> Self {
        let units = if units == Units::Named { Units::Millimetre } else { units };
        Self {
            units,
            unit_name: units.name().to_string(),
            file_name: String::new(),
            author: String::new(),
            organization: String::new(),
            timestamp: None,
            resolution: 1e-7,
            entities: Vec::new(),
            max_coordinate: 0.0,
        }
    }

    /// Sets the file name of Global parameter 4.
    pub fn file_name(mut self, name: &str) -> Self {
        self.file_name = name.to_string();
        self
    }

    /// Sets the author (Global parameter 21).
    pub fn author(mut self, author: &str) -> Self {
        self.author = author.to_string();
        self
    }

    /// Sets the organisation (Global parameter 22).
    pub fn organization(mut self, organization: &str) -> Self {
        self.organization = organization.to_string();
        self
    }

    /// Fixes the dates (Global parameters 18 and 25, `YYYYMMDD.HHNNSS`) instead of the
    /// current time, for reproducible files.
    pub fn timestamp(mut self, stamp: &str) -> Self {
        self.timestamp = Some(stamp.to_string());
        self
    }

    /// Sets the minimum resolution (Global parameter 19, model units; default 1e-7).
    pub fn resolution(mut self, tol: f64) -> Self {
        self.resolution = tol;
        self
    }

    fn track(&mut self, points: &[nalgebra::Point3<f64>]) {
        for p in points {
            self.max_coordinate = self.max_coordinate.max(p.coords.amax());
        }
    }

    /// Adds an independent 126 entity holding `c` (model units); returns its DE number.
    pub fn add_curve(&mut self, c: &NurbsCurve) -> EntityId {
        self.track(c.control_points());
        self.push(0, Status::default(), bspline_curve_values(c))
    }

    /// Adds an independent 128 entity holding `s` (model units); returns its DE number.
    pub fn add_surface(&mut self, s: &NurbsSurface) -> EntityId {
        self.track(s.control_points());
        self.push(0, Status::default(), bspline_surface_values(s))
    }

    /// Adds any entity from its parameters (entity type first); returns its DE number.
    /// Pointers among the values are DE numbers of entities added before or after.
    pub fn add_entity(&mut self, form: i64, status: Status, values: Vec<Value>) -> EntityId {
        self.push(form, status, values)
    }

    /// Sets the status flags of an entity added before (e.g. physically dependent for a
    /// surface under a 144).
    ///
    /// # Panics
    ///
    /// If `id` was not returned by this builder.
    pub fn set_status(&mut self, id: EntityId, status: Status) {
        self.entities[id.index()].status = status;
    }

    /// The number of entities added.
    pub fn len(&self) -> usize {
        self.entities.len()
    }

    /// Whether no entity was added.
    pub fn is_empty(&self) -> bool {
        self.entities.is_empty()
    }

    fn push(&mut self, form: i64, status: Status, values: Vec<Value>) -> EntityId {
        self.entities.push(NewEntity { form, status, values });
        EntityId::from_index(self.entities.len() - 1)
    }

    fn stamp(&self) -> String {
        if let Some(s) = &self.timestamp {
            return s.clone();
        }
        let secs = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_secs());
        let days = (secs / 86_400) as i64;
        let rem = secs % 86_400;
        // Civil date from days since 1970-01-01 (H. Hinnant's algorithm).
        let z = days + 719_468;
        let era = z.div_euclid(146_097);
        let doe = z - era * 146_097;
        let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
        let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
        let mp = (5 * doy + 2) / 153;
        let d = doy - (153 * mp + 2) / 5 + 1;
        let m = if mp < 10 { mp + 3 } else { mp - 9 };
        let y = yoe + era * 400 + i64::from(m <= 2);
        format!("{y:04}{m:02}{d:02}.{:02}{:02}{:02}", rem / 3600, rem / 60 % 60, rem % 60)
    }

    /// The file text.
    pub fn to_bytes(&self) -> Vec<u8> {
        let eol = b"\n";
        let mut out = Vec::new();
        let line = |out: &mut Vec<u8>, body: &[u8], width: usize, tail: &[u8]| {
            out.extend_from_slice(body);
            out.resize(out.len() + width.saturating_sub(body.len()), b' ');
            out.extend_from_slice(tail);
            out.extend_from_slice(eol);
        };
        line(&mut out, b"cadmorph-iges: NURBS geometry", 72, b"S0000001");
        let t = |s: &str| Value::Text(s.as_bytes().to_vec());
        let stamp = self.stamp();
        let global = vec![
            t(","),
            t(";"),
            t("cadmorph"),
            t(&self.file_name),
            t("cadmorph"),
            t(concat!("cadmorph-iges ", env!("CARGO_PKG_VERSION"))),
            Value::Integer(32),
            Value::Integer(308),
            Value::Integer(15),
            Value::Integer(308),
            Value::Integer(15),
            t("cadmorph"),
            Value::Real(1.0),
            Value::Integer(self.units.flag()),
            t(&self.unit_name),
            Value::Integer(1),
            Value::Real(1.0),
            t(&stamp),
            Value::Real(self.resolution),
            Value::Real(if self.max_coordinate > 0.0 { self.max_coordinate } else { 1.0 }),
            t(&self.author),
            t(&self.organization),
            Value::Integer(11),
            Value::Integer(0),
            t(&stamp),
        ];
        let g_lines = layout_record(&global, b',', b';', G_WIDTH);
        for (k, l) in g_lines.iter().enumerate() {
            line(&mut out, l, 72, format!("G{}", seq(k + 1, true)).as_bytes());
        }
        // The D section is two 81-byte lines per entity (72 columns of fields, the
        // section's 8-column tail, the line feed) that need each record's P line count:
        // room is left for it here and filled once the P section, written right after
        // it straight from the values, has told the counts.
        let d_start = out.len();
        let n_entities = self.entities.len();
        out.resize(d_start + 2 * 81 * n_entities, b' ');
        let mut p_lines = Vec::with_capacity(n_entities);
        let mut n = 0;
        for (k, e) in self.entities.iter().enumerate() {
            let before = n;
            super::lay_out(&e.values, b',', b';', P_WIDTH, &mut out, |out, start| {
                out.resize(out.len().max(start + P_WIDTH), b' ');
                put_number(out, 2 * k + 1, 8, false);
                out.push(b'P');
                n += 1;
                put_number(out, n, 7, true);
                out.extend_from_slice(eol);
            });
            p_lines.push(n - before);
        }
        let mut d_section = Vec::with_capacity(2 * 81 * n_entities);
        let mut p_next = 1usize;
        for (k, (e, lines)) in self.entities.iter().zip(&p_lines).enumerate() {
            let ty = match e.values.first() {
                Some(Value::Integer(t)) => *t,
                _ => 0,
            };
            let s = e.status;
            let status = format!("{:02}{:02}{:02}{:02}", s.blank, s.subordinate, s.entity_use, s.hierarchy);
            let a = format!("{ty:>8}{p_next:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{status:>8}", 0, 0, 0, 0, 0, 0);
            line(&mut d_section, a.as_bytes(), 72, format!("D{}", seq(2 * k + 1, true)).as_bytes());
            let b = format!("{ty:>8}{:>8}{:>8}{:>8}{:>8}{:8}{:8}{:8}{:>8}", 0, 0, lines, e.form, "", "", "", 0);
            line(&mut d_section, b.as_bytes(), 72, format!("D{}", seq(2 * k + 2, true)).as_bytes());
            p_next += lines;
        }
        if d_section.len() == 2 * 81 * n_entities {
            out[d_start..d_start + d_section.len()].copy_from_slice(&d_section);
        } else {
            // A field wider than its 8 columns (never from this builder's numbers): the
            // section takes the room it needs.
            out.splice(d_start..d_start + 2 * 81 * n_entities, d_section);
        }
        let t_body = format!(
            "S{}G{}D{}P{}",
            seq(1, true),
            seq(g_lines.len(), true),
            seq(2 * self.entities.len(), true),
            seq(n, true)
        );
        line(&mut out, t_body.as_bytes(), 72, b"T0000001");
        out
    }

    /// The document (its text parsed back, so it behaves like any read file).
    ///
    /// # Panics
    ///
    /// Never for curves and surfaces; only if [`add_entity`](Self::add_entity) was given
    /// values that do not make a record (e.g. pointers to missing entities are fine, but
    /// an empty value list is not).
    pub fn build(&self) -> Document {
        Document::parse(&self.to_bytes()).expect("cadmorph writes readable IGES")
    }
}

mod brep;
mod trimmed;
