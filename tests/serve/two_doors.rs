//! One player, two doors: the same keys through this process's terminal (`tidepool play` in a
//! pseudo-terminal) and through `tidepool serve` (an SSH channel) reach the same seat and the
//! same screen code, so they draw the same help, the same stone sizes and the same messages.

use std::time::Duration;

use crate::common::*;
use crate::pty::{Player, temp_dir};

const WAIT: Duration = Duration::from_secs(20);
/// Still water in both doors, so the picture does not hide what the keys did.
const WATER: &[&str] = &["--rain", "0", "--breeze", "0", "--color", "truecolor", "--graphics", "cells"];

/// The help box's lines from its title to its last key (their text, without the picture's
/// half blocks around them).
fn help_rows(rows: impl Iterator<Item = String>) -> Vec<String> {
    let rows: Vec<String> = rows.collect();
    let first = rows.iter().position(|r| r.contains("tidepool keys")).unwrap_or(rows.len());
    let last = rows.iter().rposition(|r| r.contains("q esc ctrl-c")).unwrap_or(0);
    rows.iter()
        .take(last + 1)
        .skip(first)
        .map(|r| {
            let text: String = r.chars().filter(|c| !matches!(c, '\u{2580}' | '\u{2584}' | '\u{2588}')).collect();
            text.split_whitespace().collect::<Vec<_>>().join(" ")
        })
        .collect()
}

#[tokio::test]
async fn the_same_keys_through_the_terminal_and_through_ssh_draw_the_same_overlays() {
    // The terminal's door.
    let mut local = Player::spawn(&temp_dir("two-doors"), 80, 24, &[&["play"], WATER].concat(), &[]);
    local.wait_for_status("pool", WAIT);
    local.send(b"+?");
    local.wait_for_status("stone 4", WAIT);
    local.wait_until("the help", WAIT, |s| (0..s.rows()).any(|y| s.row_text(y).contains("tidepool keys")));
    let screen = local.screen();
    let local_help = help_rows((0..screen.rows()).map(|y| screen.row_text(y)));
    let local_status = screen.row_text(screen.rows() - 1);
    local.send(b"q");
    local.wait_exit(WAIT);

    // The SSH door, the same keys.
    let s = Server::start(TEST_FLAGS);
    let h = connect_none(s.port).await;
    let mut t = Term::new(open_shell(&h, "xterm-256color", 80, 24).await, 80, 24);
    t.read_until_status("1 playing").await;
    t.ch.data(&b"+?"[..]).await.unwrap();
    t.read_until_status("stone 4").await;
    t.read_until(|t| (0..t.screen.rows()).any(|y| t.screen.row_text(y).contains("tidepool keys"))).await;
    let remote_help = help_rows((0..t.screen.rows()).map(|y| t.screen.row_text(y)));

    assert!(!local_help.is_empty(), "the help is open");
    assert_eq!(local_help, remote_help, "the same help box");
    for door in [&local_status, &t.status()] {
        assert!(door.contains("stone 4"), "`+` stepped the stone size the same way: {door}");
    }
}
