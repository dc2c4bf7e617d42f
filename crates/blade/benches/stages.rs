//! blade/stages: where the time of one tutorial blade goes (profiles, placement, loft,
//! faces, IGES text), median of 30 runs each, printed as a table.
//!
//! `cargo bench -p cadmorph-blade --bench stages`

use std::path::PathBuf;
use std::time::Instant;

use cadmorph_blade::export::iges_solids;
use cadmorph_blade::{loft, BladeSolid, DesignTable};

fn med(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../samples/blade/tutorial.toml");
    let table = DesignTable::read(&path).unwrap();
    let mut t = [Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new()];
    for _ in 0..30 {
        let a = Instant::now();
        let b = table.blade().unwrap();
        let bb = Instant::now();
        let c = b.apply_transformations(table.reflect).unwrap();
        let cc = Instant::now();
        let rows: Vec<Vec<_>> =
            c.up.iter().zip(&c.down).map(|(u, d)| u.iter().rev().chain(d[1..].iter()).copied().collect()).collect();
        std::hint::black_box(loft::loft(&rows, 3, 3).unwrap());
        let dd = Instant::now();
        let s = BladeSolid::from_coordinates(&c, 3, 3).unwrap();
        let ee = Instant::now();
        std::hint::black_box(iges_solids(&[s.faces()], table.unit, 2e-8, Some("20260101.000000")));
        let ff = Instant::now();
        for (k, (x, y)) in [(a, bb), (bb, cc), (cc, dd), (dd, ee), (ee, ff)].iter().enumerate() {
            t[k].push((*y - *x).as_secs_f64() * 1e3);
        }
    }
    for (name, v) in
        ["table -> profiles", "placement + wrap", "loft alone", "solid (loft, split, caps)", "IGES text"].iter().zip(t)
    {
        println!("{name:>28}: {:8.3} ms", med(v));
    }
}
