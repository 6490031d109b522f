use super::*;
use crate::output::graphics::kitty_decode::decode;
use crate::output::graphics::test_pictures::{golden_pool, noise};

/// Every APC command in a stream (tmux wrappers removed), as (control, payload).
fn commands(stream: &[u8]) -> Vec<(String, Vec<u8>)> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < stream.len() {
        if stream[i..].starts_with(tmux::PASSTHROUGH_BEGIN) {
            let (inner, len) = tmux::unwrap(&stream[i..]).unwrap();
            out.extend(commands(&inner));
            i += len;
        } else if stream[i..].starts_with(b"\x1b_G") {
            let end = stream[i..].windows(2).position(|w| w == b"\x1b\\").unwrap();
            let body = &stream[i + 3..i + end];
            let semi = body.iter().position(|&b| b == b';').unwrap_or(body.len());
            out.push((String::from_utf8(body[..semi].to_vec()).unwrap(), body[(semi + 1).min(body.len())..].to_vec()));
            i += end + 2;
        } else {
            i += 1;
        }
    }
    out
}

#[test]
fn a_frame_decodes_to_the_scenes_pixels() {
    let (w, h, rgb) = golden_pool();
    let mut enc = KittyEncoder::new(KittyOptions { origin: (2, 1), ..KittyOptions::new((80, 23)) });
    let mut out = Vec::new();
    assert_eq!(enc.encode(&rgb, w, h, &mut out).unwrap(), Update::Full);
    assert!(out.starts_with(b"\x1b[2;3H\x1b_G"), "the cursor goes to the origin first");
    let state = decode(&out).unwrap();
    let image = &state.images[&IMAGE_ID];
    assert_eq!((image.width, image.height), (w, h));
    assert!(image.rgb == rgb, "decoded pixels differ from the source");
    let k = |key: char| image.keys.get(&key).map(String::as_str);
    assert_eq!(
        [k('a'), k('f'), k('o'), k('q'), k('c'), k('r'), k('C'), k('p')],
        [Some("T"), Some("24"), Some("z"), Some("2"), Some("80"), Some("23"), Some("1"), Some("1")]
    );
}

#[test]
fn chunks_are_at_most_4096_base64_bytes_and_flagged() {
    // Noise does not compress: many chunks.
    let (w, h) = (97, 61);
    let rgb = noise(w, h, 7);
    let mut enc = KittyEncoder::new(KittyOptions::new((10, 5)));
    let mut out = Vec::new();
    enc.encode(&rgb, w, h, &mut out).unwrap();
    let cmds = commands(&out);
    assert!(cmds.len() >= 4, "{} chunks", cmds.len());
    for (i, (control, payload)) in cmds.iter().enumerate() {
        let last = i + 1 == cmds.len();
        assert!(payload.len() <= CHUNK_BASE64, "chunk {i}: {} bytes", payload.len());
        assert!(last || payload.len() % 4 == 0, "chunk {i} is not a multiple of 4");
        assert!(control.contains(if last { "m=0" } else { "m=1" }), "chunk {i}: {control}");
        assert!(control.contains("q=2"), "chunk {i}: responses not suppressed: {control}");
        if i > 0 {
            assert_eq!(control, if last { "m=0,q=2" } else { "m=1,q=2" }, "continuations carry only m and q");
        }
    }
    assert_eq!(decode(&out).unwrap().images[&IMAGE_ID].rgb, rgb);
}

#[test]
fn still_pictures_send_nothing_and_a_resize_sends_all() {
    let (w, h) = (16, 9);
    let rgb = noise(w, h, 1);
    let mut enc = KittyEncoder::new(KittyOptions::new((8, 4)));
    let mut out = Vec::new();
    enc.encode(&rgb, w, h, &mut out).unwrap();
    out.clear();
    assert_eq!(enc.encode(&rgb, w, h, &mut out).unwrap(), Update::Unchanged);
    assert!(out.is_empty());
    let bigger = noise(w + 1, h, 1);
    assert_eq!(enc.encode(&bigger, w + 1, h, &mut out).unwrap(), Update::Full);
    enc.invalidate();
    out.clear();
    assert_eq!(enc.encode(&bigger, w + 1, h, &mut out).unwrap(), Update::Full, "after invalidate");
    assert!(!out.is_empty());
}

