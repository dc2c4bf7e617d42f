//! Scaling of boundary pairing (issue 13 item 4): how long [`shared_boundaries`] (iso
//! boundaries of bare patches) and [`shared_curves`] (trimming curves) take on generated
//! models of 100, 1 000 and 10 000 faces, and 200 coincident copies of one face.
//!
//!     cargo run --release -p cadmorph-seam --example pairing_scaling
//!
//! The models are `k × k` grids of unit bilinear patches (a slight bulge so they are not
//! all in one plane), each sharing its four sides with its neighbours: `2k(k − 1)`
//! shared edges, which the run checks. Prints faces, edges found, seconds, and
//! microseconds per face; near-linear pairing keeps the last column flat.

use std::time::Instant;

use cadmorph_nurbs::{NurbsCurve, NurbsSurface, Side};
use cadmorph_seam::{shared_boundaries, shared_curves, TrimCurve};

fn height(x: f64, y: f64) -> f64 {
    0.01 * (x * 0.37).sin() * (y * 0.23).cos()
}

fn grid(k: usize) -> Vec<NurbsSurface> {
    let mut out = Vec::with_capacity(k * k);
    for i in 0..k {
        for j in 0..k {
            let (x, y) = (i as f64, j as f64);
            let p = |x: f64, y: f64| [x, y, height(x, y)];
            out.push(NurbsSurface::bilinear([p(x, y), p(x + 1.0, y), p(x, y + 1.0), p(x + 1.0, y + 1.0)]));
        }
    }
    out
}

fn boundaries(patches: &[NurbsSurface]) -> Vec<TrimCurve> {
    patches
        .iter()
        .enumerate()
        .flat_map(|(patch, s)| {
            Side::ALL.into_iter().map(move |side| {
                let curve: NurbsCurve = s.boundary(side);
                TrimCurve { patch, curve, label: None }
            })
        })
        .collect()
}

fn main() {
    println!("{:>8} {:>10} {:>10} {:>12} {:>14}", "faces", "kind", "edges", "seconds", "us per face");
    for k in [10usize, 32, 100] {
        let patches = grid(k);
        let n = patches.len();
        let expected = 2 * k * (k - 1);
        let refs: Vec<&NurbsSurface> = patches.iter().collect();
        let tol = 1e-3 * (k as f64) * std::f64::consts::SQRT_2;
        let t = Instant::now();
        let iso = shared_boundaries(&refs, tol, 64, 0.9);
        let dt = t.elapsed().as_secs_f64();
        assert_eq!(iso.len(), expected, "iso edges of a {k} x {k} grid");
        println!("{n:>8} {:>10} {:>10} {dt:>12.4} {:>14.2}", "iso", iso.len(), dt * 1e6 / n as f64);
        let curves = boundaries(&patches);
        let t = Instant::now();
        let trims = shared_curves(&curves, tol, 32, 0.9);
        let dt = t.elapsed().as_secs_f64();
        assert_eq!(trims.len(), expected, "trim edges of a {k} x {k} grid");
        println!("{n:>8} {:>10} {:>10} {dt:>12.4} {:>14.2}", "trims", trims.len(), dt * 1e6 / n as f64);
    }
    // 200 coincident copies of one face: each boundary keeps one partner.
    let one = grid(1).remove(0);
    let copies: Vec<&NurbsSurface> = std::iter::repeat_n(&one, 200).collect();
    let t = Instant::now();
    let iso = shared_boundaries(&copies, 1e-3, 64, 0.9);
    let dt = t.elapsed().as_secs_f64();
    assert_eq!(iso.len(), 4 * 199, "coincident copies");
    println!("{:>8} {:>10} {:>10} {dt:>12.4} {:>14.2}", 200, "coincident", iso.len(), dt * 1e6 / 200.0);
}
