//! Profiles against BladeX's test arrays (`tests/test_profiles.py` and the former
//! `tests/test_profilebase.py` at BladeX 0c84eab / b73269c^): each array must be
//! reproduced to 1e-10.

mod common;

use cadmorph_blade::{naca, NacaOptions, NacaSpacing, Profile};
use common::{max_diff, npy};

/// The claim of the issue: BladeX arrays reproduced to 1e-10.
const BLADEX_MATCH: f64 = 1e-10;

fn check(p: &Profile, stem: &str, suffix: &str) {
    for (side, v) in [("xup", &p.xup), ("yup", &p.yup), ("xdown", &p.xdown), ("ydown", &p.ydown)] {
        let name = format!("{stem}_{side}{suffix}.npy");
        let (_, want) = npy(&name);
        let d = max_diff(v, &want);
        assert!(d <= BLADEX_MATCH, "{name}: max difference {d:e}");
    }
}

fn opts(spacing: NacaSpacing) -> NacaOptions {
    NacaOptions { n_points: 240, spacing, closed_trailing_edge: true }
}

#[test]
fn naca_0012_symmetric() {
    check(&naca("0012", opts(NacaSpacing::Cosine)).unwrap(), "naca4_0012", "");
}

#[test]
fn naca_2412_cosine_and_linear() {
    check(&naca("2412", opts(NacaSpacing::Cosine)).unwrap(), "naca4_2412", "_cosine");
    check(&naca("2412", opts(NacaSpacing::Linear)).unwrap(), "naca4_2412", "_linear");
}

#[test]
fn naca_00012_symmetric_five_digit() {
    check(&naca("00012", opts(NacaSpacing::Cosine)).unwrap(), "naca5_00012", "");
}

#[test]
fn naca_23012_cosine_and_linear() {
    check(&naca("23012", opts(NacaSpacing::Cosine)).unwrap(), "naca5_23012", "_cosine");
    check(&naca("23012", opts(NacaSpacing::Linear)).unwrap(), "naca5_23012", "_linear");
}

#[test]
fn naca_23112_reflex() {
    check(&naca("23112", opts(NacaSpacing::Cosine)).unwrap(), "naca5_23112", "");
}

#[test]
fn unit_circle_rbf_interpolation() {
    // BladeX test_profilebase.create_sample_profile_3: 250 points of the unit circle,
    // interpolate_coordinates(num=500, radius=10).
    let x: Vec<f64> = cadmorph_blade::spline1d::linspace(-1.0, 1.0, 250);
    let yu: Vec<f64> = x.iter().map(|x| (1.0 - x * x).sqrt()).collect();
    let yd: Vec<f64> = yu.iter().map(|y| -y).collect();
    let p = Profile::try_new(x.clone(), yu, x, yd).unwrap();
    let [xu, xd, yu, yd] = p.interpolate_coordinates(500, 10.0).unwrap();
    for (name, v) in [("xup", &xu), ("xdown", &xd)] {
        let (_, want) = npy(&format!("interp_{name}_unit_circle.npy"));
        assert!(max_diff(v, &want) <= BLADEX_MATCH, "{name}");
    }
    // The y arrays come from a 250×250 Wendland system of radius 10 (condition number
    // ~1e17): BladeX's own test only asks 5 decimals of them, and no two LU codes agree
    // beyond that, so this is the claim checked here (the RBF interpolates the circle
    // to that accuracy).
    for (name, v) in [("yup", &yu), ("ydown", &yd)] {
        let (_, want) = npy(&format!("interp_{name}_unit_circle.npy"));
        let d = max_diff(v, &want);
        assert!(d <= 1e-5, "{name}: {d:e}");
    }
}

#[test]
fn bladex_profile_measurements() {
    // BladeX test_profiles.TestBaseProfileMethods.
    let p = naca("2412", NacaOptions::default()).unwrap();
    assert!((p.max_thickness(None).unwrap() - 0.12).abs() < 1e-4);
    let mut q = p.clone();
    q.set_thickness_max(0.24).unwrap();
    assert!((q.max_thickness(None).unwrap() - 0.24).abs() < 1e-4);
    let c = naca("3412", NacaOptions::default()).unwrap();
    assert!((c.max_camber(None).unwrap() - 0.03).abs() < 1e-4);
    let mut d = c.clone();
    d.set_camber_line_max(0.05).unwrap();
    assert!((d.max_camber(None).unwrap() - 0.05).abs() < 1e-4);
}
