//! Run-time SIMD dispatch of the morph kernels (the FFD lattice sum, the RBF and IDW sums,
//! the conjugate-gradient products and block solves): every kernel is one
//! `pulp::WithSimd` operation, compiled once per instruction set, and run in the widest
//! one the CPU has: AVX-512 (pulp's `x86-v4` level: AVX-512 F/BW/CD/DQ/VL), else AVX2 with
//! FMA (`x86-v3`), else portable scalar code (pulp, <https://docs.rs/pulp>).
//!
//! The crate's unit tests force each instruction set the CPU has in turn
//! ([`for_each_isa`]), so the narrower paths stay tested on a machine with a wider one.

/// Runs `op` in the widest instruction set this CPU has.
#[cfg(not(test))]
#[inline]
pub(crate) fn dispatch<Op: pulp::WithSimd>(op: Op) -> Op::Output {
    pulp::Arch::new().dispatch(op)
}

/// Runs `op` in the instruction set [`for_each_isa`] forces (the widest otherwise).
#[cfg(test)]
pub(crate) fn dispatch<Op: pulp::WithSimd>(op: Op) -> Op::Output {
    use std::sync::atomic::Ordering;
    match forced::FORCE.load(Ordering::SeqCst) {
        forced::SCALAR => op.with_simd(pulp::Scalar::new()),
        #[cfg(target_arch = "x86_64")]
        forced::V3 => match pulp::x86::V3::try_new() {
            Some(simd) => pulp::Simd::vectorize(simd, op),
            None => pulp::Arch::new().dispatch(op),
        },
        #[cfg(target_arch = "x86_64")]
        forced::V4 => match pulp::x86::V4::try_new() {
            Some(simd) => pulp::Simd::vectorize(simd, op),
            None => pulp::Arch::new().dispatch(op),
        },
        _ => pulp::Arch::new().dispatch(op),
    }
}

/// Calls `f` once per instruction set this CPU has (scalar, then AVX2/FMA and AVX-512 where
/// present), with [`dispatch`] forced to it; `f` gets its name.
#[cfg(test)]
pub(crate) fn for_each_isa(mut f: impl FnMut(&'static str)) {
    use std::sync::atomic::Ordering;
    let _one = forced::LOCK.lock().unwrap_or_else(|e| e.into_inner());
    let mut sets = vec![(forced::SCALAR, "scalar")];
    #[cfg(target_arch = "x86_64")]
    {
        if pulp::x86::V3::try_new().is_some() {
            sets.push((forced::V3, "avx2"));
        }
        if pulp::x86::V4::try_new().is_some() {
            sets.push((forced::V4, "avx512"));
        }
    }
    for (set, name) in sets {
        forced::FORCE.store(set, Ordering::SeqCst);
        // Reset even when `f` panics, so later tests run the widest set again.
        struct Reset;
        impl Drop for Reset {
            fn drop(&mut self) {
                forced::FORCE.store(forced::WIDEST, std::sync::atomic::Ordering::SeqCst);
            }
        }
        let _reset = Reset;
        f(name);
    }
}

#[cfg(test)]
mod forced {
    use std::sync::atomic::AtomicU8;
    use std::sync::Mutex;

    pub const WIDEST: u8 = 0;
    pub const SCALAR: u8 = 1;
    pub const V3: u8 = 2;
    pub const V4: u8 = 3;
    /// The forced instruction set (tests running at the same time may see it too: every
    /// path computes the same values, so they only run a different one).
    pub static FORCE: AtomicU8 = AtomicU8::new(WIDEST);
    /// One forcing test at a time.
    pub static LOCK: Mutex<()> = Mutex::new(());
}
