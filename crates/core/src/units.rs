//! Units: deflect is SI inside (m, N, N m, rad, s, kg). This module holds the one standard
//! gravity constant and the file units loaders convert from.

/// Standard gravity g_n \[m/s^2\] (ISO 80000-3; 1 kgf = 9.80665 N).
pub const STANDARD_GRAVITY: f64 = 9.80665;

/// Standard gravity as a base-frame acceleration with z up \[m/s^2\]: the default of every
/// model that takes a gravity vector.
pub const GRAVITY_Z_DOWN: [f64; 3] = [0.0, 0.0, -STANDARD_GRAVITY];

/// Force unit of a file. Moments (force axes 3..5 of a map) are in this unit times the
/// length unit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ForceUnit {
    /// Newton.
    #[default]
    Newton,
    /// Kilogram-force, [`STANDARD_GRAVITY`] N.
    KilogramForce,
}

impl ForceUnit {
    /// Newtons per unit.
    pub fn to_newton(self) -> f64 {
        match self {
            Self::Newton => 1.0,
            Self::KilogramForce => STANDARD_GRAVITY,
        }
    }
    /// Parses "N" or "kgf" (case-insensitive).
    pub fn parse(s: &str) -> Option<Self> {
        if s.eq_ignore_ascii_case("n") {
            Some(Self::Newton)
        } else if s.eq_ignore_ascii_case("kgf") {
            Some(Self::KilogramForce)
        } else {
            None
        }
    }
}

/// Length unit of a file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LengthUnit {
    /// Metre.
    #[default]
    Metre,
    /// Millimetre.
    Millimetre,
    /// Inch (25.4 mm exactly), for G-code in `G20`.
    Inch,
}

impl LengthUnit {
    /// Metres per unit.
    pub fn to_metre(self) -> f64 {
        match self {
            Self::Metre => 1.0,
            Self::Millimetre => 1e-3,
            Self::Inch => 25.4e-3,
        }
    }
    /// Parses "m", "mm" or "in" (case-insensitive).
    pub fn parse(s: &str) -> Option<Self> {
        if s.eq_ignore_ascii_case("m") {
            Some(Self::Metre)
        } else if s.eq_ignore_ascii_case("mm") {
            Some(Self::Millimetre)
        } else if s.eq_ignore_ascii_case("in") {
            Some(Self::Inch)
        } else {
            None
        }
    }
}
