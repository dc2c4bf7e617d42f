//! VTK XML files (`.vtu` unstructured grids, `.vtp` polydata; VTK User's Guide, "VTK File
//! Formats", XML formats): `<VTKFile type byte_order header_type compressor>`, one
//! `<Piece>` with `<Points>`, `<Cells>` (`connectivity`, `offsets`, `types`) or
//! `<Verts>/<Lines>/<Polys>`, and `<PointData>`/`<CellData>` arrays. Each `<DataArray>` is
//! `ascii`, inline `binary` (base64) or `appended` (raw or base64, after `<AppendedData>`),
//! each binary block led by its byte count (`UInt32` or `UInt64`), optionally
//! zlib-compressed in blocks (`vtkZLibDataCompressor`: a header of block count, block
//! size, last block size and compressed sizes). Little-endian only.
//!
//! Lossless: an unchanged file is written back as read; after a morph only the points
//! array is encoded anew, in its own format, and the offsets of later appended arrays are
//! shifted when its size changed. Every other array, attribute and byte is kept.

use std::io::{Read, Write};
use std::ops::Range;

use base64::Engine as _;
use nalgebra::Point3;

use crate::cell::{Cell, CellKind};
use crate::text::{check_finite, py_str};
use crate::{Error, Result};

const B64: base64::engine::GeneralPurpose = base64::engine::general_purpose::STANDARD;

/// How a data array is stored.
#[derive(Debug, Clone, PartialEq)]
enum Storage {
    /// Text between the tags.
    Ascii(Range<usize>),
    /// Base64 text between the tags.
    Inline(Range<usize>),
    /// In the appended section at `offset`; `attr` is the byte range of the offset
    /// attribute's value in the file.
    Appended { offset: usize, attr: Range<usize> },
}

#[derive(Debug, Clone, PartialEq)]
struct Array {
    section: String,
    name: String,
    ty: String,
    storage: Storage,
}

/// A VTK XML file.
#[derive(Debug, Clone, PartialEq)]
pub struct Vtu {
    /// The points.
    pub points: Vec<Point3<f64>>,
    /// The cells (`<Cells>` of an unstructured grid with linear kinds; `<Verts>`,
    /// `<Lines>`, `<Polys>` of polydata).
    pub cells: Vec<Cell>,
    /// `VTKFile type` (`UnstructuredGrid`, `PolyData`).
    pub kind: String,
    bytes: Vec<u8>,
    arrays: Vec<Array>,
    points_array: usize,
    header64: bool,
    compressed: bool,
    /// Start of the appended data (after `_`), and whether it is base64.
    appended: Option<(usize, bool)>,
    original: Vec<Point3<f64>>,
}

fn attr<'a>(tag: &'a str, key: &str) -> Option<(&'a str, Range<usize>)> {
    let pat = format!("{key}=");
    let mut from = 0;
    while let Some(i) = tag[from..].find(&pat) {
        let at = from + i;
        let q = tag.as_bytes().get(at + pat.len()).copied();
        if (at == 0 || tag.as_bytes()[at - 1].is_ascii_whitespace()) && matches!(q, Some(b'"') | Some(b'\'')) {
            let s = at + pat.len() + 1;
            let e = s + tag[s..].find(q? as char)?;
            return Some((&tag[s..e], s..e));
        }
        from = at + pat.len();
    }
    None
}

fn type_size(ty: &str) -> Option<usize> {
    Some(match ty {
        "Int8" | "UInt8" => 1,
        "Int16" | "UInt16" => 2,
        "Int32" | "UInt32" | "Float32" => 4,
        "Int64" | "UInt64" | "Float64" => 8,
        _ => return None,
    })
}

