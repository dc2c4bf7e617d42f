//! Bad input: every error names section, line, column and (where there is one) entity,
//! and no input panics (a proptest mutates the samples' bytes).

use cadmorph_iges::{Document, EntityId, Error, Position};
use proptest::prelude::*;

fn sample(name: &str) -> Vec<u8> {
    std::fs::read(cadmorph_testkit::sample(name)).unwrap()
}

/// Line `k` (0-based) of `bytes` replaced by `f(line)`.
fn edit_line(bytes: &[u8], k: usize, f: impl Fn(&mut Vec<u8>)) -> Vec<u8> {
    let mut lines: Vec<Vec<u8>> = bytes.split(|&c| c == b'\n').map(<[u8]>::to_vec).collect();
    f(&mut lines[k]);
    lines.join(&b"\n"[..])
}

fn at(err: &Error) -> Position {
    match err {
        Error::Syntax { at, .. }
        | Error::Section { at, .. }
        | Error::Truncated { at, .. }
        | Error::Hollerith { at, .. }
        | Error::ParamRange { at, .. }
        | Error::Mismatch { at, .. }
        | Error::DanglingPointer { at, .. }
        | Error::Count { at, .. }
        | Error::Parameter { at, .. }
        | Error::Terminate { at, .. }
        | Error::Sequence { at, .. } => *at,
        e => panic!("no position in {e}"),
    }
}

#[test]
fn truncated_file() {
    let bytes = sample("bspline_surface.igs");
    let err = Document::parse(&bytes[..bytes.len() / 2]).unwrap_err();
    assert!(matches!(err, Error::Section { .. } | Error::Truncated { .. }), "{err}");
    // Cut at a line end: no Terminate record.
    let cut = bytes.iter().enumerate().filter(|(_, &c)| c == b'\n').nth(14).unwrap().0 + 1;
    let err = Document::parse(&bytes[..cut]).unwrap_err();
    assert!(matches!(err, Error::Truncated { .. }), "{err}");
    assert_eq!(at(&err).section, 'P');
    assert_eq!(at(&err).line, 15);
    println!("{err}");
    // Cut inside a line: the last line is too short.
    let err = Document::parse(&bytes[..cut + 30]).unwrap_err();
    assert_eq!((at(&err).section, at(&err).line, at(&err).column), ('P', 16, 31), "{err}");
    assert!(Document::parse(b"").is_err());
}

#[test]
fn wrong_section_letter() {
    let bytes = edit_line(&sample("bspline_surface.igs"), 6, |l| l[72] = b'X');
    let err = Document::parse(&bytes).unwrap_err();
    assert!(matches!(err, Error::Section { .. }));
    assert_eq!((at(&err).line, at(&err).column), (7, 73));
    assert_eq!(err.to_string(), "section D, line 7, column 73: expected S, G, D, P or T in column 73, found \"X\"");
    // A P line among the D lines: its sequence number (D 3) is not the first of a P section.
    let bytes = edit_line(&sample("mixed_solid.igs"), 7, |l| l[72] = b'P');
    let bytes = edit_line(&bytes, 8, |l| l[72] = b'D');
    let err = Document::parse(&bytes).unwrap_err();
    assert!(matches!(err, Error::Sequence { expected: 1, .. }), "{err}");
    assert_eq!((at(&err).section, at(&err).line, at(&err).column), ('P', 8, 74), "{err}");
    // Without sequence numbers, the order of the letters is what is wrong.
    let bytes = edit_line(&sample("mixed_solid.igs"), 7, |l| {
        l[72] = b'P';
        l[73..80].copy_from_slice(b"       ");
    });
    let bytes = edit_line(&bytes, 8, |l| {
        l[72] = b'D';
        l[73..80].copy_from_slice(b"       ");
    });
    let err = Document::parse(&bytes).unwrap_err();
    assert_eq!((at(&err).section, at(&err).line), ('D', 9), "{err}");
    // Compressed form.
    let bytes = edit_line(&sample("nurbs_arc.igs"), 0, |l| l[72] = b'C');
    assert!(Document::parse(&bytes).unwrap_err().to_string().contains("compressed"));
}

