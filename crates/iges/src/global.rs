//! The Global section: delimiters, units, scale, resolution and the file's identity.

use crate::document::Param;
use crate::read::lexer::{Raw, Token};

/// The model's length unit (Global parameter 14, with the name of parameter 15).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Units {
    /// 1: inch.
    Inch,
    /// 2: millimetre.
    Millimetre,
    /// 3: named in parameter 15 only (see [`Global::unit_name`]).
    Named,
    /// 4: foot.
    Foot,
    /// 5: mile.
    Mile,
    /// 6: metre.
    Metre,
    /// 7: kilometre.
    Kilometre,
    /// 8: mil (0.001 inch).
    Mil,
    /// 9: micron.
    Micron,
    /// 10: centimetre.
    Centimetre,
    /// 11: microinch.
    Microinch,
}

impl Units {
    /// The unit of flag `flag`, `None` for values IGES does not define.
    pub fn from_flag(flag: i64) -> Option<Self> {
        Some(match flag {
            1 => Units::Inch,
            2 => Units::Millimetre,
            3 => Units::Named,
            4 => Units::Foot,
            5 => Units::Mile,
            6 => Units::Metre,
            7 => Units::Kilometre,
            8 => Units::Mil,
            9 => Units::Micron,
            10 => Units::Centimetre,
            11 => Units::Microinch,
            _ => return None,
        })
    }

    /// The unit flag (Global parameter 14).
    pub fn flag(self) -> i64 {
        match self {
            Units::Inch => 1,
            Units::Millimetre => 2,
            Units::Named => 3,
            Units::Foot => 4,
            Units::Mile => 5,
            Units::Metre => 6,
            Units::Kilometre => 7,
            Units::Mil => 8,
            Units::Micron => 9,
            Units::Centimetre => 10,
            Units::Microinch => 11,
        }
    }

    /// The name IGES gives the unit in parameter 15 (`"MM"`, `"M"`, `"IN"`, ...).
    pub fn name(self) -> &'static str {
        match self {
            Units::Inch => "IN",
            Units::Millimetre => "MM",
            Units::Named => "",
            Units::Foot => "FT",
            Units::Mile => "MI",
            Units::Metre => "M",
            Units::Kilometre => "KM",
            Units::Mil => "MIL",
            Units::Micron => "UM",
            Units::Centimetre => "CM",
            Units::Microinch => "UIN",
        }
    }

    /// Millimetres per unit; `None` for [`Units::Named`].
    pub fn millimetres(self) -> Option<f64> {
        Some(match self {
            Units::Inch => 25.4,
            Units::Millimetre => 1.0,
            Units::Named => return None,
            Units::Foot => 304.8,
            Units::Mile => 1_609_344.0,
            Units::Metre => 1000.0,
            Units::Kilometre => 1_000_000.0,
            Units::Mil => 0.0254,
            Units::Micron => 0.001,
            Units::Centimetre => 10.0,
            Units::Microinch => 0.0000254,
        })
    }

    /// The unit of an IGES unit name (`"MM"`, `"M"`, `"IN"`, `"INCH"`, ...), case-insensitive.
    pub fn from_name(name: &str) -> Option<Self> {
        let n = name.trim().to_ascii_uppercase();
        Some(match n.as_str() {
            "IN" | "INCH" => Units::Inch,
            "MM" => Units::Millimetre,
            "FT" => Units::Foot,
            "MI" => Units::Mile,
            "M" => Units::Metre,
            "KM" => Units::Kilometre,
            "MIL" => Units::Mil,
            "UM" => Units::Micron,
            "CM" => Units::Centimetre,
            "UIN" => Units::Microinch,
            _ => return None,
        })
    }
}

/// The Global section as read: every parameter, plus typed access to the ones cadmorph
/// uses. Parameter numbers below are IGES 5.3's (1-based).
#[derive(Debug, Clone, PartialEq)]
pub struct Global {
    pub(crate) text: Vec<u8>,
    pub(crate) tokens: Vec<Token>,
    pub(crate) parameter_delimiter: u8,
    pub(crate) record_delimiter: u8,
}

