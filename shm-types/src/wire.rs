//! How enums and flags travel: as raw integers, read back with a check.
//!
//! A Rust `enum` or `bool` read from shared memory that another process wrote is undefined
//! behaviour when the bytes hold no valid value (a `ControlRequest` whose command field held 257
//! crashed an earlier walkd). So no message type holds one: an enum travels as a [`Code<T>`] (a
//! `u32`) and a flag as a [`Flag`] (a `u8`), and the receiver decodes them with [`Code::get`] /
//! [`Flag::get`], which name the value they could not read.

use core::marker::PhantomData;

use iceoryx2::prelude::ZeroCopySend;

/// A received field held a value the contract does not define.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("{what} holds {value}, expected {expected}")]
pub struct DecodeError {
    /// The type (or field) that could not be read.
    pub what: &'static str,
    /// The raw value found.
    pub value: u64,
    /// The values the contract allows, for the message.
    pub expected: &'static str,
}

impl DecodeError {
    /// The same error, naming the field it was read from.
    pub fn in_field(self, field: &'static str) -> Self {
        Self {
            what: field,
            ..self
        }
    }
}

/// A C-like enum that travels as a [`Code`]; implemented by [`wire_enum!`].
pub trait WireEnum: Copy + 'static {
    /// The enum's name, for errors.
    const NAME: &'static str;
    /// The codes and their names, for errors ("0 hold, 1 track").
    const EXPECTED: &'static str;
    /// This value's code.
    fn code(self) -> u32;
    /// The value of `code`, if the contract defines one.
    fn from_code(code: u32) -> Option<Self>;
    /// Lower-case name for printing and JSON.
    fn name(self) -> &'static str;
}

/// An enum `T` as it travels: its `u32` code, decoded with a check.
#[repr(transparent)]
pub struct Code<T> {
    raw: u32,
    _enum: PhantomData<T>,
}

// SAFETY: `Code<T>` is a `u32` (repr(transparent); the PhantomData has no bytes), self-contained
// and valid for every bit pattern.
unsafe impl<T: WireEnum> ZeroCopySend for Code<T> {
    unsafe fn type_name() -> &'static str {
        "walk.v8.Code"
    }
}

impl<T: WireEnum> Code<T> {
    /// A code as received (or as a hostile peer would write it).
    pub const fn from_raw(raw: u32) -> Self {
        Self {
            raw,
            _enum: PhantomData,
        }
    }

    /// The code of `value`.
    pub fn new(value: T) -> Self {
        Self::from_raw(value.code())
    }

    /// The value, or why the code means none.
    pub fn get(self) -> Result<T, DecodeError> {
        T::from_code(self.raw).ok_or(DecodeError {
            what: T::NAME,
            value: u64::from(self.raw),
            expected: T::EXPECTED,
        })
    }

    /// The code as received.
    pub fn raw(self) -> u32 {
        self.raw
    }

    /// The value's name, or `invalid` for a code without one.
    pub fn name(self) -> &'static str {
        self.get().map_or("invalid", T::name)
    }
}

impl<T> Clone for Code<T> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<T> Copy for Code<T> {}

impl<T: WireEnum> PartialEq for Code<T> {
    fn eq(&self, other: &Self) -> bool {
        self.raw == other.raw
    }
}

impl<T: WireEnum> Eq for Code<T> {}

/// Compares the code with a value without decoding (an undefined code equals no value).
impl<T: WireEnum> PartialEq<T> for Code<T> {
    fn eq(&self, other: &T) -> bool {
        self.raw == other.code()
    }
}

impl<T: WireEnum> core::fmt::Debug for Code<T> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self.get() {
            Ok(value) => f.write_str(value.name()),
            Err(_) => write!(f, "invalid {} code {}", T::NAME, self.raw),
        }
    }
}

impl<T: WireEnum> core::fmt::Display for Code<T> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        core::fmt::Debug::fmt(self, f)
    }
}

impl<T: WireEnum> From<T> for Code<T> {
    fn from(value: T) -> Self {
        Self::new(value)
    }
}

/// A yes/no field as it travels: 0 or 1 in a byte, decoded with a check.
#[repr(C)]
#[derive(Clone, Copy, PartialEq, Eq, Default, ZeroCopySend)]
#[type_name("walk.v8.Flag")]
pub struct Flag(u8);

impl Flag {
    /// Not set.
    pub const NO: Self = Self(0);
    /// Set.
    pub const YES: Self = Self(1);

