//! The mesh readers (crates/mesh) on arbitrary bytes: the first byte picks the format,
//! the rest is the file. Reading never panics; an accepted file writes back to a file that
//! reads again and writes back to the same bytes.
#![no_main]

use cadmorph_mesh::format::{dyna, elmer, gmsh, mdpa, obj, stl, unv, vtk, vtu};
use libfuzzer_sys::fuzz_target;

/// `write(parse(write(x))) == write(x)` for an accepted `x`.
macro_rules! round_trip {
    ($parse:expr, $write:expr, $input:expr) => {
        if let Ok(m) = $parse($input) {
            let once = $write(&m);
            let again = $parse(&once).unwrap_or_else(|e| panic!("written file rejected: {e}"));
            assert!($write(&again) == once, "second write differs");
        }
    };
}

fuzz_target!(|data: &[u8]| {
    let Some((&kind, rest)) = data.split_first() else { return };
    match kind % 9 {
        0 => round_trip!(|b: &[u8]| stl::Stl::parse(b), |m: &stl::Stl| m.write(), rest),
        1 => round_trip!(|b: &[u8]| vtu::Vtu::parse(b), |m: &vtu::Vtu| m.write(), rest),
        k => {
            let Ok(text) = std::str::from_utf8(rest) else { return };
            match k {
                2 => round_trip!(|t: &str| gmsh::Msh::parse(t), |m: &gmsh::Msh| m.write(), text),
                3 => round_trip!(|t: &str| vtk::VtkLegacy::parse(t), |m: &vtk::VtkLegacy| m.write(), text),
                4 => round_trip!(|t: &str| obj::Obj::parse(t), |m: &obj::Obj| m.write(), text),
                5 => round_trip!(|t: &str| unv::Unv::parse(t), |m: &unv::Unv| m.write(), text),
                6 => round_trip!(|t: &str| dyna::KeywordFile::parse(t), |m: &dyna::KeywordFile| m.write(), text),
                7 => round_trip!(|t: &str| mdpa::Mdpa::parse(t), |m: &mdpa::Mdpa| m.write(), text),
                _ => round_trip!(|t: &str| elmer::ElmerNodes::parse(t), |m: &elmer::ElmerNodes| m.write(), text),
            }
        }
    }
});
