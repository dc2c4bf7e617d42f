//! An OpenFOAM `points` file (`class vectorField`): `N ( (x y z) … )` in ASCII, or `N`
//! raw little-endian scalar triples in binary. Kept losslessly: writing an unchanged file
//! gives its bytes back; moved points are written in the file's own format.

use std::ops::Range;

use nalgebra::Point3;
use rayon::prelude::*;

use super::file::{read_header, Header, Lexer, Tok};
use crate::nodelines::NodeLines;
use crate::text::py_str;
use crate::{Error, Result};

/// The layout of the point data in the file.
#[derive(Debug, Clone, PartialEq)]
enum Layout {
    /// ASCII: each point's `( … )` entry, with its byte range.
    Ascii(NodeLines),
    /// Binary: the byte range of the raw scalars.
    Binary(Range<usize>),
}

/// The `(x y z)` records of an ASCII point list through the general lexer (the path that
/// names the line of a bad entry): each record's byte range and its point.
fn ascii_records(lx: &mut Lexer<'_>, n: usize) -> Result<Vec<(Range<usize>, Point3<f64>)>> {
    let mut records = Vec::with_capacity(n.min(lx.bytes.len() / 7));
    for _ in 0..n {
        lx.skip_ws();
        let start = lx.pos;
        lx.expect(b'(', "`(` opening a point")?;
        let mut c = [0.0; 3];
        for v in &mut c {
            lx.skip_ws();
            let save = lx.pos;
            match lx.next() {
                Some(Tok::Word(w)) => match w.parse::<f64>() {
                    Ok(x) => *v = x,
                    Err(_) => {
                        lx.pos = save;
                        return Err(lx.error("a coordinate"));
                    }
                },
                _ => {
                    lx.pos = save;
                    return Err(lx.error("a coordinate"));
                }
            }
        }
        lx.expect(b')', "`)` closing a point (three coordinates)")?;
        records.push((start..lx.pos, Point3::new(c[0], c[1], c[2])));
    }
    Ok(records)
}

/// The point in the `3 × w` bytes `c` of a binary list (`w` = 8, or 4 for `scalar=32`).
fn binary_point(c: &[u8], w: usize) -> Point3<f64> {
    let v = |k: usize| {
        let s = &c[k * w..(k + 1) * w];
        if w == 8 {
            f64::from_le_bytes(s.try_into().unwrap_or([0; 8]))
        } else {
            f32::from_le_bytes(s.try_into().unwrap_or([0; 4])) as f64
        }
    };
    Point3::new(v(0), v(1), v(2))
}

/// An OpenFOAM points file.
///
/// # Examples
///
/// ```
/// use cadmorph_mesh::format::foam::FoamPoints;
/// let text = "FoamFile { version 2.0; format ascii; class vectorField; object points; }\n2\n(\n(0 0 0)\n(1 0 0)\n)\n";
/// let mut f = FoamPoints::parse(text.as_bytes())?;
/// assert_eq!(f.write()?, text.as_bytes());
/// f.points[1].y = 0.5;
/// assert!(String::from_utf8(f.write()?).unwrap().contains("(1.0 0.5 0.0)"));
/// # Ok::<(), cadmorph_mesh::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct FoamPoints {
    /// The points.
    pub points: Vec<Point3<f64>>,
    /// The header.
    pub header: Header,
    bytes: Vec<u8>,
    layout: Layout,
}

impl FoamPoints {
    /// Read a (decompressed) points file.
    ///
    /// # Errors
    ///
    /// [`Error::Syntax`] with the line of a malformed entry or a wrong list size;
    /// [`Error::Binary`] for a truncated binary list; [`Error::NonFinite`] for NaN.
    pub fn parse(bytes: &[u8]) -> Result<FoamPoints> {
        FoamPoints::parse_owned(bytes.to_vec())
    }

