//! `tidepool serve --bus`: the flags of one pool across many machines (feature `bus`).

use std::path::PathBuf;

use clap::Args;

/// The bus's flags.
#[derive(Args, Debug, Clone)]
pub struct BusArgs {
    /// Share one pool with every `tidepool serve` on this NATS server (JetStream on:
    /// `nats-server -js`): `nats://HOST:4222`, or `tls://HOST:4222` for TLS. Each machine
    /// runs the same command; the pool, its settings and seed are the same on all of them.
    #[arg(long, value_name = "nats://HOST:PORT")]
    pub bus: Option<String>,

    /// The pool's name on the bus (letters, digits, '-' and '_'); edges with the same name
    /// share one pool.
    #[arg(long, value_name = "NAME", default_value = "main")]
    pub pool: String,

    /// This machine's name on the bus [default: the host name and the process id].
    #[arg(long, value_name = "NAME", requires = "bus")]
    pub bus_edge: Option<String>,

    /// A NATS credentials file (the user's JWT and nkey seed, from `nsc`).
    #[arg(long, value_name = "FILE", requires = "bus")]
    pub bus_credentials: Option<PathBuf>,

    /// Trust this CA certificate (PEM) for the bus's TLS certificate; TLS is then required.
    #[arg(long, value_name = "FILE", requires = "bus")]
    pub bus_ca: Option<PathBuf>,

    /// Save the pool's picture here when a player presses `s` (every machine with this flag
    /// saves the same step: tidepool-pool-STEP.png).
    #[arg(long, value_name = "DIR", requires = "bus")]
    pub bus_shots: Option<PathBuf>,
}
