use std::time::{Duration, Instant};

use tiny_skia::{ColorU8, Pixmap};

use super::*;
use crate::output::bucket::ByteBucket;
use crate::output::diff;
use crate::output::oklab;
use crate::output::vt::TerminalModel;

fn picture(cols: u32, rows: u32, f: impl Fn(u32, u32) -> [u8; 3]) -> Pixmap {
    let mut p = Pixmap::new(cols, 2 * rows).unwrap();
    for y in 0..2 * rows {
        for x in 0..cols {
            let [r, g, b] = f(x, y);
            p.pixels_mut()[(y * cols + x) as usize] = ColorU8::from_rgba(r, g, b, 255).premultiply();
        }
    }
    p
}

fn frame_of(p: &Pixmap, mode: ColorMode) -> Frame {
    let mut f = Frame::new(p.width() as usize, p.height() as usize / 2);
    f.draw_pixels(p, mode);
    f
}

/// A terminal model of exactly the frame's size (no spare row), in raw mode.
fn terminal(cols: usize, rows: usize) -> TerminalModel {
    let mut s = TerminalModel::new(cols, rows);
    s.lf_returns = false;
    s
}

/// The terminal shows exactly what the model claims: every pixel of a pixel cell, and a text
/// cell's glyph, background and (unless it is a space) foreground.
fn assert_screen_matches(screen: &TerminalModel, model: &Frame) {
    for y in 0..model.rows() {
        for x in 0..model.cols() {
            match model.get(x, y) {
                Cell::Pixels { top, bottom } => {
                    assert_eq!(screen.pixel(x, 2 * y), top.rgb(), "top of ({x}, {y})");
                    assert_eq!(screen.pixel(x, 2 * y + 1), bottom.rgb(), "bottom of ({x}, {y})");
                }
                Cell::Text { ch, fg, bg } => {
                    let c = screen.cell(x, y);
                    assert_eq!((c.ch, c.bg), (ch, bg.rgb()), "text at ({x}, {y})");
                    if ch != ' ' {
                        assert_eq!(c.fg, fg.rgb(), "foreground of {ch:?} at ({x}, {y})");
                    }
                }
            }
        }
    }
}

/// Moving blobs over a gradient with a status line: every glyph choice and text.
fn busy_frame(cols: u32, rows: u32, t: u32, mode: ColorMode) -> (Frame, Pixmap) {
    let p = picture(cols, rows, |x, y| {
        let d = (x as i32 - 3 * t as i32 - 4).pow(2) + (y as i32 - 2 * t as i32).pow(2);
        if d < 20 {
            [200, 40, (t * 30) as u8]
        } else if y > 12 {
            [9, 9, 9]
        } else {
            [(x * 11 + t) as u8, (y * 13) as u8, 90]
        }
    });
    let mut frame = frame_of(&p, mode);
    frame.text(2, rows as usize - 1, &format!("t={t}"), Color::Index(15), Color::Index(4));
    (frame, p)
}

fn exact(cols: usize, rows: usize) -> RateOptions {
    let _ = (cols, rows);
    RateOptions::default()
}

#[test]
fn unlimited_is_byte_identical_to_the_diff_encoder() {
    for mode in [ColorMode::TrueColor, ColorMode::Palette256, ColorMode::Palette16] {
        for sync in [true, false] {
            let (mut old, mut new) = (Shown::UNKNOWN, Shown::UNKNOWN);
            let mut encoder = RateEncoder::new();
            for t in 0..8 {
                let (frame, p) = busy_frame(23, 9, t, mode);
                let mut a = Vec::new();
                diff::encode_into(&mut old, &frame, EncodeOptions { threshold: 0, sync }, &mut a);
                let mut b = Vec::new();
                let options = RateOptions { sync, ..RateOptions::default() };
                encoder.encode_into(&mut new, Target::with_truth(&frame, &p, mode), UNLIMITED, options, &mut b);
                assert_eq!(String::from_utf8_lossy(&a), String::from_utf8_lossy(&b), "{mode:?} frame {t}");
                assert_eq!(old, new);
            }
        }
    }
}

