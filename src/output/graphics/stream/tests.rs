use super::*;
use crate::output::bucket::ByteBucket;
use crate::output::graphics::GraphicsMode;
use crate::output::graphics::geometry::{SCALED_CAP, layout};
use crate::output::graphics::kitty::{self, KittyOptions};
use crate::output::graphics::kitty_decode;
use crate::output::graphics::test_pictures::golden_pool;

const FRAME: Duration = Duration::from_nanos(1_000_000_000 / 30);

/// The golden pool picture (640x360) shifted `k` pixels: a picture that moves every frame.
fn moving(k: u32) -> Pixmap {
    let (w, h, rgb) = golden_pool();
    let mut p = Pixmap::new(w, h).unwrap();
    for (i, px) in p.pixels_mut().iter_mut().enumerate() {
        let (x, y) = (i as u32 % w, i as u32 / w);
        let at = ((y * w + (x + 3 * k) % w) * 3) as usize;
        *px = tiny_skia::ColorU8::from_rgba(rgb[at], rgb[at + 1], rgb[at + 2], 255).premultiply();
    }
    p
}

fn kitty_stream() -> PictureStream {
    let l = layout(GraphicsMode::Kitty, (160, 48), Some((8, 16)), None, SCALED_CAP);
    PictureStream::new(Protocol::Kitty(KittyOptions { frame_edits: true, ..KittyOptions::new(l.cells) }), l)
}

fn sixel_stream() -> PictureStream {
    let l = layout(GraphicsMode::Sixel, (160, 48), Some((8, 16)), Some((4096, 4096)), SCALED_CAP);
    let protocol =
        Protocol::Sixel { palette: SixelPalette::for_registers(256), registers: Registers::PerImage, tmux: false };
    PictureStream::new(protocol, l)
}

fn iterm2_stream() -> PictureStream {
    let l = layout(GraphicsMode::Iterm2, (160, 48), Some((8, 16)), None, SCALED_CAP);
    PictureStream::new(Protocol::Iterm2 { tmux: false }, l)
}

/// Plays `frames` moving frames at 30 fps through `stream` with a bucket of `rate` bytes a
/// second, committing every offer; returns (pictures, bytes, the largest overshoot of what
/// was available).
fn play(stream: &mut PictureStream, rate: f64, frames: u32) -> (u32, usize, isize) {
    let t0 = Instant::now();
    let mut bucket = ByteBucket::new(rate);
    bucket.refill(t0);
    let (mut pictures, mut bytes, mut over) = (0, 0, isize::MIN);
    for n in 1..=frames {
        let now = t0 + FRAME * n;
        bucket.refill(now);
        let budget = Budget::new(bucket.budget(), Some(rate), FRAME);
        let picture = moving(n);
        if let Some(offer) = stream.prepare(&picture, budget, now) {
            let len = offer.bytes.len();
            over = over.max(len as isize - budget.available as isize);
            bucket.spend(len);
            stream.commit();
            pictures += 1;
            bytes += len;
        }
    }
    (pictures, bytes, over)
}

#[test]
fn at_250_kb_a_second_every_mode_moves_at_10_fps_or_more_within_the_budget() {
    for (name, mut stream) in [("kitty", kitty_stream()), ("sixel", sixel_stream()), ("iterm2", iterm2_stream())] {
        let frames = 60;
        let (pictures, bytes, over) = play(&mut stream, 250e3, frames);
        let seconds = f64::from(frames) / 30.0;
        assert!(over <= 0, "{name}: an offer exceeded the bytes available by {over}");
        assert!(
            f64::from(pictures) / seconds >= 10.0,
            "{name}: {pictures} pictures in {seconds} s ({:?})",
            stream.state()
        );
        assert!(bytes as f64 / seconds <= 250e3 * 1.05, "{name}: {bytes} bytes in {seconds} s");
        // kitty's rung is chosen for 16 pictures a second (`plan::KITTY_MIN_RATE`): fresher
        // pictures, and a key's effect crosses the link in a sixteenth of a second.
        if name == "kitty" {
            assert!(f64::from(pictures) / seconds >= 16.0, "kitty: {pictures} pictures in {seconds} s");
        }
    }
}

