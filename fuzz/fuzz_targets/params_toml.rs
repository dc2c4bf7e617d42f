//! The TOML parameter reader on arbitrary bytes: reading never panics nor allocates past
//! the memory budget, and accepted parameters write back to TOML that reads to the same
//! parameters.
#![no_main]

use cadmorph_morph::{budget, Parameters};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    // A small budget: a fuzzer-made lattice of millions of nodes is refused, not built.
    budget::set_limit(64 << 20);
    let Ok(params) = Parameters::from_bytes(data, true) else {
        return;
    };
    let text = params.to_toml();
    let again = Parameters::from_toml(&text).unwrap_or_else(|e| panic!("written TOML rejected: {e}\n{text}"));
    assert_eq!(again.to_toml(), text, "second write differs");
});
