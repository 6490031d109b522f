use std::cell::{Cell, RefCell};
use std::time::Instant;

use super::*;
use crate::output::graphics::kitty_decode;
use crate::term::probe::run_probe;

const MS: Duration = Duration::from_millis(1);

/// A scripted terminal: each reply chunk arrives at its time after the queries were written.
/// The clock is fake: reading jumps it to the next chunk's time or to the deadline.
struct FakeTerminal {
    script: Vec<(Duration, Vec<u8>)>,
}

struct Run {
    outcome: ProbeOutcome,
    written: Vec<u8>,
    took: Duration,
}

impl FakeTerminal {
    fn new(script: &[(u64, &[u8])]) -> FakeTerminal {
        FakeTerminal { script: script.iter().map(|&(ms, b)| (Duration::from_millis(ms), b.to_vec())).collect() }
    }

    fn run(&self, options: &ProbeOptions) -> Run {
        let start = Instant::now();
        let clock = Cell::new(start);
        let written = RefCell::new(Vec::new());
        let next = Cell::new(0usize);
        let offset = Cell::new(0usize); // bytes of the current chunk already read
        let mut write = |b: &[u8]| {
            written.borrow_mut().extend_from_slice(b);
            Ok(())
        };
        let mut read = |buf: &mut [u8], deadline: Instant| {
            let Some((at, chunk)) = self.script.get(next.get()) else {
                clock.set(deadline);
                return Ok(0);
            };
            if start + *at > deadline {
                clock.set(deadline);
                return Ok(0);
            }
            clock.set(clock.get().max(start + *at));
            let rest = &chunk[offset.get()..];
            let n = rest.len().min(buf.len());
            buf[..n].copy_from_slice(&rest[..n]);
            if n == rest.len() {
                next.set(next.get() + 1);
                offset.set(0);
            } else {
                offset.set(offset.get() + n);
            }
            Ok(n)
        };
        let now = || clock.get();
        let outcome = run_probe(options, &mut write, &mut read, &now, PROBE_BUDGET).unwrap();
        Run { outcome, written: written.into_inner(), took: clock.get() - start }
    }
}

fn options(tmux: bool) -> ProbeOptions {
    ProbeOptions {
        env: EnvHints { tmux, ..EnvHints::default() },
        winsize: WinSize { cols: 160, rows: 48, x_px: 0, y_px: 0 },
        kitty_file: None,
        colours: true,
    }
}

const KITTY_OK: &[u8] = b"\x1b_Gi=31;OK\x1b\\";
const XTERM_DA1: &[u8] = b"\x1b[?63;1;2;3;4;6;9;15;16;22;28;29c";

fn kitty_answers() -> Vec<u8> {
    let mut v = KITTY_OK.to_vec();
    v.extend_from_slice(format!("\x1b_Gi={KITTY_EDIT_PROBE_ID};OK\x1b\\").as_bytes());
    v.extend_from_slice(b"\x1b[6;16;8t\x1b[4;752;1280t\x1b[?1016;2$y\x1b[?2026;2$y\x1b[?62;22;52c");
    v
}

#[test]
fn kitty_answers_everything() {
    let answers = kitty_answers();
    // The answers cut into three reads, one in the middle of the first APC.
    let run = FakeTerminal::new(&[(2, &answers[..5]), (3, &answers[5..40]), (4, &answers[40..])]).run(&options(false));
    let s = &run.outcome.support;
    assert!(s.answered && s.kitty && s.kitty_frame_edits && !s.kitty_temp_file, "{s:?}");
    assert_eq!((s.sixel, s.cell_px, s.sgr_pixels_mouse, s.sync_output), (None, Some((8, 16)), true, true));
    assert_eq!(run.took, 4 * MS, "done as soon as DA1 arrived");
    assert!(run.outcome.leftover.is_empty());
    let choice = choose(GraphicsRequest::Auto, Some(s));
    assert_eq!(
        choice,
        GraphicsChoice { mode: GraphicsMode::Kitty, tmux_wrap: false, kitty_placeholders: false, hint: None }
    );
}