#[test]
fn a_slow_link_gets_smaller_pictures_and_never_more_than_it_has() {
    let mut fast = kitty_stream();
    let mut slow = kitty_stream();
    play(&mut fast, 2e6, 30);
    let (pictures, _, over) = play(&mut slow, 50e3, 60);
    assert!(over <= 0, "overshoot {over}");
    assert!(pictures > 0);
    let (f, s) = (fast.state().size, slow.state().size);
    assert!(s.0 < f.0 && s.1 < f.1, "2 MB/s sends {f:?}, 50 kB/s {s:?}");
}

#[test]
fn an_uncommitted_offer_is_not_believed_shown() {
    let mut stream = kitty_stream();
    let picture = moving(0);
    let budget = Budget::unlimited(FRAME);
    let t0 = Instant::now();
    let first = stream.prepare(&picture, budget, t0).expect("a first picture").state.part;
    assert_eq!(first, Part::Whole);
    // Not committed: the same picture is offered again, whole.
    let again = stream.prepare(&picture, budget, t0 + FRAME).expect("offered again").state.part;
    assert_eq!(again, Part::Whole);
    stream.commit();
    assert!(stream.prepare(&picture, budget, t0 + FRAME * 2).is_none(), "shown: an unchanged picture sends nothing");
}

#[test]
fn kitty_offers_decode_to_the_picture_on_the_wire_and_edits_apply_to_it() {
    let mut stream = kitty_stream();
    let t0 = Instant::now();
    let mut wire = Vec::new();
    // Unlimited, then 2 MB/s until the rung settles, then a small change: a frame edit (of
    // the lossy picture shown, found against the picture it was made from).
    let rates = [None, Some(2e6), Some(2e6), Some(2e6), Some(2e6), Some(2e6)];
    let mut picture = moving(0);
    for (n, rate) in (0u32..).zip(rates) {
        picture = if n + 1 < rates.len() as u32 { moving(n) } else { picture };
        if n + 1 == rates.len() as u32 {
            for px in picture.pixels_mut()[..640 * 4].iter_mut() {
                *px = tiny_skia::ColorU8::from_rgba(255, 0, 0, 255).premultiply();
            }
        }
        let budget = Budget::new(usize::MAX, rate, FRAME);
        let offer = stream.prepare(&picture, budget, t0 + FRAME * (10 * n)).expect("an offer");
        let part = offer.state.part;
        if rate.is_none() {
            // Unlimited: the exact picture as a PNG (fdeflate), not zlib of raw RGB, whose
            // deflate cost a third of the player (docs/pixels/cpu.md, Round 6).
            assert_eq!(offer.state.packing, Some(Packing::Png));
        } else {
            // Under a rate: an indexed PNG of a few colours (4 bits a pixel, colour type 3)
            // that the decoder below must read.
            assert_eq!(offer.state.packing, Some(Packing::PalettePng(KITTY_COLOURS)));
        }
        wire.extend_from_slice(offer.bytes);
        stream.commit();
        let image = &kitty_decode::decode(&wire).unwrap().images[&kitty::IMAGE_ID];
        let size = stream.state().size;
        assert_eq!((image.width, image.height), size);
        let mut want = Vec::new();
        Resampler::default().resample(picture.data(), 4, (640, 360), size, &mut want);
        // Unlimited: the picture itself; under a rate: the palette PNG, which the stream's
        // model of the terminal holds exactly and which is near the picture.
        assert!(image.rgb == stream.shown.as_ref().unwrap().1, "step {n} ({part:?}): the model is not what is shown");
        let mean = image.rgb.iter().zip(&want).map(|(a, b)| f64::from(a.abs_diff(*b))).sum::<f64>() / want.len() as f64;
        if rate.is_none() {
            assert!(image.rgb == want, "step {n}: unlimited shows the picture itself");
        } else {
            assert!(mean <= 4.0, "step {n} ({part:?}): {mean} a channel from the picture at {size:?}");
        }
        if n + 1 == rates.len() as u32 {
            assert!(matches!(part, Part::Changed(..)), "{part:?}");
        }
    }
}

