//! Hostile parameter files (issue 13): sizes that would wrap or exhaust memory are refused
//! with the parameter and the bytes they would need; bad bytes and bad centres are named.
//! The files are the reproducers in `tests/repro/` (see its README).

use cadmorph_morph::math::{Point3, Vector3};
use cadmorph_morph::rbf::Kernel;
use cadmorph_morph::{budget, Error, Parameters, Rbf};

fn repro(name: &str) -> Vec<u8> {
    std::fs::read(cadmorph_testkit::repro(name)).unwrap()
}

#[test]
fn repro_lattice_that_wraps_to_zero_nodes_is_refused() {
    // 2^32 × 2^32 × 2 nodes: the product wraps to 0 in usize.
    let err = Parameters::from_bytes(&repro("latwrap.prm"), false).unwrap_err();
    match &err {
        Error::TooLarge { what, needed, .. } => {
            assert!(what.contains("4294967296x4294967296x2"), "{what}");
            assert_eq!(*needed, (1u128 << 65) * 3 * 8);
        }
        other => panic!("expected TooLarge, got {other}"),
    }
    assert!(err.to_string().contains("FFD lattice"), "{err}");
}

#[test]
fn repro_petabyte_lattices_are_refused_before_allocating() {
    for (name, toml) in [("lathuge.prm", false), ("huge.toml", true)] {
        let err = Parameters::from_bytes(&repro(name), toml).unwrap_err();
        assert!(matches!(err, Error::TooLarge { .. }), "{name}: {err}");
        let msg = err.to_string();
        assert!(msg.contains("100000x100000x100000") && msg.contains("PB"), "{name}: {msg}");
    }
}

#[test]
fn repro_non_utf8_parameter_file_names_the_byte() {
    let bytes = repro("ffd_nonutf8.prm");
    let bad = std::str::from_utf8(&bytes).unwrap_err().valid_up_to();
    let line = bytes[..bad].iter().filter(|&&b| b == b'\n').count() + 1;
    let err = Parameters::from_bytes(&bytes, false).unwrap_err();
    assert_eq!(err, Error::Encoding { offset: bad, line });
    assert!(err.to_string().starts_with(&format!("byte {bad} (line {line})")), "{err}");
}

#[test]
fn repro_coincident_rbf_centres_are_named() {
    let Parameters::Rbf(p) = Parameters::from_bytes(&repro("rbf_coincident.prm"), false).unwrap() else {
        panic!("an RBF file")
    };
    // Centres 3 and 8 (0-based) are both (60, 15, 15).
    let err = Rbf::from_parameters(&p).unwrap_err();
    assert_eq!(err, Error::CoincidentCentres { first: 3, second: 8, point: [60.0, 15.0, 15.0] });
    assert!(err.to_string().contains("centres 3 and 8"), "{err}");
}

#[test]
fn toml_errors_give_the_line_of_the_key_itself() {
    // `k` is given to a kernel that takes none; the line is that of `k`, not of `kernel`
    // (which starts with the same letter) nor of a `k` in a comment or another table.
    let text = "# k is explained below\n[rbf]\nkernel = \"gaussian_spline\"\nradius = 0.5\n\nk = 3\noriginal_control_points = [[0.0, 0.0, 0.0]]\ndeformed_control_points = [[0.0, 0.0, 0.0]]\n";
    let err = Parameters::from_toml(text).unwrap_err();
    assert!(matches!(err, Error::UnknownParameter { line: 6, .. }), "{err}");
    // A bad radius written with dotted keys, after the control points.
    let text = "rbf.kernel = \"gaussian_spline\"\nrbf.original_control_points = []\nrbf.deformed_control_points = []\nrbf.radius = -1.0\n";
    let err = Parameters::from_toml(text).unwrap_err();
    assert!(matches!(err, Error::InvalidParameter { line: Some(4), .. }), "{err}");
}

/// The one test that changes the process-wide budget (tests of a binary run in parallel,
/// so every budget-dependent check is here, in sequence, and the default is restored).
#[test]
fn budget_limits_lattices_and_dense_rbf_systems() {
    budget::set_limit(1 << 20);
    let small = Parameters::from_bytes(&repro("ok.prm"), false).map(|_| ());
    let big = budget::check("x", &[200, 200, 200, 3], 8);
    // 20 000 Gaussian centres need a 3.2 GB system (three times that with the fallback's
    // factor): with a 1 GB budget the build is refused before assembly, naming the size.
    let n = 20_000;
    let centres: Vec<Point3<f64>> =
        (0..n).map(|i| Point3::new((i % 100) as f64, ((i / 100) % 100) as f64, (i / 10_000) as f64)).collect();
    let moves = vec![Vector3::zeros(); n];
    budget::set_limit(1_000_000_000);
    let rbf = Rbf::try_new(&centres, &moves, Kernel::Gaussian { radius: 1.0 });
    budget::set_limit(0);
    assert!(small.is_ok(), "a 3x3x3 lattice fits 1 MiB");
    assert!(matches!(big, Err(Error::TooLarge { limit: 1048576, .. })));
    assert_eq!(budget::limit(), budget::default_limit());
    match rbf {
        Err(Error::TooLarge { what, needed, limit }) => {
            assert!(what.contains("20000 centres"), "{what}");
            assert_eq!(needed, ((n + 4) * (n + 4) * 3 * 8) as u128);
            assert_eq!(limit, 1_000_000_000);
        }
        Err(e) => panic!("expected TooLarge, got {e}"),
        Ok(_) => panic!("expected TooLarge, got a solved system"),
    }
}

/// Found by `scripts/fuzz` (params_toml): a five-value `box_length` was read as its first
/// three values. Arrays of the wrong length are refused at their line.
#[test]
fn toml_arrays_of_the_wrong_length_are_refused() {
    let text =
        "[ffd]\nn_control_points = [8, 3, 2]\nbox_origin = [-18.0, -30, -1.0]\nbox_length = [4, 20, 600.0, 0.0, 0.2]\n";
    let err = Parameters::from_toml(text).unwrap_err();
    assert!(matches!(err, Error::Toml { line: 4, .. }), "{err}");
    assert!(err.to_string().contains("exactly three"), "{err}");
    let text = "[ffd]\nn_control_points = [3, 3]\nbox_origin = [0.0, 0.0, 0.0]\nbox_length = [1.0, 1.0, 1.0]\n";
    assert!(matches!(Parameters::from_toml(text), Err(Error::Toml { line: 2, .. })));
    let text = "[idw]\nvariant = \"paper\"\npower = 2.0\noriginal_control_points = [[0.0, 0.0, 0.0, 9.0]]\ndeformed_control_points = [[0.0, 0.0, 0.1]]\n";
    let err = Parameters::from_toml(text).unwrap_err();
    assert!(matches!(err, Error::Toml { line: 4, .. }) && err.to_string().contains("point 0 has 4"), "{err}");
}
