//! Volume- and barycentre-keeping FFD on the planing-hull sample: a bulb-like FFD at the
//! bow; the kept quantities measured on the morphed faces, and (ignored tests) by OCCT on
//! the written file.

use cadmorph_hull::{enclosed, keep, Error, Keep};
use cadmorph_model::{Model, MorphOptions};
use cadmorph_morph::math::{Point3, Vector3};
use cadmorph_morph::{Ffd, LinearInParameters};
use cadmorph_testkit::{harness, sample};

type StepModel = Model<cadmorph_step::Document>;

fn hull() -> StepModel {
    StepModel::open(&sample("planing_hull.stp")).unwrap()
}

/// A 3×3×3 lattice over the bow's bottom (x 7 .. 10.5, z −0.3 .. 0.9): the two middle
/// nodes of the front face pushed forward and down, a bulb.
fn bulb() -> (Ffd, Vec<bool>) {
    let mut ffd =
        Ffd::try_new([3, 3, 3], Point3::new(7.0, -1.5, -0.3), Vector3::new(3.5, 3.0, 1.2), Vector3::zeros()).unwrap();
    ffd.mu_mut().set(2, 1, 0, [0.12, 0.0, -0.15]);
    ffd.mu_mut().set(2, 1, 1, [0.10, 0.0, -0.05]);
    // Free: the nodes the user moved (the others keep the lattice joined to the hull).
    let n = ffd.n_params() / 3;
    let mut free = vec![false; 3 * n];
    for node in [ffd.mu().index(2, 1, 0), ffd.mu().index(2, 1, 1)] {
        for c in 0..3 {
            free[c * n + node] = true;
        }
    }
    (ffd, free)
}

fn occt_volume(path: &std::path::Path) -> (bool, f64, [f64; 3]) {
    let p = harness::solid_properties(path);
    (p.valid, p.volume, p.centre)
}

#[test]
fn keep_volume_on_the_morphed_faces() {
    let mut m = hull();
    let (ffd, free) = bulb();
    let what = Keep { volume: true, barycentre: false, volume_factor: 1.0 };
    let (kept, report) = keep(m.patches(), m.bound_curves(), m.size(), &ffd, what, Some(&free)).unwrap();
    let v0 = report.before.volume;
    let raw = (report.unconstrained.volume - v0) / v0;
    assert!(raw.abs() > 5e-4, "the bulb must change the volume for the test to mean anything ({raw:e})");
    m.morph(&kept, &MorphOptions::default()).unwrap();
    let after = enclosed(m.patches(), m.bound_curves(), m.size()).unwrap().total.volume;
    let rel = (after - v0).abs() / v0;
    eprintln!(
        "bulb: unconstrained ΔV/V {raw:.3e}, kept {rel:.3e}, |Δμ| {:.4}, {} Newton steps",
        report.change, report.iterations
    );
    assert!(rel <= 1e-12, "{rel:e}");
}

#[test]
#[ignore = "needs the OCCT venv (bash tests/occt/setup.sh)"]
fn keep_volume_measured_by_occt() {
    let mut m = hull();
    let (ffd, free) = bulb();
    let (v0_occt, c0_occt) = {
        let (ok, v, c) = occt_volume(&sample("planing_hull.stp"));
        assert!(ok);
        (v, c)
    };
    let dir = std::env::temp_dir().join(format!("cadmorph-hull-keep-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (name, what) in [
        ("volume", Keep { volume: true, barycentre: false, volume_factor: 1.0 }),
        ("volume_barycentre", Keep { volume: true, barycentre: true, volume_factor: 1.0 }),
    ] {
        let mut mm = hull();
        let n = ffd.n_params() / 3;
        // Keeping the barycentre as well needs more freedom: all nodes of the front face.
        let mut free = free.clone();
        if what.barycentre {
            for j in 0..3 {
                for k in 0..2 {
                    for c in 0..3 {
                        free[c * n + ffd.mu().index(2, j, k)] = true;
                    }
                }
            }
        }
        let (kept, _) = keep(mm.patches(), mm.bound_curves(), mm.size(), &ffd, what, Some(&free)).unwrap();
        mm.morph(&kept, &MorphOptions::default()).unwrap();
        let path = dir.join(format!("bulb_{name}.stp"));
        mm.save(&path).unwrap();
        let (ok, v, c) = occt_volume(&path);
        let rel = (v - v0_occt).abs() / v0_occt;
        eprintln!("{name}: OCCT valid {ok}, OCCT ΔV/V {rel:.3e}, centre {c:?} (before {c0_occt:?})");
        assert!(ok, "OCCT finds the morphed hull invalid");
        assert!(rel <= 1e-9, "{name}: OCCT volume change {rel:e}");
        if what.barycentre {
            for k in 0..3 {
                assert!((c[k] - c0_occt[k]).abs() <= 1e-9 * 10.0, "centroid {k}: {} vs {}", c[k], c0_occt[k]);
            }
        }
    }
    // The unconstrained bulb, for contrast.
    m.morph(&ffd, &MorphOptions::default()).unwrap();
    let path = dir.join("bulb_raw.stp");
    m.save(&path).unwrap();
    let (_, v, _) = occt_volume(&path);
    assert!((v - v0_occt).abs() / v0_occt > 5e-4);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn impossible_constraints_fail_clearly() {
    let m = hull();
    let (ffd, free) = bulb();
    let what = Keep { volume: true, barycentre: false, volume_factor: 1.0 };
    // All displacements fixed.
    let none = vec![false; free.len()];
    let e = keep(m.patches(), m.bound_curves(), m.size(), &ffd, what, Some(&none)).unwrap_err();
    assert!(e.to_string().contains("every displacement is fixed"), "{e}");
    // Halving the hull's volume with two bow nodes: out of reach.
    let e = keep(m.patches(), m.bound_curves(), m.size(), &ffd, Keep { volume_factor: 0.5, ..what }, Some(&free))
        .unwrap_err();
    assert!(matches!(e, Error::Constraint(cadmorph_morph::Error::Infeasible(_))), "{e}");
    eprintln!("{e}");
    // A lattice reaching the transom (a trimmed plane).
    let mut aft =
        Ffd::try_new([2, 2, 2], Point3::new(-0.5, -2.0, -0.5), Vector3::new(2.0, 4.0, 3.0), Vector3::zeros()).unwrap();
    aft.mu_mut().set(1, 1, 1, [0.1, 0.0, 0.0]);
    let e = keep(m.patches(), m.bound_curves(), m.size(), &aft, what, None).unwrap_err();
    assert!(matches!(e, Error::MovesTrimmedFace { .. }), "{e}");
}