#[test]
fn a_picture_bigger_than_the_bucket_ever_holds_goes_when_the_caller_can_overdraw() {
    // kitty without frame edits: no tiles. Its smallest whole picture is more than 500 bytes.
    let layout = layout(GraphicsMode::Kitty, (160, 48), Some((8, 16)), None, SCALED_CAP);
    let protocol = Protocol::Kitty(KittyOptions { origin: layout.origin, ..KittyOptions::new(layout.cells) });
    let mut stream = PictureStream::new(protocol, layout);
    let picture = moving(0);
    let t0 = Instant::now();
    let tight = Budget::new(500, Some(5_000.0), FRAME);
    for n in 0..10u32 {
        assert!(stream.prepare(&picture, tight, t0 + FRAME * n).is_none(), "nothing fits 500 bytes");
    }
    let offer = stream.prepare(&picture, Budget { overdraw: true, ..tight }, t0 + FRAME * 10);
    let offer = offer.expect("the smallest whole picture goes when the caller can overdraw");
    assert!(offer.bytes.len() > 500 && offer.state.part == Part::Whole);
}

#[test]
fn sixel_tiles_and_blocks_end_where_their_cells_end() {
    // mlterm 3.9 fills the rest of a row of cells a sixel image reaches into with its
    // background: tiles of whole bands (24 rows on 22-pixel cells) left white holes across the
    // picture over a shaped link. Every part starts at a cell and ends at one or at the bottom.
    let cell = (10u16, 22u16);
    let l = layout(GraphicsMode::Sixel, (140, 45), Some(cell), Some((4096, 4096)), SCALED_CAP);
    let protocol =
        Protocol::Sixel { palette: SixelPalette::for_registers(256), registers: Registers::PerImage, tmux: false };
    let mut stream = PictureStream::new(protocol, l);
    let (pw, ph) = l.picture;
    let t0 = Instant::now();
    let mut bucket = ByteBucket::new(30_000.0);
    let mut parts = 0;
    for n in 1..=90u32 {
        let now = t0 + FRAME * n;
        bucket.refill(now);
        let budget = Budget::new(bucket.budget(), Some(30_000.0), FRAME);
        let Some(offer) = stream.prepare(&moving(n), budget, now) else { continue };
        bucket.spend(offer.bytes.len());
        if let Part::Changed(x, y, w, h) | Part::Tile(x, y, w, h) = offer.state.part {
            parts += 1;
            let (cw, ch) = (u32::from(cell.0), u32::from(cell.1));
            assert!(x % cw == 0 && y % ch == 0, "({x}, {y}) is not a cell's corner");
            assert!((y + h) % ch == 0 || y + h == ph, "{w}x{h} at ({x}, {y}) ends inside a row of cells");
            assert!(x + w <= pw && y + h <= ph);
        }
        stream.commit();
    }
    assert!(parts > 0, "30 kB/s sends tiles of the 1400x966 picture");
}

/// FNV-1a, 64 bits: a stable hash of bytes (std's hashers may change between releases).
fn fnv1a(hash: u64, bytes: &[u8]) -> u64 {
    bytes.iter().fold(hash, |h, &b| (h ^ u64::from(b)).wrapping_mul(0x100_0000_01b3))
}

