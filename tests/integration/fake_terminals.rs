//! `tidepool play` in a pseudo-terminal against fake graphics terminals
//! ([`crate::common::fake_terminal`]): each gets a picture in the protocol it speaks, or cells
//! with a notice, never a blank screen.

use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use crate::common::fake_terminal::{Edits, FakeTerminal, Profile};
use crate::common::pty::{Player, temp_dir};
use tidepool::graphics::kitty;

/// Bound for a hang only: every scenario ends much sooner when the player works.
const HANG: Duration = Duration::from_secs(20);
const COLS: usize = 160;
const ROWS: usize = 48;
/// An SSH login's `SSH_CONNECTION`.
const SSH: (&str, &str) = ("SSH_CONNECTION", "10.227.0.1 50000 10.227.0.2 22");

/// What the terminal ended up showing.
#[derive(Debug, PartialEq, Eq)]
enum Shown {
    /// A kitty picture, decoded by the independent decoder: its size.
    Kitty(u32, u32),
    /// Half-block cells, and the status line's text.
    Cells(String),
}

/// Runs `tidepool play ARGS` in a pty of 160x48 cells against `profile`, over SSH when `ssh`,
/// until the terminal shows a picture or cells with a notice; panics on a blank screen.
fn play(profile: Profile, args: &[&str], ssh: bool) -> (Shown, Arc<Mutex<FakeTerminal>>) {
    let fake = Arc::new(Mutex::new(FakeTerminal::new(profile.clone(), COLS, ROWS)));
    let mut env = vec![("TERM", profile.term), ("COLORTERM", "")];
    if ssh {
        env.push(SSH);
    }
    let all: Vec<&str> = ["play", "--rain", "0.05"].iter().chain(args).copied().collect();
    let name = format!("fake-{}", profile.name.replace(' ', "-"));
    let mut p = Player::spawn_fake(&temp_dir(&name), &all, &env, Arc::clone(&fake));
    let deadline = Instant::now() + HANG;
    let mut cells_since: Option<Instant> = None;
    let shown = loop {
        {
            let f = fake.lock().unwrap();
            if f.kitty_shown(kitty::IMAGE_ID) {
                // What the terminal holds now (the player deletes its image when it quits).
                break Err(f.kitty_stream.clone());
            }
            if f.cells_drawn() {
                // Cells, and the notice that says why (or, after a while, whatever it says).
                // A terminal without graphics gets cells and nothing to say about them.
                let since = *cells_since.get_or_insert_with(Instant::now);
                let text = profile.kitty.is_none() && !profile.da1.windows(2).any(|w| w == b";4");
                let settle = Duration::from_millis(if text { 300 } else { 5000 });
                if (f.status().contains("cells") && !text) || since.elapsed() > settle {
                    break Ok(Shown::Cells(f.status()));
                }
            }
            if Instant::now() >= deadline {
                let blank = format!(
                    "{}: the screen stayed blank for {HANG:?}: {} bytes, status line {:?}",
                    profile.name,
                    f.raw.len(),
                    f.status().trim_end()
                );
                drop(f);
                panic!("{blank}");
            }
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    p.send(b"q");
    let _ = p.wait_exit(HANG);
    let shown = shown.unwrap_or_else(|stream| {
        let images = FakeTerminal::decode_kitty(profile.name, &stream);
        let image = images.iter().find(|i| i.id == kitty::IMAGE_ID).expect("the placed image decodes");
        assert!(image.colours() > 16, "{}: the picture shows water, not a flat image", profile.name);
        Shown::Kitty(image.width, image.height)
    });
    (shown, fake)
}

/// Panics with what `play` found when the screen stayed blank, instead of at once: the other
/// runs still run, and the failure lists them all.
fn play_or_blank(profile: Profile, args: &[&str], ssh: bool) -> Result<Shown, String> {
    std::panic::catch_unwind(|| play(profile, args, ssh).0).map_err(|e| {
        e.downcast_ref::<String>()
            .cloned()
            .or_else(|| e.downcast_ref::<&str>().map(|s| s.to_string()))
            .unwrap_or_default()
    })
}

#[test]
fn a_kitty_terminal_refusing_or_ignoring_frame_edits_over_ssh_gets_pictures() {
    let mut outcomes = Vec::new();
    for edits in [Edits::Refuse, Edits::Ignore] {
        for args in [&["--graphics", "kitty"][..], &[][..]] {
            for run in 0..3 {
                let shown = play_or_blank(Profile::kitty_minimal(edits), args, true);
                outcomes.push((edits, args, run, shown));
            }
        }
    }
    let failed: Vec<String> = outcomes
        .iter()
        .filter(|(_, _, _, shown)| !matches!(shown, Ok(Shown::Kitty(..))))
        .map(|(edits, args, run, shown)| format!("{edits:?} {args:?} run {run}: {shown:?}"))
        .collect();
    assert!(failed.is_empty(), "{} of {} runs without a picture:\n{}", failed.len(), outcomes.len(), failed.join("\n"));
}

#[test]
fn a_forced_protocol_the_terminal_does_not_speak_draws_cells_and_says_why() {
    use crate::common::fake_terminal::{Sgr, Tcap};
    for (flag, says) in [("kitty", "kitty"), ("sixel", "sixel")] {
        for ssh in [false, true] {
            let (shown, _) = play(Profile::text(Tcap::Silent, Sgr::Silent), &["--graphics", flag], ssh);
            let Shown::Cells(status) = &shown else { panic!("--graphics {flag}: {shown:?}") };
            assert!(status.contains(says) && status.contains("cells"), "--graphics {flag} (ssh {ssh}): {status:?}");
        }
    }
}

/// The colour codes the frames used (after the screen was taken; the probe sets a 24-bit
/// colour of its own): (24-bit codes, 256-colour codes). In true colour the rate-controlled
/// encoder still sends some cells approximately, in 256 colours (half the bytes).
fn colour_codes(raw: &[u8]) -> (usize, usize) {
    let entered = raw.windows(8).position(|w| w == b"\x1b[?1049h").expect("the screen was taken");
    let frames = &raw[entered..];
    let count = |needle: &[u8]| frames.windows(needle.len()).filter(|w| *w == needle).count();
    (count(b"8;2;"), count(b"8;5;"))
}

#[test]
fn true_colour_is_found_by_asking_the_terminal_or_by_its_name() {
    use crate::common::fake_terminal::{Sgr, Tcap};
    let text = |tcap, sgr, term| Profile { term, ..Profile::text(tcap, sgr) };
    let cases = [
        (text(Tcap::Rgb, Sgr::Silent, "xterm-256color"), &[][..], true),
        (text(Tcap::Silent, Sgr::TrueColor, "xterm-256color"), &[][..], true),
        (text(Tcap::Missing, Sgr::TrueColor, "xterm-256color"), &[][..], true),
        (text(Tcap::Missing, Sgr::Palette, "xterm-256color"), &[][..], false),
        (text(Tcap::Silent, Sgr::Silent, "xterm-256color"), &[][..], false),
        (text(Tcap::Silent, Sgr::Silent, "xterm-kitty"), &[][..], true),
        (text(Tcap::Silent, Sgr::Silent, "foot"), &[][..], true),
        (text(Tcap::Silent, Sgr::Silent, "wezterm"), &[][..], true),
        // The manual override wins over the answers.
        (text(Tcap::Rgb, Sgr::TrueColor, "xterm-256color"), &["--color", "256"][..], false),
    ];
    for (profile, args, truecolor) in cases {
        for ssh in [true, false] {
            let what = format!("{:?}/{:?} TERM={} {args:?} ssh {ssh}", profile.tcap, profile.sgr, profile.term);
            let (shown, fake) = play(profile.clone(), args, ssh);
            assert!(matches!(shown, Shown::Cells(_)), "{what}: {shown:?}");
            let (rgb, palette) = colour_codes(&fake.lock().unwrap().raw);
            if truecolor {
                assert!(
                    rgb > 100 && rgb > palette,
                    "{what}: 24-bit colours expected ({rgb} 24-bit, {palette} palette)"
                );
            } else {
                assert!(palette > 100 && rgb == 0, "{what}: 256 colours expected ({rgb} 24-bit, {palette} palette)");
            }
            let raw = fake.lock().unwrap().raw.clone();
            let hint = raw.windows(17).any(|w| w == b"--color truecolor");
            assert_eq!(hint, !truecolor && args.is_empty(), "{what}: the hint to use --color truecolor");
        }
    }
}
