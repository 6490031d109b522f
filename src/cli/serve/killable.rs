//! A socket wrapper the server can cut at any moment.
//!
//! russh spawns each session's event loop itself (`run_stream` → `russh_util::runtime::spawn`) and
//! gives no way to abort it: `Handle::disconnect` is queued behind data on a bounded queue that the
//! loop stops draining while the client's window is exhausted, so a client that keeps TCP alive but
//! never consumes channel data could never be removed. Wrapping the stream makes every read and
//! write fail once the token is cancelled; the loop then ends with an I/O error and drops the socket.
//!
//! It also counts the bytes that cross the socket each way (what the wire carries, after
//! encryption and compression), for the log.

use std::io;
use std::pin::Pin;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::task::{Context, Poll};

use tokio::io::{AsyncRead, AsyncWrite, ReadBuf};
use tokio_util::sync::{CancellationToken, WaitForCancellationFutureOwned};

/// Bytes written to and read from a socket so far.
#[derive(Debug, Default)]
pub struct Counts {
    written: AtomicU64,
    read: AtomicU64,
}

impl Counts {
    /// (written, read).
    pub fn get(&self) -> (u64, u64) {
        (self.written.load(Ordering::Relaxed), self.read.load(Ordering::Relaxed))
    }
}

/// `inner`, cut when `token` is cancelled.
pub struct Killable<S> {
    inner: S,
    cancelled: Pin<Box<WaitForCancellationFutureOwned>>,
    token: CancellationToken,
    counts: Arc<Counts>,
}

impl<S> Killable<S> {
    /// Wraps `inner`; cancelling `token` (or a parent of it) cuts the stream.
    pub fn new(inner: S, token: CancellationToken) -> Self {
        let counts = Arc::new(Counts::default());
        Self { inner, cancelled: Box::pin(token.clone().cancelled_owned()), token, counts }
    }

    /// The bytes that crossed the socket, updated as they do.
    pub fn counts(&self) -> Arc<Counts> {
        self.counts.clone()
    }

    fn check(&mut self, cx: &mut Context<'_>) -> io::Result<()> {
        if self.token.is_cancelled() || self.cancelled.as_mut().poll(cx).is_ready() {
            return Err(io::Error::new(io::ErrorKind::ConnectionAborted, "connection cut by the server"));
        }
        Ok(())
    }
}

impl<S: AsyncRead + Unpin> AsyncRead for Killable<S> {
    fn poll_read(mut self: Pin<&mut Self>, cx: &mut Context<'_>, buf: &mut ReadBuf<'_>) -> Poll<io::Result<()>> {
        if let Err(e) = self.check(cx) {
            return Poll::Ready(Err(e));
        }
        let before = buf.filled().len();
        let result = Pin::new(&mut self.inner).poll_read(cx, buf);
        self.counts.read.fetch_add((buf.filled().len() - before) as u64, Ordering::Relaxed);
        result
    }
}

impl<S: AsyncWrite + Unpin> AsyncWrite for Killable<S> {
    fn poll_write(mut self: Pin<&mut Self>, cx: &mut Context<'_>, buf: &[u8]) -> Poll<io::Result<usize>> {
        if let Err(e) = self.check(cx) {
            return Poll::Ready(Err(e));
        }
        let result = Pin::new(&mut self.inner).poll_write(cx, buf);
        if let Poll::Ready(Ok(n)) = result {
            self.counts.written.fetch_add(n as u64, Ordering::Relaxed);
        }
        result
    }

    fn poll_flush(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        if let Err(e) = self.check(cx) {
            return Poll::Ready(Err(e));
        }
        Pin::new(&mut self.inner).poll_flush(cx)
    }

    fn poll_shutdown(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        // Shutting down is always allowed: it only sends FIN.
        Pin::new(&mut self.inner).poll_shutdown(cx)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tokio::io::{AsyncReadExt, AsyncWriteExt};

    #[tokio::test]
    async fn a_pending_read_fails_when_cancelled() {
        let (a, mut b) = tokio::io::duplex(64);
        let token = CancellationToken::new();
        let mut k = Killable::new(a, token.clone());
        let reader = tokio::spawn(async move {
            let mut buf = [0u8; 8];
            k.read(&mut buf).await
        });
        tokio::task::yield_now().await;
        token.cancel();
        let r = reader.await.unwrap();
        assert_eq!(r.unwrap_err().kind(), io::ErrorKind::ConnectionAborted);
        b.write_all(b"x").await.ok();
    }
}