#[test]
fn sixel_streams_write_the_same_bytes_as_before() {
    // The encoder's speed-ups (the enlargement fused with the dither, the bands' colour passes)
    // must not change a byte: a hash of every offer over moving water at every rate class
    // (the screen-size rung, the lower rungs and their tiles, changed blocks), taken from the
    // encoder before them (4099f6b). A change meant to alter the picture updates it after
    // looking at the picture (docs/pixels/cpu.md, "Round 3").
    let t0 = Instant::now();
    let mut hash = 0xcbf2_9ce4_8422_2325u64;
    for (rate, frames) in [(None, 6u32), (Some(2e6), 12), (Some(250e3), 12)] {
        let mut stream = sixel_stream();
        let mut bucket = rate.map_or_else(ByteBucket::unlimited, ByteBucket::new);
        for n in 1..=frames {
            let now = t0 + FRAME * (4 * n);
            bucket.refill(now);
            let budget = Budget::new(bucket.budget(), rate, FRAME);
            // Moving water, then a still picture with a small changed block.
            let mut picture = moving(n.min(frames - 2));
            if n == frames {
                for px in picture.pixels_mut()[100 * 640 + 200..100 * 640 + 260].iter_mut() {
                    *px = tiny_skia::ColorU8::from_rgba(250, 240, 10, 255).premultiply();
                }
            }
            let Some(offer) = stream.prepare(&picture, budget, now) else { continue };
            hash = fnv1a(hash, format!("{:?}", offer.state.part).as_bytes());
            hash = fnv1a(hash, offer.bytes);
            bucket.spend(offer.bytes.len());
            stream.commit();
        }
    }
    assert_eq!(hash, 10844920514458207448, "the sixel bytes changed");
}

/// Plays `moving` frames of moving water and then `still` frames of the last one through
/// `stream` with a bucket of `rate` bytes a second (no overdraw), committing every offer and
/// feeding kitty's to a decoder. Checks every offer against the bytes available and the
/// decoded image against the stream's model of what is shown. Returns the frame (counted from
/// the first still one) from which the decoded image is the exact source at the top rung and
/// stays so with nothing sent (`None`: never), and the bytes sent.
fn still_after_moving(
    stream: &mut PictureStream,
    rate: f64,
    (moving_frames, still): (u32, u32),
    moving: &dyn Fn(u32) -> Pixmap,
) -> (Option<u32>, usize) {
    let t0 = Instant::now();
    let mut bucket = ByteBucket::new(rate);
    bucket.refill(t0);
    let mut terminal = kitty_decode::KittyState::default();
    let kitty = matches!(stream.protocol, Protocol::Kitty(_));
    let last = moving(moving_frames);
    let (mut exact, size) = (Vec::new(), (last.width(), last.height()));
    Resampler::default().resample(last.data(), 4, size, size, &mut exact);
    let (mut converged, mut total) = (None, 0);
    for n in 1..=moving_frames + still {
        let now = t0 + FRAME * n;
        bucket.refill(now);
        let budget = Budget::new(bucket.budget(), Some(rate), FRAME);
        let picture = if n <= moving_frames { moving(n) } else { last.clone() };
        let offer = stream.prepare(&picture, budget, now).map(|o| o.bytes.to_vec());
        if let Some(bytes) = &offer {
            assert!(
                bytes.len() <= budget.available,
                "frame {n}: {} bytes, {} available",
                bytes.len(),
                budget.available
            );
            bucket.spend(bytes.len());
            total += bytes.len();
            stream.commit();
            if kitty {
                terminal.feed(bytes).expect("the stream decodes");
                let image = &terminal.images[&kitty::IMAGE_ID];
                let (rung, shown) = stream.shown.as_ref().expect("shown after a commit");
                assert_eq!((image.width, image.height), stream.rungs[*rung], "frame {n}");
                assert!(&image.rgb == shown, "frame {n}: the terminal shows what the stream believes");
            }
        }
        if n > moving_frames {
            let at_top = stream.shown.as_ref().is_some_and(|(r, s)| *r == 0 && *s == exact);
            match (at_top && offer.is_none(), converged) {
                (true, None) => converged = Some(n - moving_frames),
                (false, Some(_)) => panic!("frame {n}: sent {:?} bytes after converging", offer.map(|b| b.len())),
                _ => {}
            }
        }
    }
    (converged, total)
}

