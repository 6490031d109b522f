//! The async-nats glue of an edge: the connection (credentials, TLS, its state for the status
//! line), the pool's stream and stores, following the log (from a snapshot when it must), and
//! sending requests and presence. Thin on purpose: every decision is in the sans-IO modules.

use std::sync::Arc;
use std::sync::atomic::Ordering;
use std::time::Duration;

use async_nats::jetstream::{self, consumer, kv, object_store, stream};
use async_nats::{Client, ConnectOptions, Event};
use futures_util::StreamExt;
use tokio::io::AsyncReadExt;
use tokio::sync::{Notify, mpsc};
use tokio_util::sync::CancellationToken;

use super::edge::{BusState, Incoming, Outgoing};
use super::lockstep::MAX_SNAPSHOT_BYTES;
use super::protocol::{self, MAX_TICK_BYTES, Names, Presence};
use super::{BusOptions, CONNECT_TIMEOUT};
use crate::cli::serve::limits::PlayerSlots;

/// The log's bounds: a day of ticks at 30 a second is 2.6 million; an hour is kept, and at most
/// this many bytes (a tick is 60 bytes when nothing happens, a few kB when much does).
const LOG_MAX_BYTES: i64 = 256 << 20;
const LOG_MAX_MESSAGES: i64 = 1_000_000;
const LOG_MAX_AGE: Duration = Duration::from_secs(3600);
/// The snapshot store's bound (a few snapshots' chunks while one replaces another).
const SNAPSHOTS_MAX_BYTES: i64 = 4 * MAX_SNAPSHOT_BYTES as i64;
/// The key-value bucket's largest value (the pool's settings text, the lease holder's name).
const KV_MAX_VALUE: i32 = 4096;
/// The object holding the latest snapshot.
pub const SNAPSHOT_OBJECT: &str = "latest";
/// The key holding the pool's settings.
const SETTINGS_KEY: &str = "settings";
/// How long a JetStream request (a publish's acknowledgement, a get) may take.
pub const REQUEST_TIMEOUT: Duration = Duration::from_secs(1);
/// How often an edge says how many players it has.
const PRESENCE_PERIOD: Duration = Duration::from_secs(1);
/// Pause before trying again after the bus failed a request.
const RETRY: Duration = Duration::from_millis(500);
/// The longest wait between two tries to reach the bus again (async-nats's own grows to 4 s).
/// Every edge is back within this of nats-server's return, so the holder of the sequencer's
/// lease renews it before a standby has read it unchanged for the lease's expiry (a second):
/// a restart does not move the role (docs/serve/bus.md, round 4).
const RECONNECT_DELAY_MAX: Duration = Duration::from_millis(250);
/// Messages a subscription buffers before the client drops them (bounds the sequencer's
/// intake from a flood).
const SUBSCRIPTION_CAPACITY: usize = 4096;

/// The pool on the bus: the connection, its names, its stream and stores.
pub struct PoolLink {
    /// The connection.
    pub client: Client,
    /// JetStream on it.
    pub js: jetstream::Context,
    /// The pool's subjects and buckets.
    pub names: Names,
    /// The log.
    pub stream: stream::Stream,
    /// The lease and the settings.
    pub kv: kv::Store,
    /// Snapshots.
    pub snapshots: object_store::ObjectStore,
    /// Wakes the follower when the game thread found a gap.
    pub rejoin: Notify,
}