fn decode_values(raw: &[u8], ty: &str) -> Result<Vec<f64>> {
    let w = type_size(ty).ok_or_else(|| Error::Unsupported(format!("DataArray type {ty}")))?;
    Ok(raw
        .chunks_exact(w)
        .map(|c| match ty {
            "Int8" => c[0] as i8 as f64,
            "UInt8" => c[0] as f64,
            "Int16" => i16::from_le_bytes([c[0], c[1]]) as f64,
            "UInt16" => u16::from_le_bytes([c[0], c[1]]) as f64,
            "Int32" => i32::from_le_bytes([c[0], c[1], c[2], c[3]]) as f64,
            "UInt32" => u32::from_le_bytes([c[0], c[1], c[2], c[3]]) as f64,
            "Float32" => f32::from_le_bytes([c[0], c[1], c[2], c[3]]) as f64,
            "Int64" => i64::from_le_bytes(c.try_into().unwrap_or([0; 8])) as f64,
            "UInt64" => u64::from_le_bytes(c.try_into().unwrap_or([0; 8])) as f64,
            _ => f64::from_le_bytes(c.try_into().unwrap_or([0; 8])),
        })
        .collect())
}

impl Vtu {
    /// Number of points read.
    pub(crate) fn n_points_read(&self) -> usize {
        self.original.len()
    }

    fn header_len(&self) -> usize {
        if self.header64 {
            8
        } else {
            4
        }
    }

    fn read_uint(&self, b: &[u8], at: usize) -> Option<usize> {
        let h = self.header_len();
        let s = b.get(at..at + h)?;
        Some(if h == 8 {
            u64::from_le_bytes(s.try_into().ok()?) as usize
        } else {
            u32::from_le_bytes(s.try_into().ok()?) as usize
        })
    }

    /// Decode a binary block (`bin` holds the block and possibly more): the raw bytes and
    /// the number of bytes of `bin` it took.
    fn decode_block(&self, bin: &[u8], at: usize) -> Result<(Vec<u8>, usize)> {
        let bad = |what: String| Error::Binary { offset: at, what };
        let h = self.header_len();
        if !self.compressed {
            let n = self.read_uint(bin, 0).ok_or_else(|| bad("a block byte count".into()))?;
            // A count near 2^64 (appended raw data, header UInt64) must not wrap `h + n`.
            let data = h
                .checked_add(n)
                .and_then(|end| bin.get(h..end))
                .ok_or_else(|| bad(format!("{n} bytes of data, but the block is shorter")))?;
            return Ok((data.to_vec(), h + n));
        }
        let nb = self.read_uint(bin, 0).ok_or_else(|| bad("a compression header".into()))?;
        if nb > bin.len() {
            return Err(bad(format!("{nb} compressed blocks")));
        }
        let hl = (3 + nb) * h;
        let sizes: Vec<usize> = (0..3 + nb)
            .map(|k| self.read_uint(bin, k * h))
            .collect::<Option<_>>()
            .ok_or_else(|| bad("a compression header".into()))?;
        let mut out = Vec::new();
        let mut p = hl;
        for k in 0..nb {
            let cs = sizes[3 + k];
            let chunk = p
                .checked_add(cs)
                .and_then(|end| bin.get(p..end))
                .ok_or_else(|| bad(format!("compressed block {k} of {cs} bytes")))?;
            flate2::read::ZlibDecoder::new(chunk).read_to_end(&mut out).map_err(|e| bad(format!("zlib: {e}")))?;
            p += cs;
        }
        Ok((out, p))
    }

