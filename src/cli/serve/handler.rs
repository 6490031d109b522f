//! russh's per-connection `Handler`: authentication policy, the one session channel, its
//! requests (pty, env, shell, window-change accepted; everything else refused) and key input,
//! handed as bytes to the player's task.
//!
//! Rule for every callback: never await anything that depends on this session making progress
//! (e.g. `Handle::data`): callbacks run *inside* the session's event loop, which would deadlock.
//! Replies go through the `&mut Session` argument; bulk output goes through the player task.

use std::net::SocketAddr;
use std::sync::Arc;
use std::sync::atomic::Ordering;
use std::time::Instant;

use russh::keys::ssh_key::HashAlg;
use russh::server::{Auth, ChannelOpenHandle, Msg, PublicKeyOffer, Response, Session, VerifiedPublicKey};
use russh::{Channel, ChannelId, ChannelOpenFailure, ChannelWriteHalf, Pty};
use tokio::sync::watch;
use tokio_util::sync::CancellationToken;

use crate::play::{ColorMode, EncodeOptions};
// The hints and the window size are the doors' (crate-private); the API's `ProbeOptions` is
// built from numbers.
use crate::play::screen::probe::{EnvHints, WinSize};
use crate::play::{GraphicsRequest, ProbeOptions, ScreenConfig};
use tokio::sync::mpsc;

use super::authorized_keys::Refused;
use super::hub::Hub;
use super::limits::{self, clamp_pixels, clamp_size};
use super::viewer::{self, TerminalState, ViewerCtx};

/// Longest TERM / COLORTERM value kept (longer values are refused).
pub const MAX_TERM_LEN: usize = 64;
/// Colour changes of at most this much per channel are not re-sent (as `play` does over SSH).
const COLOR_THRESHOLD: u8 = 3;
/// Packets of key bytes waiting for the player's task; more are dropped (each is at most the
/// SSH window we offer, `INPUT_WINDOW_BYTES`).
const INPUT_QUEUE: usize = 64;

/// One connection's handler.
pub struct ClientHandler {
    hub: Arc<Hub>,
    id: u64,
    peer: SocketAddr,
    kill: CancellationToken,
    playing: CancellationToken,
    channel: Option<ChannelId>,
    write: Option<ChannelWriteHalf<Msg>>,
    term: Option<String>,
    colorterm: Option<String>,
    size: (u16, u16),
    /// The terminal's size in pixels as the client reports it (0 when it does not).
    pixels: (u16, u16),
    shell_requested: bool,
    /// Whether the key's authorized_keys line allows a pty (`no-pty`, `restrict` take it away).
    pty_allowed: bool,
    terminal: Option<watch::Sender<TerminalState>>,
    /// The channel's bytes for the player task, with the moment each packet arrived.
    input: Option<mpsc::Sender<(Instant, Vec<u8>)>>,
}

impl ClientHandler {
    pub(crate) fn new(
        hub: Arc<Hub>,
        id: u64,
        peer: SocketAddr,
        kill: CancellationToken,
        playing: CancellationToken,
    ) -> Self {
        Self {
            hub,
            id,
            peer,
            kill,
            playing,
            channel: None,
            write: None,
            term: None,
            colorterm: None,
            size: (80, 24),
            pixels: (0, 0),
            shell_requested: false,
            pty_allowed: true,
            terminal: None,
            input: None,
        }
    }

    fn ours(&self, channel: ChannelId) -> bool {
        self.channel == Some(channel)
    }

    fn refuse(&self, what: &str) {
        self.hub.stats.refused_requests.fetch_add(1, Ordering::Relaxed);
        eprintln!("serve: {} #{} refused {what}", self.peer, self.id);
    }

    fn refuse_request(&self, what: &str, channel: ChannelId, session: &mut Session) -> Result<(), russh::Error> {
        self.refuse(what);
        session.channel_failure(channel)
    }

    fn public(&self) -> bool {
        self.hub.allow.is_none()
    }

