//! `tidepool serve` as players meet it: the real binary, in-process russh clients (and the
//! real OpenSSH client where it is installed).

mod bad_input;
/// One pool across machines over NATS (needs nats-server: scripts/bus_tests.sh).
#[cfg(feature = "bus")]
mod bus;
/// The bus's figures (ignored: scripts/bus_tests.sh load).
#[cfg(feature = "bus")]
mod bus_load;
mod common;
/// A crowd of players in a process of its own (ignored: scripts/bus_scale.sh).
mod crowd_client;
/// Fake graphics terminals (shared with the integration tests).
#[allow(dead_code)]
#[path = "../integration/common/fake_terminal/mod.rs"]
mod fake_terminal;
mod fake_terminals;
mod groups;
mod limits;
mod load;
mod openssh;
/// The local player in a pseudo-terminal (shared with the integration tests).
#[allow(dead_code)]
#[path = "../integration/common/pty.rs"]
mod pty;
mod session;
mod two_doors;
mod walls;
