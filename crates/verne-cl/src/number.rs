//! Numbers of CL records (SPEC §3.3): `[+-]digits[.digits]`, `[+-]digits.`, `[+-].digits`,
//! with an optional exponent `E|e|D|d[+-]digits` (Fortran `D`). Any number of digits.

/// The result of reading a field as a number.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Num {
    /// Not a number by the grammar (a word, an empty field, `1.2.3`, `-115 .0`, `inf`).
    NotNumber,
    /// A finite value.
    Value(f64),
    /// A number by the grammar whose value does not fit a finite `f64`.
    OutOfRange,
}

/// Checks the grammar; returns the index of a `D`/`d` exponent letter (to be replaced by `E`
/// before conversion), `Some(None)` for a valid number without one, `None` for no number.
fn scan(s: &[u8]) -> Option<Option<usize>> {
    let n = s.len();
    let mut i = 0;
    if i < n && (s[i] == b'+' || s[i] == b'-') {
        i += 1;
    }
    let int_start = i;
    while i < n && s[i].is_ascii_digit() {
        i += 1;
    }
    let int_digits = i - int_start;
    let mut frac_digits = 0;
    if i < n && s[i] == b'.' {
        i += 1;
        let f = i;
        while i < n && s[i].is_ascii_digit() {
            i += 1;
        }
        frac_digits = i - f;
    }
    if int_digits == 0 && frac_digits == 0 {
        return None;
    }
    let mut d_at = None;
    if i < n {
        match s[i] {
            b'e' | b'E' => {}
            b'd' | b'D' => d_at = Some(i),
            _ => return None,
        }
        i += 1;
        if i < n && (s[i] == b'+' || s[i] == b'-') {
            i += 1;
        }
        let e = i;
        while i < n && s[i].is_ascii_digit() {
            i += 1;
        }
        if i == e || i != n {
            return None;
        }
    }
    Some(d_at)
}

/// Whether `s` is a number by the grammar (its value may still be out of range).
pub(super) fn is_number(s: &[u8]) -> bool {
    scan(s).is_some()
}

/// Exact powers of ten (exactly representable as `f64`).
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// Up to eight leading ASCII digits of `s` at once (no branch per digit): their count and
/// value.
#[inline(always)]
fn digits8(s: &[u8]) -> (usize, u64) {
    const ZEROS: u64 = 0x3030_3030_3030_3030;
    if s.len() < 8 {
        // the end of a record: digit by digit
        let mut v = 0u64;
        let mut c = 0;
        for &b in s {
            let d = b.wrapping_sub(b'0');
            if d > 9 {
                break;
            }
            v = v * 10 + d as u64;
            c += 1;
        }
        return (c, v);
    }
    let x = u64::from_le_bytes([s[0], s[1], s[2], s[3], s[4], s[5], s[6], s[7]]);
    // a byte is a digit when (b ^ '0') <= 9; the lowest flagged byte is the first non-digit
    // (carries only go to later bytes)
    let t = x ^ ZEROS;
    let non_digit = (t.wrapping_add(0x7676_7676_7676_7676) | t) & 0x8080_8080_8080_8080;
    let count = (non_digit.trailing_zeros() / 8) as usize;
    if count == 0 {
        return (0, 0);
    }
    // digit values (borrows only reach bytes after the digits), moved to the top bytes so
    // that the bytes below act as leading zeros
    let mut v = x.wrapping_sub(ZEROS) << (8 * (8 - count));
    v = v.wrapping_mul(10).wrapping_add(v >> 8);
    v = ((v & 0x0000_00FF_0000_00FF)
        .wrapping_mul(100 + (1_000_000 << 32))
        .wrapping_add(((v >> 16) & 0x0000_00FF_0000_00FF).wrapping_mul(1 + (10_000 << 32))))
        >> 32;
    (count, v)
}

const POW10_U64: [u64; 9] = [
    1,
    10,
    100,
    1_000,
    10_000,
    100_000,
    1_000_000,
    10_000_000,
    100_000_000,
];

/// Appends the run of decimal digits at the start of `s` to `mant`, eight at a time, counting
/// them in `digits`; returns the run's length, or `None` past 19 digits in all (the mantissa
/// could wrap a u64).
#[inline]
fn digit_run(s: &[u8], mant: &mut u64, digits: &mut usize) -> Option<usize> {
    let mut i = 0;
    loop {
        let (c, v) = digits8(&s[i..]);
        *digits += c;
        if *digits > 19 {
            return None;
        }
        *mant = *mant * POW10_U64[c] + v;
        i += c;
        if c < 8 {
            return Some(i);
        }
    }
}