/// Connects and opens the pool; fails with one line when the bus is not there, has no
/// JetStream, or runs this pool with other settings.
pub async fn open(options: &BusOptions, fingerprint: &str, state: Arc<BusState>) -> Result<PoolLink, String> {
    let names = Names::of(&options.pool).map_err(|e| e.0)?;
    let (user, address) = split_user(&options.url);
    let url = &address;
    let mut connect = ConnectOptions::new()
        .name(format!("tidepool-{}", options.edge))
        .connection_timeout(CONNECT_TIMEOUT)
        .subscription_capacity(SUBSCRIPTION_CAPACITY)
        .max_reconnects(None)
        .reconnect_delay_callback(|attempts| Duration::from_millis(1u64 << attempts.min(16)).min(RECONNECT_DELAY_MAX))
        .event_callback(move |event| {
            let state = state.clone();
            async move {
                match event {
                    Event::Connected => {
                        eprintln!("bus: connected");
                        state.connected.store(true, Ordering::Relaxed);
                        if state.lost_once.load(Ordering::Relaxed) {
                            state.back.notify_one();
                        }
                    }
                    Event::Disconnected => {
                        eprintln!("bus: disconnected; players stay, stones wait for the bus");
                        state.connected.store(false, Ordering::Relaxed);
                        state.lost_once.store(true, Ordering::Relaxed);
                    }
                    other => eprintln!("bus: {other}"),
                }
            }
        });
    if let Some((name, password)) = user {
        // async-nats does not read a password in the URL itself.
        connect = connect.user_and_password(name, password);
    }
    if let Some(path) = &options.credentials {
        connect = connect
            .credentials_file(path)
            .await
            .map_err(|e| format!("cannot read the credentials file {} ({e})", path.display()))?;
    }
    if let Some(ca) = &options.ca {
        connect = connect.add_root_certificates(ca.clone()).require_tls(true);
    }
    let client = tokio::time::timeout(CONNECT_TIMEOUT, connect.connect(without_user(&options.url)))
        .await
        .map_err(|_| format!("no answer from the bus at {url} within {} s", CONNECT_TIMEOUT.as_secs()))?
        .map_err(|e| format!("cannot reach the bus at {url} ({e}); start `nats-server -js` there or fix --bus"))?;
    let js = jetstream::ContextBuilder::new().timeout(REQUEST_TIMEOUT).build(client.clone());
    let no_js = |e: &dyn std::fmt::Display| {
        format!("the bus at {url} has no JetStream for the pool ({e}); start nats-server with -js")
    };
    let stream = js
        .get_or_create_stream(stream::Config {
            name: names.stream.clone(),
            subjects: vec![names.log.clone()],
            storage: stream::StorageType::File,
            max_bytes: LOG_MAX_BYTES,
            max_messages: LOG_MAX_MESSAGES,
            max_age: LOG_MAX_AGE,
            max_message_size: MAX_TICK_BYTES as i32,
            discard: stream::DiscardPolicy::Old,
            ..Default::default()
        })
        .await
        .map_err(|e| no_js(&e))?;
    // async-nats 0.50's `create_key_value` first reads the account's info in a form that
    // nats-server 2.9 (Debian 12's) does not send (no `reserved_memory`), so the bucket's stream
    // is made here with the settings it would make (one value a key, direct gets).
    let bucket = &names.bucket;
    js.get_or_create_stream(stream::Config {
        name: format!("KV_{bucket}"),
        subjects: vec![format!("$KV.{bucket}.>")],
        max_messages_per_subject: 1,
        max_message_size: KV_MAX_VALUE,
        storage: stream::StorageType::File,
        allow_rollup: true,
        deny_delete: true,
        allow_direct: true,
        discard: stream::DiscardPolicy::New,
        num_replicas: 1,
        ..Default::default()
    })
    .await
    .map_err(|e| no_js(&e))?;
    let kv = js.get_key_value(bucket.clone()).await.map_err(|e| no_js(&e))?;
    let snapshots = match js.get_object_store(names.snapshots.clone()).await {
        Ok(store) => store,
        Err(_) => js
            .create_object_store(object_store::Config {
                bucket: names.snapshots.clone(),
                max_bytes: SNAPSHOTS_MAX_BYTES,
                storage: stream::StorageType::File,
                ..Default::default()
            })
            .await
            .map_err(|e| no_js(&e))?,
    };
    check_settings(&kv, fingerprint, &options.pool).await?;
    Ok(PoolLink { client, js, names, stream, kv, snapshots, rejoin: Notify::new() })
}

