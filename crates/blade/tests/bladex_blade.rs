//! Wrapped and transformed blade sections against BladeX's arrays
//! (`tests/test_blade.py::create_sample_blade_NACA` at BladeX 0c84eab): 1e-10.

mod common;

use cadmorph_blade::{naca, Blade, BladeCoordinates, NacaOptions};
use common::npy;

const BLADEX_MATCH: f64 = 1e-10;

/// BladeX's sample blade: ten NACA 0012 sections, radii 0.4..1.3.
pub fn sample_blade() -> Blade {
    let sections = (0..10).map(|_| naca("0012", NacaOptions::default()).unwrap()).collect();
    let radii: Vec<f64> = (0..10).map(|i| 0.4 + i as f64 * 0.1).collect();
    let chord = vec![0.55, 0.7, 0.85, 1.0, 1.03, 1.0, 0.97, 0.94, 0.91, 0.3];
    let pitch = vec![3.0, 3.2, 3.4, 3.6, 3.8, 4.1, 3.9, 3.7, 3.5, 3.3];
    let rake = vec![0.005, 0.015, 0.025, 0.035, 0.045, 0.055, 0.065, 0.075, 0.075, 0.045];
    let skew = vec![-4.0, -7.0, -7.0, -4.0, -1.0, 2.0, 5.0, 8.0, 11.0, 14.0];
    Blade::try_new(sections, radii, chord, pitch, rake, skew).unwrap()
}

/// BladeX stores `(n_sections, 3, n_points)` with the tip section first.
fn compare(c: &BladeCoordinates, up: &str, down: &str) {
    for (side, name) in [(&c.up, up), (&c.down, down)] {
        let (shape, want) = npy(name);
        assert_eq!(shape, vec![10, 3, 240], "{name}");
        let mut worst: f64 = 0.0;
        for s in 0..10 {
            let sec = &side[9 - s];
            for k in 0..3 {
                for j in 0..240 {
                    worst = worst.max((sec[j][k] - want[(s * 3 + k) * 240 + j]).abs());
                }
            }
        }
        assert!(worst <= BLADEX_MATCH, "{name}: {worst:e}");
    }
}

#[test]
fn planar_to_cylindrical() {
    compare(
        &sample_blade().planar_to_cylindrical(),
        "planar_to_cylindrical_blade_up.npy",
        "planar_to_cylindrical_blade_down.npy",
    );
}

#[test]
fn transformations_reflect() {
    compare(
        &sample_blade().apply_transformations(true).unwrap(),
        "blade_up_after_transformation_reflect.npy",
        "blade_down_after_transformation_reflect.npy",
    );
}

#[test]
fn transformations_no_reflect() {
    compare(
        &sample_blade().apply_transformations(false).unwrap(),
        "blade_up_after_transformation_no_reflect.npy",
        "blade_down_after_transformation_no_reflect.npy",
    );
}

#[test]
fn wrapped_points_lie_on_their_cylinders() {
    let b = sample_blade();
    let c = b.apply_transformations(true).unwrap();
    for (i, s) in c.up.iter().chain(c.down.iter()).enumerate() {
        let r = b.radii[i % 10];
        for p in s {
            assert!((p.y.hypot(p.z) - r).abs() <= 1e-14 * r);
        }
    }
}
