//! STL, ASCII (`solid name` / `facet normal` / `outer loop` / `vertex` ×3 / `endloop` /
//! `endfacet` / `endsolid`, several solids per file allowed) and binary (80-byte header,
//! little-endian `u32` triangle count, 50 bytes per triangle: normal, three vertices as
//! `f32`, a `u16` attribute). 3D Systems, "StereoLithography Interface Specification", 1989.
//!
//! Vertices with identical coordinates are merged into one point, in order of first
//! appearance (as VTK's `vtkSTLReader` does, so point indices agree with PyGeM's), so that
//! a morph moves shared vertices together. Writing an unchanged file gives its bytes back;
//! a facet with a moved vertex is written anew with its normal recomputed.

use std::collections::HashMap;
use std::ops::Range;

use nalgebra::{Point3, Vector3};

use crate::text::{c_g, check_finite, line_ranges, parse_f64, py_str, trim_eol};
use crate::{Error, Result};

/// How the file was stored.
#[derive(Debug, Clone, PartialEq)]
enum Storage {
    /// ASCII text, with each facet's byte range (from `facet` to the end of `endfacet`).
    Ascii { text: String, facets: Vec<Range<usize>> },
    /// Binary bytes.
    Binary { bytes: Vec<u8> },
}

/// One `solid … endsolid` of an ASCII file (a binary file has one, named by its header).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Solid {
    /// The name after `solid`.
    pub name: String,
    /// Its triangles, as a range of [`Stl::triangles`].
    pub triangles: Range<usize>,
}

/// An STL file.
///
/// # Examples
///
/// ```
/// use cadmorph_mesh::format::stl::Stl;
/// let text = "solid t\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n   vertex 0 1 0\n  endloop\n endfacet\nendsolid t\n";
/// let mut s = Stl::parse(text.as_bytes())?;
/// assert_eq!(s.write(), text.as_bytes());
/// s.points[2].z = 1.0;
/// let back = Stl::parse(&s.write())?;
/// assert_eq!(back.points[2].z, 1.0);
/// # Ok::<(), cadmorph_mesh::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Stl {
    /// The merged vertices.
    pub points: Vec<Point3<f64>>,
    /// Triangles as indices into `points`.
    pub triangles: Vec<[usize; 3]>,
    /// The solids.
    pub solids: Vec<Solid>,
    original: Vec<Point3<f64>>,
    storage: Storage,
}

struct Merge {
    map: HashMap<[u64; 3], usize>,
    points: Vec<Point3<f64>>,
}

impl Merge {
    fn add(&mut self, p: Point3<f64>) -> usize {
        let key = [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
        let n = self.points.len();
        *self.map.entry(key).or_insert_with(|| {
            self.points.push(p);
            n
        })
    }
}

/// The unit normal of a triangle as VTK computes it (`vtkTriangle::ComputeNormal`:
/// `(v3 − v2) × (v1 − v2)`, left unnormalised when zero).
fn normal(a: &Point3<f64>, b: &Point3<f64>, c: &Point3<f64>) -> Vector3<f64> {
    let (ax, ay, az) = (c.x - b.x, c.y - b.y, c.z - b.z);
    let (bx, by, bz) = (a.x - b.x, a.y - b.y, a.z - b.z);
    let n = Vector3::new(ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx);
    let l = n.norm();
    if l != 0.0 {
        n / l
    } else {
        n
    }
}

impl Stl {
    /// Read an STL file, ASCII or binary (binary when the size is `84 + 50·n` for the
    /// count `n` in bytes 80–83, or the file does not start with `solid`).
    ///
    /// # Errors
    ///
    /// [`Error::Binary`] for a truncated binary file; [`Error::Syntax`] naming the line of
    /// a malformed ASCII record; [`Error::NonFinite`] for NaN vertices.
    pub fn parse(bytes: &[u8]) -> Result<Stl> {
        let binary_size = bytes.len() >= 84 && {
            let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
            bytes.len() == 84 + 50 * n
        };
        let starts_solid = bytes.len() >= 5 && bytes[..5].eq_ignore_ascii_case(b"solid");
        if binary_size || !starts_solid {
            Stl::parse_binary(bytes)
        } else {
            let text = std::str::from_utf8(bytes)
                .map_err(|e| Error::Binary { offset: e.valid_up_to(), what: "ASCII STL that is not UTF-8".into() })?;
            Stl::parse_ascii(text)
        }
    }