#[test]
fn a_single_cell_goes_without_the_sync_markers() {
    let (a, _) = busy_frame(12, 5, 1, ColorMode::TrueColor);
    let mut b = a.clone();
    b.set(7, 2, Cell::Pixels { top: Color::Rgb([1, 2, 3]), bottom: Color::Rgb([4, 5, 6]) });
    let (_, old) = diff::encode(&Shown::UNKNOWN, &a, EncodeOptions::default());
    let (today, _) = diff::encode(&old, &b, EncodeOptions::default());
    let (bytes, next) = encode(&old, Target::new(&b), UNLIMITED, RateOptions::default());
    assert_eq!(bytes.len() + SYNC_BEGIN.len() + SYNC_END.len(), today.len());
    assert_eq!(&today[SYNC_BEGIN.len()..today.len() - SYNC_END.len()], &bytes[..]);
    assert_eq!(next.frame.as_ref(), Some(&b));
}

#[test]
fn the_terminal_shows_what_the_model_claims_under_any_budget() {
    for mode in [ColorMode::TrueColor, ColorMode::Palette256, ColorMode::Palette16] {
        for budget in [40, 90, 300, 1500, UNLIMITED] {
            let (cols, rows) = (23, 9);
            let mut screen = terminal(cols, rows);
            let mut shown = Shown::UNKNOWN;
            let mut encoder = RateEncoder::new();
            for t in 0..12 {
                let (frame, p) = busy_frame(cols as u32, rows as u32, t.min(6), mode);
                let mut bytes = Vec::new();
                let report = encoder.encode_into(
                    &mut shown,
                    Target::with_truth(&frame, &p, mode),
                    budget,
                    exact(cols, rows),
                    &mut bytes,
                );
                assert!(bytes.len() <= budget, "{} bytes over the budget of {budget}", bytes.len());
                assert_eq!(report.bytes, bytes.len());
                screen.feed(&bytes);
                if let Some(model) = &shown.frame {
                    assert_screen_matches(&screen, model);
                }
                if !bytes.is_empty() {
                    assert_eq!(screen.private_mode(2026), Some(false), "sync closed");
                }
            }
        }
    }
}

#[test]
fn a_text_cell_foreground_is_checked() {
    // Same glyph and background, another foreground: the cell must be redrawn.
    let mut a = Frame::new(4, 1);
    a.text(0, 0, "ab", Color::Index(1), Color::Index(4));
    let mut b = a.clone();
    b.text(1, 0, "b", Color::Index(2), Color::Index(4));
    let mut screen = terminal(4, 1);
    let mut shown = Shown::UNKNOWN;
    for frame in [&a, &b] {
        let (bytes, next) = encode(&shown, Target::new(frame), 200, RateOptions::default());
        screen.feed(&bytes);
        shown = next;
        assert_screen_matches(&screen, frame);
    }
}

/// A grey field with cells changed by the given amounts of grey.
fn field_with_changes(changes: &[(usize, u8)]) -> (Frame, Frame) {
    let mut before = Frame::new(40, 6);
    for y in 0..6 {
        for x in 0..40 {
            before.set(x, y, Cell::Pixels { top: Color::Rgb([100; 3]), bottom: Color::Rgb([100; 3]) });
        }
    }
    let mut after = before.clone();
    for &(i, delta) in changes {
        let c = Color::Rgb([100 + delta; 3]);
        after.set(i % 40, i / 40, Cell::Pixels { top: c, bottom: Color::Rgb([100; 3]) });
    }
    (before, after)
}