    fn decode_base64_block(&self, text: &[u8], at: usize) -> Result<(Vec<u8>, usize)> {
        let bad = |what: String| Error::Binary { offset: at, what };
        let dec = |t: &[u8]| B64.decode(t).map_err(|e| bad(format!("base64: {e}")));
        let h = self.header_len();
        let chars = |n: usize| n.div_ceil(3) * 4;
        let take = |n: usize| text.get(..n).ok_or_else(|| bad("base64 data ends early".into()));
        if !self.compressed {
            let first = dec(take(chars(h).max(8))?)?;
            let n = self.read_uint(&first, 0).ok_or_else(|| bad("a block byte count".into()))?;
            // Base64 holds three bytes in four characters: a count beyond the text is false.
            if n > text.len() {
                return Err(bad(format!("a block of {n} bytes in {} characters of base64", text.len())));
            }
            let all = dec(take(chars(h + n))?)?;
            let block = all.get(h..h + n).ok_or_else(|| bad(format!("a block of {n} bytes")))?;
            return Ok((block.to_vec(), chars(h + n)));
        }
        let first = dec(take(chars(3 * h))?)?;
        let nb = self.read_uint(&first, 0).ok_or_else(|| bad("a compression header".into()))?;
        if nb > text.len() {
            return Err(bad(format!("{nb} compressed blocks")));
        }
        let hc = chars((3 + nb) * h);
        let header = dec(take(hc)?)?;
        let total = (0..nb)
            .map(|k| self.read_uint(&header, (3 + k) * h).unwrap_or(0))
            .try_fold(0usize, |a, b| a.checked_add(b).filter(|&t| t <= text.len()))
            .ok_or_else(|| bad(format!("compressed blocks longer than the {} characters of base64", text.len())))?;
        let data = dec(text.get(hc..hc + chars(total)).ok_or_else(|| bad("base64 data ends early".into()))?)?;
        let mut joined = header.get(..(3 + nb) * h).ok_or_else(|| bad("a compression header".into()))?.to_vec();
        joined.extend_from_slice(&data);
        let (raw, _) = self.decode_block(&joined, at)?;
        Ok((raw, hc + chars(total)))
    }

    fn array_bytes(&self, a: &Array) -> Result<Vec<u8>> {
        match &a.storage {
            Storage::Ascii(r) => {
                let text = std::str::from_utf8(&self.bytes[r.clone()])
                    .map_err(|_| Error::Binary { offset: r.start, what: "ASCII data that is not UTF-8".into() })?;
                let w = type_size(&a.ty).ok_or_else(|| Error::Unsupported(format!("DataArray type {}", a.ty)))?;
                let mut out = Vec::new();
                for t in text.split_whitespace() {
                    let v: f64 = t.parse().map_err(|_| Error::Binary {
                        offset: r.start,
                        what: format!("ascii array {:?}: bad number {t:?}", a.name),
                    })?;
                    out.extend_from_slice(&encode_value(v, &a.ty)[..w]);
                }
                Ok(out)
            }
            Storage::Inline(r) => {
                let t: Vec<u8> = self.bytes[r.clone()].iter().copied().filter(|c| !c.is_ascii_whitespace()).collect();
                Ok(self.decode_base64_block(&t, r.start)?.0)
            }
            Storage::Appended { offset, .. } => {
                let Some((start, b64)) = self.appended else {
                    return Err(Error::Syntax {
                        line: 0,
                        expected: "an <AppendedData> section",
                        found: format!("array {:?} is appended", a.name),
                    });
                };
                let at = start + offset;
                let bin = self.bytes.get(at..).ok_or_else(|| Error::Binary {
                    offset: at,
                    what: format!("array {:?}: offset beyond the file", a.name),
                })?;
                if b64 {
                    Ok(self.decode_base64_block(bin, at)?.0)
                } else {
                    Ok(self.decode_block(bin, at)?.0)
                }
            }
        }
    }