/// The first edge writes the pool's settings; every later one must have the same.
async fn check_settings(kv: &kv::Store, fingerprint: &str, pool: &str) -> Result<(), String> {
    if kv.create(SETTINGS_KEY, fingerprint.to_owned().into()).await.is_ok() {
        return Ok(());
    }
    let theirs = kv.get(SETTINGS_KEY).await.map_err(|e| format!("cannot read pool {pool}'s settings ({e})"))?;
    match theirs {
        Some(theirs) if theirs.as_ref() == fingerprint.as_bytes() => Ok(()),
        Some(theirs) => Err(format!(
            "pool {pool} runs other settings ({}); start this edge with the same --size, seed and water flags, or pick another --pool",
            String::from_utf8_lossy(&theirs).chars().take(200).collect::<String>()
        )),
        None => Err(format!("pool {pool}'s settings vanished while joining; start again")),
    }
}

/// Reads the latest snapshot, if there is one, within [`MAX_SNAPSHOT_BYTES`].
async fn latest_snapshot(pool: &PoolLink) -> Result<Option<Vec<u8>>, String> {
    let mut object = match pool.snapshots.get(SNAPSHOT_OBJECT).await {
        Ok(object) => object,
        Err(e) if e.kind() == object_store::GetErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(format!("cannot read the snapshot ({e})")),
    };
    if object.info().size > MAX_SNAPSHOT_BYTES {
        return Err(format!("the snapshot is {} bytes, more than {MAX_SNAPSHOT_BYTES}", object.info().size));
    }
    let mut bytes = Vec::with_capacity(object.info().size);
    (&mut object)
        .take(MAX_SNAPSHOT_BYTES as u64 + 1)
        .read_to_end(&mut bytes)
        .await
        .map_err(|e| format!("cannot read the snapshot ({e})"))?;
    Ok(Some(bytes))
}

/// The log sequence a snapshot ends at (its third number; see `Lockstep::snapshot`).
fn snapshot_seq(bytes: &[u8]) -> Option<u64> {
    let at = 6 + 16;
    bytes.get(at..at + 8).and_then(|b| b.try_into().ok()).map(u64::from_le_bytes)
}

/// Joins: from the latest snapshot, or from the log's start when the log has all of it.
/// Returns the log sequence to follow after.
async fn join(pool: &PoolLink, tx: &mpsc::Sender<Incoming>) -> Result<u64, String> {
    if let Some(bytes) = latest_snapshot(pool).await? {
        let seq = snapshot_seq(&bytes).ok_or("the snapshot is cut short")?;
        tx.send(Incoming::Restore(bytes)).await.map_err(|_| "stopping")?;
        return Ok(seq);
    }
    let mut stream = pool.stream.clone();
    let info = stream.info().await.map_err(|e| format!("cannot read the log ({e})"))?;
    if info.state.first_sequence <= 1 {
        tx.send(Incoming::Fresh).await.map_err(|_| "stopping")?;
        return Ok(0);
    }
    Err(format!("the log starts at entry {} and there is no snapshot yet", info.state.first_sequence))
}

