use tiny_skia::Pixmap;

use super::*;
use crate::play::fit::Fit;
use crate::play::host::SceneStatus;
use crate::play::screen::probe::{EnvHints, WinSize};
use crate::play::seat::SeatView;

const MS: Duration = Duration::from_millis(1);
const KITTY_OK: &[u8] = b"\x1b_Gi=31;OK\x1b\\";
const DA1: &[u8] = b"\x1b[?62;22c";

fn config(bandwidth: Bandwidth, probe: bool) -> ScreenConfig {
    ScreenConfig {
        fps: 30,
        bandwidth,
        color: ColorMode::TrueColor,
        color_auto: false,
        colour_hint: false,
        encode: EncodeOptions::default(),
        graphics: GraphicsRequest::Auto,
        probe: probe.then(|| ProbeOptions {
            env: EnvHints { ssh: true, ..EnvHints::default() },
            winsize: WinSize { cols: 40, rows: 12, x_px: 320, y_px: 192 },
            kitty_file: None,
            colours: false,
        }),
        link_path: LinkPath::Direct,
    }
}

fn status() -> SceneStatus {
    SceneStatus { name: "pool", takes_stones: true, ..SceneStatus::default() }
}

/// A frame of a flat picture of the screen's size; the bytes appended.
fn frame(screen: &mut Screen, now: Instant, shade: u8) -> Vec<u8> {
    let (w, h) = screen.picture_size();
    let mut picture = Pixmap::new(w, h).unwrap();
    picture.fill(tiny_skia::Color::from_rgba8(shade, 90, 160, 255));
    let mut out = Vec::new();
    screen.frame(now, &picture, &status(), &SeatView { stone: 3, ..SeatView::default() }, &mut out);
    out
}

fn contains(hay: &[u8], needle: &[u8]) -> bool {
    hay.windows(needle.len()).any(|w| w == needle)
}

#[test]
fn a_screen_that_asks_nothing_draws_cells_and_sets_the_terminal_up_first() {
    let t0 = Instant::now();
    let mut screen = Screen::new(config(Bandwidth::Unlimited, false), (40, 12), t0);
    let mut asked = Vec::new();
    screen.start(t0, &mut asked);
    assert!(asked.is_empty() && !screen.probing());
    assert_eq!(screen.picture_size(), (40, 22));
    let first = frame(&mut screen, t0, 10);
    assert!(first.starts_with(Screen::ENTER));
    assert_eq!(screen.mode(), GraphicsMode::Cells);
    let again = frame(&mut screen, t0 + 40 * MS, 10);
    assert!(!contains(&again, Screen::ENTER), "set up once");
}

#[test]
fn a_picture_of_another_size_is_drawn_whole_in_the_cells_never_its_corner() {
    // `tidepool serve` in xterm (sixel), at `auto`'s switch to cells: the frame the switch was
    // decided in brought the pixels' picture (840x481), the cells took its top-left corner,
    // and the pool showed magnified four times over the screen for a frame
    // (docs/terminals/right-pictures.md, round 11). A picture twice the cells' size, its
    // top-left quarter blue and the rest red: the cells show both, as the picture is.
    let t0 = Instant::now();
    let mut screen = Screen::new(config(Bandwidth::Unlimited, false), (40, 12), t0);
    let mut asked = Vec::new();
    screen.start(t0, &mut asked);
    frame(&mut screen, t0, 10);
    let (w, h) = screen.picture_size();
    let mut big = Pixmap::new(2 * w, 2 * h).unwrap();
    big.fill(tiny_skia::Color::from_rgba8(200, 30, 30, 255));
    let quarter = tiny_skia::Rect::from_xywh(0.0, 0.0, w as f32, h as f32).unwrap();
    let mut blue = tiny_skia::Paint::default();
    blue.set_color_rgba8(30, 30, 200, 255);
    big.fill_rect(quarter, &blue, tiny_skia::Transform::identity(), None);
    let mut out = Vec::new();
    screen.frame(t0 + 40 * MS, &big, &status(), &SeatView { stone: 3, ..SeatView::default() }, &mut out);
    assert!(contains(&out, b"200;30;30"), "the cells show the picture's red three quarters");
    assert!(contains(&out, b"30;30;200"), "and its blue top-left quarter");
    let next = frame(&mut screen, t0 + 80 * MS, 60);
    assert!(contains(&next, b"60;90;160"), "the next picture, of the cells' size, is drawn as it is");
}

