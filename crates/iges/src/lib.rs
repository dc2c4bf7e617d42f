//! IGES 5.3 lossless reader/writer with NURBS views of every surface (being written; see the issue).
