//! OCCT's view of morphed solids and hulls (`tests/occt/edge_check.py`): the written file
//! is valid with the input's faces, shells and solids; the written edge curves lie on
//! their faces as far as the "after" report says (and within 1e-7 of the size where the
//! morph keeps the faces joined); repair keeps the solid valid and its 28 creases, and
//! the area change it reports is OCCT's.

use std::path::{Path, PathBuf};
use std::process::Command;

use cadmorph_model::{CadDocument, Model, MorphOptions};
use cadmorph_morph::math::{Point3, Vector3};
use cadmorph_morph::Ffd;
use cadmorph_seam::SeamRefineOptions;
use cadmorph_testkit::{harness, sample};
use serde_json::Value;

fn edge_check(file: &Path) -> Value {
    let mut c = Command::new(harness::python());
    c.arg(harness::root().join("tests/occt/edge_check.py")).arg(file);
    let out = c.output().expect("edge_check.py starts");
    serde_json::from_slice(&out.stdout)
        .unwrap_or_else(|e| panic!("edge_check.py: {e}\n{}", String::from_utf8_lossy(&out.stderr)))
}

fn open(name: &str) -> Model {
    let bytes = std::fs::read(sample(name)).unwrap();
    let doc: Box<dyn CadDocument> = if name.ends_with(".stp") {
        Box::new(cadmorph_step::Document::parse(&bytes).unwrap())
    } else {
        Box::new(cadmorph_iges::Document::parse(&bytes).unwrap())
    };
    Model::new(doc).unwrap()
}

