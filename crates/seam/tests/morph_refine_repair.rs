//! Refinement under a non-affine FFD keeps the hull's seams closed; repair closes the
//! defective seam exactly.

use cadmorph_morph::math::{Point3, Vector3};
use cadmorph_morph::{Deformation, Ffd};
use cadmorph_nurbs::NurbsSurface;
use cadmorph_seam::{
    deformed, make_compatible, measure_boundary, morph_error, refine_for, refine_seams, refine_uniform, repair,
    shared_boundaries, Face, RefineOptions, Scope, SeamRefineOptions, SeamReport,
};
use cadmorph_testkit::occt::reference;

fn patches(name: &str) -> Vec<NurbsSurface> {
    reference(name).faces.iter().map(|f| f.to_nurbs().expect("B-spline").expect("valid")).collect()
}

fn seams(p: &[NurbsSurface]) -> SeamReport {
    let refs: Vec<&NurbsSurface> = p.iter().collect();
    let edges = shared_boundaries(&refs, 0.145, 64, 0.9);
    let faces: Vec<Face> = p.iter().map(|s| Face { surface: s, reversed: false }).collect();
    SeamReport::new(edges.iter().map(|e| measure_boundary(&faces, e, 120)).collect())
}

/// A bow-dome-like FFD: a 4×3×3 lattice over the forward 60 % of the hull that pushes
/// the middle control points outwards and down (non-affine).
fn bulge() -> Ffd {
    let mut ffd =
        Ffd::try_new([4, 3, 3], Point3::new(40.0, -12.0, -2.0), Vector3::new(110.0, 24.0, 17.0), Vector3::zeros())
            .unwrap();
    for i in 1..3 {
        ffd.mu_mut().set(i, 2, 1, [0.0, 0.08, -0.05]);
        ffd.mu_mut().set(i, 0, 1, [0.0, -0.08, -0.05]);
        ffd.mu_mut().set(i, 1, 1, [0.03, 0.0, -0.06]);
    }
    ffd
}

/// The hull with the middle patch refined in v, as CAD patches often are: the two sides
/// of each seam then have different boundary control rows, so moving control points
/// alone opens the seams.
fn mismatched_hull() -> Vec<NurbsSurface> {
    let mut p = patches("hull3.igs");
    p[1].refine_v(&[0.13, 0.41, 0.77]).unwrap();
    p
}

#[test]
fn moving_control_points_alone_opens_the_seams() {
    let ffd = bulge();
    let moved: Vec<NurbsSurface> = mismatched_hull().iter().map(|s| deformed(s, &ffd)).collect();
    let r = seams(&moved);
    println!("{}", r.table());
    assert!(r.max_gap_closest > 1e-4, "expected an opened seam, got {}", r.max_gap_closest);
    assert!(r.max_g1_angle_deg > 0.01, "expected a normal jump, got {}", r.max_g1_angle_deg);
}

const LENGTH: f64 = 145.0;

/// Control points of all patches.
fn count(p: &[NurbsSurface]) -> usize {
    p.iter().map(|s| s.control_points().len()).sum()
}

fn edges_of(p: &[NurbsSurface]) -> Vec<cadmorph_seam::SharedBoundary> {
    let refs: Vec<&NurbsSurface> = p.iter().collect();
    shared_boundaries(&refs, 0.145, 64, 0.9)
}

/// The target: after refinement, max gap ≤ 1e-7 × hull length and G1 ≤ 0.01°,
/// with fewer control points than PyGeM's 30 knots per direction.
#[test]
fn seam_refinement_meets_the_target_with_fewer_points_than_uniform() {
    let ffd = bulge();
    let tol = 1e-7 * LENGTH;
    for (name, mut p) in [("hull3", patches("hull3.igs")), ("mismatched", mismatched_hull())] {
        let edges = edges_of(&p);
        let before = count(&p);
        let compat = make_compatible(&mut p, &edges).unwrap();
        let r = refine_seams(&mut p, &edges, &ffd, &SeamRefineOptions::new(tol, 0.01));
        assert!(r.converged, "{name}: {r:?}");
        let moved: Vec<NurbsSurface> = p.iter().map(|s| deformed(s, &ffd)).collect();
        let after = seams(&moved);
        println!("{name}: +{compat} for compatible knots, {r:?}\n{}", after.table());
        assert!(after.max_gap_closest <= tol && after.max_gap_matched <= tol, "{name}: {}", after.max_gap_matched);
        assert!(after.max_g1_angle_deg <= 0.01, "{name}: G1 {}", after.max_g1_angle_deg);
        let mut uniform = patches("hull3.igs");
        if name == "mismatched" {
            uniform = mismatched_hull();
        }
        for s in &mut uniform {
            refine_uniform(s, 30).unwrap();
        }
        let moved: Vec<NurbsSurface> = uniform.iter().map(|s| deformed(s, &ffd)).collect();
        let baseline = seams(&moved);
        println!("{name}: uniform 30 knots, {} control points\n{}", count(&uniform), baseline.table());
        assert!(count(&p) < count(&uniform), "{name}: {} ≥ {}", count(&p), count(&uniform));
        assert!(count(&p) > before, "{name}: the morph bends at the seams, so some knots are needed");
    }
}

