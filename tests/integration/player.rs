//! The terminal player in a real pseudo-terminal: every way out restores the terminal, keys and
//! clicks drop stones where expected (decoded from the half-block output with the terminal
//! model), still water sends only the status line, and a recorded session replays exactly.

use std::time::Duration;

use crate::common::pty::{Player, cooked, find, rfind, temp_dir};
use tidepool::testing::Screen;

const ENTER: &[u8] = Screen::ENTER;
const RESTORE: &[u8] = Screen::RESTORE;
/// Makes the player panic after its first frame (a test hook of the terminal door, not a user
/// feature).
const TEST_PANIC_VAR: &str = "TIDEPOOL_TEST_PANIC";
use tidepool::testing::{SYNC_BEGIN, SYNC_END};

const WAIT: Duration = Duration::from_secs(20);
const ARGS: &[&str] = &["play", "--color", "truecolor", "--color-threshold", "0"];

/// Starts a player and waits for its first whole frame; checks the terminal is in raw mode.
fn started(name: &str, extra: &[&str], env: &[(&str, &str)]) -> Player {
    let dir = temp_dir(name);
    let args: Vec<&str> = ARGS.iter().chain(extra).copied().collect();
    let p = Player::spawn(&dir, 40, 12, &args, env);
    p.wait_for(SYNC_END, 0, WAIT);
    assert!(find(&p.output(), ENTER).is_some(), "the alternate screen, hidden cursor and mouse were set up");
    assert!(!cooked(&p.stty()), "raw mode while playing: {}", p.stty());
    p
}

/// The terminal was handed back: the restore sequence after the last frame, cooked mode.
fn assert_restored(p: &Player) {
    let out = p.output();
    let restore = rfind(&out, RESTORE).expect("the restore sequence was written");
    // (A one-cell frame goes without synchronized-output markers.)
    if let Some(last_frame) = rfind(&out, SYNC_BEGIN) {
        assert!(restore > last_frame, "restored after the last frame");
    }
    let after = &out[restore + RESTORE.len()..];
    assert!(
        after.is_empty(),
        "nothing after the restore: {:?}",
        String::from_utf8_lossy(&after[..after.len().min(200)])
    );
    assert!(cooked(&p.stty()), "cooked mode (icanon, echo) again: {}", p.stty());
}

#[test]
fn q_esc_and_ctrl_c_quit_and_restore() {
    for (name, key) in [("q", &b"q"[..]), ("esc", b"\x1b"), ("ctrl-c", b"\x03")] {
        let mut p = started(&format!("quit-{name}"), &[], &[]);
        p.send(key);
        let status = p.wait_exit(WAIT);
        assert_eq!(status.exit_code(), 0, "{name}");
        assert_restored(&p);
        assert!(p.output().ends_with(RESTORE), "{name}: nothing after the restore");
    }
}

#[test]
fn sigterm_and_sighup_restore() {
    for (signal, code) in [("TERM", 143), ("HUP", 129), ("INT", 130)] {
        let mut p = started(&format!("signal-{signal}"), &[], &[]);
        p.signal(signal);
        let status = p.wait_exit(WAIT);
        assert_eq!(status.exit_code(), code, "SIG{signal}");
        assert_restored(&p);
    }
}

#[test]
fn a_panic_restores_before_its_message() {
    let dir = temp_dir("panic");
    let mut p = Player::spawn(&dir, 40, 12, ARGS, &[(TEST_PANIC_VAR, "1")]);
    let status = p.wait_exit(WAIT);
    assert_eq!(status.exit_code(), 101);
    let out = p.output();
    let restore = find(&out, RESTORE).expect("restored");
    let message = find(&out, b"panicking on purpose").expect("the panic message is printed");
    assert!(restore < message, "the terminal is restored first, so the message is readable");
    assert!(cooked(&p.stty()));
}

#[test]
fn not_a_terminal_is_one_line_and_status_2() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_tidepool")).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8(out.stderr).unwrap();
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("not a terminal") && err.contains("tidepool render"), "{err}");
    assert!(out.stdout.is_empty());
}

