use super::*;
use crate::output::graphics::test_pictures::{golden_pool, noise};
use crate::output::oklab;

/// Decodes one sixel image with an independent decoder (icy_sixel) into its RGB, checking its
/// size is `w x h`: every pixel of it painted; a decoder that sizes images by whole six-row
/// bands may add rows below, which must be left unpainted (transparent, `P2=1`).
fn decode(stream: &[u8], w: u32, h: u32) -> Vec<u8> {
    let start = stream.windows(2).position(|w| w == b"\x1bP").expect("a DCS");
    let image = icy_sixel::SixelImage::decode(&stream[start..]).expect("icy_sixel decodes the stream");
    assert_eq!(image.width as u32, w);
    assert!(image.height as u32 == h || image.height as u32 == h.div_ceil(6) * 6, "{}x{}", image.width, image.height);
    let split = w as usize * h as usize * 4;
    assert!(image.pixels[..split].chunks_exact(4).all(|p| p[3] == 255), "a pixel was left unpainted");
    assert!(image.pixels[split..].chunks_exact(4).all(|p| p[3] == 0), "a pixel below the picture was painted");
    image.pixels[..split].chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect()
}

#[test]
fn cubes_fit_the_registers() {
    assert_eq!(SixelPalette::for_registers(256).len(), 6 * 7 * 6);
    assert_eq!(SixelPalette::for_registers(4096).len(), 252, "capped at 256 registers");
    assert_eq!(SixelPalette::for_registers(64).len(), 64);
    assert_eq!(SixelPalette::for_registers(16).len(), 16);
    assert_eq!(SixelPalette::for_registers(0).len(), 8);
    let p = SixelPalette::for_registers(256);
    assert_eq!(p.rgb(0), [0, 0, 0]);
    assert_eq!(p.rgb(251), [255, 255, 255]);
    assert_eq!(p.percent_rgb(1), [0, 0, 20], "blue is the fastest-varying channel");
    assert_eq!(p.percent_rgb(6), [0, 17, 0], "green levels are sixths: 16.7% rounds to 17");
    assert_eq!(p.rgb(6), [0, 43, 0]);
}

/// The mean OKLab distance from each pixel of `rgb` to the colour `shown` has there.
fn mean_error(rgb: &[u8], shown: &[u8]) -> f32 {
    let n = rgb.len() / 3;
    let sum: f32 = rgb
        .chunks_exact(3)
        .zip(shown.chunks_exact(3))
        .map(|(a, b)| oklab::from_rgb([a[0], a[1], a[2]]).distance(oklab::from_rgb([b[0], b[1], b[2]])))
        .sum();
    sum / n as f32
}

/// Each pixel of `rgb` as its nearest register's colour (no dither).
fn undithered(palette: &SixelPalette, rgb: &[u8]) -> Vec<u8> {
    let mut map = lookup::ColourMap::new(palette);
    rgb.chunks_exact(3).flat_map(|p| palette.rgb(map.register([p[0], p[1], p[2]], lookup::ColourMap::MIDDLE))).collect()
}

#[test]
fn a_fitted_palette_is_close_to_the_picture() {
    // The golden pool: its pixels are within a third of a just-noticeable difference of their
    // nearest register with 256 fitted colours on average, within one with 16 (xterm -ti
    // vt340's default), where the fixed cubes are several times further.
    let (w, h, rgb) = golden_pool();
    for (registers, bound) in [(256u16, oklab::JND / 3.0), (16, oklab::JND)] {
        let fitted = SixelPalette::fit(&rgb, 3, registers);
        assert!(fitted.len() <= usize::from(registers) && fitted.len() > usize::from(registers) / 2);
        let error = mean_error(&rgb, &undithered(&fitted, &rgb));
        let cube = mean_error(&rgb, &undithered(&SixelPalette::for_registers(registers), &rgb));
        assert!(error < bound, "{registers} registers: mean error {error} (bound {bound})");
        assert!(error * 3.0 < cube, "{registers} registers: fitted {error}, cube {cube}");
        // Dithered, the picture keeps its mean colour.
        let shown = dithered_rgb(&fitted, &rgb, w, h);
        let mean =
            |v: &[u8], c: usize| v.iter().skip(c).step_by(3).map(|&x| f64::from(x)).sum::<f64>() / (v.len() / 3) as f64;
        for c in 0..3 {
            assert!((mean(&shown, c) - mean(&rgb, c)).abs() < 1.5, "{registers} registers: channel {c} drifted");
        }
    }
    // The same picture gives the same palette (nothing depends on the order of a hash or on
    // threads).
    assert_eq!(SixelPalette::fit(&rgb, 3, 256), SixelPalette::fit(&rgb, 3, 256));
}