#[test]
fn the_largest_errors_go_first() {
    // Every change noticeable, of many sizes, scattered; the three largest late in screen
    // order, in cells of their own colours (so each costs about the same).
    let mut changes: Vec<(usize, u8)> = (0..40).map(|i| (i * 5 + 1, 20 + (i % 7) as u8 * 5)).collect();
    changes.extend([(212, 150), (225, 140), (238, 130)]);
    let (before, after) = field_with_changes(&changes);
    let options = RateOptions { sync: false, ..RateOptions::default() };
    let (_, shown) = encode(&Shown::UNKNOWN, Target::new(&before), UNLIMITED, options);
    // Enough for about three cells of the forty-three.
    let (bytes, next) = encode(&shown, Target::new(&after), 90, options);
    assert!(bytes.len() <= 90);
    let model = next.frame.as_ref().unwrap();
    // Drawn exactly or approximately: touched.
    let touched: Vec<u8> = changes
        .iter()
        .filter(|(i, _)| model.get(i % 40, i / 40) != before.get(i % 40, i / 40))
        .map(|&(_, d)| d)
        .collect();
    assert_eq!(touched, [150, 140, 130], "the three largest changes only: {:?}", String::from_utf8_lossy(&bytes));
    // The naive order sends the early ones instead.
    let naive = RateOptions { strategy: Strategy::ScanOrder, ..options };
    let (_, scan) = encode(&shown, Target::new(&after), 90, naive);
    assert_ne!(scan.frame.as_ref().unwrap().get(212 % 40, 212 / 40), after.get(212 % 40, 212 / 40));
}

/// The largest grey step from 100 that stays below `fraction` of the JND (or the smallest at
/// or above it, when `above`).
fn grey_step(fraction: f32, above: bool) -> u8 {
    let grey = oklab::from_rgb([100; 3]);
    let distance = |d: u8| grey.distance(oklab::from_rgb([100 + d; 3]));
    if above {
        (1..100).find(|&d| distance(d) >= fraction * JND).unwrap()
    } else {
        (1..100).take_while(|&d| distance(d) < fraction * JND).last().unwrap()
    }
}

#[test]
fn changes_below_the_jnd_wait_while_larger_ones_are_pending() {
    // A run of thirty cells whose both halves changed just below the JND: cheap (after the
    // first, each is a space in the colour already in effect) and together worth more per
    // byte than one isolated cell whose upper half changed just above it.
    let (small, big) = (grey_step(0.95, false), grey_step(1.05, true));
    let (mut before, _) = field_with_changes(&[]);
    before.set(20, 5, Cell::Pixels { top: Color::Rgb([100; 3]), bottom: Color::Rgb([7, 50, 200]) });
    let mut after = before.clone();
    for x in 0..30 {
        after.set(x, 0, Cell::Pixels { top: Color::Rgb([100 + small; 3]), bottom: Color::Rgb([100 + small; 3]) });
    }
    after.set(20, 5, Cell::Pixels { top: Color::Rgb([100 + big; 3]), bottom: Color::Rgb([7, 50, 200]) });
    let options = RateOptions { sync: false, ..RateOptions::default() };
    let (_, shown) = encode(&Shown::UNKNOWN, Target::new(&before), UNLIMITED, options);
    // A budget for the noticeable cell, or for most of the run.
    let (bytes, next) = encode(&shown, Target::new(&after), 40, options);
    let model = next.frame.as_ref().unwrap();
    assert!(!bytes.is_empty());
    assert_eq!(model.get(20, 5), after.get(20, 5), "{:?}", String::from_utf8_lossy(&bytes));
    assert!((0..30).all(|x| model.get(x, 0) == before.get(x, 0)), "no change below the JND went before it");
    // Once it is sent, the run follows.
    let (_, next) = encode(&next, Target::new(&after), 200, options);
    assert!((0..30).all(|x| next.frame.as_ref().unwrap().get(x, 0) == after.get(x, 0)));
}

/// Whether two frames look the same (a space's foreground does not matter).
fn same_picture(a: &Frame, b: &Frame) -> bool {
    (a.cols(), a.rows()) == (b.cols(), b.rows()) && a.cells().iter().zip(b.cells()).all(|(x, y)| x.close_to(y, 0))
}

