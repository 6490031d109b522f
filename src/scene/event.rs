//! Events: everything that can happen to a scene, live in the player or read back from a replay.
//!
//! An event is *resolved*: it says exactly what happened (a random stone is recorded where it
//! landed), so applying the same events at the same steps gives the same water bit for bit.
//! The serde form is the replay file's: one JSON key per event, its value checked by the same
//! constructors the command line uses (`{"stone":[80,40,4,160]}`, `{"damping":"6"}`,
//! `{"clear":true}`).

use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::sim::noise::NoiseKind;
use crate::sim::ripple::{Damping, Stone};
use crate::size::Size;

/// Something that happened during a session.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Event {
    /// A stone (or a stir of the water) landed, in pixels.
    #[serde(with = "stone")]
    Stone(Stone),
    /// The rain rate changed (drops per step; 0 is off).
    #[serde(with = "rain")]
    Rain(f64),
    /// The damping changed.
    #[serde(with = "damping")]
    Damping(Damping),
    /// The breeze's level changed (0: still water).
    #[serde(with = "breeze")]
    Breeze(f64),
    /// The water was stilled.
    #[serde(serialize_with = "flag::serialize", deserialize_with = "flag::deserialize")]
    Clear,
    /// The picture was resized to `[width, height]` pixels (within the picture limits).
    #[serde(with = "resize")]
    Resize([u32; 2]),
    /// A screenshot was saved to this file.
    Screenshot(String),
    /// The wind changed: speed in m/s and where it comes from, degrees clockwise from north.
    #[serde(with = "wind")]
    Wind([f64; 2]),
    /// The session ended.
    #[serde(serialize_with = "flag::serialize", deserialize_with = "flag::deserialize")]
    End,
    /// The lake's noise changed.
    Noise {
        /// Octaves summed.
        #[serde(deserialize_with = "octaves")]
        octaves: u32,
        /// Amplitude ratio between octaves.
        #[serde(deserialize_with = "persistence")]
        persistence: f64,
        /// Value or gradient noise.
        #[serde(with = "noise_kind")]
        kind: NoiseKind,
    },
}

impl Event {
    /// The names of the events, as the replay file spells them.
    pub const NAMES: [&'static str; 10] =
        ["stone", "rain", "damping", "breeze", "clear", "resize", "screenshot", "wind", "noise", "end"];
}

/// `true` in the file; nothing else is accepted.
mod flag {
    use super::*;

    pub fn serialize<S: Serializer>(serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_bool(true)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(deserializer: D) -> Result<(), D::Error> {
        match bool::deserialize(deserializer)? {
            true => Ok(()),
            false => Err(serde::de::Error::custom("must be true")),
        }
    }
}

/// `[X, Y, RADIUS, WEIGHT]`, checked by [`Stone::new`].
mod stone {
    use super::*;

    pub fn serialize<S: Serializer>(s: &Stone, serializer: S) -> Result<S::Ok, S::Error> {
        [i64::from(s.x()), i64::from(s.y()), i64::from(s.radius()), i64::from(s.weight())].serialize(serializer)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(deserializer: D) -> Result<Stone, D::Error> {
        let [x, y, r, w] = <[i64; 4]>::deserialize(deserializer)?;
        Stone::new(x, y, r, w).map_err(|e| serde::de::Error::custom(format!("bad stone: {e}")))
    }
}

/// Drops per step, checked by [`crate::sim::rain::check_rate`].
mod rain {
    use super::*;

    pub fn serialize<S: Serializer>(rate: &f64, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_f64(*rate)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(deserializer: D) -> Result<f64, D::Error> {
        let rate = f64::deserialize(deserializer)?;
        crate::sim::rain::check_rate(rate).map_err(|e| serde::de::Error::custom(format!("bad rain: {e}")))
    }
}

/// A level, checked by [`crate::sim::breeze::check_level`].
mod breeze {
    use super::*;

    pub fn serialize<S: Serializer>(level: &f64, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_f64(*level)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(deserializer: D) -> Result<f64, D::Error> {
        let level = f64::deserialize(deserializer)?;
        crate::sim::breeze::check_level(level).map_err(|e| serde::de::Error::custom(format!("bad breeze: {e}")))
    }
}

/// `"5"` or `"off"`.
mod damping {
    use super::*;

    pub fn serialize<S: Serializer>(d: &Damping, serializer: S) -> Result<S::Ok, S::Error> {
        d.serialize(serializer)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(deserializer: D) -> Result<Damping, D::Error> {
        let text = crate::numbers::text_or_number(deserializer)?;
        text.parse().map_err(|e| serde::de::Error::custom(format!("bad damping: {e}")))
    }
}

/// `[WIDTH, HEIGHT]` within the picture limits.
mod resize {
    use super::*;