    /// Whether `key` may play from this client's address (`log`: say why not).
    fn listed(&mut self, key: &russh::keys::PublicKey, log: bool) -> bool {
        let Some(list) = &self.hub.allow else { return false };
        match list.admit(key, self.peer.ip()) {
            Ok(grant) => {
                self.pty_allowed = grant.pty;
                true
            }
            Err(Refused::From(line)) => {
                if log {
                    let fingerprint = key.fingerprint(HashAlg::Sha256);
                    eprintln!(
                        "serve: {} #{} key {fingerprint} refused: from= of line {line} does not admit {}",
                        self.peer,
                        self.id,
                        self.peer.ip()
                    );
                }
                false
            }
            Err(Refused::Unlisted) => false,
        }
    }

    fn closed(&mut self) {
        // Input that arrived before the EOF is handled first: "q" then EOF (a piped stdin) is
        // still a quit.
        self.input = None;
        if let Some(terminal) = &self.terminal {
            terminal.send_modify(|c| c.closed = true);
        }
    }
}

impl russh::server::Handler for ClientHandler {
    type Error = russh::Error;

    async fn auth_none(&mut self, _user: &str) -> Result<Auth, Self::Error> {
        Ok(if self.public() { Auth::Accept } else { Auth::reject() })
    }

    async fn auth_password(&mut self, _user: &str, _password: &str) -> Result<Auth, Self::Error> {
        Ok(Auth::reject())
    }

    async fn auth_publickey_offered(&mut self, _user: &str, offer: PublicKeyOffer<'_>) -> Result<Auth, Self::Error> {
        Ok(if self.public() || self.listed(offer.public_key, true) { Auth::Accept } else { Auth::reject() })
    }

    async fn auth_publickey(&mut self, _user: &str, key: VerifiedPublicKey<'_>) -> Result<Auth, Self::Error> {
        let ok = self.public() || self.listed(key.public_key, true);
        if ok {
            eprintln!("serve: {} #{} key {}", self.peer, self.id, key.public_key.fingerprint(HashAlg::Sha256));
        }
        Ok(if ok { Auth::Accept } else { Auth::reject() })
    }

