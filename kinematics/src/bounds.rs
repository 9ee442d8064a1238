//! The documented range of every number a robot config or a command line takes.
//!
//! Each config section keeps its table of [`Bound`]s next to its keys, one line per key, and
//! checks it when it is read ([`first_outside`]); the docs page that owns the section lists the
//! same ranges. A command-line number takes [`Range::parser`] as its `clap` value parser, so a
//! value outside its range is refused while the command line is parsed, naming the flag.

use std::fmt;

/// A closed range of finite numbers; NaN and the infinities lie outside every range.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Range {
    /// The smallest value allowed.
    pub min: f64,
    /// The largest value allowed.
    pub max: f64,
}

impl Range {
    /// `[min, max]`.
    pub const fn new(min: f64, max: f64) -> Self {
        Self { min, max }
    }

    /// Whether `value` lies in the range (never for NaN or an infinity).
    pub fn contains(self, value: f64) -> bool {
        self.min <= value && value <= self.max
    }

    /// What a value must satisfy: `must be in [min, max]`.
    pub fn requirement(self) -> String {
        format!("must be in {self}")
    }

    /// A command-line value parser (for `#[arg(value_parser = RANGE.parser())]`): the number if
    /// it parses and lies in the range, else what is wrong (clap names the flag and the value).
    pub fn parser(self) -> impl Fn(&str) -> Result<f64, String> + Clone + Send + Sync + 'static {
        move |text| {
            let value: f64 = text.trim().parse().map_err(|_| "not a number".to_owned())?;
            if self.contains(value) {
                Ok(value)
            } else {
                Err(self.requirement())
            }
        }
    }
}

impl fmt::Display for Range {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "[{}, {}]", Number(self.min), Number(self.max))
    }
}

/// A number as a person reads it: plain in the usual magnitudes, `1e-300` rather than three
/// hundred zeros outside them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Number(pub f64);

impl fmt::Display for Number {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let magnitude = self.0.abs();
        if self.0 == 0.0 || !self.0.is_finite() || (1e-4..1e9).contains(&magnitude) {
            write!(f, "{}", self.0)
        } else {
            write!(f, "{:e}", self.0)
        }
    }
}

/// One numeric key of a config section with its value and its documented range: one line of
/// the section's table.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bound {
    /// The key, as written in the file (`rate_hz`, `sole.length`).
    pub key: &'static str,
    /// Its value; `None` for an optional key the file leaves out.
    pub value: Option<f64>,
    /// Where the value must lie.
    pub range: Range,
}

impl Bound {
    /// `key = value` must lie in `[min, max]`.
    pub fn new(key: &'static str, value: f64, min: f64, max: f64) -> Self {
        Self::optional(key, Some(value), min, max)
    }

    /// An optional `key` must lie in `[min, max]` when it is given.
    pub fn optional(key: &'static str, value: Option<f64>, min: f64, max: f64) -> Self {
        Self {
            key,
            value,
            range: Range::new(min, max),
        }
    }
}

/// A value outside its range: `key = value: must be in [min, max]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Violation {
    /// The key.
    pub key: &'static str,
    /// Its value.
    pub value: f64,
    /// Its range.
    pub range: Range,
}

impl fmt::Display for Violation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} = {}: {}",
            self.key,
            Number(self.value),
            self.range.requirement()
        )
    }
}

/// The first value of `bounds` outside its range, if any.
pub fn first_outside(bounds: &[Bound]) -> Option<Violation> {
    bounds.iter().find_map(|bound| {
        let value = bound.value?;
        (!bound.range.contains(value)).then_some(Violation {
            key: bound.key,
            value,
            range: bound.range,
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_non_finite_value_is_outside_and_the_ends_are_inside() {
        let range = Range::new(1.0, 10_000.0);
        for value in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 0.999, 10_000.5] {
            assert!(!range.contains(value), "{value}");
        }
        assert!(range.contains(1.0) && range.contains(10_000.0));
    }

    #[test]
    fn the_first_value_outside_is_named_and_absent_optional_keys_pass() {
        let bounds = [
            Bound::optional("com_height_m", None, 0.1, 3.0),
            Bound::new("rate_hz", 500.0, 1.0, 10_000.0),
            Bound::new("status_rate_hz", 1e-300, 1.0, 1000.0),
            Bound::new("watchdog_periods", f64::NAN, 1.0, 1000.0),
        ];
        let violation = first_outside(&bounds).unwrap();
        assert_eq!(
            violation.to_string(),
            "status_rate_hz = 1e-300: must be in [1, 1000]"
        );
        assert_eq!(first_outside(&bounds[..2]), None);
    }

    #[test]
    fn the_parser_takes_numbers_in_range_only() {
        let parse = Range::new(1e-5, 0.5).parser();
        assert_eq!(parse(" 0.25"), Ok(0.25));
        assert_eq!(parse("1e12"), Err("must be in [1e-5, 0.5]".to_owned()));
        assert_eq!(parse("NaN"), Err("must be in [1e-5, 0.5]".to_owned()));
        assert_eq!(parse("fast"), Err("not a number".to_owned()));
    }
}