#[test]
fn the_palette_is_refitted_only_when_the_colours_drift() {
    let (w, h, rgb) = golden_pool();
    let mut enc = SixelEncoder::new(SixelPalette::for_registers(256), (0, 0), Some((8, 16)));
    assert!(enc.fit_to(&rgb, 3, 256), "the first picture fits the palette");
    let fitted = enc.palette().clone();
    assert!(!enc.fit_to(&rgb, 3, 256), "the same picture: kept");
    // A little brighter everywhere (two levels): kept, the dither covers it.
    let brighter: Vec<u8> = rgb.iter().map(|&v| v.saturating_add(2)).collect();
    assert!(!enc.fit_to(&brighter, 3, 256), "a small change: kept");
    // Half the picture turned red: refitted, and the next picture is sent whole.
    let mut out = Vec::new();
    enc.encode(&rgb, w, h, &mut out);
    let mut red = rgb.clone();
    for p in red.chunks_exact_mut(3).take((w * h / 2) as usize) {
        p.copy_from_slice(&[220, 40, 30]);
    }
    assert!(enc.fit_to(&red, 3, 256), "new colours: refitted");
    assert!(enc.palette() != &fitted);
    assert_eq!(enc.encode(&red, w, h, &mut out), Update::Full, "new registers: sent whole");
}

#[test]
fn a_frame_decodes_to_the_dithered_scene() {
    let (w, h, rgb) = golden_pool();
    let palette = SixelPalette::fit(&rgb, 3, 256);
    let mut enc = SixelEncoder::new(palette.clone(), (0, 0), None);
    let mut out = Vec::new();
    assert_eq!(enc.encode(&rgb, w, h, &mut out), Update::Full);
    assert!(out.starts_with(b"\x1b[1;1H\x1bP0;1;0q\"1;1;640;360"));
    let decoded = decode(&out, w, h);
    assert!(decoded == dithered_rgb(&palette, &rgb, w, h), "decoded pixels differ from the dithered picture");
    // And the dither stays close to the source: the mean of each channel within 2 levels.
    let mean =
        |v: &[u8], c: usize| v.iter().skip(c).step_by(3).map(|&x| f64::from(x)).sum::<f64>() / (v.len() / 3) as f64;
    for c in 0..3 {
        assert!((mean(&decoded, c) - mean(&rgb, c)).abs() < 2.0, "channel {c} drifted");
    }
}

#[test]
fn odd_sizes_and_small_palettes_decode_exactly() {
    for (w, h, registers) in [(37, 13, 256), (1, 1, 16), (9, 6, 64), (50, 7, 16)] {
        let rgb = noise(w, h, u64::from(w * h));
        let palette = SixelPalette::for_registers(registers);
        let mut out = Vec::new();
        SixelEncoder::new(palette.clone(), (3, 2), None).encode(&rgb, w, h, &mut out);
        assert!(out.starts_with(b"\x1b[3;4H"), "placed at the origin cell");
        let decoded = decode(&out, w, h);
        assert!(decoded == dithered_rgb(&palette, &rgb, w, h), "{w}x{h} with {registers} registers");
    }
}

#[test]
fn dithering_is_ordered_stable_and_keeps_the_mean() {
    let (gw, gh, golden) = golden_pool();
    let palette = SixelPalette::fit(&golden, 3, 256);
    let mut enc = SixelEncoder::new(palette.clone(), (0, 0), None);
    // A flat colour of the water between registers: a mix of registers whose mean is the colour.
    let pick = golden[(gh as usize / 2 * gw as usize + gw as usize / 3) * 3..][..3].to_vec();
    let flat: Vec<u8> = pick.repeat(16 * 16);
    let mut idx = Vec::new();
    enc.dither_into(&flat, 16, 16, &mut idx);
    let distinct: std::collections::BTreeSet<u8> = idx.iter().copied().collect();
    assert!(distinct.len() > 1, "a colour between registers must dither");
    let shown = dithered_rgb(&palette, &flat, 16, 16);
    for (c, &want) in flat[..3].iter().enumerate() {
        let mean = shown.iter().skip(c).step_by(3).map(|&v| f64::from(v)).sum::<f64>() / 256.0;
        assert!((mean - f64::from(want)).abs() < 2.0, "channel {c}: mean {mean}, colour {want}");
    }
    // The pattern repeats every 8 pixels and depends on nothing else.
    for y in 0..8 {
        for x in 0..8 {
            assert_eq!(idx[y * 16 + x], idx[(y + 8) * 16 + x + 8]);
        }
    }
    // One changed pixel changes one register (error diffusion would change its neighbours).
    let mut changed = flat.clone();
    changed[(5 * 16 + 5) * 3] = 250;
    let mut idx2 = Vec::new();
    enc.dither_into(&changed, 16, 16, &mut idx2);
    let differing: Vec<usize> = (0..256).filter(|&i| idx[i] != idx2[i]).collect();
    assert_eq!(differing, vec![5 * 16 + 5]);
}

