//! What a player's task writes to and reads the time from: the SSH channel's write half and
//! tokio's clock in the server; memory and tokio's paused clock in the viewer's tests, which
//! then play a scripted session through the viewer's own loop (`viewer/tests.rs`).

use std::future::Future;
use std::time::Instant;

use bytes::Bytes;
use russh::ChannelWriteHalf;
use russh::server::Msg;

/// The time the player's task goes by: tokio's clock as a [`std::time::Instant`]. In the
/// server it reads the system's monotonic clock, as `Instant::now()` does; under a test's
/// paused runtime (`tokio::time::pause`) it is the virtual time that moves only to the next
/// timer, so a scripted session's times are exact.
pub(crate) fn now() -> Instant {
    tokio::time::Instant::now().into_std()
}

/// The write half of a player's channel. `Err` means the channel is gone (the player is cut).
pub(crate) trait Channel: Send + Sync + 'static {
    /// Sends `bytes` as channel data; waits for the client's window and the session's queue
    /// (the backpressure a slow player meets).
    fn data(&self, bytes: Bytes) -> impl Future<Output = Result<(), ()>> + Send;
    /// Sends the exit status.
    fn exit_status(&self, status: u32) -> impl Future<Output = Result<(), ()>> + Send;
    /// Sends end of file.
    fn eof(&self) -> impl Future<Output = Result<(), ()>> + Send;
    /// Closes the channel.
    fn close(&self) -> impl Future<Output = Result<(), ()>> + Send;
}

impl Channel for ChannelWriteHalf<Msg> {
    async fn data(&self, bytes: Bytes) -> Result<(), ()> {
        self.data_bytes(bytes).await.map_err(drop)
    }
    async fn exit_status(&self, status: u32) -> Result<(), ()> {
        ChannelWriteHalf::exit_status(self, status).await.map_err(drop)
    }
    async fn eof(&self) -> Result<(), ()> {
        ChannelWriteHalf::eof(self).await.map_err(drop)
    }
    async fn close(&self) -> Result<(), ()> {
        ChannelWriteHalf::close(self).await.map_err(drop)
    }
}