#[test]
fn small_changes_go_as_frame_edits_when_allowed() {
    let (w, h, first) = golden_pool();
    let mut second = first.clone();
    // A ripple: change a 20x10 block at (100, 50) and one pixel at (130, 52).
    for y in 50..60 {
        for x in 100..120 {
            second[(y * w as usize + x) * 3] ^= 0x55;
        }
    }
    second[(52 * w as usize + 130) * 3 + 2] ^= 1;
    assert_eq!(changed_rect(&first, &second, w, h), Some((100, 50, 31, 10)));

    let mut enc = KittyEncoder::new(KittyOptions { frame_edits: true, ..KittyOptions::new((80, 23)) });
    let mut stream = Vec::new();
    enc.encode(&first, w, h, &mut stream).unwrap();
    let mut edit = Vec::new();
    assert_eq!(enc.encode(&second, w, h, &mut edit).unwrap(), Update::Rect(100, 50, 31, 10));
    let cmds = commands(&edit);
    assert!(cmds[0].0.starts_with("a=f,r=1,") && cmds[0].0.contains("x=100,y=50,s=31,v=10,X=1"), "{}", cmds[0].0);
    stream.extend_from_slice(&edit);
    assert!(decode(&stream).unwrap().images[&IMAGE_ID].rgb == second, "the edited image differs");
    assert!(edit.len() < 2000, "an edit of 310 pixels took {} bytes", edit.len());

    // Without frame edits, or when most of the picture changed, the whole image goes.
    let mut enc = KittyEncoder::new(KittyOptions::new((80, 23)));
    enc.encode(&first, w, h, &mut Vec::new()).unwrap();
    assert_eq!(enc.encode(&second, w, h, &mut Vec::new()).unwrap(), Update::Full);
    let mut enc = KittyEncoder::new(KittyOptions { frame_edits: true, ..KittyOptions::new((80, 23)) });
    enc.encode(&first, w, h, &mut Vec::new()).unwrap();
    let inverted: Vec<u8> = first.iter().map(|v| !v).collect();
    assert_eq!(enc.encode(&inverted, w, h, &mut Vec::new()).unwrap(), Update::Full);
}

#[test]
fn changed_rect_finds_the_exact_box() {
    let (w, h) = (5u32, 4u32);
    let a = vec![0u8; 60];
    assert_eq!(changed_rect(&a, &a, w, h), None);
    let mut b = a.clone();
    b[(3 * 5 + 4) * 3 + 1] = 1; // (4, 3)
    assert_eq!(changed_rect(&a, &b, w, h), Some((4, 3, 1, 1)));
    b[5 * 3] = 1; // (0, 1)
    assert_eq!(changed_rect(&a, &b, w, h), Some((0, 1, 5, 3)));
}

