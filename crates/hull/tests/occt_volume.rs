//! Exact enclosed volume against OCCT `BRepGProp::VolumeProperties` (adaptive Gauss,
//! Eps 1e-12, `tests/occt/planing_hull.py volume`).

use std::path::{Path, PathBuf};
use std::process::Command;

use cadmorph_brep::CadDocument;
use cadmorph_hull::{enclosed, Enclosed, FaceMethod};
use cadmorph_model::Model;
use cadmorph_testkit::{harness, sample};

fn open(path: &Path) -> Enclosed {
    let bytes = std::fs::read(path).unwrap();
    if bytes.starts_with(b"ISO-10303-21") {
        let m: Model<cadmorph_step::Document> = Model::from_bytes(&bytes).unwrap();
        of(&m)
    } else {
        let m: Model<cadmorph_iges::Document> = Model::from_bytes(&bytes).unwrap();
        of(&m)
    }
}

fn of<D: CadDocument>(m: &Model<D>) -> Enclosed {
    enclosed(m.patches(), m.bound_curves(), m.size()).unwrap()
}

/// OCCT's volume, centre of mass and face area of the solid in `path`.
pub fn occt_volume(path: &Path) -> (f64, [f64; 3], f64) {
    let p = harness::solid_properties(path);
    assert!(p.valid, "OCCT finds {} invalid", path.display());
    assert_eq!(p.solids, 1, "{}", path.display());
    (p.volume, p.centre, p.area)
}

fn compare(path: &Path, rel: f64) -> Enclosed {
    let ours = open(path);
    let (v, c, a) = occt_volume(path);
    let err = (ours.total.volume - v).abs() / v;
    let area_err = (ours.total.area - a).abs() / a;
    let centroid = ours.total.centroid();
    eprintln!(
        "{}: cadmorph {:.15e}, OCCT {:.15e}, relative {err:.2e}; area {:.15e} vs {a:.15e}, relative {area_err:.2e}; \
         centroid {centroid:?} vs {c:?}",
        path.display(),
        ours.total.volume,
        v,
        ours.total.area
    );
    assert!(err <= rel, "{}: relative volume difference {err:e}", path.display());
    // The area integrand |S_u × S_v| is not polynomial, so neither side is exact; both
    // converge far below this.
    assert!(area_err <= rel, "{}: relative area difference {area_err:e}", path.display());
    let scale = v.cbrt();
    for k in 0..3 {
        assert!((centroid[k] - c[k]).abs() <= 1e-8 * scale, "centroid {k}: {} vs {}", centroid[k], c[k]);
    }
    ours
}

/// The figures OCCT gave when the samples were made (the ignored tests below measure
/// them again), so that plain `cargo test` checks the integration too.
#[test]
fn recorded_occt_volumes() {
    for (name, occt, occt_area, planar) in [
        ("planing_hull.stp", 40.41889533333262, 84.49921197609802, 2),
        ("mixed_solid.stp", 33515.302782352825, 8677.521689895158, 4),
    ] {
        let e = open(&sample(name));
        let err = (e.total.volume - occt).abs() / occt;
        assert!(err <= 1e-8, "{name}: {} vs OCCT {occt} ({err:e})", e.total.volume);
        let err = (e.total.area - occt_area).abs() / occt_area;
        assert!(err <= 1e-10, "{name}: area {} vs OCCT {occt_area} ({err:e})", e.total.area);
        assert_eq!(e.methods.iter().filter(|m| **m == FaceMethod::Planar).count(), planar, "{name}");
    }
}

#[test]
#[ignore = "needs the OCCT venv (bash tests/occt/setup.sh)"]
fn planing_hull_volume_matches_occt() {
    compare(&sample("planing_hull.stp"), 1e-8);
    compare(&sample("planing_hull.igs"), 1e-8);
}

#[test]
#[ignore = "needs the OCCT venv (bash tests/occt/setup.sh)"]
fn mixed_solid_volume_matches_occt() {
    compare(&sample("mixed_solid.stp"), 1e-8);
    // IGES faces without a B-rep carry no orientation of their own: each is taken with
    // its surface's IGES normal. The solid's surface of revolution (a 120 under a
    // reflecting 124) is built as OCCT builds it, with the IGES normal S_t × S_θ, which
    // points out of the material here: no face needs turning.
    let e = compare(&sample("mixed_solid.igs"), 1e-8);
    assert!(e.turned.is_empty(), "{:?}", e.turned);
    // The B-rep IGES twin: its cylinder is bounded by two circles and the seam line, loops
    // that close only across the periodic seam, and is integrated over its parameter box.
    let e = compare(&sample("mixed_solid_brep.igs"), 1e-8);
    assert!(e.methods.iter().any(|m| matches!(m, FaceMethod::Rectangle(_))), "{:?}", e.methods);
}

