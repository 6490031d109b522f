//! The graphics probe run to its end at once, for a picture written once to this process's
//! terminal (`render --out -`): the questions written, the answers read until they are complete
//! or the budget has passed. The play session asks without blocking (its screen's probe);
//! this is the door's blocking loop around the same sans-IO [`Probe`].

use std::io;
use std::time::{Duration, Instant};

use crate::play::input::InputParser;
use crate::play::screen::probe::{Probe, ProbeOptions, ProbeOutcome, queries};

/// Sends the queries with `write`, reads the answers with `read_with_deadline` until they are
/// complete or `budget` has passed (measured with `now`), and folds them. `read_with_deadline`
/// reads what is available into the buffer, waiting at most until the deadline, and returns 0
/// when the deadline passed with nothing to read (a real one polls the tty's descriptor).
pub fn run_probe(
    options: &ProbeOptions,
    write: &mut dyn FnMut(&[u8]) -> io::Result<()>,
    read_with_deadline: &mut dyn FnMut(&mut [u8], Instant) -> io::Result<usize>,
    now: &dyn Fn() -> Instant,
    budget: Duration,
) -> io::Result<ProbeOutcome> {
    let deadline = now() + budget;
    write(&queries(options))?;
    let mut probe = Probe::new(options.clone());
    let mut parser = InputParser::new();
    let mut received = Vec::new();
    let mut buf = [0u8; 4096];
    while !probe.done() && now() < deadline {
        let n = read_with_deadline(&mut buf, deadline)?;
        probe.count_bytes(n);
        parser.feed(&buf[..n], now(), &mut received);
        for r in received.drain(..) {
            probe.receive(r);
        }
    }
    Ok(probe.finish())
}
