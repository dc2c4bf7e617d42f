//! I-DEAS Universal files (`.unv`): dataset 2411 (nodes, double precision: a record of
//! `label export_cs displacement_cs colour` then a line of three `1P3D25.16` coordinates)
//! and dataset 2412 (elements: `label fe_id physical material colour n_nodes`, a beam
//! orientation record for beam ids 11 and 21–24, then the node labels, eight per line).
//! Datasets open and close with a `    -1` line. Every other dataset is kept verbatim.
//!
//! Element kinds recognised: 11/21 line, 41/91 triangle, 44/94 quadrilateral, 111
//! tetrahedron, 112 wedge, 115 hexahedron; node order as in the file.

use nalgebra::Point3;

use crate::cell::{Cell, CellKind};
use crate::nodelines::NodeLines;
use crate::text::{check_finite, line_ranges, parse_f64, parse_i64, py_exp, trim_eol};
use crate::{Error, Result};

/// A Universal file, kept losslessly.
#[derive(Debug, Clone, PartialEq)]
pub struct Unv {
    /// Node coordinates (all 2411 datasets, in file order).
    pub points: Vec<Point3<f64>>,
    /// Node labels.
    pub labels: Vec<i64>,
    /// Elements of the 2412 datasets with a recognised kind.
    pub cells: Vec<Cell>,
    lines: NodeLines,
}

fn is_delim(l: &str) -> bool {
    l.trim() == "-1"
}

impl Unv {
    /// Read the text of a Universal file.
    ///
    /// # Errors
    ///
    /// [`Error::Syntax`] naming the line of a malformed record or a dataset left open;
    /// [`Error::OutOfRange`] for an element node label that is not a node.
    pub fn parse(text: &str) -> Result<Unv> {
        let ranges = line_ranges(text);
        let line = |i: usize| trim_eol(&text[ranges[i].clone()]);
        let mut points = Vec::new();
        let mut labels = Vec::new();
        let mut records = Vec::new();
        let mut raw: Vec<(usize, CellKind, Vec<i64>)> = Vec::new();
        let mut i = 0;
        while i < ranges.len() {
            if !is_delim(line(i)) {
                i += 1;
                continue;
            }
            // Opening delimiter; the next line is the dataset number.
            let open = i;
            i += 1;
            if i >= ranges.len() {
                break;
            }
            let number = line(i).trim().to_string();
            i += 1;
            let end_of = |from: usize| (from..ranges.len()).find(|&k| is_delim(line(k)));
            let Some(close) = end_of(i) else {
                return Err(Error::syntax(open + 1, "a dataset closed by `    -1`", "end of file"));
            };
            match number.as_str() {
                "2411" => {
                    if (close - i) % 2 != 0 {
                        return Err(Error::syntax(close, "node records in pairs of lines", line(close - 1)));
                    }
                    let mut k = i;
                    while k < close {
                        let head: Vec<&str> = line(k).split_whitespace().collect();
                        if head.len() != 4 {
                            return Err(Error::syntax(k + 1, "`label export_cs disp_cs colour`", line(k)));
                        }
                        labels.push(parse_i64(head[0], k + 1)?);
                        let c: Vec<&str> = line(k + 1).split_whitespace().collect();
                        if c.len() != 3 {
                            return Err(Error::syntax(k + 2, "three coordinates", line(k + 1)));
                        }
                        let p = Point3::new(parse_f64(c[0], k + 2)?, parse_f64(c[1], k + 2)?, parse_f64(c[2], k + 2)?);
                        let r = ranges[k + 1].clone();
                        records.push((r.start..r.start + line(k + 1).len(), p));
                        points.push(p);
                        k += 2;
                    }
                }
                "2412" => {
                    let mut k = i;
                    while k < close {
                        let head: Vec<&str> = line(k).split_whitespace().collect();
                        if head.len() != 6 {
                            return Err(Error::syntax(k + 1, "`label fe_id phys mat colour n_nodes`", line(k)));
                        }
                        let fe = parse_i64(head[1], k + 1)?;
                        let nn = parse_i64(head[5], k + 1)?;
                        if !(1..=1000).contains(&nn) {
                            return Err(Error::syntax(k + 1, "a node count in 1..=1000", head[5]));
                        }
                        let start = k + 1;
                        k += 1;
                        if matches!(fe, 11 | 21..=24) {
                            k += 1; // beam orientation record
                        }
                        let mut nodes = Vec::with_capacity(nn as usize);
                        while nodes.len() < nn as usize {
                            if k >= close {
                                return Err(Error::syntax(start, "the element's node labels", "end of dataset"));
                            }
                            for t in line(k).split_whitespace() {
                                nodes.push(parse_i64(t, k + 1)?);
                            }
                            k += 1;
                        }
                        let kind = match (fe, nn) {
                            (11 | 21, 2) => Some(CellKind::Line),
                            (41 | 91, 3) => Some(CellKind::Triangle),
                            (44 | 94, 4) => Some(CellKind::Quad),
                            (111, 4) => Some(CellKind::Tetra),
                            (112, 6) => Some(CellKind::Wedge),
                            (115, 8) => Some(CellKind::Hexahedron),
                            _ => None,
                        };
                        if let Some(kind) = kind {
                            raw.push((start, kind, nodes));
                        }
                    }
                }
                _ => {}
            }
            i = close + 1;
        }
        check_finite(&points)?;
        let index: std::collections::HashMap<i64, usize> = labels.iter().enumerate().map(|(i, &l)| (l, i)).collect();
        let mut cells = Vec::with_capacity(raw.len());
        for (l, kind, nodes) in raw {
            let mut idx = Vec::with_capacity(nodes.len());
            for id in nodes {
                let Some(&j) = index.get(&id) else {
                    return Err(Error::OutOfRange {
                        what: "element on line",
                        index: l,
                        target_kind: "node label",
                        target: id,
                        count: labels.len(),
                    });
                };
                idx.push(j);
            }
            cells.push(Cell::new(kind, idx));
        }
        Ok(Unv { points, labels, cells, lines: NodeLines { text: text.to_string(), records } })
    }

    /// The file, with the coordinate lines of moved nodes written as PyGeM's `UnvHandler`
    /// writes them (three spaces and `'{:.16E}'` per coordinate), the rest as read.
    pub fn write(&self) -> String {
        self.lines.write(&self.points, false, |_, p, _| format_coords(p))
    }

    /// What PyGeM's `UnvHandler.write` writes: every coordinate line formatted anew.
    pub fn write_pygem(&self) -> String {
        self.lines.write(&self.points, true, |_, p, _| format_coords(p))
    }
}

fn format_coords(p: &Point3<f64>) -> String {
    format!("   {}   {}   {}", py_exp(p.x, 16), py_exp(p.y, 16), py_exp(p.z, 16))
}
