use super::*;

fn complete(bytes: &[u8]) -> (Reply, usize) {
    match parse_reply(bytes, Expecting::NOTHING) {
        Parsed::Complete(r, n) => (r, n),
        other => panic!("{:?}: {other:?}", String::from_utf8_lossy(bytes)),
    }
}

/// Every reply the probe asks for, as terminals send them, with what it parses to.
fn samples() -> Vec<(&'static [u8], Reply)> {
    vec![
        (b"\x1b_Gi=31;OK\x1b\\", Reply::KittyGraphics { id: Some(31), message: "OK".into() }),
        (
            b"\x1b_Gi=32;ENOENT:no such file\x1b\\",
            Reply::KittyGraphics { id: Some(32), message: "ENOENT:no such file".into() },
        ),
        (b"\x1b_Gi=99,I=13;OK\x1b\\", Reply::KittyGraphics { id: Some(99), message: "OK".into() }),
        (b"\x1b[?62;4;22c", Reply::PrimaryAttributes(vec![62, 4, 22])),
        (b"\x1b[?64;1;2;4;6;17;18;21;22c", Reply::PrimaryAttributes(vec![64, 1, 2, 4, 6, 17, 18, 21, 22])),
        (b"\x1b[>41;390;0c", Reply::SecondaryAttributes(vec![41, 390, 0])),
        (b"\x1b[?1;0;256S", Reply::GraphicsAttribute { item: 1, status: 0, values: vec![256] }),
        (b"\x1b[?2;0;1000;1000S", Reply::GraphicsAttribute { item: 2, status: 0, values: vec![1000, 1000] }),
        (b"\x1b[?2;3;0S", Reply::GraphicsAttribute { item: 2, status: 3, values: vec![0] }),
        (b"\x1b[6;16;8t", Reply::CellSize { width: 8, height: 16 }),
        (b"\x1b[4;752;1280t", Reply::TextAreaSize { width: 1280, height: 752 }),
        (b"\x1b[?1016;2$y", Reply::ModeReport { mode: 1016, state: 2, private: true }),
        (b"\x1b[?2026;0$y", Reply::ModeReport { mode: 2026, state: 0, private: true }),
        (b"\x1b[?12;7R", Reply::CursorPosition { row: 12, col: 7 }),
        (b"\x1bP1+r736978656c=31\x1b\\", Reply::Dcs(b"1+r736978656c=31".to_vec())),
        (b"\x1bP>|kitty(0.39.1)\x1b\\", Reply::Dcs(b">|kitty(0.39.1)".to_vec())),
        (b"\x1b]11;rgb:0000/0000/0000\x07", Reply::Osc(b"11;rgb:0000/0000/0000".to_vec())),
        (
            b"\x1b]1337;ReportCellSize=17.0;8.0;2.0\x1b\\",
            Reply::Iterm2CellSize { width: 8.0, height: 17.0, scale: 2.0 },
        ),
        (b"\x1b]1337;ReportCellSize=16;8\x07", Reply::Iterm2CellSize { width: 8.0, height: 16.0, scale: 1.0 }),
        (b"\x1b[?1u", Reply::OtherCsi(b"?1".to_vec(), b'u')),
        (b"\x1b[0n", Reply::DeviceStatus(0)),
    ]
}

#[test]
fn every_reply_is_recognised_with_its_length() {
    for (bytes, want) in samples() {
        let mut buf = bytes.to_vec();
        buf.extend_from_slice(b"5q");
        assert_eq!(complete(&buf), (want, bytes.len()), "{:?}", String::from_utf8_lossy(bytes));
    }
}

#[test]
fn every_proper_prefix_is_incomplete() {
    for (bytes, _) in samples() {
        for end in 0..bytes.len() {
            assert_eq!(
                parse_reply(&bytes[..end], Expecting::NOTHING),
                Parsed::Incomplete,
                "{:?}",
                String::from_utf8_lossy(&bytes[..end])
            );
        }
    }
}

