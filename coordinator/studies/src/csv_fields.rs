//! How the studies' CSV rows spell their fields, for `#[serde(with = "…")]`: numbers as Rust
//! prints them ([`shortest`]) or to a fixed number of decimals ([`fixed1`], [`fixed4`], and
//! the optional [`fixed1_or_empty`], [`fixed6_or_empty`]), planner names through `Display` /
//! `FromStr` ([`display`]). Each row is one
//! typed struct; the `csv` crate writes and reads it.

use serde::Serialize;

/// A header line and one line per record.
pub fn to_csv<T: Serialize>(records: impl IntoIterator<Item = T>) -> String {
    let mut writer = csv::Writer::from_writer(Vec::new());
    for record in records {
        // Writing rows of numbers and names into memory cannot fail.
        writer
            .serialize(record)
            .expect("a study row serialises to CSV");
    }
    let bytes = writer
        .into_inner()
        .expect("flushing into memory cannot fail");
    String::from_utf8(bytes).expect("CSV of UTF-8 fields is UTF-8")
}

/// The header line `T` writes (from one record of it).
pub fn header<T: Serialize>(sample: &T) -> String {
    to_csv(std::iter::once(sample))
        .lines()
        .next()
        .unwrap_or_default()
        .to_owned()
}

/// A finite number as Rust's `Display` prints it (the shortest text that reads back to the
/// same bits); NaN and infinities as an empty field, read back as NaN.
pub mod shortest {
    use serde::{Deserialize, Deserializer, Serializer};

    /// Writes the number.
    pub fn serialize<S: Serializer>(x: &f64, s: S) -> Result<S::Ok, S::Error> {
        if x.is_finite() {
            s.collect_str(x)
        } else {
            s.serialize_str("")
        }
    }

    /// Reads it back.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        let text = String::deserialize(d)?;
        if text.is_empty() {
            Ok(f64::NAN)
        } else {
            text.parse().map_err(serde::de::Error::custom)
        }
    }
}

/// A value written through `Display` and read through `FromStr`.
pub mod display {
    use serde::{Deserialize, Deserializer, Serializer};
    use std::fmt::Display;
    use std::str::FromStr;

    /// Writes the value.
    pub fn serialize<T: Display, S: Serializer>(value: &T, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(value)
    }

    /// Reads it back.
    pub fn deserialize<'de, T, D>(d: D) -> Result<T, D::Error>
    where
        T: FromStr<Err: Display>,
        D: Deserializer<'de>,
    {
        String::deserialize(d)?
            .parse()
            .map_err(serde::de::Error::custom)
    }
}

macro_rules! fixed {
    ($name:ident, $decimals:literal) => {
        #[doc = concat!("A number with ", stringify!($decimals), " decimals.")]
        pub mod $name {
            use serde::{Deserialize, Deserializer, Serializer};

            /// Writes the number.
            pub fn serialize<S: Serializer>(x: &f64, s: S) -> Result<S::Ok, S::Error> {
                s.collect_str(&format_args!("{:.*}", $decimals, x))
            }

            /// Reads it back (to the decimals written).
            pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
                String::deserialize(d)?
                    .parse()
                    .map_err(serde::de::Error::custom)
            }
        }
    };
}

fixed!(fixed1, 1);
fixed!(fixed4, 4);

macro_rules! fixed_or_empty {
    ($name:ident, $decimals:literal) => {
        #[doc = concat!(
            "An optional number with ", stringify!($decimals), " decimals; `None` is an empty field."
        )]
        pub mod $name {
            use serde::{Deserialize, Deserializer, Serializer};

            /// Writes the number or nothing.
            pub fn serialize<S: Serializer>(x: &Option<f64>, s: S) -> Result<S::Ok, S::Error> {
                match x {
                    Some(x) => s.collect_str(&format_args!("{:.*}", $decimals, x)),
                    None => s.serialize_str(""),
                }
            }

            /// Reads it back.
            pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
                let text = String::deserialize(d)?;
                if text.is_empty() {
                    Ok(None)
                } else {
                    text.parse().map(Some).map_err(serde::de::Error::custom)
                }
            }
        }
    };
}

fixed_or_empty!(fixed1_or_empty, 1);
fixed_or_empty!(fixed6_or_empty, 6);

#[cfg(test)]
mod tests {
    use super::*;
    use serde::Deserialize;

    #[derive(Debug, PartialEq, Serialize, Deserialize)]
    struct Row {
        #[serde(with = "shortest")]
        a: f64,
        #[serde(with = "fixed4")]
        b: f64,
        #[serde(with = "fixed1_or_empty")]
        c: Option<f64>,
    }

    #[test]
    fn numbers_are_spelled_as_before_and_read_back() {
        let rows = [
            Row {
                a: 0.1,
                b: 2.0,
                c: Some(0.25),
            },
            Row {
                a: f64::NAN,
                b: 1e-7,
                c: None,
            },
            Row {
                a: 1e-7,
                b: -3.5,
                c: Some(10.0),
            },
        ];
        let text = to_csv(&rows);
        // Rust's Display, not ryu's "1e-7" or "1.0"; format!'s rounding for fixed decimals.
        assert_eq!(
            text,
            "a,b,c\n0.1,2.0000,0.2\n,0.0000,\n0.0000001,-3.5000,10.0\n"
        );
        assert_eq!(header(&rows[0]), "a,b,c");
        let back: Vec<Row> = csv::Reader::from_reader(text.as_bytes())
            .deserialize()
            .collect::<Result<_, _>>()
            .expect("our own output reads back");
        assert_eq!(
            back[0],
            Row {
                c: Some(0.2),
                ..rows[0]
            }
        );
        assert!(back[1].a.is_nan() && back[1].c.is_none());
        assert_eq!(back[2].a.to_bits(), 1e-7_f64.to_bits());
    }
}
