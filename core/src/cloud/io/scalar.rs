//! [`ScalarType`]: the numeric types a PLY property or PCD field may have, their sizes,
//! names, binary decoding and text parsing.

/// A numeric type of a file field.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum ScalarType {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    I64,
    U64,
    F32,
    F64,
}

impl ScalarType {
    /// Size in bytes.
    pub(crate) fn size(self) -> usize {
        match self {
            Self::I8 | Self::U8 => 1,
            Self::I16 | Self::U16 => 2,
            Self::I32 | Self::U32 | Self::F32 => 4,
            Self::I64 | Self::U64 | Self::F64 => 8,
        }
    }

    /// Whether it is a floating-point type.
    pub(crate) fn is_float(self) -> bool {
        matches!(self, Self::F32 | Self::F64)
    }

    /// The type of a PLY property type name (both the original and the sized spellings).
    pub(crate) fn from_ply(name: &str) -> Option<Self> {
        Some(match name {
            "char" | "int8" => Self::I8,
            "uchar" | "uint8" => Self::U8,
            "short" | "int16" => Self::I16,
            "ushort" | "uint16" => Self::U16,
            "int" | "int32" => Self::I32,
            "uint" | "uint32" => Self::U32,
            "float" | "float32" => Self::F32,
            "double" | "float64" => Self::F64,
            _ => return None,
        })
    }

    /// The PLY name this crate writes.
    pub(crate) fn ply_name(self) -> &'static str {
        match self {
            Self::I8 => "char",
            Self::U8 => "uchar",
            Self::I16 => "short",
            Self::U16 => "ushort",
            Self::I32 => "int",
            Self::U32 => "uint",
            Self::I64 => "int64",
            Self::U64 => "uint64",
            Self::F32 => "float",
            Self::F64 => "double",
        }
    }

    /// The type of a PCD `TYPE` letter and `SIZE`.
    pub(crate) fn from_pcd(kind: &str, size: usize) -> Option<Self> {
        Some(match (kind, size) {
            ("I" | "i", 1) => Self::I8,
            ("U" | "u", 1) => Self::U8,
            ("I" | "i", 2) => Self::I16,
            ("U" | "u", 2) => Self::U16,
            ("I" | "i", 4) => Self::I32,
            ("U" | "u", 4) => Self::U32,
            ("I" | "i", 8) => Self::I64,
            ("U" | "u", 8) => Self::U64,
            ("F" | "f", 4) => Self::F32,
            ("F" | "f", 8) => Self::F64,
            _ => return None,
        })
    }

    /// The PCD `TYPE` letter.
    pub(crate) fn pcd_letter(self) -> char {
        match self {
            Self::I8 | Self::I16 | Self::I32 | Self::I64 => 'I',
            Self::U8 | Self::U16 | Self::U32 | Self::U64 => 'U',
            Self::F32 | Self::F64 => 'F',
        }
    }

    /// A name for error messages.
    pub(crate) fn describe(self) -> &'static str {
        match self {
            Self::I8 => "8-bit signed integer",
            Self::U8 => "8-bit unsigned integer",
            Self::I16 => "16-bit signed integer",
            Self::U16 => "16-bit unsigned integer",
            Self::I32 => "32-bit signed integer",
            Self::U32 => "32-bit unsigned integer",
            Self::I64 => "64-bit signed integer",
            Self::U64 => "64-bit unsigned integer",
            Self::F32 => "32-bit float",
            Self::F64 => "64-bit float",
        }
    }

    /// Decodes the value at the start of `bytes`, or `None` if `bytes` is too short.
    pub(crate) fn decode(self, bytes: &[u8], big_endian: bool) -> Option<f64> {
        fn arr<const N: usize>(bytes: &[u8], big_endian: bool) -> Option<[u8; N]> {
            let mut a: [u8; N] = bytes.get(..N)?.try_into().ok()?;
            if big_endian {
                a.reverse();
            }
            Some(a)
        }
        Some(match self {
            Self::I8 => f64::from(i8::from_le_bytes(arr(bytes, big_endian)?)),
            Self::U8 => f64::from(u8::from_le_bytes(arr(bytes, big_endian)?)),
            Self::I16 => f64::from(i16::from_le_bytes(arr(bytes, big_endian)?)),
            Self::U16 => f64::from(u16::from_le_bytes(arr(bytes, big_endian)?)),
            Self::I32 => f64::from(i32::from_le_bytes(arr(bytes, big_endian)?)),
            Self::U32 => f64::from(u32::from_le_bytes(arr(bytes, big_endian)?)),
            Self::I64 => i64::from_le_bytes(arr(bytes, big_endian)?) as f64,
            Self::U64 => u64::from_le_bytes(arr(bytes, big_endian)?) as f64,
            Self::F32 => f64::from(f32::from_le_bytes(arr(bytes, big_endian)?)),
            Self::F64 => f64::from_le_bytes(arr(bytes, big_endian)?),
        })
    }

    /// Decodes a list length (an integer type, non-negative), or `None` if `bytes` is too
    /// short or the value is not a valid length.
    pub(crate) fn decode_len(self, bytes: &[u8], big_endian: bool) -> Option<u64> {
        if self.is_float() {
            return None;
        }
        let v = self.decode(bytes, big_endian)?;
        (v >= 0.0).then_some(v as u64)
    }

    /// Parses a text token as a value of this type (integers must be integers in range;
    /// floats accept `nan`, `inf` and exponents, and are rounded to the declared width).
    pub(crate) fn parse(self, token: &str) -> Option<f64> {
        fn int<T: std::str::FromStr + Into<f64>>(token: &str) -> Option<f64> {
            token.parse::<T>().ok().map(Into::into)
        }
        match self {
            Self::I8 => int::<i8>(token),
            Self::U8 => int::<u8>(token),
            Self::I16 => int::<i16>(token),
            Self::U16 => int::<u16>(token),
            Self::I32 => int::<i32>(token),
            Self::U32 => int::<u32>(token),
            Self::I64 => token.parse::<i64>().ok().map(|v| v as f64),
            Self::U64 => token.parse::<u64>().ok().map(|v| v as f64),
            Self::F32 => token.parse::<f32>().ok().map(f64::from),
            Self::F64 => token.parse::<f64>().ok(),
        }
    }

    /// Parses a text token as a list length.
    pub(crate) fn parse_len(self, token: &str) -> Option<u64> {
        if self.is_float() {
            return None;
        }
        let v = self.parse(token)?;
        (v >= 0.0).then_some(v as u64)
    }
}

