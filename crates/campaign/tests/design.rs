//! The design space, the samplers and the manifest: bad files refused with line and
//! field, Sobol' against the published Joe–Kuo construction, Latin hypercube strata,
//! seeded reproducibility, exact sensitivities, active subspaces of a known ridge.

use std::path::{Path, PathBuf};

use cadmorph_campaign::active::{active_subspace, Fit};
use cadmorph_campaign::online::{Base, Basis};
use cadmorph_campaign::sampler::{lhs, sobol, Criterion};
use cadmorph_campaign::{sensitivity, DesignSpace, Manifest};

fn samples() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../samples")
}

fn bow_dome() -> PathBuf {
    samples().join("campaigns/bow_dome.toml")
}

/// The bow-dome campaign with `edit` applied to its text, parsed as if it sat beside the
/// original (so relative paths resolve).
fn edited(edit: impl Fn(String) -> String) -> cadmorph_campaign::Result<DesignSpace> {
    let text = edit(std::fs::read_to_string(bow_dome()).unwrap());
    DesignSpace::parse(&bow_dome(), &text)
}

fn line_of(text: &str, needle: &str) -> usize {
    text.lines().position(|l| l.contains(needle)).unwrap() + 1
}

#[test]
fn bad_campaign_files_are_refused_with_line_and_field() {
    let text = std::fs::read_to_string(bow_dome()).unwrap();
    // A lattice node that does not exist (the lattice is 5 x 4 x 4).
    let e = edited(|t| t.replace("mu_y[2,1,1]", "mu_y[2,4,1]")).unwrap_err().to_string();
    let line = line_of(&text, "mu_y[2,1,1]");
    assert!(e.contains(&format!("line {line}, field `parameter[1].entry`")), "{e}");
    assert!(e.contains("5 x 4 x 4"), "{e}");
    // An empty range.
    let e = edited(|t| t.replace("range = [0.0, 0.04]", "range = [0.04, 0.04]")).unwrap_err().to_string();
    let line = line_of(&text, "range = [0.0, 0.04]");
    assert!(e.contains(&format!("line {line}, field `parameter[5].range`")), "{e}");
    assert!(e.contains("empty range"), "{e}");
    // An empty set, an RBF entry on an FFD, a second binding of one entry, a bad method,
    // an unknown field, a zero count.
    for (from, to, field) in [
        ("range = [-0.08, 0.0]", "set = []", "parameter[2].set"),
        ("mu_z[2,1,1]", "d_z[2]", "parameter[3].entry"),
        ("mu_z[3,1,1]", "mu_z[2,1,1]", "parameter[4].entry"),
        ("method = \"lhs\"", "method = \"lhc\"", "sampling.method"),
        ("seed = 5415", "seed = 5415\nsede = 1", "sede"),
        ("n = 130", "n = 0", "sampling.n"),
    ] {
        let e = edited(|t| t.replacen(from, to, 1)).unwrap_err().to_string();
        assert!(e.contains(&format!("field `{field}`")), "{from} -> {to}: {e}");
        assert!(e.contains(": line "), "{e}");
        assert!(!e.contains("line 0"), "{e}");
    }
    // A shard K >= N.
    let e = cadmorph_campaign::Shard::parse("13/13").unwrap_err().to_string();
    assert_eq!(e, "--shard: K = 13 must be below N = 13 (K counts from 0)");
}

/// Sobol' points from the published table of Joe & Kuo (new-joe-kuo-6.21201, its first
/// rows `d s a m_i`), built here independently of the crate: direction numbers by the
/// recurrence of Joe & Kuo's notes (eq. (2) of "Notes on generating Sobol' sequences",
/// 2008), point i in Gray-code order as their generator gives it.
fn joe_kuo_reference(n: usize) -> Vec<Vec<u32>> {
    // d = 1 has all m_k = 1; then d = 2..6.
    let table: [(u32, u32, &[u32]); 5] =
        [(1, 0, &[1]), (2, 1, &[1, 3]), (3, 1, &[1, 3, 1]), (3, 2, &[1, 1, 1]), (4, 1, &[1, 1, 3, 3])];
    let mut dirs: Vec<[u32; 33]> = Vec::new();
    let mut v = [0u32; 33];
    for k in 1..=32 {
        v[k] = 1 << (32 - k);
    }
    dirs.push(v);
    for &(s, a, m) in &table {
        let s = s as usize;
        let mut v = [0u32; 33];
        for k in 1..=32 {
            if k <= s {
                v[k] = m[k - 1] << (32 - k);
            } else {
                v[k] = v[k - s] ^ (v[k - s] >> s);
                for j in 1..s {
                    if (a >> (s - 1 - j)) & 1 == 1 {
                        v[k] ^= v[k - j];
                    }
                }
            }
        }
        dirs.push(v);
    }
    (0..n)
        .map(|i| {
            let gray = i ^ (i >> 1);
            dirs.iter().map(|v| (1..=32).filter(|&k| (gray >> (k - 1)) & 1 == 1).fold(0u32, |x, k| x ^ v[k])).collect()
        })
        .collect()
}

