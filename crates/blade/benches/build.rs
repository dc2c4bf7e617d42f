//! blade/build/tutorial_10x240: one 10-section blade (BladeX tutorial 3 values, NACA 0012,
//! 240 points per side) from its design table to IGES (and STEP) bytes in memory:
//! profiles, placement, loft, split, caps, file text. Prints min/median/max of 30 runs,
//! as one JSON line for `benches/blade/bench.py`.
//!
//! `cargo bench -p cadmorph-blade --bench build`

use std::path::PathBuf;
use std::time::Instant;

use cadmorph_blade::export::{iges_solids, step_solids};
use cadmorph_blade::{BladeSolid, DesignTable};

fn stats(mut v: Vec<f64>) -> [f64; 3] {
    v.sort_by(f64::total_cmp);
    [v[0], v[v.len() / 2], v[v.len() - 1]]
}

fn main() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../samples/blade/tutorial.toml");
    let table = DesignTable::read(&path).unwrap();
    let mut iges = Vec::new();
    let mut step = Vec::new();
    let mut size = 0;
    for _ in 0..30 {
        let t0 = Instant::now();
        let b = table.blade().unwrap();
        let c = b.apply_transformations(table.reflect).unwrap();
        let s = BladeSolid::from_coordinates(&c, 3, 3).unwrap();
        let t1 = Instant::now();
        let bytes = std::hint::black_box(iges_solids(&[s.faces()], table.unit, 2e-8, Some("20260101.000000")));
        let t2 = Instant::now();
        let sb = std::hint::black_box(step_solids("blade", &[s.faces()], table.unit, 2e-8).unwrap());
        let t3 = Instant::now();
        size = bytes.len() + sb.len();
        iges.push((t2 - t0).as_secs_f64() * 1e3);
        step.push(((t1 - t0) + (t3 - t2)).as_secs_f64() * 1e3);
    }
    let (i, s) = (stats(iges), stats(step));
    println!(
        "{{\"bench\": \"blade/build/tutorial_10x240\", \"runs\": 30, \"iges_ms\": [{:.3}, {:.3}, {:.3}], \"step_ms\": [{:.3}, {:.3}, {:.3}], \"bytes\": {size}}}",
        i[0], i[1], i[2], s[0], s[1], s[2]
    );
}