#[test]
fn a_tiny_terminal_says_it_is_too_small() {
    let dir = temp_dir("tiny");
    let mut p = Player::spawn(&dir, 20, 4, ARGS, &[]);
    p.wait_for(SYNC_END, 0, WAIT);
    let s = p.screen();
    assert!((0..4).any(|y| s.row_text(y).contains("terminal too small")));
    p.master.resize(portable_pty::PtySize { rows: 8, cols: 20, pixel_width: 0, pixel_height: 0 }).unwrap();
    p.rows = 8;
    p.wait_until("the pool drawn once there is room", WAIT, |s| s.pixel(3, 3).is_some());
    p.send(b"q");
    assert_eq!(p.wait_exit(WAIT).exit_code(), 0);
}

/// With still water a frame changes only what changed: keys that change only the status line
/// (the stone size) send only the status line, and not one picture cell is redrawn.
#[test]
fn still_water_sends_only_the_status_line() {
    // Wide enough for the whole status line.
    let mut p = Player::spawn(&temp_dir("still"), 100, 12, &[ARGS, &["--rain", "0", "--breeze", "0"]].concat(), &[]);
    p.wait_for_status("stone 3", WAIT);
    // The first frames may be approximate (the link's rate is still being found); they
    // converge to the exact picture. Ready when a status-only key leaves the picture as it was.
    let picture = |s: &tidepool::testing::TerminalModel| (0..s.rows() - 1).map(|y| s.row_text(y)).collect::<Vec<_>>();
    let cells = |s: &tidepool::testing::TerminalModel| {
        (0..s.rows() - 1)
            .flat_map(|y| (0..s.cols()).map(move |x| (x, y)))
            .map(|(x, y)| s.cell(x, y))
            .collect::<Vec<_>>()
    };
    // Each round trip ends at stone 3, so the window below starts from a known size.
    loop {
        let before = p.screen();
        for (key, status) in [(&b"+"[..], "stone 4"), (b"-", "stone 3")] {
            p.send(key);
            p.wait_for_status(status, WAIT);
        }
        let after = p.screen();
        if picture(&before) == picture(&after) && cells(&before) == cells(&after) {
            break;
        }
    }
    let before = p.screen();
    let from = p.len();
    for (key, status) in [(&b"+"[..], "stone 4"), (b"+", "stone 6"), (b"-", "stone 4")] {
        p.send(key);
        p.wait_for_status(status, WAIT);
    }
    let out = p.output();
    let window = &out[from..];
    let mut after = before.clone();
    after.feed(window);
    for y in 0..before.rows() - 1 {
        for x in 0..before.cols() {
            assert_eq!(before.cell(x, y), after.cell(x, y), "picture cell ({x}, {y}) was redrawn");
        }
    }
    // Every frame in the window is at most a status line's worth of bytes.
    let frames = window.windows(SYNC_BEGIN.len()).filter(|w| *w == SYNC_BEGIN).count().max(1);
    let status_line = 40 * usize::from(p.cols);
    assert!(window.len() <= frames * status_line, "{} bytes in {frames} frames", window.len());
    p.send(b"q");
    assert_eq!(p.wait_exit(WAIT).exit_code(), 0);
}

/// The straight colour of pixel (x, y).
fn pixel_rgb(pixmap: &tiny_skia::Pixmap, x: usize, y: usize) -> [u8; 3] {
    let c = pixmap.pixel(x as u32, y as u32).unwrap().demultiply();
    [c.red(), c.green(), c.blue()]
}

