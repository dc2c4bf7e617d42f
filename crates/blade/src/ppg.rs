//! BladeX's PPG export (`Blade.export_ppg`): the propeller's normalised radial table and
//! sectional profiles in the PPTC workshop's `.ppg` layout.

use crate::blade::Blade;
use crate::Result;

/// C's `%.8e` (two-digit exponent at least), as Python's `"%.8e" % x`.
pub fn c_exp(x: f64) -> String {
    let s = format!("{x:.8e}");
    let (m, e) = s.split_once('e').unwrap_or((&s, "0"));
    let e: i32 = e.parse().unwrap_or(0);
    format!("{m}e{}{:02}", if e < 0 { '-' } else { '+' }, e.abs())
}

/// The `.ppg` text of `blade` (BladeX `export_ppg(D_prop, D_hub, n_blades,
/// params_normalized)`): radii normalised by `D/2`, chord, pitch and rake by `D` unless
/// `normalized`; per section the British maximum thickness and the signed maximum
/// camber of the profile as given (`max_thickness()`, `max_camber()`), then each
/// profile's points, then BladeX's fixed hub offsets.
///
/// # Errors
///
/// Those of the profile measurements.
pub fn export_ppg(blade: &Blade, d_prop: f64, d_hub: f64, n_blades: usize, normalized: bool) -> Result<String> {
    let n = blade.len();
    let (rs, cs, ps, ks) =
        if normalized { (1.0, 1.0, 1.0, 1.0) } else { (2.0 / d_prop, 1.0 / d_prop, 1.0 / d_prop, 1.0 / d_prop) };
    let mut t = String::new();
    t.push_str("propeller id       = SVA\n");
    t.push_str(&format!("propeller diameter = {}\n", crate::prm::py_float(d_prop)));
    t.push_str(&format!("hub diameter       = {}\n", crate::prm::py_float(d_hub)));
    t.push_str(&format!("number of blades   = {n_blades}\n"));
    t.push_str("'Elica PPTC workshop'\n");
    t.push_str(&format!("number of radial sections         = {n}\n"));
    t.push_str(&format!("number of radial sections         = {n}\n"));
    t.push_str(&format!("number of sectional profiles      = {n}\n"));
    t.push_str("description of sectional profiles = BNF\n");
    t.push_str(
        "            r/R            c/D      skew[deg]         rake/D            P/D            t/C            f/C\n",
    );
    for i in 0..n {
        let s = &blade.sections[i];
        let th = s.max_thickness(None)?;
        let ca = s.max_camber(Some(500))?;
        t.push_str(&format!(
            " {} {} {} {} {} {} {}\n",
            c_exp(blade.radii[i] * rs),
            c_exp(blade.chord[i] * cs),
            c_exp(blade.skew[i]),
            c_exp(blade.rake[i] * ks),
            c_exp(blade.pitch[i] * ps),
            c_exp(th),
            c_exp(ca)
        ));
    }
    for i in 0..n {
        let s = &blade.sections[i];
        t.push_str(&format!("{}  {}\n", c_exp(blade.radii[i] * rs), s.xup.len()));
        for v in [&s.xup, &s.yup, &s.ydown] {
            for x in v.iter() {
                t.push(' ');
                t.push_str(&c_exp(*x));
            }
            t.push_str(" \n");
        }
    }
    let hub = [
        [-3.0, 0.305],
        [-0.57, 0.305],
        [-0.49, 0.305],
        [-0.41, 0.305],
        [-0.33, 0.305],
        [-0.25, 0.305],
        [-0.17, 0.305],
        [0.23, 0.305],
        [0.31, 0.285],
        [0.39, 0.2656],
        [0.47, 0.2432],
        [0.55, 0.2124],
        [0.63, 0.1684],
        [0.71, 0.108],
        [0.79, 0.0],
    ];
    t.push_str(&format!("number of Hub offsets = {}\n", hub.len()));
    let lines: Vec<String> = hub.iter().map(|o| format!("{} {}", c_exp(o[0]), c_exp(o[1]))).collect();
    t.push_str(&lines.join("\n"));
    Ok(t)
}
