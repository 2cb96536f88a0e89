//! Real roots of `A β² + B β + C = 0` in the numerically stable form.

/// The roots of a quadratic with `A > 0`, or `None` when the discriminant
/// is negative. The smaller root comes first; a double root is returned twice.
///
/// Uses `q = -(B + sign(B) √disc) / 2`, roots `q / A` and `C / q`, which
/// avoids the cancellation of the schoolbook formula. Never produces NaN
/// for finite inputs with `A > 0`.
#[inline]
pub fn solve(a: f64, b: f64, c: f64, discriminant: f64) -> Option<(f64, f64)> {
    if discriminant < 0.0 || a.is_nan() || a <= 0.0 {
        return None;
    }
    let sqrt = discriminant.sqrt();
    let q = if b >= 0.0 {
        -0.5 * (b + sqrt)
    } else {
        -0.5 * (b - sqrt)
    };
    if q == 0.0 {
        // b = 0 and disc = 0, so c = 0: a double root at 0.
        return Some((0.0, 0.0));
    }
    let r0 = q / a;
    let r1 = c / q;
    Some(if r0 <= r1 { (r0, r1) } else { (r1, r0) })
}

/// `B² - 4AC`.
#[inline]
pub fn discriminant(a: f64, b: f64, c: f64) -> f64 {
    b * b - 4.0 * a * c
}
