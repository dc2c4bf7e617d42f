//! VTK legacy files, ASCII (VTK User's Guide, "VTK File Formats", simple legacy format):
//! `# vtk DataFile Version x.y`, a title line, `ASCII`, `DATASET POLYDATA |
//! UNSTRUCTURED_GRID | STRUCTURED_GRID`, `POINTS n type` with `3n` numbers, then cells
//! (`CELLS n size` + `CELL_TYPES n`, or `POLYGONS`/`VERTICES`/`LINES n size`), then any
//! `POINT_DATA`/`CELL_DATA`/`FIELD` sections, kept verbatim. The `BINARY` variant is
//! refused with [`Error::Unsupported`].

use std::ops::Range;

use nalgebra::Point3;

use crate::cell::{Cell, CellKind};
use crate::text::{c_g, check_finite, py_str};
use crate::{Error, Result};

/// A VTK legacy ASCII file.
#[derive(Debug, Clone, PartialEq)]
pub struct VtkLegacy {
    /// The points.
    pub points: Vec<Point3<f64>>,
    /// Cells (`CELLS`/`CELL_TYPES` of an unstructured grid with linear kinds, or the
    /// `VERTICES`, `LINES` and `POLYGONS` of polydata: triangles, quadrilaterals and polygons).
    pub cells: Vec<Cell>,
    /// The `DATASET` type.
    pub dataset: String,
    text: String,
    /// Byte range of the `3n` point numbers.
    block: Range<usize>,
    original: Vec<Point3<f64>>,
}

struct Words<'a> {
    text: &'a str,
    pos: usize,
}

