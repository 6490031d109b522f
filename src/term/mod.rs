//! The door of this process's own terminal (and of any byte stream that stands for one): the
//! play session's host, seat and screen driven by one loop ([`door`]), the tty's raw mode and
//! its restore on every way out ([`tty`]), and the writer thread that never queues frames
//! ([`writer`]). Everything the session decides lives in [`crate::play`]; this is I/O only.

mod arrivals;
pub mod door;
pub(crate) mod probe;
pub mod tty;
pub mod writer;
