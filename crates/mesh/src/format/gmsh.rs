//! Gmsh MSH files, ASCII, versions 2.2 and 4.1 (Gmsh reference manual §10 "Gmsh file
//! formats", "MSH file format version 2 (legacy)" and "MSH file format"): `$MeshFormat`,
//! `$Nodes`, `$Elements`; every other section (`$PhysicalNames`, `$Entities`,
//! `$NodeData`, `$Periodic`, …) kept verbatim. Binary MSH is refused with
//! [`Error::Unsupported`].
//!
//! Element types read: 15 point, 1 line, 2 triangle, 3 quadrilateral, 4 tetrahedron,
//! 5 hexahedron, 6 prism, 7 pyramid (node orders as VTK's, except the prism, whose
//! bottom triangle Gmsh orients towards the top: it is reordered to VTK's wedge).

use std::collections::HashMap;

use nalgebra::Point3;

use crate::cell::{Cell, CellKind};
use crate::nodelines::NodeLines;
use crate::text::{check_finite, line_ranges, parse_f64, parse_i64, py_str, trim_eol};
use crate::{Error, Result};

/// A Gmsh MSH file, kept losslessly.
#[derive(Debug, Clone, PartialEq)]
pub struct Msh {
    /// The format version (`2.2` or `4.1`).
    pub version: String,
    /// Node coordinates, in file order.
    pub points: Vec<Point3<f64>>,
    /// Node tags.
    pub tags: Vec<i64>,
    /// Elements of the kinds above, with their physical tag (2.2: first tag; 4.1: the
    /// entity tag of their block).
    pub cells: Vec<(i64, Cell)>,
    lines: NodeLines,
}

fn kind_of(t: i64) -> Option<(CellKind, usize)> {
    Some(match t {
        15 => (CellKind::Vertex, 1),
        1 => (CellKind::Line, 2),
        2 => (CellKind::Triangle, 3),
        3 => (CellKind::Quad, 4),
        4 => (CellKind::Tetra, 4),
        5 => (CellKind::Hexahedron, 8),
        6 => (CellKind::Wedge, 6),
        7 => (CellKind::Pyramid, 5),
        _ => return None,
    })
}

