//! `auto`'s switch from kitty pictures to half-block cells, as a user over a link meets it: the
//! fake kitty's link slows down (the pty's bytes are taken at 30 kB/s), `play` leaves its
//! pictures for cells, and the link recovers: `auto` comes back to pictures. Between the first picture and `q`, no moment
//! outside a synchronized update may leave the picture area blank: neither kitty's image placed
//! nor the cells painted (a switch used to delete the image and clear the screen first: about a
//! second of black).

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, PoisonError};
use std::time::{Duration, Instant};

use crate::common::fake_terminal::{FakeTerminal, Profile};
use crate::common::pty::{Player, temp_dir};

const COLS: usize = 160;
const ROWS: usize = 48;
/// The slow link's rate, bytes a second: below kitty's crossover (50 kB/s) by more than the
/// switch's margin.
const SLOW: u64 = 30_000;
/// Bound for each phase (a hang only: the switches come within seconds).
const PHASE: Duration = Duration::from_secs(60);

/// What the fake saw, checked after every chunk it took.
#[derive(Default)]
struct Seen {
    /// A kitty picture was shown.
    pictured: bool,
    /// The moments the picture area was blank (time since the start, status line).
    blank: Vec<(f64, String)>,
    /// The switch to cells happened (the image taken away, the cells painted).
    in_cells: bool,
    /// The switch back happened (the image shown again, the cells blank under it).
    in_pixels: bool,
    /// `q` was sent: the image is deleted on the way out.
    quitting: bool,
    /// The status line's notices as they changed (time, text), for the failure's message.
    notices: Vec<(f64, String)>,
}

/// The share of the half-block pixels above the status line that show a colour.
fn painted(fake: &FakeTerminal) -> f64 {
    let (cols, rows) = (fake.screen.cols(), fake.screen.rows());
    let all = cols * 2 * (rows - 1);
    let some =
        (0..2 * (rows - 1)).map(|y| (0..cols).filter(|&x| fake.screen.pixel(x, y).is_some()).count()).sum::<usize>();
    some as f64 / all as f64
}

fn image_shown(fake: &FakeTerminal) -> bool {
    fake.placed.keys().any(|&id| fake.kitty_shown(id))
}

/// Waits until `done` says so (checked every 50 ms), at most [`PHASE`]; whether it did.
fn wait_for(seen: &Mutex<Seen>, fake: &Mutex<FakeTerminal>, done: impl Fn(&Seen, &FakeTerminal) -> bool) -> bool {
    let until = Instant::now() + PHASE;
    while Instant::now() < until {
        // In the responder's order (the fake, then what was seen): no deadlock. Both are let
        // go before the sleep: held through it (as they were), they kept the responder from
        // the pty's bytes for most of each 50 ms (a mutex is not fair), so the fake read at a
        // few kB/s, its answers came seconds late, and the switch took 20 to 60 s.
        let finished = {
            let f = fake.lock().unwrap();
            done(&seen.lock().unwrap(), &f)
        };
        if finished {
            return true;
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    false
}

#[test]
fn auto_leaving_kitty_pictures_for_cells_and_coming_back_never_shows_a_blank_picture_area() {
    let _alone = crate::fake_terminals::PLAYERS.write().unwrap_or_else(PoisonError::into_inner);
    let fake = Arc::new(Mutex::new(FakeTerminal::new(Profile::kitty_current(), COLS, ROWS)));
    let seen = Arc::new(Mutex::new(Seen::default()));
    // 0: no limit; else the link's rate in bytes a second.
    let rate = Arc::new(AtomicU64::new(0));
    let start = Instant::now();
    let respond = {
        let (fake, seen, rate) = (Arc::clone(&fake), Arc::clone(&seen), Arc::clone(&rate));
        move |chunk: &[u8]| {
            let r = rate.load(Ordering::Relaxed);
            if r > 0 {
                std::thread::sleep(Duration::from_secs_f64(chunk.len() as f64 / r as f64));
            }
            let mut f = fake.lock().unwrap();
            let answers = f.feed(chunk);
            // What the person sees: only outside a synchronized update.
            if f.screen.private_mode(2026) != Some(true) {
                let mut s = seen.lock().unwrap();
                let (image, painted) = (image_shown(&f), painted(&f));
                s.pictured |= image;
                if s.pictured && !s.quitting && !image && painted < 0.98 {
                    s.blank.push((start.elapsed().as_secs_f64(), f.status().trim_end().to_string()));
                }
                let status = f.status();
                let notice = status.rsplit("  ").next().unwrap_or("").trim().to_string();
                if s.notices.last().is_none_or(|(_, n)| *n != notice) {
                    s.notices.push((start.elapsed().as_secs_f64(), notice));
                }
                // The status line's notice may show only in part while the rate is low: the
                // switches are seen on the screen itself.
                s.in_pixels |= s.in_cells && image && painted < 0.02;
                s.in_cells |= s.pictured && !image && painted >= 0.98;
            }
            answers
        }
    };
    let env = [("TERM", "xterm-kitty"), ("COLORTERM", ""), ("SSH_CONNECTION", "10.227.0.1 50000 10.227.0.2 22")];
    let args = ["play", "--rain", "0.05"];
    let mut p = Player::spawn_responding(&temp_dir("fake-switch"), COLS as u16, ROWS as u16, &args, &env, respond);
    let pictured = wait_for(&seen, &fake, |s, _| s.pictured);
    std::thread::sleep(Duration::from_secs(2));
    // The link slows down: auto leaves the pictures for cells.
    rate.store(SLOW, Ordering::Relaxed);
    let to_cells = pictured && wait_for(&seen, &fake, |s, _| s.in_cells);
    let at_cells = start.elapsed().as_secs_f64();
    // It recovers: auto comes back to pictures once the rate has held over the crossover (and
    // at least `AutoSwitch::MIN_BETWEEN` after the last switch), and the way back is watched
    // for blank moments too, for two seconds after it.
    rate.store(0, Ordering::Relaxed);
    let to_pixels = to_cells && wait_for(&seen, &fake, |s, _| s.in_pixels);
    let at_pixels = start.elapsed().as_secs_f64();
    std::thread::sleep(Duration::from_secs(2));
    let status = fake.lock().unwrap().status().trim_end().to_string();
    seen.lock().unwrap().quitting = true;
    p.send(b"q");
    let _ = p.wait_exit(PHASE);
    let s = seen.lock().unwrap();
    println!(
        "switch: pictured {pictured}, cells {to_cells} at {at_cells:.1} s, pixels again {to_pixels} at {at_pixels:.1} s, \
         blank moments {}, status {status:?}\nnotices: {:?}",
        s.blank.len(),
        s.notices
    );
    assert!(
        pictured && to_cells && to_pixels,
        "the switches did not happen: pictured {pictured}, cells {to_cells}, pixels again {to_pixels}; status {status:?}"
    );
    assert!(
        s.blank.is_empty(),
        "{} moments with the picture area blank (neither image nor cells), first at {:.2} s ({:?}), last at {:.2} s",
        s.blank.len(),
        s.blank[0].0,
        s.blank[0].1,
        s.blank[s.blank.len() - 1].0
    );
}
