//! Parsing IGES and converting every face to a NURBS surface, on generated large files:
//! a 3-patch hull with 200 × 150 poles per patch (about 5 MB) and a file of 300 trimmed
//! faces. Throughput in bytes of IGES text.
#![allow(missing_docs)]

mod generate;

use cadmorph_iges::Document;
use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};

fn bench(c: &mut Criterion) {
    let files = [("hull3_200x150", generate::hull(200, 150)), ("faces300", generate::many_faces(300))];
    let mut g = c.benchmark_group("iges");
    g.sample_size(20);
    for (name, bytes) in &files {
        g.throughput(Throughput::Bytes(bytes.len() as u64));
        g.bench_function(format!("parse/{name}"), |b| b.iter(|| Document::parse(black_box(bytes)).unwrap()));
        g.bench_function(format!("parse_convert/{name}"), |b| {
            b.iter(|| {
                let doc = Document::parse(black_box(bytes)).unwrap();
                doc.faces().iter().map(|f| doc.face_surface(f).unwrap().surface).collect::<Vec<_>>()
            })
        });
        let doc = Document::parse(bytes).unwrap();
        g.bench_function(format!("write_unchanged/{name}"), |b| b.iter(|| black_box(&doc).write()));
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