    /// Read a VTK XML file.
    ///
    /// # Errors
    ///
    /// [`Error::Unsupported`] for big-endian files or other compressors;
    /// [`Error::Binary`] with the byte offset of a truncated or corrupt block;
    /// [`Error::Syntax`] for missing parts; [`Error::OutOfRange`] for a cell node that is
    /// not a point; [`Error::NonFinite`] for NaN points.
    pub fn parse(bytes: &[u8]) -> Result<Vtu> {
        let app = bytes.windows(13).position(|w| w == b"<AppendedData");
        let head_end = app.unwrap_or(bytes.len());
        let head = std::str::from_utf8(&bytes[..head_end])
            .map_err(|e| Error::Binary { offset: e.valid_up_to(), what: "XML that is not UTF-8".into() })?;
        let mut v = Vtu {
            points: Vec::new(),
            cells: Vec::new(),
            kind: String::new(),
            bytes: bytes.to_vec(),
            arrays: Vec::new(),
            points_array: usize::MAX,
            header64: false,
            compressed: false,
            appended: None,
            original: Vec::new(),
        };
        if let Some(a) = app {
            let rest = &bytes[a..];
            let gt = rest
                .iter()
                .position(|&c| c == b'>')
                .ok_or_else(|| Error::Binary { offset: a, what: "an <AppendedData> tag".into() })?;
            let tag = String::from_utf8_lossy(&rest[..gt]).into_owned();
            let us = rest[gt..]
                .iter()
                .position(|&c| c == b'_')
                .ok_or_else(|| Error::Binary { offset: a + gt, what: "the `_` that starts appended data".into() })?;
            let b64 = attr(&tag, "encoding").map(|x| x.0 == "base64").unwrap_or(false);
            v.appended = Some((a + gt + us + 1, b64));
        }
        let mut section = String::new();
        let mut pos = 0;
        let line_at = |at: usize| 1 + head.as_bytes()[..at].iter().filter(|&&c| c == b'\n').count();
        while let Some(i) = head[pos..].find('<') {
            let s = pos + i;
            let Some(e) = head[s..].find('>').map(|e| s + e) else {
                return Err(Error::syntax(line_at(s), "`>` closing the tag", &head[s..]));
            };
            let tag = &head[s + 1..e];
            pos = e + 1;
            if tag.starts_with('?') || tag.starts_with('!') {
                continue;
            }
            if let Some(name) = tag.strip_prefix('/') {
                if name.trim() == section {
                    section.clear();
                }
                continue;
            }
            let name = tag.split_whitespace().next().unwrap_or("").trim_end_matches('/');
            match name {
                "VTKFile" => {
                    v.kind = attr(tag, "type").map(|x| x.0.to_string()).unwrap_or_default();
                    if attr(tag, "byte_order").is_some_and(|x| x.0 == "BigEndian") {
                        return Err(Error::Unsupported("big-endian VTK XML".into()));
                    }
                    v.header64 = attr(tag, "header_type").is_some_and(|x| x.0 == "UInt64");
                    match attr(tag, "compressor").map(|x| x.0) {
                        None | Some("") => {}
                        Some("vtkZLibDataCompressor") => v.compressed = true,
                        Some(c) => return Err(Error::Unsupported(format!("VTK XML compressor {c}"))),
                    }
                }
                "Points" | "Cells" | "Verts" | "Lines" | "Strips" | "Polys" | "PointData" | "CellData"
                | "FieldData"
                    if !tag.ends_with('/') =>
                {
                    section = name.to_string()
                }
                "DataArray" => {
                    let ty = attr(tag, "type").map(|x| x.0.to_string()).unwrap_or_default();
                    let aname = attr(tag, "Name").map(|x| x.0.to_string()).unwrap_or_default();
                    let format = attr(tag, "format").map(|x| x.0).unwrap_or("ascii");
                    let storage = if format == "appended" {
                        let (o, r) = attr(tag, "offset")
                            .ok_or_else(|| Error::syntax(line_at(s), "an offset on an appended DataArray", tag))?;
                        let offset = o.trim().parse().map_err(|_| Error::syntax(line_at(s), "a numeric offset", o))?;
                        Storage::Appended { offset, attr: s + 1 + r.start..s + 1 + r.end }
                    } else {
                        let end = head[pos..]
                            .find("</DataArray>")
                            .map(|k| pos + k)
                            .ok_or_else(|| Error::syntax(line_at(s), "`</DataArray>`", tag))?;
                        let r = pos..end;
                        pos = end + "</DataArray>".len();
                        if format == "binary" {
                            Storage::Inline(r)
                        } else {
                            Storage::Ascii(r)
                        }
                    };
                    if section == "Points" && v.points_array == usize::MAX {
                        v.points_array = v.arrays.len();
                    }
                    v.arrays.push(Array { section: section.clone(), name: aname, ty, storage });
                }
                _ => {}
            }
        }
        if v.points_array == usize::MAX {
            return Err(Error::syntax(1, "a <Points> DataArray", "none"));
        }
        let pa = v.arrays[v.points_array].clone();
        let vals = decode_values(&v.array_bytes(&pa)?, &pa.ty)?;
        if vals.len() % 3 != 0 {
            return Err(Error::CountMismatch {
                what: "point coordinates (three per point)".into(),
                expected: vals.len() / 3 * 3 + 3,
                found: vals.len(),
            });
        }
        v.points = vals.chunks_exact(3).map(|c| Point3::new(c[0], c[1], c[2])).collect();
        check_finite(&v.points)?;
        v.original = v.points.clone();
        v.cells = v.read_cells()?;
        Ok(v)
    }

