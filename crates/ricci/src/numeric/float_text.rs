//! Shortest round-trip decimal text of `f64` in Rust's `{:e}` notation (`-1.25e-3`, `0e0`),
//! the notation of the OBJ and OFF files the CLI writes, from the shortest digits of the
//! Schubfach algorithm (Giulietti 2020, "The Schubfach way to render doubles"; the `zmij`
//! crate, already built for `serde_json`) instead of `core::fmt`: the same bytes, several
//! times faster on the millions of coordinates of a large mesh.

/// Whether two shortest digit strings may be equally near `x`, where `core::fmt` rounds half
/// up and Schubfach to even: only when the exact decimal value of `x` has at most 18
/// significant digits (the tie is a 5 right after the digits). With `x = m·2⁻ⁿ`, `m` odd, that
/// value has the digits of `m·5ⁿ`, so it needs `m·5ⁿ < 10¹⁸`: short mantissas (quantized
/// coordinates such as `k/2¹⁶`) and integers. Those `core::fmt` writes (zero too).
fn may_tie(x: f64) -> bool {
    let bits = x.to_bits();
    let (exponent, fraction) = (((bits >> 52) & 0x7ff) as i32, bits & ((1u64 << 52) - 1));
    let (mut m, mut e) = if exponent == 0 {
        (fraction, -1074)
    } else {
        (fraction | 1u64 << 52, exponent - 1075)
    };
    if m == 0 {
        return true;
    }
    let tz = m.trailing_zeros();
    m >>= tz;
    e += tz as i32;
    if e >= 0 {
        return true;
    }
    // log₂(m·5ⁿ) ≥ bits(m) − 1 + n·log₂5; 10¹⁸ = 2^59.79.
    let n = -e as f64;
    f64::from(64 - m.leading_zeros()) + n * 2.321_928 < 61.0
}

/// Append `x` to `out` exactly as `write!(out, "{:e}", x)` would.
pub fn push_exp(out: &mut String, x: f64) {
    if !x.is_finite() || may_tie(x) {
        use std::fmt::Write;
        let _ = write!(out, "{x:e}");
        return;
    }
    let mut buf = zmij::Buffer::new();
    let text = buf.format_finite(x);
    let (negative, text) = match text.strip_prefix('-') {
        Some(t) => (true, t),
        None => (false, text),
    };
    let (mantissa, exp) = match text.find(['e', 'E']) {
        Some(i) => (&text[..i], text[i + 1..].parse::<i32>().unwrap_or(0)),
        None => (text, 0),
    };
    let (int, frac) = mantissa.split_once('.').unwrap_or((mantissa, ""));
    // value = 0.d₁d₂… × 10^point with the digits of `int` then `frac`.
    let mut point = int.len() as i32 + exp;
    let mut digits = [0u8; 40];
    let mut n = 0;
    for &d in int.as_bytes().iter().chain(frac.as_bytes()) {
        if n == 0 && d == b'0' {
            point -= 1;
        } else if n < digits.len() {
            digits[n] = d;
            n += 1;
        }
    }
    while n > 0 && digits[n - 1] == b'0' {
        n -= 1;
    }
    // The text in a byte buffer, pushed once: `-d.ddde-x`.
    let mut text = [0u8; 64];
    let mut len = 0;
    let mut put = |bytes: &[u8]| {
        text[len..len + bytes.len()].copy_from_slice(bytes);
        len += bytes.len();
    };
    if negative {
        put(b"-");
    }
    if n == 0 {
        put(b"0e0");
    } else {
        put(&digits[..1]);
        if n > 1 {
            put(b".");
            put(&digits[1..n]);
        }
        put(b"e");
        put(itoa::Buffer::new().format(point - 1).as_bytes());
    }
    out.push_str(std::str::from_utf8(&text[..len]).unwrap_or_default());
}

#[cfg(test)]
mod tests {
    use super::push_exp;

    /// Bit for bit the text of `core::fmt`'s `{:e}` on special values, powers of ten, halves,
    /// integers and 200 000 doubles with random bits (a linear congruential generator).
    #[test]
    fn push_exp_is_fmt_lower_exp() {
        let mut xs = vec![
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.1,
            0.5,
            1e-7,
            1e21,
            1e22,
            123456789.0,
            f64::MIN_POSITIVE,
            5e-324,
            f64::MAX,
            f64::MIN,
            f64::EPSILON,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        // Short mantissas (k / 2^j) and large integers: exact values with few digits.
        for j in 0..64 {
            for k in 1..2000u64 {
                xs.push(k as f64 / (1u64 << j) as f64);
                xs.push(-((k << j) as f64) - 0.5);
            }
        }
        for k in -320..=308 {
            xs.push(10f64.powi(k));
            xs.push(1.5 * 10f64.powi(k));
        }
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        for _ in 0..200_000 {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            xs.push(f64::from_bits(state));
            xs.push((state >> 11) as f64 / (1u64 << 40) as f64 - 4096.0);
        }
        let mut ours = String::new();
        for x in xs {
            ours.clear();
            push_exp(&mut ours, x);
            assert_eq!(ours, format!("{x:e}"), "bits {:#x}", x.to_bits());
        }
    }
}
