//! The picture through the Screen: made-up time, a scripted terminal, a simulated link.

use std::collections::VecDeque;
use std::time::Duration;

use super::*;
use crate::output::color::ColorMode;
use crate::output::diff::EncodeOptions;
use crate::output::graphics::kitty_decode;
use crate::output::graphics::stream::Part;
use crate::output::graphics::stream::ladder::resample;
use crate::output::graphics::test_pictures::golden_pool;
use crate::play::host::SceneStatus;
use crate::play::screen::probe::{EnvHints, GraphicsRequest, ProbeOptions, WinSize};
use crate::play::screen::{Bandwidth, Screen, ScreenConfig, link};
use crate::play::seat::SeatView;

const MS: Duration = Duration::from_millis(1);
const FRAME: Duration = Duration::from_nanos(1_000_000_000 / 30);
/// kitty's answers: the graphics query and the frame-edit test OK, then DA1.
const KITTY: &[u8] = b"\x1b_Gi=31;OK\x1b\\\x1b_Gi=7627890;OK\x1b\\\x1b[?62;22c";
/// xterm -ti vt340's: 256 registers, DA1 with sixel.
const SIXEL: &[u8] = b"\x1b[?1;0;256S\x1b[?2;0;4096;4096S\x1b[?62;4;22c";
/// iTerm2's: its cell size report, then DA1.
const ITERM2: &[u8] = b"\x1b]1337;ReportCellSize=16.0;8.0\x1b\\\x1b[?62;22c";

fn choice(mode: GraphicsMode) -> GraphicsChoice {
    GraphicsChoice { mode, tmux_wrap: false, kitty_placeholders: false, hint: None }
}

/// A 160x48 terminal of 8x16-pixel cells over SSH.
fn config(bandwidth: Bandwidth, graphics: GraphicsRequest) -> ScreenConfig {
    ScreenConfig {
        fps: 30,
        bandwidth,
        color: ColorMode::TrueColor,
        color_auto: false,
        colour_hint: false,
        encode: EncodeOptions::default(),
        graphics,
        probe: Some(ProbeOptions {
            env: EnvHints { ssh: true, ..EnvHints::default() },
            winsize: WinSize { cols: 160, rows: 48, x_px: 1280, y_px: 768 },
            kitty_file: None,
            colours: false,
        }),
        link_path: Default::default(),
    }
}

/// A screen that asked the terminal and got `answer` at once.
fn screen(config: ScreenConfig, answer: &[u8], t0: Instant) -> Screen {
    let mut screen = Screen::new(config, (160, 48), t0);
    screen.start(t0, &mut Vec::new());
    screen.feed(answer, t0 + MS, &mut Vec::new());
    assert!(!screen.probing());
    screen
}

/// Moving water: the pool's golden picture shifted `3k` pixels, at `size`.
struct Water {
    frames: Vec<Pixmap>,
}

impl Water {
    fn new(size: (u32, u32), count: u32) -> Water {
        let (w, h, rgb) = golden_pool();
        let frames = (0..count)
            .map(|k| {
                let shifted: Vec<u8> = (0..(w * h) as usize)
                    .flat_map(|i| {
                        let (x, y) = (i as u32 % w, i as u32 / w);
                        let at = ((y * w + (x + 3 * k) % w) * 3) as usize;
                        [rgb[at], rgb[at + 1], rgb[at + 2]]
                    })
                    .collect();
                let mut out = Vec::new();
                resample(&shifted, 3, (w, h), size, &mut out);
                let mut p = Pixmap::new(size.0, size.1).unwrap();
                for (px, c) in p.pixels_mut().iter_mut().zip(out.chunks_exact(3)) {
                    *px = tiny_skia::ColorU8::from_rgba(c[0], c[1], c[2], 255).premultiply();
                }
                p
            })
            .collect();
        Water { frames }
    }
}

fn status() -> SceneStatus {
    SceneStatus { name: "pool", takes_stones: true, ..SceneStatus::default() }
}

/// One frame at `now` of picture `n`; the bytes.
fn frame(screen: &mut Screen, water: &Water, n: usize, now: Instant) -> Vec<u8> {
    let mut out = Vec::new();
    let picture = &water.frames[n % water.frames.len()];
    assert_eq!((picture.width(), picture.height()), screen.picture_size());
    screen.frame(now, picture, &status(), &SeatView { stone: 3, ..SeatView::default() }, &mut out);
    out
}