    fn ints(&self, section: &str, name: &str) -> Result<Option<Vec<i64>>> {
        match self.arrays.iter().find(|a| a.section == section && a.name == name) {
            None => Ok(None),
            Some(a) => Ok(Some(decode_values(&self.array_bytes(a)?, &a.ty)?.into_iter().map(|x| x as i64).collect())),
        }
    }

    fn read_cells(&self) -> Result<Vec<Cell>> {
        let np = self.points.len();
        let mut cells = Vec::new();
        for section in ["Cells", "Verts", "Lines", "Polys"] {
            let (Some(conn), Some(off)) = (self.ints(section, "connectivity")?, self.ints(section, "offsets")?) else {
                continue;
            };
            let types = if section == "Cells" { self.ints(section, "types")? } else { None };
            let mut start = 0usize;
            for (k, &o) in off.iter().enumerate() {
                if o < start as i64 || o as usize > conn.len() {
                    return Err(Error::Topology(format!(
                        "{section} offsets[{k}] = {o}: not increasing within the {} connectivity entries",
                        conn.len()
                    )));
                }
                let mut nodes = Vec::with_capacity(o as usize - start);
                for &c in &conn[start..o as usize] {
                    if c < 0 || c as usize >= np {
                        return Err(Error::OutOfRange {
                            what: "cell",
                            index: k,
                            target_kind: "point",
                            target: c,
                            count: np,
                        });
                    }
                    nodes.push(c as usize);
                }
                start = o as usize;
                let kind = match (section, &types) {
                    ("Cells", Some(t)) => t.get(k).copied().and_then(CellKind::from_vtk_id),
                    ("Verts", _) => Some(CellKind::Vertex),
                    ("Lines", _) if nodes.len() == 2 => Some(CellKind::Line),
                    ("Polys", _) => Some(match nodes.len() {
                        3 => CellKind::Triangle,
                        4 => CellKind::Quad,
                        _ => CellKind::Polygon,
                    }),
                    _ => None,
                };
                if let Some(kind) = kind {
                    if kind.n_nodes().is_none_or(|n| n == nodes.len()) {
                        cells.push(Cell::new(kind, nodes));
                    }
                }
            }
        }
        Ok(cells)
    }

    fn encode_block(&self, raw: &[u8]) -> Vec<u8> {
        let put = |out: &mut Vec<u8>, n: usize| {
            if self.header64 {
                out.extend_from_slice(&(n as u64).to_le_bytes());
            } else {
                out.extend_from_slice(&(n as u32).to_le_bytes());
            }
        };
        let mut out = Vec::new();
        if !self.compressed {
            put(&mut out, raw.len());
            out.extend_from_slice(raw);
            return out;
        }
        const BLOCK: usize = 32768;
        let blocks: Vec<&[u8]> = if raw.is_empty() { vec![] } else { raw.chunks(BLOCK).collect() };
        let comp: Vec<Vec<u8>> = blocks
            .iter()
            .map(|b| {
                let mut e = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
                let _ = e.write_all(b);
                e.finish().unwrap_or_default()
            })
            .collect();
        put(&mut out, blocks.len());
        put(&mut out, BLOCK);
        put(&mut out, blocks.last().map(|b| b.len()).unwrap_or(0));
        for c in &comp {
            put(&mut out, c.len());
        }
        for c in &comp {
            out.extend_from_slice(c);
        }
        out
    }