    pub fn serialize<S: Serializer>(size: &[u32; 2], serializer: S) -> Result<S::Ok, S::Error> {
        size.serialize(serializer)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(deserializer: D) -> Result<[u32; 2], D::Error> {
        let [w, h] = <[i64; 2]>::deserialize(deserializer)?;
        let size = Size::new(w, h).map_err(|e| serde::de::Error::custom(format!("bad resize to {w}x{h}: {e}")))?;
        Ok([size.width(), size.height()])
    }
}

/// `[SPEED_M_S, FROM_DEG]`: a speed the sea takes and a finite direction.
mod wind {
    use super::*;

    pub fn serialize<S: Serializer>(wind: &[f64; 2], serializer: S) -> Result<S::Ok, S::Error> {
        wind.serialize(serializer)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(deserializer: D) -> Result<[f64; 2], D::Error> {
        let [speed, from] = <[f64; 2]>::deserialize(deserializer)?;
        if crate::sim::wind::check_sea_wind(speed).is_err() || !from.is_finite() {
            return Err(serde::de::Error::custom(format!("bad wind: {speed} m/s from {from} degrees")));
        }
        Ok([speed, from])
    }
}

fn octaves<'de, D: Deserializer<'de>>(deserializer: D) -> Result<u32, D::Error> {
    let text = crate::numbers::text_or_number(deserializer)?;
    crate::sim::lake::parse_octaves(&text).map_err(|e| serde::de::Error::custom(format!("bad noise: {e}")))
}

fn persistence<'de, D: Deserializer<'de>>(deserializer: D) -> Result<f64, D::Error> {
    let text = crate::numbers::text_or_number(deserializer)?;
    crate::sim::lake::parse_persistence(&text).map_err(|e| serde::de::Error::custom(format!("bad noise: {e}")))
}

/// `"value"` or `"gradient"`.
mod noise_kind {
    use super::*;

    pub fn serialize<S: Serializer>(kind: &NoiseKind, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(kind.name())
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(deserializer: D) -> Result<NoiseKind, D::Error> {
        let text = String::deserialize(deserializer)?;
        text.parse().map_err(|e| serde::de::Error::custom(format!("bad noise: {e}")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn round_trip(event: Event, json: &str) {
        assert_eq!(serde_json::to_string(&event).unwrap(), json);
        assert_eq!(serde_json::from_str::<Event>(json).unwrap(), event);
    }

    #[test]
    fn the_file_form_of_every_event() {
        round_trip(Event::Stone(Stone::new(-3, 4, 5, 160).unwrap()), r#"{"stone":[-3,4,5,160]}"#);
        round_trip(Event::Rain(0.25), r#"{"rain":0.25}"#);
        round_trip(Event::Damping(Damping::OFF), r#"{"damping":"off"}"#);
        round_trip(Event::Breeze(1.5), r#"{"breeze":1.5}"#);
        round_trip(Event::Clear, r#"{"clear":true}"#);
        round_trip(Event::Resize([30, 12]), r#"{"resize":[30,12]}"#);
        round_trip(Event::Screenshot("a b.png".into()), r#"{"screenshot":"a b.png"}"#);
        round_trip(Event::Wind([4.5, 0.0]), r#"{"wind":[4.5,0.0]}"#);
        round_trip(Event::End, r#"{"end":true}"#);
        round_trip(
            Event::Noise { octaves: 6, persistence: 0.55, kind: NoiseKind::Gradient },
            r#"{"noise":{"octaves":6,"persistence":0.55,"kind":"gradient"}}"#,
        );
    }

    #[test]
    fn values_are_checked_with_the_domain_messages() {
        let err = |json: &str| serde_json::from_str::<Event>(json).unwrap_err().to_string();
        assert!(err(r#"{"stone":[1,2,0,3]}"#).starts_with("bad stone: the radius 0 is outside 1..=1000"));
        assert!(err(r#"{"rain":-1}"#).starts_with("bad rain:"));
        assert!(err(r#"{"damping":"0"}"#).starts_with("bad damping: a shift of 0"));
        assert!(err(r#"{"clear":false}"#).starts_with("must be true"));
        assert!(err(r#"{"resize":[60000,1]}"#).contains("larger than the limit of 16384"));
        assert!(err(r#"{"wind":[61,0]}"#).starts_with("bad wind: 61 m/s"));
        assert!(
            err(r#"{"noise":{"octaves":0,"persistence":0.5,"kind":"value"}}"#)
                .starts_with("bad noise: the octave count 0")
        );
        assert!(
            err(r#"{"noise":{"octaves":3,"persistence":0.5,"kind":"pink"}}"#).starts_with("bad noise: unknown kind")
        );
        assert_eq!(serde_json::from_str::<Event>(r#"{"damping":7}"#).unwrap(), Event::Damping("7".parse().unwrap()));
    }
}
