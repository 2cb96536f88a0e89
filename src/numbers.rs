//! The one wording of the checks on input numbers, shared by the trace
//! validation, the simulation's options, the command-line flags and the
//! comparison tolerances: `must be a finite number ≥ 0, got -1`.
//!
//! Each function returns the problem in words, without the field's name;
//! the caller puts it next to the name the user knows (a JSON field path, a
//! flag, a parameter).

/// `x` in the shortest decimal that reads back to the same `f64`, as a
/// person writes it: `0.3`, `250`, `-1.5`; with an exponent when plain
/// digits would be long (`1e308`, not 309 digits; `1e-7`, not
/// `0.0000001`). `inf`, `-inf`, `NaN` as Rust writes them. Every number
/// taken from an input and printed in a message goes through it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shortest(pub f64);

impl std::fmt::Display for Shortest {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let x = self.0;
        let a = x.abs();
        if x.is_finite() && x != 0.0 && !(1e-5..1e16).contains(&a) {
            write!(f, "{x:e}")
        } else {
            write!(f, "{x}")
        }
    }
}

/// [`Shortest`] as a string.
pub fn shortest(x: f64) -> String {
    Shortest(x).to_string()
}

/// What a number must be.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rule {
    /// Any finite number.
    Finite,
    /// A finite number `≥ 0`.
    NonNegative,
    /// A finite number `> 0`.
    Positive,
}

/// Checks `value` against `rule`; the error says what was expected and
/// what was given (`must be a finite number > 0, got NaN`).
pub fn check(value: f64, rule: Rule) -> Result<(), String> {
    let (ok, wanted) = match rule {
        Rule::Finite => (value.is_finite(), "a finite number"),
        Rule::NonNegative => (value.is_finite() && value >= 0.0, "a finite number ≥ 0"),
        Rule::Positive => (value.is_finite() && value > 0.0, "a finite number > 0"),
    };
    if ok {
        Ok(())
    } else {
        Err(format!("must be {wanted}, got {}", Shortest(value)))
    }
}

/// Checks every coordinate of `point`; the error names the coordinate
/// (`[2] must be a finite number, got inf`).
pub fn check_point(point: &[f64; 3]) -> Result<(), String> {
    for (k, &c) in point.iter().enumerate() {
        check(c, Rule::Finite).map_err(|e| format!("[{k}] {e}"))?;
    }
    Ok(())
}

/// Checks a margin against the radius it belongs to: `0 ≤ margin < radius`
/// (both finite).
pub fn check_margin(margin: f64, radius: f64) -> Result<(), String> {
    check(margin, Rule::NonNegative)?;
    if margin < radius {
        Ok(())
    } else {
        Err(format!(
            "must be smaller than the radius {} (0 ≤ margin < radius), got {}",
            Shortest(radius),
            Shortest(margin)
        ))
    }
}

/// `x` as a hexadecimal floating-point literal, as C's `%a` writes it:
/// `0x1.5555555555555p-2`, `-0x1.8p+1`, `0x0p+0`; subnormals as
/// `0x0.0000000000001p-1022`. Exact: [`parse_f64`] reads it back to the
/// same bits. Infinities and NaN are written `inf`, `-inf`, `NaN`.
pub fn hex_float(x: f64) -> String {
    if x.is_nan() {
        return "NaN".to_string();
    }
    let sign = if x.is_sign_negative() { "-" } else { "" };
    if x.is_infinite() {
        return format!("{sign}inf");
    }
    let bits = x.to_bits();
    let exponent_bits = ((bits >> 52) & 0x7ff) as i64;
    let mantissa = bits & ((1u64 << 52) - 1);
    let (lead, exponent) = match exponent_bits {
        0 if mantissa == 0 => return format!("{sign}0x0p+0"),
        0 => (0, -1022),
        e => (1, e - 1023),
    };
    let mut fraction = format!("{mantissa:013x}");
    while fraction.ends_with('0') {
        fraction.pop();
    }
    let dot = if fraction.is_empty() { "" } else { "." };
    let exponent_sign = if exponent >= 0 { "+" } else { "-" };
    format!(
        "{sign}0x{lead}{dot}{fraction}p{exponent_sign}{}",
        exponent.abs()
    )
}