    fn encode_base64(&self, block: &[u8]) -> Vec<u8> {
        if !self.compressed {
            return B64.encode(block).into_bytes();
        }
        // VTK encodes the compression header and the data as two base64 strings.
        let h = self.header_len();
        let nb = self.read_uint(block, 0).unwrap_or(0);
        let hl = (3 + nb) * h;
        let mut s = B64.encode(&block[..hl]).into_bytes();
        s.extend_from_slice(B64.encode(&block[hl..]).as_bytes());
        s
    }

    /// The file: as read when no point moved; otherwise with the points array encoded anew
    /// in its own format (and later appended offsets shifted), everything else as read.
    pub fn write(&self) -> Vec<u8> {
        if self.points == self.original {
            return self.bytes.clone();
        }
        let pa = &self.arrays[self.points_array];
        let mut raw = Vec::with_capacity(self.points.len() * 24);
        for p in &self.points {
            for &x in p.iter() {
                raw.extend_from_slice(&encode_value(x, &pa.ty));
            }
        }
        match &pa.storage {
            Storage::Ascii(r) => {
                let mut text = String::from("\n");
                for p in &self.points {
                    text += &format!("          {} {} {}\n", py_str(p.x), py_str(p.y), py_str(p.z));
                }
                text += "        ";
                splice(&self.bytes, &[(r.clone(), text.into_bytes())])
            }
            Storage::Inline(r) => {
                let enc = self.encode_base64(&self.encode_block(&raw));
                let indent = b"\n          ".to_vec();
                let mut body = indent.clone();
                body.extend_from_slice(&enc);
                body.extend_from_slice(b"\n        ");
                splice(&self.bytes, &[(r.clone(), body)])
            }
            Storage::Appended { offset, .. } => {
                let Some((start, b64)) = self.appended else { return self.bytes.clone() };
                // Every appended array's encoded span, in file order.
                let mut spans: Vec<(usize, usize)> = Vec::new(); // (array index, encoded length)
                let mut order: Vec<usize> = (0..self.arrays.len())
                    .filter(|&i| matches!(self.arrays[i].storage, Storage::Appended { .. }))
                    .collect();
                order.sort_by_key(|&i| match self.arrays[i].storage {
                    Storage::Appended { offset, .. } => offset,
                    _ => 0,
                });
                for &i in &order {
                    let Storage::Appended { offset: o, .. } = self.arrays[i].storage else { continue };
                    let at = start + o;
                    let len = if b64 {
                        self.decode_base64_block(&self.bytes[at..], at).map(|x| x.1)
                    } else {
                        self.decode_block(&self.bytes[at..], at).map(|x| x.1)
                    };
                    spans.push((i, len.unwrap_or(0)));
                }
                let new_block = self.encode_block(&raw);
                let new_enc = if b64 { self.encode_base64(&new_block) } else { new_block };
                let mut data = Vec::new();
                let mut edits = Vec::new();
                for &(i, len) in &spans {
                    let Storage::Appended { offset: o, attr } = &self.arrays[i].storage else { continue };
                    let new_offset = data.len();
                    if new_offset != *o {
                        edits.push((attr.clone(), new_offset.to_string().into_bytes()));
                    }
                    if i == self.points_array {
                        data.extend_from_slice(&new_enc);
                    } else {
                        data.extend_from_slice(&self.bytes[start + o..start + o + len]);
                    }
                }
                let _ = offset;
                let data_end = spans.last().map(|&(i, len)| match &self.arrays[i].storage {
                    Storage::Appended { offset: o, .. } => start + o + len,
                    _ => start,
                });
                edits.push((start..data_end.unwrap_or(start), data));
                splice(&self.bytes, &edits)
            }
        }
    }