#[test]
fn an_unchanged_block_encodes_to_the_same_bytes() {
    // Two frames of the pool that differ only outside the cell block 64..128 x 48..96: the
    // block's image is byte for byte the same in both, whatever changed around it.
    let (w, h, first) = golden_pool();
    let palette = SixelPalette::fit(&first, 3, 256);
    let mut second = first.clone();
    for (i, p) in second.chunks_exact_mut(3).enumerate() {
        let (x, y) = (i % w as usize, i / w as usize);
        if !(64..128).contains(&x) || !(48..96).contains(&y) {
            p[0] = p[0].wrapping_add((x * 7 + y * 3) as u8 % 23);
        }
    }
    let block = (64, 48, 64, 48);
    let mut enc = SixelEncoder::new(palette, (0, 0), Some((8, 16)));
    let (mut a, mut b, mut pixels) = (Vec::new(), Vec::new(), Vec::new());
    enc.dither_into(&first, w, h, &mut pixels);
    enc.push_block(&mut a, &pixels, w, block, (0, 0), (8, 16));
    let before = pixels.clone();
    enc.dither_into(&second, w, h, &mut pixels);
    enc.push_block(&mut b, &pixels, w, block, (0, 0), (8, 16));
    assert!(before != pixels, "the frames differ");
    assert!(a == b, "the unchanged block encoded to other bytes");
    assert!(a.len() > 500, "a real block: {} bytes", a.len());
}

#[test]
fn the_same_picture_gives_the_same_bytes_and_still_water_sends_nothing() {
    let (w, h, rgb) = golden_pool();
    let palette = SixelPalette::for_registers(256);
    let (mut a, mut b) = (Vec::new(), Vec::new());
    SixelEncoder::new(palette.clone(), (0, 0), None).encode(&rgb, w, h, &mut a);
    let mut enc = SixelEncoder::new(palette, (0, 0), None);
    enc.encode(&rgb, w, h, &mut b);
    assert!(a == b, "two encoders disagree");
    let mut again = Vec::new();
    assert_eq!(enc.encode(&rgb, w, h, &mut again), Update::Unchanged);
    assert!(again.is_empty());
    enc.invalidate();
    assert_eq!(enc.encode(&rgb, w, h, &mut again), Update::Full);
    assert!(again == a);
}

#[test]
fn runs_are_length_encoded() {
    // 100 black pixels in one band: one colour, one run.
    let palette = SixelPalette::for_registers(256);
    let mut out = Vec::new();
    SixelEncoder::new(palette, (0, 0), None).encode(&[0; 100 * 6 * 3], 100, 6, &mut out);
    let text = String::from_utf8(out).unwrap();
    assert!(text.ends_with("\"1;1;100;6#0;2;0;0;0#0!100~-\x1b\\"), "only the register used is defined: {text:?}");
    // A two-row stripe of white over black: passes overlap with `$`, empties are skipped.
    let mut rgb = vec![0u8; 10 * 6 * 3];
    rgb[..10 * 2 * 3].fill(255);
    let mut out = Vec::new();
    SixelEncoder::new(SixelPalette::for_registers(256), (0, 0), None).encode(&rgb, 10, 6, &mut out);
    let text = String::from_utf8(out).unwrap();
    // Black covers rows 2..6 (bits 0b111100 -> '?' + 60 = '{'), white rows 0..2 ('?' + 3 = 'B').
    assert!(text.ends_with("#0;2;0;0;0#0!10{$#251;2;100;100;100#251!10B-\x1b\\"), "{text:?}");
}