#[test]
fn sobol_points_equal_the_published_joe_kuo_sequence() {
    let ours = sobol::integer_points(1024, 6);
    assert_eq!(ours, joe_kuo_reference(1024));
    // The first points of dimensions 1 and 2 as Joe & Kuo's program prints them.
    let unit = sobol::points(8, 2, None);
    let d1: Vec<f64> = unit.iter().map(|p| p[0]).collect();
    let d2: Vec<f64> = unit.iter().map(|p| p[1]).collect();
    assert_eq!(d1, [0.0, 0.5, 0.75, 0.25, 0.375, 0.875, 0.625, 0.125]);
    assert_eq!(d2, [0.0, 0.5, 0.25, 0.75, 0.375, 0.875, 0.125, 0.625]);
}

#[test]
fn scrambled_sobol_keeps_the_net_property_and_is_seeded() {
    // Dimensions 1-2 of Sobol' are a (0, m, 2)-net in base 2: every elementary interval
    // [i/2^a, (i+1)/2^a) x [j/2^b, (j+1)/2^b) with a + b = m holds exactly one of 2^m
    // points. Owen scrambling keeps that.
    let m = 8;
    let pts = sobol::points(1 << m, 2, Some(42));
    for a in 0..=m {
        let b = m - a;
        let mut seen = vec![0u32; 1 << m];
        for p in &pts {
            let i = (p[0] * (1u64 << a) as f64) as usize;
            let j = (p[1] * (1u64 << b) as f64) as usize;
            seen[(i << b) | j] += 1;
        }
        assert!(seen.iter().all(|&c| c == 1), "a = {a}");
    }
    assert_eq!(pts, sobol::points(1 << m, 2, Some(42)));
    assert_ne!(pts, sobol::points(1 << m, 2, Some(43)));
    assert_ne!(pts, sobol::points(1 << m, 2, None));
}

#[test]
fn latin_hypercube_strata_each_hold_one_point() {
    for criterion in [Criterion::None, Criterion::Maximin, Criterion::Correlation] {
        let rows = lhs::latin_hypercube(130, 6, 5415, criterion, 10);
        assert_eq!(rows.len(), 130);
        for j in 0..6 {
            let mut strata: Vec<usize> = rows.iter().map(|r| (r[j] * 130.0) as usize).collect();
            strata.sort_unstable();
            assert_eq!(strata, (0..130).collect::<Vec<_>>(), "{criterion:?}, column {j}");
        }
        assert_eq!(rows, lhs::latin_hypercube(130, 6, 5415, criterion, 10));
    }
    // The criteria pick what they promise among the same candidates.
    let plain = lhs::latin_hypercube(60, 4, 9, Criterion::None, 10);
    let maximin = lhs::latin_hypercube(60, 4, 9, Criterion::Maximin, 10);
    let corr = lhs::latin_hypercube(60, 4, 9, Criterion::Correlation, 10);
    assert!(lhs::min_distance(&maximin) >= lhs::min_distance(&plain));
    assert!(lhs::max_correlation(&corr) <= lhs::max_correlation(&plain));
}

#[test]
fn manifest_is_byte_for_byte_reproducible_from_the_seed() {
    let space = DesignSpace::read(&bow_dome()).unwrap();
    let a = Manifest::plan(&space);
    let b = Manifest::plan(&DesignSpace::read(&bow_dome()).unwrap());
    assert_eq!(a.variants.len(), 130);
    assert_eq!(a.to_csv(), b.to_csv());
    assert_eq!(a.to_json(), b.to_json());
    // Values within their ranges; every variant's input hash distinct.
    for v in &a.variants {
        for (x, p) in v.values.iter().zip(&space.parameters) {
            let (lo, hi) = p.values.bounds();
            assert!(*x >= lo && *x <= hi);
        }
    }
    let mut hashes: Vec<&str> = a.variants.iter().map(|v| v.input_sha256.as_str()).collect();
    hashes.sort_unstable();
    hashes.dedup();
    assert_eq!(hashes.len(), 130);
    // Another seed, another plan; the JSON reads back with the same variants.
    let other = edited(|t| t.replace("seed = 5415", "seed = 5416")).unwrap();
    assert_ne!(Manifest::plan(&other).to_csv(), a.to_csv());
    let back: Manifest = serde_json::from_str(&a.to_json()).unwrap();
    assert_eq!(back.variants.iter().map(|v| &v.input_sha256).collect::<Vec<_>>(), hashes_in_order(&a));
    // Every other sampler is seeded and reproducible too.
    for method in [
        "method = \"random\"",
        "method = \"sobol\"",
        "method = \"full_factorial\"\nlevels = 2",
        "method = \"one_at_a_time\"\nlevels = 3",
    ] {
        let s = edited(|t| t.replace("method = \"lhs\"", method).replace("criterion = \"maximin\"\n", "")).unwrap();
        assert_eq!(Manifest::plan(&s).to_csv(), Manifest::plan(&s).to_csv(), "{method}");
    }
    let ff = edited(|t| t.replace("method = \"lhs\"", "method = \"full_factorial\"\nlevels = 2")).unwrap();
    assert_eq!(Manifest::plan(&ff).variants.len(), 64);
    let oat = edited(|t| t.replace("method = \"lhs\"", "method = \"one_at_a_time\"\nlevels = 3")).unwrap();
    assert_eq!(Manifest::plan(&oat).variants.len(), 1 + 6 * 2);
}

