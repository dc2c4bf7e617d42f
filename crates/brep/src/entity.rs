//! File formats and references to their entities.

use std::fmt;

use serde::Serialize;

/// A CAD exchange format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub enum Format {
    /// IGES 5.3, fixed 80-column ASCII form.
    Iges,
    /// ISO 10303-21 (STEP) exchange structure.
    Step,
}

impl Format {
    /// The format of a file name's extension (`igs`, `iges`, `stp`, `step`, `p21`, any
    /// case), or `None`.
    ///
    /// ```
    /// use cadmorph_brep::Format;
    /// assert_eq!(Format::from_extension("out.STP".as_ref()), Some(Format::Step));
    /// assert_eq!(Format::from_extension("out.txt".as_ref()), None);
    /// ```
    pub fn from_extension(path: &std::path::Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "igs" | "iges" => Some(Format::Iges),
            "stp" | "step" | "p21" => Some(Format::Step),
            _ => None,
        }
    }

    /// The format's usual file extension (`igs`, `stp`).
    pub fn extension(self) -> &'static str {
        match self {
            Format::Iges => "igs",
            Format::Step => "stp",
        }
    }
}

impl fmt::Display for Format {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Format::Iges => "IGES",
            Format::Step => "STEP",
        })
    }
}

/// An entity of a document: an IGES directory entry (its `DE` sequence number) or a STEP
/// instance (`#n`), and which assembly occurrence of it is meant (0 unless an assembly
/// places the same shape twice; IGES has one).
///
/// Displayed as the format writes it: `DE 5`, `#12`, `#12 (occurrence 2)` for the
/// second occurrence. Serialised as `{ "format", "id", "occurrence" }`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub struct EntityRef {
    /// The document's format.
    pub format: Format,
    /// IGES directory-entry sequence number, or STEP instance number.
    pub id: u64,
    /// Assembly occurrence (0-based).
    pub occurrence: u32,
}

impl EntityRef {
    /// Occurrence 0 of entity `id`.
    pub fn new(format: Format, id: u64) -> Self {
        Self { format, id, occurrence: 0 }
    }

    /// The same entity at another occurrence.
    pub fn with_occurrence(self, occurrence: u32) -> Self {
        Self { occurrence, ..self }
    }
}

impl fmt::Display for EntityRef {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.format {
            Format::Iges => write!(f, "DE {}", self.id)?,
            Format::Step => write!(f, "#{}", self.id)?,
        }
        if self.occurrence > 0 {
            write!(f, " (occurrence {})", self.occurrence + 1)?;
        }
        Ok(())
    }
}
