//! `play --graphics` in a real pseudo-terminal, against a scripted fake terminal (the test
//! writes the terminal's answers to the pty): forced kitty frames decode into the scene's own
//! picture; `auto` chooses kitty or sixel from the answers and cells when the terminal is
//! silent; keys typed during the probe reach the player; late answers never become keys; every
//! way out deletes kitty's image before the usual restore.

use std::time::Duration;

use crate::common::pty::{DA1_ANSWER, Player, cooked, find, rfind, temp_dir};
use tidepool::testing::KittyOptions;
use tidepool::testing::Screen;
use tidepool::testing::kitty_decode;

const ENTER: &[u8] = Screen::ENTER;
const RESTORE: &[u8] = Screen::RESTORE;
use tidepool::testing::SYNC_END;

const WAIT: Duration = Duration::from_secs(20);
/// Still water (no rain, no breeze), so the picture only changes when a key changes it.
const ARGS: &[&str] = &["play", "--color", "truecolor", "--rain", "0", "--breeze", "0", "--bandwidth", "unlimited"];
/// A kitty terminal's answers to the probe: the graphics query's OK, SGR-pixels mouse, then
/// DA1 (no sixel).
const KITTY_ANSWERS: &[u8] = b"\x1b_Gi=31;OK\x1b\\\x1b[?1016;2$y\x1b[?62;22c";
/// An xterm -ti vt340's: 256 colour registers, a 1000x1000 largest image, DA1 with sixel (4).
const SIXEL_ANSWERS: &[u8] = b"\x1b[?1;0;256S\x1b[?2;0;1000;1000S\x1b[?62;4;22c";
/// The start of a kitty graphics command.
const APC_G: &[u8] = b"\x1b_G";

/// A player whose terminal answers the probe with `probe_answer` (`None`: silence) and every
/// later device attributes question as xterm does.
fn spawn(name: &str, extra: &[&str], probe_answer: Option<&'static [u8]>) -> Player {
    let args: Vec<&str> = ARGS.iter().chain(extra).copied().collect();
    Player::spawn_answering(&temp_dir(name), 100, 12, &args, &[], move |n| {
        if n == 0 { probe_answer.map(<[u8]>::to_vec) } else { Some(DA1_ANSWER.to_vec()) }
    })
}

/// The output after the player took the screen.
fn after_enter(p: &Player) -> Vec<u8> {
    let out = p.output();
    let at = find(&out, ENTER).expect("the screen was taken");
    out[at + ENTER.len()..].to_vec()
}

/// The kitty commands in `bytes` that delete the player's image.
fn deletes(bytes: &[u8]) -> usize {
    let state = kitty_decode(bytes).expect("kitty commands decode");
    let id = KittyOptions::IMAGE_ID.to_string();
    state.commands.iter().filter(|c| c.get(&'a').map(String::as_str) == Some("d") && c.get(&'i') == Some(&id)).count()
}

/// Where the picture's restore (CAN, then kitty's delete) starts: the last CAN before the
/// usual restore (which starts with CAN too).
fn picture_restore_at(out: &[u8]) -> usize {
    assert!(out.ends_with(RESTORE), "the usual restore comes last");
    let body = &out[..out.len() - RESTORE.len()];
    rfind(body, b"\x18").expect("a CAN before the usual restore starts the picture's restore")
}

/// After the last frame: CAN, kitty's delete, then the usual restore; and cooked mode.
fn assert_image_deleted_on_restore(p: &Player) {
    let out = p.output();
    let at = picture_restore_at(&out);
    let tail = &out[at..out.len() - RESTORE.len()];
    assert!(rfind(&out, SYNC_END).is_some_and(|f| f < at || f >= out.len() - RESTORE.len()), "after the last frame");
    let shown = String::from_utf8_lossy(&tail[..tail.len().min(200)]).into_owned();
    assert_eq!(deletes(tail), 1, "kitty's image is deleted: {shown:?}");
    assert!(cooked(&p.stty()), "cooked mode again");
}

