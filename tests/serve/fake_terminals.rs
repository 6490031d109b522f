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

/// How many times each scenario runs (`TIDEPOOL_FAKE_RUNS`, default 2, as over a pty).
fn runs() -> usize {
    std::env::var("TIDEPOOL_FAKE_RUNS").ok().and_then(|v| v.parse().ok()).unwrap_or(2)
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
        // WezTerm's TERM is xterm-256color: true colour from its answers to the colour
        // questions (XTGETTCAP `RGB`).
        (Profile::wezterm(), kitty, true),
        (Profile::konsole(), kitty, false),
        (Profile::kitty_minimal(Edits::Refuse), kitty, false),
        (Profile::kitty_minimal(Edits::Ignore), kitty, false),
        // Sixel never beats cells over a link: cells, and the notice says so.
        // (xterm's TERM is xterm-256color: true colour from DECRQSS, as for WezTerm.)
        (Profile::xterm_vt340(), |s| matches!(s, Shown::Cells(status) if status.contains("sixel over a link")), true),
    ];
    // Two servers at a time: a run mostly waits for its picture to grow with the link
    // control's first seconds, and the 24 runs took 40 s one after another.
    let gate = std::sync::Arc::new(tokio::sync::Semaphore::new(2));
    let mut set = tokio::task::JoinSet::new();
    for (profile, expected, true_colour) in scenarios {
        for run in 0..runs() {
            let (profile, gate) = (profile.clone(), std::sync::Arc::clone(&gate));
            set.spawn(async move {
                let _turn = gate.acquire_owned().await.expect("the gate stays open");
                let (shown, fake) = serve_to(profile.clone()).await;
                let (rgb, _) = fake.colour_codes();
                if !expected(&shown) {
                    Some(format!("{} run {run}: {shown:?}", profile.name))
                } else if true_colour != (rgb > 0) {
                    Some(format!("{} run {run}: true colour {true_colour} but {rgb} 24-bit codes", profile.name))
                } else {
                    None
                }
            });
        }
    }
    let seen = set.len();
    let failed: Vec<String> = set.join_all().await.into_iter().flatten().collect();
    assert!(failed.is_empty(), "{} of {seen} runs wrong:\n{}", failed.len(), failed.join("\n"));
}

#[tokio::test]
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
        // `--color` is the server's flag, not the player's: serve never suggests it.
        let hint = fake.raw.windows(17).any(|w| w == b"--color truecolor");
        assert!(!hint, "{what}: a hint of a flag the player cannot pass");
    }
}

/// A real-time rate, measured beside the test command's other tests, as its twin over a pty
/// is (`tests/integration/fake_terminals.rs`): the server's own time building a frame is not
/// a queue on the link (`link/handover.rs`).
#[tokio::test]
async fn a_kitty_slow_to_answer_keeps_its_rate_through_serve() {
    // kitty 0.26 under llvmpipe, busy for its own answer time at each device-attributes
    // question (median 18 ms, p90 98 ms; reading nothing meanwhile): through serve the rate fell
    // to the 2 kB/s floor within 5 s (round 3, real kitty over the shaped link).
    use crate::fake_terminal::kitty_026_answer_time;
    use std::time::Duration;
    let mut failed = Vec::new();
    for run in 0..runs() {
        // Busy water, so every frame has something to send.
        let server = Server::start(&["--rain", "0.05", "--breeze", "0", "--handshake-timeout-ms", "5000"]);
        let h = connect_none(server.port).await;
        let profile = Profile::kitty_026();
        let mut ch = open_shell(&h, profile.term, COLS, ROWS).await;
        let mut fake = FakeTerminal::new(profile, COLS as usize, ROWS as usize);
        let start = Instant::now();
        let (mut asked, mut at_4s) = (0u32, None);
        while start.elapsed() < Duration::from_secs(12) {
            let left = Duration::from_secs(12).saturating_sub(start.elapsed());
            match tokio::time::timeout(left, ch.wait()).await {
                Ok(Some(ChannelMsg::Data { data })) => {
                    for _ in 0..data.windows(3).filter(|w| w == b"\x1b[c").count() {
                        asked += 1;
                        tokio::time::sleep(kitty_026_answer_time(asked)).await;
                    }
                    let answers = fake.feed(&data);
                    if !answers.is_empty() {
                        ch.data(&answers[..]).await.expect("the answers go back");
                    }
                }
                Ok(Some(_)) => {}
                Ok(None) => panic!("the channel closed; status {:?}", fake.status()),
                Err(_) => {}
            }
            if at_4s.is_none() && start.elapsed() >= Duration::from_secs(4) {
                at_4s = Some((fake.raw.len(), start.elapsed()));
            }
        }
        let (before, from) = at_4s.expect("four seconds passed");
        let rate = (fake.raw.len() - before) as f64 / (start.elapsed() - from).as_secs_f64();
        let status = fake.status();
        println!(
            "slow kitty 0.26 through serve, run {run}: {:.1} kB/s from 4 to 12 s; status {:?}",
            rate / 1e3,
            status.trim_end()
        );
        // At the floor it was 1-3 kB/s; the loopback carries megabytes a second.
        let allowed = crate::fake_terminal::status_rate(&status);
        if rate < 20_000.0 || allowed.is_some_and(|r| r < 20_000.0) {
            failed.push(format!("run {run}: {:.1} kB/s, status {:?}", rate / 1e3, status.trim_end()));
        }
    }
    assert!(failed.is_empty(), "the rate fell:\n{}", failed.join("\n"));
}
