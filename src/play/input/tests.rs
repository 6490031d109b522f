use super::*;

/// Everything the bytes mean.
fn received(bytes: &[u8]) -> Vec<Received> {
    let mut p = InputParser::new();
    let mut out = Vec::new();
    let t = Instant::now();
    p.feed(bytes, t, &mut out);
    p.flush_stale(t + ESC_WAIT, &mut out);
    out
}

/// The person's inputs among them.
fn parse(bytes: &[u8]) -> Vec<Input> {
    inputs(received(bytes))
}

fn inputs(received: Vec<Received>) -> Vec<Input> {
    received
        .into_iter()
        .filter_map(|r| match r {
            Received::Input(i) => Some(i),
            _ => None,
        })
        .collect()
}

#[test]
fn keys() {
    assert_eq!(parse(b"q"), vec![Input::Quit]);
    assert_eq!(parse(b" j[w"), vec![Input::RandomStone, Input::Aim(0, 1), Input::Damping(true), Input::Other('w')]);
    assert_eq!(parse(b"\x03"), vec![Input::Quit]);
    assert_eq!(parse(b"\x18\x7f"), vec![], "other control keys mean nothing");
    assert_eq!(parse(b"\r\t"), vec![Input::DropAtAim, Input::NextScene]);
    assert_eq!(parse("é".as_bytes()), vec![Input::Other('é')]);
    assert_eq!(
        parse(b"\x1b[A\x1b[D\x1bOB\x1b[Z"),
        vec![Input::Aim(0, -1), Input::Aim(-1, 0), Input::Aim(0, 1), Input::NextScene]
    );
    assert_eq!(parse(b"\x1b[1;5C"), vec![], "modified arrows are not aim keys");
    assert_eq!(parse(b"\x1bq"), vec![], "Alt-q does not quit");
}

#[test]
fn a_lone_escape_waits_for_what_follows() {
    let mut p = InputParser::new();
    let mut out = Vec::new();
    let t = Instant::now();
    p.feed(b"\x1b", t, &mut out);
    assert!(out.is_empty(), "could be the start of a sequence");
    assert_eq!(p.deadline(), Some(t + ESC_WAIT));
    p.flush_stale(t + ESC_WAIT / 2, &mut out);
    assert!(out.is_empty());
    p.feed(b"[B", t + Duration::from_millis(5), &mut out);
    assert_eq!(inputs(std::mem::take(&mut out)), vec![Input::Aim(0, 1)], "an arrow split across reads");
    p.feed(b"\x1b", t, &mut out);
    p.flush_stale(t + ESC_WAIT, &mut out);
    assert_eq!(inputs(out), vec![Input::Escape]);
    assert_eq!(p.deadline(), None);
}

#[test]
fn mouse_reports() {
    assert_eq!(parse(b"\x1b[<0;4;5M"), vec![Input::Press { col: 3, row: 4, big: false }]);
    assert_eq!(parse(b"\x1b[<2;1;1M"), vec![Input::Press { col: 0, row: 0, big: true }]);
    assert_eq!(parse(b"\x1b[<32;10;2M"), vec![Input::Drag { col: 9, row: 1 }]);
    assert_eq!(parse(b"\x1b[<0;10;2m"), vec![Input::Release]);
    assert_eq!(parse(b"\x1b[<64;10;2M"), vec![], "the wheel");
    assert_eq!(parse(b"\x1b[M !!"), vec![Input::Press { col: 0, row: 0, big: false }], "X10 form");
    assert_eq!(parse(b"\x1b[M#!!"), vec![Input::Release]);
}

#[test]
fn terminal_replies_are_never_keys() {
    // A kitty graphics reply, device attributes, a mode report, a cell size, XTSMGRAPHICS,
    // an OSC colour reply and an XTGETTCAP reply, in one burst with one real key after them.
    let burst = b"\x1b_Gi=31;OK\x1b\\\x1b[>1;10;0c\x1b[?1016;2$y\x1b[6;16;8t\x1b[?1;0;256S\x1b]11;rgb:0000/0000/0000\x07\x1bP1+r544e=787465726d\x1b\\5";
    assert_eq!(parse(burst), vec![Input::Other('5')]);
    let all = received(burst);
    assert_eq!(all.iter().filter(|r| matches!(r, Received::Reply(_))).count(), 7, "{all:?}");
    assert_eq!(
        received(b"\x1b[?62;4;22c"),
        vec![Received::Reply(Reply::PrimaryAttributes(vec![62, 4, 22]))],
        "the round trip's answer"
    );
    assert_eq!(received(b"\x1b[12;40R"), vec![Received::Reply(Reply::CursorPosition { row: 12, col: 40 })]);
}