#[test]
fn the_probe_holds_the_first_frame_until_the_answer_and_keys_typed_meanwhile_come_after() {
    let t0 = Instant::now();
    let mut screen = Screen::new(config(Bandwidth::Unlimited, true), (40, 12), t0);
    let mut asked = Vec::new();
    screen.start(t0, &mut asked);
    assert!(asked.ends_with(b"\x1b[c") && screen.probing());
    assert!(!screen.ready(t0, true), "no frame while the terminal is asked");
    let mut inputs = Vec::new();
    let mut answer = b"q".to_vec();
    answer.extend_from_slice(KITTY_OK);
    answer.extend_from_slice(DA1);
    screen.feed(&answer, t0 + 20 * MS, &mut inputs);
    assert_eq!(inputs, vec![Input::Quit], "the key typed during the probe, once it is over");
    assert!(!screen.probing() && screen.mode() == GraphicsMode::Kitty);
    assert!(screen.take_layout_change());
    assert!(screen.take_notice().unwrap().starts_with("kitty graphics"));
    let first = frame(&mut screen, t0 + 20 * MS, 10);
    assert!(first.starts_with(Screen::ENTER) && contains(&first, b"\x1b_G"), "a kitty picture");
}

#[test]
fn a_late_answer_upgrades_cells_to_pixels() {
    let t0 = Instant::now();
    let mut screen = Screen::new(config(Bandwidth::Unlimited, true), (40, 12), t0);
    screen.start(t0, &mut Vec::new());
    let mut inputs = Vec::new();
    screen.tick(t0 + probe::PROBE_BUDGET, &mut inputs);
    assert!(!screen.probing() && screen.mode() == GraphicsMode::Cells, "cells after the deadline");
    assert!(!contains(&frame(&mut screen, t0 + 200 * MS, 10), b"\x1b_G"));
    let mut answer = KITTY_OK.to_vec();
    answer.extend_from_slice(DA1);
    screen.feed(&answer, t0 + 400 * MS, &mut inputs);
    assert_eq!(screen.mode(), GraphicsMode::Kitty, "upgraded when the answer came");
    assert!(screen.take_layout_change());
    assert!(screen.take_notice().unwrap().contains("late"));
    assert!(contains(&frame(&mut screen, t0 + 450 * MS, 10), b"\x1b_G"), "a kitty picture now");
    assert!(inputs.is_empty(), "no answer became a key");
}

#[test]
fn a_late_probe_answer_is_the_probes_and_never_pairs_with_a_link_question() {
    let t0 = Instant::now();
    let mut screen = Screen::new(config(Bandwidth::Auto, true), (40, 12), t0);
    screen.start(t0, &mut Vec::new());
    let mut inputs = Vec::new();
    screen.tick(t0 + probe::PROBE_BUDGET, &mut inputs);
    // The link asks nothing while the probe's answer is due (at most a second)...
    let out = frame(&mut screen, t0 + 200 * MS, 10);
    assert!(!out.ends_with(link::PROBE), "no link question while the probe's answer is due");
    // ...then its first question goes out after a frame, at 1.2 s.
    screen.tick(t0 + 1200 * MS, &mut inputs);
    let out = frame(&mut screen, t0 + 1200 * MS, 20);
    assert!(out.ends_with(link::PROBE), "the link's question after the frame");
    // The probe's answer comes at 1.5 s (a slow terminal), the link's at 1.6 s.
    screen.feed(DA1, t0 + 1500 * MS, &mut inputs);
    assert_eq!(screen.link.last_rtt(), None, "the probe's late answer is not a round trip");
    screen.feed(DA1, t0 + 1600 * MS, &mut inputs);
    assert_eq!(screen.link.last_rtt(), Some(400 * MS), "the link's own answer: 1.6 - 1.2 s");
    assert!(inputs.is_empty());
}

#[test]
fn a_terminal_that_never_answers_keeps_getting_frames() {
    let t0 = Instant::now();
    let mut screen = Screen::new(config(Bandwidth::Auto, true), (40, 12), t0);
    screen.start(t0, &mut Vec::new());
    let mut inputs = Vec::new();
    let mut sent = 0;
    let mut frames = 0;
    for i in 5..600u32 {
        let now = t0 + i * 33 * MS / 2;
        screen.tick(now, &mut inputs);
        if screen.ready(now, false) {
            let bytes = frame(&mut screen, now, (i % 200) as u8);
            sent += bytes.len();
            frames += usize::from(!bytes.is_empty());
        }
    }
    assert!(!screen.probing());
    assert!(screen.take_notice().is_some_and(|n| n.contains("did not answer")), "said on the status line");
    assert!(frames > 200, "drawing all along: {frames} frames in 10 s");
    assert!(sent > 100_000, "{sent} bytes");
}

