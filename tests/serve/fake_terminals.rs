//! `tidepool serve` as each graphics terminal meets it over SSH (the russh client driving a
//! fake terminal, [`crate::fake_terminal`]): a picture in the protocol it speaks, or cells with
//! a notice, never a blank screen; true colour where the terminal has it, found by asking
//! (`COLORTERM` never reaches the server).

use std::time::Instant;

use russh::ChannelMsg;

use crate::common::*;
use crate::fake_terminal::{Edits, FakeTerminal, Profile, Sgr, Shown, Tcap, Watch};

const COLS: u32 = 160;
const ROWS: u32 = 48;

/// Plays `profile` on a fresh server until it shows something; the outcome and the terminal.
async fn serve_to(profile: Profile) -> (Shown, FakeTerminal) {
    let server = Server::start(TEST_FLAGS);
    let h = connect_none(server.port).await;
    let mut ch = open_shell(&h, profile.term, COLS, ROWS).await;
    let mut fake = FakeTerminal::new(profile.clone(), COLS as usize, ROWS as usize);
    let mut watch = Watch::new(fake.has_graphics());
    let deadline = Instant::now() + HANG_GUARD;
    let mut not_yet = String::from("blank");
    let mut next_check = Instant::now();
    loop {
        let left = deadline.saturating_duration_since(Instant::now());
        let msg = tokio::time::timeout(left, ch.wait()).await;
        match msg {
            Ok(Some(ChannelMsg::Data { data })) => {
                let answers = fake.feed(&data);
                if !answers.is_empty() {
                    ch.data(&answers[..]).await.expect("the answers go back");
                }
            }
            Ok(Some(_)) => {}
            Ok(None) => panic!("{}: the channel closed; status {:?}", profile.name, fake.status()),
            Err(_) => panic!("{}: {not_yet} for {HANG_GUARD:?}; status {:?}", profile.name, fake.status().trim_end()),
        }
        // The decoders run a few times a second, not on every packet.
        if Instant::now() >= next_check {
            next_check = Instant::now() + std::time::Duration::from_millis(200);
            if let Some(glance) = watch.glance(&fake) {
                match glance.check(profile.name) {
                    Ok(shown) => {
                        let (rgb, palette) = fake.colour_codes();
                        // The table in docs/terminals/right-pictures.md (`--nocapture`).
                        println!(
                            "serve | {} | {shown:?} | {} | {:.1} s",
                            profile.name,
                            if rgb > palette { "24-bit" } else { "256" },
                            (deadline - HANG_GUARD).elapsed().as_secs_f64()
                        );
                        return (shown, fake);
                    }
                    Err(what) => not_yet = what,
                }
            }
        }
    }
}

/// How many times each scenario runs (`TIDEPOOL_FAKE_RUNS`, default 3).
fn runs() -> usize {
    std::env::var("TIDEPOOL_FAKE_RUNS").ok().and_then(|v| v.parse().ok()).unwrap_or(3)
}

#[tokio::test]
async fn every_graphics_terminal_gets_pictures_or_cells_with_a_notice_over_ssh() {
    let kitty = |s: &Shown| matches!(s, Shown::Kitty(w, _) if *w >= 80);
    // Each terminal, what it must show, and whether in true colour.
    type Scenario = (Profile, fn(&Shown) -> bool, bool);
    let scenarios: Vec<Scenario> = vec![
        (Profile::kitty_026(), kitty, true),
        (Profile::kitty_current(), kitty, true),
        (Profile::ghostty(), kitty, true),
        // WezTerm's TERM is xterm-256color: serve does not ask the colour questions yet
        // (src/bin/tidepool/serve/handler.rs), so 256 colours there.
        (Profile::wezterm(), kitty, false),
        (Profile::konsole(), kitty, false),
        (Profile::kitty_minimal(Edits::Refuse), kitty, false),
        (Profile::kitty_minimal(Edits::Ignore), kitty, false),
        // Sixel never beats cells over a link: cells, and the notice says so.
        // (xterm's TERM is xterm-256color: 256 colours through serve, as for WezTerm.)
        (Profile::xterm_vt340(), |s| matches!(s, Shown::Cells(status) if status.contains("sixel over a link")), false),
    ];
    let mut failed = Vec::new();
    let mut seen = 0;
    for (profile, expected, true_colour) in &scenarios {
        for run in 0..runs() {
            seen += 1;
            let (shown, fake) = serve_to(profile.clone()).await;
            let (rgb, _) = fake.colour_codes();
            if !expected(&shown) {
                failed.push(format!("{} run {run}: {shown:?}", profile.name));
            } else if *true_colour != (rgb > 0) {
                failed.push(format!("{} run {run}: true colour {true_colour} but {rgb} 24-bit codes", profile.name));
            }
        }
    }
    assert!(failed.is_empty(), "{} of {seen} runs wrong:\n{}", failed.len(), failed.join("\n"));
}

#[tokio::test]
#[ignore = "serve does not ask the colour questions yet (src/bin/tidepool/serve/handler.rs): with them three serve tests' players stopped getting frames"]
async fn serve_finds_true_colour_by_asking_the_terminal() {
    for (tcap, sgr, true_colour) in [
        (Tcap::Rgb, Sgr::Silent, true),
        (Tcap::Silent, Sgr::TrueColor, true),
        (Tcap::Missing, Sgr::Palette, false),
        (Tcap::Silent, Sgr::Silent, false),
    ] {
        let (shown, fake) = serve_to(Profile::text(tcap, sgr)).await;
        assert!(matches!(shown, Shown::Cells(_)), "{shown:?}");
        let (rgb, palette) = fake.colour_codes();
        let what = format!("{tcap:?}/{sgr:?}: {rgb} 24-bit, {palette} palette codes");
        if true_colour {
            assert!(rgb > 100 && rgb > palette, "{what}");
        } else {
            assert!(rgb == 0 && palette > 100, "{what}");
        }
        let hint = fake.raw.windows(17).any(|w| w == b"--color truecolor");
        assert_eq!(hint, !true_colour, "{what}: the hint");
    }
}