#[test]
fn xterm_vt340_gets_sixel_with_its_registers_and_limit() {
    let run =
        FakeTerminal::new(&[(3, b"\x1b[?1;0;256S\x1b[?2;0;1000;1000S\x1b[6;17;9t\x1b[?1016;2$y"), (4, XTERM_DA1)])
            .run(&options(false));
    let s = &run.outcome.support;
    assert!(s.answered && !s.kitty && !s.iterm2);
    assert_eq!(s.sixel, Some(SixelSupport { registers: 256, max_w: Some(1000), max_h: Some(1000) }));
    assert_eq!(s.cell_px, Some((9, 17)));
    assert_eq!(choose(GraphicsRequest::Auto, Some(s)).mode, GraphicsMode::Sixel);
    // DA1 alone: sixel with the VT340's 16 registers.
    let s = FakeTerminal::new(&[(1, XTERM_DA1)]).run(&options(false)).outcome.support;
    assert_eq!(s.sixel, Some(SixelSupport { registers: 16, max_w: None, max_h: None }));
}

#[test]
fn no_answer_means_cells_after_the_budget() {
    let run = FakeTerminal::new(&[]).run(&options(false));
    assert!(!run.outcome.support.answered);
    assert_eq!(run.took, PROBE_BUDGET);
    assert_eq!(choose(GraphicsRequest::Auto, Some(&run.outcome.support)).mode, GraphicsMode::Cells);
}

#[test]
fn a_slow_answer_means_cells() {
    let answers = kitty_answers();
    let late = PROBE_BUDGET.as_millis() as u64 + 150;
    let run = FakeTerminal::new(&[(20, &answers[..30]), (late, &answers[30..])]).run(&options(false));
    let s = &run.outcome.support;
    assert!(!s.answered && !s.kitty, "a partial answer is not trusted: {s:?}");
    assert_eq!(run.took, PROBE_BUDGET);
    assert_eq!(choose(GraphicsRequest::Auto, Some(s)).mode, GraphicsMode::Cells);
    // The unfinished reply waits in the input parser (which drops it when the rest arrives):
    // none of its bytes became a key.
    assert!(run.outcome.leftover.is_empty(), "{:?}", run.outcome.leftover);
}

#[test]
fn garbage_means_cells() {
    for garbage in [&b"\x1b[?62;4\x01c"[..], b"\x1b\x1b\x1b[[[", b"\x1b_Gi=31;O\x1bK\x1b\\"] {
        let mut script = garbage.to_vec();
        script.extend_from_slice(KITTY_OK);
        script.extend_from_slice(XTERM_DA1);
        let run = FakeTerminal::new(&[(2, &script)]).run(&options(false));
        let s = &run.outcome.support;
        assert!(s.garbled && !s.answered, "{:?}: {s:?}", String::from_utf8_lossy(garbage));
        assert_eq!(choose(GraphicsRequest::Auto, Some(s)).mode, GraphicsMode::Cells);
    }
    // A flood that never ends stops the probe at the byte bound.
    let flood = vec![b'x'; 2 * MAX_PROBE_BYTES];
    let run = FakeTerminal::new(&[(1, &flood)]).run(&options(false));
    assert!(run.outcome.support.garbled && !run.outcome.support.answered);
}

#[test]
fn keys_typed_during_the_probe_are_kept() {
    let mut script = b"q".to_vec();
    script.extend_from_slice(KITTY_OK);
    script.extend_from_slice(b"7");
    script.extend_from_slice(b"\x1b[?62c");
    script.extend_from_slice(b"x");
    let run = FakeTerminal::new(&[(2, &script)]).run(&options(false));
    assert!(run.outcome.support.kitty && run.outcome.support.answered);
    assert_eq!(run.outcome.leftover, vec![Input::Quit, Input::Other('7'), Input::Other('x')]);
}

