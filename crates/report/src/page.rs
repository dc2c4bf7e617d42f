//! What every page shares: HTML escaping, the style sheet, the inlined scripts, the
//! embedding of JSON and pictures.

use base64::Engine;

/// The style sheet of every page.
pub const CSS: &str = include_str!("../assets/report.css");
/// The WebGL viewer (hand-written, no library: see the crate docs).
pub const VIEWER_JS: &str = include_str!("../assets/viewer.js");
/// Sortable tables.
pub const SORT_JS: &str = include_str!("../assets/sort.js");

/// `s` with `& < > " '` escaped for HTML text and attribute values.
pub fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// JSON text that can stand inside a `<script>` element: `</` written `<\/` (the same
/// string to a JSON reader).
pub fn script_json(json: &str) -> String {
    json.replace("</", "<\\/")
}

/// A `data:` URL of PNG bytes, for an `<img src>`.
pub fn png_data_url(png: &[u8]) -> String {
    format!("data:image/png;base64,{}", base64::engine::general_purpose::STANDARD.encode(png))
}

/// A number for a table cell: 4 significant digits in exponent form, `–` for NaN.
pub fn num(v: f64) -> String {
    if v.is_nan() {
        "–".into()
    } else if v == 0.0 {
        "0".into()
    } else {
        format!("{v:.3e}")
    }
}

/// The page's opening up to `<body>`, with `title` and the style sheet.
pub fn head(title: &str) -> String {
    format!(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
         <meta name=\"generator\" content=\"cadmorph {}\"><title>{}</title><style>{CSS}</style></head><body>\n",
        env!("CARGO_PKG_VERSION"),
        escape(title)
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escaping() {
        assert_eq!(escape("a<b>&\"c'"), "a&lt;b&gt;&amp;&quot;c&#39;");
        let j = script_json(r#"{"s":"</script>"}"#);
        assert!(!j.contains("</"));
        let back: serde_json::Value = serde_json::from_str(&j).unwrap();
        assert_eq!(back["s"], "</script>");
        assert_eq!(num(f64::NAN), "–");
        assert_eq!(num(0.0024444), "2.444e-3");
        assert!(png_data_url(b"x").starts_with("data:image/png;base64,"));
    }
}
