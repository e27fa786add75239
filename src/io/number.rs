//! Decimal numbers of the text formats (OBJ, ASCII PLY and OFF), read
//! exactly as `str::parse::<f64>` reads them, faster for the usual forms;
//! and points as messages print them ([`point_text`]).

/// `(x, y, z)` exactly (shortest round trip), in scientific notation where
/// the plain one runs long (1e300 has 301 digits, 1e-300 as many): a point
/// as a message names it.
pub fn point_text(p: impl Into<[f64; 3]>) -> String {
    let [x, y, z] = p.into();
    format!("({}, {}, {})", number_text(x), number_text(y), number_text(z))
}

/// `x` exactly (shortest round trip), in scientific notation where the
/// plain one runs long: `1e-320`, not 320 zeros; as a message names a
/// number read from a file.
pub fn number_text(x: f64) -> String {
    if x != 0.0 && (x.abs() >= 1e16 || x.abs() < 1e-15) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// Exact powers of ten: every 10^k with k ≤ 22 is an `f64`.
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20,
    1e21, 1e22,
];

/// The `f64` nearest to the decimal number `tok` (the same value as
/// `str::parse::<f64>`, which it falls back to), or `None` if `tok` is not
/// a number that `str::parse` accepts.
#[inline]
pub fn parse_f64(tok: &[u8]) -> Option<f64> {
    match short_decimal(tok) {
        Some(x) => Some(x),
        None => std::str::from_utf8(tok).ok()?.parse().ok(),
    }
}

/// `[+-]digits[.digits]` with at most 19 digits whose integer m is at most
/// 2^53, as m / 10^k (k the digits after the point, at most 22): m and 10^k
/// are exact, so the one division rounds correctly (Clinger's fast path).
/// `None` for anything else (exponents, long mantissas, "inf", ...).
#[inline]
fn short_decimal(tok: &[u8]) -> Option<f64> {
    match short_decimal_prefix(tok)? {
        (x, end) if end == tok.len() => Some(x),
        _ => None,
    }
}

/// The short decimal that `bytes` start with (`[+-]digits[.digits]`, at
/// most 19 digits, at most 22 after the point, a value of at most 2^53
/// before the point is placed: the fast path of [`parse_f64`]) and where it
/// ends: it stops at the first byte that is not a digit or the (one) point.
/// `None` if that prefix is not such a number.
#[inline]
pub fn short_decimal_prefix(bytes: &[u8]) -> Option<(f64, usize)> {
    let (negative, start) = match bytes.first()? {
        b'-' => (true, 1),
        b'+' => (false, 1),
        _ => (false, 0),
    };
    let mut m: u64 = 0;
    let mut digits = 0usize;
    let mut point = None;
    let mut i = start;
    while i < bytes.len() {
        match bytes[i] {
            b @ b'0'..=b'9' => {
                m = m.wrapping_mul(10).wrapping_add(u64::from(b - b'0'));
                digits += 1;
            }
            b'.' if point.is_none() => point = Some(i),
            _ => break,
        }
        i += 1;
    }
    let k = point.map_or(0, |p| i - p - 1);
    if digits == 0 || digits > 19 || k > 22 || m > 1 << 53 {
        return None;
    }
    let x = m as f64 / POW10[k];
    Some((if negative { -x } else { x }, i))
}

/// `[+-]digits` with at most 18 digits (so that it fits in an `i64`), the
/// value `str::parse::<i64>` gives it; `None` for anything else, which the
/// caller then reads the slow way.
#[inline]
pub fn short_integer(tok: &[u8]) -> Option<i64> {
    let (negative, digits) = match tok.split_first()? {
        (b'-', rest) => (true, rest),
        (b'+', rest) => (false, rest),
        _ => (false, tok),
    };
    if digits.is_empty() || digits.len() > 18 {
        return None;
    }
    let mut v: i64 = 0;
    for &d in digits {
        if !d.is_ascii_digit() {
            return None;
        }
        v = v * 10 + i64::from(d - b'0');
    }
    Some(if negative { -v } else { v })
}

/// Why an integer of a text format (a face's vertex index, a count) that
/// its reader refused is refused: digits too many for any value are out of
/// range (as `-1` or a count beyond the file is), anything else is not an
/// integer.
pub(crate) fn unreadable_integer(text: &[u8]) -> &'static str {
    let digits = text
        .strip_prefix(b"-")
        .or_else(|| text.strip_prefix(b"+"))
        .unwrap_or(text);
    if !digits.is_empty() && digits.iter().all(u8::is_ascii_digit) {
        "is out of range"
    } else {
        "is not an integer"
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn std_parse(s: &str) -> Option<f64> {
        s.parse().ok()
    }

    fn same(s: &str) {
        let (got, want) = (parse_f64(s.as_bytes()), std_parse(s));
        assert_eq!(got.map(f64::to_bits), want.map(f64::to_bits), "{s:?}");
    }

    #[test]
    fn agrees_with_std_on_edge_cases() {
        for s in [
            "0",
            "-0",
            "+0",
            "0.0",
            "-0.0",
            "1.",
            ".5",
            "-.5",
            "+.5",
            ".",
            "-",
            "+",
            "",
            "1..2",
            "1.2.3",
            "--1",
            "+-1",
            "1e5",
            "1E-5",
            "-52.9283",
            "67.3194",
            "0.1",
            "0.3",
            "9007199254740992",
            "9007199254740993",
            "9007199254740992.0",
            "0.9007199254740993",
            "1234567890123456789",
            "12345678901234567890",
            "0.0000000000000000000001",
            "0.00000000000000000000001",
            "000000000000000000001.5",
            "inf",
            "-inf",
            "NaN",
            "nan",
            "infinity",
            "1_0",
            " 1",
            "1 ",
            "0x10",
            "1.7976931348623157e308",
            "4.9e-324",
            "179769313486231570000000000000000000000",
            "1/2",
            "٣",
        ] {
            same(s);
        }
    }

    #[test]
    fn short_integers_agree_with_std() {
        for s in [
            "0",
            "-0",
            "+7",
            "42",
            "-42",
            "999999999999999999",
            "-999999999999999999",
            "9999999999999999999",
            "",
            "-",
            "+",
            "1.0",
            "1e3",
            " 1",
            "0x1",
            "--1",
        ] {
            if let Some(v) = short_integer(s.as_bytes()) {
                assert_eq!(Some(v), s.parse::<i64>().ok(), "{s:?}");
            }
        }
        assert_eq!(short_integer(b"9999999999999999999"), None);
        assert_eq!(short_integer(b"1.0"), None);
    }

    #[test]
    fn agrees_with_std_on_random_decimals() {
        let mut rng = crate::test_rng::Rng(0x2545_f491_4f6c_dd1d);
        let mut next = move || rng.next();
        let mut buffer = zmij::Buffer::new();
        for _ in 0..200_000 {
            let r = next();
            // Short decimals as meshes write them, and shortest round-trip
            // forms of arbitrary doubles.
            let digits = (r % 20) as usize;
            let point = (r >> 8) as usize % (digits + 1);
            let mut s = String::new();
            if r & (1 << 40) != 0 {
                s.push('-');
            }
            let mut v = next();
            for i in 0..digits.max(1) {
                if i == point && i > 0 {
                    s.push('.');
                }
                s.push(char::from(b'0' + (v % 10) as u8));
                v /= 10;
            }
            same(&s);
            let x = f64::from_bits(next());
            if x.is_finite() {
                same(buffer.format_finite(x));
            }
        }
    }
}