#[test]
fn tmux_with_passthrough_gets_kitty_through_placeholders() {
    let mut outer = KITTY_OK.to_vec();
    outer.extend_from_slice(format!("\x1b_Gi={KITTY_PLACEHOLDER_PROBE_ID};OK\x1b\\").as_bytes());
    outer.extend_from_slice(b"\x1b[6;16;8t\x1b[?62;22;52c");
    let run = FakeTerminal::new(&[(1, b"\x1b[?2026;2$y\x1b[?1;2c"), (20, &outer)]).run(&options(true));
    let s = &run.outcome.support;
    assert!(s.answered && s.tmux && s.tmux_passthrough && s.kitty && s.kitty_placeholders, "{s:?}");
    assert_eq!((s.sixel, s.cell_px, s.sgr_pixels_mouse), (None, Some((8, 16)), false));
    assert_eq!(run.took, 20 * MS, "done at the outer terminal's DA1");
    assert_eq!(
        choose(GraphicsRequest::Auto, Some(s)),
        GraphicsChoice { mode: GraphicsMode::Kitty, tmux_wrap: true, kitty_placeholders: true, hint: None }
    );
    // kitty without placeholders (0.26, silent on `U=1`): cells and a hint, even with
    // passthrough.
    let run_old = FakeTerminal::new(&[(1, b"\x1b[?1;2c"), (20, b"\x1b_Gi=31;OK\x1b\\\x1b[?62;c")]).run(&options(true));
    let old = &run_old.outcome.support;
    assert!(old.kitty && old.tmux_passthrough && !old.kitty_placeholders);
    assert_eq!(
        choose(GraphicsRequest::Auto, Some(old)),
        GraphicsChoice {
            mode: GraphicsMode::Cells,
            tmux_wrap: false,
            kitty_placeholders: false,
            hint: Some(PLACEHOLDER_HINT)
        }
    );
    // Passthrough shown by the outer terminal's DA1 alone (xterm in tmux): no hint, cells.
    let xterm = FakeTerminal::new(&[(1, b"\x1b[?1;2c"), (5, XTERM_DA1)]).run(&options(true)).outcome.support;
    assert!(xterm.tmux_passthrough && !xterm.kitty && xterm.sixel.is_none(), "tmux's own DA1 decides sixel");
    assert_eq!(
        choose(GraphicsRequest::Auto, Some(&xterm)),
        GraphicsChoice { mode: GraphicsMode::Cells, tmux_wrap: false, kitty_placeholders: false, hint: None }
    );
    // What went out: tmux's own queries plain, DA1 among them before anything wrapped; the
    // kitty query wrapped.
    let first_wrap = run.written.windows(7).position(|w| w == tmux::PASSTHROUGH_BEGIN).unwrap();
    let plain_da1 = run.written.windows(3).position(|w| w == b"\x1b[c").unwrap();
    assert!(plain_da1 < first_wrap);
    let state = kitty_decode::decode(&run.written).unwrap();
    assert!(state.commands.iter().any(|k| k.get(&'a').map(String::as_str) == Some("q")));
    // After tmux's own queries, everything is wrapped.
    let mut rest = &run.written[first_wrap..];
    while !rest.is_empty() {
        let (_, len) = tmux::unwrap(rest).expect("only passthrough sequences after the plain ones");
        rest = &rest[len..];
    }
}

#[test]
fn tmux_without_passthrough_gets_cells_and_a_hint() {
    let run = FakeTerminal::new(&[(1, b"\x1b[?2026;2$y\x1b[?1;2c")]).run(&options(true));
    let s = &run.outcome.support;
    assert!(s.answered && s.tmux && !s.tmux_passthrough && !s.kitty);
    assert_eq!(run.took, PROBE_BUDGET, "waits for an outer answer that never comes");
    assert_eq!(
        choose(GraphicsRequest::Auto, Some(s)),
        GraphicsChoice {
            mode: GraphicsMode::Cells,
            tmux_wrap: false,
            kitty_placeholders: false,
            hint: Some(TMUX_HINT)
        }
    );
    // tmux that draws sixel itself says so in its own DA1.
    let s = FakeTerminal::new(&[(1, b"\x1b[?1;2;4c")]).run(&options(true)).outcome.support;
    assert_eq!(choose(GraphicsRequest::Auto, Some(&s)).mode, GraphicsMode::Sixel);
    // Forcing kitty there would draw nothing: cells and the hint.
    let forced = choose(GraphicsRequest::Force(GraphicsMode::Kitty), Some(&run.outcome.support));
    assert_eq!((forced.mode, forced.hint), (GraphicsMode::Cells, Some(TMUX_HINT)));
}

#[test]
fn iterm2_by_its_reply_or_by_name_as_a_fallback() {
    let run =
        FakeTerminal::new(&[(2, b"\x1b]1337;ReportCellSize=17.0;8.0;2.0\x1b\\\x1b[?62;22c")]).run(&options(false));
    let s = &run.outcome.support;
    assert!(s.iterm2 && s.answered);
    assert_eq!(s.cell_px, Some((16, 34)), "points times scale");
    assert_eq!(choose(GraphicsRequest::Auto, Some(s)).mode, GraphicsMode::Iterm2);
    let mut by_name = options(false);
    by_name.env.term_program = Some("iTerm.app".into());
    assert!(FakeTerminal::new(&[(2, b"\x1b[?62;22c")]).run(&by_name).outcome.support.iterm2);
    assert!(!FakeTerminal::new(&[]).run(&by_name).outcome.support.iterm2, "a name without an answer is nothing");
}

