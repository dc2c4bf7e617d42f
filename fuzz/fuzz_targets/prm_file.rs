//! The PyGeM `.prm` reader on arbitrary bytes: reading never panics, and an accepted file
//! writes back to a file that reads again and writes back to the same text.
#![no_main]

use cadmorph_morph::{budget, Parameters};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    // A small budget: a fuzzer-made lattice of millions of nodes is refused, not built.
    budget::set_limit(64 << 20);
    let Ok(params) = Parameters::from_bytes(data, false) else {
        return;
    };
    let _ = params.to_toml();
    if let Ok(written) = params.to_prm() {
        let again = Parameters::from_prm(&written).unwrap_or_else(|e| panic!("written file rejected: {e}\n{written}"));
        assert_eq!(again.to_prm().ok().as_deref(), Some(written.as_str()), "second write differs");
    }
});