/// Appends the shortest text that reads back to exactly `v` (as `f32` if `single`), with
/// `nan`, `inf` and `-inf` spelled as PCL and C libraries read them.
pub(crate) fn push_float(out: &mut String, v: f64, single: bool) {
    use std::fmt::Write;
    if v.is_nan() {
        out.push_str("nan");
    } else if v.is_infinite() {
        out.push_str(if v > 0.0 { "inf" } else { "-inf" });
    } else {
        let a = v.abs();
        let plain = a == 0.0 || (1e-5..1e16).contains(&a);
        // Writing to a String cannot fail.
        let _ = match (single, plain) {
            (true, true) => write!(out, "{}", v as f32),
            (true, false) => write!(out, "{:e}", v as f32),
            (false, true) => write!(out, "{v}"),
            (false, false) => write!(out, "{v:e}"),
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decode_both_endians() {
        let le = 1.5f32.to_le_bytes();
        let be = 1.5f32.to_be_bytes();
        assert_eq!(ScalarType::F32.decode(&le, false), Some(1.5));
        assert_eq!(ScalarType::F32.decode(&be, true), Some(1.5));
        assert_eq!(
            ScalarType::I16.decode(&(-3i16).to_be_bytes(), true),
            Some(-3.0)
        );
        assert_eq!(ScalarType::F64.decode(&[0; 7], false), None);
        assert_eq!(ScalarType::U8.decode_len(&[200], false), Some(200));
        assert_eq!(ScalarType::I8.decode_len(&[0xff], false), None);
    }

    #[test]
    fn parse_checks_ranges_and_widths() {
        assert_eq!(ScalarType::U8.parse("255"), Some(255.0));
        assert_eq!(ScalarType::U8.parse("256"), None);
        assert_eq!(ScalarType::I32.parse("1.5"), None);
        assert_eq!(ScalarType::F32.parse("0.1"), Some(f64::from(0.1f32)));
        assert!(ScalarType::F64.parse("-nan").unwrap().is_nan());
        assert_eq!(ScalarType::U32.parse_len("-1"), None);
    }

    #[test]
    fn floats_print_shortest_round_trip() {
        for &(v, single) in &[
            (0.1, true),
            (0.1, false),
            (1e-30, false),
            (-3.25e20, true),
            (0.0, true),
            (123456.789, false),
        ] {
            let mut s = String::new();
            push_float(&mut s, v, single);
            let back = if single {
                f64::from(s.parse::<f32>().unwrap())
            } else {
                s.parse::<f64>().unwrap()
            };
            let want = if single { f64::from(v as f32) } else { v };
            assert_eq!(back.to_bits(), want.to_bits(), "{v} -> {s}");
        }
        let mut s = String::new();
        push_float(&mut s, f64::NAN, true);
        push_float(&mut s, f64::NEG_INFINITY, true);
        assert_eq!(s, "nan-inf");
    }
}
