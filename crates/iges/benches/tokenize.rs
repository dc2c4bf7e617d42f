//! The IGES tokenizer alone, on one thread: every parameter record of the generated
//! files (`hull3_200x150`, 4.6 MB, three records of about 1.5 MB; `faces300`, many short
//! records) tokenized as the reader does with one thread, without the line split, the
//! Directory Entry section or the building of the document. Throughput in bytes of the
//! whole file (as the `parse` bench), the Parameter Data text being most of it.
//!
//!     cargo bench -p cadmorph-iges --features bench-internals --bench tokenize
#![allow(missing_docs)] // criterion's macros generate undocumented items

mod generate;

use std::hint::black_box;

use cadmorph_iges::bench::ParameterRecords;
use criterion::{criterion_group, criterion_main, Criterion, Throughput};

fn bench(c: &mut Criterion) {
    let files = [("hull3_200x150", generate::hull(200, 150)), ("faces300", generate::many_faces(300))];
    let mut g = c.benchmark_group("iges/tokenize");
    g.sample_size(30);
    for (name, bytes) in files {
        let size = bytes.len();
        let records = ParameterRecords::new(bytes).expect("parses");
        eprintln!("{name}: {size} bytes, {} bytes of parameter text", records.parameter_bytes());
        g.throughput(Throughput::Bytes(size as u64));
        g.bench_function(name, |b| b.iter(|| black_box(&records).tokenize().expect("tokenizes")));
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
