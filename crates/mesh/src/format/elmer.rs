//! Elmer `mesh.nodes` (ElmerSolver manual, appendix "Format of mesh files": one node per
//! line, `node_id partition x y z`, partition −1 when not partitioned).
//!
//! Only the nodes file carries coordinates; `mesh.header`, `mesh.elements` and
//! `mesh.boundary` are left untouched by a morph, as PyGeM's `ElmerHandler` does.

use nalgebra::Point3;

use crate::nodelines::NodeLines;
use crate::text::{check_finite, line_ranges, parse_f64, parse_i64, py_str, trim_eol};
use crate::{Error, Result};

/// An Elmer nodes file, kept losslessly.
///
/// # Examples
///
/// ```
/// use cadmorph_mesh::format::elmer::ElmerNodes;
/// let mut f = ElmerNodes::parse("1 -1 0 1 0\n2 -1 0.5 1.1 0\n")?;
/// f.points[1].x = 2.0;
/// assert_eq!(f.write(), "1 -1 0 1 0\n2 -1 2.0 1.1 0.0\n");
/// # Ok::<(), cadmorph_mesh::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct ElmerNodes {
    /// Node coordinates, in file order.
    pub points: Vec<Point3<f64>>,
    /// Node ids, in file order.
    pub ids: Vec<i64>,
    lines: NodeLines,
}

impl ElmerNodes {
    /// Read the text of a nodes file.
    ///
    /// # Errors
    ///
    /// [`Error::Syntax`] naming the line of a record without five fields or with a bad
    /// number; [`Error::NonFinite`] for a NaN coordinate.
    pub fn parse(text: &str) -> Result<ElmerNodes> {
        let mut points = Vec::new();
        let mut ids = Vec::new();
        let mut records = Vec::new();
        for (n, r) in line_ranges(text).into_iter().enumerate() {
            let line = trim_eol(&text[r.clone()]);
            if line.trim().is_empty() {
                continue;
            }
            let tok: Vec<&str> = line.split_whitespace().collect();
            if tok.len() != 5 {
                return Err(Error::syntax(n + 1, "`id partition x y z`", line));
            }
            let id = parse_i64(tok[0], n + 1)?;
            parse_i64(tok[1], n + 1)?;
            let p = Point3::new(parse_f64(tok[2], n + 1)?, parse_f64(tok[3], n + 1)?, parse_f64(tok[4], n + 1)?);
            ids.push(id);
            points.push(p);
            records.push((r.start..r.start + line.len(), p));
        }
        check_finite(&points)?;
        Ok(ElmerNodes { points, ids, lines: NodeLines { text: text.to_string(), records } })
    }

    /// The file: unchanged nodes as read, moved nodes as `id partition x y z` with
    /// Python `str` numbers (shortest round-trip digits).
    pub fn write(&self) -> String {
        self.lines.write(&self.points, false, |_, p, orig| format_record(p, orig))
    }

    /// What PyGeM's `ElmerHandler.write` writes: every record formatted anew, no newline
    /// after the last one.
    pub fn write_pygem(&self) -> String {
        let s = self.lines.write(&self.points, true, |_, p, orig| format_record(p, orig));
        s.trim_end_matches('\n').to_string()
    }
}

fn format_record(p: &Point3<f64>, orig: &str) -> String {
    let mut t = orig.split_whitespace();
    let id = t.next().unwrap_or("0");
    let part = t.next().unwrap_or("-1");
    format!("{id} {part} {} {} {}", py_str(p.x), py_str(p.y), py_str(p.z))
}