fn count(hay: &[u8], needle: &[u8]) -> usize {
    hay.windows(needle.len()).filter(|w| *w == needle).count()
}

#[test]
fn cells_mode_has_no_picture() {
    assert!(Picture::new(&choice(GraphicsMode::Cells), &GraphicsSupport::default(), (80, 24), None).is_none());
}

#[test]
fn unlimited_kitty_sends_the_scenes_own_pixels_and_still_pictures_send_nothing() {
    let t0 = Instant::now();
    let mut s = screen(config(Bandwidth::Unlimited, GraphicsRequest::Auto), KITTY, t0);
    assert_eq!(s.mode(), GraphicsMode::Kitty);
    assert_eq!(s.picture_size(), (480, 282));
    let water = Water::new((480, 282), 1);
    let first = frame(&mut s, &water, 0, t0 + 10 * MS);
    let image = &kitty_decode::decode(&first).unwrap().images[&kitty::IMAGE_ID];
    assert_eq!((image.width, image.height), (480, 282), "the source's size: no interpolated pixels");
    assert!(image.rgb == crate::output::graphics::rgb(&water.frames[0]), "pixel for pixel");
    let again = frame(&mut s, &water, 0, t0 + 100 * MS);
    assert_eq!(count(&again, b"\x1b_G"), 0, "an unchanged picture sends nothing");
    let deleted = kitty_decode::decode(&restore_bytes(&choice(GraphicsMode::Kitty), false)).unwrap();
    assert!(deleted.images.is_empty() && deleted.commands[0][&'a'] == "d", "kitty's image is deleted on exit");
}

#[test]
fn sixel_pictures_cover_the_screen_pixels_without_an_upscaled_copy() {
    let t0 = Instant::now();
    let mut s = screen(config(Bandwidth::Unlimited, GraphicsRequest::Auto), SIXEL, t0);
    assert_eq!(s.mode(), GraphicsMode::Sixel);
    assert_eq!(s.picture_size(), (480, 281));
    let water = Water::new((480, 281), 1);
    let out = frame(&mut s, &water, 0, t0 + 10 * MS);
    assert_eq!(count(&out, b"\"1;1;1280;750"), 1, "one image, one pixel a screen pixel");
}

/// Plays `seconds` of moving water at 30 fps through a screen forced to `mode` under a fixed
/// `rate`; returns (whole-or-changed pictures, tiles, bytes after the first second, the most
/// any second carried, the seconds counted).
fn play_fixed(mode: GraphicsMode, answer: &[u8], rate: u64, seconds: u32) -> (u32, u32, u64, u64, f64) {
    let t0 = Instant::now();
    let mut s = screen(config(Bandwidth::Fixed(rate), GraphicsRequest::Force(mode)), answer, t0);
    assert_eq!(s.mode(), mode);
    let water = Water::new(s.picture_size(), 24);
    let (mut pictures, mut tiles, mut bytes) = (0, 0, 0u64);
    let mut window: VecDeque<(Instant, usize)> = VecDeque::new();
    let mut most = 0u64;
    let frames = 30 * seconds;
    for n in 1..=frames {
        let now = t0 + FRAME * n;
        let out = frame(&mut s, &water, n as usize, now);
        let after = s.picture.as_ref().unwrap().state();
        window.push_back((now, out.len()));
        while window.front().is_some_and(|(t, _)| now.duration_since(*t) >= Duration::from_secs(1)) {
            window.pop_front();
        }
        most = most.max(window.iter().map(|(_, b)| *b as u64).sum());
        if n > 30 {
            bytes += out.len() as u64;
            let offered = count(&out, b"\x1b_G") + count(&out, b"1337;File=") + count(&out, b"\x1bP") > 0;
            if offered {
                match after.part {
                    Part::Tile(..) => tiles += 1,
                    _ => pictures += 1,
                }
            }
        }
    }
    (pictures, tiles, bytes, most, f64::from(frames - 30) / 30.0)
}

