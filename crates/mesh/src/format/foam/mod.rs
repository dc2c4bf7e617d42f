//! OpenFOAM `polyMesh` directories (OpenFOAM User Guide §5.1 "Mesh description"): `points`,
//! `faces`, `owner`, `neighbour` and `boundary`, each ASCII or binary and optionally
//! gzip-compressed (`points.gz` …). Every other file of the directory (zones, sets,
//! `cellZones`, `meshModifiers`, anything unknown) is kept byte for byte, and so are the
//! topology files: a morph rewrites `points` only. The plain ASCII `faces`, `owner` and
//! `neighbour` lists, most of a mesh's bytes, are streamed (`stream.rs`) rather than held,
//! and copied from disk when the mesh is written.

mod fast;
mod file;
mod points;
mod stream;

pub use file::Header;
pub use points::FoamPoints;

use std::path::{Path, PathBuf};

use nalgebra::Point3;
use rayon::prelude::*;

use crate::error::io;
use crate::{Error, Result};
use stream::Kept;

/// A boundary patch (an entry of the `boundary` file).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Patch {
    /// Patch name.
    pub name: String,
    /// `type` (`patch`, `wall`, `empty`, `symmetryPlane`, `cyclic`…).
    pub kind: String,
    /// `startFace`.
    pub start_face: usize,
    /// `nFaces`.
    pub n_faces: usize,
}

/// A point or cell label as a mesh keeps it: 32 bits, OpenFOAM's default label size
/// (`WM_LABEL_SIZE=32`). Files written with 64-bit labels are read while their labels fit
/// (a mesh with 2³² points or cells would need hundreds of GB here); half the memory of
/// `usize` labels, and for a 10⁶-cell mesh about 100 MB fewer fresh pages to fault in.
pub type Label = u32;

/// A face list as CSR: offsets (one more than the faces) into the faces' point labels.
type FaceLists = (Vec<usize>, Vec<Label>);

/// An OpenFOAM polyhedral mesh: points, faces (as point lists, right-hand normal from
/// owner to neighbour), owner and neighbour cells of each face, boundary patches.
#[derive(Debug, Clone)]
pub struct PolyMesh {
    /// The points (the only part a morph changes).
    pub points: Vec<Point3<f64>>,
    face_offsets: Vec<usize>,
    face_points: Vec<Label>,
    owner: Vec<Label>,
    neighbour: Vec<Label>,
    n_cells: usize,
    patches: Vec<Patch>,
    source: Option<Source>,
}

/// The files a mesh was read from, kept for lossless writing (the streamed lists as where
/// they are on disk, see [`stream::Kept`]).
#[derive(Debug, Clone)]
struct Source {
    /// Every regular file of the directory: name and bytes as on disk.
    files: Vec<(String, Kept)>,
    /// The points file as read, and whether it was gzipped.
    points: PointsKept,
    points_gz: bool,
}

/// How the points file is kept.
#[derive(Debug, Clone)]
enum PointsKept {
    /// Parsed whole (binary, gzipped, or not in the streamed layout), with its records.
    Parsed(FoamPoints),
    /// Streamed: the file stays on disk (its entry in `files`), and is written by
    /// parsing it again and putting the current points in its records.
    OnDisk,
}

impl PolyMesh {
    /// Build a mesh from its parts, checking them as [`PolyMesh::read`] does.
    ///
    /// `faces` are point lists; internal faces come first (`neighbour.len()` of them),
    /// then the boundary faces of each patch in turn.
    ///
    /// # Errors
    ///
    /// As the checks of [`PolyMesh::read`].
    pub fn try_new(
        points: Vec<Point3<f64>>,
        faces: Vec<Vec<usize>>,
        owner: Vec<usize>,
        neighbour: Vec<usize>,
        patches: Vec<Patch>,
    ) -> Result<PolyMesh> {
        let mut face_offsets = Vec::with_capacity(faces.len() + 1);
        face_offsets.push(0);
        let mut face_points = Vec::with_capacity(faces.len() * 4);
        for (i, f) in faces.iter().enumerate() {
            for &p in f {
                face_points.push(label(p, "face", i, "point")?);
            }
            face_offsets.push(face_points.len());
        }
        let n_cells = owner.iter().chain(neighbour.iter()).map(|&c| c + 1).max().unwrap_or(0);
        let labels = |v: Vec<usize>, what| {
            v.into_iter().enumerate().map(|(i, c)| label(c, what, i, "cell")).collect::<Result<Vec<_>>>()
        };
        let (owner, neighbour) = (labels(owner, "owner entry of face")?, labels(neighbour, "neighbour entry of face")?);
        let m = PolyMesh { points, face_offsets, face_points, owner, neighbour, n_cells, patches, source: None };
        m.validate(false)?;
        Ok(m)
    }

