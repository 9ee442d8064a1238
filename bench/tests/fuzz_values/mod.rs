//! The numbers the fuzz tests of configs and command lines try: hostile spellings and random
//! magnitudes.

use rand::Rng;
use rand_chacha::ChaCha8Rng;

/// Zeros, signs, the extremes of `f64`, NaN and the infinities (in several spellings), the
/// integer limits and just past them, numbers no integer or float type holds, and non-numbers.
pub const HOSTILE: [&str; 26] = [
    "0",
    "0.0",
    "-0",
    "-0.0",
    "-1",
    "1",
    "0.5",
    "1e-300",
    "-1e-300",
    "1e300",
    "-1e300",
    "NaN",
    "nan",
    "inf",
    "-inf",
    "4294967295",
    "4294967296",
    "-2147483649",
    "9223372036854775807",
    "18446744073709551615",
    "18446744073709551616",
    "340282366920938463463374607431768211456",
    "1e400",
    "\"1\"",
    "true",
    "fast",
];

/// `count` random numbers from 1e-12 to 1e12 in magnitude, a fifth negative, a third written as
/// integers.
pub fn random(rng: &mut ChaCha8Rng, count: usize) -> Vec<String> {
    (0..count)
        .map(|_| {
            let magnitude = 10f64.powf(rng.random_range(-12.0..12.0));
            let value = if rng.random_bool(0.8) {
                magnitude
            } else {
                -magnitude
            };
            if rng.random_bool(0.3) {
                format!("{}", value.round() as i64)
            } else {
                format!("{value:?}")
            }
        })
        .collect()
}

/// Fails listing the cases that panicked, then those that were accepted outside their range or
/// refused without naming what was wrong.
pub fn assert_clean(panics: &[String], wrong: &[String]) {
    assert!(
        panics.is_empty(),
        "{} panics:\n{}",
        panics.len(),
        panics.join("\n")
    );
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}