/// Keys and clicks drop stones where expected; what the terminal shows (decoded with the
/// terminal model) is the replay of the recorded session; the screenshot is bit-identical to
/// `render pool --replay` at its step; a resize redraws the whole window at the new size.
#[test]
fn keys_and_clicks_drop_stones_where_expected_and_replay_exactly() {
    use tidepool::{Event, Stone};

    // An unlimited link: every frame is exact at once (on an auto link the first frames are
    // coarse while the rate is found, and this test compares the picture pixel for pixel).
    let args = ["--rain", "0", "--breeze", "0", "--record", "session.jsonl", "--bandwidth", "unlimited"];
    let mut p = started("drive", &args, &[]);
    p.send(b"p");
    p.wait_for_status("PAUSED", WAIT);
    // A random stone, a left click at cell (10, 3) and a right click at (30, 8), 1-based.
    p.send(b" ");
    p.send(b"\x1b[<0;10;3M\x1b[<0;10;3m");
    p.send(b"\x1b[<2;30;8M\x1b[<2;30;8m");
    // Aim three columns right and one row up from the centre, then drop.
    p.send(b"lllk\r");
    p.send(b"s");
    // The frame that shows the message also shows every event before it (events are applied
    // before a frame is drawn), and the water is paused.
    p.wait_for_status("saved tidepool-pool-", WAIT);
    let shown = p.screen();
    let before_resize = p.len();
    p.master.resize(portable_pty::PtySize { rows: 10, cols: 30, pixel_width: 0, pixel_height: 0 }).unwrap();
    // The first whole frame after the resize (the status line on the new last row).
    let mut resized = tidepool::testing::TerminalModel::new(30, 10);
    resized.lf_returns = false;
    let redrawn = |p: &Player| {
        let mut s = resized.clone();
        s.feed(&p.output()[before_resize..]);
        s.row_text(9).contains("pool") && s.pixel(1, 1).is_some()
    };
    let deadline = std::time::Instant::now() + WAIT;
    while !redrawn(&p) {
        assert!(std::time::Instant::now() < deadline, "never redrawn after the resize");
        std::thread::sleep(Duration::from_millis(20));
    }
    p.send(b"q");
    assert_eq!(p.wait_exit(WAIT).exit_code(), 0);
    assert_restored(&p);

    let path = p.dir.join("session.jsonl");
    let replay = tidepool::replay::Replay::read(&path).unwrap();
    assert_eq!(replay.size(), [40, 22]);
    // Every (step, event) the file holds, the end last.
    let entries = replay.script();
    let stones: Vec<Stone> =
        entries.iter().filter_map(|(_, e)| if let Event::Stone(s) = e { Some(*s) } else { None }).collect();
    assert_eq!(stones.len(), 4, "{:?}", entries);
    assert_eq!(stones[1], Stone::new(9, 4, 3, 128).unwrap(), "left click: the cell's upper pixel");
    assert_eq!(stones[2], Stone::new(29, 14, 6, 256).unwrap(), "right click: a big stone");
    assert_eq!(stones[3], Stone::new(26, 8, 3, 128).unwrap(), "aim: centre (20, 10) + 3 columns, 1 row up");
    let step = entries[0].0;
    assert!(entries.iter().all(|(s, _)| *s == step), "paused: every event at one step");
    let shot =
        entries.iter().find_map(|(_, e)| if let Event::Screenshot(f) = e { Some(f.clone()) } else { None }).unwrap();
    assert!(entries.iter().any(|(_, e)| *e == Event::Resize([30, 18])));

    // The picture on screen before the resize is the replay at the screenshot.
    let spec = replay.spec(tidepool::PoolSettings::default_floor());
    let mut scene = replay.simulate(&spec, Some(step), &mut |_| {}).unwrap();
    let expected = scene.snapshot().unwrap();
    let mut compared = 0;
    for y in 0..22 {
        for x in 0..40 {
            if let Some(rgb) = shown.pixel(x, y) {
                assert_eq!(rgb, pixel_rgb(&expected, x, y), "({x}, {y})");
                compared += 1;
            }
        }
    }
    assert!(compared >= 40 * 22 - 2, "only the aim marker's cell is not a picture: {compared}");

    // The screenshot file equals `render pool --replay --steps S`.
    let rendered = p.dir.join("replayed.png");
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_tidepool"))
        .args(["render", "pool", "--replay"])
        .arg(&path)
        .args(["--steps", &step.to_string(), "--out"])
        .arg(&rendered)
        .status()
        .unwrap();
    assert!(status.success());
    assert_eq!(std::fs::read(p.dir.join(&shot)).unwrap(), std::fs::read(&rendered).unwrap(), "bit-identical");

    // After the resize the window shows the 30x18 pool of the replay's end.
    resized.feed(&p.output()[before_resize..rfind(&p.output(), RESTORE).unwrap()]);
    let end = replay.simulate(&spec, None, &mut |_| {}).unwrap().snapshot().unwrap();
    assert_eq!((end.width(), end.height()), (30, 18));
    for y in 0..18 {
        for x in 0..30 {
            let want = pixel_rgb(&end, x, y);
            if (x, y / 2) == (26, 4) {
                assert_eq!(resized.cell(x, y / 2).ch, '+', "the aim marker is still shown");
                continue;
            }
            assert_eq!(resized.pixel(x, y), Some(want), "({x}, {y}) after the resize");
        }
    }
    assert!(resized.row_text(9).contains("pool"), "the status line moved to the new last row");
}

