//! Streamed reading of the large ASCII lists of a `polyMesh` (`points`, `faces`, `owner`,
//! `neighbour`): the file goes through one buffer of [`WINDOW`] bytes and is parsed as it
//! comes, so its text never takes fresh memory, and the mesh does not keep it (a lossless
//! write reads the file from disk again, see [`Kept`]). For a 10⁶-cell mesh these files
//! are 195 MB: held in memory, their fresh pages alone cost a sixth of the whole read +
//! quality check.
//!
//! Like [`super::fast`], it takes only the plain layout OpenFOAM writes and returns `None`
//! for anything else (binary, gzipped, a comment or a sign in the list, a record that
//! does not close, a count that does not match); the caller then reads the whole file
//! and parses it by the fast or general path, which gives the same values, or the error
//! with its line. So streaming changes memory and speed, never results. Written by hand:
//! no crate parses these lists.

use std::fs::File;
use std::io::{ErrorKind, Read};
use std::path::{Path, PathBuf};
use std::time::SystemTime;

use nalgebra::Point3;

use super::fast::{is_ws, starts_face, Scan};
use super::file::{read_header, Header, Lexer};
use super::{FaceLists, Label};
use crate::error::io;
use crate::Result;

/// The read buffer: large enough that syscalls do not matter, small enough to stay in
/// the cache. A record longer than this grows it (up to the file's size).
const WINDOW: usize = if cfg!(test) { 64 } else { 1 << 19 };

/// A file as the mesh keeps it for lossless writing: its bytes, or (for a streamed list)
/// where it is and what it looked like when read.
#[derive(Debug, Clone)]
pub(super) enum Kept {
    /// The bytes as on disk.
    Bytes(Vec<u8>),
    /// A file left on disk: written back by copying it, after checking that its size and
    /// modification time are those it had when read.
    OnDisk {
        /// Where it was read.
        path: PathBuf,
        /// Its size then.
        len: u64,
        /// Its modification time then (where the file system has one).
        modified: Option<SystemTime>,
    },
}

impl Kept {
    /// The bytes to write: as read, or the file on disk again. A file whose size or
    /// modification time changed since it was read (for example rewritten in place by
    /// a previous write of the same mesh) is taken only when `same` finds it holds the
    /// same lists; `None` when it does not, or is gone (the caller then writes the file
    /// afresh from the mesh).
    ///
    /// # Errors
    ///
    /// [`Error::Io`] when the file is there but cannot be read.
    pub(super) fn bytes(&self, same: impl Fn(&[u8]) -> bool) -> Result<Option<Vec<u8>>> {
        match self {
            Kept::Bytes(b) => Ok(Some(b.clone())),
            Kept::OnDisk { path, len, modified } => {
                let (meta, bytes) = match std::fs::metadata(path).and_then(|m| Ok((m, std::fs::read(path)?))) {
                    Ok(r) => r,
                    Err(e) if e.kind() == ErrorKind::NotFound => return Ok(None),
                    Err(e) => return Err(io(path)(e)),
                };
                let as_read = meta.len() == *len && meta.modified().ok() == *modified && bytes.len() as u64 == *len;
                Ok((as_read || same(&bytes)).then_some(bytes))
            }
        }
    }
}

/// A window over a file read from the start.
struct Window {
    file: File,
    path: PathBuf,
    buf: Vec<u8>,
    len: usize,
    eof: bool,
}

impl Window {
    /// Drop the bytes before `from`, then read until the buffer is full or the file ends;
    /// a buffer that was full before (one record longer than it) doubles.
    fn refill(&mut self, from: usize) -> Result<()> {
        self.buf.copy_within(from..self.len, 0);
        self.len -= from;
        if self.len == self.buf.len() {
            self.buf.resize(2 * self.buf.len(), 0);
        }
        while self.len < self.buf.len() && !self.eof {
            match self.file.read(&mut self.buf[self.len..]) {
                Ok(0) => self.eof = true,
                Ok(k) => self.len += k,
                Err(e) if e.kind() == ErrorKind::Interrupted => {}
                Err(e) => return Err(io(&self.path)(e)),
            }
        }
        Ok(())
    }
}

