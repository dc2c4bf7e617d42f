//! A variant's `report.json`: what was made, from what, how well the seams held, how long
//! it took. Written last, after every output, so its presence means the variant is done.

use std::path::Path;

use serde::{Deserialize, Serialize};

/// One output file of a variant.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Output {
    /// File name inside the variant's folder.
    pub file: String,
    /// SHA-256 of its bytes.
    pub sha256: String,
    /// Its size.
    pub bytes: usize,
}

/// Seam maxima of the written document, read back (see `Model::verify`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Seams {
    /// Shared edges measured.
    pub edges: usize,
    /// Largest closest-point gap, model units.
    pub max_gap_closest: f64,
    /// Largest gap at matched parameters, model units.
    pub max_gap_matched: f64,
    /// Largest normal angle across a smooth edge, degrees.
    pub max_g1_angle_deg: f64,
    /// Largest relative C1 mismatch.
    pub max_c1_mismatch: f64,
}

/// Volume and surface area of a variant's faces, by `cadmorph_hull::enclosed` (Gauss
/// quadrature on the faces, the divergence theorem for the volume; agrees with OCCT's
/// `BRepGProp` to 1e-8 relative or better on the samples).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Measures {
    /// The enclosed volume, cubic model units; `None` when the faces do not enclose a
    /// solid the quadrature can measure (an open shell, a face whose curves are off it).
    pub volume: Option<f64>,
    /// The area of every face, square model units; `None` when a face cannot be
    /// measured.
    pub area: Option<f64>,
    /// Why they are `None`, when they are.
    pub note: Option<String>,
}

/// Wall times of the variant's steps, milliseconds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Timings {
    /// Reading the refined base, the online product and the morph.
    pub morph_ms: f64,
    /// Writing every output.
    pub write_ms: f64,
    /// Reading the written document back and measuring its seams.
    pub verify_ms: f64,
    /// Measuring volume and area.
    #[serde(default)]
    pub measure_ms: f64,
    /// All of it.
    pub total_ms: f64,
}

/// `report.json` of one variant.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Report {
    /// The variant id.
    pub id: String,
    /// The manifest's input hash it was made from.
    pub input_sha256: String,
    /// Parameter values, in the campaign's order.
    pub values: Vec<f64>,
    /// `"ok"` or `"failed"`.
    pub status: String,
    /// The error, for a failed variant.
    pub error: Option<String>,
    /// The outputs, in the order of the campaign's formats.
    pub outputs: Vec<Output>,
    /// Control points of all faces after the morph.
    pub control_points: usize,
    /// Faces rewritten.
    pub faces_rewritten: usize,
    /// Curves rewritten.
    pub curves_rewritten: usize,
    /// Seams of the written document.
    pub seams: Option<Seams>,
    /// Volume and area of the morphed faces (`None` for a failed variant).
    #[serde(default)]
    pub measures: Option<Measures>,
    /// The campaign's seam gap tolerance, if it has one.
    pub refine_tol: Option<f64>,
    /// The campaign's angle tolerance.
    pub angle_tol: f64,
    /// Whether the seams are within the tolerances (always true without `refine_tol`
    /// when the variant succeeded).
    pub in_tolerance: bool,
    /// Step times.
    pub timings: Timings,
}

impl Report {
    /// The report in `dir`, if there is a readable one.
    pub fn read(dir: &Path) -> Option<Report> {
        let text = std::fs::read_to_string(dir.join("report.json")).ok()?;
        serde_json::from_str(&text).ok()
    }

    /// Whether this report is of the variant with `input_sha256` and every output it
    /// lists is in `dir` with its hash (what makes a rerun skip the variant).
    pub fn is_complete(&self, dir: &Path, input_sha256: &str) -> bool {
        self.input_sha256 == input_sha256
            && self
                .outputs
                .iter()
                .all(|o| std::fs::read(dir.join(&o.file)).is_ok_and(|b| crate::space::sha256_hex(&b) == o.sha256))
    }
}
