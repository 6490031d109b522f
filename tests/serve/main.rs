//! `tidepool serve` as players meet it: the real binary, in-process russh clients (and the
//! real OpenSSH client where it is installed).

mod bad_input;
mod common;
mod limits;
mod load;
mod openssh;
mod session;