    /// [`FoamPoints::parse`] of a file it may keep (no copy of the text).
    pub(crate) fn parse_owned(file: Vec<u8>) -> Result<FoamPoints> {
        let bytes = &file[..];
        let mut lx = Lexer::new(bytes);
        let header = read_header(&mut lx)?;
        let n = lx.count(bytes.len())?;
        lx.expect(b'(', "`(` opening the point list")?;
        let mut points = Vec::with_capacity(n);
        let layout = if header.binary {
            let w = header.scalar_bytes;
            let start = lx.pos;
            let len = n * 3 * w;
            if start + len > bytes.len() {
                return Err(Error::Binary {
                    offset: start,
                    what: format!("{n} points of 3×{w} bytes, but the file ends at byte {}", bytes.len()),
                });
            }
            points.extend(bytes[start..start + len].chunks_exact(3 * w).map(|c| binary_point(c, w)));
            lx.pos = start + len;
            Layout::Binary(start..start + len)
        } else {
            let records = match super::fast::points(bytes, lx.pos, n) {
                Some((records, close)) => {
                    lx.pos = close;
                    records
                }
                None => ascii_records(&mut lx, n)?,
            };
            records.par_iter().with_min_len(1 << 14).map(|r| r.1).collect_into_vec(&mut points);
            Layout::Ascii(NodeLines { text: String::new(), records })
        };
        lx.expect(b')', "`)` closing the point list (is the size right?)")?;
        crate::text::check_finite(&points)?;
        // The ASCII layout keeps the file as its text; the binary one as its bytes.
        let (bytes, layout) = match layout {
            Layout::Ascii(lines) => {
                let text = String::from_utf8(file).map_err(|e| Error::Binary {
                    offset: e.utf8_error().valid_up_to(),
                    what: "an ASCII points file that is not UTF-8".into(),
                })?;
                (Vec::new(), Layout::Ascii(NodeLines { text, ..lines }))
            }
            binary => (file, binary),
        };
        Ok(FoamPoints { points, header, bytes, layout })
    }

    /// Whether `points` equal (as numbers) the points as read: those of the file's
    /// records, so also when [`FoamPoints::points`] was taken or changed since.
    pub(crate) fn is_as_read(&self, points: &[Point3<f64>]) -> bool {
        match &self.layout {
            Layout::Ascii(l) => l.records.len() == points.len() && l.records.iter().zip(points).all(|(r, p)| r.1 == *p),
            Layout::Binary(r) => {
                let w = self.header.scalar_bytes;
                let read = self.bytes[r.clone()].chunks_exact(3 * w);
                read.len() == points.len() && read.zip(points).all(|(c, p)| binary_point(c, w) == *p)
            }
        }
    }

    /// The file with the current points: unchanged entries as read; moved ones as
    /// `(x y z)` with shortest round-trip numbers (ASCII) or in place (binary).
    ///
    /// # Errors
    ///
    /// [`Error::CountMismatch`] when points were added or removed.
    pub fn write(&self) -> Result<Vec<u8>> {
        self.write_impl(false)
    }

    /// What PyGeM's `OpenFoamHandler.write` writes for an ASCII file: every point entry
    /// formatted anew as `(x y z)` with Python `str` numbers.
    ///
    /// # Errors
    ///
    /// As [`FoamPoints::write`].
    pub fn write_pygem(&self) -> Result<Vec<u8>> {
        self.write_impl(true)
    }

    fn write_impl(&self, all: bool) -> Result<Vec<u8>> {
        let n = match &self.layout {
            Layout::Ascii(l) => l.records.len(),
            Layout::Binary(r) => r.len() / (3 * self.header.scalar_bytes),
        };
        if n != self.points.len() {
            return Err(Error::CountMismatch {
                what: "points (a morph keeps the count)".into(),
                expected: n,
                found: self.points.len(),
            });
        }
        Ok(match &self.layout {
            Layout::Ascii(lines) => lines
                .write(&self.points, all, |_, p, _| format!("({} {} {})", py_str(p.x), py_str(p.y), py_str(p.z)))
                .into_bytes(),
            Layout::Binary(r) => {
                let mut out = self.bytes.clone();
                let w = self.header.scalar_bytes;
                let mut at = r.start;
                for p in &self.points {
                    for &v in p.iter() {
                        if w == 8 {
                            out[at..at + 8].copy_from_slice(&v.to_le_bytes());
                        } else {
                            out[at..at + 4].copy_from_slice(&(v as f32).to_le_bytes());
                        }
                        at += w;
                    }
                }
                out
            }
        })
    }
}
