//! The accept loop: HTTP/1.1 with bounds on connections and on how long each may take.
//!
//! `axum::serve` has no header or idle timeout, so 20,000 idle connections exhaust the file
//! descriptors. Here:
//! - a connection that has not yet sent a whole request header is *waiting*; at most
//!   [`max_waiting`] wait at once (half the process's descriptor limit, at most 16,384), and
//!   a new connection beyond that closes the oldest waiting one. A flood of idle or slow
//!   (slow-loris) connections therefore costs a bounded number of descriptors and a few
//!   kilobytes each, and never blocks a real request, which sends its header at once and
//!   stops waiting: it is answered however many idle connections are open;
//! - a waiting connection must send its first byte within [`IDLE_TIMEOUT`] and its whole
//!   header within [`HEADER_TIMEOUT`] (hyper's header-read timer);
//! - one request per connection (no keep-alive, so no idle connection is held between
//!   requests), and every connection is closed after [`CONNECTION_TIMEOUT`] whatever it does.
//!   The work requests cause is bounded apart, by the computation queue (`guard.rs`).

use std::collections::BTreeMap;
use std::sync::{Arc, Mutex, PoisonError};
use std::time::Duration;

use axum::Router;
use hyper_util::rt::{TokioIo, TokioTimer};
use hyper_util::service::TowerToHyperService;
use tokio::net::TcpListener;
use tokio::task::AbortHandle;
use tower::ServiceExt;

/// How long a new connection may stay silent.
pub const IDLE_TIMEOUT: Duration = Duration::from_secs(10);
/// How long a request's header may take to arrive.
pub const HEADER_TIMEOUT: Duration = Duration::from_secs(10);
/// How long any connection may last (a render takes a few seconds at most).
pub const CONNECTION_TIMEOUT: Duration = Duration::from_secs(120);
/// The most connections that may wait for their request at once, whatever the limit.
const MOST_WAITING: usize = 16_384;

/// How many connections may wait for their request header at once: half this process's
/// soft limit on open files (read from `/proc/self/limits`; 1,024 assumed where it cannot
/// be read), at least 64 and at most 16,384, so that accepting never runs out of
/// descriptors while the oldest waiting connection is closed to make room.
#[must_use]
pub fn max_waiting() -> usize {
    let soft_limit = std::fs::read_to_string("/proc/self/limits")
        .ok()
        .and_then(|limits| {
            let line = limits.lines().find(|l| l.starts_with("Max open files"))?;
            line.split_whitespace().nth(3)?.parse::<usize>().ok()
        })
        .unwrap_or(1024);
    (soft_limit / 2).clamp(64, MOST_WAITING)
}

/// The connections waiting for their request by id: ids only grow, so the first is the
/// oldest, and removing one is logarithmic in their number.
#[derive(Default)]
struct Waiting {
    next_id: u64,
    queue: BTreeMap<u64, AbortHandle>,
}

impl Waiting {
    /// No longer waiting: its request arrived, or it ended.
    fn remove(waiting: &Mutex<Waiting>, id: u64) {
        let mut waiting = waiting.lock().unwrap_or_else(PoisonError::into_inner);
        waiting.queue.remove(&id);
    }
}

/// Removes its connection from the waiting ones when the connection's task ends, however
/// it ends.
struct Registered {
    waiting: Arc<Mutex<Waiting>>,
    id: u64,
}

impl Drop for Registered {
    fn drop(&mut self) {
        Waiting::remove(&self.waiting, self.id);
    }
}

/// Serves `router` on `listener` until `shutdown` completes, at most [`max_waiting`]
/// connections waiting for their request.
pub async fn serve(
    listener: TcpListener,
    router: Router,
    shutdown: impl std::future::Future<Output = ()>,
) -> Result<(), String> {
    serve_with(listener, router, shutdown, max_waiting()).await
}

/// [`serve`] with at most `most_waiting` connections waiting for their request.
pub async fn serve_with(
    listener: TcpListener,
    router: Router,
    shutdown: impl std::future::Future<Output = ()>,
    most_waiting: usize,
) -> Result<(), String> {
    let waiting = Arc::new(Mutex::new(Waiting::default()));
    let mut shutdown = std::pin::pin!(shutdown);
    loop {
        let (stream, _) = tokio::select! {
            accepted = listener.accept() => match accepted {
                Ok(accepted) => accepted,
                // Out of descriptors or a reset before accept: keep serving the others.
                Err(_) => {
                    tokio::time::sleep(Duration::from_millis(10)).await;
                    continue;
                }
            },
            () = &mut shutdown => return Ok(()),
        };
        let mut queue = waiting.lock().unwrap_or_else(PoisonError::into_inner);
        let id = queue.next_id;
        queue.next_id += 1;
        // The request's arrival takes the connection out of the waiting ones, for good.
        let arrived = Arc::clone(&waiting);
        let service = TowerToHyperService::new(router.clone().map_request(
            move |request: hyper::Request<hyper::body::Incoming>| {
                Waiting::remove(&arrived, id);
                request
            },
        ));
        let registered = Registered {
            waiting: Arc::clone(&waiting),
            id,
        };
        let task = tokio::spawn(async move {
            let _registered = registered;
            if !matches!(
                tokio::time::timeout(IDLE_TIMEOUT, stream.readable()).await,
                Ok(Ok(()))
            ) {
                return;
            }
            let mut http = hyper::server::conn::http1::Builder::new();
            http.timer(TokioTimer::new())
                .header_read_timeout(HEADER_TIMEOUT)
                .keep_alive(false);
            let connection = http.serve_connection(TokioIo::new(stream), service);
            let _ = tokio::time::timeout(CONNECTION_TIMEOUT, connection).await;
        });
        queue.queue.insert(id, task.abort_handle());
        while queue.queue.len() > most_waiting {
            if let Some((_, oldest)) = queue.queue.pop_first() {
                oldest.abort();
            }
        }
    }
}
