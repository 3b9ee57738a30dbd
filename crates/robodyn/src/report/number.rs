//! How numbers are written: the one formatter of the library and the CLI, in two forms.
//!
//! - **Data** ([`Number`], [`format_number`]): what another program reads back (CSV, robot
//!   files, JSON-like text). The shortest decimal that reads back to the same `f64` (Rust's
//!   shortest round-trip digits), whole numbers below 1e15 as integers (`1`, `-3`), an exponent
//!   outside [1e-5, 1e16) (`1e49`, `2.5e-7`), and `0` for both zeros.
//! - **Reports** ([`Sig`], [`significant`]): what a person reads (tables, messages, plot
//!   labels). A fixed number of significant digits, written like C's `%g`: plain decimals when
//!   the decimal exponent e of the rounded value is in [-4, digits), else `d.ddde<e>`; trailing
//!   zeros (and a trailing point) dropped, so `5000` Hz, `8.9998` s, `1.68993`, `2.5e-7`,
//!   `1.235e6`; never `e0`, `e+`, or `-0` (a value that rounds to zero is `0`).
//!
//! Both write `NaN`, `inf` and `-inf` for non-finite values (a result that is not finite is an
//! error elsewhere; a report that must show one says so rather than panic).

use std::fmt;

/// [`Number`] as a `String`: the data form (shortest round-trip).
pub fn format_number(x: f64) -> String {
    Number(x).to_string()
}

/// The data form of a number as a `Display`, written in place (`write!(out, "{}",
/// Number(x))`: no allocation per number). See the [module](self).
#[derive(Clone, Copy, Debug)]
pub struct Number(pub f64);

impl fmt::Display for Number {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let x = self.0;
        if x == 0.0 {
            f.write_str("0")
        } else if x.fract() == 0.0 && x.abs() < 1e15 {
            write!(f, "{}", x as i64)
        } else {
            // Debug is Display's shortest round-trip digits, switching to an exponent for very
            // small and very large magnitudes
            write!(f, "{x:?}")
        }
    }
}

/// [`Sig`] as a `String`: `x` with `digits` significant digits, the report form.
pub fn significant(x: f64, digits: usize) -> String {
    Sig(x, digits).to_string()
}

/// The report form of a number: `Sig(x, digits)` writes `x` with `digits` (at least 1)
/// significant digits, `%g`-style. See the [module](self).
#[derive(Clone, Copy, Debug)]
pub struct Sig(pub f64, pub usize);

impl fmt::Display for Sig {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (x, digits) = (self.0, self.1.max(1));
        if !x.is_finite() {
            return write!(f, "{}", Number(x));
        }
        if x == 0.0 {
            return f.write_str("0");
        }
        // the exponent after rounding to `digits` (9.9996 with 4 digits is 10.00: e = 1)
        let sci = format!("{x:.*e}", digits - 1);
        let (mantissa, exp) = sci.split_once('e').expect("`e` formatting has an exponent");
        let exp: i32 = exp
            .parse()
            .expect("`e` formatting writes an integer exponent");
        if exp >= 308 && sci.parse::<f64>().is_ok_and(f64::is_infinite) {
            // rounded past the largest double (1.8e308 with 1 digit): the data form
            write!(f, "{}", Number(x))
        } else if exp < -4 || exp >= digits as i32 {
            write!(f, "{}e{exp}", trim_zeros(mantissa))
        } else {
            let decimals = (digits as i32 - 1 - exp).max(0) as usize;
            f.write_str(trim_zeros(&format!("{x:.decimals$}")))
        }
    }
}

/// A vector for a message: `[0.1, -2.5e-7, 3]`, each entry in the report form with `digits`
/// significant digits.
pub fn vector(v: &[f64], digits: usize) -> String {
    let s: Vec<String> = v.iter().map(|&x| significant(x, digits)).collect();
    format!("[{}]", s.join(", "))
}