/// A plain ASCII list file opened and read up to its list: the window, the header, the
/// list size, the position after the list's `(`, and how the file is kept.
type Opened = (Window, Header, usize, usize, Kept);

/// Open `path` and read its header and list size; `None` when it is not a plain ASCII
/// list whose `N (` lies in the first window, or when the file is too short to hold `N`
/// records of at least `min_record` bytes (so that no buffer is sized from a count the
/// file cannot back; the whole-file reader then names the problem).
fn open(path: &Path, min_record: u64) -> Result<Option<Opened>> {
    let file = File::open(path).map_err(io(path))?;
    let meta = file.metadata().map_err(io(path))?;
    let kept = Kept::OnDisk { path: path.to_path_buf(), len: meta.len(), modified: meta.modified().ok() };
    let mut w = Window { file, path: path.to_path_buf(), buf: vec![0; WINDOW.max(1 << 12)], len: 0, eof: false };
    w.refill(0)?;
    let mut lx = Lexer::new(&w.buf[..w.len]);
    let Ok(h) = read_header(&mut lx) else { return Ok(None) };
    if h.binary {
        return Ok(None);
    }
    // A count followed by `(` was read whole.
    let max = usize::try_from(meta.len() / min_record + 1).unwrap_or(usize::MAX);
    let Ok(n) = lx.count(max) else { return Ok(None) };
    if lx.expect(b'(', "").is_err() {
        return Ok(None);
    }
    let pos = lx.pos;
    Ok(Some((w, h, n, pos, kept)))
}

/// The end of the part of `w.buf[pos..]` that can be parsed now: the whole window at the
/// end of the file, else the last offset where `cut_here` holds (`pos` when none does).
fn cut(w: &Window, pos: usize, cut_here: impl Fn(&[u8], usize) -> bool) -> usize {
    if w.eof {
        return w.len;
    }
    let b = &w.buf[..w.len];
    (pos + 1..w.len).rev().find(|&i| cut_here(b, i)).unwrap_or(pos)
}

