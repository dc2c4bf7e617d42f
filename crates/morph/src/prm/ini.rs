//! The subset of Python's `configparser` (`RawConfigParser` defaults) that PyGeM's `.prm`
//! files use, keeping the line of every value.
//!
//! - `[section]` headers; `key: value` or `key = value` (first delimiter wins, keys are
//!   lower-cased and trimmed, as `optionxform` does);
//! - full-line comments start with `#` or `;` (also when indented);
//! - a line indented deeper than its key continues the key's value; blank lines in between
//!   are skipped;
//! - a duplicate section or key is an error (configparser's `strict=True`).

use crate::{Error, Result};

/// One value line: its 1-based line number and trimmed text.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ValueLine {
    pub line: usize,
    pub text: String,
}

/// A key and its value lines (the first is the text after the delimiter, possibly empty).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Entry {
    pub key: String,
    pub line: usize,
    pub lines: Vec<ValueLine>,
}

impl Entry {
    /// The single-line value (configparser joins continuation lines with `\n`; a scalar key
    /// with continuation lines is an error here).
    pub fn scalar(&self) -> Result<&ValueLine> {
        if self.lines.len() > 1 {
            return Err(Error::Syntax {
                line: self.lines[1].line,
                expected: "a single value (no continuation line)",
                found: self.lines[1].text.clone(),
            });
        }
        Ok(&self.lines[0])
    }

    /// The non-empty value lines (the first line's value may be empty when the list starts
    /// on the next line).
    pub fn rows(&self) -> impl Iterator<Item = &ValueLine> {
        self.lines.iter().filter(|l| !l.text.is_empty())
    }
}

/// A section with its entries.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Section {
    pub name: String,
    pub line: usize,
    pub entries: Vec<Entry>,
}

impl Section {
    pub fn get(&self, key: &str) -> Option<&Entry> {
        self.entries.iter().find(|e| e.key == key)
    }

    pub fn require(&self, section: &'static str, key: &'static str) -> Result<&Entry> {
        self.get(key).ok_or(Error::MissingKey { line: self.line, section, key })
    }
}

/// A parsed file.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Ini {
    pub sections: Vec<Section>,
}

impl Ini {
    pub fn parse(text: &str) -> Result<Ini> {
        let mut sections: Vec<Section> = Vec::new();
        // Indentation of the key whose value may still continue.
        let mut key_indent: Option<usize> = None;
        for (idx, raw) in text.lines().enumerate() {
            let line = idx + 1;
            let raw = raw.strip_suffix('\r').unwrap_or(raw);
            let trimmed = raw.trim();
            if trimmed.is_empty() || trimmed.starts_with('#') || trimmed.starts_with(';') {
                continue;
            }
            let indent = raw.len() - raw.trim_start().len();
            if let (Some(ki), Some(section)) = (key_indent, sections.last_mut()) {
                if indent > ki {
                    let entry = section.entries.last_mut().expect("key_indent implies an entry");
                    entry.lines.push(ValueLine { line, text: trimmed.to_string() });
                    continue;
                }
            }
            if trimmed.starts_with('[') {
                let name =
                    trimmed.strip_prefix('[').and_then(|s| s.strip_suffix(']')).filter(|s| !s.is_empty()).ok_or_else(
                        || Error::Syntax { line, expected: "a section header `[name]`", found: trimmed.to_string() },
                    )?;
                if let Some(first) = sections.iter().find(|s| s.name == name) {
                    return Err(Error::Duplicate { line, first: first.line, what: format!("section [{name}]") });
                }
                sections.push(Section { name: name.to_string(), line, entries: Vec::new() });
                key_indent = None;
                continue;
            }
            let Some(section) = sections.last_mut() else {
                return Err(Error::Syntax {
                    line,
                    expected: "a section header before the first key",
                    found: trimmed.to_string(),
                });
            };
            let cut = trimmed.find([':', '=']).ok_or_else(|| Error::Syntax {
                line,
                expected: "`key: value` or `key = value`",
                found: trimmed.to_string(),
            })?;
            let key = trimmed[..cut].trim().to_lowercase();
            if key.is_empty() {
                return Err(Error::Syntax { line, expected: "a key before the delimiter", found: trimmed.to_string() });
            }
            if let Some(first) = section.get(&key) {
                return Err(Error::Duplicate {
                    line,
                    first: first.line,
                    what: format!("key {key:?} in [{}]", section.name),
                });
            }
            let value = trimmed[cut + 1..].trim().to_string();
            section.entries.push(Entry { key, line, lines: vec![ValueLine { line, text: value }] });
            key_indent = Some(indent);
        }
        Ok(Ini { sections })
    }