/// Frames until the screen is exact once the input stops changing, and the bytes of drawing
/// every cell of the still frame on its own, at `rate` bytes a frame
/// carried over in a bucket (as [`ByteBucket`] does, at least [`crate::output::bucket::MIN_CAPACITY`]).
fn frames_to_converge(mode: ColorMode, rate: usize, approximate: bool) -> (usize, usize) {
    let (cols, rows) = (30, 10);
    let mut screen = terminal(cols, rows);
    let mut shown = Shown::UNKNOWN;
    let mut encoder = RateEncoder::new();
    let options = RateOptions { approximate, ..RateOptions::default() };
    let capacity = (3 * rate).max(crate::output::bucket::MIN_CAPACITY as usize);
    let mut level = 0;
    let mut frame = |shown: &mut Shown, target: Target<'_>, screen: &mut TerminalModel| {
        level = (level + rate).min(capacity);
        let mut bytes = Vec::new();
        let report = encoder.encode_into(shown, target, level, options, &mut bytes);
        assert!(bytes.len() <= level);
        level -= bytes.len();
        screen.feed(&bytes);
        report
    };
    // Some frames of motion first, so the screen is a patchwork of approximations.
    for t in 0..10 {
        let (moving, p) = busy_frame(cols as u32, rows as u32, t, mode);
        frame(&mut shown, Target::with_truth(&moving, &p, mode), &mut screen);
    }
    let (still, p) = busy_frame(cols as u32, rows as u32, 10, mode);
    // Drawn one at a time, a cell costs at most an absolute move (8 bytes here), its colour
    // codes from a fresh pen and its glyph.
    let alone: usize = still.cells().iter().map(|&c| diff::best_draw(c, None, None).len(None, None) + 8).sum();
    for n in 1..=1000 {
        let report = frame(&mut shown, Target::with_truth(&still, &p, mode), &mut screen);
        if report.pending == 0 {
            assert!(same_picture(shown.frame.as_ref().unwrap(), &still));
            assert_screen_matches(&screen, &still);
            let (again, _) = encode(&shown, Target::with_truth(&still, &p, mode), UNLIMITED, options);
            assert!(again.is_empty(), "an exact screen costs nothing");
            return (n, alone);
        }
    }
    panic!("{mode:?} at {rate} bytes a frame did not converge in 1000 frames");
}

#[test]
fn a_still_picture_converges_to_the_exact_frame() {
    for mode in [ColorMode::TrueColor, ColorMode::Palette256, ColorMode::Palette16] {
        for rate in [40, 100, 400, 1500] {
            for approximate in [true, false] {
                let (frames, alone) = frames_to_converge(mode, rate, approximate);
                // Once the picture is still, every cell is sent at most twice (flat, then
                // exact), each alone at worst, and each frame pays for its markers.
                let markers = SYNC_BEGIN.len() + SYNC_END.len();
                let bound = 2 * alone / (rate - markers) + 10;
                assert!(frames <= bound, "{mode:?} {rate} B/frame: {frames} frames, bound {bound}");
            }
        }
    }
}

#[test]
fn a_resize_invalidates_the_model() {
    let (a, _) = busy_frame(20, 6, 1, ColorMode::TrueColor);
    let (_, shown) = encode(&Shown::UNKNOWN, Target::new(&a), UNLIMITED, RateOptions::default());
    // A bigger terminal: what it shows is unknown, so a whole frame that fits is sent whole...
    let (b, _) = busy_frame(25, 8, 1, ColorMode::TrueColor);
    let (bytes, next) = encode(&shown, Target::new(&b), UNLIMITED, RateOptions::default());
    let (full, _) = diff::encode(&Shown::UNKNOWN, &b, EncodeOptions::default());
    assert_eq!(bytes, full);
    assert_eq!(next.frame.as_ref(), Some(&b));
    // ...and one that does not fit starts with a clear, after which the model is known.
    let mut screen = terminal(25, 8);
    screen.feed(b"garbage left by the resize");
    let (bytes, next) = encode(&shown, Target::new(&b), 300, RateOptions::default());
    assert!(bytes.len() <= 300);
    assert!(bytes.windows(CLEAR.len()).any(|w| w == CLEAR), "{:?}", String::from_utf8_lossy(&bytes));
    screen.feed(&bytes);
    let model = next.frame.as_ref().unwrap();
    assert_eq!((model.cols(), model.rows()), (25, 8));
    assert_screen_matches(&screen, model);
    // A budget too small even for the clear sends nothing and keeps the model unknown.
    let (bytes, next) = encode(&shown, Target::new(&b), 20, RateOptions::default());
    assert!(bytes.is_empty());
    assert_eq!(next.frame.as_ref().map(Frame::cols), Some(20), "still the old, wrong-sized model");
}

