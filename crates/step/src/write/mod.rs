//! Writing: the original bytes with edited instances replaced and new ones appended,
//! and brand-new documents ([`DocumentBuilder`]).

mod new;
mod orphans;

use std::io::Write;

pub use new::{DocumentBuilder, Schema};

use crate::document::Document;
use crate::error::{Error, Position, Result};
use crate::read::scan_instance;
use crate::EntityId;

/// Formats a real the way Part 21 wants it (a `.` always, `E` exponent) with the
/// shortest digits that read back to the same `f64`.
///
/// # Examples
///
/// ```
/// use cadmorph_step::format_real;
/// assert_eq!(format_real(1.0), "1.");
/// assert_eq!(format_real(-0.25), "-0.25");
/// assert_eq!(format_real(1e-7), "1.E-7");
/// assert_eq!(format_real(6.02e23), "6.02E23");
/// for x in [0.1, 1.0 / 3.0, -123456.789e-30, f64::MAX] {
///     assert_eq!(format_real(x).parse::<f64>().unwrap(), x);
/// }
/// ```
pub fn format_real(x: f64) -> String {
    let mut out = Vec::with_capacity(24);
    write_real(x, &mut out);
    String::from_utf8(out).expect("ASCII")
}

/// [`format_real`] appended to `out`, without allocating.
pub(crate) fn write_real(x: f64, out: &mut Vec<u8>) {
    // Part 21 has no infinities; the largest real keeps the file readable.
    let x = if x.is_finite() {
        x
    } else if x.is_nan() {
        0.0
    } else {
        x.signum() * f64::MAX
    };
    // Decimal notation where `{:?}` uses it: 1e-4 ≤ |x| < 1e16.
    cadmorph_brep::real::write_real(x, (1e-4, 1e16), out);
}

impl Document {
    /// The document as bytes: the input, byte for byte, except for the instances that
    /// were edited (rewritten in place) and added (before the `ENDSEC` of the last data
    /// section, one per line), and for those the edits left unused (removed; see
    /// `orphans`: only instances something referenced before, or that an edit added).
    pub fn write(&self) -> Vec<u8> {
        let extra: usize = self.texts.values().map(|t| t.len() + 1).sum();
        let mut out = Vec::with_capacity(self.source.len() + extra);
        self.write_to(&mut out).expect("writing to a Vec cannot fail");
        out
    }

    /// Writes [`write`](Self::write)'s bytes to `w`.
    ///
    /// # Errors
    ///
    /// The writer's I/O errors.
    pub fn write_to<W: Write>(&self, mut w: W) -> std::io::Result<()> {
        let orphans = self.orphans();
        let mut cursor = 0;
        let mut added = Vec::new();
        // Original instances in file order: the rewritten ones replaced, the orphaned
        // ones (with the line break after them) left out.
        let mut changes: Vec<usize> = self.texts.keys().copied().filter(|&k| k < self.n_original).collect();
        changes.extend(orphans.iter().copied().filter(|&k| k < self.n_original && !self.texts.contains_key(&k)));
        changes.sort_by_key(|&k| self.instances[k].start);
        for (&k, text) in &self.texts {
            if k >= self.n_original && !orphans.contains(&k) {
                added.push(text);
            }
        }
        for k in changes {
            let inst = &self.instances[k];
            w.write_all(&self.source[cursor..inst.start])?;
            cursor = inst.end;
            if orphans.contains(&k) {
                let rest = &self.source[cursor..];
                cursor += if rest.starts_with(b"\r\n") { 2 } else { usize::from(rest.starts_with(b"\n")) };
            } else {
                w.write_all(self.texts[&k].as_bytes())?;
            }
        }
        if !added.is_empty() {
            w.write_all(&self.source[cursor..self.insert_at])?;
            cursor = self.insert_at;
            for t in added {
                w.write_all(t.as_bytes())?;
                w.write_all(b"\n")?;
            }
        }
        w.write_all(&self.source[cursor..])
    }

    /// Replaces the whole text of instance `#id` with `text` (which must be one instance
    /// `#id = ...;` with the same id, whose references all exist).
    ///
    /// # Errors
    ///
    /// [`Error::NoSuchInstance`], [`Error::Edit`] for a different id or a reference to a
    /// missing instance, and the syntax errors of [`Document::parse`] for bad text.
    pub fn replace_instance_text(&mut self, id: EntityId, text: String) -> Result<()> {
        let k = self.index.get(id.0).ok_or(Error::NoSuchInstance(id))?;
        let (inst, refs) = scan_instance(text.as_bytes())?;
        if inst.id != id.0 {
            return Err(Error::Edit { at: self.position_of(k, 0), reason: format!("the text defines #{}", inst.id) });
        }
        self.check_refs(k, &refs)?;
        let old = &mut self.instances[k];
        old.body = inst.body;
        old.name_len = inst.name_len;
        old.complex = inst.complex;
        self.texts.insert(k, text);
        self.pristine.remove(&k);
        self.views_changed();
        Ok(())
    }

