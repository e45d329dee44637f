//! Units named in a record's header: `p [kPa]`, `p [kPa gauge]`, `x [mm]`, `t [ms]`,
//! `dV [cm^3]`, `theta [deg]`. Each column is converted to SI on reading (the model's units:
//! Pa absolute, m, s, m^3, rad), so a lab record is read as it was logged. A gauge pressure
//! gets the standard atmosphere ([`AMBIENT`](crate::data::units::AMBIENT)) added; the fit's free pressure offset
//! (`p_offset`) takes the difference to the day's ambient pressure.

/// The ambient pressure added to a gauge pressure (Pa): the standard atmosphere.
pub const AMBIENT: f64 = 101_325.0;

/// What a unit measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    Time,
    Pressure,
    Length,
    Volume,
    Angle,
}

impl Kind {
    fn noun(self) -> &'static str {
        match self {
            Kind::Time => "a time",
            Kind::Pressure => "a pressure",
            Kind::Length => "a length",
            Kind::Volume => "a volume",
            Kind::Angle => "an angle",
        }
    }

    /// The units of this kind, as a list for a message.
    fn known(self) -> String {
        let names: Vec<&str> = UNITS.iter().filter(|u| u.1 == self).map(|u| u.0).collect();
        let gauge = if self == Kind::Pressure {
            " (gauge pressure: add `gauge`, e.g. `kPa gauge`, or write `psig`, `barg`)"
        } else {
            ""
        };
        format!("{}{gauge}", names.join(", "))
    }
}

/// Units: name, kind, factor to SI.
const UNITS: [(&str, Kind, f64); 22] = [
    ("s", Kind::Time, 1.0),
    ("ms", Kind::Time, 1e-3),
    ("us", Kind::Time, 1e-6),
    ("Pa", Kind::Pressure, 1.0),
    ("hPa", Kind::Pressure, 1e2),
    ("kPa", Kind::Pressure, 1e3),
    ("MPa", Kind::Pressure, 1e6),
    ("mbar", Kind::Pressure, 1e2),
    ("bar", Kind::Pressure, 1e5),
    ("psi", Kind::Pressure, 6_894.757_293_168),
    ("atm", Kind::Pressure, 101_325.0),
    ("m", Kind::Length, 1.0),
    ("cm", Kind::Length, 1e-2),
    ("mm", Kind::Length, 1e-3),
    ("um", Kind::Length, 1e-6),
    ("m^3", Kind::Volume, 1.0),
    ("cm^3", Kind::Volume, 1e-6),
    ("mm^3", Kind::Volume, 1e-9),
    ("l", Kind::Volume, 1e-3),
    ("ml", Kind::Volume, 1e-6),
    ("rad", Kind::Angle, 1.0),
    ("deg", Kind::Angle, std::f64::consts::PI / 180.0),
];

/// A column's unit: SI value = `scale * value + offset`.
#[derive(Clone, Debug, PartialEq)]
pub struct Unit {
    /// As written in the header.
    pub text: String,
    pub kind: Kind,
    pub scale: f64,
    /// [`AMBIENT`] for a gauge pressure, else 0.
    pub offset: f64,
}

impl Unit {
    /// The SI value of `v`.
    pub fn si(&self, v: f64) -> f64 {
        self.scale * v + self.offset
    }
}

/// A header cell split into its column name and its unit, if one is given in brackets or
/// parentheses after the name (`p [kPa]`, `p (kPa)`).
pub fn split(cell: &str) -> (&str, Option<&str>) {
    for (open, close) in [('[', ']'), ('(', ')')] {
        if let (Some(a), true) = (cell.find(open), cell.ends_with(close)) {
            let name = cell[..a].trim();
            if !name.is_empty() {
                return (name, Some(cell[a + 1..cell.len() - 1].trim()));
            }
        }
    }
    (cell, None)
}

/// Fold the spellings people log: `µs`, `cm³`, `cc`, `°`, `L`, `mL`, `degrees`.
fn canonical(s: &str) -> String {
    let s = s
        .replace('µ', "u")
        .replace('³', "^3")
        .replace("**3", "^3")
        .replace('°', "deg");
    match s.as_str() {
        "cc" | "ccm" | "cm3" => "cm^3".into(),
        "m3" => "m^3".into(),
        "mm3" => "mm^3".into(),
        "L" => "l".into(),
        "mL" => "ml".into(),
        "degrees" | "degree" => "deg".into(),
        "sec" => "s".into(),
        "msec" => "ms".into(),
        _ => s,
    }
}