/// Clinger's fast path on a number at the start of `s`: `[+-]digits[.digits][(E|D)[+-]digits]`
/// with at most 19 digits whose value is below 2^53 and a decimal exponent in [-22, 22] is
/// correctly rounded by one exact multiplication or division. Returns the value and the
/// bytes used, `None` outside that case (the general path then decides).
#[inline]
pub(super) fn fast_prefix(s: &[u8]) -> Option<(f64, usize)> {
    let n = s.len();
    let mut i = 0;
    let neg = match s.first() {
        Some(b'-') => {
            i = 1;
            true
        }
        Some(b'+') => {
            i = 1;
            false
        }
        _ => false,
    };
    let mut mant: u64 = 0;
    let mut digits = 0;
    i += digit_run(&s[i..], &mut mant, &mut digits)?;
    let mut frac = 0;
    if i < n && s[i] == b'.' {
        i += 1;
        frac = digit_run(&s[i..], &mut mant, &mut digits)?;
        i += frac;
    }
    // the value must be exact in an f64
    if digits == 0 || mant > 1 << 53 {
        return None;
    }
    let mut exp = 0i32;
    if i < n && matches!(s[i], b'e' | b'E' | b'd' | b'D') {
        i += 1;
        let eneg = match s.get(i) {
            Some(b'-') => {
                i += 1;
                true
            }
            Some(b'+') => {
                i += 1;
                false
            }
            _ => false,
        };
        let start = i;
        while i < n && s[i].is_ascii_digit() && i - start < 4 {
            exp = exp * 10 + (s[i] - b'0') as i32;
            i += 1;
        }
        if i == start || (i < n && s[i].is_ascii_digit()) {
            return None;
        }
        if eneg {
            exp = -exp;
        }
    }
    let e = exp - frac as i32;
    let m = mant as f64;
    let v = if (0..=22).contains(&e) {
        m * POW10[e as usize]
    } else if (-22..0).contains(&e) {
        m / POW10[(-e) as usize]
    } else {
        return None;
    };
    Some((if neg { -v } else { v }, i))
}

#[inline]
fn fast(s: &[u8]) -> Option<f64> {
    match fast_prefix(s) {
        Some((v, used)) if used == s.len() => Some(v),
        _ => None,
    }
}

/// Reads `s` (already trimmed) as a number.
pub(super) fn parse(s: &[u8]) -> Num {
    if let Some(v) = fast(s) {
        return Num::Value(v);
    }
    let Some(d_at) = scan(s) else {
        return Num::NotNumber;
    };
    let v = match d_at {
        None => convert(s),
        Some(k) => {
            // Fortran exponent: replace `D` by `E`. Short numbers on the stack, long ones
            // (rare: more than 64 digits with a D exponent) in a temporary buffer.
            let mut small = [0u8; 64];
            if s.len() <= small.len() {
                let t = &mut small[..s.len()];
                t.copy_from_slice(s);
                t[k] = b'E';
                convert(t)
            } else {
                let mut t = s.to_vec();
                t[k] = b'E';
                convert(&t)
            }
        }
    };
    match v {
        Some(v) if v.is_finite() => Num::Value(v),
        _ => Num::OutOfRange,
    }
}