#[test]
fn a_bucket_at_100_kb_s_holds_over_150_frames() {
    let (cols, rows) = (48, 16);
    let start = Instant::now();
    let rate = 100_000.0;
    let mut bucket = ByteBucket::new(rate);
    bucket.refill(start);
    let mut encoder = RateEncoder::new();
    let mut shown = Shown::UNKNOWN;
    let mut screen = terminal(cols, rows);
    let (mut total, mut frames_sent) = (0usize, 0);
    let frame_time = Duration::from_nanos(1_000_000_000 / 30);
    for n in 1..=150u32 {
        let now = start + frame_time * n;
        bucket.refill(now);
        let budget = bucket.budget();
        // Busy, changing frames: more bytes than the rate, every frame.
        let p =
            picture(cols as u32, rows as u32, |x, y| [(x * 5 + n * 7) as u8, (y * 9 + n * 3) as u8, (x ^ y) as u8 * 4]);
        let frame = frame_of(&p, ColorMode::TrueColor);
        let mut bytes = Vec::new();
        encoder.encode_into(&mut shown, Target::new(&frame), budget, RateOptions::default(), &mut bytes);
        assert!(bytes.len() <= budget, "frame {n}: {} bytes over the bucket's {budget}", bytes.len());
        bucket.spend(bytes.len());
        total += bytes.len();
        frames_sent += usize::from(!bytes.is_empty());
        screen.feed(&bytes);
        assert_screen_matches(&screen, shown.frame.as_ref().unwrap());
    }
    let allowed = rate * (frame_time * 150).as_secs_f64();
    assert!(total as f64 <= allowed, "{total} bytes in 5 s at 100 kB/s");
    assert!(total as f64 >= 0.9 * allowed, "the budget is used: {total} of {allowed}");
    assert!(frames_sent >= 140, "{frames_sent} frames carried something");
}

#[test]
fn a_trickle_still_sends_a_cell_every_few_frames() {
    // 500 B/s at 30 fps is 17 bytes a frame: not even the synchronized-output markers and a
    // colour code.
    let start = Instant::now();
    let mut bucket = ByteBucket::new(500.0);
    bucket.refill(start);
    let (before, after) = field_with_changes(&(0..240).map(|i| (i, 40 + (i % 50) as u8)).collect::<Vec<_>>());
    let (_, mut shown) = encode(&Shown::UNKNOWN, Target::new(&before), UNLIMITED, RateOptions::default());
    let mut encoder = RateEncoder::new();
    let mut sent = Vec::new();
    for n in 1..=30u32 {
        bucket.refill(start + Duration::from_nanos(1_000_000_000 / 30) * n);
        let mut bytes = Vec::new();
        encoder.encode_into(&mut shown, Target::new(&after), bucket.budget(), RateOptions::default(), &mut bytes);
        bucket.spend(bytes.len());
        sent.push(bytes.len());
    }
    let longest_wait = sent.split(|&b| b > 0).skip(1).map(<[usize]>::len).max().unwrap_or(0);
    assert!(longest_wait <= 4, "a cell at least every five frames: {sent:?}");
    let total: usize = sent.iter().sum();
    assert!((350..=500).contains(&total), "a second's worth of the rate: {total} in {sent:?}");
}

#[test]
fn identical_frames_cost_nothing() {
    let (frame, _) = busy_frame(12, 5, 2, ColorMode::TrueColor);
    let (_, shown) = encode(&Shown::UNKNOWN, Target::new(&frame), UNLIMITED, RateOptions::default());
    for budget in [0, 10, 1000, UNLIMITED] {
        assert!(encode(&shown, Target::new(&frame), budget, RateOptions::default()).0.is_empty());
    }
}