    fn parse_binary(bytes: &[u8]) -> Result<Stl> {
        if bytes.len() < 84 {
            return Err(Error::Binary { offset: bytes.len(), what: "a binary STL header of 84 bytes".into() });
        }
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
        if bytes.len() != 84 + 50 * n {
            return Err(Error::Binary {
                offset: bytes.len().min(84 + 50 * n),
                what: format!(
                    "{n} triangles of 50 bytes after the header ({} bytes), but the file has {}",
                    84 + 50 * n,
                    bytes.len()
                ),
            });
        }
        let mut m = Merge { map: HashMap::new(), points: Vec::new() };
        let mut triangles = Vec::with_capacity(n);
        for t in 0..n {
            let r = &bytes[84 + 50 * t..84 + 50 * (t + 1)];
            let f = |k: usize| f32::from_le_bytes([r[4 * k], r[4 * k + 1], r[4 * k + 2], r[4 * k + 3]]) as f64;
            let mut tri = [0; 3];
            for (v, slot) in tri.iter_mut().enumerate() {
                let p = Point3::new(f(3 + 3 * v), f(4 + 3 * v), f(5 + 3 * v));
                if let Some(bad) = p.iter().find(|x| !x.is_finite()) {
                    return Err(Error::Binary {
                        offset: 84 + 50 * t + 12 * (v + 1),
                        what: format!("triangle {t}: vertex coordinate {bad} is not finite"),
                    });
                }
                *slot = m.add(p);
            }
            triangles.push(tri);
        }
        let name = String::from_utf8_lossy(&bytes[..80]).trim_end_matches(['\0', ' ']).to_string();
        Ok(Stl {
            original: m.points.clone(),
            points: m.points,
            solids: vec![Solid { name, triangles: 0..n }],
            triangles,
            storage: Storage::Binary { bytes: bytes.to_vec() },
        })
    }

    fn parse_ascii(text: &str) -> Result<Stl> {
        let mut m = Merge { map: HashMap::new(), points: Vec::new() };
        let mut triangles = Vec::new();
        let mut solids = Vec::new();
        let mut facets = Vec::new();
        let mut solid: Option<(String, usize)> = None;
        let mut facet: Option<(usize, usize, Vec<usize>)> = None; // (start byte, line, vertices)
        let ranges = line_ranges(text);
        for (n, r) in ranges.iter().enumerate() {
            let line = trim_eol(&text[r.clone()]);
            let mut tok = line.split_whitespace();
            let Some(kw) = tok.next() else { continue };
            let lno = n + 1;
            match kw {
                "solid" if solid.is_none() => {
                    solid = Some((line.trim_start()[5..].trim().to_string(), triangles.len()))
                }
                "endsolid" => {
                    let Some((name, first)) = solid.take() else {
                        return Err(Error::syntax(lno, "`solid` before `endsolid`", line));
                    };
                    solids.push(Solid { name, triangles: first..triangles.len() });
                }
                "facet" if solid.is_some() && facet.is_none() => {
                    let start = r.start + (line.len() - line.trim_start().len());
                    facet = Some((start, lno, Vec::new()));
                }
                "outer" | "endloop" if facet.is_some() => {}
                "vertex" => {
                    let Some(f) = facet.as_mut() else {
                        return Err(Error::syntax(lno, "`vertex` inside a facet", line));
                    };
                    let c: Vec<&str> = tok.collect();
                    if c.len() != 3 {
                        return Err(Error::syntax(lno, "`vertex x y z`", line));
                    }
                    let p = Point3::new(parse_f64(c[0], lno)?, parse_f64(c[1], lno)?, parse_f64(c[2], lno)?);
                    check_finite(&[p]).map_err(|_| Error::syntax(lno, "finite coordinates", line))?;
                    f.2.push(m.add(p));
                }
                "endfacet" => {
                    let Some((start, fl, v)) = facet.take() else {
                        return Err(Error::syntax(lno, "`facet` before `endfacet`", line));
                    };
                    if v.len() != 3 {
                        return Err(Error::syntax(fl, "a facet with three vertices", &format!("{} vertices", v.len())));
                    }
                    triangles.push([v[0], v[1], v[2]]);
                    facets.push(start..r.start + line.len());
                }
                _ => {
                    return Err(Error::syntax(
                        lno,
                        "an STL keyword (solid, facet, outer loop, vertex, endloop, endfacet, endsolid)",
                        line,
                    ))
                }
            }
        }
        if let Some((_, fl, _)) = facet {
            return Err(Error::syntax(fl, "`endfacet` closing this facet", "end of file"));
        }
        if let Some((name, first)) = solid {
            // A missing `endsolid` is common; accept it.
            solids.push(Solid { name, triangles: first..triangles.len() });
        }
        Ok(Stl {
            original: m.points.clone(),
            points: m.points,
            triangles,
            solids,
            storage: Storage::Ascii { text: text.to_string(), facets },
        })
    }