    /// Read a `polyMesh` directory (`case/constant/polyMesh`; a case directory is also
    /// accepted).
    ///
    /// # Errors
    ///
    /// [`Error::Io`] for a missing file; any reader error, wrapped in
    /// [`Error::InFile`] with the file's path; topology errors: a face point or cell
    /// label out of range ([`Error::OutOfRange`], naming the face), list sizes that do
    /// not agree ([`Error::CountMismatch`]), patches that do not cover the boundary faces
    /// or a cell with fewer than four faces ([`Error::Topology`]).
    pub fn read(dir: &Path) -> Result<PolyMesh> {
        let dir =
            if dir.join("constant/polyMesh").is_dir() { dir.join("constant/polyMesh") } else { dir.to_path_buf() };
        // Every regular file of the directory is read once and kept as on disk for
        // lossless writing: first all of them in parallel (copies out of the page cache into
        // fresh pages, no parse), then the four lists, nearly all of a mesh, parsed in
        // parallel, each also cut into pieces that run in parallel (so no thread waits for
        // another's big file).
        let mut paths = Vec::new();
        for e in std::fs::read_dir(&dir).map_err(io(&dir))? {
            let e = e.map_err(io(&dir))?;
            let p = e.path();
            if p.is_file() {
                paths.push((e.file_name().to_string_lossy().into_owned(), p));
            }
        }
        paths.sort();
        // `name`, else `name.gz`: its index in `paths` and whether it is gzipped.
        let locate = |name: &str| -> Result<(usize, bool)> {
            let gz = format!("{name}.gz");
            for (want, is_gz) in [(name, false), (gz.as_str(), true)] {
                if let Some(k) = paths.iter().position(|(n, _)| n == want) {
                    return Ok((k, is_gz));
                }
            }
            Err(missing(&dir, name))
        };
        let (lp, lf, lo, ln) = (locate("points")?, locate("faces")?, locate("owner")?, locate("neighbour")?);
        let boundary = locate("boundary")?;
        // The faces, owner and neighbour lists are streamed and the points file read by its
        // parse task (below); the other files read here.
        let streamed = [lf.0, lo.0, ln.0];
        let files: Vec<(String, Vec<u8>)> = paths
            .par_iter()
            .enumerate()
            .with_max_len(1)
            .map(|(k, (n, p))| {
                let later = streamed.contains(&k) || k == lp.0;
                Ok((n.clone(), if later { Vec::new() } else { std::fs::read(p).map_err(io(p))? }))
            })
            .collect::<Result<_>>()?;
        let path = |l: (usize, bool)| paths[l.0].1.clone();
        let (pp, fp, op) = (path(lp), path(lf), path(lo));
        // A gzipped file's text (the file stays as on disk).
        let plain = |l: (usize, bool), bytes: &[u8]| -> Result<Option<Vec<u8>>> {
            Ok(if l.1 {
                Some(file::maybe_gunzip(bytes.to_vec(), true).map_err(|e| e.in_file(&paths[l.0].1))?)
            } else {
                None
            })
        };
        let (points, (faces, (owner, neighbour))) = rayon::join(
            // A plain ASCII points file is streamed and left on disk; any other is read
            // whole. A plain one read whole is kept by the points reader as its text (its
            // entry in `files` stays empty; `to_files` writes it); a gzipped one is kept as
            // on disk.
            || -> Result<(Kept, PointsKept, Vec<Point3<f64>>)> {
                if !lp.1 {
                    if let Some((_, pts, kept)) = stream::points(&pp)? {
                        return Ok((kept, PointsKept::OnDisk, pts));
                    }
                }
                let raw = std::fs::read(&pp).map_err(io(&pp))?;
                let (raw, mut parsed) = match plain(lp, &raw)? {
                    Some(text) => (raw, FoamPoints::parse_owned(text).map_err(|e| e.in_file(&pp))?),
                    None => (Vec::new(), FoamPoints::parse_owned(raw).map_err(|e| e.in_file(&pp))?),
                };
                // The mesh takes the points; the kept file compares against its records.
                let pts = std::mem::take(&mut parsed.points);
                Ok((Kept::Bytes(raw), PointsKept::Parsed(parsed), pts))
            },
            || {
                // Streamed when plain ASCII, else read whole (and kept) and parsed.
                let whole = |l: (usize, bool)| -> Result<(Vec<u8>, Option<Vec<u8>>)> {
                    let p = &paths[l.0].1;
                    let raw = std::fs::read(p).map_err(io(p))?;
                    let text = plain(l, &raw)?;
                    Ok((raw, text))
                };
                rayon::join(
                    || -> Result<(FaceLists, Kept)> {
                        if let Some((_, faces, kept)) = stream::faces(&fp)? {
                            return Ok((faces, kept));
                        }
                        let (raw, text) = whole(lf)?;
                        Ok((read_faces(text.as_deref().unwrap_or(&raw), &fp)?, Kept::Bytes(raw)))
                    },
                    || {
                        let cells =
                            |l: (usize, bool), what: &'static str| -> Result<((file::Header, Vec<Label>), Kept)> {
                                let p = &paths[l.0].1;
                                if let Some((h, v, kept)) = stream::labels(p)? {
                                    return Ok(((h, in_label_range(v, what, p)?), kept));
                                }
                                let (raw, text) = whole(l)?;
                                Ok((read_cells(text.as_deref().unwrap_or(&raw), what, p)?, Kept::Bytes(raw)))
                            };
                        rayon::join(|| cells(lo, "owner entry of face"), || cells(ln, "neighbour entry of face"))
                    },
                )
            },
        );
        let ((points_kept, points, mesh_points), (faces, faces_kept), (owner, owner_kept), (neighbour, neighbour_kept)) =
            (points?, faces?, owner?, neighbour?);