impl Global {
    /// Parameter delimiter (parameter 1, default `,`).
    pub fn parameter_delimiter(&self) -> u8 {
        self.parameter_delimiter
    }
    /// Record delimiter (parameter 2, default `;`).
    pub fn record_delimiter(&self) -> u8 {
        self.record_delimiter
    }
    /// Number of parameters present.
    pub fn len(&self) -> usize {
        self.tokens.len()
    }
    /// Whether there are no parameters.
    pub fn is_empty(&self) -> bool {
        self.tokens.is_empty()
    }
    /// Parameter `n` (1-based, as IGES numbers them).
    pub fn param(&self, n: usize) -> Option<Param<'_>> {
        let t = self.tokens.get(n.checked_sub(1)?)?;
        Some(match t.raw {
            Raw::Default => Param::Default,
            Raw::Integer(i) => Param::Integer(i),
            Raw::Real(x) => Param::Real(x),
            Raw::Text { start, len } => {
                Param::Text(self.text.get(start as usize..(start + len) as usize).unwrap_or(&[]))
            }
        })
    }
    /// Parameter `n` as a string (lossy UTF-8), `None` if absent, defaulted or not a string.
    pub fn string(&self, n: usize) -> Option<String> {
        match self.param(n)? {
            Param::Text(t) => Some(String::from_utf8_lossy(t).into_owned()),
            _ => None,
        }
    }
    fn real(&self, n: usize) -> Option<f64> {
        self.param(n)?.as_real()
    }
    fn integer(&self, n: usize) -> Option<i64> {
        self.param(n)?.as_integer()
    }
    /// Parameter 3: product identification from the sender.
    pub fn sender_product_id(&self) -> Option<String> {
        self.string(3)
    }
    /// Parameter 4: file name.
    pub fn file_name(&self) -> Option<String> {
        self.string(4)
    }
    /// Parameter 5: native system id.
    pub fn native_system_id(&self) -> Option<String> {
        self.string(5)
    }
    /// Parameter 6: preprocessor version.
    pub fn preprocessor_version(&self) -> Option<String> {
        self.string(6)
    }
    /// Parameter 13: model space scale (model units per real-world unit), default 1.
    pub fn model_scale(&self) -> f64 {
        self.real(13).filter(|s| s.is_finite() && *s > 0.0).unwrap_or(1.0)
    }
    /// Parameter 14: the units flag (default 1, inch, as IGES says).
    pub fn unit_flag(&self) -> i64 {
        self.integer(14).unwrap_or(1)
    }
    /// Parameter 15: the units name (default `"IN"`).
    pub fn unit_name(&self) -> String {
        self.string(15).unwrap_or_else(|| "IN".to_string())
    }
    /// The model's unit: flag 14, or the name when the flag is 3 (`None` if neither is
    /// understood).
    pub fn units(&self) -> Option<Units> {
        match Units::from_flag(self.unit_flag())? {
            Units::Named => Units::from_name(&self.unit_name()),
            u => Some(u),
        }
    }
    /// Millimetres per model unit, from [`units`](Self::units).
    pub fn millimetres_per_unit(&self) -> Option<f64> {
        self.units()?.millimetres()
    }
    /// Parameter 18: date and time of file generation.
    pub fn date(&self) -> Option<String> {
        self.string(18)
    }
    /// Parameter 19: minimum user-intended resolution (model units), the file's own
    /// tolerance.
    pub fn min_resolution(&self) -> Option<f64> {
        self.real(19)
    }
    /// Parameter 20: approximate maximum coordinate value.
    pub fn max_coordinate(&self) -> Option<f64> {
        self.real(20)
    }
    /// Parameter 21: author.
    pub fn author(&self) -> Option<String> {
        self.string(21)
    }
    /// Parameter 22: organisation.
    pub fn organization(&self) -> Option<String> {
        self.string(22)
    }
    /// Parameter 23: IGES version flag (11 is 5.3).
    pub fn version(&self) -> Option<i64> {
        self.integer(23)
    }
}
