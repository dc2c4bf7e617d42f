use cadmorph_hull::{chine, ChineLaw, Law};
use cadmorph_model::Model;
fn main() {
    let p = std::env::args().nth(1).unwrap();
    let mut m = Model::<cadmorph_step::Document>::open(std::path::Path::new(&p)).unwrap();
    for (i, f) in m.patches().iter().enumerate() {
        eprintln!("face {i} {} {:?} kind {:?} nu {} nv {}", f.entity, f.type_name, f.kind, f.surface.n_u(), f.surface.n_v());
    }
    let law = ChineLaw::new(&m, Law::new(&[2.0f64, 4.0, 4.5, 3.0, 0.0].map(f64::to_radians)).unwrap(), None).unwrap();
    for l in law.lines() { eprintln!("line edge {} {:?} {:?}", l.edge, l.side, l.x); }
    let tol: f64 = std::env::args().nth(2).map(|s| s.parse().unwrap()).unwrap_or(1e-7);
    let r = chine(&mut m, &law, tol).unwrap();
    eprintln!("rounds {} cps {} -> {} dev {:.2e}", r.rounds, r.control_points_before, r.control_points_after, r.max_deviation);
    println!("{}", r.morph.seams_before.table());
    println!("{}", r.morph.seams_after.table());
}