        let patches = match plain(boundary, &files[boundary.0].1)? {
            Some(text) => read_boundary(&text),
            None => read_boundary(&files[boundary.0].1),
        }
        .map_err(|e| e.in_file(&paths[boundary.0].1))?;
        let mut files: Vec<(String, Kept)> = files.into_iter().map(|(n, b)| (n, Kept::Bytes(b))).collect();
        for (k, kept) in [lp.0].into_iter().chain(streamed).zip([points_kept, faces_kept, owner_kept, neighbour_kept]) {
            files[k].1 = kept;
        }
        let points_gz = lp.1;
        let ((face_offsets, face_points), (oh, owner), (_, neighbour)) = (faces, owner, neighbour);
        let np_ = mesh_points.len();
        // A parallel scan for the largest label first; the search for the first bad one
        // only when there is one (so also below).
        let bad_point = face_points.par_iter().max().is_some_and(|&m| m as usize >= np_);
        if let Some(k) = if bad_point { first_where(&face_points, |v| v as usize >= np_) } else { None } {
            let face = face_offsets.partition_point(|&o| o <= k).saturating_sub(1);
            return Err(Error::OutOfRange {
                what: "face",
                index: face,
                target_kind: "point",
                target: face_points[k] as i64,
                count: np_,
            }
            .in_file(&fp));
        }
        let n_from_data = owner.par_iter().chain(neighbour.par_iter()).map(|&c| c as usize + 1).max().unwrap_or(0);
        // The owner note gives nCells; a label beyond it is out of range.
        let n_cells = note_value(&oh.note, "nCells").unwrap_or(n_from_data);
        if n_from_data > n_cells {
            let (i, c) = owner
                .iter()
                .enumerate()
                .chain(neighbour.iter().enumerate())
                .find(|(_, &c)| c as usize >= n_cells)
                .map(|(i, &c)| (i, c))
                .unwrap_or((0, 0));
            return Err(Error::OutOfRange {
                what: "face",
                index: i,
                target_kind: "cell",
                target: c as i64,
                count: n_cells,
            }
            .in_file(&op));
        }
        let m = PolyMesh {
            points: mesh_points,
            face_offsets,
            face_points,
            owner,
            neighbour,
            n_cells,
            patches,
            source: Some(Source { files, points, points_gz }),
        };
        m.validate(true).map_err(|e| e.in_file(&dir))?;
        Ok(m)
    }

    /// The checks of [`PolyMesh::try_new`] and [`PolyMesh::read`]; `read_checked` when
    /// the reader already checked the face point labels against the point count and the
    /// coordinates for NaN and infinity (so they are not scanned twice).
    fn validate(&self, read_checked: bool) -> Result<()> {
        let nf = self.n_faces();
        if nf > Label::MAX as usize {
            return Err(Error::Topology(format!("{nf} faces: more than a 32-bit label can number ({})", Label::MAX)));
        }
        if self.owner.len() != nf {
            return Err(Error::CountMismatch {
                what: "owner entries (one per face)".into(),
                expected: nf,
                found: self.owner.len(),
            });
        }
        let ni = self.neighbour.len();
        if ni > nf {
            return Err(Error::CountMismatch {
                what: "neighbour entries (at most one per face)".into(),
                expected: nf,
                found: ni,
            });
        }
        // The face-by-face search for the first bad face runs only when a quick scan (of
        // the sizes, and of the largest point label) finds one.
        let short = self.face_offsets.par_windows(2).any(|w| w[1] < w[0].saturating_add(3));
        let beyond =
            !read_checked && self.face_points.par_iter().max().is_some_and(|&m| m as usize >= self.points.len());
        for (i, f) in (0..if short || beyond { nf } else { 0 }).map(|i| (i, self.face(i))) {
            if f.len() < 3 {
                return Err(Error::Topology(format!("face {i} has {} points; a face needs 3 or more", f.len())));
            }
            if let Some(&p) = f.iter().find(|&&p| p as usize >= self.points.len()) {
                return Err(Error::OutOfRange {
                    what: "face",
                    index: i,
                    target_kind: "point",
                    target: p as i64,
                    count: self.points.len(),
                });
            }
        }
        let (own, nei, nc) = (&self.owner[..ni.min(self.owner.len())], &self.neighbour[..], self.n_cells);
        let bad_cells =
            own.par_iter().zip(nei.par_iter()).any(|(&o, &n)| n as usize >= nc || o as usize >= nc || n == o);
        for i in 0..if bad_cells { ni } else { 0 } {
            if self.neighbour[i] as usize >= nc || self.owner[i] as usize >= nc {
                return Err(Error::OutOfRange {
                    what: "face",
                    index: i,
                    target_kind: "cell",
                    target: self.neighbour[i].max(self.owner[i]) as i64,
                    count: self.n_cells,
                });
            }
            if self.neighbour[i] == self.owner[i] {
                return Err(Error::Topology(format!("internal face {i} has cell {} on both sides", self.owner[i])));
            }
        }
        let mut next = ni;
        for p in &self.patches {
            if p.start_face != next {
                return Err(Error::Topology(format!(
                    "patch {:?} starts at face {}, but the previous boundary faces end at {next}",
                    p.name, p.start_face
                )));
            }
            next += p.n_faces;
        }
        if next != nf {
            return Err(Error::Topology(format!("the patches cover faces up to {next}, but there are {nf} faces ({ni} internal): dangling boundary faces")));
        }
        // Faces per cell: the owner and the neighbour list counted in parallel.
        let count = |cells: &[Label]| {
            let mut n = vec![0u32; self.n_cells];
            for &c in cells {
                n[c as usize] += 1;
            }
            n
        };
        let (by_owner, by_neighbour) = rayon::join(|| count(&self.owner), || count(&self.neighbour));
        let few = by_owner.par_iter().zip(&by_neighbour).any(|(a, b)| a + b < 4);
        let n_faces_of = by_owner.iter().zip(&by_neighbour).map(|(a, b)| a + b);
        if let Some((c, k)) = n_faces_of.enumerate().take(if few { usize::MAX } else { 0 }).find(|&(_, k)| k < 4) {
            return Err(Error::Topology(format!("cell {c} has {k} faces; a closed cell needs 4 or more")));
        }
        if read_checked {
            return Ok(());
        }
        crate::text::check_finite(&self.points)
    }

    /// Number of faces.
    pub fn n_faces(&self) -> usize {
        self.face_offsets.len().saturating_sub(1)
    }
    /// Number of internal faces (faces with a neighbour).
    pub fn n_internal_faces(&self) -> usize {
        self.neighbour.len()
    }
    /// Number of cells.
    pub fn n_cells(&self) -> usize {
        self.n_cells
    }
    /// The point labels of face `i`.
    #[inline]
    pub fn face(&self, i: usize) -> &[Label] {
        &self.face_points[self.face_offsets[i]..self.face_offsets[i + 1]]
    }
    /// Owner cell of each face.
    pub fn owner(&self) -> &[Label] {
        &self.owner
    }
    /// Neighbour cell of each internal face.
    pub fn neighbour(&self) -> &[Label] {
        &self.neighbour
    }
    /// The boundary patches.
    pub fn patches(&self) -> &[Patch] {
        &self.patches
    }

    /// The files of the written directory, relative names and bytes: the files as read,
    /// with `points` (or `points.gz`) rewritten in its own format when a point moved; a
    /// mesh made by [`PolyMesh::try_new`] gets fresh ASCII files.
    ///
    /// The plain ASCII `points`, `faces`, `owner` and `neighbour` files, streamed by
    /// [`PolyMesh::read`] and not held in memory, are read again from where they were
    /// read. One that is gone since, or now holds other lists, is written afresh from the
    /// mesh (same values, OpenFOAM's ASCII layout) instead.
    ///
    /// # Errors
    ///
    /// [`Error::CountMismatch`] when the point count changed; [`Error::Io`] when a file
    /// left on disk is there but cannot be read.
    pub fn to_files(&self) -> Result<Vec<(PathBuf, Vec<u8>)>> {
        let Some(src) = &self.source else {
            return Ok(self.fresh_files());
        };
        let name = if src.points_gz { "points.gz" } else { "points" };
        // A file written afresh from the mesh (one that is gone or changed on disk): all
        // of them are formatted once, on the first need.
        let all_fresh = std::cell::OnceCell::new();
        let fresh = |n: &str| -> Vec<u8> {
            let all = all_fresh.get_or_init(|| self.fresh_files());
            all.iter()
                .find(|(f, _): &&(PathBuf, Vec<u8>)| f.as_os_str() == n)
                .map(|(_, b)| b.clone())
                .unwrap_or_default()
        };
        // The points file with the current points (unchanged records as read), and whether
        // no point moved.
        let (bytes, unchanged) = match &src.points {
            PointsKept::Parsed(read) => {
                let mut p = read.clone();
                p.points.clone_from(&self.points);
                (p.write()?, read.is_as_read(&self.points))
            }
            PointsKept::OnDisk => {
                // The file now there serves as the template of the records (also when
                // a previous write of this mesh replaced it); a file that is gone, does
                // not read, or holds another number of points gives a fresh one.
                let kept = src.files.iter().find(|(n, _)| n == name).map(|(_, k)| k);
                let template = match kept {
                    Some(k) => k.bytes(|_| true)?.and_then(|b| FoamPoints::parse_owned(b).ok()),
                    None => None,
                };
                match template {
                    Some(mut p) if p.points.len() == self.points.len() => {
                        let unchanged = p.is_as_read(&self.points);
                        p.points.clone_from(&self.points);
                        (p.write()?, unchanged)
                    }
                    _ => (fresh(name), false),
                }
            }
        };
        let bytes = if src.points_gz { file::gzip(&bytes) } else { bytes };
        src.files
            .iter()
            .map(|(n, b)| {
                // The plain points file's entry is empty when its reader kept it, or the file
                // on disk when streamed: either way its lossless write is `bytes`. A gzipped
                // one is kept as read unless a point moved.
                Ok(if n == name && (!unchanged || !src.points_gz) {
                    (PathBuf::from(n), bytes.clone())
                } else {
                    let bytes = b.bytes(|bytes| self.holds_list_of(n, bytes))?;
                    (PathBuf::from(n), bytes.unwrap_or_else(|| fresh(n)))
                })
            })
            .collect()
    }

    /// Whether `bytes`, the file `name` of a polyMesh directory, hold this mesh's faces,
    /// owner or neighbour list.
    fn holds_list_of(&self, name: &str, bytes: &[u8]) -> bool {
        let cells = |v: &[Label]| file::label_list_fast(bytes).is_some_and(|(_, w)| w == v);
        match name {
            "faces" => {
                file::face_list_fast(bytes).is_some_and(|(_, o, p)| o == self.face_offsets && p == self.face_points)
            }
            "owner" => cells(&self.owner),
            "neighbour" => cells(&self.neighbour),
            _ => false,
        }
    }

    /// Write the mesh as the `polyMesh` directory `dir` (atomically: into a temporary
    /// sibling, then renamed).
    ///
    /// # Errors
    ///
    /// [`Error::Io`] naming the path; as [`PolyMesh::to_files`].
    pub fn write(&self, dir: &Path) -> Result<()> {
        crate::atomic::write_dir_atomic(dir, &self.to_files()?)
    }

    fn fresh_files(&self) -> Vec<(PathBuf, Vec<u8>)> {
        use std::fmt::Write;
        let head = |class: &str, object: &str, note: &str| {
            let note = if note.is_empty() { String::new() } else { format!("    note        \"{note}\";\n") };
            format!("FoamFile\n{{\n    version     2.0;\n    format      ascii;\n    class       {class};\n{note}    location    \"constant/polyMesh\";\n    object      {object};\n}}\n\n")
        };
        let note = format!(
            "nPoints:{} nCells:{} nFaces:{} nInternalFaces:{}",
            self.points.len(),
            self.n_cells,
            self.n_faces(),
            self.n_internal_faces()
        );
        let mut pts = head("vectorField", "points", "");
        let _ = writeln!(pts, "{}\n(", self.points.len());
        for p in &self.points {
            let _ = writeln!(pts, "({} {} {})", p.x, p.y, p.z);
        }
        pts.push_str(")\n");
        let mut faces = head("faceList", "faces", "");
        let _ = writeln!(faces, "{}\n(", self.n_faces());
        for i in 0..self.n_faces() {
            let f = self.face(i);
            let _ = write!(faces, "{}(", f.len());
            for (k, p) in f.iter().enumerate() {
                let _ = write!(faces, "{}{p}", if k > 0 { " " } else { "" });
            }
            faces.push_str(")\n");
        }
        faces.push_str(")\n");
        let labels = |object: &str, v: &[Label]| {
            let mut s = head("labelList", object, &note);
            let _ = writeln!(s, "{}\n(", v.len());
            for c in v {
                let _ = writeln!(s, "{c}");
            }
            s.push_str(")\n");
            s
        };
        let mut boundary = head("polyBoundaryMesh", "boundary", "");
        let _ = writeln!(boundary, "{}\n(", self.patches.len());
        for p in &self.patches {
            let _ = writeln!(boundary, "    {}\n    {{\n        type            {};\n        nFaces          {};\n        startFace       {};\n    }}", p.name, p.kind, p.n_faces, p.start_face);
        }
        boundary.push_str(")\n");
        vec![
            ("points".into(), pts.into_bytes()),
            ("faces".into(), faces.into_bytes()),
            ("owner".into(), labels("owner", &self.owner).into_bytes()),
            ("neighbour".into(), labels("neighbour", &self.neighbour).into_bytes()),
            ("boundary".into(), boundary.into_bytes()),
        ]
    }
}