/// The per-round records: one per round and the input, control points growing from the
/// input's count to the final one, the last row the report's own final numbers, and the
/// gap growth falling below the tolerance exactly in the last round.
#[test]
fn refinement_records_every_round() {
    let ffd = bulge();
    let tol = 1e-5 * LENGTH;
    let mut p = mismatched_hull();
    let edges = edges_of(&p);
    let before = count(&p);
    let r = refine_seams(&mut p, &edges, &ffd, &SeamRefineOptions::new(tol, 0.05));
    assert!(r.converged && r.rounds >= 2, "{r:?}");
    assert_eq!(r.per_round.len(), r.rounds + 1);
    assert!(r.per_round.iter().enumerate().all(|(k, x)| x.round == k));
    assert_eq!(r.per_round[0].control_points, before);
    assert!(r.per_round.windows(2).all(|w| w[1].control_points > w[0].control_points), "{:?}", r.per_round);
    let last = r.per_round.last().unwrap();
    assert_eq!(last.control_points, r.control_points_after);
    assert_eq!(last.control_points, count(&p));
    assert_eq!(
        (last.max_gap, last.max_angle_deg, last.max_gap_growth, last.max_angle_growth_deg),
        (r.max_gap, r.max_angle_deg, r.max_gap_growth, r.max_angle_growth_deg)
    );
    assert!(r.per_round[..r.rounds].iter().all(|x| x.max_gap_growth > tol || x.max_angle_growth_deg > 0.05));
    assert!(last.max_gap_growth <= tol && last.max_angle_growth_deg <= 0.05, "{last:?}");
}

/// Without making the knots compatible first, the gap criterion alone also converges
/// (by refining along the edges), at a higher cost.
#[test]
fn gap_refinement_alone_closes_mismatched_seams() {
    let ffd = bulge();
    let tol = 1e-5 * LENGTH;
    let mut p = mismatched_hull();
    let edges = edges_of(&p);
    let r = refine_seams(&mut p, &edges, &ffd, &SeamRefineOptions::new(tol, 0.05));
    assert!(r.converged, "{r:?}");
    let moved: Vec<NurbsSurface> = p.iter().map(|s| deformed(s, &ffd)).collect();
    assert!(seams(&moved).max_gap_matched <= tol);
}

/// The single-patch refinement makes the whole patch follow the exact morph.
#[test]
fn patch_refinement_follows_the_morph_everywhere() {
    let ffd = bulge();
    let mut s = patches("hull3.igs").remove(1);
    let before = morph_error(&s, &ffd, 5);
    let mut opts = RefineOptions::new(1e-3);
    opts.scope = Scope::Everywhere;
    let r = refine_for(&mut s, &ffd, &opts);
    assert!(r.converged, "{r:?}");
    assert!(before > 1e-2 && morph_error(&s, &ffd, 7) <= 1.5e-3, "{before} -> {r:?}");
}

#[test]
fn zero_morph_needs_no_refinement() {
    let ffd =
        Ffd::try_new([3, 3, 3], Point3::new(-1.0, -12.0, -2.0), Vector3::new(150.0, 24.0, 17.0), Vector3::zeros())
            .unwrap();
    let mut s = patches("hull3.igs").remove(1);
    let before = s.clone();
    let r = refine_for(&mut s, &ffd, &RefineOptions::new(1e-12));
    assert!(r.converged && r.rounds == 0 && r.max_error < 1e-12, "{r:?}");
    assert_eq!(s, before);
    assert!(ffd.deformed(s.control_points()) == s.control_points());
}

#[test]
fn repair_closes_the_defect_seam_exactly() {
    let mut p = patches("hull3_defect.igs");
    let refs: Vec<&NurbsSurface> = p.iter().collect();
    let edges = shared_boundaries(&refs, 0.145, 64, 0.9);
    let bad = *edges.iter().find(|e| e.a.patch == 1 && e.b.patch == 2).expect("mid/bow seam");
    let (left, right) = p.split_at_mut(2);
    let (a, b) = (&mut left[1], &mut right[0]);
    let before_a = a.clone();
    let rep = repair(a, b, &bad, true).unwrap();
    assert!(rep.max_move > 0.01, "the 32.7 mm matched gap is split between the sides: {rep:?}");
    let r = seams(&p);
    println!("{}", r.table());
    let length = 145.0;
    let e = r.edges.iter().find(|e| e.a.patch == 1 && e.b.patch == 2).unwrap();
    assert!(e.gap_matched.max <= 1e-12 * length, "matched gap {}", e.gap_matched.max);
    assert!(e.gap_closest.max <= 1e-12 * length, "closest gap {}", e.gap_closest.max);
    assert!(e.g1_angle_deg.max <= 1e-6, "G1 {}", e.g1_angle_deg.max);
    // The far side of the repaired patch did not move.
    let unchanged = r.edges.iter().find(|e| e.a.patch == 0).unwrap();
    assert!(unchanged.gap_closest.max < 1e-12 * length);
    use cadmorph_nurbs::Surface;
    assert!((p[1].eval(0.0, 0.5) - before_a.eval(0.0, 0.5)).norm() < 1e-12);
}