#[test]
fn tmux_wraps_every_command_and_uses_placeholders() {
    let (w, h, rgb) = golden_pool();
    let options = KittyOptions { tmux: true, placeholders: true, origin: (0, 2), ..KittyOptions::new((40, 12)) };
    let mut enc = KittyEncoder::new(options);
    let mut out = Vec::new();
    enc.encode(&rgb, w, h, &mut out).unwrap();
    // Outside the wrappers there is no APC at all: only placeholder text.
    let mut outside = Vec::new();
    let mut i = 0;
    while i < out.len() {
        if let Some((_, len)) = tmux::unwrap(&out[i..]) {
            i += len;
        } else {
            outside.push(out[i]);
            i += 1;
        }
    }
    assert!(!outside.windows(2).any(|w| w == b"\x1b_"), "an APC escaped the wrapper");
    let text = String::from_utf8(outside).unwrap();
    assert_eq!(text.matches('\u{10EEEE}').count(), 40 * 12);
    assert!(text.starts_with("\x1b[3;1H"), "placeholders start at the origin: {:?}", &text[..12]);
    let state = decode(&out).unwrap();
    assert!(state.images[&IMAGE_ID].rgb == rgb);
    assert_eq!(state.images[&IMAGE_ID].keys.get(&'U').map(String::as_str), Some("1"));
    assert!(!state.images[&IMAGE_ID].keys.contains_key(&'p'), "a virtual placement has no position");

    // The next frame re-sends the image but not the text.
    let mut next = Vec::new();
    let changed: Vec<u8> = rgb.iter().map(|v| v.wrapping_add(1)).collect();
    enc.encode(&changed, w, h, &mut next).unwrap();
    assert!(!String::from_utf8_lossy(&next).contains('\u{10EEEE}'));
    out.extend_from_slice(&next);
    assert!(decode(&out).unwrap().images[&IMAGE_ID].rgb == changed);
}

#[test]
fn temporary_files_carry_raw_pixels_without_base64_data() {
    let dir = std::env::temp_dir().join(format!("tidepool-kitty-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (w, h, rgb) = golden_pool();
    let mut enc =
        KittyEncoder::new(KittyOptions { medium: Medium::TempFile(dir.clone()), ..KittyOptions::new((8, 4)) });
    let mut out = Vec::new();
    enc.encode(&rgb, w, h, &mut out).unwrap();
    let cmds = commands(&out);
    assert_eq!(cmds.len(), 1);
    assert!(cmds[0].0.contains("t=t") && !cmds[0].0.contains("o=z"), "{}", cmds[0].0);
    let path = String::from_utf8(BASE64.decode(&cmds[0].1).unwrap()).unwrap();
    assert!(path.contains(TEMP_FILE_MARKER) && path.starts_with(dir.to_str().unwrap()), "{path}");
    assert_eq!(std::fs::read(&path).unwrap(), rgb, "the file holds the raw RGB");
    assert!(decode(&out).unwrap().images[&IMAGE_ID].rgb == rgb);
    assert!(!Path::new(&path).exists(), "t=t: the reader deletes the file");
    // A second frame gets a file of its own.
    enc.invalidate();
    let mut second = Vec::new();
    enc.encode(&rgb, w, h, &mut second).unwrap();
    assert_ne!(commands(&second)[0].1, cmds[0].1);
    decode(&second).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_failed_file_write_appends_nothing() {
    let missing = std::env::temp_dir().join("tidepool-no-such-dir-for-kitty/x");
    let mut enc = KittyEncoder::new(KittyOptions { medium: Medium::TempFile(missing), ..KittyOptions::new((8, 4)) });
    let mut out = b"kept".to_vec();
    assert!(enc.encode(&[0; 12], 2, 2, &mut out).is_err());
    assert_eq!(out, b"kept");
    // Nothing was recorded as shown: the next attempt sends the whole picture again.
    enc.set_options(KittyOptions::new((8, 4)));
    assert_eq!(enc.encode(&[0; 12], 2, 2, &mut out).unwrap(), Update::Full);
}

#[test]
fn delete_removes_the_image() {
    let mut enc = KittyEncoder::new(KittyOptions { tmux: true, ..KittyOptions::new((8, 4)) });
    let mut out = Vec::new();
    enc.encode(&[9; 12], 2, 2, &mut out).unwrap();
    enc.push_delete(&mut out);
    let state = decode(&out).unwrap();
    assert!(state.images.is_empty());
    let last = state.commands.last().unwrap();
    assert_eq!((last[&'a'].as_str(), last[&'d'].as_str(), last[&'q'].as_str()), ("d", "I", "2"));
}
