//! The accept loop: HTTP/1.1 with bounds on connections and on how long each may take.
//!
//! `axum::serve` has no header or idle timeout, so 20,000 idle connections exhaust the file
//! descriptors. Here:
//! - at most [`MAX_CONNECTIONS`] are served at once; one more is answered `503` with
//!   `Retry-After` and closed at once, so the server keeps answering while it is flooded;
//! - a connection must send its first byte within [`IDLE_TIMEOUT`] and its whole header
//!   within [`HEADER_TIMEOUT`] (hyper's header-read timer; slow-loris);
//! - one request per connection (no keep-alive, so no idle connection is held between
//!   requests), and every connection is closed after [`CONNECTION_TIMEOUT`] whatever it does.

use std::sync::Arc;
use std::time::Duration;

use axum::Router;
use hyper_util::rt::{TokioIo, TokioTimer};
use hyper_util::service::TowerToHyperService;
use tokio::io::AsyncWriteExt;
use tokio::net::TcpListener;
use tokio::sync::Semaphore;

/// Connections served at once.
pub const MAX_CONNECTIONS: usize = 256;
/// How long a new connection may stay silent.
pub const IDLE_TIMEOUT: Duration = Duration::from_secs(10);
/// How long a request's header may take to arrive.
pub const HEADER_TIMEOUT: Duration = Duration::from_secs(10);
/// How long any connection may last (a render takes a few seconds at most).
pub const CONNECTION_TIMEOUT: Duration = Duration::from_secs(120);

/// The answer to a connection beyond the limit.
fn busy() -> Vec<u8> {
    let body = format!(
        "{{\"error\":\"more than {MAX_CONNECTIONS} connections at once; retry in a second\"}}\n"
    );
    format!(
        "HTTP/1.1 503 Service Unavailable\r\nRetry-After: 1\r\nContent-Type: application/json\r\nContent-Length: {}\r\nConnection: close\r\n\r\n{body}",
        body.len()
    )
    .into_bytes()
}

/// Serves `router` on `listener` until `shutdown` completes.
pub async fn serve(
    listener: TcpListener,
    router: Router,
    shutdown: impl std::future::Future<Output = ()>,
) -> Result<(), String> {
    let slots = Arc::new(Semaphore::new(MAX_CONNECTIONS));
    let mut shutdown = std::pin::pin!(shutdown);
    loop {
        let (mut stream, _) = tokio::select! {
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
        let Ok(slot) = Arc::clone(&slots).try_acquire_owned() else {
            tokio::spawn(async move {
                let _ =
                    tokio::time::timeout(Duration::from_secs(1), stream.write_all(&busy())).await;
            });
            continue;
        };
        let service = TowerToHyperService::new(router.clone());
        tokio::spawn(async move {
            let _slot = slot;
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
    }
}
