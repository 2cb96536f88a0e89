//! The one wording of the checks on input numbers, shared by the trace
//! validation, the simulation's options, the command-line flags and the
//! comparison tolerances: `must be a finite number ≥ 0, got -1`.
//!
//! Each function returns the problem in words, without the field's name;
//! the caller puts it next to the name the user knows (a JSON field path, a
//! flag, a parameter).

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
        Err(format!("must be {wanted}, got {value}"))
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
            "must be smaller than the radius {radius} (0 ≤ margin < radius), got {margin}"
        ))
    }
}
