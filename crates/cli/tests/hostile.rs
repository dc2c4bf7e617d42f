//! The CLI under hostile input, limits and output faults (issue 13): each reproducer of
//! `tests/repro/` (see its README) and each output case gives a clear error, exit 1 (2 for
//! a bad command line), and leaves the target as it was, with no temporary file behind.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn cadmorph(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_cadmorph")).args(args).current_dir(root()).output().expect("the binary runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A scratch folder removed when the test ends (also when it fails).
struct Scratch(PathBuf);

impl Scratch {
    fn new(name: &str) -> Scratch {
        let d = std::env::temp_dir().join(format!("cadmorph-hostile-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        Scratch(d)
    }
    fn path(&self, name: &str) -> String {
        self.0.join(name).to_string_lossy().into_owned()
    }
    fn temporaries(&self) -> Vec<String> {
        std::fs::read_dir(&self.0)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".tmp"))
            .collect()
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

const HULL: &str = "samples/hull3.igs";
const BOW: &str = "samples/prm/bow_dome.prm";

#[test]
fn repro_uniform_refinement_of_a_huge_knot_span_and_of_too_many_knots() {
    let s = Scratch::new("knots");
    let out = s.path("k.igs");
    let o = cadmorph(&["refine", "tests/repro/gen_knots_huge_span.igs", "-o", &out, "--knots", "3"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = cadmorph(&["refine", "tests/repro/gen_knots_huge_span.igs", "-o", &s.path("k2.igs"), "--knots", "100000"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(e.contains("uniform refinement by 100000 knots") && e.contains("would need"), "{e}");
    assert!(!Path::new(&s.path("k2.igs")).exists());
}

#[test]
fn repro_lattices_past_memory_are_refused_with_the_parameter() {
    let s = Scratch::new("lattice");
    for (file, flag) in [("latwrap.prm", "--ffd"), ("lathuge.prm", "--ffd"), ("huge.toml", "--ffd")] {
        let out = s.path("o.igs");
        let o = cadmorph(&["morph", HULL, flag, &format!("tests/repro/{file}"), "-o", &out]);
        assert_eq!(o.status.code(), Some(1), "{file}: {}", stderr(&o));
        let e = stderr(&o);
        assert!(e.contains("FFD lattice") && e.contains("over the budget"), "{file}: {e}");
        assert_eq!(e.lines().count(), 1, "one line: {e}");
        assert!(!Path::new(&out).exists());
    }
    // A budget given on the command line is the one in force.
    let o = cadmorph(&["--max-memory", "1k", "morph", HULL, "--ffd", BOW, "-o", &s.path("o.igs")]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("1.0 kB"), "{}", stderr(&o));
    let o = cadmorph(&["--max-memory", "lots", "info", HULL]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}

#[test]
fn bad_tolerances_are_refused() {
    let s = Scratch::new("tol");
    let out = s.path("o.igs");
    for bad in ["nan", "inf", "0", "-1e-5"] {
        let o = cadmorph(&["morph", HULL, "--ffd", BOW, "-o", &out, &format!("--refine-tol={bad}")]);
        assert_eq!(o.status.code(), Some(2), "{bad}: {}", stderr(&o));
        assert!(stderr(&o).contains("positive finite"), "{bad}: {}", stderr(&o));
        let o =
            cadmorph(&["morph", HULL, "--ffd", BOW, "-o", &out, "--refine-tol", "1e-5", &format!("--angle-tol={bad}")]);
        assert_eq!(o.status.code(), Some(2), "{bad}: {}", stderr(&o));
    }
    // Below what f64 resolves at the hull's size (145 m).
    let o = cadmorph(&["morph", HULL, "--ffd", BOW, "-o", &out, "--refine-tol", "1e-17"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("double precision"), "{}", stderr(&o));
    assert!(!Path::new(&out).exists());
}

#[test]
fn refinement_that_does_not_converge_fails_and_writes_nothing() {
    // The hull's bow dome needs some knots at 1.45e-5 (576 -> 600 control points); a
    // budget below that stops the refinement before it converges.
    let s = Scratch::new("converge");
    let out = s.path("o.igs");
    let o =
        cadmorph(&["morph", HULL, "--ffd", BOW, "-o", &out, "--refine-tol", "1.45e-5", "--max-control-points", "590"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(e.contains("did not converge") && e.contains("nothing written"), "{e}");
    assert!(!Path::new(&out).exists());
    assert!(s.temporaries().is_empty());
}

#[test]
fn a_gap_the_input_already_had_is_reported_and_does_not_drive_refinement() {
    // The defect hull's 33 mm matched gap (2.44 mm closest) was there before the morph:
    // each edge is held to its own input gap + tol, so refinement converges with no
    // more than twice the input's control points, and the defect is named with the hint.
    let s = Scratch::new("defect");
    for input in ["samples/hull3_defect.igs", "samples/hull3_defect.stp"] {
        let ext = &input[input.len() - 3..];
        let out = s.path(&format!("o.{ext}"));
        let o = cadmorph(&["morph", input, "--ffd", BOW, "-o", &out, "--refine-tol", "1.45e-5", "--json"]);
        assert_eq!(o.status.code(), Some(0), "{input}: {}", stderr(&o));
        let r: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        let (before, after) =
            (r["control_points_before"].as_u64().unwrap(), r["control_points_after"].as_u64().unwrap());
        assert!(after <= 2 * before, "{input}: {before} -> {after}");
        assert_eq!(r["refinement"]["converged"], true, "{input}");
        assert_eq!(r["refinement"]["input_defects"], 1, "{input}");
        let check = &r["check"];
        assert_eq!(check["failed"], 0, "{input}");
        assert_eq!(check["input_defects"], 1, "{input}");
        let defect = check["edges"].as_array().unwrap().iter().find(|e| e["input_defect"] == true).unwrap();
        assert!((defect["gap_before"].as_f64().unwrap() - 2.444e-3).abs() < 1e-5, "{input}: {defect}");
        assert!((defect["matched_before"].as_f64().unwrap() - 3.272e-2).abs() < 1e-5, "{input}: {defect}");
        // Text mode names the defect and the hint.
        let o = cadmorph(&["morph", input, "--ffd", BOW, "-o", &out, "--refine-tol", "1.45e-5"]);
        let text = String::from_utf8_lossy(&o.stdout);
        assert!(text.contains("pre-existing defect") && text.contains("--repair"), "{text}");
        // With --repair the defect edge closes to 1e-12 of its length.
        let o = cadmorph(&["morph", input, "--ffd", BOW, "-o", &out, "--refine-tol", "1.45e-5", "--repair", "--json"]);
        assert_eq!(o.status.code(), Some(0), "{input}: {}", stderr(&o));
        let r: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        for e in r["seams_after"]["edges"].as_array().unwrap() {
            let len = e["length"].as_f64().unwrap();
            assert!(e["gap_matched"]["max"].as_f64().unwrap() <= 1e-12 * len, "{input}: {e}");
        }
        assert_eq!(r["repair"]["edges_repaired"], 2, "{input}");
    }
    // Unrefined, the bow dome turns the clean hull's seams by 0.012 deg: checked at the
    // default 0.01 deg, the morph fails, writing nothing (the check can fail).
    let out = s.path("strict.igs");
    let o = cadmorph(&["morph", HULL, "--ffd", BOW, "-o", &out, "--tol", "1.45e-5"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("fail the seam check") && stderr(&o).contains("nothing written"), "{}", stderr(&o));
    assert!(!Path::new(&out).exists());
}

#[test]
fn outputs_that_are_not_regular_files_are_refused() {
    let s = Scratch::new("kinds");
    // /dev/null (named with a CAD extension through a link) stays a device.
    let link = s.path("null.igs");
    std::os::unix::fs::symlink("/dev/null", &link).unwrap();
    let o = cadmorph(&["morph", HULL, "--ffd", BOW, "-o", &link]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("not a regular file"), "{}", stderr(&o));
    assert!(std::os::unix::fs::FileTypeExt::is_char_device(&std::fs::metadata("/dev/null").unwrap().file_type()));
    // A directory named like a file.
    let dir = s.path("dir.igs");
    std::fs::create_dir(&dir).unwrap();
    let o = cadmorph(&["morph", HULL, "--ffd", BOW, "-o", &dir]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("is a directory"), "{}", stderr(&o));
    assert!(s.temporaries().is_empty());
}

#[test]
fn outputs_keep_links_and_permissions_and_nothing_is_replaced_before_everything_succeeded() {
    use std::os::unix::fs::PermissionsExt;
    let s = Scratch::new("replace");
    let out = s.path("out.igs");
    std::fs::write(&out, b"previous").unwrap();
    std::fs::set_permissions(&out, std::fs::Permissions::from_mode(0o604)).unwrap();
    // A report that cannot be written: the output must not have been replaced.
    let o = cadmorph(&["morph", HULL, "--ffd", BOW, "-o", &out, "--report", &s.path("no/such/dir/r.json")]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert_eq!(std::fs::read(&out).unwrap(), b"previous");
    // Through a link: the file it names is replaced, the link stays, permissions kept.
    let link = s.path("link.igs");
    std::os::unix::fs::symlink("out.igs", &link).unwrap();
    let o = cadmorph(&["morph", HULL, "--ffd", BOW, "-o", &link]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
    assert!(std::fs::read(&out).unwrap().len() > 1000);
    assert_eq!(std::fs::metadata(&out).unwrap().permissions().mode() & 0o777, 0o604);
    // The output may be the input: it is replaced at once by the whole new file.
    let o = cadmorph(&["morph", &out, "--ffd", BOW, "-o", &out]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = cadmorph(&["info", &out]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(s.temporaries().is_empty());
}

#[test]
fn a_write_that_fails_midway_leaves_no_temporary_file() {
    // The file-size limit makes the write fail with EFBIG after a few blocks.
    let s = Scratch::new("efbig");
    let out = s.path("big.stp");
    let o = Command::new("bash")
        .arg("-c")
        .arg(format!("ulimit -f 8; exec \"$0\" morph samples/hull3.stp --ffd {BOW} -o {out}"))
        .arg(env!("CARGO_BIN_EXE_cadmorph"))
        .current_dir(root())
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("writing"), "{}", stderr(&o));
    assert!(!Path::new(&out).exists());
    assert!(s.temporaries().is_empty(), "{:?}", s.temporaries());
}

/// An IGES file with the sample B-spline surface as one face and a 144 whose "surface"
/// is a curve (a face nothing can convert).
fn file_with_an_unconvertible_face() -> Vec<u8> {
    use cadmorph::iges::write::DocumentBuilder;
    use cadmorph::iges::{Document, EntityId, Status, Units, Value};
    let doc = Document::parse(&std::fs::read(root().join("samples/bspline_surface.igs")).unwrap()).unwrap();
    let surface = doc.surface(EntityId(1)).unwrap().surface;
    let mut b = DocumentBuilder::new(Units::Millimetre);
    b.add_surface(&surface);
    let curve = b.add_curve(&surface.boundary(cadmorph::nurbs::Side::UMin));
    b.set_status(curve, Status { subordinate: 1, ..Status::default() });
    b.add_entity(
        0,
        Status::default(),
        vec![Value::Integer(144), Value::Integer(curve.0 as i64), Value::Integer(0), Value::Integer(0)],
    );
    b.to_bytes()
}

#[test]
fn faces_that_cannot_be_converted_are_named_and_stop_the_morph() {
    let s = Scratch::new("skip");
    let input = s.path("in.igs");
    std::fs::write(&input, file_with_an_unconvertible_face()).unwrap();
    let out = s.path("out.igs");
    let o = cadmorph(&["morph", &input, "--ffd", "tests/repro/ok.prm", "-o", &out]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("cannot be converted") && stderr(&o).contains("DE 5"), "{}", stderr(&o));
    assert!(!Path::new(&out).exists());
    let o = cadmorph(&["morph", &input, "--ffd", "tests/repro/ok.prm", "-o", &out, "--skip-unsupported"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("warning: face DE 5"), "{}", stderr(&o));
    let o = cadmorph(&["seams", &input]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("warning: face DE 5"), "{}", stderr(&o));
}

#[test]
fn a_part_placed_twice_is_morphed_with_a_copy_for_each_moved_placement() {
    // The sample assembly places one part twice (two NEXT_ASSEMBLY_USAGE_OCCURRENCEs of
    // one product) and a pair of pins twice: each placement the morph moves gets its own
    // copy of the part (new product definition, representation and geometry), the faces
    // stay the input's 30, and the file reads back with every placement's own surface.
    let s = Scratch::new("assembly");
    let out = s.path("out.stp");
    let o = cadmorph(&["morph", "samples/assembly_ap214.stp", "--ffd", "tests/repro/fuzz_small.prm", "-o", &out]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = cadmorph(&["info", &out, "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let info: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let faces = info["faces"].as_array().unwrap();
    assert_eq!(faces.len(), 30);
    let surfaces: std::collections::HashSet<_> = faces.iter().map(|p| p["surface"].as_str().unwrap()).collect();
    assert_eq!(surfaces.len(), 30, "every placed face has its own surface");
    assert!(surfaces.iter().all(|s| !s.contains("occurrence")), "{surfaces:?}");
    let text = std::fs::read_to_string(&out).unwrap();
    assert_eq!(
        text.matches("NEXT_ASSEMBLY_USAGE_OCCURRENCE").count(),
        8,
        "the occurrences of the input and of the copied pair"
    );
    assert_eq!(text.matches("SHAPE_DEFINITION_REPRESENTATION").count(), 9);
}

#[test]
fn a_part_placed_by_mapped_items_is_morphed_with_a_copy_for_each_moved_placement() {
    // MAPPED_ITEM placements of one representation: each moved one maps its own copy.
    let s = Scratch::new("mapped");
    let out = s.path("out.stp");
    let o = cadmorph(&["morph", "samples/mapped_item.stp", "--ffd", "tests/repro/fuzz_small.prm", "-o", &out]);
    assert!(o.status.success(), "{}", stderr(&o));
    let said = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(said.contains("placed parts copied first"), "{said}");
    let o = cadmorph(&["info", &out]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("faces (35;"), "{}", String::from_utf8_lossy(&o.stdout));
    let o = cadmorph(&["seams", &out]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("75 shared edges"), "{}", String::from_utf8_lossy(&o.stdout));
    // A morph that moves nothing copies nothing: the file comes back byte for byte.
    let zero = s.path("zero.stp");
    let mut prm = String::from("[Box info]\n");
    for (k, v) in
        [("n control points", "2"), ("box length", "4000.0"), ("box origin", "-2000.0"), ("rotation angle", "0.0")]
    {
        for a in ["x", "y", "z"] {
            prm += &format!("{k} {a}: {v}\n");
        }
    }
    prm += "\n[Parameters weights]\n";
    for a in ["x", "y", "z"] {
        for n in 0..8 {
            let head = if n == 0 { format!("parameter {a}:") } else { String::new() };
            prm += &format!("{head:13} {} {} {} 0.0\n", n / 4, n / 2 % 2, n % 2);
        }
    }
    let zero_prm = s.path("zero.prm");
    std::fs::write(&zero_prm, prm).unwrap();
    let o = cadmorph(&["morph", "samples/mapped_item.stp", "--ffd", &zero_prm, "-o", &zero]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(std::fs::read(&zero).unwrap(), std::fs::read(root().join("samples/mapped_item.stp")).unwrap());
}

#[test]
fn a_part_placed_by_subfigure_instances_is_copied_for_each_placement() {
    // IGES 408 instances of one 308 definition: one surface cannot hold two moves, so
    // each instance gets its own copy of the part (nested instances too) before the morph.
    let s = Scratch::new("subfigure");
    let out = s.path("out.igs");
    let o = cadmorph(&["morph", "samples/subfigure.igs", "--ffd", "tests/repro/fuzz_small.prm", "-o", &out]);
    assert!(o.status.success(), "{}", stderr(&o));
    let said = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(said.contains("4 placed parts copied first"), "{said}");
    let o = cadmorph(&["info", &out]);
    assert!(o.status.success(), "{}", stderr(&o));
    let info = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(info.contains("faces (28;"), "{info}");
    // The two definitions, PART four times and PAIR twice now.
    assert!(info.contains("6  308 subfigure definition"), "{info}");
    let o = cadmorph(&["info", "samples/subfigure.igs"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("faces (28;"), "{}", String::from_utf8_lossy(&o.stdout));
    // A 408 of something that is not a 308: a clear error naming it.
    let text = std::fs::read_to_string(root().join("samples/subfigure.igs")).unwrap();
    let bad = s.path("bad.igs");
    std::fs::write(&bad, text.replace("408,155,0.,0.,0.,;", "408,111,0.,0.,0.,;")).unwrap();
    let o = cadmorph(&["seams", &bad]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("entity DE 157: 408 instance of DE 111"), "{}", stderr(&o));
}