#[test]
fn a_terminal_that_answers_only_the_probe_gets_a_bounded_rate() {
    // It answers the probe's questions, then never again (a multiplexer that stopped passing
    // answers on): the link's questions go unanswered, and the rate falls instead of growing.
    let t0 = Instant::now();
    let mut screen = Screen::new(config(Bandwidth::Auto, true), (40, 12), t0);
    screen.start(t0, &mut Vec::new());
    let mut inputs = Vec::new();
    screen.feed(DA1, t0 + 5 * MS, &mut inputs);
    let mut frames = 0;
    for i in 1..300u32 {
        let now = t0 + i * 33 * MS;
        screen.tick(now, &mut inputs);
        if screen.ready(now, false) && !frame(&mut screen, now, (i % 200) as u8).is_empty() {
            frames += 1;
        }
    }
    let rate = screen.bucket.rate().unwrap();
    assert!(rate <= link::START_RATE, "never above where it started: {rate}");
    assert!(frames > 100, "still drawing: {frames}");
}

#[test]
fn the_fit_follows_the_mode() {
    let t0 = Instant::now();
    let screen = Screen::new(config(Bandwidth::Unlimited, false), (40, 12), t0);
    let fit: Fit = screen.fit((40, 22));
    assert!(fit.one_to_one());
    assert_eq!(fit.scene_at(3, 2), Some((3, 4)));
    let tiny = Screen::new(config(Bandwidth::Unlimited, false), (8, 4), t0);
    assert_eq!(tiny.fit((8, 6)).scene_at(1, 1), None, "a terminal too small takes no clicks");
}

#[test]
fn inside_tmux_its_own_answer_is_an_answer_and_the_hint_says_how_to_get_pictures() {
    let t0 = Instant::now();
    let mut config = config(Bandwidth::Unlimited, true);
    if let Some(p) = &mut config.probe {
        p.env.tmux = true;
    }
    let mut screen = Screen::new(config, (40, 12), t0);
    screen.start(t0, &mut Vec::new());
    let mut inputs = Vec::new();
    // tmux answers its plain question at once; the outer terminal's answer never comes back.
    screen.feed(DA1, t0 + 2 * MS, &mut inputs);
    screen.tick(t0 + probe::PROBE_BUDGET, &mut inputs);
    assert_eq!(screen.mode(), GraphicsMode::Cells);
    assert_eq!(screen.take_notice().as_deref(), Some(probe::TMUX_HINT));
    screen.tick(t0 + probe::PROBE_BUDGET + LATE_ANSWERS, &mut inputs);
    assert_eq!(screen.take_notice(), None, "tmux answered: not a silent terminal");
}

#[test]
fn inside_tmux_the_link_asks_the_terminal_through_passthrough_and_takes_only_its_answer() {
    // tmux answers the probe's DA1 itself; the link's question, a device status report wrapped
    // for tmux's passthrough, is answered by the terminal (`ESC[0n`).
    for (name, question) in [("tmux", link::TMUX_QUESTION), ("screen", link::SCREEN_QUESTION)] {
        let t0 = Instant::now();
        let mut screen = Screen::new(
            ScreenConfig { link_path: LinkPath::Multiplexer(name), ..config(Bandwidth::Auto, true) },
            (40, 12),
            t0,
        );
        screen.start(t0, &mut Vec::new());
        let mut inputs = Vec::new();
        screen.feed(b"\x1b[?1;2c", t0 + MS, &mut inputs);
        assert!(!screen.probing(), "{name}: the multiplexer's own answer ends the probe");
        let out = frame(&mut screen, t0 + 10 * MS, 10);
        assert!(out.ends_with(question), "{name}: the wrapped question after the frame");
        // A device attributes answer now is not the link's (the multiplexer's, or typed).
        screen.feed(DA1, t0 + 30 * MS, &mut inputs);
        assert_eq!(screen.link.last_rtt(), None, "{name}: DA1 is not the link's answer");
        screen.feed(b"\x1b[0n", t0 + 90 * MS, &mut inputs);
        assert_eq!(screen.link.last_rtt(), Some(80 * MS), "{name}: the terminal's answer, 90 - 10 ms");
        assert!(inputs.is_empty(), "{name}: no answer became a key");
    }
}

#[test]
fn a_late_answer_without_kitty_turns_a_forced_kitty_into_cells() {
    let t0 = Instant::now();
    let mut config = config(Bandwidth::Unlimited, true);
    config.graphics = GraphicsRequest::Force(GraphicsMode::Kitty);
    let mut screen = Screen::new(config, (40, 12), t0);
    screen.start(t0, &mut Vec::new());
    let mut inputs = Vec::new();
    screen.tick(t0 + probe::PROBE_BUDGET, &mut inputs);
    assert_eq!(screen.mode(), GraphicsMode::Kitty, "no answer yet: as asked");
    screen.feed(DA1, t0 + 700 * MS, &mut inputs);
    assert_eq!(screen.mode(), GraphicsMode::Cells, "the answer came without kitty's");
    assert_eq!(screen.take_notice().as_deref(), Some(probe::NO_KITTY));
    assert!(!contains(&frame(&mut screen, t0 + 750 * MS, 10), b"\x1b_G"));
}

