//! Inventory closure of the gas model (docs/physics.md section 4).

use serde::{Deserialize, Serialize};

/// How the masses of linked control volumes are treated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Closure {
    /// Every linked CV keeps its mass as a state: mass consistent (the default).
    #[default]
    Full,
    /// Masses frozen at their equilibrium values `m_i0`: one state per CV, as the seed counts
    /// orders; not mass consistent.
    Frozen,
}

impl Closure {
    /// `"full"` or `"frozen"`.
    pub fn as_str(self) -> &'static str {
        match self {
            Closure::Full => "full",
            Closure::Frozen => "frozen",
        }
    }
}

impl std::fmt::Display for Closure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

impl std::str::FromStr for Closure {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "full" => Ok(Closure::Full),
            "frozen" => Ok(Closure::Frozen),
            _ => Err(format!(
                "unknown closure `{s}`: expected `full` or `frozen`"
            )),
        }
    }
}