/// `v` as a [`Label`], or the error naming the entry (`what` `index`) that holds it.
fn label(v: usize, what: &'static str, index: usize, target_kind: &'static str) -> Result<Label> {
    Label::try_from(v).map_err(|_| Error::OutOfRange {
        what,
        index,
        target_kind,
        target: v as i64,
        count: Label::MAX as usize,
    })
}

/// Cell labels read by a fast path (non-negative by construction), refused where one is
/// beyond 2³¹ − 1, as the general reader refuses it.
fn in_label_range(v: Vec<Label>, what: &'static str, path: &Path) -> Result<Vec<Label>> {
    match first_where(&v, |c| c > i32::MAX as Label) {
        Some(i) => Err(cell_out_of_range(what, i, v[i] as i64).in_file(path)),
        None => Ok(v),
    }
}

/// A cell label that no 32-bit OpenFOAM label holds (negative, or beyond 2³¹ − 1).
fn cell_out_of_range(what: &'static str, index: usize, target: i64) -> Error {
    Error::OutOfRange { what, index, target_kind: "cell", target, count: 0 }
}

/// `key:value` from an owner file's `note` (`"nPoints:882 nCells:400 …"`).
/// A required polyMesh file that is not there (nor gzipped).
fn missing(dir: &Path, name: &str) -> Error {
    Error::Io {
        path: dir.join(name),
        source: std::io::Error::new(std::io::ErrorKind::NotFound, "no such file (nor .gz)"),
    }
}