/// `1.2300` -> `1.23`, `5000.00` -> `5000`, `7` -> `7` (only after a decimal point).
fn trim_zeros(s: &str) -> &str {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::{format_number, significant};

    /// Every finite f64 (random bit patterns, fixed seed, and edge cases) reads back exactly,
    /// in at most 24 characters; whole numbers are integers; no `-0`.
    #[test]
    fn format_number_round_trips_short() {
        let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
        let mut values = vec![
            1e49,
            -1e-300,
            f64::MIN_POSITIVE,
            5e-324,
            f64::MAX,
            0.1 + 0.2,
            1e15,
            1e15 - 1.0,
            123456.0,
            -0.5,
        ];
        for _ in 0..20000 {
            // xorshift64
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            values.push(f64::from_bits(x));
        }
        for v in values.into_iter().filter(|v| v.is_finite()) {
            let s = format_number(v);
            assert_eq!(s.parse::<f64>().unwrap(), v, "{s}");
            assert!(s.len() <= 24, "{v:e} written as {s}");
        }
        assert_eq!(format_number(-0.0), "0");
        assert_eq!(format_number(0.0), "0");
        assert_eq!(format_number(1.0), "1");
        assert_eq!(format_number(-3.0), "-3");
        assert_eq!(format_number(1e49), "1e49");
        assert_eq!(format_number(2.5e-7), "2.5e-7");
        assert_eq!(format_number(0.1 + 0.2), "0.30000000000000004");
        assert_eq!(format_number(1e300), "1e300");
    }

    /// The report form on the values issue 30 found printed as `5000.000000`, `1.68993e0`,
    /// `0.000000e0`, `-0.000000`, and its rules at the edges.
    #[test]
    fn significant_digits_for_people() {
        assert_eq!(significant(5000.0, 6), "5000");
        assert_eq!(significant(1.689934, 6), "1.68993");
        assert_eq!(significant(0.0, 6), "0");
        assert_eq!(significant(-0.0, 6), "0");
        assert_eq!(significant(-1e-9, 6), "-1e-9");
        assert_eq!(significant(8.99980001, 6), "8.9998");
        assert_eq!(significant(8.4937, 4), "8.494");
        assert_eq!(significant(-1234.4, 4), "-1234");
        assert_eq!(significant(0.012345, 3), "0.0123");
        assert_eq!(significant(3.0e7, 3), "3e7");
        assert_eq!(significant(1234567.0, 4), "1.235e6");
        assert_eq!(significant(9.9996, 4), "10");
        assert_eq!(significant(0.00012345, 3), "0.000123");
        assert_eq!(significant(0.000012345, 3), "1.23e-5");
        assert_eq!(significant(2.8879e-4, 6), "0.00028879");
        assert_eq!(significant(f64::NAN, 3), "NaN");
        assert_eq!(significant(f64::NEG_INFINITY, 3), "-inf");
        // 12 digits remove the noise of sums: 10.899999999999999 -> 10.9
        assert_eq!(significant(10.899999999999999, 12), "10.9");
        assert_eq!(significant(0.1 + 0.2, 12), "0.3");
        // no output has `e0`, `e+`, `-0` or a trailing point, over many magnitudes
        let mut x: u64 = 0x2545_F491_4F6C_DD1D;
        for _ in 0..20000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let v = f64::from_bits(x);
            if !v.is_finite() {
                continue;
            }
            for d in [1, 3, 6, 12] {
                let s = significant(v, d);
                assert!(
                    !s.contains("e0") && !s.contains("e+") && !s.ends_with('.'),
                    "{s}"
                );
                let back: f64 = s.parse().unwrap();
                assert!(back != 0.0, "{v:e} with {d} digits: {s}");
                let tol = 10f64.powi(1 - d as i32) * v.abs();
                assert!((back - v).abs() <= tol, "{v:e} with {d} digits: {s}");
            }
        }
    }
}