    /// Number of (merged) points read.
    pub(crate) fn n_points_read(&self) -> usize {
        self.original.len()
    }

    fn moved(&self) -> Vec<bool> {
        let mv: Vec<bool> = self
            .points
            .iter()
            .zip(&self.original)
            .map(|(a, b)| a.iter().zip(b.iter()).any(|(x, y)| x.to_bits() != y.to_bits()))
            .collect();
        self.triangles.iter().map(|t| t.iter().any(|&v| mv.get(v).copied().unwrap_or(false))).collect()
    }

    /// The file in its own format: unchanged facets as read, facets with a moved vertex
    /// written anew (ASCII: shortest round-trip numbers; binary: `f32`), with recomputed
    /// normals.
    pub fn write(&self) -> Vec<u8> {
        let moved = self.moved();
        match &self.storage {
            Storage::Ascii { text, facets } => {
                let mut out = String::with_capacity(text.len());
                let mut at = 0;
                for (t, r) in facets.iter().enumerate() {
                    if moved[t] {
                        out.push_str(&text[at..r.start]);
                        let [a, b, c] = self.triangles[t].map(|i| self.points[i]);
                        let n = normal(&a, &b, &c);
                        let indent: String = text[..r.start].rsplit('\n').next().unwrap_or("").to_string();
                        out.push_str(&format!(
                            "facet normal {} {} {}\n{indent}  outer loop\n",
                            py_str(n.x),
                            py_str(n.y),
                            py_str(n.z)
                        ));
                        for p in [a, b, c] {
                            out.push_str(&format!(
                                "{indent}    vertex {} {} {}\n",
                                py_str(p.x),
                                py_str(p.y),
                                py_str(p.z)
                            ));
                        }
                        out.push_str(&format!("{indent}  endloop\n{indent}endfacet"));
                        at = r.end;
                    }
                }
                out.push_str(&text[at..]);
                out.into_bytes()
            }
            Storage::Binary { bytes } => {
                let mut out = bytes.clone();
                for (t, &mv) in moved.iter().enumerate() {
                    if mv {
                        let [a, b, c] = self.triangles[t].map(|i| self.points[i]);
                        let n = normal(&a, &b, &c);
                        let at = 84 + 50 * t;
                        let vals = [n.x, n.y, n.z, a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z];
                        for (k, v) in vals.iter().enumerate() {
                            out[at + 4 * k..at + 4 * k + 4].copy_from_slice(&(*v as f32).to_le_bytes());
                        }
                    }
                }
                out
            }
        }
    }

