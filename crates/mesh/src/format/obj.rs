//! Wavefront OBJ (Wavefront Technologies, "Object Files (.obj)", Appendix B1 of the
//! Advanced Visualizer manual): `v x y z [w]` vertices, `f i[/t][/n] …` faces with 1-based
//! (or negative, relative) indices, `g`/`o` groups; `vt`, `vn`, `usemtl`, `mtllib`, `s`,
//! comments and anything else kept verbatim.

use nalgebra::Point3;

use crate::cell::{Cell, CellKind};
use crate::nodelines::NodeLines;
use crate::text::{check_finite, line_ranges, parse_f64, py_str, trim_eol};
use crate::{Error, Result};

/// An OBJ file, kept losslessly.
///
/// # Examples
///
/// ```
/// use cadmorph_mesh::format::obj::Obj;
/// let mut o = Obj::parse("v 0 0 0\nv 1 0 0\nv 0 1 0\ng hull\nf 1 2 3\n")?;
/// assert_eq!(o.groups[0], "hull");
/// o.points[2].z = 0.5;
/// assert_eq!(o.write(), "v 0 0 0\nv 1 0 0\nv 0.0 1.0 0.5\ng hull\nf 1 2 3\n");
/// # Ok::<(), cadmorph_mesh::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Obj {
    /// Vertex positions.
    pub points: Vec<Point3<f64>>,
    /// Faces (triangle, quadrilateral or polygon), 0-based.
    pub cells: Vec<Cell>,
    /// Group names (`g`/`o`); the group of each face is [`Obj::face_groups`].
    pub groups: Vec<String>,
    /// Index into `groups` of each face (`None` before any `g`/`o`).
    pub face_groups: Vec<Option<usize>>,
    lines: NodeLines,
}

impl Obj {
    /// Read the text of an OBJ file.
    ///
    /// # Errors
    ///
    /// [`Error::Syntax`] naming the line of a bad vertex or face; [`Error::OutOfRange`]
    /// for a face index that is not a vertex (yet).
    pub fn parse(text: &str) -> Result<Obj> {
        let (mut points, mut records, mut cells, mut groups, mut face_groups) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let mut group = None;
        for (n, r) in line_ranges(text).into_iter().enumerate() {
            let line = trim_eol(&text[r.clone()]);
            let mut tok = line.split_whitespace();
            match tok.next() {
                Some("v") => {
                    let c: Vec<&str> = tok.collect();
                    if c.len() < 3 {
                        return Err(Error::syntax(n + 1, "`v x y z`", line));
                    }
                    let p = Point3::new(parse_f64(c[0], n + 1)?, parse_f64(c[1], n + 1)?, parse_f64(c[2], n + 1)?);
                    points.push(p);
                    records.push((r.start..r.start + line.len(), p));
                }
                Some("f") => {
                    let mut nodes = Vec::new();
                    for t in tok {
                        let i: i64 = t
                            .split('/')
                            .next()
                            .unwrap_or("")
                            .parse()
                            .map_err(|_| Error::syntax(n + 1, "a vertex index", t))?;
                        let j = if i < 0 { points.len() as i64 + i } else { i - 1 };
                        if j < 0 || j as usize >= points.len() {
                            return Err(Error::OutOfRange {
                                what: "face on line",
                                index: n + 1,
                                target_kind: "vertex",
                                target: i,
                                count: points.len(),
                            });
                        }
                        nodes.push(j as usize);
                    }
                    let kind = match nodes.len() {
                        0..=2 => return Err(Error::syntax(n + 1, "a face of 3 or more vertices", line)),
                        3 => CellKind::Triangle,
                        4 => CellKind::Quad,
                        _ => CellKind::Polygon,
                    };
                    cells.push(Cell::new(kind, nodes));
                    face_groups.push(group);
                }
                Some("g") | Some("o") => {
                    groups.push(tok.collect::<Vec<_>>().join(" "));
                    group = Some(groups.len() - 1);
                }
                _ => {}
            }
        }
        check_finite(&points)?;
        Ok(Obj { points, cells, groups, face_groups, lines: NodeLines { text: text.to_string(), records } })
    }

    /// Number of vertices read.
    pub(crate) fn n_points_read(&self) -> usize {
        self.lines.len()
    }

    /// The file, with the `v` lines of moved vertices written anew (shortest round-trip
    /// numbers; a `w` or colour after z kept), the rest as read.
    pub fn write(&self) -> String {
        self.lines.write(&self.points, false, |_, p, orig| {
            let rest: Vec<&str> = orig.split_whitespace().skip(4).collect();
            let mut s = format!("v {} {} {}", py_str(p.x), py_str(p.y), py_str(p.z));
            for r in rest {
                s.push(' ');
                s.push_str(r);
            }
            s
        })
    }
}
