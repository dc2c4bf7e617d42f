//! Length units of a document.

use serde::Serialize;

/// The length unit and tolerance of a document's geometry. Every coordinate a
/// [`CadDocument`](crate::CadDocument) gives or takes is in this unit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Units {
    /// Metres per model unit (0.001 for millimetres, 0.0254 for inches, 0.3048 for feet).
    pub metres_per_unit: f64,
    /// The unit's name as the file gives it (IGES global parameter 15: `MM`, `IN`, `FT`;
    /// STEP: `MILLI METRE`, `METRE`, `INCH`).
    pub name: String,
    /// The file's distance uncertainty in model units (IGES global parameter 19, the
    /// minimum resolution; STEP `UNCERTAINTY_MEASURE_WITH_UNIT`), when it states one.
    pub uncertainty: Option<f64>,
}
