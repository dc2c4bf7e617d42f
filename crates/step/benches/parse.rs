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

mod generate;

use std::hint::black_box;

use cadmorph_step::Document;
use criterion::{criterion_group, criterion_main, Criterion, Throughput};

fn parse_world(bytes: &[u8]) -> usize {
    let doc = Document::parse(bytes).expect("parses");
    let faces = doc.faces().expect("faces");
    doc.faces_nurbs(&faces).into_iter().map(|w| w.expect("world NURBS").surface.control_points().len()).sum()
}

fn bench(c: &mut Criterion) {
    let files = [("hull3_200x150", generate::hull3()), ("faces300", generate::faces300())];
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
