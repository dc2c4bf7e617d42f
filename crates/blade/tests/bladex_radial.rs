//! Radial laws and parameter files against BladeX (`tests/test_deform.py`,
//! `tests/test_params.py` at 0c84eab): arrays to 1e-10, corrupt files refused with
//! their line.

mod common;

use cadmorph_blade::{Deformation, Error, LawParam, ParamFile, RadialLaw};
use common::{data, max_diff, npy};

const BLADEX_MATCH: f64 = 1e-10;

fn prm() -> ParamFile {
    ParamFile::read(&data("parameters.prm")).unwrap()
}

fn pitch_law(rbf: usize) -> RadialLaw {
    let p = prm();
    let s = &p.settings[LawParam::Pitch.index()];
    RadialLaw::fit(LawParam::Pitch, &p.radii, &p.parameters[1], s.degree, s.nbasis, rbf).unwrap()
}

fn flat(cv: &[[f64; 2]]) -> Vec<f64> {
    cv.iter().flat_map(|c| [c[0], c[1]]).collect()
}

#[test]
fn reads_the_test_parameter_file() {
    let p = prm();
    assert_eq!(p.radii, vec![0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0]);
    assert_eq!(p.parameters[LawParam::Skew.index()][0], 3.6);
    let pitch = &p.settings[LawParam::Pitch.index()];
    assert_eq!((pitch.degree, pitch.npoints, pitch.nbasis), (5, 400, 6));
    assert_eq!(pitch.deformations, vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
}

#[test]
fn pitch_control_points_with_and_without_rbf() {
    let (_, want) = npy("pitch_control_points.npy");
    let d = max_diff(&flat(&pitch_law(1000).control_points), &want);
    assert!(d <= BLADEX_MATCH, "rbf: {d:e}");
    let (_, want) = npy("pitch_control_points_no_rbf.npy");
    let d = max_diff(&flat(&pitch_law(0).control_points), &want);
    assert!(d <= BLADEX_MATCH, "no rbf: {d:e}");
}

#[test]
fn pitch_updated_control_points() {
    let mut law = pitch_law(1000);
    law.deform(&prm().settings[1].deformations).unwrap();
    let (_, want) = npy("pitch_updated_control_points.npy");
    let d = max_diff(&flat(&law.control_points), &want);
    assert!(d <= BLADEX_MATCH, "{d:e}");
    assert!(law.deform(&[0.0; 4]).is_err());
}

#[test]
fn camber_spline() {
    let p = prm();
    let s = &p.settings[LawParam::Camber.index()];
    let law = RadialLaw::fit(LawParam::Camber, &p.radii, &p.parameters[4], s.degree, s.nbasis, 1000).unwrap();
    let (shape, want) = npy("camber_spline.npy");
    assert_eq!(shape, vec![s.npoints, 2]);
    let d = max_diff(&flat(&law.samples(s.npoints).unwrap()), &want);
    assert!(d <= BLADEX_MATCH, "{d:e}");
}

fn deformed(param: LawParam, degree: Option<usize>, tol: f64) -> Vec<f64> {
    let p = prm();
    let s = &p.settings[param.index()];
    let deg = degree.unwrap_or(s.degree);
    let mut law = RadialLaw::fit(param, &p.radii, &p.parameters[param.index()], deg, s.nbasis, 1000).unwrap();
    law.deform(&s.deformations).unwrap();
    law.sampled_values(&p.radii, s.npoints, tol).unwrap()
}

#[test]
fn deformed_distributions() {
    // As BladeX's test_deformed_*: rake with degree 3 (its file says 4 for 4 control
    // points), tolerances 1e-3 for chord and pitch, 1e-2 for the others.
    for (param, degree, tol, file) in [
        (LawParam::Chord, None, 1e-3, "deformed_chord.npy"),
        (LawParam::Pitch, None, 1e-3, "deformed_pitch.npy"),
        (LawParam::Rake, Some(3), 1e-2, "deformed_rake.npy"),
        (LawParam::Skew, None, 1e-2, "deformed_skew.npy"),
        (LawParam::Camber, None, 1e-2, "deformed_camber.npy"),
    ] {
        let (_, want) = npy(file);
        let d = max_diff(&deformed(param, degree, tol), &want);
        assert!(d <= BLADEX_MATCH, "{file}: {d:e}");
    }
}

#[test]
fn small_tolerance_is_refused() {
    let p = prm();
    let s = &p.settings[4];
    let law = RadialLaw::fit(LawParam::Camber, &p.radii, &p.parameters[4], s.degree, s.nbasis, 1000).unwrap();
    let e = law.sampled_values(&p.radii, s.npoints, 1e-7).unwrap_err();
    assert!(e.to_string().contains("camber"), "{e}");
}

#[test]
fn compute_all_and_export() {
    let mut p = prm();
    p.settings[LawParam::Rake.index()].degree = 3;
    let d = Deformation::compute_all(p, 1000, [1e-3, 1e-3, 1e-2, 1e-2, 1e-2]).unwrap();
    let (_, want) = npy("deformed_skew.npy");
    assert!(max_diff(&d.deformed[3], &want) <= BLADEX_MATCH);
    let out = d.deformed_param_file();
    let back = ParamFile::parse(&out.to_text(), "out.prm").unwrap();
    assert_eq!(back, out);
    assert_eq!(back.parameters[0], d.deformed[0]);
    assert!(back.settings.iter().all(|s| s.deformations.iter().all(|x| *x == 0.0)));
}

#[test]
fn write_then_read_is_identity() {
    for f in ["parameters.prm", "default.prm", "pptc.prm"] {
        let p = ParamFile::read(&data(f)).unwrap();
        let back = ParamFile::parse(&p.to_text(), f).unwrap();
        assert_eq!(back, p, "{f}");
    }
}

#[test]
fn corrupt_files_are_refused_with_their_line() {
    // (file, line of the offending value in that file, words of the reason)
    for (file, line, words) in [
        ("parameters_corrupt.prm", 16, "same length"),
        ("parameters_corrupt_2.prm", 76, "non-empty"),
        ("parameters_corrupt_3.prm", 76, "one value per line"),
        ("parameters_corrupt_4.prm", 73, "Y-deformations"),
        ("parameters_corrupt_5.prm", 8, "one value per line"),
        ("parameters_corrupt_6.prm", 17, "one value per line"),
    ] {
        match ParamFile::read(&data(file)) {
            Err(Error::Prm { line: l, reason, .. }) => {
                assert_eq!(l, line, "{file}: {reason}");
                assert!(reason.contains(words), "{file}: {reason}");
            }
            other => panic!("{file}: {other:?}"),
        }
    }
}

#[test]
fn toml_form_round_trips() {
    let p = prm();
    let t = p.to_toml().unwrap();
    assert_eq!(ParamFile::from_toml(&t, "p.toml").unwrap(), p);
    let bad = t.replacen("deformations = [1.0, 2.0, 3.0, 4.0, 5.0]", "deformations = [1.0]", 1);
    assert_ne!(bad, t);
    assert!(matches!(ParamFile::from_toml(&bad, "p.toml"), Err(Error::Prm { .. })));
}