#[test]
fn the_window_size_pixels_come_first() {
    let mut o = options(false);
    o.winsize = WinSize { cols: 100, rows: 40, x_px: 1000, y_px: 800 };
    let s = FakeTerminal::new(&[(1, b"\x1b[6;16;8t\x1b[?62c")]).run(&o).outcome.support;
    assert_eq!(s.cell_px, Some((10, 20)));
    // No pixels anywhere but the text area: divided by the grid.
    let s = FakeTerminal::new(&[(1, b"\x1b[4;800;1000t\x1b[?62c")]).run(&options(false)).outcome.support;
    assert_eq!(s.cell_px, Some((6, 16)), "1000/160, 800/48");
}

#[test]
fn the_file_query_is_sent_only_on_this_machine() {
    let mut o = options(false);
    o.kitty_file = Some("/dev/shm/tidepool-1-tty-graphics-protocol.rgb".into());
    let q = String::from_utf8(queries(&o)).unwrap();
    assert!(q.contains(&format!("i={KITTY_FILE_QUERY_ID},s=1,v=1,a=q,t=t")), "{q:?}");
    let reply = format!("\x1b_Gi={KITTY_FILE_QUERY_ID};OK\x1b\\\x1b[?62c");
    assert!(FakeTerminal::new(&[(1, reply.as_bytes())]).run(&o).outcome.support.kitty_temp_file);
    o.env.ssh = true;
    assert!(!String::from_utf8(queries(&o)).unwrap().contains("t=t"));
}

#[test]
fn queries_end_with_da1_and_carry_every_question() {
    let q = queries(&options(false));
    assert!(q.ends_with(b"\x1b[c"));
    let text = String::from_utf8_lossy(&q);
    for part in [
        "a=q",
        "\x1b[?1;1;0S",
        "\x1b[?2;1;0S",
        "\x1b[16t",
        "\x1b[14t",
        "\x1b[?1016$p",
        "\x1b[?2026$p",
        "1337;ReportCellSize",
    ] {
        assert!(text.contains(part), "{part:?} missing");
    }
    // The frame-edit test edits and deletes its scratch image.
    let state = kitty_decode::decode(&q).unwrap();
    let actions: Vec<&str> = state.commands.iter().map(|k| k.get(&'a').map_or("t", String::as_str)).collect();
    assert_eq!(actions, ["q", "t", "f", "d", "t", "p", "d"]);
    assert!(state.images.is_empty(), "the scratch images are deleted");
    assert!(state.commands[5].get(&'U').is_some_and(|u| u == "1") && !state.commands[5].contains_key(&'q'), "answered");
}

#[test]
fn no_terminal_no_query() {
    assert!(!should_probe(true, false) && !should_probe(false, true) && should_probe(true, true));
    assert_eq!(choose(GraphicsRequest::Auto, None).mode, GraphicsMode::Cells);
    assert_eq!(choose(GraphicsRequest::Force(GraphicsMode::Sixel), None).mode, GraphicsMode::Sixel);
    let env = EnvHints::from_lookup(|k| match k {
        "TMUX" => Some("/tmp/tmux-0/default,1,0".into()),
        "SSH_TTY" => Some("/dev/pts/1".into()),
        "TERM_PROGRAM" => Some(String::new()),
        _ => None,
    });
    assert_eq!(env, EnvHints { tmux: true, ssh: true, term_program: None });
}

/// Through the Screen, as a player meets its terminal: answers at made-up times.
mod through_the_screen {
    use std::time::{Duration, Instant};

    use crate::output::color::ColorMode;
    use crate::output::diff::EncodeOptions;
    use crate::output::graphics::GraphicsMode;
    use crate::play::input::Input;
    use crate::play::screen::probe::{EnvHints, GraphicsRequest, PROBE_BUDGET, ProbeOptions, WinSize};
    use crate::play::screen::{Bandwidth, LATE_ANSWERS, Screen, ScreenConfig};

    const MS: Duration = Duration::from_millis(1);
    const KITTY: &[u8] = b"\x1b_Gi=31;OK\x1b\\";
    const DA1: &[u8] = b"\x1b[?62;22c";