#[test]
fn keys_are_not_replies() {
    let keys: [&[u8]; 14] = [
        b"a",
        b"5",
        b" ",
        b"\x1b[A",             // up
        b"\x1b[1;5A",          // ctrl-up
        b"\x1bOP",             // F1
        b"\x1b[15~",           // F5
        b"\x1b[200~hi",        // bracketed paste
        b"\x1b[<0;10;5M",      // SGR mouse press
        b"\x1ba",              // Alt-a
        b"\x1bPa",             // Alt-P, a
        b"\x1b_x",             // Alt-_, x
        b"\x1b]\r",            // Alt-], Enter
        b"\x1bP1\rmore bytes", // Alt-P, 1, Enter: a control byte ends the candidate
    ];
    for k in keys {
        assert_eq!(parse_reply(k, Expecting::NOTHING), Parsed::NotAReply, "{:?}", String::from_utf8_lossy(k));
    }
}

#[test]
fn a_cursor_report_is_a_reply_only_while_one_is_awaited() {
    // `CSI 1 ; 5 R` is Ctrl-F3 in some terminals: a key unless a report is outstanding.
    assert_eq!(parse_reply(b"\x1b[1;5R", Expecting::NOTHING), Parsed::NotAReply);
    assert_eq!(
        parse_reply(b"\x1b[1;5R", Expecting::CURSOR_POSITION),
        Parsed::Complete(Reply::CursorPosition { row: 1, col: 5 }, 6)
    );
    // DECXCPR carries a `?`: always a reply.
    assert_eq!(complete(b"\x1b[?1;5R").0, Reply::CursorPosition { row: 1, col: 5 });
}

#[test]
fn a_late_kitty_reply_leaves_no_digits_behind() {
    // The bytes a late reply would have become: Alt-_, G, i, =, 3, 1... the `3` and `1` would
    // have set the Beaufort number. Recognised whole, only the user's key remains.
    let stream = b"\x1b_Gi=31;OK\x1b\\\x1b_Gi=32;EBADF:bad file\x1b\\3";
    let mut rest: &[u8] = stream;
    let mut replies = 0;
    while let Parsed::Complete(_, n) = parse_reply(rest, Expecting::NOTHING) {
        rest = &rest[n..];
        replies += 1;
    }
    assert_eq!((replies, rest), (2, &b"3"[..]));
}

#[test]
fn bounds_hold() {
    // A string reply with no end is dropped at the bound, not waited for forever.
    let mut long = b"\x1b_G".to_vec();
    long.extend(std::iter::repeat_n(b'A', 2 * MAX_STRING_REPLY));
    assert_eq!(parse_reply(&long, Expecting::NOTHING), Parsed::Complete(Reply::Overlong, MAX_STRING_REPLY));
    assert_eq!(parse_reply(&long[..MAX_STRING_REPLY - 1], Expecting::NOTHING), Parsed::Incomplete);
    // A CSI that never ends is not a reply.
    let mut csi = b"\x1b[?".to_vec();
    csi.extend(std::iter::repeat_n(b'1', MAX_CSI_REPLY));
    assert_eq!(parse_reply(&csi, Expecting::NOTHING), Parsed::NotAReply);
    // Numbers that overflow, or too many of them, are garbage.
    assert_eq!(parse_reply(b"\x1b[?99999999999c", Expecting::NOTHING), Parsed::NotAReply);
    let many = format!("\x1b[?{}c", ["1"; 40].join(";"));
    assert_eq!(parse_reply(many.as_bytes(), Expecting::NOTHING), Parsed::NotAReply);
}

#[test]
fn garbled_replies_are_not_replies() {
    let garbled: [&[u8]; 5] = [
        b"\x1b_Gi=31;O\x1bK\x1b\\", // ESC inside a string not followed by `\`
        b"\x1b[?62;4\x01c",         // a control byte inside a CSI
        b"\x1b[?1;2$z",             // an unknown reply shape
        b"\x1b[6;16t",              // a cell size with a value missing
        b"\x1b_Gi=31;\xffOK\x1b\\", // a non-text byte in a string
    ];
    for g in garbled {
        assert_eq!(parse_reply(g, Expecting::NOTHING), Parsed::NotAReply, "{:?}", String::from_utf8_lossy(g));
    }
}
