//! LS-DYNA keyword files (`.k`, LS-DYNA Keyword User's Manual vol. I, `*NODE` and
//! `*ELEMENT_SHELL`/`*ELEMENT_SOLID`): a `*NODE` card is `NID X Y Z [TC RC]` in fixed
//! columns (I8, 3×E16, I8, I8) or free format separated by commas; an element card is
//! `EID PID N1 …` on one line, or for `*ELEMENT_SOLID` also in the two-card form (`EID PID`,
//! then `N1 … N10`); `$` starts a comment;
//! each keyword block runs to the next line starting with `*`. Every other keyword is
//! kept verbatim.

use nalgebra::Point3;

use crate::cell::{Cell, CellKind};
use crate::nodelines::NodeLines;
use crate::text::{check_finite, line_ranges, parse_f64, parse_i64, trim_eol};
use crate::{Error, Result};

/// An LS-DYNA keyword file, kept losslessly.
#[derive(Debug, Clone, PartialEq)]
pub struct KeywordFile {
    /// Node coordinates, in file order.
    pub points: Vec<Point3<f64>>,
    /// Node ids.
    pub ids: Vec<i64>,
    /// Shell (triangle or quadrilateral, a repeated last node making a triangle) and
    /// solid (hexahedron; tetrahedron and wedge in LS-DYNA's degenerate-hexahedron form
    /// `n1 n2 n3 n4 n4 n4 n4 n4` / `n1 n2 n3 n4 n5 n5 n6 n6`) elements.
    pub cells: Vec<Cell>,
    lines: NodeLines,
    comma: Vec<bool>,
}

/// Split a card into fields: by commas when it has one, else in the fixed columns
/// `widths` (falling back to whitespace when the columns do not hold numbers).
fn fields<'a>(line: &'a str, widths: &[usize]) -> Vec<&'a str> {
    if line.contains(',') {
        return line.split(',').map(str::trim).filter(|s| !s.is_empty()).collect();
    }
    let mut out = Vec::new();
    let mut at = 0;
    for &w in widths {
        if at >= line.len() || !line.is_char_boundary(at) {
            break;
        }
        let end = (at + w).min(line.len());
        if !line.is_char_boundary(end) {
            break;
        }
        let f = line[at..end].trim();
        if !f.is_empty() {
            out.push(f);
        }
        at = end;
    }
    let numeric = out.iter().all(|f| f.parse::<f64>().is_ok());
    if numeric && out.len() >= 2 {
        out
    } else {
        line.split_whitespace().collect()
    }
}

impl KeywordFile {
    /// Read the text of a keyword file.
    ///
    /// # Errors
    ///
    /// [`Error::Syntax`] naming the line of a malformed `*NODE` card;
    /// [`Error::OutOfRange`] for an element node id that is not a node.
    pub fn parse(text: &str) -> Result<KeywordFile> {
        let mut points = Vec::new();
        let mut ids = Vec::new();
        let mut records = Vec::new();
        let mut comma = Vec::new();
        let mut raw: Vec<(usize, bool, Vec<i64>)> = Vec::new();
        #[derive(PartialEq, Clone, Copy)]
        enum Block {
            Other,
            Node,
            Shell,
            Solid,
        }
        let mut block = Block::Other;
        // The line of an `*ELEMENT_SOLID` card holding only `EID PID`.
        let mut solid_head: Option<usize> = None;
        for (n, r) in line_ranges(text).into_iter().enumerate() {
            let line = trim_eol(&text[r.clone()]);
            if line.starts_with('$') || line.trim().is_empty() {
                continue;
            }
            if let Some(kw) = line.strip_prefix('*') {
                solid_head = None;
                let kw = kw.trim().to_ascii_uppercase();
                block = if kw == "NODE" {
                    Block::Node
                } else if kw.starts_with("ELEMENT_SHELL") {
                    Block::Shell
                } else if kw.starts_with("ELEMENT_SOLID") {
                    Block::Solid
                } else {
                    Block::Other
                };
                continue;
            }
            match block {
                Block::Node => {
                    let f = fields(line, &[8, 16, 16, 16, 8, 8]);
                    if f.len() < 4 {
                        return Err(Error::syntax(n + 1, "`NID X Y Z`", line));
                    }
                    ids.push(parse_i64(f[0], n + 1)?);
                    let p = Point3::new(parse_f64(f[1], n + 1)?, parse_f64(f[2], n + 1)?, parse_f64(f[3], n + 1)?);
                    points.push(p);
                    records.push((r.start..r.start + line.len(), p));
                    comma.push(line.contains(','));
                }
                Block::Shell | Block::Solid => {
                    let f = fields(line, &[8; 10]);
                    let v: Result<Vec<i64>> = f.iter().map(|s| parse_i64(s, n + 1)).collect();
                    if let Ok(v) = v {
                        if let Some(head) = solid_head.take() {
                            // The second card of the two-card form: N1 … N10 (zeros unused).
                            let nodes: Vec<i64> = v.into_iter().take(8).collect();
                            raw.push((head, true, nodes));
                        } else if block == Block::Solid && v.len() == 2 {
                            // `EID PID` alone: the two-card form (PyDyna, LS-PrePost's
                            // newer decks), the nodes on the next card.
                            solid_head = Some(n + 1);
                        } else if v.len() >= 5 {
                            raw.push((n + 1, block == Block::Solid, v[2..].to_vec()));
                        }
                    }
                }
                Block::Other => {}
            }
        }
        check_finite(&points)?;
        let index: std::collections::HashMap<i64, usize> = ids.iter().enumerate().map(|(i, &l)| (l, i)).collect();
        let mut cells = Vec::new();
        for (line, solid, nodes) in raw {
            let mut idx = Vec::with_capacity(nodes.len());
            for &id in &nodes {
                let Some(&j) = index.get(&id) else {
                    return Err(Error::OutOfRange {
                        what: "element on line",
                        index: line,
                        target_kind: "node id",
                        target: id,
                        count: ids.len(),
                    });
                };
                idx.push(j);
            }
            let cell = if !solid {
                match idx.len() {
                    3 => Cell::new(CellKind::Triangle, idx),
                    4 if idx[2] == idx[3] => Cell::new(CellKind::Triangle, idx[..3].to_vec()),
                    4 => Cell::new(CellKind::Quad, idx),
                    _ => continue,
                }
            } else if idx.len() == 8 {
                if idx[3..].iter().all(|&k| k == idx[4]) && idx[3] == idx[4] {
                    Cell::new(CellKind::Tetra, idx[..4].to_vec())
                } else if idx[4] == idx[5] && idx[6] == idx[7] {
                    Cell::new(CellKind::Wedge, vec![idx[0], idx[1], idx[2], idx[3], idx[4], idx[6]])
                } else {
                    Cell::new(CellKind::Hexahedron, idx)
                }
            } else {
                continue;
            };
            cells.push(cell);
        }
        Ok(KeywordFile { points, ids, cells, lines: NodeLines { text: text.to_string(), records }, comma })
    }

