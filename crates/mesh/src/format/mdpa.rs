//! Kratos Multiphysics `.mdpa` model part files (Kratos wiki, "Input data": blocks
//! `Begin Nodes` … `End Nodes` of `id x y z`, `Begin Elements <Name>` … `End Elements`
//! of `id property n₁ n₂ …`, likewise `Conditions`; every other block is kept verbatim).

use nalgebra::Point3;

use crate::cell::{Cell, CellKind};
use crate::nodelines::NodeLines;
use crate::text::{check_finite, line_ranges, parse_f64, parse_i64, py_exp, trim_eol};
use crate::{Error, Result};

/// A Kratos `.mdpa` file, kept losslessly.
#[derive(Debug, Clone, PartialEq)]
pub struct Mdpa {
    /// Node coordinates, in file order.
    pub points: Vec<Point3<f64>>,
    /// Node ids, in file order.
    pub ids: Vec<i64>,
    /// Elements and conditions whose node count gives a linear kind (2 line, 3 triangle,
    /// 4 tetrahedron for names with `Tetra` or `3D4` but not `Shell`, `Quad`, `Surface`
    /// or `Membrane`, else quadrilateral; 6 wedge, 8 hexahedron), with their block name.
    pub cells: Vec<(String, Cell)>,
    lines: NodeLines,
}

impl Mdpa {
    /// Read the text of an `.mdpa` file.
    ///
    /// # Errors
    ///
    /// [`Error::Syntax`] for a bad node record or an unterminated block (with its line);
    /// [`Error::OutOfRange`] for an element node id that is not a node.
    pub fn parse(text: &str) -> Result<Mdpa> {
        let mut points = Vec::new();
        let mut ids = Vec::new();
        let mut records = Vec::new();
        let mut raw_cells: Vec<(String, usize, Vec<i64>)> = Vec::new();
        #[derive(PartialEq)]
        enum Block {
            None,
            Nodes,
            Elements(String),
            Other,
        }
        let mut block = Block::None;
        let mut depth_other = 0usize;
        let mut block_line = 0;
        for (n, r) in line_ranges(text).into_iter().enumerate() {
            let line = trim_eol(&text[r.clone()]);
            let t = line.trim();
            if t.is_empty() || t.starts_with("//") {
                continue;
            }
            if let Some(rest) = t.strip_prefix("Begin ") {
                if block == Block::Other {
                    depth_other += 1;
                    continue;
                }
                if block != Block::None {
                    return Err(Error::syntax(n + 1, "`End` of the open block", line));
                }
                block_line = n + 1;
                let mut w = rest.split_whitespace();
                block = match w.next() {
                    Some("Nodes") => Block::Nodes,
                    Some("Elements") | Some("Conditions") => Block::Elements(w.next().unwrap_or("").to_string()),
                    _ => {
                        depth_other = 0;
                        Block::Other
                    }
                };
                continue;
            }
            if t.starts_with("End ") || t == "End" {
                if block == Block::Other && depth_other > 0 {
                    depth_other -= 1;
                } else {
                    block = Block::None;
                }
                continue;
            }
            match &block {
                Block::Nodes => {
                    let tok: Vec<&str> = t.split_whitespace().collect();
                    if tok.len() != 4 {
                        return Err(Error::syntax(n + 1, "`id x y z`", line));
                    }
                    let p =
                        Point3::new(parse_f64(tok[1], n + 1)?, parse_f64(tok[2], n + 1)?, parse_f64(tok[3], n + 1)?);
                    ids.push(parse_i64(tok[0], n + 1)?);
                    points.push(p);
                    records.push((r.start..r.start + line.len(), p));
                }
                Block::Elements(name) => {
                    let tok: Vec<&str> = t.split_whitespace().collect();
                    if tok.len() < 3 {
                        return Err(Error::syntax(n + 1, "`id property node…`", line));
                    }
                    let nodes = tok[2..].iter().map(|s| parse_i64(s, n + 1)).collect::<Result<Vec<_>>>()?;
                    raw_cells.push((name.clone(), n + 1, nodes));
                }
                _ => {}
            }
        }
        if block != Block::None {
            return Err(Error::syntax(block_line, "a block closed by `End`", "end of file"));
        }
        check_finite(&points)?;
        let index: std::collections::HashMap<i64, usize> = ids.iter().enumerate().map(|(i, &id)| (id, i)).collect();
        let mut cells = Vec::new();
        for (name, line, nodes) in raw_cells {
            let kind = match nodes.len() {
                2 => CellKind::Line,
                3 => CellKind::Triangle,
                4 if (name.contains("Tetra") || name.contains("3D4"))
                    && !["Shell", "Quad", "Surface", "Membrane"].iter().any(|w| name.contains(w)) =>
                {
                    CellKind::Tetra
                }
                4 => CellKind::Quad,
                6 => CellKind::Wedge,
                8 => CellKind::Hexahedron,
                _ => continue,
            };
            let mut idx = Vec::with_capacity(nodes.len());
            for id in nodes {
                match index.get(&id) {
                    Some(&i) => idx.push(i),
                    None => {
                        return Err(Error::OutOfRange {
                            what: "element on line",
                            index: line,
                            target_kind: "node id",
                            target: id,
                            count: ids.len(),
                        })
                    }
                }
            }
            cells.push((name, Cell::new(kind, idx)));
        }
        Ok(Mdpa { points, ids, cells, lines: NodeLines { text: text.to_string(), records } })
    }

    /// The file, with the records of moved nodes in PyGeM's `MdpaHandler` layout
    /// (`' {:6d} {:23.16E} {:23.16E} {:23.16E}'`, the node's own id), the rest as read.
    pub fn write(&self) -> String {
        self.lines.write(&self.points, false, |i, p, _| self.format(i, p))
    }

    /// What PyGeM's `MdpaHandler.write` writes: every node record formatted anew (with
    /// PyGeM's id, the 1-based position).
    pub fn write_pygem(&self) -> String {
        self.lines.write(&self.points, true, |i, p, _| {
            format!(" {:6} {:>23} {:>23} {:>23}", i + 1, py_exp(p.x, 16), py_exp(p.y, 16), py_exp(p.z, 16))
        })
    }

    fn format(&self, i: usize, p: &Point3<f64>) -> String {
        format!(" {:6} {:>23} {:>23} {:>23}", self.ids[i], py_exp(p.x, 16), py_exp(p.y, 16), py_exp(p.z, 16))
    }
}