    pub fn section(&self, name: &str) -> Option<&Section> {
        self.sections.iter().find(|s| s.name == name)
    }

    pub fn require(&self, name: &'static str) -> Result<&Section> {
        self.section(name).ok_or(Error::MissingSection { section: name })
    }
}

/// Python `float(text)`: decimal or scientific, optional sign, leading/trailing dot
/// (`.2`, `-.2`, `1.`), `inf`/`nan`; no thousands separators.
pub(crate) fn parse_float(text: &str, line: usize) -> Result<f64> {
    let t = text.trim();
    let ok = !t.is_empty() && t.chars().all(|c| c.is_ascii_alphanumeric() || matches!(c, '.' | '+' | '-' | '_'));
    if ok && !t.contains('_') {
        if let Ok(v) = t.parse::<f64>() {
            return Ok(v);
        }
    }
    Err(Error::Syntax { line, expected: "a number", found: t.to_string() })
}

/// A finite float.
pub(crate) fn parse_finite(text: &str, line: usize, name: &'static str) -> Result<f64> {
    let v = parse_float(text, line)?;
    if !v.is_finite() {
        return Err(Error::InvalidParameter { line: Some(line), name, value: v, reason: "must be finite" });
    }
    Ok(v)
}

/// Python `int(text)` for non-negative values.
pub(crate) fn parse_usize(text: &str, line: usize) -> Result<usize> {
    let t = text.trim();
    let t = t.strip_prefix('+').unwrap_or(t);
    t.parse::<usize>().map_err(|_| Error::Syntax {
        line,
        expected: "a non-negative integer",
        found: text.trim().to_string(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn continuation_comments_and_case() {
        let text = "\n[Box]\n# c\nKey A: 1\n  2\n\n  ; note\n  3\nb = x\n";
        let ini = Ini::parse(text).unwrap();
        let s = ini.section("Box").unwrap();
        let a = s.get("key a").unwrap();
        assert_eq!(a.line, 4);
        let texts: Vec<_> = a.rows().map(|l| (l.line, l.text.as_str())).collect();
        assert_eq!(texts, vec![(4, "1"), (5, "2"), (8, "3")]);
        assert_eq!(s.get("b").unwrap().scalar().unwrap().text, "x");
    }

    #[test]
    fn errors_name_the_line() {
        assert!(matches!(Ini::parse("k: v\n"), Err(Error::Syntax { line: 1, .. })));
        assert!(matches!(Ini::parse("[a]\nk: 1\nk: 2\n"), Err(Error::Duplicate { line: 3, first: 2, .. })));
        assert!(matches!(Ini::parse("[a]\n[a]\n"), Err(Error::Duplicate { line: 2, first: 1, .. })));
        assert!(matches!(Ini::parse("[a]\nnovalue\n"), Err(Error::Syntax { line: 2, .. })));
        assert!(matches!(Ini::parse("[a\n"), Err(Error::Syntax { line: 1, .. })));
    }

    #[test]
    fn python_float_forms() {
        for (s, v) in [(".2", 0.2), ("-.2", -0.2), ("1", 1.0), ("1.", 1.0), ("1e-3", 1e-3), ("+4.5", 4.5)] {
            assert_eq!(parse_float(s, 1).unwrap(), v);
        }
        for s in ["", "1,5", "0x10", "1_000", "a"] {
            assert!(parse_float(s, 7).is_err(), "{s}");
        }
        assert!(parse_finite("nan", 3, "x").is_err());
        assert_eq!(parse_usize("3", 1).unwrap(), 3);
        assert!(parse_usize("3.0", 1).is_err());
        assert!(parse_usize("-1", 1).is_err());
    }
}