#[test]
fn under_250_kb_a_second_kitty_and_iterm2_stay_within_it_at_10_pictures_a_second_or_more() {
    for (mode, answer) in [(GraphicsMode::Kitty, KITTY), (GraphicsMode::Iterm2, ITERM2)] {
        let (pictures, tiles, bytes, most, seconds) = play_fixed(mode, answer, 250_000, 5);
        let per_second = f64::from(pictures) / seconds;
        assert!(per_second >= 10.0, "{mode:?}: {pictures} pictures in {seconds} s");
        assert_eq!(tiles, 0, "{mode:?}: whole pictures fit");
        // The bucket holds at most 100 ms of the rate: no second carries more than 1.1 s of it.
        assert!(most <= 275_000, "{mode:?}: a second carried {most} bytes");
        let rate = bytes as f64 / seconds;
        assert!(rate >= 150_000.0, "{mode:?}: the link's rate is used, not left idle: {rate:.0} B/s");
    }
}

#[test]
fn under_250_kb_a_second_sixel_stays_within_it_and_refreshes_every_part() {
    let (pictures, tiles, bytes, most, seconds) = play_fixed(GraphicsMode::Sixel, SIXEL, 250_000, 5);
    assert!(most <= 275_000, "a second carried {most} bytes");
    assert!(pictures + tiles >= 30, "{pictures} pictures and {tiles} tiles in {seconds} s ({bytes} bytes)");
}

#[test]
fn at_50_kb_a_second_every_pixel_mode_still_moves_within_the_budget() {
    for (mode, answer) in [(GraphicsMode::Kitty, KITTY), (GraphicsMode::Sixel, SIXEL), (GraphicsMode::Iterm2, ITERM2)] {
        let (pictures, tiles, _, most, seconds) = play_fixed(mode, answer, 50_000, 4);
        assert!(most <= 55_000 + 256, "{mode:?}: a second carried {most} bytes");
        assert!(pictures + tiles >= 10, "{mode:?}: {pictures} pictures and {tiles} tiles in {seconds} s");
    }
}

/// A link whose rate changes over time, with a deep buffer (like SSH's) and a 30 ms round
/// trip: the terminal reads what the screen wrote as fast as the link carries it now, and
/// answers each device-attributes question once it has read it.
struct Link {
    /// Bytes written, and bytes the terminal has read.
    written: f64,
    read: f64,
    /// Where each unanswered question ends in the byte stream.
    questions: VecDeque<f64>,
    /// Answers on their way back.
    answers: VecDeque<Instant>,
}

impl Link {
    fn send(&mut self, out: &[u8]) {
        let mut at = self.written;
        for chunk in out.split_inclusive(|&b| b == b'c') {
            at += chunk.len() as f64;
            if chunk.ends_with(link::PROBE) {
                self.questions.push_back(at);
            }
        }
        self.written += out.len() as f64;
    }

    /// The link carries `rate` bytes a second for `dt` up to `now`; answers arrive.
    fn advance(&mut self, screen: &mut Screen, now: Instant, dt: Duration, rate: f64) {
        self.read = (self.read + rate * dt.as_secs_f64()).min(self.written);
        while self.questions.front().is_some_and(|&q| q <= self.read) {
            self.questions.pop_front();
            self.answers.push_back(now + 30 * MS);
        }
        while self.answers.front().is_some_and(|t| *t <= now) {
            let at = self.answers.pop_front().unwrap();
            screen.feed(b"\x1b[?62;22c", at, &mut Vec::new());
        }
    }
}