    /// Adds a new instance with a fresh id (one above the highest in use) and returns
    /// the id. `body` is the text after `#id = ` without the `;`, e.g.
    /// `CARTESIAN_POINT('',(0.,0.,0.))`.
    ///
    /// # Errors
    ///
    /// As [`replace_instance_text`](Self::replace_instance_text).
    ///
    /// An added instance is written only if something references it then: one that
    /// nothing does is dead geometry of an edit and is dropped on writing, like the
    /// instances edits leave unused (`write/orphans.rs`).
    ///
    /// # Examples
    ///
    /// ```
    /// use cadmorph_step::{Document, EntityId};
    /// let mut doc = Document::parse(
    ///     b"ISO-10303-21;HEADER;ENDSEC;DATA;\n#6=CARTESIAN_POINT('',(0.,0.,0.));\n#7=DIRECTION('',(1.,0.,0.));\n#8=VECTOR('',#7,1.);\n#9=LINE('',#6,#8);\nENDSEC;END-ISO-10303-21;",
    /// )
    /// .unwrap();
    /// let id = doc.add_instance("VECTOR('',#7,2.)").unwrap();
    /// assert_eq!(id, EntityId(10));
    /// // The line takes the new vector; the old one, now unused, is not written.
    /// doc.replace_instance_text(EntityId(9), "#9=LINE('',#6,#10);".into()).unwrap();
    /// let text = String::from_utf8(doc.write()).unwrap();
    /// assert!(text.contains("#10 = VECTOR('',#7,2.);") && text.contains("#9=LINE('',#6,#10);"));
    /// assert!(!text.contains("#8="));
    /// ```
    pub fn add_instance(&mut self, body: &str) -> Result<EntityId> {
        let id = self.max_id.checked_add(1).ok_or(Error::Limit {
            at: Position { line: 0, column: 0, id: None },
            what: "no id left above the highest one",
        })?;
        let text = format!("#{id} = {body};");
        let (inst, refs) = scan_instance(text.as_bytes())?;
        let k = self.instances.len();
        self.check_refs(k, &refs)?;
        self.instances.push(inst);
        self.index.insert(id, k);
        self.texts.insert(k, text);
        self.views_changed();
        self.max_id = id;
        Ok(EntityId(id))
    }

    fn check_refs(&self, k: usize, refs: &[u64]) -> Result<()> {
        for &r in refs {
            if self.index.get(r).is_none() && !(k >= self.instances.len() && r == self.max_id + 1) {
                let at = if k < self.instances.len() {
                    self.position_of(k, 0)
                } else {
                    Position { line: 0, column: 0, id: None }
                };
                return Err(Error::DanglingReference { at, target: EntityId(r) });
            }
        }
        Ok(())
    }

    /// Replaces bytes `start..end` of instance `k`'s current text.
    pub(crate) fn splice(&mut self, k: usize, start: usize, end: usize, with: &str) -> Result<()> {
        let cur = self.text(k);
        let mut t = String::with_capacity(cur.len() + with.len());
        t.push_str(&String::from_utf8_lossy(&cur[..start]));
        t.push_str(with);
        t.push_str(&String::from_utf8_lossy(&cur[end..]));
        let id = EntityId(self.instances[k].id);
        self.replace_instance_text(id, t)
    }
}

/// A knot vector as Part 21's two lists: `(multiplicities, distinct values)`.
pub(crate) fn knot_lists(knots: &cadmorph_nurbs::KnotVector) -> (String, String) {
    let (vals, ms) = knots.distinct();
    (format!("({})", ms.iter().map(usize::to_string).collect::<Vec<_>>().join(",")), real_list(vals))
}

/// `(a,b,c)` with [`format_real`] numbers.
pub(crate) fn real_list(xs: impl IntoIterator<Item = f64>) -> String {
    let mut s = vec![b'('];
    for (i, x) in xs.into_iter().enumerate() {
        if i > 0 {
            s.push(b',');
        }
        write_real(x, &mut s);
    }
    s.push(b')');
    String::from_utf8(s).expect("ASCII")
}
