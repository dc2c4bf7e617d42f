//! blade/campaign/500: the paper's 500-propeller campaign (§3.1.2) on the tutorial-like
//! blade: each variant moves the chord, pitch, rake and skew radial-law control points
//! (seeded pseudo-random, BladeX-style `.prm` settings of `samples/blade/deform.prm`),
//! regenerates the blade and writes it as a STEP solid. Runs on all cores with std
//! threads; prints the wall time of the whole campaign (min/median/max of 3 runs).
//!
//! `cargo bench -p cadmorph-blade --bench campaign`

use std::path::PathBuf;
use std::time::Instant;

use cadmorph_blade::export::{step_solids, LengthUnit};
use cadmorph_blade::{BladeSolid, DesignTable, ParamFile};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// xorshift64*: reproducible variants without a dependency.
fn rng(seed: u64) -> impl FnMut() -> f64 {
    let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    move || {
        s ^= s >> 12;
        s ^= s << 25;
        s ^= s >> 27;
        (s.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn variant(base: &DesignTable, prm: &ParamFile, i: usize, dir: &std::path::Path) -> usize {
    let mut p = prm.clone();
    let mut r = rng(i as u64 + 1);
    // Amplitudes per law: chord, pitch, rake, skew (camber untouched).
    let amp = [0.2, 0.5, 0.05, 2.0, 0.0];
    for (k, s) in p.settings.iter_mut().enumerate() {
        let n = s.deformations.len();
        for (j, d) in s.deformations.iter_mut().enumerate() {
            // Ends stay (BladeX fixes the end control points by construction anyway).
            *d = if j == 0 || j + 1 == n { 0.0 } else { amp[k] * (2.0 * r() - 1.0) };
        }
    }
    let mut t = base.clone();
    t.deform(&p, 1000).expect("variant table");
    let b = t.blade().expect("variant blade");
    let c = b.apply_transformations(t.reflect).expect("placed");
    let s = BladeSolid::from_coordinates(&c, 3, 3).expect("solid");
    let bytes = step_solids("variant", &[s.faces()], LengthUnit::M, 2e-8).expect("step");
    let path = dir.join(format!("blade_{i:03}.stp"));
    cadmorph_blade::output::write_atomic(&path, &bytes).expect("write");
    bytes.len()
}

fn main() {
    let base = DesignTable::read(&root().join("samples/blade/tutorial.toml")).unwrap();
    let prm = ParamFile::read(&root().join("samples/blade/deform.prm")).unwrap();
    let n: usize = std::env::var("CAMPAIGN_N").ok().and_then(|s| s.parse().ok()).unwrap_or(500);
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let dir = std::env::temp_dir().join(format!("cadmorph-blade-campaign-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut times = Vec::new();
    let mut bytes = 0;
    for _ in 0..3 {
        let t0 = Instant::now();
        bytes = std::thread::scope(|sc| {
            let hs: Vec<_> = (0..threads)
                .map(|w| {
                    let (base, prm, dir) = (&base, &prm, &dir);
                    sc.spawn(move || (w..n).step_by(threads).map(|i| variant(base, prm, i, dir)).sum::<usize>())
                })
                .collect();
            hs.into_iter().map(|h| h.join().unwrap()).sum::<usize>()
        });
        times.push(t0.elapsed().as_secs_f64());
    }
    times.sort_by(f64::total_cmp);
    println!(
        "blade/campaign/{n}: {threads} threads, {:.1} MB of STEP, wall s min {:.2} median {:.2} max {:.2} ({:.1} ms per blade at the median)",
        bytes as f64 / 1e6,
        times[0],
        times[1],
        times[2],
        1e3 * times[1] / n as f64
    );
    std::fs::remove_dir_all(&dir).ok();
}