#[test]
fn alt_p_and_a_letter_are_keys_to_the_reply_reader_and_the_key_reader_alike() {
    // `ESC P` starts a DCS reply only when a digit or `>` follows (what tidepool asks for);
    // Alt-P then `q` is a key press, and the `q` still quits.
    assert_eq!(received(b"\x1bPq"), vec![Received::Unknown, Received::Input(Input::Quit)]);
    assert_eq!(received(b"\x1b]q"), vec![Received::Unknown, Received::Input(Input::Quit)]);
    // A DCS reply is one reply however its body reads.
    assert_eq!(
        received(b"\x1bP>|kitty(0.26.5)\x1b\\q"),
        vec![Received::Reply(Reply::Dcs(b">|kitty(0.26.5)".to_vec())), Received::Input(Input::Quit)]
    );
}

#[test]
fn an_overlong_reply_is_dropped_to_its_end() {
    let mut bytes = b"\x1b_G".to_vec();
    bytes.extend(std::iter::repeat_n(b'7', 2 * crate::play::replies::MAX_STRING_REPLY));
    bytes.extend_from_slice(b"\x1b\\r");
    assert_eq!(parse(&bytes), vec![Input::ToggleRain], "no digit of the string is a key");
}

#[test]
fn a_reply_split_across_reads_is_still_dropped() {
    let mut p = InputParser::new();
    let mut out = Vec::new();
    let t = Instant::now();
    for chunk in [&b"\x1b_Gi=3"[..], b"1;OK", b"\x1b", b"\\7"] {
        p.feed(chunk, t, &mut out);
    }
    assert_eq!(inputs(out), vec![Input::Other('7')], "the digits of the reply do not leak");
}

#[test]
fn endless_garbage_is_bounded() {
    let mut p = InputParser::new();
    let mut out = Vec::new();
    let t = Instant::now();
    p.feed(b"\x1b_G", t, &mut out);
    for _ in 0..10 {
        p.feed(&[b'x'; 1000], t, &mut out);
    }
    assert!(inputs(std::mem::take(&mut out)).is_empty());
    p.feed(b"q", t, &mut out);
    assert!(p.pending.len() <= MAX_SEQUENCE);
}

#[test]
fn drags_coalesce_to_their_last_position() {
    let drag = |col| Input::Drag { col, row: 1 };
    let mut inputs = vec![drag(1), drag(2), drag(3), Input::Clear, drag(4), Input::Release, drag(5), drag(6)];
    coalesce(&mut inputs);
    assert_eq!(inputs, vec![drag(3), Input::Clear, drag(4), Input::Release, drag(6)]);
    let mut many: Vec<Input> = (0..10_000).map(|i| drag(i as u16)).collect();
    coalesce(&mut many);
    assert_eq!(many, vec![drag(9_999)]);
}

mod properties {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// No bytes make the parser panic, in any split, and what is pending stays bounded.
        #[test]
        fn any_bytes_any_split(bytes in proptest::collection::vec(any::<u8>(), 0..400), cut in 0usize..400) {
            let mut p = InputParser::new();
            let mut out = Vec::new();
            let t = Instant::now();
            let cut = cut.min(bytes.len());
            p.feed(&bytes[..cut], t, &mut out);
            p.feed(&bytes[cut..], t, &mut out);
            p.flush_stale(t + ESC_WAIT, &mut out);
            prop_assert!(p.pending.is_empty());
        }

        /// Printable ASCII typed in any split gives the same inputs as typed at once.
        #[test]
        fn splits_do_not_change_keys(text in "[ -~]{0,40}", cut in 0usize..40) {
            let whole = parse(text.as_bytes());
            let mut p = InputParser::new();
            let mut out = Vec::new();
            let t = Instant::now();
            let cut = cut.min(text.len());
            p.feed(&text.as_bytes()[..cut], t, &mut out);
            p.feed(&text.as_bytes()[cut..], t, &mut out);
            prop_assert_eq!(inputs(out), whole);
        }
    }
}