#[test]
fn bad_pointers() {
    // Directory pointer past the P section.
    let bytes = edit_line(&sample("bspline_surface.igs"), 7, |l| l[8..16].copy_from_slice(b"      99"));
    let err = Document::parse(&bytes).unwrap_err();
    assert!(matches!(err, Error::ParamRange { first: 99, .. }), "{err}");
    assert_eq!(at(&err), Position { section: 'D', line: 8, column: 9, entity: Some(3) });
    // Directory pointer to another entity's record.
    let bytes = edit_line(&sample("bspline_surface.igs"), 7, |l| l[8..16].copy_from_slice(b"       1"));
    let err = Document::parse(&bytes).unwrap_err();
    assert!(matches!(err, Error::Mismatch { .. } | Error::ParamRange { .. }), "{err}");
    // Transformation pointer to nothing.
    let bytes = edit_line(&sample("bspline_surface.igs"), 5, |l| l[48..56].copy_from_slice(b"      77"));
    let err = Document::parse(&bytes).unwrap_err();
    assert!(matches!(err, Error::DanglingPointer { target: 77, .. }), "{err}");
    assert_eq!(at(&err), Position { section: 'D', line: 6, column: 49, entity: Some(1) });
    // A parameter pointer to nothing: the 144's surface pointer PTS = 41.
    let bytes = edit_line(&sample("bspline_surface.igs"), 9, |l| l[..12].copy_from_slice(b"144,41,0,0,;"));
    let doc = Document::parse(&bytes).unwrap();
    let err = doc.view(EntityId(1)).unwrap_err();
    assert!(matches!(err, Error::DanglingPointer { target: 41, entries: 2, .. }), "{err}");
    assert_eq!(at(&err), Position { section: 'P', line: 10, column: 5, entity: Some(1) });
    assert!(doc.surfaces()[0].nurbs.is_err());
    println!("{err}");
}

#[test]
fn bad_counts() {
    // K1 = 500 control points in u: more than the record holds.
    let bytes = edit_line(&sample("bspline_surface.igs"), 10, |l| l[..8].copy_from_slice(b"128,500,"));
    let doc = Document::parse(&bytes).unwrap();
    let err = doc.view(EntityId(3)).unwrap_err();
    assert!(matches!(err, Error::Count { count: 500, .. }), "{err}");
    assert_eq!(at(&err), Position { section: 'P', line: 11, column: 5, entity: Some(3) });
    // A negative count.
    let bytes = edit_line(&sample("nurbs_arc.igs"), 7, |l| l[..6].copy_from_slice(b"126,-2"));
    let doc = Document::parse(&bytes).unwrap();
    assert!(matches!(doc.view(EntityId(1)).unwrap_err(), Error::Count { count: -22, .. }));
    // An odd number of directory lines.
    let text = String::from_utf8(sample("nurbs_arc.igs")).unwrap();
    let mut lines: Vec<&str> = text.lines().collect();
    lines.remove(6);
    let err = Document::parse(lines.join("\n").as_bytes()).unwrap_err();
    assert!(matches!(err, Error::Truncated { .. } | Error::ParamRange { .. }), "{err}");
}

#[test]
fn hollerith_past_the_end() {
    // In the Global section (one Rhino export does this): 99H runs past the section. Read
    // as OCCT reads it, the string takes the rest of the section, with a warning at the count.
    let bytes = edit_line(&sample("nurbs_arc.igs"), 4, |l| l[..3].copy_from_slice(b"99H"));
    let doc = Document::parse(&bytes).unwrap();
    let w = doc.warnings();
    assert_eq!(w.len(), 1, "{w:?}");
    assert_eq!(w[0].at, Position { section: 'G', line: 5, column: 1, entity: None });
    assert!(w[0].message.contains("99"), "{}", w[0]);
    assert!(Document::parse(&sample("nurbs_arc.igs")).unwrap().warnings().is_empty());
    // In a parameter record.
    let bytes = edit_line(&sample("bspline_surface.igs"), 9, |l| l[..12].copy_from_slice(b"144,80Hxxxxx"));
    let err = Document::parse(&bytes).unwrap_err();
    assert!(matches!(err, Error::Hollerith { length: 80, within: "record", .. }), "{err}");
    assert_eq!(at(&err), Position { section: 'P', line: 10, column: 5, entity: Some(1) });
}