#[test]
fn forced_kitty_frames_decode_into_the_scenes_picture() {
    // A kitty terminal answering the probe (forcing kitty where the terminal answered without
    // it draws cells instead: `fake_terminals.rs`).
    let mut p = spawn("gfx-kitty", &["--graphics", "kitty"], Some(KITTY_ANSWERS));
    let start = p.wait_for(APC_G, 0, WAIT);
    p.wait_for(SYNC_END, start, WAIT);
    p.send(b"p");
    p.wait_for_status("PAUSED", WAIT);
    p.send(b"s");
    p.wait_for_status("saved", WAIT);
    p.send(b"q");
    assert_eq!(p.wait_exit(WAIT).exit_code(), 0);
    let out = p.output();
    let frames = &out[find(&out, ENTER).unwrap()..picture_restore_at(&out)];
    let state = kitty_decode(frames).expect("the frames decode");
    let image = &state.images[&KittyOptions::IMAGE_ID];
    // 100x12 cells of the assumed 8x16 pixels, less the status row: 800x176 over 100x11 cells,
    // rendered within the scene cap (480x300: 480x106) and scaled up by the terminal.
    assert_eq!((image.width, image.height), (480, 106));
    assert_eq!((image.keys.get(&'c'), image.keys.get(&'r')), (Some(&"100".to_string()), Some(&"11".to_string())));
    let shot = std::fs::read_dir(&p.dir)
        .unwrap()
        .flatten()
        .find(|e| e.file_name().to_string_lossy().ends_with(".png"))
        .expect("the `s` screenshot was saved");
    let shot = image::open(shot.path()).unwrap().to_rgb8();
    assert_eq!((shot.width(), shot.height()), (480, 106), "the scene renders at the picture's size");
    assert!(image.rgb == shot.into_raw(), "the last kitty frame is the scene's own picture, pixel for pixel");
    let s = p.screen();
    assert!(s.row_text(s.rows() - 1).contains("pool"), "the status line stays text on the last row");
    assert_image_deleted_on_restore(&p);
}

#[test]
fn auto_chooses_kitty_when_the_terminal_answers_its_query_and_keys_typed_meanwhile_count() {
    // A `+` typed while the probe waits arrives before the answers: the probe hands it on.
    let answers: &'static [u8] = &[b"+", KITTY_ANSWERS].concat().leak()[..];
    let mut p = spawn("gfx-auto-kitty", &[], Some(answers));
    p.wait_for(APC_G, find(&p.output(), ENTER).map_or(0, |i| i + ENTER.len()), WAIT);
    p.wait_for_status("stone 4", WAIT);
    let out = after_enter(&p);
    assert!(out.starts_with(b"\x1b[?1016h"), "SGR-pixels mouse reports on, since the terminal has them");
    p.send(b"q");
    assert_eq!(p.wait_exit(WAIT).exit_code(), 0);
    assert_image_deleted_on_restore(&p);
    let out = p.output();
    assert!(find(&out[picture_restore_at(&out)..], b"\x1b[?1016l").is_some(), "pixel mouse off on exit");
}

#[test]
fn auto_chooses_sixel_from_device_attributes() {
    let mut p = spawn("gfx-auto-sixel", &[], Some(SIXEL_ANSWERS));
    // A sixel picture: DCS, raster attributes, the 256-register palette's first colour.
    let start = find(&p.output(), ENTER).map_or(0, |i| i + ENTER.len());
    let at = p.wait_for(b"\x1bP0;1;0q\"1;1;800;174", start, WAIT);
    p.wait_for(b"\x1b\\", at, WAIT);
    p.wait_for_status("pool", WAIT);
    assert_eq!(find(&after_enter(&p), APC_G), None, "no kitty commands");
    p.send(b"q");
    assert_eq!(p.wait_exit(WAIT).exit_code(), 0);
    assert!(p.output().ends_with(RESTORE));
}

