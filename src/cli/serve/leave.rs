//! How a player leaves: why, what they are told (scene by name), and how the connection ends
//! (a closing channel, an exit status, a client that lingers cut after a moment).

use std::time::Duration;

use bytes::Bytes;
use tokio_util::sync::CancellationToken;

use super::channel::Channel;
use super::limits::FAREWELL_TIMEOUT;

/// Time a player's connection may stay open after its game ended before it is cut.
pub const LINGER: Duration = Duration::from_secs(1);

/// Why a player leaves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Leave {
    /// Pressed q, Esc or Ctrl-C.
    Quit,
    /// Sent EOF or closed the channel.
    ClientClosed,
    /// No key for the idle timeout.
    Idle,
    /// A frame could not be sent within the stall timeout.
    Stalled,
    /// The server is stopping.
    Shutdown,
    /// The connection was cut (it ended, or the server cut it).
    Cut,
}

impl Leave {
    /// What the player is told as they go, if anything.
    fn farewell(self, scene: &str) -> Option<String> {
        match self {
            Leave::Quit => Some(format!("bye from the {scene}")),
            Leave::Idle => Some(format!("you were idle too long; the {scene} sent you home")),
            Leave::Shutdown => Some(format!("the {scene} is closing (server shutting down); bye")),
            Leave::Stalled | Leave::ClientClosed | Leave::Cut => None,
        }
    }

    /// The reason, for the log.
    pub fn name(self) -> &'static str {
        match self {
            Leave::Quit => "quit",
            Leave::ClientClosed => "closed",
            Leave::Idle => "idle",
            Leave::Stalled => "stalled",
            Leave::Shutdown => "shutdown",
            Leave::Cut => "cut",
        }
    }
}

/// Hands the terminal back (`restore`: the screen's farewell bytes), says why, and ends the
/// channel as `reason` calls for (bounded in time).
pub(crate) async fn say_goodbye(
    reason: Leave,
    scene: &str,
    restore: Vec<u8>,
    write: &impl Channel,
    kill: &CancellationToken,
) {
    let mut goodbye = restore;
    match reason.farewell(scene) {
        Some(message) => {
            goodbye.extend_from_slice(format!("{message}\r\n").as_bytes());
            let _ = tokio::time::timeout(FAREWELL_TIMEOUT, async {
                write.data(Bytes::from(goodbye)).await.ok()?;
                write.exit_status(0).await.ok()?;
                write.eof().await.ok()?;
                // No DISCONNECT after this: OpenSSH exits on DISCONNECT before writing channel
                // data it has already received, so the farewell and the restore would be lost.
                write.close().await.ok()
            })
            .await;
        }
        None if reason == Leave::ClientClosed => {
            let _ = tokio::time::timeout(FAREWELL_TIMEOUT, async {
                write.data(Bytes::from(goodbye)).await.ok()?;
                write.close().await.ok()
            })
            .await;
        }
        None => {}
    }
    match reason {
        Leave::Cut => {}
        // It is not reading: nothing more will get through, cut now.
        Leave::Stalled => kill.cancel(),
        // A client that keeps the connection open after its game ended is cut shortly after.
        _ => {
            tokio::select! {
                _ = kill.cancelled() => {}
                _ = tokio::time::sleep(LINGER) => kill.cancel(),
            }
        }
    }
}