#[test]
fn shared_registers_are_defined_once_per_session() {
    let mut enc = SixelEncoder::new(SixelPalette::for_registers(256), (0, 0), None);
    enc.set_registers(Registers::Shared);
    let mut out = Vec::new();
    enc.encode(&[0; 12 * 6 * 3], 12, 6, &mut out);
    assert!(String::from_utf8_lossy(&out).contains("#0;2;0;0;0"), "defined at first use");
    out.clear();
    enc.encode(&[255; 12 * 6 * 3], 12, 6, &mut out);
    enc.encode(&[0; 12 * 6 * 3], 12, 6, &mut out);
    let text = String::from_utf8(out).unwrap();
    assert!(text.contains("#251;2;100;100;100") && !text.contains("#0;2;"), "register 0 kept: {text:?}");
    enc.forget_registers();
    let mut out = Vec::new();
    enc.encode(&[255; 12 * 6 * 3], 12, 6, &mut out);
    assert!(String::from_utf8(out).unwrap().contains("#251;2;"), "defined again after forgetting");
}

#[test]
fn images_stay_under_the_tmux_limit_cut_on_text_rows_and_decode_to_the_whole() {
    let (w, h) = (200u32, 96u32);
    let rgb = noise(w, h, 5);
    let palette = SixelPalette::for_registers(256);
    let mut whole = Vec::new();
    SixelEncoder::new(palette.clone(), (0, 0), Some((10, 12))).encode(&rgb, w, h, &mut whole);
    let mut enc = SixelEncoder::new(palette.clone(), (0, 0), Some((10, 12)));
    let cap = 30_000;
    enc.set_max_image_bytes(Some(cap), true);
    let mut out = Vec::new();
    enc.encode(&rgb, w, h, &mut out);
    // Each piece: a cursor move to a text row, then one wrapped image under the cap.
    let mut pieces = Vec::new();
    let mut rest = &out[..];
    while !rest.is_empty() {
        let begin = rest
            .windows(7)
            .position(|w| w == crate::output::graphics::tmux::PASSTHROUGH_BEGIN)
            .expect("a wrapped image");
        let head = std::str::from_utf8(&rest[..begin]).unwrap();
        let row: u32 = head.trim_start_matches("\x1b[").split(';').next().unwrap().parse().unwrap();
        let (inner, len) = crate::output::graphics::tmux::unwrap(&rest[begin..]).expect("whole wrapper");
        assert!(len <= cap, "a piece of {len} bytes");
        pieces.push((row, inner));
        rest = &rest[begin + len..];
    }
    assert!(pieces.len() >= 3, "{} pieces of a {}-byte picture", pieces.len(), whole.len());
    // Decoded and stacked at their rows, the pieces are the whole dithered picture.
    let want = dithered_rgb(&palette, &rgb, w, h);
    let mut got = vec![0u8; want.len()];
    for (row, inner) in &pieces {
        let image = icy_sixel::SixelImage::decode(inner).expect("each piece decodes");
        let y0 = (row - 1) as usize * 12;
        for y in 0..image.height.min(h as usize - y0) {
            for x in 0..w as usize {
                let p = &image.pixels[(y * image.width + x) * 4..];
                if p[3] == 255 {
                    got[((y0 + y) * w as usize + x) * 3..][..3].copy_from_slice(&p[..3]);
                }
            }
        }
    }
    assert!(got == want, "the pieces differ from the whole picture");
}