#[test]
fn a_silent_terminal_gets_cells_and_its_late_answers_never_become_keys() {
    let mut p = spawn("gfx-silent", &[], None);
    p.wait_until("the pool drawn in cells", WAIT, |s| s.pixel(3, 3).is_some());
    let out = after_enter(&p);
    assert_eq!(find(&out, APC_G), None, "no kitty commands");
    assert_eq!(find(&out, b"\x1bP"), None, "no sixel");
    // The answers arrive now, late. As keys, `_` and `=` would change the stone size, `?`
    // would open the help; then `+` makes the stone 4 only if none of them counted.
    p.send(b"\x1b_Gi=31;OK\x1b\\\x1b[?1016;2$y\x1b[?2;0;1000;1000S\x1b[6;16;8t\x1b]1337;ReportCellSize=16;8\x1b\\");
    p.send(b"\x1b[?62;4;22c+");
    p.wait_for_status("stone 4", WAIT);
    let s = p.screen();
    assert!(!(0..s.rows()).any(|y| s.row_text(y).contains("a stone at a random spot")), "the help stayed closed");
    p.send(b"q");
    assert_eq!(p.wait_exit(WAIT).exit_code(), 0);
    assert!(p.output().ends_with(RESTORE));
}

#[test]
fn sigterm_deletes_the_kitty_image() {
    let mut p = spawn("gfx-sigterm", &["--graphics", "kitty"], Some(KITTY_ANSWERS));
    let start = p.wait_for(APC_G, 0, WAIT);
    p.wait_for(SYNC_END, start, WAIT);
    p.signal("TERM");
    assert_eq!(p.wait_exit(WAIT).exit_code(), 143);
    assert_image_deleted_on_restore(&p);
}

#[test]
fn cells_sends_no_query() {
    let mut p = spawn("gfx-cells", &["--graphics", "cells"], Some(DA1_ANSWER));
    p.wait_for(SYNC_END, 0, WAIT);
    let out = p.output();
    assert!(out.starts_with(ENTER), "the screen is taken at once: no probe before it");
    p.send(b"q");
    assert_eq!(p.wait_exit(WAIT).exit_code(), 0);
}

#[test]
fn render_to_a_kitty_terminal_draws_the_picture_as_one_image() {
    let answers: &'static [u8] = KITTY_ANSWERS;
    let dir = temp_dir("gfx-render");
    let mut p = Player::spawn_answering(&dir, 100, 12, &["render", "pool", "--out", "-"], &[], move |n| {
        (n == 0).then(|| answers.to_vec())
    });
    assert_eq!(p.wait_exit(WAIT).exit_code(), 0);
    let out = p.output();
    let state = kitty_decode(&out).expect("the picture decodes");
    let image = &state.images[&KittyOptions::IMAGE_ID];
    // The cell area above the prompt's row: 100x11 cells of the assumed 8x16 pixels.
    assert_eq!((image.width, image.height), (800, 176));
    assert!(out.ends_with(b"\x1b[12;1H"), "the cursor is left on the last row for the prompt");
    // The same picture as a PNG file.
    let png = std::process::Command::new(env!("CARGO_BIN_EXE_tidepool"))
        .current_dir(&dir)
        .args(["render", "pool", "--size", "800x176", "--out", "same.png"])
        .status()
        .unwrap();
    assert!(png.success());
    let want = image::open(dir.join("same.png")).unwrap().to_rgb8().into_raw();
    assert!(image.rgb == want, "the image is the scene's picture, pixel for pixel");
}

#[test]
fn render_into_a_pipe_asks_nothing_and_writes_half_blocks() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_tidepool"))
        .args(["render", "pool", "--out", "-", "--size", "30x20"])
        .output()
        .unwrap();
    assert!(out.status.success());
    assert_eq!(find(&out.stdout, APC_G), None, "no kitty query or image");
    assert_eq!(find(&out.stdout, b"\x1b[c"), None, "no device attributes question");
    assert!(String::from_utf8_lossy(&out.stdout).contains('▀'), "half-block text");
}