impl Msh {
    /// Read the text of an MSH 2.2 or 4.1 ASCII file.
    ///
    /// # Errors
    ///
    /// [`Error::Syntax`] naming the line of a malformed record or an unterminated section;
    /// [`Error::Unsupported`] for binary files or other versions; [`Error::OutOfRange`]
    /// for an element node tag that is not a node.
    pub fn parse(text: &str) -> Result<Msh> {
        let ranges = line_ranges(text);
        let line = |i: usize| trim_eol(&text[ranges[i].clone()]).trim();
        let mut version = String::new();
        let (mut points, mut tags, mut records) = (Vec::new(), Vec::new(), Vec::new());
        let mut raw: Vec<(usize, i64, i64, Vec<i64>)> = Vec::new();
        let mut i = 0;
        let need = |i: usize, what: &'static str| {
            if i < ranges.len() {
                Ok(())
            } else {
                Err(Error::syntax(i, what, "end of file"))
            }
        };
        while i < ranges.len() {
            let l = line(i);
            match l {
                "$MeshFormat" => {
                    need(i + 1, "the format line")?;
                    let f: Vec<&str> = line(i + 1).split_whitespace().collect();
                    if f.len() < 3 {
                        return Err(Error::syntax(i + 2, "`version file-type data-size`", line(i + 1)));
                    }
                    if f[1] != "0" {
                        return Err(Error::Unsupported("binary MSH (write it with Mesh.Binary = 0)".into()));
                    }
                    if f[0] != "2.2" && f[0] != "4.1" {
                        return Err(Error::Unsupported(format!("MSH version {} (2.2 and 4.1 are read)", f[0])));
                    }
                    version = f[0].to_string();
                    i += 2;
                }
                "$Nodes" if version == "2.2" => {
                    need(i + 1, "the node count")?;
                    let n = parse_i64(line(i + 1), i + 2)? as usize;
                    if n > ranges.len() {
                        return Err(Error::syntax(i + 2, "a node count the file can hold", line(i + 1)));
                    }
                    for k in 0..n {
                        let j = i + 2 + k;
                        need(j, "a node record")?;
                        let f: Vec<&str> = line(j).split_whitespace().collect();
                        if f.len() != 4 {
                            return Err(Error::syntax(j + 1, "`tag x y z`", line(j)));
                        }
                        tags.push(parse_i64(f[0], j + 1)?);
                        let p = Point3::new(parse_f64(f[1], j + 1)?, parse_f64(f[2], j + 1)?, parse_f64(f[3], j + 1)?);
                        points.push(p);
                        let r = ranges[j].clone();
                        records.push((r.start..r.start + trim_eol(&text[r]).len(), p));
                    }
                    i += 2 + n;
                }
                "$Nodes" => {
                    need(i + 1, "the node header")?;
                    let h: Vec<i64> =
                        line(i + 1).split_whitespace().map(|s| parse_i64(s, i + 2)).collect::<Result<_>>()?;
                    if h.len() != 4 {
                        return Err(Error::syntax(i + 2, "`numEntityBlocks numNodes minTag maxTag`", line(i + 1)));
                    }
                    let mut j = i + 2;
                    for _ in 0..h[0] {
                        need(j, "an entity block header")?;
                        let b: Vec<i64> =
                            line(j).split_whitespace().map(|s| parse_i64(s, j + 1)).collect::<Result<_>>()?;
                        if b.len() != 4 || b[3] < 0 || b[3] as usize > ranges.len() {
                            return Err(Error::syntax(j + 1, "`entityDim entityTag parametric numNodes`", line(j)));
                        }
                        let m = b[3] as usize;
                        for k in 0..m {
                            need(j + 1 + k, "a node tag")?;
                            tags.push(parse_i64(line(j + 1 + k), j + 2 + k)?);
                        }
                        for k in 0..m {
                            let c = j + 1 + m + k;
                            need(c, "node coordinates")?;
                            let f: Vec<&str> = line(c).split_whitespace().collect();
                            if f.len() < 3 {
                                return Err(Error::syntax(c + 1, "`x y z`", line(c)));
                            }
                            let p =
                                Point3::new(parse_f64(f[0], c + 1)?, parse_f64(f[1], c + 1)?, parse_f64(f[2], c + 1)?);
                            points.push(p);
                            let r = ranges[c].clone();
                            records.push((r.start..r.start + trim_eol(&text[r]).len(), p));
                        }
                        j += 1 + 2 * m;
                    }
                    i = j;
                }
                "$Elements" if version == "2.2" => {
                    need(i + 1, "the element count")?;
                    let n = parse_i64(line(i + 1), i + 2)? as usize;
                    if n > ranges.len() {
                        return Err(Error::syntax(i + 2, "an element count the file can hold", line(i + 1)));
                    }
                    for k in 0..n {
                        let j = i + 2 + k;
                        need(j, "an element record")?;
                        let f: Vec<i64> =
                            line(j).split_whitespace().map(|s| parse_i64(s, j + 1)).collect::<Result<_>>()?;
                        // ntags must be a count the record holds (a negative or huge one is
                        // malformed, and its sum with the record's start must not overflow).
                        if f.len() < 3 || f[2] < 0 || f[2] as u64 > (f.len() - 3) as u64 {
                            return Err(Error::syntax(j + 1, "`tag type ntags tags… nodes…`", line(j)));
                        }
                        let nt = f[2] as usize;
                        let phys = if nt > 0 { f[3] } else { 0 };
                        raw.push((j + 1, f[1], phys, f[3 + nt..].to_vec()));
                    }
                    i += 2 + n;
                }
                "$Elements" => {
                    need(i + 1, "the element header")?;
                    let h: Vec<i64> =
                        line(i + 1).split_whitespace().map(|s| parse_i64(s, i + 2)).collect::<Result<_>>()?;
                    if h.len() != 4 {
                        return Err(Error::syntax(i + 2, "`numEntityBlocks numElements minTag maxTag`", line(i + 1)));
                    }
                    let mut j = i + 2;
                    for _ in 0..h[0] {
                        need(j, "an entity block header")?;
                        let b: Vec<i64> =
                            line(j).split_whitespace().map(|s| parse_i64(s, j + 1)).collect::<Result<_>>()?;
                        if b.len() != 4 || b[3] < 0 || b[3] as usize > ranges.len() {
                            return Err(Error::syntax(j + 1, "`entityDim entityTag elementType numElements`", line(j)));
                        }
                        for k in 0..b[3] as usize {
                            let e = j + 1 + k;
                            need(e, "an element record")?;
                            let f: Vec<i64> =
                                line(e).split_whitespace().map(|s| parse_i64(s, e + 1)).collect::<Result<_>>()?;
                            if f.is_empty() {
                                return Err(Error::syntax(e + 1, "`tag nodes…`", line(e)));
                            }
                            raw.push((e + 1, b[2], b[1], f[1..].to_vec()));
                        }
                        j += 1 + b[3] as usize;
                    }
                    i = j;
                }
                _ => i += 1,
            }
        }
        if version.is_empty() {
            let first = if ranges.is_empty() { "an empty file" } else { line(0) };
            return Err(Error::syntax(1, "a `$MeshFormat` section", first));
        }
        check_finite(&points)?;
        let index: HashMap<i64, usize> = tags.iter().enumerate().map(|(i, &t)| (t, i)).collect();
        let mut cells = Vec::new();
        for (l, t, phys, nodes) in raw {
            let Some((kind, nn)) = kind_of(t) else { continue };
            if nodes.len() != nn {
                return Err(Error::syntax(
                    l,
                    "as many nodes as the element type has",
                    &format!("{} nodes for type {t}", nodes.len()),
                ));
            }
            let mut idx = Vec::with_capacity(nn);
            for id in nodes {
                let Some(&k) = index.get(&id) else {
                    return Err(Error::OutOfRange {
                        what: "element on line",
                        index: l,
                        target_kind: "node tag",
                        target: id,
                        count: tags.len(),
                    });
                };
                idx.push(k);
            }
            if kind == CellKind::Wedge {
                idx = vec![idx[0], idx[2], idx[1], idx[3], idx[5], idx[4]];
            }
            cells.push((phys, Cell::new(kind, idx)));
        }
        Ok(Msh { version, points, tags, cells, lines: NodeLines { text: text.to_string(), records } })
    }

    /// The file, with the coordinate records of moved nodes written anew (shortest
    /// round-trip numbers; MSH 2.2 keeps the tag, 4.1 any parametric values), the rest as read.
    pub fn write(&self) -> String {
        let v2 = self.version == "2.2";
        self.lines.write(&self.points, false, |i, p, orig| {
            if v2 {
                format!("{} {} {} {}", self.tags[i], py_str(p.x), py_str(p.y), py_str(p.z))
            } else {
                let rest: Vec<&str> = orig.split_whitespace().skip(3).collect();
                let mut s = format!("{} {} {}", py_str(p.x), py_str(p.y), py_str(p.z));
                for r in rest {
                    s.push(' ');
                    s.push_str(r);
                }
                s
            }
        })
    }
}
