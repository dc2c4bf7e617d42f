//! Trimmed faces are drawn trimmed: the drawn triangles of each face of
//! `samples/mixed_solid.stp` (a box with a hole and a loft standing on it: the top
//! face has the hole cut out, the face under the loft its footprint, the loft's
//! bottom ellipse and top circle are cut from planes larger than they are) cover the face's own area, not its parameter box.

use std::f64::consts::PI;

use cadmorph_report::grid::{face_mesh, grid_size, mesh_area};
use cadmorph_report::{Input, Scene};
use cadmorph_testkit::sample;

/// Drawn area against the face's true area: the grid (17 to 97 vertices a side) keeps
/// or drops each triangle by its centroid, which misplaces the boundary by up to a
/// cell, and flat triangles cut the chords of curved faces: 2 % covers both at these
/// grids (measured: at most 0.24 %, the top face, whose whole box is 6.9 % off).
const TRIMMED_AREA: f64 = 0.02;

fn drawn_areas(path: &str) -> (Vec<f64>, Vec<f64>, Vec<bool>) {
    let m = cadmorph::open(&sample(path)).unwrap();
    let seams = m.seams(20);
    let sc = Scene::new::<_, Box<dyn cadmorph::CadDocument>>(
        Input { model: &m, seams: &seams, source: path.into() },
        None,
        None,
        1e-7 * m.size(),
        0.01,
    )
    .unwrap();
    let drawn = sc.before.faces.iter().map(|f| mesh_area(&f.mesh)).collect();
    // What was drawn before faces were trimmed: the whole grid of the parameter box.
    let whole = m.patches().iter().map(|p| mesh_area(&face_mesh(p, grid_size(&p.surface)))).collect();
    let trimmed = sc.before.faces.iter().map(|f| f.trimmed).collect();
    (drawn, whole, trimmed)
}

/// OCCT 7.9.3's area of each face (`BRepGProp::SurfaceProperties_s` per face, as
/// `tests/occt/occt_ref.py validate samples/mixed_solid.stp` prints in `face_areas`;
/// the ignored test below asks OCCT again).
const OCCT_FACE_AREAS: [f64; 14] = [
    480.0,
    720.0,
    1800.0,
    720.0,
    2246.0619599741003,
    480.0,
    402.78050448325394,
    143.63177796205005,
    143.63177796205017,
    402.7805044832538,
    287.26355590761705,
    527.78756580312,
    169.64600329384882,
    153.93804002589997,
];

/// The four faces cut inside their planes have their areas (OCCT's, and the closed
/// forms where the cut is a circle or an ellipse); every other face is its whole box.
#[test]
fn mixed_solid_faces_cut_inside_their_surfaces_have_their_area() {
    let (drawn, whole, trimmed) = drawn_areas("mixed_solid.stp");
    assert_eq!(drawn.len(), 14);
    // Face 4: the 60 × 40 top of the box less the hole of radius 7; face 12: the loft's
    // bottom ellipse (semi-axes 9 and 6); face 13: its top circle (radius 7).
    let exact = [(4, 60.0 * 40.0 - PI * 49.0), (12, PI * 9.0 * 6.0), (13, PI * 49.0)];
    for (k, a) in exact {
        assert!((OCCT_FACE_AREAS[k] - a).abs() < 1e-9 * a, "face {k}: OCCT {} vs {a}", OCCT_FACE_AREAS[k]);
    }
    for (k, o) in OCCT_FACE_AREAS.iter().enumerate() {
        let err = (drawn[k] - o).abs() / o;
        println!("face {k}: drawn {:.3}, OCCT {o:.3} ({:.2} %), whole box {:.3}", drawn[k], 100.0 * err, whole[k]);
        assert!(err < TRIMMED_AREA, "face {k}: drawn {} vs OCCT {o}", drawn[k]);
        let cut = [2, 4, 12, 13].contains(&k);
        assert_eq!(trimmed[k], cut, "face {k}");
        if cut {
            assert!((whole[k] - o) / o > 0.05, "face {k}: its box is larger than the face");
        } else {
            assert_eq!(drawn[k], whole[k], "face {k} fills its box");
        }
    }
}

/// Every face's drawn area against OCCT's (`BRepGProp::SurfaceProperties` of each face),
/// for the solid in STEP, IGES (trimmed surfaces 144) and IGES B-rep (510 faces).
#[test]
#[ignore = "needs the OCCT venv (bash tests/occt/setup.sh)"]
fn mixed_solid_drawn_areas_match_occt() {
    for file in ["mixed_solid.stp", "mixed_solid.igs", "mixed_solid_brep.igs"] {
        let (code, occt) = cadmorph_testkit::harness::validate(&sample(file), None);
        assert_eq!(code, 0, "{occt}");
        let occt: Vec<f64> = occt["face_areas"].as_array().unwrap().iter().map(|a| a.as_f64().unwrap()).collect();
        let (drawn, whole, trimmed) = drawn_areas(file);
        assert_eq!(occt.len(), drawn.len(), "{file}");
        for (k, ((d, w), o)) in drawn.iter().zip(&whole).zip(&occt).enumerate() {
            let err = (d - o).abs() / o;
            println!(
                "{file} face {k}: drawn {d:.3}, OCCT {o:.3} ({:.2} %), whole box {w:.3}, trimmed {}",
                100.0 * err,
                trimmed[k]
            );
            assert!(err < TRIMMED_AREA, "{file} face {k}: drawn {d} vs OCCT {o}");
        }
        // Every face whose box OCCT finds larger than the face is trimmed; the others are
        // their whole box.
        for (k, ((w, o), d)) in whole.iter().zip(&occt).zip(&drawn).enumerate() {
            if (w - o) / o > 0.05 {
                assert!(trimmed[k], "{file} face {k}: box {w}, OCCT {o}");
            } else if !trimmed[k] {
                assert_eq!(d, w, "{file} face {k}");
            }
        }
    }
}
