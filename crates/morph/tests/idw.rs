//! IDW: PyGeM's power-3 case, both variants, `.prm` reading and writing.

mod common;

use cadmorph_morph::math::{Point3, Vector3};
use cadmorph_morph::{Deformation, Error, Idw, IdwParameters, IdwVariant, LinearInParameters, Parameters};
use common::*;

#[test]
fn power_3_point_matches_pygem() {
    let params = IdwParameters::from_prm(&read_text("parameters_idw_deform.prm")).unwrap();
    assert_eq!(params.variant, IdwVariant::PyGem { power: 3 });
    let idw = Idw::from_parameters(&params).unwrap();
    let mut pts = cube_grid();
    idw.deform(&mut pts);
    let p = pts[pts.len() - 3];
    let full = pygem_reference("idw_deform_point_-3");
    assert!((p - full).amax() < PYGEM_MATCH, "{p} vs {full}");
    let printed = Point3::new(1.19541593, 1.36081491, 1.42095073); // tests/test_idw.py
    assert!((p - printed).amax() < 1e-8);
    // The paper's d⁻ᵖ weights give a different point: the variants really differ.
    let paper =
        Idw::from_parameters(&IdwParameters { variant: IdwVariant::Paper { power: 3.0, cutoff: None }, ..params })
            .unwrap();
    assert!((paper.deform_point(&cube_grid()[7997]) - full).norm() > 1e-3);
}

#[test]
fn default_file_is_identity() {
    let params = IdwParameters::from_prm(&read_text("parameters_idw_default.prm")).unwrap();
    let idw = Idw::from_parameters(&params).unwrap();
    let pts = cube_grid();
    assert!(max_abs_diff(&idw.deformed(&pts), &pts) < 1e-15);
    let cube = IdwParameters::from_prm(&read_text("parameters_idw_cube.prm")).unwrap();
    assert_eq!(cube.original[0], Point3::new(-0.1, 0.0, 0.0));
    assert_eq!(cube.deformed[7], Point3::new(1.2, 1.2, 1.2));
}

#[test]
fn writer_matches_pygem_byte_for_byte() {
    for name in ["parameters_idw_default.prm", "parameters_idw_deform.prm"] {
        let text = read_text(name);
        let p = IdwParameters::from_prm(&text).unwrap();
        if name == "parameters_idw_default.prm" {
            assert_eq!(p.to_prm().unwrap(), text, "{name}");
        }
        assert_eq!(IdwParameters::from_prm(&p.to_prm().unwrap()).unwrap(), p);
        assert!(matches!(Parameters::from_prm(&text).unwrap(), Parameters::Idw(_)));
    }
    let paper = IdwParameters {
        variant: IdwVariant::Paper { power: 2.0, cutoff: None },
        original: vec![Point3::origin()],
        deformed: vec![Point3::origin()],
    };
    assert!(paper.to_prm().is_err());
}

#[test]
fn malformed_idw_files_name_the_line() {
    let good = read_text("parameters_idw_deform.prm");
    assert!(matches!(
        IdwParameters::from_prm(&good.replace("power = 3", "power = 2.5")),
        Err(Error::Syntax { line: 6, .. })
    ));
    assert!(matches!(
        IdwParameters::from_prm(&good.replace("power = 3", "power = 0")),
        Err(Error::InvalidParameter { line: Some(6), .. })
    ));
    assert!(matches!(
        IdwParameters::from_prm(&good.replace("power = 3\n", "")),
        Err(Error::MissingKey { key: "power", .. })
    ));
    let extra = good.replace("1.5   1.6   1.7", "1.5   1.6   1.7\n                         2   2   2");
    assert!(matches!(IdwParameters::from_prm(&extra), Err(Error::CountMismatch { expected: 8, found: 9, .. })));
}

#[test]
fn batched_and_pointwise_agree_for_every_variant() {
    let params = IdwParameters::from_prm(&read_text("parameters_idw_deform.prm")).unwrap();
    let grid = cube_grid();
    for variant in [
        IdwVariant::PyGem { power: 1 },
        IdwVariant::PyGem { power: 2 },
        IdwVariant::PyGem { power: 3 },
        IdwVariant::Paper { power: 2.0, cutoff: None },
        IdwVariant::Paper { power: 3.5, cutoff: None },
        IdwVariant::Paper { power: 2.0, cutoff: Some(0.6) },
    ] {
        let idw = Idw::from_parameters(&IdwParameters { variant, ..params.clone() }).unwrap();
        let batched = idw.deformed(&grid);
        for (i, p) in grid.iter().enumerate().step_by(13) {
            assert!((idw.deform_point(p) - batched[i]).norm() < 1e-14, "{variant:?}");
        }
        // Reproduces the control displacements.
        for (o, d) in params.original.iter().zip(&params.deformed) {
            assert!((idw.deform_point(o) - d).norm() < 1e-15);
        }
    }
}

#[test]
fn jacobians_match_finite_differences() {
    let params = IdwParameters::from_prm(&read_text("parameters_idw_deform.prm")).unwrap();
    let probe = [Point3::new(0.3, 0.4, 0.5), Point3::new(0.9, 0.2, 0.7), Point3::new(0.5, 0.5, 0.45)];
    let h = 1e-6;
    for variant in [
        IdwVariant::PyGem { power: 3 },
        IdwVariant::PyGem { power: 2 },
        IdwVariant::Paper { power: 2.0, cutoff: None },
        IdwVariant::Paper { power: 2.0, cutoff: Some(0.9) },
    ] {
        let idw = Idw::from_parameters(&IdwParameters { variant, ..params.clone() }).unwrap();
        for p in &probe {
            let j = idw.jacobian(p).unwrap();
            for a in 0..3 {
                let mut e = Vector3::zeros();
                e[a] = h;
                let fd = (idw.deform_point(&(p + e)) - idw.deform_point(&(p - e))) / (2.0 * h);
                assert!((fd - j.column(a)).norm() < 1e-6, "{variant:?} {p}");
            }
            let jac = idw.param_jacobian(p);
            let lin = p.coords + &jac * nalgebra::DVector::from_vec(idw.params());
            assert!((idw.deform_point(p).coords - lin).norm() < 1e-14);
        }
    }
    let idw = Idw::from_parameters(&IdwParameters {
        variant: IdwVariant::Paper { power: 2.0, cutoff: None },
        ..params.clone()
    })
    .unwrap();
    assert_eq!(idw.jacobian(&params.original[7]), Some(nalgebra::Matrix3::identity()));
    let idw = Idw::from_parameters(&params).unwrap();
    assert_eq!(idw.jacobian(&params.original[7]), None);
}
