//! Real roots of `A β² + B β + C = 0` in the numerically stable form.

/// The roots of a quadratic with `A > 0`, or `None` when the discriminant
/// is negative. The smaller root comes first; a double root is returned twice.
///
/// Uses `q = -(B + sign(B) √disc) / 2`, roots `q / A` and `C / q`, which
/// avoids the cancellation of the schoolbook formula. Never produces NaN:
/// a NaN discriminant (an overflowed input) or a NaN root gives `None`.
///
/// `q = 0` happens only when `B = 0` and the discriminant is 0. The
/// discriminant is computed in another form than `B² - 4AC` (see
/// [`discriminant_from_cross`]) and can round to 0 while `C ≠ 0`, so the
/// roots then come from `A β² + C = 0` itself: none for `C > 0`,
/// `±√(-C/A)` for `C < 0`, a double root at 0 only for `C = 0`.
#[inline]
pub fn solve(a: f64, b: f64, c: f64, discriminant: f64) -> Option<(f64, f64)> {
    if discriminant.is_nan() || discriminant < 0.0 || a.is_nan() || a <= 0.0 {
        return None;
    }
    let sqrt = discriminant.sqrt();
    let q = if b >= 0.0 {
        -0.5 * (b + sqrt)
    } else {
        -0.5 * (b - sqrt)
    };
    if q == 0.0 {
        // B = 0 and the discriminant rounded to 0: solve A β² + C = 0.
        return if c > 0.0 {
            None
        } else if c == 0.0 {
            Some((0.0, 0.0))
        } else {
            let r = (-c / a).sqrt();
            (!r.is_nan()).then_some((-r, r))
        };
    }
    let r0 = q / a;
    let r1 = c / q;
    if r0.is_nan() || r1.is_nan() {
        return None;
    }
    Some(if r0 <= r1 { (r0, r1) } else { (r1, r0) })
}

/// Where a ball-versus-line or ball-versus-point quadratic first touches the
/// path, from its roots (`solve`'s answer): the smaller root `s0` when it
/// lies in `[0, 1]`; otherwise why not (no real roots, before the start,
/// beyond the end). The one ladder of the edge and the vertex tests (steps
/// 2 to 4 of the edge test in docs/SEMANTICS.md).
#[inline]
pub(crate) fn first_contact(roots: Option<(f64, f64)>) -> Result<f64, super::record::Verdict> {
    use super::record::Verdict;
    match roots {
        None => Err(Verdict::NoRealRoots),
        Some((s0, _)) if s0 < 0.0 => Err(Verdict::BeforeStart),
        Some((s0, _)) if s0 > 1.0 => Err(Verdict::BeyondEnd),
        Some((s0, _)) => Ok(s0),
    }
}

/// `B² - 4AC` of a ball-versus-line or ball-versus-point quadratic, computed
/// without cancellation: with `A = |d|²`, `B = 2 d·m`, `C = |m|² - ρ²`
/// (Lagrange's identity `|d|²|m|² - (d·m)² = |d × m|²`),
/// `B² - 4AC = 4 (ρ² A - |d × m|²)`. `cross_squared` is `|d × m|²`.
///
/// `B²` and `4AC` are both about `(2 |d| |m|)²`; when the start is far from
/// the feature compared with `ρ`, their difference `4 ρ² A - 4 |d × m|²` is
/// below their rounding error, and for `|d| |m|` above about 1e154 both
/// overflow and `B² - 4AC` is NaN. This form has neither problem.
#[inline]
pub fn discriminant_from_cross(a: f64, rho: f64, cross_squared: f64) -> f64 {
    4.0 * (rho * rho * a - cross_squared)
}

#[cfg(test)]
mod tests {
    use super::solve;

    #[test]
    fn zero_q_uses_the_sign_of_c() {
        // B = 0 and a discriminant rounded to 0: the sign of C decides.
        assert_eq!(solve(2.0, 0.0, 1e-17, 0.0), None);
        assert_eq!(solve(2.0, 0.0, 0.0, 0.0), Some((0.0, 0.0)));
        assert_eq!(solve(2.0, 0.0, -8.0, 0.0), Some((-2.0, 2.0)));
        assert_eq!(solve(2.0, -0.0, 1e-17, 0.0), None);
    }
}