impl<'a> Words<'a> {
    fn next(&mut self) -> Option<(usize, &'a str)> {
        let b = self.text.as_bytes();
        while self.pos < b.len() && b[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        if self.pos >= b.len() {
            return None;
        }
        let s = self.pos;
        while self.pos < b.len() && !b[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        Some((s, &self.text[s..self.pos]))
    }
    fn line(&self, at: usize) -> usize {
        1 + self.text.as_bytes()[..at.min(self.text.len())].iter().filter(|&&c| c == b'\n').count()
    }
    fn num<T: std::str::FromStr>(&mut self, what: &'static str) -> Result<T> {
        match self.next() {
            Some((at, w)) => w.parse::<T>().map_err(|_| Error::syntax(self.line(at), what, w)),
            None => Err(Error::syntax(self.line(self.pos), what, "end of file")),
        }
    }
}

impl VtkLegacy {
    /// Read the text of a legacy VTK file.
    ///
    /// # Errors
    ///
    /// [`Error::Syntax`] naming the line of a bad header, number or count;
    /// [`Error::Unsupported`] for `BINARY`; [`Error::OutOfRange`] for a cell node that
    /// is not a point; [`Error::NonFinite`] for NaN points.
    pub fn parse(text: &str) -> Result<VtkLegacy> {
        let mut lines = text.lines();
        let head = lines.next().unwrap_or("");
        if !head.starts_with("# vtk DataFile") {
            return Err(Error::syntax(1, "`# vtk DataFile Version x.y`", head));
        }
        lines.next();
        let fmt = lines.next().unwrap_or("").trim();
        if fmt.eq_ignore_ascii_case("BINARY") {
            return Err(Error::Unsupported("binary legacy VTK (use VTU or ASCII)".into()));
        }
        if !fmt.eq_ignore_ascii_case("ASCII") {
            return Err(Error::syntax(3, "`ASCII`", fmt));
        }
        let start = text.match_indices('\n').nth(2).map(|(i, _)| i + 1).unwrap_or(text.len());
        let mut w = Words { text, pos: start };
        let mut dataset = String::new();
        let mut points = Vec::new();
        let mut block = 0..0;
        let mut cells = Vec::new();
        let mut cell_nodes: Vec<Vec<usize>> = Vec::new();
        while let Some((at, kw)) = w.next() {
            match kw.to_ascii_uppercase().as_str() {
                "DATASET" => dataset = w.next().map(|x| x.1.to_string()).unwrap_or_default(),
                "DIMENSIONS" | "ORIGIN" | "SPACING" => {
                    for _ in 0..3 {
                        w.next();
                    }
                }
                "POINTS" => {
                    let n: usize = w.num("a point count")?;
                    if n > text.len() {
                        return Err(Error::syntax(w.line(at), "a point count the file can hold", &n.to_string()));
                    }
                    w.next(); // type
                    let mut first = None;
                    for _ in 0..n {
                        let mut c = [0.0; 3];
                        for v in &mut c {
                            let save = w.pos;
                            *v = w.num("a coordinate")?;
                            if first.is_none() {
                                first = Some(save);
                            }
                        }
                        points.push(Point3::from(c));
                    }
                    let s = first.map(|f| f + (text[f..].len() - text[f..].trim_start().len())).unwrap_or(w.pos);
                    block = s..w.pos;
                }
                "CELLS" | "POLYGONS" | "VERTICES" | "LINES" | "TRIANGLE_STRIPS" => {
                    let upper = kw.to_ascii_uppercase();
                    let n: usize = w.num("a cell count")?;
                    // Every cell takes at least a character: a larger count is false (and
                    // was allocated for before anything else was read).
                    if n > text.len() {
                        return Err(Error::syntax(w.line(at), "a cell count the file can hold", &n.to_string()));
                    }
                    let size: usize = w.num("a cell list size")?;
                    if size > text.len() {
                        return Err(Error::syntax(w.line(at), "a list size the file can hold", &size.to_string()));
                    }
                    let mut list = Vec::with_capacity(n);
                    // Version 5.x: `OFFSETS type` (n values) then `CONNECTIVITY type` (size values).
                    let save = w.pos;
                    if w.next().is_some_and(|t| t.1 == "OFFSETS") {
                        w.next();
                        let mut off = Vec::with_capacity(n);
                        for _ in 0..n {
                            off.push(w.num::<usize>("an offset")?);
                        }
                        match w.next() {
                            Some((_, "CONNECTIVITY")) => {
                                w.next();
                            }
                            other => {
                                return Err(Error::syntax(
                                    w.line(w.pos),
                                    "`CONNECTIVITY`",
                                    other.map(|o| o.1).unwrap_or("end of file"),
                                ))
                            }
                        }
                        let mut conn = Vec::with_capacity(size);
                        for _ in 0..size {
                            let at = w.pos;
                            let i: i64 = w.num("a point index")?;
                            if i < 0 || i as usize >= points.len() {
                                return Err(Error::OutOfRange {
                                    what: "cell on line",
                                    index: w.line(at),
                                    target_kind: "point",
                                    target: i,
                                    count: points.len(),
                                });
                            }
                            conn.push(i as usize);
                        }
                        for k in 1..off.len() {
                            if off[k - 1] > off[k] || off[k] > conn.len() {
                                return Err(Error::syntax(
                                    w.line(at),
                                    "increasing offsets within the connectivity",
                                    &format!("offset {} = {}", k, off[k]),
                                ));
                            }
                            list.push(conn[off[k - 1]..off[k]].to_vec());
                        }
                    } else {
                        w.pos = save;
                    }
                    for _ in 0..if list.is_empty() { n } else { 0 } {
                        let k: usize = w.num("a node count")?;
                        if k > size {
                            return Err(Error::syntax(
                                w.line(w.pos),
                                "a node count within the list size",
                                &k.to_string(),
                            ));
                        }
                        let mut nodes = Vec::with_capacity(k);
                        for _ in 0..k {
                            let save = w.pos;
                            let i: i64 = w.num("a point index")?;
                            if i < 0 || i as usize >= points.len() {
                                return Err(Error::OutOfRange {
                                    what: "cell on line",
                                    index: w.line(save),
                                    target_kind: "point",
                                    target: i,
                                    count: points.len(),
                                });
                            }
                            nodes.push(i as usize);
                        }
                        list.push(nodes);
                    }
                    match upper.as_str() {
                        "CELLS" => cell_nodes = list,
                        "TRIANGLE_STRIPS" => {}
                        kind => {
                            for nodes in list {
                                let k = match (kind, nodes.len()) {
                                    ("VERTICES", 1) => CellKind::Vertex,
                                    ("LINES", 2) => CellKind::Line,
                                    ("POLYGONS", 3) => CellKind::Triangle,
                                    ("POLYGONS", 4) => CellKind::Quad,
                                    ("POLYGONS", _) => CellKind::Polygon,
                                    _ => continue,
                                };
                                cells.push(Cell::new(k, nodes));
                            }
                        }
                    }
                }
                "CELL_TYPES" => {
                    let n: usize = w.num("a cell type count")?;
                    if n != cell_nodes.len() {
                        return Err(Error::syntax(w.line(at), "as many CELL_TYPES as CELLS", &n.to_string()));
                    }
                    for nodes in std::mem::take(&mut cell_nodes) {
                        let id: i64 = w.num("a cell type")?;
                        if let Some(k) = CellKind::from_vtk_id(id) {
                            if k.n_nodes().is_none_or(|m| m == nodes.len()) {
                                cells.push(Cell::new(k, nodes));
                            }
                        }
                    }
                }
                // Data sections run to the end of the file and are kept verbatim.
                "POINT_DATA" | "CELL_DATA" | "FIELD" => break,
                _ => {}
            }
        }
        check_finite(&points)?;
        Ok(VtkLegacy { original: points.clone(), points, cells, dataset, text: text.to_string(), block })
    }

    /// Number of points read.
    pub(crate) fn n_points_read(&self) -> usize {
        self.original.len()
    }

    fn write_with(&self, always: bool, f: impl Fn(f64) -> String) -> String {
        if !always && self.points == self.original {
            return self.text.clone();
        }
        let mut s = String::with_capacity(self.text.len());
        s.push_str(&self.text[..self.block.start]);
        for (i, p) in self.points.iter().enumerate() {
            for &v in p.iter() {
                s.push_str(&f(v));
                s.push(' ');
            }
            if i % 3 == 2 || i + 1 == self.points.len() {
                s.push('\n');
            }
        }
        // Drop the original block's own final line break (ours ends with one).
        let rest = &self.text[self.block.end..];
        s.push_str(rest.strip_prefix(" \n").or_else(|| rest.strip_prefix('\n')).unwrap_or(rest));
        s
    }

    /// The file: as read when no point moved; otherwise with the point block rewritten
    /// (three points per line, shortest round-trip numbers), everything else as read.
    pub fn write(&self) -> String {
        self.write_with(false, py_str)
    }

    /// The point block as VTK's `vtkDataWriter` writes it (`%g` of the `f32` points, three
    /// points per line, each number followed by a space), which is what PyGeM's
    /// `VtkHandler.write` gives.
    pub fn write_vtk_style(&self) -> String {
        self.write_with(true, |v| c_g(v as f32 as f64, 6))
    }
}