#[test]
fn auto_leaves_pixels_when_the_link_falls_below_the_crossover_and_comes_back_once() {
    let at = crossover(GraphicsMode::Kitty).unwrap();
    let t0 = Instant::now();
    let mut s = screen(config(Bandwidth::Auto, GraphicsRequest::Auto), KITTY, t0);
    assert_eq!(s.mode(), GraphicsMode::Kitty, "an unmeasured link starts with pixels");
    let _ = s.take_notice();
    let water = Water::new(s.picture_size(), 24);
    let cells_water = Water::new((160, 94), 24);
    let mut link = Link { written: 0.0, read: 0.0, questions: VecDeque::new(), answers: VecDeque::new() };
    // Fast for 15 s, slow for 25 s, fast again for 30 s.
    let rate = |secs: f64| if (15.0..40.0).contains(&secs) { at / 3.0 } else { at * 8.0 };
    let mut notices = Vec::new();
    let mut modes = Vec::new();
    for n in 1..=30 * 70u32 {
        let now = t0 + FRAME * n;
        let secs = (FRAME * n).as_secs_f64();
        link.advance(&mut s, now, FRAME, rate(secs));
        s.tick(now, &mut Vec::new());
        if let Some(notice) = s.take_notice() {
            notices.push((secs, notice));
        }
        // Over SSH a write never blocks (the channel and socket buffers take megabytes): only
        // the terminal's answers tell the screen about the queue.
        if s.ready(now, false) {
            let picture = if s.mode() == GraphicsMode::Cells { &cells_water } else { &water };
            if s.mode() == GraphicsMode::Cells {
                assert_eq!(s.picture_size(), (160, 94));
            }
            let out = frame(&mut s, picture, n as usize, now);
            link.send(&out);
        }
        if modes.last() != Some(&s.mode()) {
            modes.push(s.mode());
        }
    }
    assert_eq!(
        modes,
        [GraphicsMode::Kitty, GraphicsMode::Cells, GraphicsMode::Kitty],
        "one switch each way, no flapping: {notices:?}"
    );
    let switches: Vec<_> = notices.iter().filter(|(_, n)| n.starts_with("link ")).collect();
    assert_eq!(switches.len(), 2, "each switch said on the status line: {notices:?}");
    // Down once the link control has found the slow rate and it held (the queue the fast
    // pictures left in the link's buffers drains first); up once the rate held again.
    assert!(switches[0].1.contains("half-block cells") && (15.0..35.0).contains(&switches[0].0), "{switches:?}");
    assert!(
        switches[1].1.contains("pixels again; kitty graphics") && (40.0..55.0).contains(&switches[1].0),
        "{switches:?}"
    );
}

#[test]
fn a_fixed_rate_below_the_crossover_starts_with_cells_and_says_why() {
    let t0 = Instant::now();
    let at = crossover(GraphicsMode::Kitty).unwrap();
    let slow = screen(config(Bandwidth::Fixed((at / 4.0) as u64), GraphicsRequest::Auto), KITTY, t0);
    let mut slow = slow;
    assert_eq!(slow.mode(), GraphicsMode::Cells);
    let notice = slow.take_notice().unwrap();
    assert!(notice.contains("half-block cells (truer than kitty below"), "{notice}");
    let mut fast = screen(config(Bandwidth::Fixed((at * 4.0) as u64), GraphicsRequest::Auto), KITTY, t0);
    assert_eq!(fast.mode(), GraphicsMode::Kitty);
    assert!(fast.take_notice().unwrap().starts_with("kitty graphics"));
    // A forced mode is kept whatever the rate.
    let forced =
        screen(config(Bandwidth::Fixed((at / 4.0) as u64), GraphicsRequest::Force(GraphicsMode::Kitty)), KITTY, t0);
    assert_eq!(forced.mode(), GraphicsMode::Kitty);
}

/// kitty's answers without frame edits (refused or not answered: the same to the probe).
const KITTY_NO_EDITS: &[u8] = b"\x1b_Gi=31;OK\x1b\\\x1b[?62;22c";

#[test]
fn kitty_without_frame_edits_gets_whole_pictures_over_a_fast_link_answering_late() {
    // A terminal 5 ms away over SSH: the first answers come back after the first frames, which
    // carried the status line only. Every picture must still go (it went blank: the window
    // stayed at the few bytes those frames took, and a whole picture never fit it).
    for delay in [MS / 10, MS, 5 * MS, 30 * MS] {
        for graphics in [GraphicsRequest::Auto, GraphicsRequest::Force(GraphicsMode::Kitty)] {
            let t0 = Instant::now();
            let mut s = screen(config(Bandwidth::Auto, graphics), KITTY_NO_EDITS, t0);
            assert_eq!(s.mode(), GraphicsMode::Kitty);
            let water = Water::new(s.picture_size(), 24);
            let mut answers: VecDeque<Instant> = VecDeque::new();
            let mut first = None;
            let mut pictures = 0;
            for n in 1..=30 * 3u32 {
                let now = t0 + FRAME * n;
                while answers.front().is_some_and(|t| *t <= now) {
                    s.feed(b"\x1b[?62;22c", answers.pop_front().unwrap(), &mut Vec::new());
                }
                s.tick(now, &mut Vec::new());
                if s.ready(now, false) && s.mode() == GraphicsMode::Kitty {
                    let out = frame(&mut s, &water, n as usize, now);
                    let whole = count(&out, b"a=T");
                    assert_eq!(count(&out, b"a=f"), 0, "no frame edits where the terminal has none");
                    if whole > 0 {
                        first.get_or_insert(n);
                    }
                    pictures += whole;
                    if out.ends_with(link::PROBE) {
                        answers.push_back(now + delay);
                    }
                }
            }
            let first = first.unwrap_or_else(|| panic!("{delay:?} {graphics:?}: no picture in 3 s"));
            assert!(first <= 15, "{delay:?} {graphics:?}: the first picture at frame {first}");
            assert!(pictures >= 30, "{delay:?} {graphics:?}: {pictures} pictures in 3 s");
        }
    }
}

