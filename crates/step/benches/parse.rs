//! Parse + world-coordinate NURBS of every face, on generated large STEP files:
//! `step/parse_world/hull3_200x150` (3 cubic patches of 200x150 poles, about 8 MB) and
//! `step/parse_world/faces300` (300 bicubic patches sharing edges).
//!
//! Measured with `bash benches/step_vs_occt.sh` (2-core AMD EPYC shared with other jobs,
//! commit 502569f), same files in the same run as OCCT 7.6 `STEPControl_Reader`
//! ReadFile + TransferRoots (best of 3):
//!
//! | file | size | cadmorph parse + world NURBS | OCCT read + transfer | speed-up |
//! | --- | --- | --- | --- | --- |
//! | hull3_200x150 | 8.75 MB | 109 ms (80 MB/s) | 2060 ms (4.2 MB/s) | 18.8x |
//! | faces300 | 2.76 MB | 40 ms (68 MB/s) | 705 ms (3.9 MB/s) | 17.4x |
//!
//! Parse alone: 51 ms (163 MiB/s) and 18 ms (146 MiB/s).
//!
//! With `CADMORPH_STEP_BENCH_DIR=DIR` the generated files are also written to `DIR`, so
//! `benches/step_vs_occt.sh` can time OCCT's reader on the same bytes.
#![allow(missing_docs)] // criterion's macros generate undocumented items

use std::hint::black_box;

use cadmorph_nurbs::math::Point3;
use cadmorph_nurbs::{KnotVector, NurbsSurface};
use cadmorph_step::{Document, DocumentBuilder, Schema};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};

/// A cubic patch of `n_u x n_v` poles over `[x0, x1]` of a hull-like shape with a small
/// deterministic ripple (so the numbers have full-length decimals like real files).
fn hull_patch(n_u: usize, n_v: usize, x0: f64, x1: f64) -> NurbsSurface {
    let mut pts = Vec::with_capacity(n_u * n_v);
    for i in 0..n_u {
        let x = x0 + (x1 - x0) * i as f64 / (n_u - 1) as f64;
        for j in 0..n_v {
            let t = j as f64 / (n_v - 1) as f64;
            let beam = 8.0 * (1.0 - (2.0 * x / 140.0 - 1.0).powi(4)).max(0.05);
            let y = beam * (t * std::f64::consts::FRAC_PI_2).sin() + 1e-3 * ((i * 7 + j * 3) % 11) as f64 / 11.0;
            let z = 12.5 * (1.0 - (t * std::f64::consts::FRAC_PI_2).cos()) + 0.01 * (x / 13.0).sin();
            pts.push(Point3::new(x, y, z));
        }
    }
    NurbsSurface::try_new(
        (3, 3),
        (KnotVector::clamped_uniform(3, n_u), KnotVector::clamped_uniform(3, n_v)),
        (n_u, n_v),
        pts,
        None,
    )
    .expect("valid patch")
}

fn hull3() -> Vec<u8> {
    let patches: Vec<NurbsSurface> =
        (0..3).map(|k| hull_patch(200, 150, 140.0 * k as f64 / 3.0, 140.0 * (k + 1) as f64 / 3.0)).collect();
    let mut b = DocumentBuilder::new(Schema::Ap214, "hull3_200x150", 1.0, 1e-7).expect("builder");
    b.add_shell(&patches, 1e-9);
    b.build().expect("document").write()
}

fn faces300() -> Vec<u8> {
    let mut patches = Vec::with_capacity(300);
    for a in 0..20 {
        for c in 0..15 {
            let mut s = hull_patch(8, 8, 7.0 * a as f64, 7.0 * (a + 1) as f64);
            // Stack the rows in z so the 20 x 15 patches tile a sheet.
            for p in s.control_points_mut() {
                p.z += 25.0 * c as f64;
            }
            patches.push(s);
        }
    }
    let mut b = DocumentBuilder::new(Schema::Ap214, "faces300", 1.0, 1e-7).expect("builder");
    b.add_shell(&patches, 1e-9);
    b.build().expect("document").write()
}

fn parse_world(bytes: &[u8]) -> usize {
    let doc = Document::parse(bytes).expect("parses");
    let faces = doc.faces().expect("faces");
    let mut poles = 0;
    for f in &faces {
        poles += doc.face_nurbs(f).expect("world NURBS").surface.control_points().len();
    }
    poles
}

fn bench(c: &mut Criterion) {
    let files = [("hull3_200x150", hull3()), ("faces300", faces300())];
    if let Ok(dir) = std::env::var("CADMORPH_STEP_BENCH_DIR") {
        std::fs::create_dir_all(&dir).expect("bench dir");
        for (name, bytes) in &files {
            std::fs::write(std::path::Path::new(&dir).join(format!("{name}.stp")), bytes).expect("write");
        }
    }
    let mut g = c.benchmark_group("step/parse_world");
    g.sample_size(20);
    for (name, bytes) in &files {
        g.throughput(Throughput::Bytes(bytes.len() as u64));
        g.bench_function(*name, |b| b.iter(|| parse_world(black_box(bytes))));
    }
    g.finish();
    let mut g = c.benchmark_group("step/parse");
    g.sample_size(20);
    for (name, bytes) in &files {
        g.throughput(Throughput::Bytes(bytes.len() as u64));
        g.bench_function(*name, |b| b.iter(|| Document::parse(black_box(bytes)).expect("parses").len()));
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