#[test]
fn changed_cells_are_sent_alone_and_match_the_whole_picture() {
    let (w, h, first) = golden_pool();
    let palette = SixelPalette::for_registers(256);
    let mut second = first.clone();
    for y in 40..45 {
        for x in 100..103 {
            second[(y * w as usize + x) * 3 + 1] ^= 0x80;
        }
    }
    let mut enc = SixelEncoder::new(palette.clone(), (1, 1), Some((8, 16)));
    let mut whole = Vec::new();
    enc.encode(&first, w, h, &mut whole);
    let mut part = Vec::new();
    // Pixels 100..103 x 40..45 lie in cell column 12, cell row 2: the block 96..104 x 32..48,
    // whole cells (16 rows: its last band partial).
    assert_eq!(enc.encode(&second, w, h, &mut part), Update::Rect(96, 32, 8, 16));
    assert!(part.starts_with(b"\x1b[4;14H"), "placed at the block's cell (origin + (12, 2))");
    let patch = decode(&part, 8, 16);
    // The patch pasted on the first picture gives the second.
    let mut shown = decode(&whole, w, h);
    for y in 0..16 {
        let to = ((32 + y) * w as usize + 96) * 3;
        shown[to..to + 24].copy_from_slice(&patch[y * 24..(y + 1) * 24]);
    }
    assert!(shown == dithered_rgb(&palette, &second, w, h));
    assert!(part.len() < whole.len() / 50, "the patch took {} bytes, the whole {}", part.len(), whole.len());
    let mut again = Vec::new();
    assert_eq!(enc.encode(&second, w, h, &mut again), Update::Unchanged, "nothing changed since");
    assert!(again.is_empty());

    // A change in the last cell row, cut short by the picture's bottom (352..360): that row alone.
    let mut third = second.clone();
    third[(358 * w as usize + 5) * 3] ^= 0xff;
    let mut out = Vec::new();
    assert_eq!(enc.encode(&third, w, h, &mut out), Update::Rect(0, 352, 8, 8));
    let patch = decode(&out, 8, 8);
    let want = dithered_rgb(&palette, &third, w, h);
    for y in 0..8 {
        let from = ((352 + y) * w as usize) * 3;
        assert!(patch[y * 24..(y + 1) * 24] == want[from..from + 24]);
    }
}

#[test]
fn a_changed_block_ends_at_a_cell_boundary_not_below_it() {
    // mlterm 3.9 sizes a sixel image in whole cells and fills the rest of the last row of cells
    // it reaches into with its background: a block of one 22-pixel row of cells made 24 rows
    // tall (whole bands) blanked 20 rows of the picture below it (white holes under every
    // block, seen under Xvfb). A block must end where its cells end.
    let (w, h, first) = golden_pool();
    let palette = SixelPalette::for_registers(256);
    let mut second = first.clone();
    second[(30 * w as usize + 15) * 3] ^= 0xff; // cell (1, 1) of 10x22-pixel cells
    let mut enc = SixelEncoder::new(palette, (0, 0), Some((10, 22)));
    enc.encode(&first, w, h, &mut Vec::new());
    let mut part = Vec::new();
    assert_eq!(enc.encode(&second, w, h, &mut part), Update::Rect(10, 22, 10, 22));
    let start = part.windows(2).position(|w| w == b"\x1bP").unwrap();
    let image = icy_sixel::SixelImage::decode(&part[start..]).unwrap();
    let painted = image.pixels.chunks_exact(4).enumerate().filter(|(_, p)| p[3] == 255);
    let lowest = painted.map(|(i, _)| i / image.width).max().unwrap();
    assert_eq!((image.width, lowest), (10, 21), "painted down to the cell's last row, no further");
    assert!(header_height(&part[start..]) == 22, "the raster attributes say 22 rows");
}

/// The height `"Pan;Pad;Ph;Pv` gives in a sixel image.
fn header_height(image: &[u8]) -> u32 {
    let at = image.iter().position(|&b| b == b'"').expect("raster attributes");
    let end = image[at..].iter().position(|&b| b == b'#').unwrap() + at;
    let fields: Vec<&str> = std::str::from_utf8(&image[at + 1..end]).unwrap().split(';').collect();
    fields[3].parse().unwrap()
}

#[test]
fn every_colour_definition_is_followed_by_its_selection() {
    // DEC's `#Pc;Pu;Px;Py;Pz` defines and selects; xterm (379, -ti vt340) only defines: the
    // pixels that follow were drawn in the register it had selected before (a VT340 default:
    // green lines along every block's first band). Each definition must be followed by `#Pc`.
    let (w, h, rgb) = golden_pool();
    let mut e = SixelEncoder::new(SixelPalette::for_registers(256), (0, 0), Some((8, 16)));
    let mut out = Vec::new();
    e.encode(&rgb, w, h, &mut out);
    let text = String::from_utf8_lossy(&out);
    let mut definitions = 0;
    for (at, _) in text.match_indices(";2;") {
        let before = &text[..at];
        let hash = before.rfind('#').expect("a definition starts with #");
        let register = &before[hash + 1..];
        assert!(register.bytes().all(|b| b.is_ascii_digit()), "{register:?}");
        let after = &text[at + 3..];
        let end = after.find(|c: char| !(c.is_ascii_digit() || c == ';')).unwrap();
        assert!(
            after[end..].starts_with(&format!("#{register}")),
            "#{register} is defined but not selected: {:?}",
            &after[..end + 8]
        );
        definitions += 1;
    }
    assert!(definitions > 20, "{definitions} definitions");
}