struct Scratch(PathBuf);
impl Scratch {
    fn new(name: &str) -> Self {
        let d = std::env::temp_dir().join(format!("cadmorph-occt-solids-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        Scratch(d)
    }
}
impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// `../shared/repro/box.toml`: a 2x2x2 box, its top corner raised (non-affine).
fn box2() -> Ffd {
    let mut f =
        Ffd::try_new([2, 2, 2], Point3::new(-40.0, -30.0, -10.0), Vector3::new(80.0, 60.0, 20.0), Vector3::zeros())
            .unwrap();
    f.mu_mut().set(1, 1, 1, [0.0, 0.0, 0.2]);
    f
}

/// A 3x3x3 box around the whole solid, its centre node moved 5 % of the diagonal.
fn box3() -> Ffd {
    let mut f =
        Ffd::try_new([3, 3, 3], Point3::new(-35.0, -25.0, -10.0), Vector3::new(70.0, 50.0, 40.0), Vector3::zeros())
            .unwrap();
    f.mu_mut().set(1, 1, 1, [0.0322, 0.0451, 0.0564]);
    f
}

/// The FFD for real files: a 3×3×3 lattice around the model's control points
/// (5 % of the size beyond them), its centre node moved by 5 % of the diagonal.
fn real_file_ffd(m: &Model) -> Ffd {
    let size = m.size();
    let b = cadmorph_nurbs::Aabb::from_points(m.patches().iter().flat_map(|p| p.surface.control_points())).unwrap();
    let (lo, hi) = (b.min - Vector3::repeat(0.05 * size), b.max + Vector3::repeat(0.05 * size));
    let mut f = Ffd::try_new([3, 3, 3], lo, hi - lo, Vector3::zeros()).unwrap();
    let step = 0.05 * size / 3f64.sqrt();
    f.mu_mut().set(1, 1, 1, [step / (hi.x - lo.x), step / (hi.y - lo.y), step / (hi.z - lo.z)]);
    f
}

/// Morphs `m` (the sample `name`) by [`real_file_ffd`] with seam refinement at 1e-5 of
/// its size and 0.01°, and checks that the refinement converges with fewer control
/// points than PyGeM's 30-knot refinement of the same file and passes the seam check.
/// Returns the tolerance.
fn refine_below_pygem(name: &str, m: &mut Model) -> f64 {
    let f = real_file_ffd(m);
    let mut baseline = open(name);
    baseline.morph(&f, &MorphOptions { uniform_knots: Some(30), ..Default::default() }).unwrap();
    let pygem: usize = baseline.patches().iter().map(|p| p.surface.control_points().len()).sum();
    let tol = 1e-5 * m.size();
    let out =
        m.morph(&f, &MorphOptions { refine: Some(SeamRefineOptions::new(tol, 0.01)), ..Default::default() }).unwrap();
    let r = out.refinement.as_ref().unwrap();
    println!(
        "{name}: {} -> {} control points in {} rounds (PyGeM's 30 knots: {pygem})",
        r.control_points_before, r.control_points_after, r.rounds
    );
    assert!(r.converged, "{name}: {r:?}");
    assert!(r.control_points_after < pygem, "{name}: {} vs {pygem}", r.control_points_after);
    let check = cadmorph_seam::SeamCheck::new(&out.seams_before, &out.seams_after, tol, 0.01);
    assert_eq!(check.failed, 0, "{name}\n{}", out.seams_after.table());
    tol
}

#[test]
#[ignore = "needs the OCCT venv (bash tests/occt/setup.sh)"]
fn morphed_and_repaired_solids_stay_valid_with_their_topology_and_creases() {
    let s = Scratch::new("solids");
    for name in ["mixed_solid.stp", "mixed_solid_brep.igs", "mixed_solid.igs"] {
        let input = edge_check(&sample(name));
        let topo = |v: &Value, k: &str| v["topology"][k].as_u64().unwrap();
        for (which, d) in [("2x2x2", box2()), ("3x3x3", box3())] {
            for repair in [false, true] {
                let what = format!("{name} {which} repair {repair}");
                let mut m = open(name);
                let size = m.size();
                let out = m.morph(&d, &MorphOptions { repair, ..Default::default() }).unwrap();
                let path = s.0.join(format!("{which}-{repair}-{name}"));
                m.save(&path).unwrap();
                let r = edge_check(&path);
                println!(
                    "{what}: valid {} {} edge-to-face {:.3e}, after max gap {:.3e}, sharp {}",
                    r["valid"],
                    r["topology"],
                    r["edge_to_face_max"].as_f64().unwrap(),
                    out.seams_after.max_gap_closest,
                    out.seams_after.sharp_edges
                );
                assert_eq!(r["valid"], true, "{what}");
                for k in ["solids", "shells", "faces"] {
                    assert_eq!(topo(&r, k), topo(&input, k), "{what}: {k}");
                }
                // IGES faces mode included: the in-plane faces' loops are closed again.
                assert_eq!(topo(&r, "edges"), topo(&input, "edges"), "{what}: edges");
                // The 28 creases of the input stay creases, repaired or not.
                assert_eq!(out.seams_before.sharp_edges, 28, "{what}");
                if name == "mixed_solid.igs" && which == "3x3x3" {
                    // Known: without topology the edges are paired from the trimming
                    // curves within 1e-3 of the size (0.076 mm); the unrefined bilinear
                    // planes open 0.34 mm gaps, so some pairs are lost (22 of 28 creases
                    // found). A tripwire: when pairing holds, make the test strict.
                    assert!(out.seams_after.sharp_edges < 28, "{what}: all creases found now: assert it");
                } else {
                    assert_eq!(out.seams_after.sharp_edges, 28, "{what}");
                }
                if let Some(rep) = &out.repair {
                    // Only the smooth shared iso edge of two B-spline faces (the prism's
                    // rounded side) is repaired; the creases are left as the morph makes them.
                    assert!(rep.edges_repaired <= 1 && rep.sharp_kept > 0, "{what}: {rep:?}");
                }
                // The written edge curves lie on one of their faces and are as far from
                // the other as the after report says.
                let e2f = r["edge_to_face_max"].as_f64().unwrap();
                assert!(
                    e2f <= out.seams_after.max_gap_closest * (1.0 + 1e-3) + 1e-7 * size,
                    "{what}: {e2f} vs {}",
                    out.seams_after.max_gap_closest
                );
            }
        }
    }
}

#[test]
#[ignore = "needs the OCCT venv (bash tests/occt/setup.sh)"]
fn refined_hulls_have_edge_curves_on_their_faces_and_the_repair_reports_its_area_change() {
    let s = Scratch::new("hulls");
    let bow = Ffd::from_prm(&std::fs::read_to_string(sample("prm/bow_dome.prm")).unwrap()).unwrap();
    for name in ["hull3_defect.stp", "hull3_defect.igs"] {
        for repair in [false, true] {
            let what = format!("{name} repair {repair}");
            let input = edge_check(&sample(name));
            let mut m = open(name);
            let size = m.size();
            let opts =
                MorphOptions { refine: Some(SeamRefineOptions::new(1.45e-5, 0.01)), repair, ..Default::default() };
            let out = m.morph(&bow, &opts).unwrap();
            assert!(out.refinement.as_ref().unwrap().converged, "{what}");
            let path = s.0.join(format!("{repair}-{name}"));
            m.save(&path).unwrap();
            let r = edge_check(&path);
            let area = r["area"].as_f64().unwrap();
            println!(
                "{what}: valid {}, edge-to-face {:.3e} (1e-7 size {:.3e}), area {area:.9}",
                r["valid"],
                r["edge_to_face_max"].as_f64().unwrap(),
                1e-7 * size,
            );
            assert_eq!(r["valid"], true, "{what}");
            assert_eq!(r["topology"], input["topology"], "{what}");
            assert!(r["edge_to_face_max"].as_f64().unwrap() <= 1e-7 * size, "{what}");
            if repair {
                let rep = out.repair.as_ref().unwrap();
                let change = rep.area_after - rep.area_before;
                let plain = {
                    let mut m = open(name);
                    let opts = MorphOptions { refine: opts.refine, ..Default::default() };
                    m.morph(&bow, &opts).unwrap();
                    let p = s.0.join(format!("plain-{name}"));
                    m.save(&p).unwrap();
                    edge_check(&p)["area"].as_f64().unwrap()
                };
                // The reported change is OCCT's: the repaired file's area minus the
                // unrepaired one's (faces trimmed to their boundaries).
                assert!((area - plain - change).abs() <= 1e-6 * area, "{what}: {} vs {change}", area - plain);
            }
        }
    }
}

/// The 3×3×3 FFD with seam refinement at the default 0.01°: the faces are raised to quadratic
/// before the refinement is planned, so it converges within the default budget (on the
/// bilinear planes and ruled sides the normals converged only as the span: at 1e-5 of
/// the size it needed 112 246 control points, now 23 626, the angle driving the count);
/// the written solid is valid with the input's topology and its 28 creases, its edge
/// curves on their faces within the tolerance.
#[test]
#[ignore = "needs the OCCT venv (bash tests/occt/setup.sh)"]
fn refined_3x3x3_morph_of_the_solid_converges_within_the_default_budget() {
    let s = Scratch::new("refined3");
    let name = "mixed_solid.stp";
    let input = edge_check(&sample(name));
    let mut m = open(name);
    let size = m.size();
    let before: usize = m.patches().iter().map(|p| p.surface.control_points().len()).sum();
    let mut refine = SeamRefineOptions::new(1e-5 * size, 0.01);
    refine.max_control_points = SeamRefineOptions::default_budget(before);
    let out = m.morph(&box3(), &MorphOptions { refine: Some(refine), ..Default::default() }).unwrap();
    let r = out.refinement.as_ref().unwrap();
    println!("{} -> {} control points in {} rounds", r.control_points_before, r.control_points_after, r.rounds);
    assert!(r.converged, "{r:?}");
    assert!(r.control_points_after < 30_000, "{}", r.control_points_after);
    assert_eq!(out.seams_after.sharp_edges, 28);
    assert!(out.seams_after.max_gap_closest <= 1e-5 * size, "{}", out.seams_after.max_gap_closest);
    let path = s.0.join(name);
    m.save(&path).unwrap();
    let c = edge_check(&path);
    assert_eq!(c["valid"], true);
    assert_eq!(c["topology"], input["topology"]);
    assert!(c["edge_to_face_max"].as_f64().unwrap() <= 1e-5 * size, "{}", c["edge_to_face_max"]);
}

/// The 3×3×3 box with its centre node moved in x and z only: every plane y = const stays
/// in its plane (the solid's two faces at y = ±20 are re-bounded, not bent) while the
/// faces meeting them bend. Their common edges are lines, which stay straight when their
/// control points move: written so, the plane's edges stood 0.016–0.072 mm off the bent
/// neighbours (the after-check failed on every file; on an OCCT plate with holes 0.036 mm).
/// They are now traced on the bent face, for IGES's own trimming curves of the plane too;
/// each file converges, passes the seam check, and OCCT reads it valid with its
/// topology and its edge curves on their faces within the tolerance. At 1e-4 of the size
/// and 0.1° (four rounds; the old gaps are twice to eight times that tolerance).
#[test]
#[ignore = "needs the OCCT venv (bash tests/occt/setup.sh)"]
fn planes_kept_in_their_plane_stay_joined_to_the_faces_that_bend() {
    let s = Scratch::new("in_plane");
    for name in ["mixed_solid.stp", "mixed_solid.igs", "mixed_solid_brep.igs"] {
        let input = edge_check(&sample(name));
        let mut m = open(name);
        let size = m.size();
        let mut f =
            Ffd::try_new([3, 3, 3], Point3::new(-35.0, -25.0, -10.0), Vector3::new(70.0, 50.0, 40.0), Vector3::zeros())
                .unwrap();
        f.mu_mut().set(1, 1, 1, [0.0322, 0.0, 0.0564]);
        let tol = 1e-4 * size;
        let out = m
            .morph(&f, &MorphOptions { refine: Some(SeamRefineOptions::new(tol, 0.1)), ..Default::default() })
            .unwrap();
        let r = out.refinement.as_ref().unwrap();
        assert!(r.converged, "{name}: {r:?}");
        let check = cadmorph_seam::SeamCheck::new(&out.seams_before, &out.seams_after, tol, 0.1);
        assert_eq!(check.failed, 0, "{name}\n{}", out.seams_after.table());
        let path = s.0.join(name);
        m.save(&path).unwrap();
        let c = edge_check(&path);
        println!("{name}: {} in, {} out", input["topology"], c["topology"]);
        assert_eq!(c["valid"], true, "{name}");
        // IGES faces mode (144) too: OCCT builds each face's edges from its own trims and
        // fills a gap between two of them with an edge of its own; the in-plane faces'
        // loops are closed again after tracing (65 edges out before, 2e-4 mm gaps).
        assert_eq!(c["topology"], input["topology"], "{name}");
        assert!(c["edge_to_face_max"].as_f64().unwrap() <= tol, "{name}: {}", c["edge_to_face_max"]);
    }
}

/// The trimmed IGES shaft (surfaces of revolution placed by 124 transforms, metres) under
/// the FFD for real files (3×3×3, the centre node moved by 5 % of the diagonal)
/// with refinement at 1e-5 of the diagonal: the refinement converges with fewer control
/// points than PyGeM's 30-knot refinement and the written file passes the same seam
/// check. A trim crossing some hundred knot lines of a refined face ran the cubic fit out
/// of poles at 1e-7 of the size, and the curve fell back to its moved control points,
/// 5e-5 m off a fillet (0.5° at a plane–fillet edge). Refinement marked each side of a
/// trim edge whose normal strayed by more than half the angle tolerance even where the
/// edge as a whole kept within it (10 653 control points against PyGeM's 10 375); it now
/// marks only where the edge fails.
#[test]
#[ignore = "needs the OCCT venv (bash tests/occt/setup.sh)"]
fn refined_shaft_keeps_its_tangent_edges_and_stays_valid() {
    let s = Scratch::new("shaft");
    let name = "shaft.igs";
    let input = edge_check(&sample(name));
    let mut m = open(name);
    let tol = refine_below_pygem(name, &mut m);
    let path = s.0.join(name);
    m.save(&path).unwrap();
    let c = edge_check(&path);
    assert_eq!(c["valid"], true);
    assert_eq!(c["topology"]["faces"], input["topology"]["faces"]);
    assert!(c["edge_to_face_max"].as_f64().unwrap() <= tol, "{}", c["edge_to_face_max"]);
}

/// Assemblies and mapped items that place one part several times (the AP203 assembly: a
/// plate twice and a sub-assembly of two pins twice, in inches; a `MAPPED_ITEM` sample
/// whose part is also a root, placed alone and in two pairs) under the FFD for real files (3×3×3, the centre node
/// moved by 5 % of the diagonal; every placement moves its own way) with refinement at
/// 1e-5 of the diagonal. Each moved placement gets its own copy of the part, so the morph
/// is written instead of refused; it converges with fewer control points than PyGeM's
/// 30-knot refinement, passes the seam check, and OCCT reads the file valid with the
/// input's solids, shells, faces and edges, its edge curves on their faces.
#[test]
#[ignore = "needs the OCCT venv (bash tests/occt/setup.sh)"]
fn assemblies_with_repeated_parts_morph_each_placement_and_stay_valid() {
    let s = Scratch::new("assemblies");
    // (`assembly_ap214.stp` and `mapped_item.stp` hold the same parts as the two below;
    // cadmorph-step's `unshare` tests cover their copies.)
    for name in ["assembly_ap203.stp", "mapped_item_root.stp"] {
        let input = edge_check(&sample(name));
        let mut m = open(name);
        let tol = refine_below_pygem(name, &mut m);
        let path = s.0.join(name);
        m.save(&path).unwrap();
        let c = edge_check(&path);
        assert_eq!(c["valid"], true, "{name}");
        assert_eq!(c["topology"], input["topology"], "{name}");
        assert!(c["edge_to_face_max"].as_f64().unwrap() <= tol, "{name}: {}", c["edge_to_face_max"]);
        // Every placement moved: no two faces of the written file share a surface
        // across placements any more, and the face count is the input's.
        let again = open_path(&path);
        assert_eq!(again.patches().len(), m.patches().len(), "{name}");
    }
}

fn open_path(path: &Path) -> Model {
    let bytes = std::fs::read(path).unwrap();
    Model::new(Box::new(cadmorph_step::Document::parse(&bytes).unwrap()) as Box<dyn CadDocument>).unwrap()
}

/// The colours OCCT's XCAF reader gives each placed part (`tests/occt/color_check.py`), in
/// its walk order, without the label paths (copies are new products).
fn colours(file: &Path) -> Vec<Value> {
    let mut c = Command::new(harness::python());
    c.arg(harness::root().join("tests/occt/color_check.py")).arg(file);
    let out = c.output().expect("color_check.py starts");
    let v: Value = serde_json::from_slice(&out.stdout)
        .unwrap_or_else(|e| panic!("color_check.py: {e}\n{}", String::from_utf8_lossy(&out.stderr)));
    v["leaves"].as_array().unwrap().iter().map(|l| serde_json::json!([l["color"], l["faces"], l["styled"]])).collect()
}

/// An assembly with colours (cadquery-style XCAF: the plate red with its hole's face
/// green, the pins blue; every part placed twice) morphed so that every placement moves
/// its own way: the copies of the parts carry their styles (the solids' styled items and
/// the face's over-riding one, listed in the presentation representations), so OCCT reads
/// every placed part with the input's colours, and the file valid with its topology.
/// The morph bends the plates' tops while their sides stay in their planes.
#[test]
#[ignore = "needs the OCCT venv (bash tests/occt/setup.sh)"]
fn copied_parts_keep_their_colours() {
    let s = Scratch::new("colours");
    let name = "assembly_colors.stp";
    let input = sample(name);
    let mut m = open(name);
    let b = cadmorph_nurbs::Aabb::from_points(m.patches().iter().flat_map(|p| p.surface.control_points())).unwrap();
    let size = m.size();
    let (lo, hi) = (b.min - Vector3::repeat(0.05 * size), b.max + Vector3::repeat(0.05 * size));
    let mut f = Ffd::try_new([3, 3, 3], lo, hi - lo, Vector3::zeros()).unwrap();
    // The centre node moved in z only: the planes x = const and y = const of the plate's
    // sides stay in their planes and are re-bounded; their new sides stood 2.5e-3 in off
    // the bent top's, within the edge pairing tolerance, and were measured as
    // iso-boundaries (12 edges failed the after-check, nothing written). Refined to 1e-5
    // of the size, every edge holds.
    f.mu_mut().set(1, 1, 1, [0.0, 0.0, 0.05]);
    let tol = 1e-5 * size;
    let out =
        m.morph(&f, &MorphOptions { refine: Some(SeamRefineOptions::new(tol, 0.01)), ..Default::default() }).unwrap();
    assert!(out.refinement.as_ref().unwrap().converged);
    let check = cadmorph_seam::SeamCheck::new(&out.seams_before, &out.seams_after, tol, 0.01);
    assert_eq!(check.failed, 0, "{}", out.seams_after.table());
    let path = s.0.join(name);
    m.save(&path).unwrap();
    let (a, b) = (colours(&input), colours(&path));
    assert_eq!(a.len(), 6);
    assert_eq!(a, b);
    let surfaces: std::collections::HashSet<_> = m.patches().iter().map(|p| p.surface_entity).collect();
    assert_eq!(surfaces.len(), m.patches().len(), "every placement has its own surfaces");
    let c = edge_check(&path);
    assert_eq!(c["valid"], true);
    assert_eq!(c["topology"], edge_check(&input)["topology"]);
}

/// The area of a morphed solid against the area of its exact morph, both measured by
/// OCCT (`BRepGProp` on the written files). The reference is the exact FFD (`--exact`:
/// the Bernstein volume composed with every face) under a non-affine trilinear box that
/// holds the whole solid, so that every face is composed (a face crossing the box's side
/// would be morphed through its control points as without `--exact`, and its area would
/// be no reference). The plain control-point morph misses it by what the coarse nets
/// cannot follow (2e-4 of the area); with seam refinement at 1e-5 or 1e-6 of the size
/// the area is the exact morph's within 1e-6. OCCT integrates adaptively to 1e-10
/// (`edge_check.py`): its default Gauss rule is 3e-5 off on the degree-24 exact faces.
#[test]
#[ignore = "needs the OCCT venv (bash tests/occt/setup.sh)"]
fn refined_morph_area_approaches_the_exact_morph() {
    use cadmorph_model::{ExactFfd, Silent};
    let s = Scratch::new("area");
    // The 3x3x3 box's extent, 2x2x2, its top corner raised and pulled sideways.
    let mut f =
        Ffd::try_new([2, 2, 2], Point3::new(-35.0, -25.0, -10.0), Vector3::new(70.0, 50.0, 40.0), Vector3::zeros())
            .unwrap();
    f.mu_mut().set(1, 1, 1, [0.05, 0.05, 0.2]);
    for name in ["mixed_solid.stp", "mixed_solid_brep.igs"] {
        let area = |label: &str, morph: &dyn Fn(&mut Model, f64)| -> f64 {
            let mut m = open(name);
            let size = m.size();
            morph(&mut m, size);
            let path = s.0.join(format!("{label}-{name}"));
            m.save(&path).unwrap();
            let c = edge_check(&path);
            assert_eq!(c["valid"], true, "{name} {label}");
            c["area"].as_f64().unwrap()
        };
        let exact = area("exact", &|m, size| {
            let e = ExactFfd::new(&f, 1e-13 * size).unwrap();
            let (_, report) = m.morph_exact(&f, &e, &MorphOptions::default(), &Silent).unwrap();
            assert_eq!((report.exact_faces, report.other_faces), (14, 0), "{name}");
        });
        let plain = area("plain", &|m, _| {
            m.morph(&f, &MorphOptions::default()).unwrap();
        });
        let refined = |rel: f64| {
            area(&format!("refined{rel:e}"), &|m, size| {
                let r = Some(SeamRefineOptions::new(rel * size, 0.01));
                let out = m.morph(&f, &MorphOptions { refine: r, ..Default::default() }).unwrap();
                assert!(out.refinement.unwrap().converged, "{name}");
            })
        };
        let (r5, r6) = (refined(1e-5), refined(1e-6));
        let d = |a: f64| (a - exact).abs() / exact;
        println!(
            "{name}: exact area {exact:.9}; relative difference plain {:.2e}, refined 1e-5 {:.2e}, 1e-6 {:.2e}",
            d(plain),
            d(r5),
            d(r6)
        );
        // Measured: plain 2.0e-4; refined 1.5e-7 (1e-5) and 8e-8 (1e-6).
        assert!(d(plain) > 1e-5, "{name}: the plain morph is no test of the area");
        assert!(d(r5) <= 1e-6 && d(r6) <= 1e-6, "{name}");
    }
}

/// The exact FFD under the 3x3x3 lattice (`box3`): the degree-8 lofts' images need
/// degree 48 and are reduced to 25 within 1e-8 of the size. OCCT reads every written
/// file as valid with the input's solids, shells, faces and edges; every written edge
/// curve lies within 1e-7 of the size of its faces; the 28 creases stay; and the three
/// files, one solid written three ways, give one area within 1e-6.
#[test]
#[ignore = "needs the OCCT venv (bash tests/occt/setup.sh)"]
fn exact_3x3x3_morph_reduced_to_degree_25_is_valid_with_its_edges_on_its_faces() {
    use cadmorph_model::{ExactFfd, Silent};
    let s = Scratch::new("exact333");
    let f = box3();
    let mut areas = Vec::new();
    for name in ["mixed_solid.stp", "mixed_solid_brep.igs", "mixed_solid.igs"] {
        let input = edge_check(&sample(name));
        let topo = |v: &Value, k: &str| v["topology"][k].as_u64().unwrap();
        let mut m = open(name);
        let size = m.size();
        let e = ExactFfd::new(&f, 1e-8 * size).unwrap();
        let (out, report) = m.morph_exact(&f, &e, &MorphOptions::default(), &Silent).unwrap();
        assert_eq!((report.exact_faces, report.other_faces), (14, 0), "{name}");
        assert!(report.reduction_bound > 0.0 && report.reduction_bound <= 1e-8 * size, "{name}: {report:?}");
        let path = s.0.join(format!("exact333-{name}"));
        m.save(&path).unwrap();
        let r = edge_check(&path);
        println!(
            "{name}: valid {} {} edge-to-face {:.3e} (1e-7 size {:.3e}), area {}, reduction {:.3e}",
            r["valid"],
            r["topology"],
            r["edge_to_face_max"].as_f64().unwrap(),
            1e-7 * size,
            r["area"],
            report.reduction_bound
        );
        assert_eq!(r["valid"], true, "{name}");
        for k in ["solids", "shells", "faces", "edges"] {
            assert_eq!(topo(&r, k), topo(&input, k), "{name}: {k}");
        }
        assert!(r["edge_to_face_max"].as_f64().unwrap() <= 1e-7 * size, "{name}");
        assert_eq!(out.seams_before.sharp_edges, 28, "{name}");
        assert_eq!(out.seams_after.sharp_edges, 28, "{name}");
        areas.push(r["area"].as_f64().unwrap());
    }
    // The three files hold the same solid: their exact morphs have one area.
    for a in &areas[1..] {
        assert!((a - areas[0]).abs() <= 1e-6 * areas[0], "{areas:?}");
    }
}