/// Opens `scene`, waits for `first` in the status line, then sends each key and waits for its
/// status text; quits with `q` and checks the terminal was restored.
fn play_keys(scene: &str, first: &str, keys: &[(&[u8], &str)]) {
    let mut p = Player::spawn(&temp_dir(scene), 80, 20, &[ARGS, &[scene]].concat(), &[]);
    p.wait_for_status(first, WAIT);
    for (key, status) in keys {
        p.send(key);
        p.wait_for_status(status, WAIT);
    }
    p.send(b"q");
    assert_eq!(p.wait_exit(WAIT).exit_code(), 0);
    assert_restored(&p);
}

#[test]
fn the_ocean_plays_its_wind_keys_and_tab_switches_scenes() {
    play_keys(
        "ocean",
        "Beaufort 5",
        &[(b"8", "Beaufort 8"), (b".", "from 345"), (b"\t", "octaves"), (b"\t", "damping")],
    );
}

#[test]
fn the_lake_plays_its_wind_and_noise_keys() {
    let keys: [(&[u8], &str); 4] =
        [(b"]", "wind 4 m/s"), (b"c", "wind 0 m/s"), (b"n", "\u{b7} gradient"), (b"O", "4 octaves")];
    play_keys("lake", "wind 3 m/s", &keys);
}

#[test]
fn recording_is_refused_for_scenes_other_than_the_pool() {
    let dir = temp_dir("record-ocean");
    let mut p = Player::spawn(&dir, 40, 12, &[ARGS, &["ocean", "--record", "s.jsonl"]].concat(), &[]);
    let status = p.wait_exit(WAIT);
    assert_eq!(status.exit_code(), 2);
    let out = String::from_utf8_lossy(&p.output()).into_owned();
    assert!(out.contains("--record") && out.contains("pool"), "{out}");
    assert!(!dir.join("s.jsonl").exists());
}

#[test]
fn hostile_terminals_do_not_break_the_player() {
    // A storm of resizes (sizes from 1x1 to 500x200, many a second), then q.
    let mut p = started("resize-storm", &[], &[]);
    let sizes = [(1u16, 1u16), (500, 200), (3, 2), (80, 24), (9, 4), (10, 5), (200, 60), (1, 80), (120, 1), (40, 12)];
    for round in 0..6 {
        for &(cols, rows) in &sizes {
            p.master.resize(portable_pty::PtySize { rows, cols, pixel_width: 0, pixel_height: 0 }).unwrap();
            std::thread::sleep(Duration::from_millis(if round == 0 { 30 } else { 4 }));
        }
    }
    let settled = p.len();
    p.wait_for(SYNC_END, settled, WAIT);
    p.send(b"q");
    assert_eq!(p.wait_exit(WAIT).exit_code(), 0, "a resize storm ends in a clean quit");
    assert_restored(&p);

    // Born tiny (1x1) and born huge (500x200): a notice, or the picture, and a clean exit.
    for (cols, rows) in [(1u16, 1u16), (500, 200)] {
        let mut p = Player::spawn(&temp_dir(&format!("size-{cols}x{rows}")), cols, rows, ARGS, &[]);
        // A one-cell frame goes without the synchronized-output markers: wait for the cell.
        p.wait_until("the first frame", WAIT, |s| s.cell(0, 0).ch != ' ' || s.cell(0, 0).bg.is_some());
        p.send(b" ");
        p.send(b"q");
        assert_eq!(p.wait_exit(WAIT).exit_code(), 0, "{cols}x{rows}");
        assert_restored(&p);
    }

    // TERM=dumb and no COLORTERM: colours fall back to the 16 basic ones, nothing breaks.
    let mut p = Player::spawn(&temp_dir("dumb"), 40, 12, &["play"], &[("TERM", "dumb"), ("COLORTERM", "")]);
    p.wait_for(SYNC_END, 0, WAIT);
    p.send(b"q");
    assert_eq!(p.wait_exit(WAIT).exit_code(), 0);
    let out = String::from_utf8_lossy(&p.output()).into_owned();
    assert!(!out.contains("38;2;"), "no truecolor codes for TERM=dumb");
    assert_restored(&p);
}