    async fn auth_keyboard_interactive<'a>(
        &'a mut self,
        _user: &str,
        _submethods: &str,
        _response: Option<Response<'a>>,
    ) -> Result<Auth, Self::Error> {
        // Public pool: accept at once, with no prompts.
        Ok(if self.public() { Auth::Accept } else { Auth::reject() })
    }

    async fn auth_succeeded(&mut self, _session: &mut Session) -> Result<(), Self::Error> {
        self.hub.stats.authenticated.fetch_add(1, Ordering::Relaxed);
        Ok(())
    }

    async fn channel_open_session(
        &mut self,
        channel: Channel<Msg>,
        reply: ChannelOpenHandle,
        _session: &mut Session,
    ) -> Result<(), Self::Error> {
        if self.channel.is_some() {
            self.refuse("a second session channel");
            reply.reject(ChannelOpenFailure::ResourceShortage).await;
            return Ok(());
        }
        self.channel = Some(channel.id());
        // Keep only the write half. Dropping the read half matters: russh `await`s a send of every
        // incoming message into it (bounded, channel_buffer_size), so an unread half would stall
        // the whole session once full. With it dropped those sends fail at once and are ignored.
        let (_read, write) = channel.split();
        self.write = Some(write);
        reply.accept().await;
        Ok(())
    }

    async fn channel_open_x11(
        &mut self,
        _channel: Channel<Msg>,
        _addr: &str,
        _port: u32,
        reply: ChannelOpenHandle,
        _session: &mut Session,
    ) -> Result<(), Self::Error> {
        self.refuse("an x11 channel");
        reply.reject(ChannelOpenFailure::AdministrativelyProhibited).await;
        Ok(())
    }

    async fn channel_open_direct_tcpip(
        &mut self,
        _channel: Channel<Msg>,
        _host: &str,
        _port: u32,
        _orig: &str,
        _orig_port: u32,
        reply: ChannelOpenHandle,
        _session: &mut Session,
    ) -> Result<(), Self::Error> {
        self.refuse("direct-tcpip (local port forwarding)");
        reply.reject(ChannelOpenFailure::AdministrativelyProhibited).await;
        Ok(())
    }

    async fn channel_open_forwarded_tcpip(
        &mut self,
        _channel: Channel<Msg>,
        _host: &str,
        _port: u32,
        _orig: &str,
        _orig_port: u32,
        reply: ChannelOpenHandle,
        _session: &mut Session,
    ) -> Result<(), Self::Error> {
        self.refuse("forwarded-tcpip");
        reply.reject(ChannelOpenFailure::AdministrativelyProhibited).await;
        Ok(())
    }

    async fn channel_open_direct_streamlocal(
        &mut self,
        _channel: Channel<Msg>,
        _path: &str,
        reply: ChannelOpenHandle,
        _session: &mut Session,
    ) -> Result<(), Self::Error> {
        self.refuse("direct-streamlocal (unix socket forwarding)");
        reply.reject(ChannelOpenFailure::AdministrativelyProhibited).await;
        Ok(())
    }

    #[allow(clippy::too_many_arguments)]
    async fn pty_request(
        &mut self,
        channel: ChannelId,
        term: &str,
        cols: u32,
        rows: u32,
        pix_w: u32,
        pix_h: u32,
        _modes: &[(Pty, u32)],
        session: &mut Session,
    ) -> Result<(), Self::Error> {
        if !self.ours(channel) || self.shell_requested || !printable(term) {
            return self.refuse_request("pty-req", channel, session);
        }
        if !self.pty_allowed {
            // As sshd: the session goes on without a terminal (the game still draws, as for `ssh -T`).
            return self.refuse_request("pty-req (the key's line says no-pty or restrict)", channel, session);
        }
        self.term = Some(term.to_string());
        self.size = clamp_size(cols, rows);
        self.pixels = clamp_pixels(pix_w, pix_h);
        session.channel_success(channel)
    }

    async fn env_request(
        &mut self,
        channel: ChannelId,
        name: &str,
        value: &str,
        session: &mut Session,
    ) -> Result<(), Self::Error> {
        if self.ours(channel) && !self.shell_requested && name == "COLORTERM" && printable(value) {
            self.colorterm = Some(value.to_string());
            return session.channel_success(channel);
        }
        // OpenSSH sends LANG/LC_* with SendEnv: refusing them is normal and silent for the user.
        session.channel_failure(channel)
    }

    async fn shell_request(&mut self, channel: ChannelId, session: &mut Session) -> Result<(), Self::Error> {
        if !self.ours(channel) || self.shell_requested {
            return self.refuse_request("a second shell", channel, session);
        }
        self.shell_requested = true;
        session.channel_success(channel)?;
        let Some(slot) = self.hub.players.try_take() else {
            // Queued in order on this session: the line, exit status, EOF, close. The client
            // hangs up; one that lingers is cut by the handshake deadline (it never started playing).
            self.hub.stats.pool_full.fetch_add(1, Ordering::Relaxed);
            session.data(channel, format!("{}\r\n", limits::POOL_FULL_LINE).into_bytes())?;
            session.exit_status_request(channel, 1)?;
            session.eof(channel)?;
            session.close(channel)?;
            return Ok(());
        };
        let Some(write) = self.write.take() else {
            return Ok(());
        };
        self.playing.cancel(); // stops the handshake deadline
        let (terminal_tx, terminal_rx) = watch::channel(TerminalState { size: self.size, closed: false });
        let (input_tx, input_rx) = mpsc::channel(INPUT_QUEUE);
        self.terminal = Some(terminal_tx);
        self.input = Some(input_tx);
        let winsize = WinSize { cols: self.size.0, rows: self.size.1, x_px: self.pixels.0, y_px: self.pixels.1 };
        let screen = ScreenConfig {
            fps: self.hub.fps,
            bandwidth: self.hub.limits.client_bandwidth,
            // COLORTERM arrives only where the client sends it and this server accepts it
            // (OpenSSH sends it only with SendEnv); the TERM of a terminal known to draw 24-bit
            // colour (xterm-kitty, xterm-ghostty, wezterm, foot, ...) says it; otherwise the
            // probe asks the terminal (XTGETTCAP, DECRQSS). No hint of `--color truecolor`:
            // that flag is the server's, not the player's.
            color: ColorMode::detect(self.colorterm.as_deref(), self.term.as_deref()),
            color_auto: true,
            colour_hint: false,
            encode: EncodeOptions { threshold: COLOR_THRESHOLD, sync: true },
            graphics: GraphicsRequest::Auto,
            // A remote terminal: no file medium; its TMUX is not ours to see.
            probe: Some(ProbeOptions {
                env: EnvHints { ssh: true, ..EnvHints::default() },
                winsize,
                kitty_file: None,
                colours: false,
            }),
            // The far terminal answers for itself: whatever runs there, the round trip is real.
            link_path: crate::play::LinkPath::Direct,
        };
        let ctx = ViewerCtx {
            hub: self.hub.clone(),
            id: self.id,
            peer: self.peer,
            write,
            terminal: terminal_rx,
            input: input_rx,
            screen,
            kill: self.kill.clone(),
            slot,
        };
        self.hub.tasks.spawn(viewer::run(ctx));
        Ok(())
    }

    async fn window_change_request(
        &mut self,
        channel: ChannelId,
        cols: u32,
        rows: u32,
        pix_w: u32,
        pix_h: u32,
        session: &mut Session,
    ) -> Result<(), Self::Error> {
        if !self.ours(channel) {
            return session.channel_failure(channel);
        }
        self.size = clamp_size(cols, rows);
        self.pixels = clamp_pixels(pix_w, pix_h);
        let size = self.size;
        if let Some(terminal) = &self.terminal {
            terminal.send_modify(|c| c.size = size);
        }
        session.channel_success(channel)
    }

    async fn exec_request(
        &mut self,
        channel: ChannelId,
        _cmd: &[u8],
        session: &mut Session,
    ) -> Result<(), Self::Error> {
        self.refuse_request("exec", channel, session)
    }

    async fn subsystem_request(
        &mut self,
        channel: ChannelId,
        name: &str,
        session: &mut Session,
    ) -> Result<(), Self::Error> {
        let what = format!("subsystem {:?}", name.chars().take(32).collect::<String>());
        self.refuse_request(&what, channel, session)
    }

    async fn x11_request(
        &mut self,
        channel: ChannelId,
        _single: bool,
        _proto: &str,
        _cookie: &str,
        _screen: u32,
        session: &mut Session,
    ) -> Result<(), Self::Error> {
        self.refuse_request("x11-req", channel, session)
    }

    async fn agent_request(&mut self, _channel: ChannelId, _session: &mut Session) -> Result<bool, Self::Error> {
        self.refuse("auth-agent-req@openssh.com");
        Ok(false) // russh sends the channel failure
    }

    async fn tcpip_forward(
        &mut self,
        _addr: &str,
        _port: &mut u32,
        _session: &mut Session,
    ) -> Result<bool, Self::Error> {
        self.refuse("tcpip-forward (remote port forwarding)");
        Ok(false) // russh sends the request failure
    }

    async fn streamlocal_forward(&mut self, _path: &str, _session: &mut Session) -> Result<bool, Self::Error> {
        self.refuse("streamlocal-forward@openssh.com");
        Ok(false)
    }

    async fn data(&mut self, channel: ChannelId, data: &[u8], _session: &mut Session) -> Result<(), Self::Error> {
        if !self.ours(channel) {
            return Ok(());
        }
        if let Some(input) = &self.input
            && input.try_send((super::channel::now(), data.to_vec())).is_err()
        {
            self.hub.stats.input_dropped.fetch_add(1, Ordering::Relaxed);
        }
        Ok(())
    }

    async fn channel_eof(&mut self, channel: ChannelId, _session: &mut Session) -> Result<(), Self::Error> {
        if self.ours(channel) {
            self.closed();
        }
        Ok(())
    }

    async fn channel_close(&mut self, channel: ChannelId, _session: &mut Session) -> Result<(), Self::Error> {
        if self.ours(channel) {
            self.closed();
        }
        Ok(())
    }
}

fn printable(s: &str) -> bool {
    s.len() <= MAX_TERM_LEN && s.bytes().all(|b| b.is_ascii_graphic())
}