/// Read the records of the list whose body starts at `pos` of the window, a part at a
/// time: each part ends where `cut_here` holds (so that no record is cut), and `record`
/// reads one record at the scan (after white space, before the list's `)`), `None` for
/// anything outside the plain layout. Whether the list's `)` was met, every record read.
fn each_record(
    w: &mut Window,
    mut pos: usize,
    cut_here: impl Fn(&[u8], usize) -> bool,
    mut record: impl FnMut(&mut Scan<'_>) -> Option<()>,
) -> Result<bool> {
    loop {
        let end = cut(w, pos, &cut_here);
        let mut s = Scan { b: &w.buf, pos, end };
        let closed = loop {
            s.ws();
            match s.peek() {
                None => break false,
                Some(b')') => break true,
                Some(_) => {}
            }
            if record(&mut s).is_none() {
                return Ok(false);
            }
        };
        if closed {
            return Ok(true);
        }
        if w.eof {
            return Ok(false);
        }
        pos = s.pos;
        w.refill(pos)?;
        pos = 0;
    }
}

/// A streamed `faceList` (`N ( k(a b …) … )`): its header, CSR offsets and point labels,
/// and how the file is kept; `Ok(None)` when it is not in the plain layout.
///
/// # Errors
///
/// [`Error::Io`] when the file cannot be read.
pub(super) fn faces(path: &Path) -> Result<Option<(Header, FaceLists, Kept)>> {
    // `3(0 1 2)`: eight bytes at least.
    let Some((mut w, h, n, pos, kept)) = open(path, 8)? else { return Ok(None) };
    if h.class == "faceCompactList" {
        return Ok(None);
    }
    let mut offsets = Vec::with_capacity(n + 1);
    offsets.push(0usize);
    // Quads mostly; `open` bounded `n` by the file's length.
    let mut labels: Vec<Label> = Vec::with_capacity(4 * n);
    // A record starts at the start of a line `k(` (see `super::fast`).
    let at_record = |b: &[u8], i: usize| b[i - 1] == b'\n' && starts_face(&b[i..]);
    let closed = each_record(&mut w, pos, at_record, |s| {
        if offsets.len() > n {
            return None;
        }
        let k = s.uint()?;
        s.ws();
        s.punct(b'(')?;
        for _ in 0..k {
            s.ws();
            labels.push(s.label()?);
        }
        s.ws();
        s.punct(b')')?;
        offsets.push(labels.len());
        Some(())
    })?;
    Ok((closed && offsets.len() == n + 1).then_some((h, (offsets, labels), kept)))
}

/// A streamed `labelList` (`N ( l l … )`): its header, the labels and how the file is
/// kept; `Ok(None)` when it is not in the plain layout.
///
/// # Errors
///
/// [`Error::Io`] when the file cannot be read.
pub(super) fn labels(path: &Path) -> Result<Option<(Header, Vec<Label>, Kept)>> {
    // A digit and a separator.
    let Some((mut w, h, n, pos, kept)) = open(path, 2)? else { return Ok(None) };
    let mut out: Vec<Label> = Vec::with_capacity(n);
    // A label ends before white space.
    let after_space = |b: &[u8], i: usize| is_ws(b[i - 1]);
    let closed = each_record(&mut w, pos, after_space, |s| {
        if out.len() == n {
            return None;
        }
        out.push(s.label()?);
        Some(())
    })?;
    Ok((closed && out.len() == n).then_some((h, out, kept)))
}

/// Points as read.
type Points = Vec<Point3<f64>>;

/// A streamed `vectorField` of points (`N ( (x y z) … )`): its header, the points and
/// how the file is kept; `Ok(None)` when it is not in the plain layout (one record per
/// line) or holds a coordinate that is not finite.
///
/// # Errors
///
/// [`Error::Io`] when the file cannot be read.
pub(super) fn points(path: &Path) -> Result<Option<(Header, Points, Kept)>> {
    // `(0 0 0)`: seven bytes at least.
    let Some((mut w, h, n, pos, kept)) = open(path, 7)? else { return Ok(None) };
    let mut out = Vec::with_capacity(n);
    // A record starts a line.
    let at_line = |b: &[u8], i: usize| b[i - 1] == b'\n';
    let closed = each_record(&mut w, pos, at_line, |s| {
        if out.len() == n {
            return None;
        }
        out.push(s.point().filter(|p| p.iter().all(|x| x.is_finite()))?);
        Some(())
    })?;
    Ok((closed && out.len() == n).then_some((h, out, kept)))
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;

    fn temp(name: &str, text: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("cadmorph-stream-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p
    }

    const HEAD: &str = "FoamFile\n{\n    version 2.0;\n    format ascii;\n    class faceList;\n    object faces;\n}\n";

    #[test]
    fn faces_across_windows_equal_the_whole_file_reader() {
        // One-line and multi-line records, in windows of 64 bytes (the test size).
        let mut text = format!("{HEAD}// comment before the list\n5\n(\n");
        text.push_str("4(1000001 2 3 4)\n3(5 6 7)\n");
        text.push_str("12\n(\n");
        for k in 0..12 {
            text.push_str(&format!("{}\n", 100 + k));
        }
        text.push_str(")\n4(8 9 10 11)\n4(9999999 12 13 14)\n)\n\n// footer\n");
        let p = temp("faces", &text);
        let (_, (off, lab), kept) = faces(&p).unwrap().unwrap();
        let (_, off2, lab2) = super::super::file::face_list_fast(text.as_bytes()).unwrap();
        assert_eq!((off, lab), (off2, lab2));
        assert_eq!(kept.bytes(|_| false).unwrap().unwrap(), text.as_bytes());
    }

    #[test]
    fn labels_across_windows_and_unusual_lists() {
        let body: String = (0..200).map(|k| format!("{}\n", k * 7919)).collect();
        let text = format!("{}200\n(\n{body})\n", HEAD.replace("faceList", "labelList"));
        let p = temp("owner", &text);
        let (_, v, _) = labels(&p).unwrap().unwrap();
        assert_eq!(v, (0..200).map(|k| k * 7919).collect::<Vec<u32>>());
        // A wrong count, a sign, a comment inside the list, binary: left to the whole-file readers.
        for bad in [
            text.replace("200\n(", "201\n("),
            text.replace("\n7919\n", "\n-7919\n"),
            text.replace("\n7919\n", "\n// c\n7919\n"),
            text.replace("format ascii", "format binary"),
        ] {
            let p = temp("bad", &bad);
            assert!(labels(&p).unwrap().is_none(), "{bad}");
        }
    }

    #[test]
    fn a_file_changed_after_reading_is_copied_only_when_it_holds_the_same_lists() {
        let text = format!("{}2\n(\n0\n1\n)\n", HEAD.replace("faceList", "labelList"));
        let p = temp("changed", &text);
        let (_, v, kept) = labels(&p).unwrap().unwrap();
        let same = |b: &[u8]| super::super::file::label_list_fast(b).is_some_and(|(_, w)| w == v);
        // Rewritten with the same labels (a comment added): copied as it is now.
        let now = format!("{text}\n// appended");
        std::fs::write(&p, &now).unwrap();
        assert_eq!(kept.bytes(same).unwrap().unwrap(), now.as_bytes());
        // Other labels, or gone: not taken.
        std::fs::write(&p, text.replace("\n1\n)", "\n7\n)")).unwrap();
        assert!(kept.bytes(same).unwrap().is_none());
        std::fs::remove_file(&p).unwrap();
        assert!(kept.bytes(same).unwrap().is_none());
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]

        /// Streamed in 64-byte windows, a face list gives what the whole-file reader gives,
        /// with multi-line faces among one-line ones.
        #[test]
        fn streamed_faces_equal_the_whole_file_reader(
            faces in prop::collection::vec(prop::collection::vec(0usize..10_000_000, 3..14), 1..300),
        ) {
            let text = super::super::fast::tests::face_text(&faces, "\n// end\n");
            let p = temp("prop-faces", &text);
            let got = faces_of(&p);
            let want = super::super::file::face_list_fast(text.as_bytes()).map(|(_, o, l)| (o, l));
            prop_assert_eq!(got, want);
        }
    }

    fn faces_of(p: &Path) -> Option<FaceLists> {
        faces(p).unwrap().map(|(_, f, _)| f)
    }

    #[test]
    fn points_across_windows_equal_the_whole_file_reader() {
        let mut text =
            String::from("FoamFile { version 2.0; format ascii; class vectorField; object points; }\n40\n(\n");
        for k in 0..40 {
            text.push_str(&format!("({} {:e} -{})\n", k as f64 * 0.1, 1.0 / (k as f64 + 3.0), k));
        }
        text.push_str(")\n// end\n");
        let p = temp("points", &text);
        let (_, got, _) = points(&p).unwrap().unwrap();
        assert_eq!(got, super::super::FoamPoints::parse(text.as_bytes()).unwrap().points);
        // Not finite: left to the whole-file reader (which names it).
        let bad = text.replace("\n(0 ", "\n(nan ");
        assert_ne!(bad, text);
        assert!(points(&temp("bad-points", &bad)).unwrap().is_none());
        // A record over two lines: read, or left to the whole-file reader where a window
        // ends inside it; never other values.
        for k in [5, 17, 30] {
            let split = text.replace(&format!("\n({} ", k as f64 * 0.1), &format!("\n({}\n", k as f64 * 0.1));
            assert_ne!(split, text);
            if let Some((_, v, _)) = points(&temp("split-points", &split)).unwrap() {
                assert_eq!(v, got);
            }
        }
    }

    #[test]
    fn a_count_the_file_cannot_hold_sizes_no_buffer() {
        let text =
            "FoamFile { version 2.0; format ascii; class vectorField; object points; }\n1000000000000\n(\n(0 0 0)\n)\n";
        assert!(points(&temp("huge-count", text)).unwrap().is_none());
        let owner = text.replace("vectorField", "labelList").replace("(0 0 0)", "0");
        assert!(labels(&temp("huge-count-owner", &owner)).unwrap().is_none());
    }
}