/// The first index of `v` where `bad` holds (a scan of the whole slice: a check that
/// expects no hit; rayon's item-wise `position_first` costs more than the scan).
fn first_where(v: &[Label], bad: impl Fn(Label) -> bool) -> Option<usize> {
    v.iter().position(|&x| bad(x))
}

/// The faces file: CSR offsets and point labels (not yet checked against the point
/// count), through the fast path when it can.
fn read_faces(bytes: &[u8], path: &Path) -> Result<FaceLists> {
    if let Some((_, offsets, points)) = file::face_list_fast(bytes) {
        return Ok((offsets, points));
    }
    let (_, offsets, flat) = file::face_list(bytes).map_err(|e| e.in_file(path))?;
    let mut points = Vec::with_capacity(flat.len());
    for (k, &v) in flat.iter().enumerate() {
        if v < 0 || v > Label::MAX as i64 {
            let face = offsets.partition_point(|&o| o <= k).saturating_sub(1);
            return Err(Error::OutOfRange { what: "face", index: face, target_kind: "point", target: v, count: 0 }
                .in_file(path));
        }
        points.push(v as Label);
    }
    Ok((offsets, points))
}

/// An owner or neighbour file: its header and cell labels (`what` names an entry in
/// errors), through the fast path when it can.
fn read_cells(bytes: &[u8], what: &'static str, path: &Path) -> Result<(file::Header, Vec<Label>)> {
    let out_of_range = |i: usize, c: i64| cell_out_of_range(what, i, c).in_file(path);
    if let Some((h, v)) = file::label_list_fast(bytes) {
        return Ok((h, in_label_range(v, what, path)?));
    }
    let (h, v) = file::label_list(bytes).map_err(|e| e.in_file(path))?;
    let cells = v
        .into_iter()
        .enumerate()
        .map(|(i, c)| if c < 0 || c > i32::MAX as i64 { Err(out_of_range(i, c)) } else { Ok(c as Label) })
        .collect::<Result<_>>()?;
    Ok((h, cells))
}