    /// The ASCII file VTK's `vtkSTLWriter` writes (what PyGeM's `StlHandler.write`
    /// gives): `solid ascii`, every facet with `%.6g` numbers of the `f32` points VTK
    /// stores, the normal recomputed, `endsolid`.
    pub fn write_ascii_vtk(&self) -> String {
        let mut s = String::from("solid ascii\n");
        let g = |x: f64| c_g(x as f32 as f64, 6);
        for t in &self.triangles {
            let [a, b, c] = t.map(|i| self.points[i].map(|x| x as f32 as f64));
            let n = normal(&a, &b, &c);
            s += &format!(" facet normal {} {} {}\n  outer loop\n", c_g(n.x, 6), c_g(n.y, 6), c_g(n.z, 6));
            for p in [a, b, c] {
                s += &format!("   vertex {} {} {}\n", g(p.x), g(p.y), g(p.z));
            }
            s += "  endloop\n endfacet\n";
        }
        s += "endsolid\n";
        s
    }

    /// A new ASCII STL of `triangles` (indices into `points`) with one `solid` per entry
    /// of `solids` (each naming a range of `triangles`, in order).
    ///
    /// # Errors
    ///
    /// [`Error::OutOfRange`] for a triangle corner that is not a point;
    /// [`Error::Topology`] when the solids do not cover the triangles in order.
    pub fn from_triangles(points: Vec<Point3<f64>>, triangles: Vec<[usize; 3]>, solids: Vec<Solid>) -> Result<Stl> {
        check_finite(&points)?;
        for (i, t) in triangles.iter().enumerate() {
            if let Some(&v) = t.iter().find(|&&v| v >= points.len()) {
                return Err(Error::OutOfRange {
                    what: "triangle",
                    index: i,
                    target_kind: "point",
                    target: v as i64,
                    count: points.len(),
                });
            }
        }
        let mut next = 0;
        for s in &solids {
            if s.triangles.start != next {
                return Err(Error::Topology(format!(
                    "solid {:?} starts at triangle {}, expected {next}",
                    s.name, s.triangles.start
                )));
            }
            next = s.triangles.end;
        }
        if next != triangles.len() {
            return Err(Error::Topology(format!("the solids cover {next} of {} triangles", triangles.len())));
        }
        let mut stl = Stl {
            original: points.clone(),
            points,
            triangles,
            solids,
            storage: Storage::Ascii { text: String::new(), facets: Vec::new() },
        };
        let text = stl.write_ascii();
        let facets = Stl::parse_ascii(&text)?.storage;
        stl.storage = facets;
        Ok(stl)
    }

    /// An ASCII STL of the current triangles, one `solid … endsolid` per solid, shortest
    /// round-trip numbers, normals recomputed.
    pub fn write_ascii(&self) -> String {
        let mut s = String::new();
        for solid in &self.solids {
            s += &format!("solid {}\n", solid.name);
            for t in &self.triangles[solid.triangles.clone()] {
                let [a, b, c] = t.map(|i| self.points[i]);
                let n = normal(&a, &b, &c);
                s += &format!("  facet normal {} {} {}\n    outer loop\n", py_str(n.x), py_str(n.y), py_str(n.z));
                for p in [a, b, c] {
                    s += &format!("      vertex {} {} {}\n", py_str(p.x), py_str(p.y), py_str(p.z));
                }
                s += "    endloop\n  endfacet\n";
            }
            s += &format!("endsolid {}\n", solid.name);
        }
        s
    }

    /// A binary STL of the current triangles (80-byte header from the first solid's name).
    pub fn write_binary(&self) -> Vec<u8> {
        let mut out = vec![0u8; 80];
        let name = self.solids.first().map(|s| s.name.as_bytes()).unwrap_or(b"");
        let k = name.len().min(80);
        out[..k].copy_from_slice(&name[..k]);
        out.extend_from_slice(&(self.triangles.len() as u32).to_le_bytes());
        for t in &self.triangles {
            let [a, b, c] = t.map(|i| self.points[i]);
            let n = normal(&a, &b, &c);
            for v in [n.x, n.y, n.z, a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z] {
                out.extend_from_slice(&(v as f32).to_le_bytes());
            }
            out.extend_from_slice(&[0, 0]);
        }
        out
    }
}