#[test]
fn non_numbers() {
    let bytes = edit_line(&sample("bspline_surface.igs"), 10, |l| l[14..19].copy_from_slice(b"1.2.3"));
    let err = Document::parse(&bytes).unwrap_err();
    assert_eq!(at(&err), Position { section: 'P', line: 11, column: 15, entity: Some(3) }, "{err}");
    assert!(err.to_string().contains("1.2.3"), "{err}");
    // In a directory field.
    let bytes = edit_line(&sample("bspline_surface.igs"), 8, |l| l[24..32].copy_from_slice(b"    1x 3"));
    let err = Document::parse(&bytes).unwrap_err();
    assert_eq!(at(&err), Position { section: 'D', line: 9, column: 25, entity: Some(3) }, "{err}");
    // A string where a number belongs.
    let bytes = edit_line(&sample("nurbs_arc.igs"), 7, |l| l[..8].copy_from_slice(b"126,1Hx,"));
    let doc = Document::parse(&bytes).unwrap();
    let err = doc.view(EntityId(1)).unwrap_err();
    assert!(matches!(err, Error::Parameter { index: 1, .. }), "{err}");
}

#[test]
fn terminate_counts() {
    // One P line fewer declared than present.
    let bytes = sample("nurbs_arc.igs");
    let t_start = bytes.len() - 81;
    let mut bad = bytes.clone();
    assert_eq!(&bad[t_start + 24..t_start + 32], b"P      2");
    bad[t_start + 31] = b'1';
    let err = Document::parse(&bad).unwrap_err();
    assert!(matches!(err, Error::Terminate { section: 'P', declared: 1, found: 2, .. }), "{err}");
    assert_eq!(at(&err), Position { section: 'T', line: 10, column: 25, entity: None });
}

#[test]
fn line_endings_and_missing_blanks() {
    let bytes = sample("nurbs_arc.igs");
    let crlf: Vec<u8> = bytes.iter().flat_map(|&c| if c == b'\n' { vec![b'\r', b'\n'] } else { vec![c] }).collect();
    let doc = Document::parse(&crlf).unwrap();
    assert_eq!(doc.write(), crlf);
    let no_final_newline = &bytes[..bytes.len() - 1];
    assert_eq!(Document::parse(no_final_newline).unwrap().write(), no_final_newline);
    // Records without line terminators (80-byte blocks).
    let blocks: Vec<u8> = bytes.iter().copied().filter(|&c| c != b'\n').collect();
    let doc = Document::parse(&blocks).unwrap();
    assert_eq!(doc.len(), 1);
    assert_eq!(doc.write(), blocks);
}

fn exercise(bytes: &[u8]) {
    if let Ok(doc) = Document::parse(bytes) {
        let out = doc.write();
        assert_eq!(out, bytes);
        for e in doc.entities() {
            let _ = doc.view(e.id());
        }
        let _ = doc.surfaces();
        for f in doc.faces() {
            let _ = doc.face_surface(&f);
        }
        for e in doc.entities() {
            let _ = doc.curve(e.id());
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, ..ProptestConfig::default() })]

    /// Random byte changes, insertions and cuts in the samples never make the reader (or
    /// the views and conversions of whatever it accepts) panic. `hull3.igs` has records
    /// of 138 lines, read through the reader's 64-line window.
    #[test]
    fn mutated_samples_never_panic(
        which in 0usize..5,
        edits in proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>(), 0u8..4), 1..8),
    ) {
        let name =
            ["nurbs_arc.igs", "bspline_surface.igs", "nurbs_cylinder.igs", "mixed_solid_brep.igs", "hull3.igs"][which];
        let mut bytes = sample(name);
        for (pos, byte, kind) in edits {
            let i = pos.index(bytes.len());
            match kind {
                0 => bytes[i] = byte,
                1 => bytes[i] = b"0123456789,;.-+EDH "[byte as usize % 19],
                2 => bytes.insert(i, byte),
                _ => { bytes.remove(i); }
            }
        }
        exercise(&bytes);
    }
}