fn note_value(note: &str, key: &str) -> Option<usize> {
    note.split_whitespace().find_map(|kv| kv.strip_prefix(key)?.strip_prefix(':')?.parse().ok())
}

/// Read the `boundary` file: `N ( name { type t; nFaces n; startFace s; … } … )`.
fn read_boundary(bytes: &[u8]) -> Result<Vec<Patch>> {
    use file::Tok;
    let mut lx = file::Lexer::new(bytes);
    file::read_header(&mut lx)?;
    let n = lx.count(bytes.len())?;
    lx.expect(b'(', "`(` opening the patch list")?;
    let mut out = Vec::with_capacity(n);
    for _ in 0..n {
        let name = match lx.next() {
            Some(Tok::Word(w)) => w.to_string(),
            _ => return Err(lx.error("a patch name")),
        };
        lx.expect(b'{', "`{` opening the patch dictionary")?;
        let (mut kind, mut nf, mut sf) = (String::new(), None, None);
        let mut depth = 1;
        let mut key: Option<String> = None;
        let mut value: Vec<String> = Vec::new();
        while depth > 0 {
            match lx.next() {
                None => return Err(lx.error("`}` closing the patch dictionary")),
                Some(Tok::Punct(b'{')) => depth += 1,
                Some(Tok::Punct(b'}')) => {
                    depth -= 1;
                    if depth == 1 {
                        key = None;
                        value.clear();
                    }
                }
                Some(Tok::Punct(b';')) => {
                    if depth == 1 {
                        if let Some(k) = key.take() {
                            let v = value.join(" ");
                            match k.as_str() {
                                "type" => kind = v,
                                "nFaces" => nf = v.parse::<usize>().ok(),
                                "startFace" => sf = v.parse::<usize>().ok(),
                                _ => {}
                            }
                        }
                    }
                    value.clear();
                }
                Some(Tok::Punct(_)) => {}
                Some(Tok::Word(w)) => {
                    if depth == 1 {
                        if key.is_none() {
                            key = Some(w.to_string());
                        } else {
                            value.push(w.to_string());
                        }
                    }
                }
            }
        }
        let (Some(n_faces), Some(start_face)) = (nf, sf) else {
            return Err(lx.error("a patch with nFaces and startFace"));
        };
        out.push(Patch { name, kind, start_face, n_faces });
    }
    lx.expect(b')', "`)` closing the patch list (is the size right?)")?;
    Ok(out)
}
