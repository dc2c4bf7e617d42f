//! Writes the benchmark files and times cadmorph on them, for `benches/iges_vs_occt.sh`.
//!
//!     cargo run --release -p cadmorph-iges --example iges_bench -- --write DIR
//!     cargo run --release -p cadmorph-iges --example iges_bench -- --repeat 5 FILE...
//!
//! Each timed file prints one JSON line: bytes, best-of-repeat seconds for reading the file
//! and parsing it (`parse_s`), and for that plus converting every face to a NURBS surface
//! (`parse_convert_s`; OCCT's `ReadFile` reads the file too), the face count, and a
//! checksum (sum of x + y + z over the corners of every converted surface).

#[path = "../benches/generate.rs"]
mod generate;

use std::time::Instant;

use cadmorph_iges::Document;
use cadmorph_nurbs::Surface;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut repeat = 5;
    let mut files = Vec::new();
    let mut i = 0;
    while i < args.len() {
        match args[i].as_str() {
            "--write" => {
                let dir = std::path::Path::new(&args[i + 1]);
                std::fs::create_dir_all(dir).unwrap();
                std::fs::write(dir.join("hull3_200x150.igs"), generate::hull(200, 150)).unwrap();
                std::fs::write(dir.join("faces300.igs"), generate::many_faces(300)).unwrap();
                i += 2;
            }
            "--repeat" => {
                repeat = args[i + 1].parse().unwrap();
                i += 2;
            }
            f => {
                files.push(f.to_string());
                i += 1;
            }
        }
    }
    for f in files {
        let size = std::fs::metadata(&f).unwrap().len() as usize;
        let (mut parse_s, mut total_s) = (f64::INFINITY, f64::INFINITY);
        let (mut faces, mut checksum) = (0, 0.0);
        for _ in 0..repeat {
            let t = Instant::now();
            let doc = Document::from_bytes(std::fs::read(&f).unwrap()).unwrap();
            parse_s = parse_s.min(t.elapsed().as_secs_f64());
            drop(doc);
            let t = Instant::now();
            let doc = Document::from_bytes(std::fs::read(&f).unwrap()).unwrap();
            let surfaces: Vec<_> = doc.face_surfaces(&doc.faces()).into_iter().map(|s| s.unwrap().surface).collect();
            total_s = total_s.min(t.elapsed().as_secs_f64());
            faces = surfaces.len();
            checksum = 0.0;
            for s in &surfaces {
                let (u, v) = s.domain();
                for (a, b) in [(*u.start(), *v.start()), (*u.end(), *v.end())] {
                    let p = s.eval(a, b);
                    checksum += p.x + p.y + p.z;
                }
            }
        }
        let mb = size as f64 / 1e6;
        println!(
            "{{\"file\": {f:?}, \"bytes\": {}, \"faces\": {faces}, \"parse_s\": {parse_s:.6}, \"parse_convert_s\": {total_s:.6}, \"mb_per_s\": {:.1}, \"checksum\": {checksum:.9}}}",
            size,
            mb / total_s
        );
    }
}
