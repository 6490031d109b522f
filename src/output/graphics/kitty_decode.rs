//! A kitty graphics protocol reader: enough of a terminal's side to turn what
//! [`crate::output::graphics::kitty`] writes back into pixels. Tests use it to check that the
//! stream carries exactly the picture (and the real-terminal script can use it to inspect a
//! recorded stream).
//!
//! Understood: APC `ESC _ G keys ; payload ESC \` commands (also inside tmux passthrough
//! wrappers), chunking (`m=1`), base64, zlib (`o=z`), RGB and RGBA (`f=24`, `f=32`), PNG
//! (`f=100`: any PNG the `image` crate reads, as kitty reads any libpng does: RGB, and the
//! stream's palette PNGs of 1 to 8 bits a pixel, expanded to RGB), direct and
//! file transmission (`t=d`, `t=f`, `t=t`: the file is read, and deleted for `t=t`),
//! transmit (`a=t`, `a=T`), root-frame edits (`a=f,r=1` with `x,y,s,v`, replacement) and
//! deletes (`a=d`). Everything outside APC commands is ignored.

use std::collections::BTreeMap;
use std::io::Read;

use base64::Engine;
use base64::engine::general_purpose::STANDARD as BASE64;

use crate::output::graphics::tmux;

/// The most pixels one decoded image may have (a bound on what a hostile stream can allocate).
pub const MAX_PIXELS: u64 = 64 << 20;

/// An image the terminal holds.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// RGB, 3 bytes a pixel, row-major.
    pub rgb: Vec<u8>,
    /// The keys of the command that created it (action, placement, cells...).
    pub keys: BTreeMap<char, String>,
}

/// What the decoder has seen.
#[derive(Clone, Debug, Default)]
pub struct KittyState {
    /// The images by id.
    pub images: BTreeMap<u32, Image>,
    /// Every command's keys, in order (one entry per chunked transmission).
    pub commands: Vec<BTreeMap<char, String>>,
    /// Chunks waiting for their last one: the first chunk's keys and the payload so far.
    pending: Option<(BTreeMap<char, String>, Vec<u8>)>,
}

impl KittyState {
    /// Feeds a byte stream (which must hold whole commands).
    pub fn feed(&mut self, bytes: &[u8]) -> Result<(), String> {
        let mut i = 0;
        while i < bytes.len() {
            if bytes[i..].starts_with(tmux::PASSTHROUGH_BEGIN) {
                let (inner, len) = tmux::unwrap(&bytes[i..]).ok_or("a tmux passthrough sequence is cut short")?;
                self.feed(&inner)?;
                i += len;
            } else if bytes[i..].starts_with(b"\x1b_G") {
                let body = &bytes[i + 3..];
                let end = body.windows(2).position(|w| w == b"\x1b\\").ok_or("an APC command is not terminated")?;
                self.command(&body[..end])?;
                i += 3 + end + 2;
            } else {
                i += 1;
            }
        }
        Ok(())
    }

    fn command(&mut self, body: &[u8]) -> Result<(), String> {
        let (control, payload) = match body.iter().position(|&b| b == b';') {
            Some(p) => (&body[..p], &body[p + 1..]),
            None => (body, &body[..0]),
        };
        let keys = parse_keys(control)?;
        let more = keys.get(&'m').is_some_and(|m| m == "1");
        let (keys, payload) = match self.pending.take() {
            Some((first, mut data)) => {
                data.extend_from_slice(payload);
                (first, data)
            }
            None => (keys, payload.to_vec()),
        };
        if more {
            self.pending = Some((keys, payload));
            return Ok(());
        }
        self.commands.push(keys.clone());
        self.apply(keys, &payload)
    }

    fn apply(&mut self, keys: BTreeMap<char, String>, payload: &[u8]) -> Result<(), String> {
        let num = |k: char| -> Result<u32, String> {
            keys.get(&k).map_or(Ok(0), |v| v.parse().map_err(|_| format!("key {k}={v} is not a number")))
        };
        let action = keys.get(&'a').map_or("t", String::as_str);
        let id = num('i')?;
        match action {
            "t" | "T" => {
                let (w, h) = (num('s')?, num('v')?);
                let rgb = pixels(&keys, payload, w, h)?;
                self.images.insert(id, Image { width: w, height: h, rgb, keys });
            }
            "f" => {
                if num('r')? != 1 {
                    return Err("only edits of the root frame (r=1) are understood".into());
                }
                let (x, y, w, h) = (num('x')?, num('y')?, num('s')?, num('v')?);
                let rgb = pixels(&keys, payload, w, h)?;
                let image = self.images.get_mut(&id).ok_or(format!("frame edit of unknown image {id}"))?;
                if x + w > image.width || y + h > image.height {
                    return Err("frame edit outside the image".into());
                }
                for row in 0..h as usize {
                    let to = ((y as usize + row) * image.width as usize + x as usize) * 3;
                    image.rgb[to..to + w as usize * 3]
                        .copy_from_slice(&rgb[row * w as usize * 3..(row + 1) * w as usize * 3]);
                }
            }
            "d" => match keys.get(&'d').map_or("a", String::as_str) {
                "i" | "I" => {
                    self.images.remove(&id);
                }
                _ => self.images.clear(),
            },
            _ => {}
        }
        Ok(())
    }
}