    /// The file, with the cards of moved nodes written anew (coordinates as `{:.10f}`, as
    /// PyGeM's `KHandler` writes them, in 16 columns for fixed-format cards or separated
    /// by `, ` for free-format ones; fields after Z kept), the rest as read.
    pub fn write(&self) -> String {
        self.lines.write(&self.points, false, |i, p, orig| {
            if self.comma[i] {
                let rest: Vec<&str> = orig.split(',').skip(4).collect();
                let mut s = format!("{}, {:.10}, {:.10}, {:.10}", self.ids[i], p.x, p.y, p.z);
                for r in rest {
                    s.push(',');
                    s.push_str(r);
                }
                s
            } else {
                let rest = orig.get(56..).unwrap_or("");
                format!("{:>8}{:>16}{:>16}{:>16}{rest}", self.ids[i], fit16(p.x), fit16(p.y), fit16(p.z))
            }
        })
    }
}

/// A number in at most 16 characters (an E16 field), with as many digits as fit: `{:.10}`
/// when it fits (PyGeM's format), else fewer decimals, else scientific notation.
fn fit16(x: f64) -> String {
    for d in (0..=10).rev() {
        let s = format!(" {x:.d$}");
        if s.len() <= 16 && (d > 0 || x.abs() < 1e15) {
            return s[1..].to_string();
        }
    }
    for d in (0..=9).rev() {
        let s = crate::text::py_exp(x, d);
        if s.len() <= 15 {
            return s;
        }
    }
    format!("{x:e}")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `*ELEMENT_SOLID` in the one-card and the two-card form give the same tetrahedra.
    #[test]
    fn solid_cards_in_both_forms() {
        let nodes = "*NODE\n       1             0.0             0.0             0.0\n       2             1.0             0.0             0.0\n       3             0.0             1.0             0.0\n       4             0.0             0.0             1.0\n";
        let one = format!("*KEYWORD\n{nodes}*ELEMENT_SOLID\n       7       1       1       2       3       4       4       4       4       4\n*END\n");
        let two = format!("*KEYWORD\n{nodes}*ELEMENT_SOLID\n$#   eid     pid\n       7       1\n$#    n1      n2      n3      n4      n5      n6      n7      n8      n9     n10\n       1       2       3       4       4       4       4       4                \n*END\n");
        let a = KeywordFile::parse(&one).unwrap();
        let b = KeywordFile::parse(&two).unwrap();
        assert_eq!(a.cells, vec![Cell::new(CellKind::Tetra, vec![0, 1, 2, 3])]);
        assert_eq!(b.cells, a.cells);
        assert_eq!(b.write(), two);
    }
}