#[test]
fn a_local_sixel_terminal_gets_whole_pictures_at_full_resolution_and_over_a_link_auto_draws_cells() {
    // xterm -ti vt340 on this machine: the pty paces the pictures, the link control does not
    // (measured in bytes it settled at a few hundred kB/s and drew the lowest rung).
    let t0 = Instant::now();
    let mut local = config(Bandwidth::Auto, GraphicsRequest::Auto);
    local.probe.as_mut().unwrap().env.ssh = false;
    let mut s = screen(local, SIXEL, t0);
    assert_eq!(s.mode(), GraphicsMode::Sixel);
    assert_eq!(s.rate(), None, "no rate: the terminal's own pace");
    let water = Water::new(s.picture_size(), 4);
    for n in 1..=4u32 {
        let out = frame(&mut s, &water, n as usize, t0 + FRAME * (2 * n));
        assert!(!out.ends_with(link::PROBE), "no link questions");
        let state = s.picture.as_ref().unwrap().state();
        // The top rung is the screen's size (the 480x281 scene enlarged smoothly: the
        // terminal does not scale sixel pixels).
        assert_eq!(state.size, (1280, 750), "the top rung, every frame");
    }
    // Over SSH, sixel never beats cells on a measured link: cells from the start, and why.
    let mut remote = screen(config(Bandwidth::Auto, GraphicsRequest::Auto), SIXEL, t0);
    assert_eq!(remote.mode(), GraphicsMode::Cells);
    let notice = remote.take_notice().unwrap();
    assert!(notice.contains("sixel over a link: half-block cells are truer"), "{notice}");
    // Asked for, sixel is drawn over the link too, at the link's rate.
    let forced = screen(config(Bandwidth::Auto, GraphicsRequest::Force(GraphicsMode::Sixel)), SIXEL, t0);
    assert_eq!(forced.mode(), GraphicsMode::Sixel);
    assert!(forced.rate().is_some());
}

#[test]
fn auto_draws_sixel_from_its_crossover_and_cells_below_it() {
    // The pictures bench's table: sixel is truer than cells only with its whole palette at the
    // screen's size (from its crossover); at 2 MB/s cells.
    let t0 = Instant::now();
    let at = crossover(GraphicsMode::Sixel).expect("sixel wins from a measured rate");
    let mut slow = screen(config(Bandwidth::Fixed(2_000_000), GraphicsRequest::Auto), SIXEL, t0);
    assert_eq!(slow.mode(), GraphicsMode::Cells);
    let notice = slow.take_notice().unwrap();
    assert!(notice.contains("half-block cells (truer than sixel below 32.00 MB/s)"), "{notice}");
    let mut fast = screen(config(Bandwidth::Fixed(at as u64), GraphicsRequest::Auto), SIXEL, t0);
    assert_eq!(fast.mode(), GraphicsMode::Sixel);
    let _ = fast.take_notice();
    // Whole screen-sized pictures there, as without a limit.
    let water = Water::new(fast.picture_size(), 4);
    let images: usize =
        (1..=4u32).map(|n| count(&frame(&mut fast, &water, n as usize, t0 + FRAME * (2 * n)), b"\x1bP")).sum();
    assert!(images >= 2, "{images} sixel images in four frames");
    assert_eq!(fast.picture.as_ref().unwrap().state().size, (1280, 750), "the top rung");
}