fn parse_keys(control: &[u8]) -> Result<BTreeMap<char, String>, String> {
    let text = std::str::from_utf8(control).map_err(|_| "control data is not text")?;
    let mut keys = BTreeMap::new();
    for pair in text.split(',').filter(|p| !p.is_empty()) {
        let (k, v) = pair.split_once('=').ok_or(format!("key without value: {pair}"))?;
        let mut chars = k.chars();
        match (chars.next(), chars.next()) {
            (Some(c), None) => keys.insert(c, v.to_string()),
            _ => return Err(format!("bad key: {k}")),
        };
    }
    Ok(keys)
}

/// The RGB pixels a transmission carries.
fn pixels(keys: &BTreeMap<char, String>, payload: &[u8], w: u32, h: u32) -> Result<Vec<u8>, String> {
    if u64::from(w) * u64::from(h) > MAX_PIXELS {
        return Err(format!("{w}x{h} is too large"));
    }
    let decoded = BASE64.decode(payload).map_err(|e| format!("bad base64: {e}"))?;
    let data = match keys.get(&'t').map_or("d", String::as_str) {
        "d" => decoded,
        medium @ ("f" | "t") => {
            let path = std::path::PathBuf::from(String::from_utf8(decoded).map_err(|_| "file name is not UTF-8")?);
            let data = std::fs::read(&path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
            if medium == "t" {
                let _ = std::fs::remove_file(&path);
            }
            data
        }
        other => return Err(format!("medium t={other} is not understood")),
    };
    let limit = u64::from(w) * u64::from(h) * 4 + 1;
    let data = match keys.get(&'o').map(String::as_str) {
        Some("z") => {
            let mut out = Vec::new();
            flate2::read::ZlibDecoder::new(&data[..])
                .take(limit)
                .read_to_end(&mut out)
                .map_err(|e| format!("bad zlib data: {e}"))?;
            out
        }
        None => data,
        Some(other) => return Err(format!("compression o={other} is not understood")),
    };
    let bytes_per_pixel = match keys.get(&'f').map_or("32", String::as_str) {
        "100" => {
            let mut reader = image::ImageReader::new(std::io::Cursor::new(&data[..]));
            reader.set_format(image::ImageFormat::Png);
            let mut limits = image::Limits::default();
            limits.max_alloc = Some(MAX_PIXELS * 4);
            reader.limits(limits);
            let png = reader.decode().map_err(|e| format!("bad PNG: {e}"))?.to_rgb8();
            if png.dimensions() != (w, h) {
                return Err(format!("a {:?} PNG for a {w}x{h} image", png.dimensions()));
            }
            return Ok(png.into_raw());
        }
        "24" => 3,
        "32" => 4,
        other => return Err(format!("format f={other} is not understood")),
    };
    if data.len() != w as usize * h as usize * bytes_per_pixel {
        return Err(format!("{} bytes for a {w}x{h} image of {bytes_per_pixel} bytes a pixel", data.len()));
    }
    Ok(if bytes_per_pixel == 3 { data } else { data.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect() })
}

/// Decodes a whole stream; the state after it.
pub fn decode(bytes: &[u8]) -> Result<KittyState, String> {
    let mut state = KittyState::default();
    state.feed(bytes)?;
    Ok(state)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_the_protocols_own_example() {
        // The protocol's query example: a 1x1 RGB image, base64 "AAAA" = three zero bytes.
        let state = decode(b"\x1b_Gi=31,s=1,v=1,a=t,t=d,f=24;AAAA\x1b\\\x1b[c").unwrap();
        assert_eq!(state.images[&31].rgb, vec![0, 0, 0]);
    }

    #[test]
    fn rejects_a_payload_of_the_wrong_size() {
        assert!(decode(b"\x1b_Gi=1,s=2,v=1,f=24;AAAA\x1b\\").is_err());
        assert!(decode(b"\x1b_Gi=1,s=1,v=1,f=24;AAAA").is_err(), "not terminated");
    }
}
