//! What the server refuses before any work: requests for another host name (DNS rebinding),
//! and computations beyond a bounded queue.
//!
//! **Hosts.** A page on another origin can make a browser send requests to `127.0.0.1` under
//! a name it controls (DNS rebinding); the browser then sends that name in `Host`. Only the
//! loopback names (`localhost`, `127.0.0.1`, `[::1]`) and the bound address are answered, with
//! the server's port; anything else gets 421 Misdirected Request. A request without `Host`
//! (no browser sends one) is answered.
//!
//! **Computations.** Every endpoint that computes (`evaluate`, `analyze`, `render`) takes a
//! place in a bounded queue, then waits for one of a few workers; a full queue answers 503
//! with `Retry-After`, so a burst of requests cannot pile up threads or memory.

use std::sync::Arc;

use axum::extract::{Request, State};
use axum::http::{header, StatusCode};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};
use axum::Json;
use serde_json::json;
use tokio::sync::{OwnedSemaphorePermit, Semaphore};

/// Host names the server answers to, and its port (any port when `None`: a router used
/// in-process, without a listener).
#[derive(Clone, Debug)]
pub struct Hosts {
    names: Arc<Vec<String>>,
    port: Option<u16>,
}

impl Default for Hosts {
    fn default() -> Self {
        Self::new(None, None)
    }
}

impl Hosts {
    /// The loopback names, `bound` (the listening address, if not a wildcard) and `port`.
    #[must_use]
    pub fn new(bound: Option<std::net::IpAddr>, port: Option<u16>) -> Self {
        let mut names: Vec<String> = ["localhost", "127.0.0.1", "[::1]"]
            .map(str::to_owned)
            .to_vec();
        if let Some(ip) = bound.filter(|ip| !ip.is_unspecified()) {
            names.push(match ip {
                std::net::IpAddr::V4(v4) => v4.to_string(),
                std::net::IpAddr::V6(v6) => format!("[{v6}]"),
            });
        }
        Self {
            names: Arc::new(names),
            port,
        }
    }

    /// Whether a `Host` header value names this server.
    #[must_use]
    pub fn allows(&self, host: &str) -> bool {
        let host = host.trim().to_ascii_lowercase();
        let (name, port) = match host.rsplit_once(':') {
            // `[::1]` has colons inside its brackets; a port follows the closing one.
            Some((name, port)) if !port.contains(']') => (name.to_owned(), Some(port.to_owned())),
            _ => (host.clone(), None),
        };
        let port_ok = match (self.port, port) {
            (None, _) => true,
            (Some(expected), Some(given)) => given.parse() == Ok(expected),
            (Some(expected), None) => expected == 80,
        };
        port_ok && self.names.contains(&name)
    }
}

/// Refuses requests whose `Host` names another server.
pub async fn check_host(State(hosts): State<Hosts>, request: Request, next: Next) -> Response {
    let host = request
        .headers()
        .get(header::HOST)
        .map(|value| value.to_str().unwrap_or("(not text)").to_owned());
    match host {
        Some(host) if !hosts.allows(&host) => (
            StatusCode::MISDIRECTED_REQUEST,
            Json(json!({
                "error": format!("this server answers to localhost, not to \
                    {}", specula::excerpt(&host)),
                "parameter": "Host",
                "valid": hosts.names.join(", "),
            })),
        )
            .into_response(),
        _ => next.run(request).await,
    }
}

/// Computations waiting or running at once, at most; beyond, 503.
pub const QUEUED_COMPUTATIONS: usize = 32;
/// Computations running at once.
pub const CONCURRENT_COMPUTATIONS: usize = 2;

/// The bounded queue in front of the workers.
#[derive(Clone, Debug)]
pub struct Limiter {
    queue: Arc<Semaphore>,
    running: Arc<Semaphore>,
}

impl Limiter {
    /// A queue of `queued` places in front of `running` workers.
    #[must_use]
    pub fn new(queued: usize, running: usize) -> Self {
        Self {
            queue: Arc::new(Semaphore::new(queued)),
            running: Arc::new(Semaphore::new(running)),
        }
    }

    /// A worker's turn (held until dropped), or 503 when the queue is full.
    pub async fn turn(&self) -> Result<(OwnedSemaphorePermit, OwnedSemaphorePermit), Response> {
        let place = Arc::clone(&self.queue)
            .try_acquire_owned()
            .map_err(|_| busy())?;
        let worker = Arc::clone(&self.running)
            .acquire_owned()
            .await
            .map_err(|_| busy())?;
        Ok((place, worker))
    }
}

impl Default for Limiter {
    fn default() -> Self {
        Self::new(QUEUED_COMPUTATIONS, CONCURRENT_COMPUTATIONS)
    }
}

fn busy() -> Response {
    (
        StatusCode::SERVICE_UNAVAILABLE,
        [(header::RETRY_AFTER, "1")],
        Json(json!({
            "error": format!("the server is busy: {QUEUED_COMPUTATIONS} computations are already \
                queued; retry shortly"),
        })),
    )
        .into_response()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_loopback_names_with_the_port_are_allowed() {
        let hosts = Hosts::new(Some("127.0.0.1".parse().expect("ip")), Some(8080));
        for good in [
            "localhost:8080",
            "127.0.0.1:8080",
            "[::1]:8080",
            "LOCALHOST:8080",
        ] {
            assert!(hosts.allows(good), "{good}");
        }
        for bad in [
            "evil.example:8080",
            "localhost:9999",
            "localhost.evil.example:8080",
            "127.0.0.1.nip.io:8080",
            "localhost",
            "",
        ] {
            assert!(!hosts.allows(bad), "{bad}");
        }
        let anywhere = Hosts::new(Some("0.0.0.0".parse().expect("ip")), Some(80));
        assert!(anywhere.allows("localhost") && !anywhere.allows("0.0.0.0"));
    }

    #[tokio::test]
    async fn a_full_queue_answers_503_at_once() {
        let limiter = Limiter::new(2, 1);
        let first = limiter.turn().await.expect("a worker");
        // The second waits for the worker while holding the last place in the queue.
        let waiting = {
            let limiter = limiter.clone();
            tokio::spawn(async move { limiter.turn().await.map(|_| ()) })
        };
        while limiter.queue.available_permits() > 0 {
            tokio::task::yield_now().await;
        }
        let refused = limiter.turn().await.expect_err("the queue is full");
        assert_eq!(refused.status(), StatusCode::SERVICE_UNAVAILABLE);
        assert_eq!(refused.headers()[header::RETRY_AFTER], "1");
        drop(first);
        assert!(waiting.await.expect("task").is_ok(), "the queued one runs");
    }
}