/// Reads a number written as a decimal (`0.1`, `-3e-5`, Rust's `{}` and
/// `{:?}` of an `f64`) or as a hexadecimal floating-point literal
/// (`0x1.5555555555555p-2`, as [`hex_float`] writes it). Both are read
/// exactly: a shortest round-trip decimal or a hex float gives back the
/// bits it was written from. A hex float needs at most 53 significant
/// bits.
pub fn parse_f64(s: &str) -> Option<f64> {
    let s = s.trim();
    let (negative, body) = match s.as_bytes().first() {
        Some(b'-') => (true, &s[1..]),
        Some(b'+') => (false, &s[1..]),
        _ => (false, s),
    };
    let Some(hex) = body.strip_prefix("0x").or_else(|| body.strip_prefix("0X")) else {
        return s.parse().ok();
    };
    let (digits, exponent) = hex.split_once(['p', 'P'])?;
    let exponent: i32 = exponent.parse().ok()?;
    let (int, frac) = digits.split_once('.').unwrap_or((digits, ""));
    if int.is_empty() && frac.is_empty() {
        return None;
    }
    let mut mantissa: u64 = 0;
    for c in int.chars().chain(frac.chars()) {
        let d = c.to_digit(16)?;
        mantissa = mantissa.checked_mul(16)?.checked_add(u64::from(d))?;
    }
    if mantissa > 1u64 << 53 {
        return None;
    }
    let mut scale = i64::from(exponent) - 4 * frac.len() as i64;
    // Exact: the mantissa has at most 53 bits, and powers of two scale it
    // without rounding until the final step lands on a representable value.
    let mut value = mantissa as f64;
    while scale != 0 && value != 0.0 {
        let step = scale.clamp(-1000, 1000);
        value *= 2f64.powi(step as i32);
        scale -= step;
    }
    value
        .is_finite()
        .then_some(if negative { -value } else { value })
}

/// `noun` or `noun`s for `n` of them (regular plurals; see [`counted`]).
pub fn plural(n: u64, noun: &str) -> String {
    if n == 1 {
        noun.to_string()
    } else {
        format!("{noun}s")
    }
}

/// The verb for a subject of `n`: `one` for 1 (`diverges`), `many`
/// otherwise (`diverge`), as in `1 of 5 sweeps diverges`.
pub fn verb<'a>(n: u64, one: &'a str, many: &'a str) -> &'a str {
    if n == 1 { one } else { many }
}

/// A budget in words: `2^12` for a power of two of 32 or more, else the
/// shortest decimal (`4`, `0.5`, `100`).
pub fn power_of_two_text(x: f64) -> String {
    let exponent = x.log2();
    if x >= 32.0 && x.is_finite() && exponent.fract() == 0.0 {
        format!("2^{exponent}")
    } else {
        shortest(x)
    }
}

/// `n` and the word for that many: `1 vertex`, `3 vertices`.
pub fn counted(n: u64, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}

#[cfg(test)]
mod tests {
    use super::{Shortest, hex_float, parse_f64};

    #[test]
    fn shortest_forms_read_back() {
        for (x, text) in [
            (0.3, "0.3"),
            (250.0, "250"),
            (-1.5, "-1.5"),
            (0.0, "0"),
            (1e308, "1e308"),
            (1e300, "1e300"),
            (1e-7, "1e-7"),
            (1.5e-300, "1.5e-300"),
            (1e15, "1000000000000000"),
            (1e16, "1e16"),
            (0.00001, "0.00001"),
            (f64::MAX, "1.7976931348623157e308"),
            (f64::INFINITY, "inf"),
        ] {
            assert_eq!(Shortest(x).to_string(), text);
            assert_eq!(parse_f64(text), Some(x));
        }
    }

    #[test]
    fn hex_floats_round_trip() {
        assert_eq!(hex_float(1.0 / 3.0), "0x1.5555555555555p-2");
        assert_eq!(hex_float(-3.0), "-0x1.8p+1");
        assert_eq!(hex_float(0.0), "0x0p+0");
        assert_eq!(hex_float(-0.0), "-0x0p+0");
        assert_eq!(hex_float(f64::from_bits(1)), "0x0.0000000000001p-1022");
        for x in [
            1.0 / 3.0,
            -0.1,
            0.0,
            -0.0,
            f64::MAX,
            f64::MIN_POSITIVE,
            f64::from_bits(1),
            f64::from_bits(0x000f_ffff_ffff_ffff),
            123456.789,
            1e-300,
        ] {
            let back = parse_f64(&hex_float(x)).expect("parses");
            assert_eq!(back.to_bits(), x.to_bits(), "{x} via {}", hex_float(x));
            assert_eq!(
                parse_f64(&format!("{x}")).map(f64::to_bits),
                Some(x.to_bits())
            );
            assert_eq!(
                parse_f64(&format!("{x:?}")).map(f64::to_bits),
                Some(x.to_bits())
            );
        }
        assert_eq!(parse_f64("0x1p-1074"), Some(f64::from_bits(1)));
        assert_eq!(parse_f64("0xAp0"), Some(10.0));
        assert_eq!(parse_f64("0x.p0"), None);
        assert_eq!(parse_f64("0x1.0"), None);
        assert_eq!(parse_f64("0x1p+1024"), None);
    }
}