fn convert(s: &[u8]) -> Option<f64> {
    // `s` passed `scan`: ASCII digits, signs, `.`, `E`/`e` only, which Rust's float parser
    // accepts (`5.`, `.5`, `+2`, `1e5`), and it rounds correctly for any number of digits.
    std::str::from_utf8(s).ok()?.parse::<f64>().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(s: &str) -> f64 {
        match parse(s.as_bytes()) {
            Num::Value(v) => v,
            other => panic!("{s}: {other:?}"),
        }
    }

    #[test]
    fn forms() {
        assert_eq!(v("100"), 100.0);
        assert_eq!(v("5."), 5.0);
        assert_eq!(v(".5"), 0.5);
        assert_eq!(v("-.25"), -0.25);
        assert_eq!(v("+2.0"), 2.0);
        assert_eq!(v("0.1e1"), 1.0);
        assert_eq!(v("1E+02"), 100.0);
        assert_eq!(v("1.5e-1"), 0.15);
        assert_eq!(v("5.e3"), 5000.0);
    }

    #[test]
    fn fortran_d_exponents() {
        assert_eq!(v("1.5D+02"), 150.0);
        assert_eq!(v("2.5d-1"), 0.25);
        assert_eq!(v("1.0d0"), 1.0);
        assert_eq!(v("-1.0D-1"), -0.1);
        // a long mantissa with a D exponent goes through the heap path
        let long = format!("1.{}D+01", "0".repeat(200));
        assert_eq!(v(&long), 10.0);
    }

    #[test]
    fn huge_digit_strings() {
        let s = format!("12.5{}", "0".repeat(3000));
        assert_eq!(v(&s), 12.5);
        let s = format!("-0.{}1", "0".repeat(3000));
        assert_eq!(v(&s), -0.0);
        let s = format!("{}.0", "9".repeat(400));
        assert_eq!(parse(s.as_bytes()), Num::OutOfRange);
        let s = format!("0.{}", "3".repeat(100_000));
        assert!((v(&s) - 1.0 / 3.0).abs() < 1e-15);
        assert_eq!(parse(b"1e400"), Num::OutOfRange);
        assert_eq!(v("1e-400"), 0.0);
    }

    #[test]
    fn fast_path_is_correctly_rounded() {
        // against the standard library's (correctly rounding) parser
        let mut x = 0x2545_F491_4F6C_DD1Du64;
        for k in 0..200_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let int = x % 100_000;
            let frac = (x >> 20) % 10_000_000;
            let fd = 1 + (x >> 50) as usize % 9;
            let sign = if k % 3 == 0 { "-" } else { "" };
            let s = format!("{sign}{int}.{frac:0fd$}");
            let want: f64 = s.parse().unwrap();
            assert_eq!(parse(s.as_bytes()), Num::Value(want), "{s}");
            let e = format!("{sign}{int}.{frac}E{}", (x >> 40) as i32 % 30 - 15);
            let want: f64 = e.parse().unwrap();
            assert_eq!(parse(e.as_bytes()), Num::Value(want), "{e}");
        }
        assert_eq!(parse(b"-0.0"), Num::Value(-0.0));
        assert!(matches!(parse(b"-0.0"), Num::Value(v) if v.is_sign_negative()));
        assert_eq!(parse(b"9007199254740993"), Num::Value(9007199254740993.0));
        assert_eq!(parse(b"0.1e-30"), Num::Value(1e-31));
    }

    #[test]
    fn eight_digits_at_once() {
        assert_eq!(digits8(b""), (0, 0));
        assert_eq!(digits8(b",1"), (0, 0));
        assert_eq!(digits8(b"7"), (1, 7));
        assert_eq!(digits8(b"1234,5678"), (4, 1234));
        assert_eq!(digits8(b"12345678"), (8, 12345678));
        assert_eq!(digits8(b"123456789"), (8, 12345678));
        assert_eq!(digits8(b"0000001x"), (7, 1));
        assert_eq!(digits8(b"99999999"), (8, 99_999_999));
        assert_eq!(digits8(b"09/"), (2, 9));
        assert_eq!(digits8(b"5\xff\x99"), (1, 5));
        assert_eq!(digits8(b"5:;"), (1, 5));
        assert_eq!(digits8(b"12 34"), (2, 12));
        for k in 0..100_000u64 {
            let s = k.to_string();
            assert_eq!(digits8(s.as_bytes()), (s.len(), k));
            let t = format!("{s}.");
            assert_eq!(digits8(t.as_bytes()), (s.len(), k));
        }
    }

    #[test]
    fn not_numbers() {
        for s in [
            "",
            ".",
            "+",
            "-",
            "e5",
            "1e",
            "1e+",
            "1.2.3",
            "-115 .0000",
            "1 0",
            "inf",
            "NaN",
            "infinity",
            "0x10",
            "1,0",
            "MMPM",
            "1.0E5.0",
            "--1",
            "+-1",
            "1d",
            ".e1",
            "1_000",
        ] {
            assert_eq!(parse(s.as_bytes()), Num::NotNumber, "{s:?}");
            assert!(!is_number(s.as_bytes()), "{s:?}");
        }
    }
}