    fn screen(t0: Instant) -> Screen {
        let config = ScreenConfig {
            fps: 30,
            bandwidth: Bandwidth::Unlimited,
            color: ColorMode::TrueColor,
            color_auto: false,
            colour_hint: false,
            encode: EncodeOptions::default(),
            graphics: GraphicsRequest::Auto,
            probe: Some(ProbeOptions {
                env: EnvHints { ssh: true, ..EnvHints::default() },
                winsize: WinSize { cols: 40, rows: 12, x_px: 320, y_px: 192 },
                kitty_file: None,
                colours: false,
            }),
            link_path: Default::default(),
        };
        let mut s = Screen::new(config, (40, 12), t0);
        s.start(t0, &mut Vec::new());
        s
    }

    /// Feeds `chunks` at their times (ms after t0), ticking the clock every 10 ms up to `until`
    /// ms; returns every input the screen handed on.
    fn run(s: &mut Screen, t0: Instant, chunks: &[(u64, &[u8])], until: u64) -> Vec<Input> {
        let mut inputs = Vec::new();
        for ms in (0..=until).step_by(10) {
            for (at, bytes) in chunks.iter().filter(|(at, _)| (ms.saturating_sub(9)..=ms).contains(at)) {
                s.feed(bytes, t0 + Duration::from_millis(*at), &mut inputs);
            }
            s.tick(t0 + Duration::from_millis(ms), &mut inputs);
        }
        inputs
    }

    #[test]
    fn the_first_deadline_covers_a_far_terminal_and_da1_ends_the_wait_at_once() {
        // A terminal a 300 ms round trip away (another continent): pixels from the first frame.
        let t0 = Instant::now();
        let mut s = screen(t0);
        let inputs = run(&mut s, t0, &[(300, &[KITTY, DA1].concat())], 300);
        assert!(!s.probing() && s.mode() == GraphicsMode::Kitty, "no cells first");
        assert!(inputs.is_empty());
        // A near one: the wait ends with its DA1, not at the deadline.
        let mut near = screen(t0);
        near.feed(&[KITTY, DA1].concat(), t0 + 3 * MS, &mut Vec::new());
        assert!(!near.probing() && near.ready(t0 + 3 * MS, true));
    }

    #[test]
    fn an_answer_after_the_deadline_upgrades_cells_and_becomes_no_key() {
        let t0 = Instant::now();
        let mut s = screen(t0);
        let late = PROBE_BUDGET.as_millis() as u64 + 400;
        // `_`, `=` and `?` would be keys if the answer were read as typing.
        let answer = [&b"\x1b[?1;0;256S\x1b[?2;0;1000;1000S\x1b[6;16;8t"[..], KITTY, DA1].concat();
        let inputs = run(&mut s, t0, &[(late, &answer)], late + 100);
        assert_eq!(s.mode(), GraphicsMode::Kitty, "upgraded when the answer came");
        assert!(s.take_notice().is_some_and(|n| n.contains("answered late")));
        assert!(inputs.is_empty(), "no answer became a key: {inputs:?}");
    }

    #[test]
    fn garbage_before_the_answer_means_cells_and_no_keys() {
        let t0 = Instant::now();
        let mut s = screen(t0);
        let garbage = [&b"\x1b[?62;4\x01c\x1b[[[9~\x1b_Gi=31;O\x1bK\x1b\\"[..], KITTY, DA1].concat();
        let inputs = run(&mut s, t0, &[(20, &garbage)], 100 + LATE_ANSWERS.as_millis() as u64);
        assert_eq!(s.mode(), GraphicsMode::Cells);
        assert!(
            inputs.iter().all(|i| !matches!(i, Input::Other('_' | '=' | '?') | Input::Help)),
            "no part of an answer became a key: {inputs:?}"
        );
    }