mod properties {
    use super::super::Strategy as Order;
    use super::*;
    use crate::output::frame::strategies::frame;
    use proptest::prelude::{Just, ProptestConfig, Strategy, any, prop_assert, prop_oneof, proptest};

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(96))]

        /// Whatever the frames and budgets: no frame exceeds its budget, the terminal shows
        /// what the model claims, and once the frames stop changing the screen becomes exact.
        #[test]
        fn any_frames_any_budgets(
            (cols, rows, frames) in (1usize..14, 1usize..7).prop_flat_map(|(c, r)| {
                (Just(c), Just(r), proptest::collection::vec(frame(c, r), 1..5))
            }),
            budgets in proptest::collection::vec(prop_oneof![0usize..200, Just(UNLIMITED)], 5),
            sync in any::<bool>(),
            approximate in any::<bool>(),
            naive in any::<bool>(),
        ) {
            let strategy = if naive { Order::ScanOrder } else { Order::ErrorPerByte };
            let options = RateOptions { sync, approximate, strategy, ..RateOptions::default() };
            let mut screen = terminal(cols, rows);
            // Whatever the terminal showed before: the first frame must not rely on it.
            screen.feed("\x1b[38;5;1;48;5;2mgarbage\u{2580}".repeat(cols * rows).as_bytes());
            let mut shown = Shown::UNKNOWN;
            let mut encoder = RateEncoder::new();
            for (i, frame) in frames.iter().enumerate() {
                let budget = budgets[i % budgets.len()];
                let mut bytes = Vec::new();
                encoder.encode_into(&mut shown, Target::new(frame), budget, options, &mut bytes);
                prop_assert!(bytes.len() <= budget);
                screen.feed(&bytes);
                if let Some(model) = &shown.frame {
                    assert_screen_matches(&screen, model);
                }
            }
            let last = frames.last().unwrap();
            for _ in 0..(cols * rows * 2 + 4) {
                let mut bytes = Vec::new();
                let report = encoder.encode_into(&mut shown, Target::new(last), 120, options, &mut bytes);
                screen.feed(&bytes);
                if report.pending == 0 {
                    break;
                }
            }
            prop_assert!(shown.frame.as_ref().is_some_and(|f| same_picture(f, last)), "converged");
            assert_screen_matches(&screen, last);
        }
    }
}

/// Under a tight budget a cell's steps are bought cheapest first (a space in the nearest
/// palette colour of the cell's mean, then a space in the mean itself, then the exact cell):
/// when the second step is paid for, the cell is drawn with it, never with the cheaper
/// approximation it improves on.
#[test]
fn a_cell_is_drawn_with_the_best_approximation_paid_for() {
    // One cell of two close colours whose mean is far from the xterm palette, on a known
    // black screen.
    let (top, bottom) = ([120u8, 90, 60], [130u8, 100, 70]);
    let p = picture(1, 1, |_, y| if y == 0 { top } else { bottom });
    let wanted = frame_of(&p, ColorMode::TrueColor);
    let black = Cell::Pixels { top: Color::Rgb([0, 0, 0]), bottom: Color::Rgb([0, 0, 0]) };
    let mut blank = Frame::new(1, 1);
    blank.set(0, 0, black);
    let shown = Shown { frame: Some(blank), ..Shown::UNKNOWN };
    let mean = [125u8, 95, 65];
    let flat = Cell::Pixels { top: Color::Rgb(mean), bottom: Color::Rgb(mean) };
    let palette = Color::Index(crate::output::color::nearest_256(mean));
    let flat_palette = Cell::Pixels { top: palette, bottom: palette };
    let drawn = |budget: usize| {
        let (_, next) = encode(&shown, Target::new(&wanted), budget, RateOptions::default());
        next.frame.unwrap().get(0, 0)
    };
    let draws: Vec<(usize, Cell)> = (1..=60).map(|b| (b, drawn(b))).collect();
    // Every way is drawn at some budget, cheapest first, and once a better way fits the
    // cell is never drawn in a worse one.
    let first = |cell: Cell| draws.iter().find(|(_, c)| *c == cell).map(|&(b, _)| b);
    let (palette_at, flat_at, exact_at) = (first(flat_palette), first(flat), first(wanted.get(0, 0)));
    assert!(palette_at.is_some() && flat_at.is_some() && exact_at.is_some(), "{draws:?}");
    assert!(palette_at < flat_at && flat_at < exact_at, "{palette_at:?} {flat_at:?} {exact_at:?}");
    for &(budget, cell) in &draws[flat_at.unwrap() - 1..] {
        assert_ne!(cell, flat_palette, "at {budget} bytes the flat mean was paid for, the palette colour drawn");
    }
}
