//! `cadmorph::convert`: IGES → STEP → IGES and STEP → IGES → STEP of the samples whose
//! faces are whole surfaces, checked by OCCT (validity, faces, area), and units carried
//! across (feet, mils, kilometres).

use std::path::{Path, PathBuf};

use cadmorph::{CadDocument, Format};

fn out_dir() -> PathBuf {
    let d = std::env::temp_dir().join(format!("cadmorph-convert-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// `input` converted to `format`, written to `dir`.
fn convert_to(input: &Path, format: Format, dir: &Path) -> PathBuf {
    let m = cadmorph::open(input).unwrap();
    let stem = input.file_name().unwrap().to_string_lossy().replace('.', "_");
    let out = dir.join(format!("{stem}.{}", format.extension()));
    cadmorph::save_as(&m, &out).unwrap();
    out
}

/// The files whose faces are whole surfaces (what converts today).
const CONVERTIBLE: [&str; 10] = [
    "hull3.igs",
    "hull3_bare.igs",
    "hull3_defect.igs",
    "bspline_surface.igs",
    "blade.igs",
    "nurbs_cylinder.igs",
    "hull3.stp",
    "hull3_defect.stp",
    "bspline_surface.stp",
    "nurbs_cylinder.stp",
];

#[test]
#[ignore = "needs the OCCT venv (bash tests/occt/setup.sh)"]
fn occt_reads_converted_files_with_the_same_faces_and_area() {
    let dir = out_dir();
    for name in CONVERTIBLE.iter().copied().chain(["blade.stp"]) {
        let input = cadmorph_testkit::sample(name);
        let from = cadmorph::open(&input).unwrap().format();
        let other = if from == Format::Iges { Format::Step } else { Format::Iges };
        let once = convert_to(&input, other, &dir);
        let twice = convert_to(&once, from, &dir);
        let (code, src) = cadmorph_testkit::harness::validate(&input, None);
        assert_eq!(code, 0, "{name}: {src}");
        for file in [&once, &twice] {
            let (code, out) = cadmorph_testkit::harness::validate(file, None);
            assert_eq!(code, 0, "{}: {out}", file.display());
            assert_eq!(out["transfer_ok"], true, "{}", file.display());
            assert_eq!(out["valid"], true, "{}: {}", file.display(), out["invalid_faces"]);
            assert_eq!(out["n_faces"], src["n_faces"], "{}", file.display());
            let (a, b) = (src["area"].as_f64().unwrap(), out["area"].as_f64().unwrap());
            assert!((a - b).abs() <= 1e-9 * a, "{}: area {b} vs {a}", file.display());
            let sorted = |v: &serde_json::Value| {
                let mut x: Vec<f64> = v.as_array().unwrap().iter().map(|a| a.as_f64().unwrap()).collect();
                x.sort_by(f64::total_cmp);
                x
            };
            for (p, q) in sorted(&src["face_areas"]).iter().zip(sorted(&out["face_areas"])) {
                assert!((p - q).abs() <= 1e-9 * p, "{}: face area {q} vs {p}", file.display());
            }
            eprintln!(
                "{name} -> {}: topology {} (input {})",
                file.file_name().unwrap().to_string_lossy(),
                out["topology"],
                src["topology"]
            );
        }
    }
}

#[test]
fn units_are_carried_across() {
    let dir = out_dir();
    let patch = cadmorph::nurbs::NurbsSurface::bilinear([[0., 0., 0.], [2., 0., 0.], [0., 1., 0.], [2., 1., 1.]]);
    for (unit, metres) in [
        (cadmorph::iges::Units::Foot, 0.3048),
        (cadmorph::iges::Units::Mil, 2.54e-5),
        (cadmorph::iges::Units::Kilometre, 1e3),
    ] {
        let mut b = cadmorph::iges::write::DocumentBuilder::new(unit).timestamp("20260101.000000");
        b.add_surface(&patch);
        let igs = dir.join(format!("patch_{}.igs", unit.name()));
        std::fs::write(&igs, b.to_bytes()).unwrap();
        let stp = convert_to(&igs, Format::Step, &dir);
        let m = cadmorph::open(&stp).unwrap();
        assert!((m.units().metres_per_unit - metres).abs() <= 1e-12 * metres, "{unit:?}: {:?}", m.units());
        assert_eq!(m.patches()[0].surface, patch, "{unit:?}: coordinates stay in the model unit");
        let back = convert_to(&stp, Format::Iges, &dir);
        let doc = cadmorph::read_document(&std::fs::read(&back).unwrap(), "back").unwrap();
        assert_eq!(doc.format(), Format::Iges);
        let d = cadmorph::iges::Document::parse(&std::fs::read(&back).unwrap()).unwrap();
        assert_eq!(d.global().units(), Some(unit));
    }
}

#[test]
fn what_does_not_convert_is_refused() {
    let dir = out_dir();
    for name in ["mixed_solid.stp", "mixed_solid.igs", "bspline_curve.igs", "nurbs_arc.stp"] {
        let m = cadmorph::open(&cadmorph_testkit::sample(name)).unwrap();
        let other = if m.format() == Format::Iges { "stp" } else { "igs" };
        let out = dir.join(format!("refused.{other}"));
        let e = cadmorph::save_as(&m, &out).unwrap_err();
        assert!(matches!(e, cadmorph::Error::Unsupported(_)), "{name}: {e}");
        assert!(!out.exists(), "{name}: nothing is written");
    }
    let m = cadmorph::open(&cadmorph_testkit::sample("hull3.igs")).unwrap();
    assert!(matches!(cadmorph::save_as(&m, &dir.join("x.txt")), Err(cadmorph::Error::UnknownExtension { .. })));
}
