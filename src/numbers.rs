//! Reading the numbers people type: one place for the messages every value shares.

use crate::error::ValueError;

/// Parses a finite number; `what` names it in the message (`"wind speed"`), `example` shows a
/// good value.
pub fn finite(text: &str, what: &'static str, example: &str) -> Result<f64, ValueError> {
    let v: f64 = text
        .trim()
        .parse()
        .map_err(|_| ValueError::new(what, format!("the {what} '{}' is not a number; e.g. {example}", text.trim())))?;
    if !v.is_finite() {
        return Err(ValueError::new(what, format!("the {what} must be a finite number; e.g. {example}")));
    }
    Ok(v)
}

/// Deserializes a string or a number as text, for values whose text form is parsed by their
/// `FromStr` (a damping written as `"5"` or `5`, a refraction as `"auto"` or `1.5`).
pub(crate) fn text_or_number<'de, D: serde::Deserializer<'de>>(deserializer: D) -> Result<String, D::Error> {
    struct Text;
    impl serde::de::Visitor<'_> for Text {
        type Value = String;
        fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            f.write_str("a string or a number")
        }
        fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<String, E> {
            Ok(v.to_owned())
        }
        fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<String, E> {
            Ok(v.to_string())
        }
        fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<String, E> {
            Ok(v.to_string())
        }
        fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<String, E> {
            Ok(v.to_string())
        }
    }
    deserializer.deserialize_any(Text)
}