#[test]
fn the_block_codec_never_exceeds_its_budget_and_still_water_converges_to_the_exact_picture() {
    // kitty with frame edits at 50 and 250 kB/s: lossy pictures while the water moves, then
    // the worst blocks made exact, the climb to the top rung, and nothing once it is exact.
    for rate in [50e3, 250e3] {
        let mut stream = kitty_stream();
        let (converged, bytes) = still_after_moving(&mut stream, rate, (45, 1200), &moving);
        let frames = converged.unwrap_or_else(|| panic!("{rate} B/s: still water never became exact"));
        let seconds = f64::from(45 + frames) / 30.0;
        assert!(bytes as f64 <= rate * seconds * 1.05 + rate / 10.0, "{rate} B/s: {bytes} bytes in {seconds} s");
    }
}

/// The golden pool shifted `k` pixels at 120x72: a 40x13 terminal's picture.
fn small_moving(k: u32) -> Pixmap {
    let (mut rgb, size) = (Vec::new(), (120, 72));
    Resampler::default().resample(moving(k).data(), 4, (640, 360), size, &mut rgb);
    let mut p = Pixmap::new(size.0, size.1).unwrap();
    for (px, c) in p.pixels_mut().iter_mut().zip(rgb.chunks_exact(3)) {
        *px = tiny_skia::ColorU8::from_rgba(c[0], c[1], c[2], 255).premultiply();
    }
    p
}

#[test]
fn on_a_link_of_a_few_hundred_bytes_a_frame_still_water_still_becomes_exact() {
    // 5 kB/s: 167 bytes a frame, at most 425 a picture, where one 16x16 block's exact edit
    // alone is about a kilobyte: the blocks are halved until they fit. Every offer within the
    // bucket, the decoded image the model, the exact source at the top rung, then nothing.
    let l = layout(GraphicsMode::Kitty, (40, 13), Some((8, 16)), None, SCALED_CAP);
    let mut stream =
        PictureStream::new(Protocol::Kitty(KittyOptions { frame_edits: true, ..KittyOptions::new(l.cells) }), l);
    let rate = 5e3;
    let (converged, bytes) = still_after_moving(&mut stream, rate, (30, 3000), &small_moving);
    let frames = converged.unwrap_or_else(|| panic!("{rate} B/s: still water never became exact"));
    assert_eq!(stream.rungs[0], (120, 72));
    let seconds = f64::from(30 + frames) / 30.0;
    assert!(bytes as f64 <= rate * seconds * 1.05 + 500.0, "{rate} B/s: {bytes} bytes in {seconds} s");
}

#[test]
fn nothing_changes_nothing_is_sent() {
    // Unlimited: the second identical picture sends nothing (every picture is exact).
    let t0 = Instant::now();
    for mut stream in [kitty_stream(), iterm2_stream()] {
        let picture = moving(3);
        assert!(stream.prepare(&picture, Budget::unlimited(FRAME), t0).is_some());
        stream.commit();
        for n in 1..30u32 {
            assert!(stream.prepare(&picture, Budget::unlimited(FRAME), t0 + FRAME * n).is_none(), "frame {n}");
        }
    }
    // Under a rate: iTerm2 (no partial update) sends its exact picture once the bucket holds
    // it (here: the caller overdraws), and nothing after.
    let mut stream = iterm2_stream();
    let picture = moving(3);
    let mut sent = Vec::new();
    for n in 0..60u32 {
        let budget = Budget { overdraw: true, ..Budget::new(200_000, Some(2e6), FRAME) };
        if let Some(offer) = stream.prepare(&picture, budget, t0 + FRAME * (2 * n)) {
            sent.push(offer.state.packing);
            stream.commit();
        }
    }
    assert_eq!(sent.len(), 2, "a JPEG, then the exact PNG, then nothing: {sent:?}");
    assert_eq!(sent[1], Some(Packing::Png));
    assert!(stream.shown_exact);
}

/// The golden pool with its rows from `STILL_ROWS` down shifted `k` pixels: water moving in
/// the lower part of the picture, the upper part still.
const STILL_ROWS: u32 = 150;

