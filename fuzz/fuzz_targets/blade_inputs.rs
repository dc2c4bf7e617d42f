//! The blade crate's readers on arbitrary bytes: BladeX `.prm` parameter files (and their
//! TOML form), custom profile CSV files and TOML design tables. Reading never panics and
//! never allocates without bound; an accepted parameter file writes back to a text that
//! reads again to the same values.
//!
//! The first byte chooses the reader, the rest is its input.
#![no_main]

use std::path::Path;

use cadmorph_blade::{DesignTable, ParamFile, Profile};
use cadmorph_morph::budget;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    // A small budget: a fuzzer-made profile of millions of points is refused, not built.
    budget::set_limit(64 << 20);
    let Some((&which, rest)) = data.split_first() else {
        return;
    };
    let Ok(text) = std::str::from_utf8(rest) else {
        return;
    };
    match which % 4 {
        0 => {
            if let Ok(p) = ParamFile::parse(text, "fuzz.prm") {
                let written = p.to_text();
                let again = ParamFile::parse(&written, "written.prm")
                    .unwrap_or_else(|e| panic!("written file rejected: {e}\n{written}"));
                assert_eq!(again.to_text(), written, "second write differs");
            }
        }
        1 => {
            if let Ok(p) = ParamFile::from_toml(text, "fuzz.toml") {
                let _ = p.to_toml();
            }
        }
        2 => {
            let _ = Profile::from_csv(text);
        }
        _ => {
            // Relative profile paths point into a folder that does not exist.
            if let Ok(t) = DesignTable::parse(text, Path::new("/nonexistent-fuzz-base")) {
                let _ = t.to_toml();
            }
        }
    }
});
