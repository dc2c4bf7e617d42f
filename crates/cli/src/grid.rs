//! Grid points of a surface, as `sample` and `eval` print them.

use cadmorph::nurbs::{NurbsSurface, Surface};

/// One grid point: `(u, v, point, normal)`.
pub type Row = (f64, f64, [f64; 3], Option<[f64; 3]>);

/// Points and (face-oriented) normals of `s` on an `n × n` grid over its domain.
pub fn rows(s: &NurbsSurface, n: usize, reversed: bool) -> Vec<Row> {
    let (ud, vd) = s.domain();
    let mut rows = Vec::with_capacity(n * n);
    for i in 0..n {
        for j in 0..n {
            let u = ud.start() + (ud.end() - ud.start()) * i as f64 / (n - 1) as f64;
            let v = vd.start() + (vd.end() - vd.start()) * j as f64 / (n - 1) as f64;
            let q = s.eval(u, v);
            let nrm = s.normal(u, v).map(|n| if reversed { -n.into_inner() } else { n.into_inner() });
            rows.push((u, v, [q.x, q.y, q.z], nrm.map(|n| [n.x, n.y, n.z])));
        }
    }
    rows
}

/// The rows as JSON objects `{u, v, p, n}`.
pub fn json(rows: &[Row]) -> Vec<serde_json::Value> {
    rows.iter().map(|(u, v, q, n)| serde_json::json!({"u": u, "v": v, "p": q, "n": n})).collect()
}

/// The rows as a table.
pub fn print(rows: &[Row]) {
    println!("{:>10} {:>10} {:>14} {:>14} {:>14} {:>9} {:>9} {:>9}", "u", "v", "x", "y", "z", "nx", "ny", "nz");
    for (u, v, q, n) in rows {
        let n =
            n.map_or("    (degenerate point)".to_string(), |n| format!("{:>9.5} {:>9.5} {:>9.5}", n[0], n[1], n[2]));
        println!("{u:>10.5} {v:>10.5} {:>14.6} {:>14.6} {:>14.6} {n}", q[0], q[1], q[2]);
    }
}