/// `../shared/repro/ig_P_lines_swapped.igs` (two P lines of `bspline_surface.igs` swapped)
/// used to read as other geometry; its sequence numbers say where it breaks.
#[test]
fn repro_swapped_parameter_lines_are_refused() {
    let bytes = sample("bspline_surface.igs");
    let text = String::from_utf8(bytes).unwrap();
    let mut lines: Vec<&str> = text.lines().collect();
    let p0 = lines.iter().position(|l| l.as_bytes().get(72) == Some(&b'P')).unwrap();
    lines.swap(p0 + 3, p0 + 4);
    let err = Document::parse(lines.join("\n").as_bytes()).unwrap_err();
    assert!(matches!(err, Error::Sequence { expected: 4, .. }), "{err}");
    assert_eq!((at(&err).section, at(&err).line, at(&err).column), ('P', p0 + 4, 74));
    let err = Document::parse(&std::fs::read(cadmorph_testkit::repro("ig_P_lines_swapped.igs")).unwrap()).unwrap_err();
    assert!(matches!(err, Error::Sequence { .. }), "{err}");
}

/// `subfigure.igs` with `from` replaced by `to` (same length) in its P section.
fn subfigure_with(from: &str, to: &str) -> Document {
    let text = String::from_utf8(sample("subfigure.igs")).unwrap();
    assert_eq!(from.len(), to.len());
    assert_eq!(text.matches(from).count(), 1, "{from}");
    Document::parse(text.replace(from, to).as_bytes()).unwrap()
}

#[test]
fn subfigure_structures_that_cannot_be_read_name_the_entity() {
    let doc = Document::parse(&sample("subfigure.igs")).unwrap();
    assert_eq!(doc.try_faces().unwrap().len(), 28);
    // A 408 whose definition is a 144, not a 308.
    let doc = subfigure_with("408,155,0.,0.,0.,;", "408,111,0.,0.,0.,;");
    let e = doc.try_faces().unwrap_err();
    assert!(matches!(e, Error::Subfigure { de: 157, .. }), "{e}");
    assert_eq!(
        e.to_string(),
        "entity DE 157: 408 instance of DE 111 (type 144 form 0), which is not a 308 subfigure definition"
    );
    // The lenient list leaves that instance out (the other one's 14 faces stay).
    assert_eq!(doc.faces().len(), 14);
    // A 308 that lists itself.
    let doc = subfigure_with("308,1,4HPAIR,2,149,153;", "308,1,4HPAIR,2,149,155;");
    let e = doc.try_faces().unwrap_err();
    assert!(matches!(e, Error::Subfigure { de: 155, .. }), "{e}");
    assert!(e.to_string().contains("contains itself"), "{e}");
    // A 308 instancing itself through a 408 (PART's content is the instance of PART).
    let doc = subfigure_with("308,0,4HPART,1,1;", "308,0,4HPART,1,9;");
    assert!(doc.try_faces().is_ok(), "DE 9 is an ordinary entity");
    let text = String::from_utf8(sample("subfigure.igs")).unwrap();
    let looped = text.replace("308,0,4HPART,1,1;    ", "308,0,4HPART,1,149;  ");
    let doc = Document::parse(looped.as_bytes()).unwrap();
    let e = doc.try_faces().unwrap_err();
    assert!(matches!(e, Error::Subfigure { de: 147, .. }), "{e}");
    assert!(e.to_string().contains("contains itself (reached again inside DE 147)"), "{e}");
    eprintln!("{e}");
    // The 308's 402 group lists itself: refused, not a stack overflow.
    let doc = subfigure_with("402,7,3,19,35,57,73,95,111;", "402,7,1,19,35,57,73,95,111;");
    let e = doc.try_faces().unwrap_err();
    assert!(matches!(e, Error::Subfigure { de: 1, .. }), "{e}");
    assert!(e.to_string().contains("nested deeper than 256"), "{e}");
    assert!(doc.faces().is_empty());
}
