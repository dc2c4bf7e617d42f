//! Long parameter records (read through a window of lines, in parallel chunks, with
//! their text built only when asked for) read exactly as short ones: same values, the
//! same text, byte-identical writing, and errors at the same positions.

#[allow(dead_code)]
#[path = "../benches/generate.rs"]
mod generate;

use cadmorph_iges::{Document, Error, Param};

/// The 0-based file line and column of offset `off` of the record of the entity whose
/// record starts at file line `p_line` (1-based).
fn file_pos(p_line: usize, off: usize) -> (usize, usize) {
    (p_line - 1 + off / 64, off % 64)
}

/// The first P line (1-based) of the largest record and its line count.
fn largest_record(doc: &Document, bytes: &[u8]) -> (usize, usize, usize) {
    let e = doc.entities().max_by_key(|e| e.directory().parameter_lines).unwrap();
    let d_lines: Vec<&[u8]> = bytes.split(|&c| c == b'\n').collect();
    let p_start = d_lines.iter().position(|l| l.get(72) == Some(&b'P')).unwrap();
    (e.id().index(), p_start + e.directory().parameter_data as usize, e.directory().parameter_lines as usize)
}

#[test]
fn long_records_read_like_their_text() {
    let bytes = generate::hull(60, 40);
    let doc = Document::parse(&bytes).unwrap();
    assert_eq!(doc.write(), bytes);
    let (k, p_line, count) = largest_record(&doc, &bytes);
    assert!(count > 500, "{count} lines");
    let lines: Vec<&[u8]> = bytes.split(|&c| c == b'\n').collect();
    let e = doc.entities().nth(k).unwrap();
    let text: Vec<u8> = lines[p_line - 1..p_line - 1 + count].iter().flat_map(|l| l[..64].to_vec()).collect();
    assert_eq!(e.record_text(), &text[..]);
    // Every parameter is the number its text says.
    let fields: Vec<&[u8]> = text.split(|&c| c == b',' || c == b';').collect();
    assert_eq!(e.param_count(), fields.len() - 1);
    for (i, f) in fields[..fields.len() - 1].iter().enumerate() {
        let s = std::str::from_utf8(f).unwrap().trim();
        let want: f64 = s.parse().unwrap();
        let got = e.param(i).unwrap();
        assert_eq!(got.as_real().map(f64::to_bits), Some(want.to_bits()), "parameter {i}: {s} read as {got:?}");
        if !s.contains('.') {
            assert!(matches!(got, Param::Integer(_)), "parameter {i}: {s}");
        }
    }
}

#[test]
fn errors_deep_in_long_records_name_their_place() {
    let bytes = generate::hull(60, 40);
    let doc = Document::parse(&bytes).unwrap();
    let (k, p_line, count) = largest_record(&doc, &bytes);
    let id = doc.entities().nth(k).unwrap().id();
    // A broken number on lines around window (64-line) and chunk boundaries.
    for rel in [63usize, 64, 65, 127, 128, 300, count - 2] {
        let (line, _) = file_pos(p_line, rel * 64);
        let mut bad: Vec<Vec<u8>> = bytes.split(|&c| c == b'\n').map(<[u8]>::to_vec).collect();
        let col = bad[line].iter().position(|c| c.is_ascii_digit()).unwrap();
        bad[line][col] = b'x';
        let bad = bad.join(&b"\n"[..]);
        let err = Document::parse(&bad).unwrap_err();
        let Error::Syntax { at, .. } = &err else { panic!("{err}") };
        // The parameter starts at or before the broken character, on the same line or
        // (a number continued from the line before) the line before.
        assert_eq!((at.section, at.entity), ('P', Some(id.0)), "{err}");
        assert!(at.line == line + 1 || (at.line == line && col == 0), "line {} for {}: {err}", at.line, line + 1);
        if at.line == line + 1 {
            assert!(at.column <= col + 1 && col + 1 - at.column < 20, "{err}");
        }
    }
    // The record delimiter removed: the record runs out at its end.
    let mut bad: Vec<Vec<u8>> = bytes.split(|&c| c == b'\n').map(<[u8]>::to_vec).collect();
    let last = p_line - 1 + count - 1;
    let semi = bad[last].iter().position(|&c| c == b';').unwrap();
    bad[last][semi] = b',';
    let err = Document::parse(&bad.join(&b"\n"[..])).unwrap_err();
    assert!(matches!(err, Error::Truncated { .. }), "{err}");
}

#[test]
fn long_records_on_one_thread_and_many_agree() {
    let bytes = generate::hull(120, 80);
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    let seq = one.install(|| Document::parse(&bytes).unwrap());
    let par =
        rayon::ThreadPoolBuilder::new().num_threads(3).build().unwrap().install(|| Document::parse(&bytes).unwrap());
    for (a, b) in seq.entities().zip(par.entities()) {
        assert_eq!(a.values(), b.values(), "{}", a.id());
    }
}

/// [`Document::face_surfaces`] (faces converted on threads, for a few large patches and
/// for many small faces) gives each face's [`Document::face_surface`], in order.
#[test]
fn face_surfaces_are_each_face_surface() {
    for bytes in [generate::hull(200, 150), generate::many_faces(300)] {
        let doc = Document::parse(&bytes).unwrap();
        let faces = doc.faces();
        let all = doc.face_surfaces(&faces);
        assert_eq!(all.len(), faces.len());
        for (f, s) in faces.iter().zip(all) {
            assert_eq!(s.unwrap().surface, doc.face_surface(f).unwrap().surface);
        }
    }
}