/// Follows the pool's log until `stop`: joins, then hands every entry to the game thread in
/// order; joins again when the game thread found a gap, and picks up where it was after the
/// bus comes back.
pub async fn follow(pool: Arc<PoolLink>, tx: mpsc::Sender<Incoming>, state: Arc<BusState>, stop: CancellationToken) {
    let mut next: Option<u64> = None;
    while !stop.is_cancelled() {
        let from = match next {
            Some(seq) => seq,
            None => match join(&pool, &tx).await {
                Ok(seq) => seq + 1,
                Err(why) => {
                    eprintln!("bus: cannot join yet: {why}");
                    tokio::select! { _ = stop.cancelled() => return, _ = tokio::time::sleep(RETRY) => continue }
                }
            },
        };
        next = Some(from);
        let consumer = pool
            .stream
            .create_consumer(consumer::pull::OrderedConfig {
                filter_subject: pool.names.log.clone(),
                deliver_policy: consumer::DeliverPolicy::ByStartSequence { start_sequence: from },
                ..Default::default()
            })
            .await;
        let mut messages = match consumer {
            Ok(c) => match c.messages().await {
                Ok(m) => m,
                Err(e) => {
                    eprintln!("bus: cannot read the log ({e}); trying again");
                    tokio::time::sleep(RETRY).await;
                    continue;
                }
            },
            Err(e) => {
                eprintln!("bus: cannot read the log ({e}); trying again");
                tokio::select! { _ = stop.cancelled() => return, _ = tokio::time::sleep(RETRY) => continue }
            }
        };
        loop {
            tokio::select! {
                _ = stop.cancelled() => return,
                _ = pool.rejoin.notified() => { next = None; break; }
                _ = state.back.notified() => {
                    eprintln!("bus: back; reading the log again from entry {}", next.unwrap_or(0));
                    break;
                }
                m = messages.next() => match m {
                    Some(Ok(message)) => {
                        let Ok(info) = message.info() else { continue };
                        let seq = info.stream_sequence;
                        if tx.send(Incoming::Entry { seq, bytes: message.payload.to_vec() }).await.is_err() {
                            return;
                        }
                        next = Some(seq + 1);
                    }
                    Some(Err(e)) => {
                        if state.connected.load(Ordering::Relaxed) {
                            eprintln!("bus: the log's reader failed ({e}); reading again from entry {}", next.unwrap_or(0));
                        }
                        tokio::time::sleep(RETRY).await;
                        break;
                    }
                    None => break,
                },
            }
        }
    }
}

/// Sends the players' requests to the sequencer and, every second, this edge's player count;
/// passes the game thread's call to join again to the follower.
pub async fn forward(
    pool: Arc<PoolLink>,
    mut rx: mpsc::Receiver<Outgoing>,
    edge: String,
    players: Arc<PlayerSlots>,
    stop: CancellationToken,
) {
    let mut presence = tokio::time::interval(PRESENCE_PERIOD);
    loop {
        tokio::select! {
            _ = stop.cancelled() => return,
            _ = presence.tick() => {
                let p = Presence { edge: edge.clone(), players: players.count() as u32 };
                let _ = pool.client.publish(pool.names.presence.clone(), protocol::bytes_of(&p).into()).await;
            }
            out = rx.recv() => match out {
                Some(Outgoing::Submit(bytes)) => {
                    let _ = pool.client.publish(pool.names.submit.clone(), bytes.into()).await;
                }
                Some(Outgoing::Rejoin) => pool.rejoin.notify_one(),
                None => return,
            },
        }
    }
}

/// The user and password a bus URL names (`tls://USER:PASSWORD@HOST:PORT`, as nats-server's
/// accounts with passwords want), and the URL to show, its password hidden.
fn split_user(url: &str) -> (Option<(String, String)>, String) {
    let Some((scheme, rest)) = url.split_once("://") else { return (None, url.to_owned()) };
    let Some((userinfo, host)) = rest.rsplit_once('@') else { return (None, url.to_owned()) };
    let (name, password) = userinfo.split_once(':').unwrap_or((userinfo, ""));
    (Some((name.to_owned(), password.to_owned())), format!("{scheme}://{name}:***@{host}"))
}

/// The URL without its user and password (what the connection is given).
fn without_user(url: &str) -> String {
    match url.split_once("://") {
        Some((scheme, rest)) => match rest.rsplit_once('@') {
            Some((_, host)) => format!("{scheme}://{host}"),
            None => url.to_owned(),
        },
        None => url.to_owned(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_password_in_the_bus_url_is_used_and_never_shown() {
        let (user, shown) = split_user("tls://edge1:s3cret@nats.example:4222");
        assert_eq!(user, Some(("edge1".into(), "s3cret".into())));
        assert_eq!(shown, "tls://edge1:***@nats.example:4222");
        assert_eq!(without_user("tls://edge1:s3cret@nats.example:4222"), "tls://nats.example:4222");
        assert_eq!(split_user("nats://127.0.0.1:4222"), (None, "nats://127.0.0.1:4222".into()));
        assert_eq!(without_user("nats://127.0.0.1:4222"), "nats://127.0.0.1:4222");
    }
}