#[test]
fn control_point_jacobian_is_exact_against_finite_differences() {
    let space = DesignSpace::read(&bow_dome()).unwrap();
    let model = cadmorph::open(&space.geometry).unwrap();
    let points: Vec<_> = model.patches().iter().flat_map(|p| p.surface.control_points().iter().copied()).collect();
    let base = Base::new(&space.deformation).unwrap();
    let basis = Basis::new(&base, &space.parameters, points);
    let exact = sensitivity::jacobian(&basis);
    let mu: Vec<f64> = space.parameters.iter().map(|p| p.values.base()).collect();
    let fd = sensitivity::finite_differences(&space, &base, &basis, &mu, 1e-3).unwrap();
    // The map is linear in mu: central differences are exact up to rounding of
    // coordinates of size ~150 m divided by 2h (150 · 1e-16 / 2e-3 ≈ 1e-11).
    let scale = exact.abs().max();
    assert!(scale > 1.0, "the bow-dome parameters move the hull: {scale}");
    assert!((&exact - &fd).abs().max() < 1e-9 * scale, "{}", (&exact - &fd).abs().max());
    // And the online product agrees with the deformation itself at a variant.
    let v = &Manifest::plan(&space).variants[7];
    let online = basis.control_points(&v.values);
    let mut theta = base.theta();
    for (p, x) in space.parameters.iter().zip(&v.values) {
        theta[p.theta] = *x;
    }
    let d = base.with_theta(&theta).unwrap();
    for (p, q) in basis.points.iter().zip(&online) {
        assert!((d.deformation().deform_point(p) - q).norm() < 1e-12 * 150.0);
    }
}

fn hashes_in_order(m: &Manifest) -> Vec<&String> {
    m.variants.iter().map(|v| &v.input_sha256).collect()
}

/// `w` normalised.
fn unit(w: &[f64]) -> Vec<f64> {
    let n = w.iter().map(|x| x * x).sum::<f64>().sqrt();
    w.iter().map(|x| x / n).collect()
}

#[test]
fn active_subspace_recovers_a_one_dimensional_ridge() {
    let names: Vec<String> = (0..6).map(|i| format!("p{i}")).collect();
    // Ranges of different sizes: directions are in the normalised inputs z in [-1, 1].
    let bounds: Vec<(f64, f64)> = (0..6).map(|i| (-0.1 * (i + 1) as f64, 0.2 * (i + 1) as f64)).collect();
    let w = unit(&[0.6, -0.3, 0.5, 0.1, -0.45, 0.3]);
    let x = lhs::latin_hypercube(200, 6, 3, Criterion::Maximin, 5)
        .into_iter()
        .map(|u| u.iter().zip(&bounds).map(|(t, (lo, hi))| lo + t * (hi - lo)).collect::<Vec<f64>>())
        .collect::<Vec<_>>();
    let z = |r: &[f64]| -> f64 {
        r.iter().zip(&bounds).zip(&w).map(|((v, (lo, hi)), wi)| wi * (2.0 * (v - lo) / (hi - lo) - 1.0)).sum()
    };
    let cosine = |d: &[f64]| d.iter().zip(&w).map(|(a, b)| a * b).sum::<f64>().abs();
    for (g, fit) in [
        (Box::new(|t: f64| t * t + 0.5 * t) as Box<dyn Fn(f64) -> f64>, Fit::Quadratic),
        (Box::new(|t: f64| (0.7 * t).exp()), Fit::Quadratic),
        (Box::new(|t: f64| (0.7 * t).exp()), Fit::LocalLinear { neighbours: 14 }),
        (Box::new(|t: f64| (t + 0.3).sin()), Fit::LocalLinear { neighbours: 14 }),
    ] {
        let f: Vec<f64> = x.iter().map(|r| g(z(r))).collect();
        let a = active_subspace(&names, &bounds, &x, &f, fit).unwrap();
        let c = cosine(&a.directions[0]);
        assert!(1.0 - c < 1e-3, "{fit:?}: cosine {c}");
        // One dominant eigenvalue.
        assert!(a.eigenvalues[1] < 1e-2 * a.eigenvalues[0], "{fit:?}: {:?}", a.eigenvalues);
    }
    // Too few points for a quadratic in six parameters (28 coefficients).
    let e = active_subspace(&names, &bounds, &x[..20], &[0.0; 20], Fit::Quadratic).unwrap_err();
    assert!(e.to_string().contains("at least 28 points"), "{e}");
}
