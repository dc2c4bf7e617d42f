//! Length units in words (`metres`, `millimetres`, `inches`), whatever the file calls
//! them (IGES `M`, `MM`, `IN`; STEP `METRE`, `MILLI METRE`, `INCH`).

/// The plural name of a length unit of `metres_per_unit` metres, from the scale the file
/// states (so IGES `MM` and STEP `MILLI METRE` both read `millimetres`); a scale of no
/// common unit reads as the file's name with its size in metres.
pub fn words(metres_per_unit: f64, file_name: &str) -> String {
    const NAMED: [(f64, &str); 10] = [
        (1.0, "metres"),
        (1e-3, "millimetres"),
        (1e-2, "centimetres"),
        (1e-6, "micrometres"),
        (1e3, "kilometres"),
        (0.0254, "inches"),
        (0.3048, "feet"),
        (2.54e-5, "mils (thousandths of an inch)"),
        (1609.344, "miles"),
        (1e-9, "nanometres"),
    ];
    NAMED
        .iter()
        .find(|(m, _)| (metres_per_unit - m).abs() <= 1e-9 * m)
        .map_or_else(|| format!("{file_name} ({metres_per_unit} m each)"), |(_, w)| (*w).to_owned())
}

/// The JSON object of a unit: its name in words, the file's name and the scale.
pub fn json(metres_per_unit: f64, file_name: &str) -> serde_json::Value {
    serde_json::json!({
        "name": words(metres_per_unit, file_name),
        "file_name": file_name,
        "metres_per_unit": metres_per_unit,
    })
}

#[cfg(test)]
mod tests {
    use super::words;

    #[test]
    fn iges_and_step_names_read_alike() {
        assert_eq!(words(1.0, "M"), "metres");
        assert_eq!(words(1.0, "METRE"), "metres");
        assert_eq!(words(0.001, "MM"), "millimetres");
        assert_eq!(words(0.001, "MILLI METRE"), "millimetres");
        assert_eq!(words(0.0254, "IN"), "inches");
        assert_eq!(words(0.5, "HALF"), "HALF (0.5 m each)");
    }
}