    /// A fresh `UnstructuredGrid` file of `points` and volume or surface `cells`, with
    /// raw appended binary arrays (Float64 points, Int64 connectivity and offsets, UInt8
    /// types), `header_type="UInt64"`, uncompressed.
    pub fn write_unstructured(points: &[Point3<f64>], cells: &[Cell]) -> Vec<u8> {
        let mut blocks: Vec<Vec<u8>> = Vec::new();
        let mut pts = Vec::with_capacity(points.len() * 24);
        for p in points {
            for &x in p.iter() {
                pts.extend_from_slice(&x.to_le_bytes());
            }
        }
        blocks.push(pts);
        let (mut conn, mut off, mut types) = (Vec::new(), Vec::new(), Vec::new());
        let mut n = 0i64;
        for c in cells {
            for &k in &c.nodes {
                conn.extend_from_slice(&(k as i64).to_le_bytes());
            }
            n += c.nodes.len() as i64;
            off.extend_from_slice(&n.to_le_bytes());
            types.push(c.kind.vtk_id());
        }
        blocks.extend([conn, off, types]);
        let mut offsets = Vec::new();
        let mut at = 0;
        for b in &blocks {
            offsets.push(at);
            at += 8 + b.len();
        }
        let mut s = String::new();
        s += "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n  <UnstructuredGrid>\n";
        s += &format!("    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n", points.len(), cells.len());
        s += &format!("      <Points>\n        <DataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\" format=\"appended\" offset=\"{}\"/>\n      </Points>\n", offsets[0]);
        s += "      <Cells>\n";
        s += &format!(
            "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"appended\" offset=\"{}\"/>\n",
            offsets[1]
        );
        s += &format!(
            "        <DataArray type=\"Int64\" Name=\"offsets\" format=\"appended\" offset=\"{}\"/>\n",
            offsets[2]
        );
        s += &format!(
            "        <DataArray type=\"UInt8\" Name=\"types\" format=\"appended\" offset=\"{}\"/>\n",
            offsets[3]
        );
        s += "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n  <AppendedData encoding=\"raw\">\n   _";
        let mut out = s.into_bytes();
        for b in &blocks {
            out.extend_from_slice(&(b.len() as u64).to_le_bytes());
            out.extend_from_slice(b);
        }
        out.extend_from_slice(b"\n  </AppendedData>\n</VTKFile>\n");
        out
    }
}

fn encode_value(x: f64, ty: &str) -> Vec<u8> {
    match ty {
        "Float32" => (x as f32).to_le_bytes().to_vec(),
        "Int8" => vec![x as i8 as u8],
        "UInt8" => vec![x as u8],
        "Int16" => (x as i16).to_le_bytes().to_vec(),
        "UInt16" => (x as u16).to_le_bytes().to_vec(),
        "Int32" => (x as i32).to_le_bytes().to_vec(),
        "UInt32" => (x as u32).to_le_bytes().to_vec(),
        "Int64" => (x as i64).to_le_bytes().to_vec(),
        "UInt64" => (x as u64).to_le_bytes().to_vec(),
        _ => x.to_le_bytes().to_vec(),
    }
}

/// `bytes` with the (disjoint) ranges replaced.
fn splice(bytes: &[u8], edits: &[(Range<usize>, Vec<u8>)]) -> Vec<u8> {
    let mut e: Vec<&(Range<usize>, Vec<u8>)> = edits.iter().collect();
    e.sort_by_key(|x| x.0.start);
    let mut out = Vec::with_capacity(bytes.len());
    let mut at = 0;
    for (r, b) in e {
        out.extend_from_slice(&bytes[at..r.start]);
        out.extend_from_slice(b);
        at = r.end;
    }
    out.extend_from_slice(&bytes[at..]);
    out
}