fn partly_moving(k: u32) -> Pixmap {
    let (still, moved) = (moving(0), moving(k));
    let mut p = still.clone();
    let at = (STILL_ROWS * still.width()) as usize;
    p.pixels_mut()[at..].copy_from_slice(&moved.pixels()[at..]);
    p
}

#[test]
fn a_still_region_beside_moving_water_becomes_exact_while_the_water_moves() {
    // kitty with frame edits under a rate, the lower part of the picture moving every frame
    // for 8 seconds: the upper part's rows (those wholly from still source rows, at the rung
    // shown) must become the exact source picture within a second and a half of the last
    // whole picture and stay so, while the moving part keeps going at 10 pictures a second or
    // more. Every offer within the bucket and decoded to the stream's model.
    for rate in [250e3, 2e6] {
        let mut stream = kitty_stream();
        let t0 = Instant::now();
        let mut bucket = ByteBucket::new(rate);
        bucket.refill(t0);
        let mut terminal = kitty_decode::KittyState::default();
        let (frames, mut pictures, mut last_whole, mut exact_since) = (240u32, 0u32, 0u32, None::<u32>);
        let mut moving_rows_seen = Vec::new();
        let mut truth = ((0, 0), Vec::new());
        for n in 1..=frames {
            let now = t0 + FRAME * n;
            bucket.refill(now);
            let budget = Budget::new(bucket.budget(), Some(rate), FRAME);
            let picture = partly_moving(n);
            let Some(offer) = stream.prepare(&picture, budget, now) else { continue };
            let (len, part) = (offer.bytes.len(), offer.state.part);
            assert!(len <= budget.available, "{rate} B/s, frame {n}: {len} bytes, {} available", budget.available);
            terminal.feed(offer.bytes).expect("the stream decodes");
            bucket.spend(len);
            stream.commit();
            pictures += 1;
            let image = &terminal.images[&kitty::IMAGE_ID];
            let (rung, shown) = stream.shown.as_ref().expect("shown after a commit");
            let size = stream.rungs[*rung];
            assert_eq!((image.width, image.height), size, "frame {n}");
            assert!(&image.rgb == shown, "{rate} B/s, frame {n}: the terminal shows what the stream believes");
            if part == Part::Whole {
                (last_whole, exact_since) = (n, None);
            }
            // The rows at the rung wholly from still source rows (the resampler's support
            // reaches a row either side), and what they are exactly.
            // They are the same in every frame at one rung, so they are resampled once a rung.
            if truth.0 != size {
                Resampler::default().resample(picture.data(), 4, (640, 360), size, &mut truth.1);
                truth.0 = size;
            }
            let truth = &truth.1;
            let stride = size.0 as usize * 3;
            let still_rows = (STILL_ROWS * size.1 / 360).saturating_sub(2) as usize;
            assert!(still_rows > 10, "{size:?}");
            let exact = image.rgb[..still_rows * stride] == truth[..still_rows * stride];
            match (exact, exact_since) {
                (true, None) => exact_since = Some(n),
                (false, Some(since)) => panic!("{rate} B/s, frame {n}: the still rows were exact from frame {since}"),
                _ => {}
            }
            moving_rows_seen.push(image.rgb[(size.1 as usize - 1) * stride..].to_vec());
        }
        let seconds = f64::from(frames) / 30.0;
        assert!(f64::from(pictures) / seconds >= 10.0, "{rate} B/s: {pictures} pictures in {seconds} s");
        let since = exact_since.unwrap_or_else(|| panic!("{rate} B/s: the still rows never became exact"));
        assert!(
            since - last_whole <= 45,
            "{rate} B/s: exact {} frames after the last whole picture",
            since - last_whole
        );
        let tail = &moving_rows_seen[moving_rows_seen.len() - 10..];
        assert!(tail.windows(2).all(|w| w[0] != w[1]), "{rate} B/s: the moving part kept changing");
        eprintln!("{rate} B/s: {pictures} pictures, last whole at frame {last_whole}, still rows exact from {since}");
    }
}
