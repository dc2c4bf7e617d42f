//! `cadmorph seams --tol T --angle-tol A`: exit 1 when an edge fails, naming it by its
//! faces' entities; exit 0 when every edge passes. The defect hull's gap is OCCT's
//! independent measurement (`samples/hull3_defect.igs.check.json`: 2.4442e-3 m on the
//! mid/bow seam), the intact hull's seams are closed.

mod common;

use common::{cadmorph, stderr};

#[test]
fn the_defect_hull_fails_and_names_the_edge_by_entity() {
    let out = cadmorph(&["seams", "samples/hull3_defect.igs", "--tol", "1e-3"]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let err = stderr(&out);
    // The mid body is face 1 (DE 9), the bow face 2 (DE 13) in this file.
    assert!(err.contains("1 of 2 edges fail"), "{err}");
    assert!(err.contains("edge 1 (face 1 (DE 9) u_max | face 2 (DE 13) u_min)"), "{err}");
    assert!(err.contains("gap 2.444"), "{err}");
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(table.contains("FAIL (gap)") && table.contains("metres"), "{table}");
    assert_eq!(table.matches("FAIL").count(), 1, "only the defect edge fails: {table}");
    // Just above the defect's gap it passes.
    assert_eq!(cadmorph(&["seams", "samples/hull3_defect.igs", "--tol", "2.5e-3"]).status.code(), Some(0));
    // The STEP defect hull names its faces by STEP instance.
    let out = cadmorph(&["seams", "samples/hull3_defect.stp", "--tol", "1e-3"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("(#"), "{}", stderr(&out));
}

#[test]
fn the_intact_hull_passes() {
    let out = cadmorph(&["seams", "samples/hull3.igs", "--tol", "1e-3"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let out = cadmorph(&["seams", "samples/hull3.igs", "--tol", "1e-9", "--angle-tol", "0.001"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
}

#[test]
fn the_angle_tolerance_is_checked_on_smooth_edges() {
    // The defect's normals differ by 0.1948 degrees (its G1 angle).
    let out = cadmorph(&["seams", "samples/hull3_defect.igs", "--angle-tol", "0.1"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("G1 angle 1.948"), "{}", stderr(&out));
    assert_eq!(cadmorph(&["seams", "samples/hull3_defect.igs", "--angle-tol", "0.2"]).status.code(), Some(0));
    // The solid's box edges are sharp (creases by design) and not checked.
    let out = cadmorph(&["seams", "samples/mixed_solid.stp", "--angle-tol", "0.5", "--samples", "20"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(String::from_utf8_lossy(&out.stdout).contains(" S "));
    // Bad tolerances are a bad command line.
    assert_eq!(cadmorph(&["seams", "samples/hull3.igs", "--tol", "-1"]).status.code(), Some(2));
    assert_eq!(cadmorph(&["seams", "samples/hull3.igs", "--angle-tol", "95"]).status.code(), Some(1));
}