#[test]
fn a_resize_resends_the_picture_for_the_new_cell_area() {
    let mut p = spawn("gfx-resize", &["--graphics", "kitty"], Some(KITTY_ANSWERS));
    let start = p.wait_for(b"c=100,r=11,", 0, WAIT);
    p.master.resize(portable_pty::PtySize { rows: 10, cols: 80, pixel_width: 0, pixel_height: 0 }).unwrap();
    (p.cols, p.rows) = (80, 10);
    // 80x9 cells of 8x16: 640x144, within the scene cap 480x108, sent whole (a new image
    // replaces the old one and its placement; every cell of the new size is repainted).
    let at = p.wait_for(b"s=480,v=108,c=80,r=9,", start, WAIT);
    p.wait_for(SYNC_END, at, WAIT);
    let s = p.screen();
    assert!(s.row_text(9).contains("pool"), "the status line on the new last row");
    p.send(b"q");
    assert_eq!(p.wait_exit(WAIT).exit_code(), 0);
}

#[test]
fn inside_tmux_with_passthrough_kitty_draws_through_unicode_placeholders() {
    // tmux answers its own DA1 at once (no sixel); the outer kitty answers the wrapped queries:
    // the graphics query, frame edits and the virtual placement (Unicode placeholders), then DA1.
    const OUTER: &[u8] = b"\x1b_Gi=31;OK\x1b\\\x1b_Gi=7627890;OK\x1b\\\x1b_Gi=7627891;OK\x1b\\\x1b[?62;22c";
    let dir = temp_dir("gfx-tmux-kitty");
    let args: Vec<&str> = ARGS.to_vec();
    let mut p = Player::spawn_answering(&dir, 100, 12, &args, &[("TMUX", "/tmp/tmux-0/default,1,0")], move |n| {
        Some(if n == 1 { OUTER.to_vec() } else { DA1_ANSWER.to_vec() })
    });
    let start = find(&p.output(), ENTER).map_or(0, |i| i + ENTER.len());
    // The image goes wrapped for passthrough, with a virtual placement.
    let at = p.wait_for(b"\x1bPtmux;\x1b\x1b_G", start, WAIT);
    p.wait_for(SYNC_END, at, WAIT);
    p.send(b"q");
    assert_eq!(p.wait_exit(WAIT).exit_code(), 0);
    let out = p.output();
    let frames = &out[find(&out, ENTER).unwrap()..picture_restore_at(&out)];
    let count = |needle: &[u8]| frames.windows(needle.len()).filter(|w| *w == needle).count();
    assert!(count(b"\x1b_G") > 0, "kitty commands");
    assert_eq!(count(b"\x1b_G"), count(b"\x1bPtmux;\x1b\x1b_G"), "every kitty command is wrapped for tmux");
    let state = kitty_decode(frames).expect("the wrapped commands decode");
    let image = &state.images[&KittyOptions::IMAGE_ID];
    assert_eq!(image.keys.get(&'U').map(String::as_str), Some("1"), "a virtual placement");
    assert_eq!((image.width, image.height), (480, 106));
    // The placeholder text: 100x11 cells of U+10EEEE, the image id in the foreground colour
    // (0x746470: 116;100;112), row and column in combining marks; tmux moves it as text.
    let placeholder = "\u{10EEEE}".as_bytes();
    assert_eq!(frames.windows(4).filter(|w| *w == placeholder).count(), 100 * 11);
    assert!(find(frames, b"\x1b[38;2;116;100;112m").is_some(), "the image id as the foreground colour");
    assert!(find(frames, b"\x1b[?1016h").is_none(), "no pixel mouse inside tmux");
    // The delete on the way out is wrapped too.
    let restore = &out[picture_restore_at(&out)..];
    assert!(find(restore, b"\x1bPtmux;\x1b\x1b_Ga=d").is_some(), "the delete reaches the outer terminal");
}