    #[test]
    fn a_partial_answer_draws_cells_until_the_rest_comes_or_says_the_terminal_did_not_answer() {
        let t0 = Instant::now();
        let budget = PROBE_BUDGET.as_millis() as u64;
        // kitty's OK, then nothing until after the deadline: cells, then the rest upgrades.
        let mut s = screen(t0);
        let inputs = run(&mut s, t0, &[(20, KITTY), (budget + 800, DA1)], budget + 900);
        assert_eq!(s.mode(), GraphicsMode::Kitty);
        assert!(inputs.is_empty());
        // Only the sixel registers, and DA1 never: cells, and after the late window the
        // status line says so.
        let mut silent = screen(t0);
        let until = budget + LATE_ANSWERS.as_millis() as u64 + 20;
        let inputs = run(&mut silent, t0, &[(20, b"\x1b[?1;0;256S")], until);
        assert_eq!(silent.mode(), GraphicsMode::Cells);
        assert!(silent.take_notice().is_some_and(|n| n.contains("did not answer")));
        assert!(inputs.is_empty(), "{inputs:?}");
    }
}

#[test]
fn a_forced_protocol_the_answers_rule_out_draws_cells_and_says_why() {
    let kitty = GraphicsRequest::Force(GraphicsMode::Kitty);
    let sixel = GraphicsRequest::Force(GraphicsMode::Sixel);
    let answered = GraphicsSupport { answered: true, ..GraphicsSupport::default() };
    let with_kitty = GraphicsSupport { kitty: true, ..answered.clone() };
    assert_eq!(choose(kitty, Some(&with_kitty)).mode, GraphicsMode::Kitty);
    assert_eq!(
        choose(kitty, Some(&answered)),
        GraphicsChoice { hint: Some(NO_KITTY), ..choose(GraphicsRequest::Auto, None) }
    );
    assert_eq!(choose(sixel, Some(&answered)).hint, Some(NO_SIXEL));
    assert_eq!(choose(sixel, Some(&answered)).mode, GraphicsMode::Cells);
    let with_sixel =
        GraphicsSupport { sixel: Some(SixelSupport { registers: 256, max_w: None, max_h: None }), ..answered.clone() };
    assert_eq!(choose(sixel, Some(&with_sixel)).mode, GraphicsMode::Sixel);
    // Nothing answered: nothing is known, so the protocol is used as asked.
    let silent = GraphicsSupport::default();
    assert_eq!(choose(kitty, Some(&silent)).mode, GraphicsMode::Kitty);
    assert_eq!(choose(sixel, Some(&silent)).mode, GraphicsMode::Sixel);
    // iTerm2 has no query others answer: as asked.
    assert_eq!(choose(GraphicsRequest::Force(GraphicsMode::Iterm2), Some(&answered)).mode, GraphicsMode::Iterm2);
    // tmux passing kitty through without placeholders (kitty 0.26 outside).
    let tmux = GraphicsSupport { tmux: true, tmux_passthrough: true, ..with_kitty };
    assert_eq!(choose(kitty, Some(&tmux)).hint, Some(PLACEHOLDER_HINT));
    let tmux = GraphicsSupport { kitty_placeholders: true, ..tmux };
    assert_eq!(choose(kitty, Some(&tmux)).mode, GraphicsMode::Kitty);
}

#[test]
fn true_colour_answers_are_read_and_a_palette_index_is_not_one() {
    let with = |answer: &[u8]| FakeTerminal::new(&[(1, &[answer, XTERM_DA1].concat())]).run(&options(false));
    for yes in [
        &b"\x1bP1+r524742\x1b\\"[..],
        b"\x1bP0+r524742\x1b\\\x1bP1+r5463=\x1b\\",
        b"\x1bP1$r0;38:2::1:2:3m\x1b\\",
        b"\x1bP1$r0;38:2:1:2:3m\x1b\\",
        b"\x1bP1$r38;2;1;2;3m\x1b\\",
    ] {
        assert!(with(yes).outcome.support.true_color, "{:?}", String::from_utf8_lossy(yes));
    }
    for no in [
        &b"\x1bP0+r524742\x1b\\\x1bP0+r5463\x1b\\"[..],
        b"\x1bP1$r0;38:5:16m\x1b\\",
        b"\x1bP1$r0;38:2::11:2:3m\x1b\\",
        b"\x1bP0$r\x1b\\",
        b"",
    ] {
        assert!(!with(no).outcome.support.true_color, "{:?}", String::from_utf8_lossy(no));
    }
    let has = |hay: &[u8], needle: &[u8]| hay.windows(needle.len()).any(|w| w == needle);
    assert!(has(&queries(&options(false)), COLOUR_QUERIES));
    let quiet = ProbeOptions { colours: false, ..options(false) };
    assert!(!has(&queries(&quiet), b"\x1bP+q"), "no colour question unless asked for");
}
