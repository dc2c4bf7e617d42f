//! New documents from NURBS curves and surfaces.

/// Builds a new IGES document.
#[derive(Debug, Clone, Default)]
pub struct DocumentBuilder {}
