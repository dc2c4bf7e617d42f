//! ISO 10303-21 (STEP) lossless reader/writer with B-rep and NURBS views (being written; see the issue).