    /// The flag of `value`.
    pub const fn new(value: bool) -> Self {
        Self(value as u8)
    }

    /// A flag byte as received (or as a hostile peer would write it).
    pub const fn from_raw(raw: u8) -> Self {
        Self(raw)
    }

    /// The flag, or why the byte holds neither 0 nor 1.
    pub fn get(self) -> Result<bool, DecodeError> {
        match self.0 {
            0 => Ok(false),
            1 => Ok(true),
            other => Err(DecodeError {
                what: "flag",
                value: u64::from(other),
                expected: "0 or 1",
            }),
        }
    }

    /// Exactly 1 (an invalid byte counts as not set; use [`Flag::get`] where that matters).
    pub fn is_set(self) -> bool {
        self.0 == 1
    }

    /// The byte as received.
    pub fn raw(self) -> u8 {
        self.0
    }
}

impl core::fmt::Debug for Flag {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self.get() {
            Ok(value) => write!(f, "{value}"),
            Err(_) => write!(f, "invalid flag {}", self.0),
        }
    }
}

impl From<bool> for Flag {
    fn from(value: bool) -> Self {
        Self::new(value)
    }
}

/// Declares a C-like enum with codes and lower-case names: the [`WireEnum`] implementation (so
/// it can travel as a [`Code`]), `name()`, and `FromStr` from the names (for command lines).
macro_rules! wire_enum {
    (
        $(#[$meta:meta])*
        pub enum $name:ident {
            $( $(#[$vmeta:meta])* $variant:ident = $code:literal => $text:literal ),+ $(,)?
        }
    ) => {
        $(#[$meta])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq)]
        pub enum $name {
            $( $(#[$vmeta])* $variant = $code ),+
        }

        impl $crate::wire::WireEnum for $name {
            const NAME: &'static str = stringify!($name);
            const EXPECTED: &'static str =
                concat!($( stringify!($code), " (", $text, ") " ),+);

            fn code(self) -> u32 {
                self as u32
            }

            fn from_code(code: u32) -> Option<Self> {
                match code {
                    $( $code => Some(Self::$variant), )+
                    _ => None,
                }
            }

            fn name(self) -> &'static str {
                match self {
                    $( Self::$variant => $text ),+
                }
            }
        }

        impl $name {
            /// Lower-case name for printing and JSON.
            pub fn name(self) -> &'static str {
                $crate::wire::WireEnum::name(self)
            }
        }

        impl core::str::FromStr for $name {
            type Err = String;

            /// Parses a lower-case name.
            fn from_str(text: &str) -> Result<Self, String> {
                match text {
                    $( $text => Ok(Self::$variant), )+
                    other => Err(format!(
                        concat!("unknown ", stringify!($name), " `{}` (expected ",
                            $( $text, " ", )+ ")"),
                        other
                    )),
                }
            }
        }
    };
}

pub(crate) use wire_enum;

#[cfg(test)]
mod tests {
    use super::*;

    wire_enum! {
        /// A test enum.
        pub enum Mode {
            /// First.
            Hold = 0 => "hold",
            /// Second.
            Track = 1 => "track",
        }
    }

    #[test]
    fn codes_round_trip_and_unknown_codes_name_themselves() {
        assert_eq!(Code::new(Mode::Track).get(), Ok(Mode::Track));
        assert!(Code::new(Mode::Hold) == Mode::Hold);
        let error = Code::<Mode>::from_raw(257).get().unwrap_err();
        assert_eq!(error.value, 257);
        let text = error.in_field("mode").to_string();
        assert!(
            text.contains("mode holds 257") && text.contains("1 (track)"),
            "{text}"
        );
        assert!(Code::<Mode>::from_raw(257) != Mode::Hold);
        assert_eq!(Code::<Mode>::from_raw(9).name(), "invalid");
        assert_eq!(Mode::Track.name(), "track");
        assert_eq!("hold".parse(), Ok(Mode::Hold));
        assert!("halt".parse::<Mode>().unwrap_err().contains("halt"));
    }

    #[test]
    fn flags_accept_only_zero_and_one() {
        assert_eq!(Flag::new(true).get(), Ok(true));
        assert_eq!(Flag::NO.get(), Ok(false));
        assert_eq!(Flag(2).get().unwrap_err().value, 2);
        assert!(!Flag(2).is_set());
    }
}