fn blade_solid(dir: &Path) -> PathBuf {
    use cadmorph_blade::export::step_solids;
    use cadmorph_blade::{BladeSolid, DesignTable};
    let table = sample("blade/tutorial.toml");
    let t = DesignTable::read(&table).unwrap();
    let blade = t.blade().unwrap();
    let coords = blade.apply_transformations(t.reflect).unwrap();
    let solid = BladeSolid::from_coordinates(&coords, t.loft.u_degree, t.loft.v_degree).unwrap();
    let tol = 2e-9 * blade.radii[blade.len() - 1];
    let bytes = step_solids(&t.name, &[solid.faces()], t.unit, tol).unwrap();
    let path = dir.join("blade_solid.stp");
    std::fs::write(&path, bytes).unwrap();
    path
}

#[test]
#[ignore = "needs the OCCT venv (bash tests/occt/setup.sh)"]
fn blade_solid_volume_matches_occt() {
    let dir = std::env::temp_dir().join(format!("cadmorph-hull-blade-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = blade_solid(&dir);
    let e = compare(&path, 1e-8);
    assert!(e.methods.iter().all(|m| *m == FaceMethod::Natural));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
#[ignore = "needs the OCCT venv (bash tests/occt/setup.sh)"]
fn curved_face_trimmed_inside_its_surface_matches_occt() {
    // tests/occt/trimmed_solid.py: a B-spline bump trimmed by a turned square (lines that
    // are no iso-lines of it), planes around it; made by OCCT, in STEP and IGES.
    let dir = std::env::temp_dir().join(format!("cadmorph-hull-trimmed-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (stp, igs) = (dir.join("bump.stp"), dir.join("bump.igs"));
    let out = Command::new(harness::python())
        .arg(harness::root().join("tests/occt/trimmed_solid.py"))
        .args([&stp, &igs])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    for path in [&stp, &igs] {
        let e = compare(path, 1e-8);
        assert_eq!(e.methods.iter().filter(|m| **m == FaceMethod::Trimmed).count(), 1, "{}", path.display());
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Solids as OCCT's own writers make them (`tests/occt/writer_solids.py make DIR --more`:
/// a turned fillet box, a torus, a capsule, a cone, a nose of revolution with two poles,
/// a 270° ring sector; each as STEP, IGES B-rep and IGES faces). Before the seam moves,
/// the pole-bounded iso boxes and the STEP faces bounded by vertex loops alone, every
/// IGES B-rep face on a sphere, cone or torus that reached its surface's seam was refused,
/// and the STEP nose could not be read.
#[test]
#[ignore = "needs the OCCT venv (bash tests/occt/setup.sh)"]
fn solids_from_occt_writers_match_occt() {
    let dir = std::env::temp_dir().join(format!("cadmorph-hull-writers-{}", std::process::id()));
    let out = Command::new(harness::python())
        .arg(harness::root().join("tests/occt/writer_solids.py"))
        .args(["make", dir.to_str().unwrap(), "--more"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let mut reseamed = Vec::new();
    for name in ["fillet_box", "torus", "capsule", "cone", "nose", "ring_sector"] {
        for form in [".stp", "_brep.igs", "_faces.igs"] {
            // OCCT sews no solid from the one face of the IGES-faces torus and nose
            // (its volume reads 0); the B-spline extrusion is left out as a volume
            // oracle, see the closing note of issue 22 (OCCT's GProp is 4.6 % off there).
            if form == "_faces.igs" && (name == "torus" || name == "nose") {
                continue;
            }
            let path = dir.join(format!("{name}{form}"));
            let e = if form == "_faces.igs" {
                // OCCT sews these faces at 1e-6 and its centre of mass moves by up to
                // 2e-6 of its own STEP solid's (capsule); cadmorph's stays within 2e-9
                // of it. Volume and area against OCCT on the same file, the centroid
                // against OCCT's STEP solid.
                let ours = open(&path);
                let (v, _, a) = occt_volume(&path);
                let (_, c, _) = occt_volume(&dir.join(format!("{name}.stp")));
                assert!((ours.total.volume - v).abs() <= 1e-8 * v, "{name}{form}: {} vs {v}", ours.total.volume);
                assert!((ours.total.area - a).abs() <= 1e-8 * a, "{name}{form}: area {} vs {a}", ours.total.area);
                let centroid = ours.total.centroid();
                for k in 0..3 {
                    assert!((centroid[k] - c[k]).abs() <= 1e-8 * v.cbrt(), "{name}{form}: {centroid:?} vs {c:?}");
                }
                ours
            } else {
                compare(&path, 1e-8)
            };
            if e.methods.iter().any(|m| matches!(m, FaceMethod::Reseamed { .. })) {
                reseamed.push(format!("{name}{form}"));
            }
        }
    }
    // The seam moves are what the fillet box's sphere octants and the torus need.
    assert!(reseamed.contains(&"fillet_box_brep.igs".to_owned()), "{reseamed:?}");
    assert!(reseamed.contains(&"torus_brep.igs".to_owned()), "{reseamed:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}