/// A gauge pressure's unit without its gauge mark: `kPa gauge`, `kPa(g)`, `kPag`, `psig`,
/// `barg`, `gauge kPa`.
fn without_gauge(s: &str) -> Option<&str> {
    let s = s.trim();
    if let Some(r) = s.strip_suffix("gauge").or_else(|| s.strip_suffix("(g)")) {
        return Some(r.trim());
    }
    if let Some(r) = s.strip_prefix("gauge") {
        return Some(r.trim());
    }
    ["kPag", "MPag", "psig", "barg", "Pag"]
        .contains(&s)
        .then(|| &s[..s.len() - 1])
}

/// Why a header's unit cannot be read.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum UnitError {
    #[error(
        "unknown unit `{text}`: the units read are {known} (and `gauge` after a pressure unit)"
    )]
    Unknown { text: String, known: String },
    #[error("`{text}`: only a pressure can be gauge, `{body}` is {noun}")]
    GaugeNotPressure {
        text: String,
        body: String,
        noun: &'static str,
    },
    #[error("`{column}` is {expected}, but `{text}` is {found}: use one of {known}")]
    WrongKind {
        column: String,
        text: String,
        expected: &'static str,
        found: &'static str,
        known: String,
    },
}

/// The unit written as `text`, or why it is not one.
pub fn parse(text: &str) -> Result<Unit, UnitError> {
    let (body, gauge) = match without_gauge(text) {
        Some(b) => (b, true),
        None => (text.trim(), false),
    };
    let c = canonical(body);
    let Some(&(_, kind, scale)) = UNITS.iter().find(|u| u.0 == c) else {
        let all: Vec<&str> = UNITS.iter().map(|u| u.0).collect();
        return Err(UnitError::Unknown {
            text: text.to_string(),
            known: all.join(", "),
        });
    };
    if gauge && kind != Kind::Pressure {
        return Err(UnitError::GaugeNotPressure {
            text: text.to_string(),
            body: body.to_string(),
            noun: kind.noun(),
        });
    }
    Ok(Unit {
        text: text.trim().to_string(),
        kind,
        scale,
        offset: if gauge { AMBIENT } else { 0.0 },
    })
}

/// What column `name` measures, when the record format fixes it.
pub fn kind_of(name: &str) -> Option<Kind> {
    match name {
        "t" => Some(Kind::Time),
        "p" | "p_hot" => Some(Kind::Pressure),
        "x" | "y" => Some(Kind::Length),
        _ => None,
    }
}

/// The unit of column `name` written as `text`, checked against what the column measures.
pub fn for_column(name: &str, text: &str) -> Result<Unit, UnitError> {
    let u = parse(text)?;
    match kind_of(name) {
        Some(k) if k != u.kind => Err(UnitError::WrongKind {
            column: name.to_string(),
            text: text.to_string(),
            expected: k.noun(),
            found: u.kind.noun(),
            known: k.known(),
        }),
        _ => Ok(u),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_cells_split_into_name_and_unit() {
        assert_eq!(split("p [kPa]"), ("p", Some("kPa")));
        assert_eq!(split("x (mm)"), ("x", Some("mm")));
        assert_eq!(split("t"), ("t", None));
        // a bracket alone is not a unit
        assert_eq!(split("[kPa]"), ("[kPa]", None));
    }

    #[test]
    fn units_convert_to_si() {
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs().max(1.0);
        assert!(close(parse("kPa").unwrap().si(101.325), 101_325.0));
        assert!(close(parse("kPa gauge").unwrap().si(0.0), AMBIENT));
        assert!(close(
            parse("psig").unwrap().si(1.0),
            AMBIENT + 6_894.757_293_168
        ));
        assert!(close(parse("bar").unwrap().si(2.0), 2e5));
        assert!(close(parse("mm").unwrap().si(5.0), 5e-3));
        assert!(close(parse("ms").unwrap().si(250.0), 0.25));
        assert!(close(parse("cm³").unwrap().si(3.0), 3e-6));
        assert!(close(parse("cc").unwrap().si(3.0), 3e-6));
        assert!(close(parse("deg").unwrap().si(180.0), std::f64::consts::PI));
        assert!(close(parse("µs").unwrap().si(1.0), 1e-6));
    }

    #[test]
    fn wrong_units_are_refused_with_what_would_do() {
        let e = parse("kPaa").unwrap_err().to_string();
        assert!(
            e.contains("unknown unit `kPaa`") && e.contains("kPa"),
            "{e}"
        );
        let e = for_column("x", "kPa").unwrap_err().to_string();
        assert!(e.contains("`x` is a length") && e.contains("mm"), "{e}");
        let e = for_column("p", "mm").unwrap_err().to_string();
        assert!(e.contains("a pressure") && e.contains("gauge"), "{e}");
        let e = parse("mm gauge").unwrap_err().to_string();
        assert!(e.contains("only a pressure can be gauge"), "{e}");
        // a column the format does not fix takes any unit
        assert_eq!(for_column("dV", "cm^3").unwrap().kind, Kind::Volume);
    }
}