/// A screen with `--color auto` guessed `guess` from the environment, asking the terminal.
fn colour_screen(guess: ColorMode, t0: Instant) -> Screen {
    let mut config = config(Bandwidth::Unlimited, true);
    (config.color, config.color_auto, config.colour_hint) = (guess, true, true);
    let mut screen = Screen::new(config, (40, 12), t0);
    let mut asked = Vec::new();
    screen.start(t0, &mut asked);
    assert!(contains(&asked, probe::COLOUR_QUERIES), "the colour questions go with the probe");
    screen
}

#[test]
fn true_colour_comes_from_the_terminals_answers_and_the_hint_only_when_none_said_so() {
    let t0 = Instant::now();
    let answers: [(&[u8], bool); 6] = [
        (b"\x1bP1+r524742\x1b\\", true),
        (b"\x1bP0+r524742\x1b\\\x1bP1+r5463=\x1b\\", true),
        (b"\x1bP1$r0;38:2::1:2:3m\x1b\\", true),
        (b"\x1bP1$r38;2;1;2;3m\x1b\\", true),
        (b"\x1bP0+r524742\x1b\\\x1bP0+r5463\x1b\\\x1bP1$r0;38:5:16m\x1b\\", false),
        (b"", false),
    ];
    for (answer, true_color) in answers {
        let mut screen = colour_screen(ColorMode::Palette256, t0);
        let mut inputs = Vec::new();
        screen.feed(&[answer, DA1].concat(), t0 + 5 * MS, &mut inputs);
        assert!(inputs.is_empty(), "{answer:?}: no answer became a key");
        let want = if true_color { ColorMode::TrueColor } else { ColorMode::Palette256 };
        assert_eq!(screen.config.color, want, "{:?}", String::from_utf8_lossy(answer));
        let notice = screen.take_notice().unwrap_or_default();
        assert_eq!(notice.contains("try --color truecolor"), !true_color, "{notice:?}");
        let out = frame(&mut screen, t0 + 10 * MS, 10);
        assert_eq!(contains(&out, b"8;2;"), true_color);
    }
    // A colour asked for is kept, whatever the terminal says.
    let mut config = config(Bandwidth::Unlimited, true);
    config.color = ColorMode::Palette256;
    let mut screen = Screen::new(config, (40, 12), t0);
    screen.start(t0, &mut Vec::new());
    screen.feed(&[b"\x1bP1+r524742\x1b\\", DA1].concat(), t0 + 5 * MS, &mut Vec::new());
    assert_eq!(screen.config.color, ColorMode::Palette256);
    assert!(!screen.take_notice().unwrap_or_default().contains("--color"), "asked for: no hint");
    // A late answer still upgrades, with a repaint.
    let mut screen = colour_screen(ColorMode::Palette256, t0);
    screen.tick(t0 + probe::PROBE_BUDGET, &mut Vec::new());
    let _ = frame(&mut screen, t0 + probe::PROBE_BUDGET, 10);
    screen.feed(&[b"\x1bP1+r524742\x1b\\", DA1].concat(), t0 + 900 * MS, &mut Vec::new());
    assert_eq!(screen.config.color, ColorMode::TrueColor);
    assert!(contains(&frame(&mut screen, t0 + 950 * MS, 10), b"8;2;"));
}

#[test]
fn unlimited_bandwidth_sends_iterm2_pictures_exactly_as_png_after_the_cells_bytes() {
    // The cells' bytes (the status line) and the synchronized-output markers come out of an
    // unlimited budget: it must stay unlimited, or the stream plans for a link and sends JPEG.
    let t0 = Instant::now();
    let config =
        ScreenConfig { graphics: GraphicsRequest::Force(GraphicsMode::Iterm2), ..config(Bandwidth::Unlimited, false) };
    let mut screen = Screen::new(config, (40, 12), t0);
    assert_eq!(screen.mode(), GraphicsMode::Iterm2);
    let mut sent = Vec::new();
    screen.start(t0, &mut sent);
    for k in 0..3u32 {
        sent.extend(frame(&mut screen, t0 + k * 100 * MS, 10 + 40 * k as u8));
    }
    let files: Vec<&[u8]> = sent.split(|&b| b == b':').skip(1).filter(|p| p.len() > 8).collect();
    assert!(contains(&sent, b"1337;File=") && !files.is_empty(), "iTerm2 pictures were sent");
    let png = files.iter().filter(|p| p.starts_with(b"iVBOR")).count();
    let jpeg = files.iter().filter(|p| p.starts_with(b"/9j/")).count();
    assert!(png > 0 && jpeg == 0, "{png} PNG and {jpeg} JPEG payloads under --bandwidth unlimited");
}
